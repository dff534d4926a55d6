#!/usr/bin/env python3
"""Writes the passes, meshes and fences of the Night City captures from one description.

The capture JSON is the source of truth that framelab reads and that people edit; this script
exists because the day and night captures share almost every pass, and writing ~60 passes by
hand in two files would let them drift. It keeps the header and resources already in the
capture (names, formats and sizes follow NIGHT_CITY_PASSES.md) and rewrites `meshes`,
`fences` and `passes`, plus the few resource fields the passes depend on.

    python3 captures/night_city/build_capture.py captures/night_city/main_street_day.json
"""

import json
import sys

# ---------------------------------------------------------------------------------------------
# Scene constants shared with the shaders (scene.wgsl, geometry_prep.wgsl).

KIND_COUNTS = [768, 1024, 224]  # cars, pedestrians, holographic signs
CANDIDATES = sum(KIND_COUNTS)
BOX_INDICES = 36
CAPSULE_SEGMENTS = 12
# Two spheres (segments x segments/2 quads) and the cylinder between them.
CAPSULE_INDICES = 2 * (CAPSULE_SEGMENTS * (CAPSULE_SEGMENTS // 2) * 6) + CAPSULE_SEGMENTS * 6
LIGHT_COUNT = 256
SHADOWED_LIGHTS = 10

# Structure-of-arrays vertex layout of the source engine.
SOA = [
    {"slot": 0, "attributes": [{"semantic": "POSITION0", "format": "snorm16x4", "location": 0}]},
    {"slot": 1, "attributes": [{"semantic": "TEXCOORD0", "format": "float16x2", "location": 1}]},
    {
        "slot": 2,
        "attributes": [
            {"semantic": "NORMAL0", "format": "packed_snorm10x3", "location": 2},
            {"semantic": "TANGENT0", "format": "packed_snorm10x3", "location": 3},
        ],
    },
    {
        "slot": 3,
        "attributes": [
            {"semantic": "COLOR0", "format": "unorm8x4", "location": 4},
            {"semantic": "TEXCOORD1", "format": "float16x2", "location": 5},
        ],
    },
]


def mesh(name, generator, seed, params, index_format="uint32"):
    return {
        "name": name,
        "source": {"generator": {"name": generator, "seed": seed, "params": params}},
        "index_format": index_format,
        "streams": SOA,
    }


CITY = {"blocks_x": 4, "blocks_z": 6, "block_size": 40, "street_width": 12,
        "min_height": 12, "max_height": 95, "buildings_per_block": 4}
BUILDINGS = CITY["blocks_x"] * CITY["blocks_z"] * CITY["buildings_per_block"]
# VB7: three float4 rows of each instance's transform.
INSTANCE_ROWS = {"slot": 7, "step": "instance", "attributes": [
    {"semantic": f"INSTANCE{r}", "format": "float32x4", "location": 6 + r} for r in range(3)]}


MESHES = [
    # Instanced boxes, one per building lot.
    {**mesh("buildings", "box", 21, {"size": 1}, "uint16"),
     "streams": [*SOA, INSTANCE_ROWS], "instance_count": BUILDINGS,
     "instances": {"name": "city_lots", "seed": 21, "params": CITY}},
    # One box per block: the CSM proxy's simple meshes.
    mesh("block_proxies", "city_blocks", 21, {**CITY, "buildings_per_block": 1}),
    mesh("ground", "grid", 22, {"size": 1200, "divisions": 160}),
    mesh("terrain_chunk", "grid", 23, {"size": 300, "divisions": 48}),
    mesh("water", "water_plate", 24, {"size": 600, "divisions": 96, "height": 0}),
    mesh("box", "box", 25, {"size": 1}, "uint16"),
    mesh("capsule", "capsule", 26, {"radius": 0.3, "height": 1.8, "segments": CAPSULE_SEGMENTS}, "uint16"),
    mesh("trees", "foliage_cards", 27, {"count": 140, "area": 100, "height": 6, "width": 4}),
    mesh("decal_quad", "grid", 28, {"size": 1, "divisions": 1}, "uint16"),
]

FENCES = [
    "billboard_sources", "gui_drawn", "voxels_ready", "instances_ready",
    "reflection_done", "masks_done", "noised_ready", "ao_done", "omni_done", "cascades_done",
    "sun_shadow_ready", "env_captured", "direct_lit",
]

# ---------------------------------------------------------------------------------------------
# Helpers


def sampled(resource, **extra):
    return {"resource": resource, "access": "sampled", **extra}


def storage(resource, access="storage_write", **extra):
    return {"resource": resource, "access": access, **extra}


def sampler(name):
    return {"sampler": name}


def fullscreen(label="fullscreen"):
    return {"label": label, "count": 3}


def raster(name, markers, shader, vertex, fragment, colors, **rest):
    p = {
        "name": name,
        "queue": rest.pop("queue", "graphics"),
        "kind": "raster",
        "markers": ["Frame", *markers],
        "shader": {"file": f"shaders/{shader}", "vertex": vertex},
        "color_attachments": colors,
    }
    if fragment:
        p["shader"]["fragment"] = fragment
    p.update(rest)
    return p


def compute(name, markers, shader, entry, dispatches, **rest):
    p = {
        "name": name,
        "queue": rest.pop("queue", "compute"),
        "kind": "compute",
        "markers": ["Frame", *markers],
        "shader": {"file": f"shaders/{shader}", "compute": entry},
        "dispatches": dispatches,
    }
    p.update(rest)
    return p


def color(resource, clear=(0, 0, 0, 0), **extra):
    return {"resource": resource, "load": "clear", "clear": list(clear), **extra}


def groups(x, y=1, z=1, **extra):
    return {"groups": [x, y, z], **extra}


# Scene params: every member of scene.wgsl's Params, overridden per draw.
SCENE_DEFAULTS = {
    "view": 0, "material": 0, "light": 0, "instance_base": 0,
    "offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0], "object_mask": 0,
    "probe": [0, 0, 0, 0], "face": 0,
}


def d(label, mesh_name, vertex, **params):
    out = {"label": label, "mesh": mesh_name, "vertex": vertex}
    stencil = params.pop("stencil", None)
    indirect = params.pop("indirect", None)
    if stencil is not None:
        out["stencil_reference"] = stencil
    if indirect is not None:
        out["indirect"] = {"buffer": "draw_args", "offset": indirect}
    if params:
        out["params"] = params
    return out


FIRST_CAR = CANDIDATES
FIRST_PEDESTRIAN = CANDIDATES + KIND_COUNTS[0]
FIRST_SIGN = CANDIDATES + KIND_COUNTS[0] + KIND_COUNTS[1]

# Draws of the world, in the base pass's order, with the stencil values the seed describes.
def world_draws(shadow=False, with_instances=True, with_foliage=True, with_ground=True):
    draws = [dict(d("static meshes: buildings", "buildings", "vs_building", material=0, object_mask=0),
                  instances=BUILDINGS)]
    if with_ground:
        draws.append(d("ground", "ground", "vs_terrain", material=1, object_mask=1))
        if not shadow:
            draws.append(d("water", "water", "vs_water", material=3, object_mask=1, offset=[0, 0, 380, 0]))
    if with_instances:
        draws.append(d("holographic signs", "box", "vs_instanced", material=2, instance_base=FIRST_SIGN, indirect=40))
        draws += [
            d("cars", "box", "vs_instanced", material=4, object_mask=2, instance_base=FIRST_CAR, indirect=0),
            d("characters: bodies", "capsule", "vs_character_body", material=5, object_mask=3,
              instance_base=FIRST_PEDESTRIAN, indirect=20, stencil=0x15),
            d("characters: faces", "capsule", "vs_character_head", material=5, object_mask=3,
              instance_base=FIRST_PEDESTRIAN, indirect=20, stencil=0x35),
        ]
    if with_foliage:
        # The riverside park either side of the main street, which runs on to the water.
        for side, x in (("west", -62), ("east", 47)):
            draws.append(d(f"foliage {side}", "trees", "vs_foliage", material=6, object_mask=1,
                           offset=[x, 0, 158, 0], scale=[0.9, 1, 0.22, 0], stencil=0xA0))
    if not shadow and with_instances:
        # Zebra crossings where the view street meets the cross streets.
        for k, z in enumerate([-58, -6, 46, 98]):
            draws.append(d(f"decals: crossing {k}", "decal_quad", "vs_static", material=7,
                           offset=[-6, 0, z, 0], scale=[11, 1, 7, 0]))
        draws += [
            d("fur mask", "capsule", "vs_character_hair", material=8, object_mask=3,
              instance_base=FIRST_PEDESTRIAN, indirect=20, stencil=0x95),
            d("fur", "capsule", "vs_character_fur", material=8, object_mask=3,
              instance_base=FIRST_PEDESTRIAN, indirect=20, stencil=0x95),
        ]
    return draws


def with_view(draws, **params):
    out = []
    for dr in draws:
        dr = json.loads(json.dumps(dr))
        # Depth-only views have no stencil.
        dr.pop("stencil_reference", None)
        dr.setdefault("params", {}).update(params)
        out.append(dr)
    return out


# What each scene.wgsl entry point reads, so a pass binds (and the analysis sees) exactly the
# resources its draws use.
SCENE_GLOBALS = {
    "vs_static": [], "vs_terrain": [], "vs_building": [], "vs_omni_building": ["lights"], "vs_foliage": ["voxel_normals", "linear_clamp"],
    "vs_water": ["ocean_height", "linear_clamp"],
    "vs_instanced": ["instance_data"], "vs_character_body": ["instance_data"],
    "vs_character_head": ["instance_data"], "vs_character_hair": ["instance_data"],
    "vs_character_fur": ["instance_data"],
    "vs_omni_static": ["lights"], "vs_omni_terrain": ["lights"],
    "vs_omni_instanced": ["instance_data", "lights"], "vs_omni_character": ["instance_data", "lights"],
    "fs_depth": [], "fs_omni_depth": ["lights"], "fs_env": [],
    "fs_gbuffer": ["billboard_atlas", "blue_noise", "linear_clamp", "terrain_layers"],
}
SCENE_BINDING = {
    "voxel_normals": sampled("voxel_normals"),
    "linear_clamp": sampler("linear_clamp"),
    "ocean_height": sampled("ocean_height"),
    "instance_data": storage("instance_data", "storage_read"),
    "lights": storage("lights", "storage_read"),
    "billboard_atlas": sampled("billboard_atlas"),
    "terrain_layers": sampled("terrain_layers"),
    "blue_noise": sampled("blue_noise"),
}


def scene_bindings(pass_):
    entries = {pass_["shader"]["vertex"], pass_["shader"].get("fragment")}
    entries |= {dr.get("vertex") for dr in pass_["draws"]}
    names = sorted({g for e in entries if e for g in SCENE_GLOBALS[e]})
    pass_["bindings"] = {n: SCENE_BINDING[n] for n in names}
    return pass_

DEPTH_ATTACH = {"resource": "depth", "format": "D32_FLOAT_S8X24_UINT"}


def depth_only(name, markers, resource, fmt, draws, params, layer=0, clear=1.0, bias=(0, 0.0), **rest):
    state = {"depth_compare": "less_equal", "depth_write": True, "cull": "none"}
    if bias[0]:
        state["depth_bias"] = bias[0]
        state["depth_bias_slope"] = bias[1]
    return scene_bindings(raster(
        name, markers, "scene.wgsl", "vs_static", "fs_depth", [],
        depth_stencil={"resource": resource, "format": fmt, "layer": layer,
                       "depth_load": "clear", "depth_clear": clear},
        state=state,
        params={**SCENE_DEFAULTS, **params},
        draws=draws,
        **rest,
    ))


# ---------------------------------------------------------------------------------------------
# Passes 1-36


def passes(day=True):
    out = []
    pre = ["Pre-geometry"]
    if day:
        # 1: three glyph sheets copied out of the mega texture (byte-address atlas).
        out.append({
            "name": "billboard_copies", "queue": "copy", "kind": "copy", "markers": ["Frame", *pre],
            "copies": [
                {"src": {"resource": "mega_texture", "offset": 0, "bytes_per_row": 512},
                 "dst": {"resource": "billboard_src_0"}, "extent": [480, 272, 1]},
                {"src": {"resource": "mega_texture", "offset": 512 * 272, "bytes_per_row": 256},
                 "dst": {"resource": "billboard_src_1"}, "extent": [240, 136, 1]},
                {"src": {"resource": "mega_texture", "offset": 512 * 272 + 256 * 136, "bytes_per_row": 256},
                 "dst": {"resource": "billboard_src_2"}, "extent": [240, 136, 1]},
            ],
            "signal": ["billboard_sources"],
        })
    # 2: the screens, then their mip chain.
    out.append(raster("billboards", pre, "pregeometry.wgsl", "vs_fullscreen", "fs_billboards",
                      [color("billboard_atlas")],
                      bindings={
                          "billboard_src_0": sampled("billboard_src_0"),
                          "billboard_src_1": sampled("billboard_src_1"),
                          "billboard_src_2": sampled("billboard_src_2"),
                          "linear_wrap": sampler("linear_wrap"),
                      } if day else {},
                      draws=[fullscreen("screens")],
                      **({"wait": ["billboard_sources"]} if day else {})))
    out.append({"name": "billboards_mips", "queue": "graphics", "kind": "generate_mips",
                "markers": ["Frame", *pre, "billboards"], "generate_mips": {"resource": "billboard_atlas"}})
    # 3: GUI elements drawn, then copied into the mega texture on the copy queue.
    out.append(raster("gui_to_mega", pre, "pregeometry.wgsl", "vs_fullscreen", "fs_gui",
                      [color("gui_elements")], draws=[fullscreen("gui elements")], signal=["gui_drawn"]))
    out.append({
        "name": "gui_to_mega_copy", "queue": "copy", "kind": "copy", "markers": ["Frame", *pre, "gui_to_mega"],
        "wait": ["gui_drawn"],
        "copies": [{"src": {"resource": "gui_elements"},
                    "dst": {"resource": "mega_texture", "offset": 8 * 1024 * 1024, "bytes_per_row": 4096}}],
    })
    # 4: top-view depth for sky visibility: the city and the signs from straight above.
    per_block = CITY["buildings_per_block"]
    top = [dict(d(f"block {b}", "buildings", "vs_building", material=0), instances=per_block,
                first_instance=b * per_block)
           for b in range(BUILDINGS // per_block)]
    top += [dr for dr in world_draws(shadow=True, with_instances=False, with_foliage=False)
            if dr["mesh"] != "buildings"]
    out.append(depth_only("sky_visibility_top_view", pre, "top_view_depth", "D16_UNORM",
                          with_view(top, view=5), {"view": 5}))
    # 5: voxel normals, two dispatches.
    out.append(compute("voxel_normals", pre, "geometry_prep.wgsl", "cs_voxel_terrain", [
        groups(2, 2, 64, label="terrain field"),
        groups(16, 16, 16, label="structures", entry="cs_voxel_structures"),
    ], bindings={"voxel_normals": storage("voxel_normals")}, signal=["voxels_ready"]))
    # 6: instance preparation: animate and cull, write args, compact.
    kinds = KIND_COUNTS if day else [512, 680, 0]
    n = 63 if day else 38
    out.append(compute("instance_prep", pre, "geometry_prep.wgsl", "cs_animate", [
        groups(n, label="animate and cull"),
        groups(3, label="indirect arguments", entry="cs_args"),
        groups(n, label="compact", entry="cs_compact"),
    ], bindings={
        "instance_data": storage("instance_data", "storage_read_write"),
        "draw_args": storage("draw_args", "storage_read_write"),
    }, params={"index_counts": [BOX_INDICES, CAPSULE_INDICES, BOX_INDICES, 0],
               "kind_counts": [*kinds, 0]}, signal=["instances_ready"]))
    # 7: terrain layer maps, two chunks.
    chunk = {"scale": [1, 1, 2, 0]}
    out.append(raster("terrain", pre, "terrain.wgsl", "vs_map", "fs_layers",
                      [color("terrain_layers", layer=0), color("terrain_layers", layer=1),
                       color("terrain_ids")],
                      bindings={"voxel_normals": sampled("voxel_normals"), "linear_clamp": sampler("linear_clamp")},
                      params={"offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]},
                      state={"cull": "none"},
                      draws=[
                          {"label": "terrain chunk west", "mesh": "terrain_chunk",
                           "params": {"offset": [-150, 0, 0, 0], **chunk}},
                          {"label": "terrain chunk east", "mesh": "terrain_chunk",
                           "params": {"offset": [150, 0, 0, 0], **chunk}},
                      ], wait=["voxels_ready"]))
    if day:
        # 8: the dead pass.
        out.append(raster("unknown_color_01", pre, "terrain.wgsl", "vs_lod_ids", "fs_lod_ids",
                          [color("lod_ids")],
                          params={"offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]},
                          state={"cull": "none"},
                          draws=[{"label": "lod ids 0", "mesh": "terrain_chunk"},
                                 {"label": "lod ids 1", "mesh": "terrain_chunk",
                                  "params": {"offset": [0, 0, 150, 0], "scale": [1, 1, 1, 0]}}]))
    # 9: ocean height from the previous frame's wave field.
    out.append(raster("ocean_wave", pre, "ocean.wgsl", "vs_ocean", "fs_ocean", [color("ocean_height", (0.5, 0, 0, 0))],
                      bindings={"ocean_wave_noise": sampled("ocean_wave_noise"),
                                "ocean_mask": sampled("ocean_mask"),
                                "linear_wrap": sampler("linear_wrap"),
                                "linear_clamp": sampler("linear_clamp")},
                      params={"band": 0, "offset": [0, 0, 380, 0], "scale": [1, 1, 1, 0]},
                      state={"cull": "none"},
                      draws=[{"label": "water plates", "mesh": "water"}]))

    geo = ["Geometry"]
    # 10: depth pre-pass.
    prepass_draws = [dr for dr in world_draws() if not dr["label"].startswith(("decals", "fur"))]
    for dr in prepass_draws:
        dr.pop("stencil_reference", None)
    out.append(scene_bindings(raster("depth_prepass", geo, "scene.wgsl", "vs_static", "fs_depth", [],
                      depth_stencil={**DEPTH_ATTACH, "depth_load": "clear", "depth_clear": 1.0,
                                     "stencil_load": "clear"},
                      state={"depth_compare": "less", "depth_write": True, "cull": "none"},
                      params=dict(SCENE_DEFAULTS),
                      draws=prepass_draws, wait=["voxels_ready", "instances_ready"])))
    # 11: base material into the G-buffer.
    out.append(scene_bindings(raster("base_material", geo, "scene.wgsl", "vs_static", "fs_gbuffer",
                      [color("gbuffer_albedo"), color("gbuffer_normal"), color("gbuffer_material"),
                       color("motion_vectors")],
                      depth_stencil={**DEPTH_ATTACH, "depth_load": "load", "stencil_load": "clear"},
                      state={"depth_compare": "less_equal", "depth_write": True, "cull": "none",
                             "stencil": {"write_mask": 255, "front": {"compare": "always", "pass": "replace"},
                                         "back": {"compare": "always", "pass": "replace"}}},
                      params=dict(SCENE_DEFAULTS),
                      draws=world_draws())))
    # 12: depth/stencil conversion.
    depth_view = sampled("depth", format="R32_FLOAT_X8X24_TYPELESS")
    stencil_view = sampled("depth", format="X32_TYPELESS_G8X24_UINT")
    out.append(raster("ds_convert_depth", [*geo, "ds_convert"], "gbuffer_post.wgsl", "vs_fullscreen", "fs_depth_r32",
                      [color("depth_r32")], bindings={"depth": depth_view}, draws=[fullscreen("R32_FLOAT")]))
    out.append(raster("ds_convert_depth_half", [*geo, "ds_convert"], "gbuffer_post.wgsl", "vs_fullscreen",
                      "fs_depth_half", [color("depth_half")], bindings={"depth": depth_view},
                      draws=[fullscreen("R16_FLOAT half")]))
    out.append(raster("ds_convert_stencil_half", [*geo, "ds_convert"], "gbuffer_post.wgsl", "vs_fullscreen",
                      "fs_stencil_half", [color("stencil_half")], bindings={"stencil": stencil_view},
                      draws=[fullscreen("R8_UINT half")]))
    # 13: motion stencil.
    out.append(raster("motion_stencil", geo, "gbuffer_post.wgsl", "vs_fullscreen", "fs_motion_stencil",
                      [color("motion_stencil")],
                      bindings={"motion_vectors": sampled("motion_vectors"), "stencil": stencil_view},
                      draws=[fullscreen("dilated motion stencil")]))

    masks = ["Masks and LUTs"]
    # 14: reflection mask.
    out.append(raster("reflection_mask", masks, "gbuffer_post.wgsl", "vs_fullscreen", "fs_reflection_mask",
                      [color("reflection_mask")],
                      bindings={"depth_r32": sampled("depth_r32"), "gbuffer_normal": sampled("gbuffer_normal"),
                                "gbuffer_material": sampled("gbuffer_material")},
                      draws=[fullscreen("reflectivity")], signal=["reflection_done"]))
    # 15: noised normal.
    out.append(compute("noised_normal", masks, "gbuffer_post.wgsl", "cs_noised_normal",
                       [groups(240, 135)],
                       bindings={"gbuffer_normal": sampled("gbuffer_normal"), "blue_noise": sampled("blue_noise"),
                                 "noised_normal": storage("noised_normal")},
                       wait=["reflection_done"], signal=["noised_ready"]))
    # 16: sky masks: coarse, its mips rebuilt one from the other, then the accurate mask.
    out.append(raster("sky_mask", masks, "gbuffer_post.wgsl", "vs_fullscreen", "fs_sky_coarse",
                      [color("sky_mask_coarse", mip=0)], bindings={"depth_half": sampled("depth_half")},
                      draws=[fullscreen("coarse sky")]))
    for m in (1, 2, 3):
        out.append(raster(f"sky_mask_mip_{m}", [*masks, "sky_mask"], "gbuffer_post.wgsl", "vs_fullscreen",
                          "fs_sky_mip", [color("sky_mask_coarse", mip=m)],
                          bindings={"coarse_previous": sampled("sky_mask_coarse", mips={"base": m - 1, "count": 1})},
                          draws=[fullscreen(f"mip {m}")]))
    out.append(raster("sky_mask_accurate", [*masks, "sky_mask"], "gbuffer_post.wgsl", "vs_fullscreen",
                      "fs_sky_accurate", [color("sky_mask")],
                      bindings={"sky_mask_coarse": sampled("sky_mask_coarse"), "depth": depth_view},
                      draws=[fullscreen("accurate sky")], signal=["masks_done"]))
    # 17: HBAO.
    out.append(compute("hbao", masks, "hbao.wgsl", "cs_hbao", [groups(120, 68)],
                       bindings={"depth_half": sampled("depth_half"), "noised_normal": sampled("noised_normal"),
                                 "blue_noise": sampled("blue_noise"), "ao": storage("ao")},
                       wait=["masks_done"], signal=["ao_done"]))
    # 18: colour grading LUT.
    out.append(compute("color_grading_lut", masks, "luts.wgsl", "cs_grading_lut", [groups(8, 8, 8)],
                       bindings={"grading_lut": storage("grading_lut")}))
    # 19: ocean wave noise, 22 bands accumulated in place.
    out.append(compute("ocean_wave_noise", masks, "ocean.wgsl", "cs_wave_band",
                       [groups(32, 32, 1, label=f"band {b}", params={"band": b}) for b in range(22)],
                       bindings={"wave_field": storage("ocean_wave_noise", "storage_read_write")},
                       params={"band": 0, "offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]}))

    lights = ["Lights and shadows"]
    # 20: the never-read CSM proxy.
    proxy = [d("block proxies", "block_proxies", "vs_static", material=0, view=7)]
    out.append(depth_only("csm_proxy", lights, "csm_proxy", "D16_UNORM", proxy, {"view": 7}))
    # 21: four cascades, one pass each.
    for c in range(4):
        out.append(depth_only(f"csm_cascade_{c}", [*lights, "csm_cascade_0..3"], "csm", "D16_UNORM",
                              with_view(world_draws(shadow=True), view=1 + c), {"view": 1 + c},
                              layer=c, bias=(2, 1.5),
                              **({"signal": ["cascades_done"]} if c == 3 else {})))
    # 22: omni shadows: paraboloid depth of each shadowed light, then its variance map.
    for i in range(SHADOWED_LIGHTS):
        omni_entry = {"vs_building": "vs_omni_building", "vs_static": "vs_omni_static", "vs_instanced": "vs_omni_instanced",
                      "vs_character_body": "vs_omni_character", "vs_terrain": "vs_omni_terrain"}
        draws = [dict(dr, vertex=omni_entry[dr["vertex"]])
                 for dr in with_view(world_draws(shadow=True, with_foliage=False),
                                     view=6, light=i)
                 if dr["vertex"] in omni_entry]
        p = depth_only(f"omni_shadows_{i}", [*lights, "omni_shadows"], "omni_depth", "D32_FLOAT",
                       draws, {"view": 6, "light": i})
        p["shader"]["vertex"] = "vs_omni_static"
        p["shader"]["fragment"] = "fs_omni_depth"
        out.append(scene_bindings(p))
        out.append(raster(f"omni_shadows_vsm_{i}", [*lights, "omni_shadows"], "shadows.wgsl", "vs_fullscreen",
                          "fs_omni_vsm", [color("omni_vsm", layer=i)],
                          bindings={"omni_depth": sampled("omni_depth", format="R32_FLOAT")},
                          draws=[fullscreen(f"moments of light {i}")],
                          **({"signal": ["omni_done"]} if i == SHADOWED_LIGHTS - 1 else {})))
    # 23: cloud distribution.
    out.append(compute("cloud_distribution", lights, "luts.wgsl", "cs_clouds", [groups(64, 64)],
                       bindings={"cloud_distribution": storage("cloud_distribution")}))
    # 24: sky cube (7 prefiltered mips) and stereographic projection.
    sky_bindings = {f"sky_mip_{m}": storage("sky_cube", mips={"base": m, "count": 1}, dimension="texture_2d_array")
                    for m in range(7)}
    sky_bindings.update({"cloud_distribution": sampled("cloud_distribution"), "linear_wrap": sampler("linear_wrap"),
                         "sky_projected": storage("sky_projected")})
    out.append(compute("sky_cubemap", lights, "sky.wgsl", "cs_sky_cube",
                       [groups(max(64 >> m, 8) // 8, max(64 >> m, 8) // 8, 6, label=f"mip {m}",
                               params={"mip": m, "mip_count": 7}) for m in range(7)]
                       + [groups(32, 32, 1, label="stereographic", entry="cs_sky_projected")],
                       bindings=sky_bindings, params={"mip": 0, "mip_count": 7}))
    # 25: coat mask.
    out.append(raster("coat_mask", lights, "gbuffer_post.wgsl", "vs_fullscreen", "fs_coat_mask",
                      [color("coat_mask")],
                      bindings={"gbuffer_albedo": sampled("gbuffer_albedo"),
                                "gbuffer_material": sampled("gbuffer_material")},
                      draws=[fullscreen("clear coat")]))
    # 26: clustered light index.
    out.append(compute("clustered_light_index", lights, "lights.wgsl", "cs_cluster", [groups(60, 34)],
                       bindings={"lights": storage("lights", "storage_read"),
                                 "light_list": storage("light_list"),
                                 "cluster_index_out": storage("cluster_light_index"),
                                 "depth_half": sampled("depth_half")},
                       wait=["omni_done"],
                       params={"light_count": LIGHT_COUNT if day else 1024, "shadowed_lights": SHADOWED_LIGHTS}))
    # 27: sun shadow from the cascades.
    out.append(raster("sun_shadow", lights, "shadows.wgsl", "vs_fullscreen", "fs_sun_shadow",
                      [color("sun_shadow", (1, 0, 0, 0))],
                      bindings={"depth_r32": sampled("depth_r32"), "noised_normal": sampled("noised_normal"),
                                "csm": sampled("csm", format="R16_UNORM"),
                                "shadow_compare": sampler("shadow_compare")},
                      draws=[fullscreen("cascaded PCF")], wait=["ao_done"], signal=["sun_shadow_ready"]))
    # 28: local light masks, two resolutions.
    out.append(compute("local_light_mask", lights, "lights.wgsl", "cs_light_mask_fine",
                       [groups(15, 9, label="120x68"), groups(8, 5, label="60x34", entry="cs_light_mask_coarse")],
                       bindings={"cluster_light_index": sampled("cluster_light_index"),
                                 "depth_half": sampled("depth_half"),
                                 "light_mask_fine": storage("local_light_mask", mips={"base": 0, "count": 1}),
                                 "light_mask_coarse": storage("local_light_mask", mips={"base": 1, "count": 1})}))
    # 29: light buffer update.
    out.append(compute("light_buffer_update", lights, "lights.wgsl", "cs_update_lights", [groups(16)],
                       bindings={"lights_rw": storage("lights", "storage_read_write")},
                       params={"light_count": LIGHT_COUNT if day else 1024, "shadowed_lights": SHADOWED_LIGHTS}))
    # 30: environment capture: six faces from the street probe, then the dual-paraboloid array.
    probe = [-6, 6, 40, 0]
    for f in range(6):
        draws = with_view(world_draws(shadow=True, with_instances=False, with_foliage=False), view=8, face=f,
                          probe=probe)
        out.append(scene_bindings(raster(f"env_capture_face_{f}", [*lights, "env_capture"], "scene.wgsl", "vs_static", "fs_env",
                          [color("env_cube", layer=f)],
                          depth_stencil={"resource": "env_depth", "format": "D32_FLOAT",
                                         "depth_load": "clear", "depth_clear": 1.0},
                          state={"depth_compare": "less", "depth_write": True, "cull": "none"},
                          params={**SCENE_DEFAULTS, "view": 8, "face": f, "probe": probe},
                          draws=draws, **({"signal": ["env_captured"]} if f == 5 else {}))))
    dp = {f"dp_mip_{m}": storage("env_dual_paraboloid", mips={"base": m, "count": 1}) for m in range(6)}
    dp.update({"env_cube": sampled("env_cube"), "sky_cube": sampled("sky_cube"),
               "linear_clamp": sampler("linear_clamp")})
    out.append(compute("env_capture_paraboloid", [*lights, "env_capture"], "env.wgsl", "cs_dual_paraboloid",
                       [groups(max(64 >> m, 1), max(32 >> m, 1), 32, label=f"mip {m}",
                               params={"mip": m, "mip_count": 6}) for m in range(6)],
                       bindings=dp, params={"mip": 0, "mip_count": 6}, wait=["env_captured"]))
    # 31: GI probe indices.
    out.append(compute("gi_probe_indices", lights, "gi.wgsl", "cs_gi_probe_indices", [groups(16, 16, 16)],
                       bindings={"voxel_normals": sampled("voxel_normals"),
                                 "gi_probe_indices": storage("gi_probe_indices")}))
    # 32: landscape maps.
    out.append(raster("landscape_maps", lights, "terrain.wgsl", "vs_fullscreen", "fs_landscape",
                      [color("landscape_normal"), color("landscape_heat")],
                      bindings={"terrain_layers": sampled("terrain_layers"), "linear_clamp": sampler("linear_clamp")},
                      draws=[fullscreen("normal and heat")]))
    # 33: local volumetric fog.
    out.append(compute("volumetric_fog_local", lights, "fog.wgsl", "cs_fog_integrate",
                       [groups(30, 17, 1, label="scatter and integrate")],
                       bindings={"fog_mip_0": storage("fog_volume", mips={"base": 0, "count": 1}),
                                 "csm": sampled("csm", format="R16_UNORM"),
                                 "shadow_compare": sampler("shadow_compare"),
                                 "cluster_light_index": sampled("cluster_light_index"),
                                 "light_list": storage("light_list", "storage_read"),
                                 "lights": storage("lights", "storage_read")},
                       params={"density": 0.012 if day else 0.03, "height_falloff": 0.08,
                               "anisotropy": 0.6},
                       wait=["cascades_done"]))
    out.append(compute("volumetric_fog_local_mip1", [*lights, "volumetric_fog_local"], "fog.wgsl",
                       "cs_fog_downsample", [groups(30, 17, 16, label="mip 1")],
                       bindings={"fog_source": sampled("fog_volume", mips={"base": 0, "count": 1}),
                                 "fog_mip_1": storage("fog_volume", mips={"base": 1, "count": 1})}))
    # 34: head mask.
    out.append(raster("head_mask", lights, "gbuffer_post.wgsl", "vs_fullscreen", "fs_head_mask",
                      [color("head_mask")], bindings={"stencil": stencil_view}, draws=[fullscreen("faces")]))
    # 35: tiled direct lighting, indirect dispatch.
    out.append(compute("tiled_direct_lighting", lights, "lighting.wgsl", "cs_tiled_lighting",
                       [{"label": "16x16 tiles", "indirect": {"buffer": "draw_args", "offset": 64}}],
                       bindings={
                           "gbuffer_albedo": sampled("gbuffer_albedo"),
                           "gbuffer_normal": sampled("gbuffer_normal"),
                           "gbuffer_material": sampled("gbuffer_material"),
                           "depth_r32": sampled("depth_r32"),
                           "sun_shadow": sampled("sun_shadow"),
                           "ao": sampled("ao"),
                           "cluster_light_index": sampled("cluster_light_index"),
                           "light_list": storage("light_list", "storage_read"),
                           "lights": storage("lights", "storage_read"),
                           "omni_vsm": sampled("omni_vsm"),
                           "sky_cube": sampled("sky_cube"),
                           "top_view_depth": sampled("top_view_depth"),
                           "coat_mask": sampled("coat_mask"),
                           "local_light_mask": sampled("local_light_mask"),
                           "linear_clamp": sampler("linear_clamp"),
                           "lit_diffuse": storage("lit_diffuse"),
                           "lit_specular": storage("lit_specular"),
                       },
                       params={"shadowed_lights": SHADOWED_LIGHTS,
                               "emissive_scale": 6.0 if day else 12.0, "ambient_scale": 1.0},
                       wait=["sun_shadow_ready"], signal=["direct_lit"]))
    # 36: the sky, where the sky mask says.
    out.append(raster("sky", lights, "sky.wgsl", "vs_fullscreen", "fs_sky",
                      [{"resource": "lit_diffuse", "load": "load"}],
                      bindings={"sky_mask": sampled("sky_mask"), "sky_mask_coarse": sampled("sky_mask_coarse"),
                                "sky_cube": sampled("sky_cube"), "sky_projection": sampled("sky_projected"),
                                "linear_clamp": sampler("linear_clamp")},
                      draws=[fullscreen("sky pixels")], wait=["direct_lit"]))
    return out


# Resources the passes above produce for the post chain (passes 37-57 of the manifest) are
# frame outputs until those passes exist, so culling keeps the work that feeds them.
POST_CHAIN_INPUTS = [
    "gui_elements", "stencil_half", "motion_stencil", "reflection_mask", "grading_lut",
    "env_dual_paraboloid", "gi_probe_indices", "fog_volume", "head_mask", "lit_diffuse",
    "lit_specular", "landscape_normal", "landscape_heat", "ocean_height", "cloud_distribution",
    "motion_vectors", "noised_normal", "depth_half", "depth_r32", "ao",
]


def update_resources(resources, day=True):
    by_name = {r["name"]: r for r in resources}
    for name in POST_CHAIN_INPUTS:
        by_name[name]["output"] = True
    if "env_depth" not in by_name:
        resources.append({"name": "env_depth", "kind": "texture_2d", "format": "D32_FLOAT",
                          "width": 128, "height": 128, "flags": ["ALLOW_DEPTH_STENCIL"]})
    # The GUI copied into the mega texture this frame is what next frame's billboard copies read.
    by_name["mega_texture"]["history"] = True
    # Cleared before use, as a D3D12 frame clears its UAVs.
    by_name["draw_args"]["initial"] = {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
    by_name["instance_data"]["initial"] = {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
    # Calm water for the first frame, before any wave field exists.
    by_name["ocean_wave_noise"]["initial"] = {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
    lights = by_name["lights"]
    # Neon and shop lights over the district (the city spans about 200 x 300 m).
    lights["initial"]["generator"]["params"].update(
        {"count": LIGHT_COUNT if day else 1024, "area": 240, "intensity": 300})
    return resources


def main(path):
    with open(path) as f:
        capture = json.load(f)
    day = "day" in capture["name"]
    capture["resources"] = update_resources(capture["resources"], day)
    capture["fences"] = [{"name": n} for n in FENCES if day or n != "billboard_sources"]
    capture["meshes"] = MESHES
    capture["frame"].setdefault("shadow_cascades", {"resolution": 4096, "split_lambda": 0.8, "max_distance": 220})
    capture["passes"] = passes(day)
    # Down the street that runs along z at x = -6, towards the water.
    capture["camera"].update({"position": [-6.0, 1.8, -40.0], "target": [-6.0, 6.0, 160.0]})
    with open(path, "w") as f:
        json.dump(capture, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "captures/night_city/main_street_day.json")
