//! Passes 1-36 of the frame (37-57 in `composition` and `post`), in the order NIGHT_CITY_PASSES.md numbers them, with the names,
//! queues, markers, fences and per-pass parameters the shaders read. `day` selects the main
//! street by day; the night variant drops the billboard copies and the dead pass and lights
//! the district with more lights and denser fog.

use serde_json::{Value, json};

use super::helpers::{
    GBUFFER, color, compute, cover, depth_view, fullscreen, groups, markers, object, raster,
    sampled, sampled_each, sampler, stencil_view, storage, storage_mip, with,
};
use super::scene::{
    BOX_INDICES, BUILDINGS, BUILDINGS_PER_BLOCK, CAPSULE_INDICES, Depth, DepthOnly, KIND_COUNTS,
    LIGHTS, SHADOWED_LIGHTS, SceneError, World, d, depth_attach, depth_only, light_count,
    opaque_depth_only, opaque_gbuffer, scene_bindings, scene_defaults, with_view, world_draws,
};

const PRE: &[&str] = &["Pre-geometry"];
const GEO: &[&str] = &["Geometry"];
const MASKS: &[&str] = &["Masks and LUTs"];

/// Every pass, or what `scene.wgsl` lacks that a pass asks of it.
pub(super) fn passes(day: bool) -> Result<Vec<Value>, SceneError> {
    let mut out = Vec::new();
    pre_geometry(&mut out, day)?;
    geometry(&mut out)?;
    masks(&mut out);
    lights_and_shadows(&mut out, day)?;
    environment_and_lighting(&mut out, day)?;
    super::composition::passes(&mut out, day);
    super::post::passes(&mut out, day)?;
    Ok(out)
}

/// Passes 1-9: billboards, GUI, top view, voxels, instances, terrain, ocean.
fn pre_geometry(out: &mut Vec<Value>, day: bool) -> Result<(), SceneError> {
    if day {
        // 1: three glyph sheets copied out of the mega texture (byte-address atlas).
        out.push(json!({
            "name": "billboard_copies", "queue": "copy", "kind": "copy", "markers": markers(PRE),
            "copies": [
                {"src": {"resource": "mega_texture", "offset": 0, "bytes_per_row": 512},
                 "dst": {"resource": "billboard_src_0"}, "extent": [480, 272, 1]},
                {"src": {"resource": "mega_texture", "offset": 512 * 272, "bytes_per_row": 256},
                 "dst": {"resource": "billboard_src_1"}, "extent": [240, 136, 1]},
                {"src": {"resource": "mega_texture", "offset": 512 * 272 + 256 * 136, "bytes_per_row": 256},
                 "dst": {"resource": "billboard_src_2"}, "extent": [240, 136, 1]},
            ],
            "signal": ["billboard_sources"],
        }));
    }
    // 2: the screens, then their mip chain.
    let sources = if day {
        json!({
            "bindings": {
                "billboard_src_0": sampled("billboard_src_0"),
                "billboard_src_1": sampled("billboard_src_1"),
                "billboard_src_2": sampled("billboard_src_2"),
                "linear_wrap": sampler("linear_wrap"),
            },
            "wait": ["billboard_sources"],
        })
    } else {
        json!({"bindings": {}})
    };
    out.push(raster(
        "billboards",
        PRE,
        "pregeometry.wgsl",
        (
            "vs_fullscreen",
            Some(if day {
                "fs_billboards"
            } else {
                "fs_billboards_idle"
            }),
        ),
        vec![color("billboard_atlas")],
        with(json!({"draws": [fullscreen("screens")]}), sources),
    ));
    out.push(
        json!({"name": "billboards_mips", "queue": "graphics", "kind": "generate_mips",
        "markers": markers(&["Pre-geometry", "billboards"]),
        "generate_mips": {"resource": "billboard_atlas"}}),
    );
    // 3: GUI elements drawn, then copied into the mega texture on the copy queue.
    out.push(raster(
        "gui_to_mega",
        PRE,
        "pregeometry.wgsl",
        ("vs_fullscreen", Some("fs_gui")),
        vec![color("gui_elements")],
        json!({"draws": [fullscreen("gui elements")], "signal": ["gui_drawn"]}),
    ));
    out.push(json!({
        "name": "gui_to_mega_copy", "queue": "copy", "kind": "copy",
        "markers": markers(&["Pre-geometry", "gui_to_mega"]),
        "wait": ["gui_drawn"],
        "signal": ["gui_copied"],
        "copies": [{"src": {"resource": "gui_elements"},
                    "dst": {"resource": "mega_texture", "offset": 8 * 1024 * 1024, "bytes_per_row": 4096}}],
    }));
    // 4: top-view depth for sky visibility: the city and the signs from straight above.
    let mut top: Vec<Value> = (0..BUILDINGS / BUILDINGS_PER_BLOCK)
        .map(|b| {
            with(d(&format!("block {b}"), "buildings", "vs_building", json!({"material": 0})),
                 json!({"instances": BUILDINGS_PER_BLOCK, "first_instance": b * BUILDINGS_PER_BLOCK}))
        })
        .collect();
    let streets = World {
        instances: false,
        foliage: false,
        ..World::SHADOW
    };
    top.extend(
        world_draws(streets)
            .into_iter()
            .filter(|dr| dr["mesh"] != "buildings"),
    );
    out.push(depth_only(
        DepthOnly {
            name: "sky_visibility_top_view",
            groups: PRE,
            resource: "top_view_depth",
            format: "D16_UNORM",
            layer: 0,
            bias: None,
            cull_back: false,
            depth: Depth::AlphaTest,
        },
        with_view(top, json!({"view": 5})),
        json!({"view": 5}),
        json!({}),
    )?);
    // 5: voxel normals, two dispatches.
    out.push(compute(
        "voxel_normals",
        PRE,
        "geometry_prep.wgsl",
        "cs_voxel_terrain",
        vec![
            with(groups(2, 2, 64), json!({"label": "terrain field"})),
            with(
                groups(16, 16, 16),
                json!({"label": "structures", "entry": "cs_voxel_structures"}),
            ),
        ],
        json!({"bindings": {"voxel_normals": storage("voxel_normals", "storage_write")},
              "signal": ["voxels_ready"]}),
    ));
    // 6: instance preparation: animate and cull, write args, compact.
    // At night fewer cars and people, every sign lit; 38 groups of 32 cover the candidates.
    let kinds = if day { KIND_COUNTS } else { [480, 512, 224] };
    let n = if day { 63 } else { 38 };
    out.push(compute(
        "instance_prep",
        PRE,
        "geometry_prep.wgsl",
        "cs_animate",
        vec![
            with(groups(n, 1, 1), json!({"label": "animate and cull"})),
            with(
                groups(3, 1, 1),
                json!({"label": "indirect arguments", "entry": "cs_args"}),
            ),
            with(
                groups(n, 1, 1),
                json!({"label": "compact", "entry": "cs_compact"}),
            ),
        ],
        json!({
            "bindings": {
                "instance_data": storage("instance_data", "storage_read_write"),
                "draw_args": storage("draw_args", "storage_read_write"),
            },
            "params": {"index_counts": [BOX_INDICES, CAPSULE_INDICES, BOX_INDICES, 0],
                       "kind_counts": [kinds[0], kinds[1], kinds[2], 0],
                       "kind_bases": [0, KIND_COUNTS[0], KIND_COUNTS[0] + KIND_COUNTS[1], 0]},
            "signal": ["instances_ready"],
        }),
    ));
    terrain_and_ocean(out, day);
    Ok(())
}

/// Passes 7-9: terrain layer maps, the dead pass (by day), the ocean height.
fn terrain_and_ocean(out: &mut Vec<Value>, day: bool) {
    // 7: terrain layer maps, two chunks.
    let chunk = |label: &str, x: i32| {
        json!({"label": format!("{label} (LOD 4x4)"), "mesh": "terrain_chunk_lod",
               "params": {"offset": [x, 0, 0, 0], "scale": [1, 1, 2, 0]}})
    };
    out.push(raster("terrain", PRE, "terrain.wgsl", ("vs_map", Some("fs_layers")),
        vec![with(color("terrain_layers"), json!({"layer": 0})),
             with(color("terrain_layers"), json!({"layer": 1})),
             color("terrain_ids")],
        json!({
            "bindings": {"voxel_normals": sampled("voxel_normals"), "linear_clamp": sampler("linear_clamp")},
            "params": {"offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]},
            "state": {"cull": "none"},
            "draws": [chunk("terrain chunk west", -150), chunk("terrain chunk east", 150)],
            "wait": ["voxels_ready"],
        })));
    if day {
        // 8: the dead pass.
        out.push(raster(
            "unknown_color_01",
            PRE,
            "terrain.wgsl",
            ("vs_lod_ids", Some("fs_lod_ids")),
            vec![color("lod_ids")],
            json!({
                "params": {"offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]},
                "state": {"cull": "none"},
                "draws": [{"label": "lod ids 0", "mesh": "terrain_chunk"},
                          {"label": "lod ids 1", "mesh": "terrain_chunk",
                           "params": {"offset": [0, 0, 150, 0], "scale": [1, 1, 1, 0]}}],
            }),
        ));
    }
    // 9: ocean height from the previous frame's wave field.
    out.push(raster(
        "ocean_wave",
        PRE,
        "ocean.wgsl",
        ("vs_ocean", Some("fs_ocean")),
        vec![with(
            color("ocean_height"),
            json!({"clear": [0.5, 0, 0, 0]}),
        )],
        json!({
            "bindings": {"ocean_wave_noise": sampled("ocean_wave_noise"),
                         "ocean_mask": sampled("ocean_mask"),
                         "linear_wrap": sampler("linear_wrap")},
            "params": {"band": 0, "offset": [0, 0, 380, 0], "scale": [1, 1, 1, 0]},
            "state": {"cull": "none"},
            "draws": [{"label": "water plates (LOD 4x4)", "mesh": "water_lod"}],
        }),
    ));
}

/// Passes 10-13: depth pre-pass, G-buffer, depth/stencil conversion, motion stencil.
fn geometry(out: &mut Vec<Value>) -> Result<(), SceneError> {
    // 10: depth pre-pass.
    let prepass_draws: Vec<Value> = world_draws(World::ALL)
        .into_iter()
        .filter(|dr| {
            let label = dr["label"].as_str().unwrap_or_default();
            !label.starts_with("decals") && !label.starts_with("fur")
        })
        .map(|mut dr| {
            if let Some(o) = dr.as_object_mut() {
                o.remove("stencil_reference");
            }
            dr
        })
        .collect();
    let prepass_draws = opaque_depth_only(prepass_draws);
    out.push(scene_bindings(raster(
        "depth_prepass",
        GEO,
        "scene.wgsl",
        ("vs_static", Some("fs_depth")),
        vec![],
        json!({
            "depth_stencil": depth_attach(json!({"depth_load": "clear", "depth_clear": 1.0,
                                                 "stencil_load": "clear"})),
            "state": {"depth_compare": "less", "depth_write": true, "cull": "none"},
            "params": scene_defaults(),
            "draws": prepass_draws,
            "wait": ["voxels_ready", "instances_ready"],
        }),
    ))?);
    // 11: base material into the G-buffer.
    let replace = json!({"compare": "always", "pass": "replace"});
    out.push(scene_bindings(raster(
        "base_material",
        GEO,
        "scene.wgsl",
        ("vs_static", Some("fs_gbuffer")),
        vec![
            color("gbuffer_albedo"),
            color("gbuffer_normal"),
            color("gbuffer_material"),
            color("motion_vectors"),
        ],
        json!({
            "depth_stencil": depth_attach(json!({"depth_load": "load", "stencil_load": "clear"})),
            "state": {"depth_compare": "less_equal", "depth_write": true, "cull": "none",
                      "stencil": {"write_mask": 255, "front": replace, "back": replace}},
            "params": scene_defaults(),
            "draws": opaque_gbuffer(world_draws(World::ALL)),
        }),
    ))?);
    // 12: depth/stencil conversion.
    let convert = &["Geometry", "ds_convert"];
    let post = |name: &str,
                groups: &[&str],
                fragment: &str,
                target: &str,
                bindings: Value,
                label: &str| {
        raster(
            name,
            groups,
            "gbuffer_post.wgsl",
            ("vs_fullscreen", Some(fragment)),
            vec![color(target)],
            json!({"bindings": bindings, "draws": [fullscreen(label)]}),
        )
    };
    out.push(post(
        "ds_convert_depth",
        convert,
        "fs_depth_r32",
        "depth_r32",
        json!({"depth": depth_view()}),
        "R32_FLOAT",
    ));
    out.push(post(
        "ds_convert_depth_half",
        convert,
        "fs_depth_half",
        "depth_half",
        json!({"depth": depth_view()}),
        "R16_FLOAT half",
    ));
    out.push(post(
        "ds_convert_stencil_half",
        convert,
        "fs_stencil_half",
        "stencil_half",
        json!({"stencil": stencil_view()}),
        "R8_UINT half",
    ));
    // 13: motion stencil.
    out.push(post(
        "motion_stencil",
        GEO,
        "fs_motion_stencil",
        "motion_stencil",
        json!({"motion_vectors": sampled("motion_vectors"), "stencil": stencil_view()}),
        "dilated motion stencil",
    ));
    Ok(())
}

/// Passes 14-19: reflection mask, noised normal, sky masks, HBAO, grading LUT, waves.
fn masks(out: &mut Vec<Value>) {
    let post = |name: &str,
                groups: &[&str],
                fragment: &str,
                target: Value,
                bindings: Value,
                label: &str| {
        raster(
            name,
            groups,
            "gbuffer_post.wgsl",
            ("vs_fullscreen", Some(fragment)),
            vec![target],
            json!({"bindings": bindings, "draws": [fullscreen(label)]}),
        )
    };
    // 14: reflection mask.
    out.push(with(
        post(
            "reflection_mask",
            MASKS,
            "fs_reflection_mask",
            color("reflection_mask"),
            json!({"depth_r32": sampled("depth_r32"), "gbuffer_normal": sampled("gbuffer_normal"),
               "gbuffer_material": sampled("gbuffer_material")}),
            "reflectivity",
        ),
        json!({"signal": ["reflection_done"]}),
    ));
    // 15: noised normal.
    out.push(compute("noised_normal", MASKS, "gbuffer_post.wgsl", "cs_noised_normal",
        vec![cover("noised_normal", 0)],
        json!({
            "bindings": {"gbuffer_normal": sampled("gbuffer_normal"), "blue_noise": sampled("blue_noise"),
                         "noised_normal": storage("noised_normal", "storage_write")},
            "wait": ["reflection_done"], "signal": ["noised_ready"],
        })));
    // 16: sky masks: coarse, its mips rebuilt one from the other, then the accurate mask.
    let sky = &["Masks and LUTs", "sky_mask"];
    out.push(post(
        "sky_mask",
        MASKS,
        "fs_sky_coarse",
        with(color("sky_mask_coarse"), json!({"mip": 0})),
        json!({"depth_half": sampled("depth_half")}),
        "coarse sky",
    ));
    for m in 1..=3u32 {
        let previous = with(
            sampled("sky_mask_coarse"),
            json!({"mips": {"base": m - 1, "count": 1}}),
        );
        out.push(post(
            &format!("sky_mask_mip_{m}"),
            sky,
            "fs_sky_mip",
            with(color("sky_mask_coarse"), json!({"mip": m})),
            json!({"coarse_previous": previous}),
            &format!("mip {m}"),
        ));
    }
    out.push(with(
        post(
            "sky_mask_accurate",
            sky,
            "fs_sky_accurate",
            color("sky_mask"),
            json!({"sky_mask_coarse": sampled("sky_mask_coarse"), "depth": depth_view()}),
            "accurate sky",
        ),
        json!({"signal": ["masks_done"]}),
    ));
    // 17: HBAO.
    out.push(compute("hbao", MASKS, "hbao.wgsl", "cs_hbao", vec![cover("ao", 0)], json!({
        "bindings": {"depth_half": sampled("depth_half"), "noised_normal": sampled("noised_normal"),
                     "blue_noise": sampled("blue_noise"), "ao": storage("ao", "storage_write")},
        "wait": ["masks_done"], "signal": ["ao_done"],
    })));
    // 18: colour grading LUT.
    out.push(compute(
        "color_grading_lut",
        MASKS,
        "luts.wgsl",
        "cs_grading_lut",
        vec![groups(8, 8, 8)],
        json!({"bindings": {"grading_lut": storage("grading_lut", "storage_write")}}),
    ));
    // 19: ocean wave noise, 22 bands accumulated in place.
    let bands = (0..22)
        .map(|b| {
            with(
                groups(32, 32, 1),
                json!({"label": format!("band {b}"), "params": {"band": b}}),
            )
        })
        .collect();
    out.push(compute(
        "ocean_wave_noise",
        MASKS,
        "ocean.wgsl",
        "cs_wave_band",
        bands,
        json!({
            "bindings": {"wave_field": storage("ocean_wave_noise", "storage_read_write")},
            "params": {"band": 0, "offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0]},
        }),
    ));
}

/// Passes 20-27: CSM proxy and cascades, omni shadows, clouds, sky, coat mask, clusters, sun.
fn lights_and_shadows(out: &mut Vec<Value>, day: bool) -> Result<(), SceneError> {
    // 20: the never-read CSM proxy.
    let proxy = vec![d(
        "block proxies",
        "block_proxies",
        "vs_static",
        json!({"material": 0, "view": 7}),
    )];
    out.push(depth_only(
        DepthOnly {
            name: "csm_proxy",
            groups: LIGHTS,
            resource: "csm_proxy",
            format: "D16_UNORM",
            layer: 0,
            bias: None,
            cull_back: false,
            depth: Depth::AlphaTest,
        },
        proxy,
        json!({"view": 7}),
        json!({}),
    )?);
    // 21: four cascades, one pass each.
    for c in 0..4u32 {
        let rest = if c == 3 {
            json!({"signal": ["cascades_done"]})
        } else {
            json!({})
        };
        out.push(depth_only(
            DepthOnly {
                name: &format!("csm_cascade_{c}"),
                groups: &["Lights and shadows", "csm_cascade_0..3"],
                resource: "csm",
                format: "D16_UNORM",
                layer: c,
                bias: Some((2, 1.5)),
                cull_back: true,
                depth: Depth::AlphaTest,
            },
            with_view(world_draws(World::SHADOW), json!({"view": 1 + c})),
            json!({"view": 1 + c}),
            rest,
        )?);
    }
    omni_shadows(out)?;
    // 23: cloud distribution.
    out.push(compute(
        "cloud_distribution",
        LIGHTS,
        "luts.wgsl",
        "cs_clouds",
        vec![groups(64, 64, 1)],
        json!({"bindings": {"cloud_distribution": storage("cloud_distribution", "storage_write")}}),
    ));
    // 24: sky cube (7 prefiltered mips) and stereographic projection.
    let mut sky_bindings: Vec<(String, Value)> = (0..7)
        .map(|m| {
            (
                format!("sky_mip_{m}"),
                with(
                    storage_mip("sky_cube", m),
                    json!({"dimension": "texture_2d_array"}),
                ),
            )
        })
        .collect();
    sky_bindings.extend([
        (
            "cloud_distribution".to_owned(),
            sampled("cloud_distribution"),
        ),
        ("linear_wrap".to_owned(), sampler("linear_wrap")),
        (
            "sky_projected".to_owned(),
            storage("sky_projected", "storage_write"),
        ),
    ]);
    let mut sky_dispatches: Vec<Value> = (0..7u32)
        .map(|m| {
            let g = (64u32 >> m).max(8) / 8;
            with(
                groups(g, g, 6),
                json!({"label": format!("mip {m}"), "params": {"mip": m, "mip_count": 7}}),
            )
        })
        .collect();
    sky_dispatches.push(with(
        groups(32, 32, 1),
        json!({"label": "stereographic", "entry": "cs_sky_projected"}),
    ));
    out.push(compute(
        "sky_cubemap",
        LIGHTS,
        "sky.wgsl",
        "cs_sky_cube",
        sky_dispatches,
        json!({"bindings": object(sky_bindings), "params": {"mip": 0, "mip_count": 7}}),
    ));
    // 25: coat mask.
    out.push(raster(
        "coat_mask",
        LIGHTS,
        "gbuffer_post.wgsl",
        ("vs_fullscreen", Some("fs_coat_mask")),
        vec![color("coat_mask")],
        json!({"bindings": {"gbuffer_albedo": sampled("gbuffer_albedo"),
                            "gbuffer_material": sampled("gbuffer_material")},
               "draws": [fullscreen("clear coat")]}),
    ));
    // 26: clustered light index.
    out.push(compute(
        "clustered_light_index",
        LIGHTS,
        "lights.wgsl",
        "cs_cluster",
        vec![groups(60, 34, 1)],
        json!({
            "bindings": {"lights": storage("lights", "storage_read"),
                         "light_list": storage("light_list", "storage_write"),
                         "cluster_index_out": storage("cluster_light_index", "storage_write"),
                         "depth_half": sampled("depth_half")},
            "wait": ["omni_done"],
            "params": {"light_count": light_count(day), "shadowed_lights": SHADOWED_LIGHTS},
        }),
    ));
    // 27: sun shadow from the cascades.
    out.push(raster("sun_shadow", LIGHTS, "shadows.wgsl", ("vs_fullscreen", Some("fs_sun_shadow")),
        vec![with(color("sun_shadow"), json!({"clear": [1, 0, 0, 0]}))],
        json!({
            "bindings": {"depth_r32": sampled("depth_r32"), "noised_normal": sampled("noised_normal"),
                         "csm": with(sampled("csm"), json!({"format": "R16_UNORM"})),
                         "shadow_compare": sampler("shadow_compare")},
            "draws": [fullscreen("cascaded PCF")], "wait": ["ao_done"], "signal": ["sun_shadow_ready"],
        })));
    Ok(())
}

/// Pass 22: the paraboloid depth of each shadowed light, then its variance map.
fn omni_shadows(out: &mut Vec<Value>) -> Result<(), SceneError> {
    let groups_ = &["Lights and shadows", "omni_shadows"];
    let omni_entry = |vertex: &str| match vertex {
        "vs_building" => Some("vs_omni_building"),
        "vs_static" => Some("vs_omni_static"),
        "vs_instanced" => Some("vs_omni_instanced"),
        "vs_character_body" => Some("vs_omni_character"),
        "vs_terrain" => Some("vs_omni_terrain"),
        _ => None,
    };
    let world = World {
        foliage: false,
        ..World::SHADOW
    };
    for i in 0..SHADOWED_LIGHTS {
        let draws: Vec<Value> = with_view(world_draws(world), json!({"view": 6, "light": i}))
            .into_iter()
            .filter_map(|dr| {
                let entry = omni_entry(dr["vertex"].as_str().unwrap_or_default())?;
                Some(with(dr, json!({ "vertex": entry })))
            })
            .collect();
        let p = depth_only(
            DepthOnly {
                name: &format!("omni_shadows_{i}"),
                groups: groups_,
                resource: "omni_depth",
                format: "D32_FLOAT",
                layer: 0,
                bias: None,
                cull_back: true,
                depth: Depth::Distance,
            },
            draws,
            json!({"view": 6, "light": i}),
            json!({}),
        )?;
        out.push(p);
        let rest = if i == SHADOWED_LIGHTS - 1 {
            json!({"signal": ["omni_done"]})
        } else {
            json!({})
        };
        out.push(raster(&format!("omni_shadows_vsm_{i}"), groups_, "shadows.wgsl",
            ("vs_fullscreen", Some("fs_omni_vsm")), vec![with(color("omni_vsm"), json!({"layer": i}))],
            with(json!({
                "bindings": {"omni_depth": with(sampled("omni_depth"), json!({"format": "R32_FLOAT"})),
                             "point_clamp": sampler("point_clamp")},
                "draws": [fullscreen(&format!("moments of light {i}"))],
            }), rest)));
    }
    Ok(())
}

/// Passes 28-36: light masks and buffer, environment capture, GI, landscape, fog, head mask,
/// tiled direct lighting and the sky.
fn environment_and_lighting(out: &mut Vec<Value>, day: bool) -> Result<(), SceneError> {
    // 28: local light masks, two resolutions.
    out.push(compute(
        "local_light_mask",
        LIGHTS,
        "lights.wgsl",
        "cs_light_mask_fine",
        vec![
            with(groups(15, 9, 1), json!({"label": "120x68"})),
            with(
                groups(8, 5, 1),
                json!({"label": "60x34", "entry": "cs_light_mask_coarse"}),
            ),
        ],
        json!({"bindings": {
            "cluster_light_index": sampled("cluster_light_index"),
            "depth_half": sampled("depth_half"),
            "light_mask_fine": storage_mip("local_light_mask", 0),
            "light_mask_coarse": storage_mip("local_light_mask", 1),
        }}),
    ));
    // 29: light buffer update.
    out.push(compute(
        "light_buffer_update",
        LIGHTS,
        "lights.wgsl",
        "cs_update_lights",
        vec![groups(16, 1, 1)],
        json!({"bindings": {"lights_rw": storage("lights", "storage_read_write")},
               "params": {"light_count": light_count(day), "shadowed_lights": SHADOWED_LIGHTS}}),
    ));
    environment_capture(out)?;
    // 31: GI probe indices.
    out.push(compute(
        "gi_probe_indices",
        LIGHTS,
        "gi.wgsl",
        "cs_gi_probe_indices",
        vec![groups(16, 16, 16)],
        json!({"bindings": {"voxel_normals": sampled("voxel_normals"),
                            "gi_probe_indices": storage("gi_probe_indices", "storage_write")}}),
    ));
    // 32: landscape maps.
    out.push(raster("landscape_maps", LIGHTS, "terrain.wgsl", ("vs_fullscreen", Some("fs_landscape")),
        vec![color("landscape_normal"), color("landscape_heat")],
        json!({"bindings": {"terrain_layers": sampled("terrain_layers"), "linear_clamp": sampler("linear_clamp")},
               "draws": [fullscreen("normal and heat")]})));
    // 33: local volumetric fog.
    out.push(compute("volumetric_fog_local", LIGHTS, "fog.wgsl", "cs_fog_integrate",
        vec![with(groups(30, 17, 1), json!({"label": "scatter and integrate"}))],
        json!({
            "bindings": {"fog_mip_0": storage_mip("fog_volume", 0),
                         "csm": with(sampled("csm"), json!({"format": "R16_UNORM"})),
                         "shadow_compare": sampler("shadow_compare"),
                         "cluster_light_index": sampled("cluster_light_index"),
                         "light_list": storage("light_list", "storage_read"),
                         "lights": storage("lights", "storage_read")},
            "params": {"density": if day { 0.025 } else { 0.06 }, "height_falloff": 0.08, "anisotropy": 0.6},
            "wait": ["cascades_done"],
        })));
    out.push(compute("volumetric_fog_local_mip1", &["Lights and shadows", "volumetric_fog_local"], "fog.wgsl",
        "cs_fog_downsample", vec![with(groups(30, 17, 16), json!({"label": "mip 1"}))],
        json!({"bindings": {"fog_source": with(sampled("fog_volume"), json!({"mips": {"base": 0, "count": 1}})),
                            "fog_mip_1": storage_mip("fog_volume", 1)}})));
    // 34: head mask.
    out.push(raster(
        "head_mask",
        LIGHTS,
        "gbuffer_post.wgsl",
        ("vs_fullscreen", Some("fs_head_mask")),
        vec![color("head_mask")],
        json!({"bindings": {"stencil": stencil_view()}, "draws": [fullscreen("faces")]}),
    ));
    direct_lighting(out, day);
    Ok(())
}

/// Pass 30: six faces of the street probe, then the dual-paraboloid array.
fn environment_capture(out: &mut Vec<Value>) -> Result<(), SceneError> {
    let groups_ = &["Lights and shadows", "env_capture"];
    let probe = json!([-6, 6, 40, 0]);
    let world = World {
        instances: false,
        foliage: false,
        ..World::SHADOW
    };
    for f in 0..6u32 {
        let view = json!({"view": 8, "face": f, "probe": probe});
        let rest = if f == 5 {
            json!({"signal": ["env_captured"]})
        } else {
            json!({})
        };
        out.push(scene_bindings(raster(
            &format!("env_capture_face_{f}"),
            groups_,
            "scene.wgsl",
            ("vs_static", Some("fs_env")),
            vec![with(color("env_cube"), json!({"layer": f}))],
            with(
                json!({
                    "depth_stencil": {"resource": "env_depth", "format": "D32_FLOAT",
                                      "depth_load": "clear", "depth_clear": 1.0},
                    "state": {"depth_compare": "less", "depth_write": true, "cull": "none"},
                    "params": with(scene_defaults(), view.clone()),
                    "draws": with_view(world_draws(world), view),
                }),
                rest,
            ),
        ))?);
    }
    let mut dp: Vec<(String, Value)> = (0..6)
        .map(|m| (format!("dp_mip_{m}"), storage_mip("env_dual_paraboloid", m)))
        .collect();
    dp.extend([
        ("env_cube".to_owned(), sampled("env_cube")),
        ("sky_cube".to_owned(), sampled("sky_cube")),
        ("linear_clamp".to_owned(), sampler("linear_clamp")),
    ]);
    let dispatches = (0..6u32)
        .map(|m| {
            with(
                // z: the captured probe, then all the distant ones (see the shader).
                groups((64u32 >> m).max(1), (32u32 >> m).max(1), 2),
                json!({"label": format!("mip {m}"), "params": {"mip": m, "mip_count": 6}}),
            )
        })
        .collect();
    out.push(compute("env_capture_paraboloid", groups_, "env.wgsl", "cs_dual_paraboloid", dispatches,
        json!({"bindings": object(dp), "params": {"mip": 0, "mip_count": 6, "layers": 32}, "wait": ["env_captured"]})));
    Ok(())
}

/// Passes 35-36: tiled direct lighting by indirect dispatch, then the sky where the mask says.
fn direct_lighting(out: &mut Vec<Value>, day: bool) {
    out.push(compute(
        "tiled_direct_lighting",
        LIGHTS,
        "lighting.wgsl",
        "cs_tiled_lighting",
        vec![json!({"label": "16x16 tiles", "indirect": {"buffer": "draw_args", "offset": 64}})],
        json!({
            "bindings": with(sampled_each(&GBUFFER), json!({
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
                "lit_diffuse": storage("lit_diffuse", "storage_write"),
                "lit_specular": storage("lit_specular", "storage_write"),
            })),
            "params": {"shadowed_lights": SHADOWED_LIGHTS,
                       "emissive_scale": if day { 6.0 } else { 12.0 }, "ambient_scale": 1.0},
            "wait": ["sun_shadow_ready"], "signal": ["direct_lit"],
        }),
    ));
    // 36: the sky, where the sky mask says.
    out.push(raster("sky", LIGHTS, "sky.wgsl", ("vs_fullscreen", Some("fs_sky")),
        vec![json!({"resource": "lit_diffuse", "load": "load"})],
        json!({
            "bindings": {"sky_mask": sampled("sky_mask"), "sky_mask_coarse": sampled("sky_mask_coarse"),
                         "sky_cube": sampled("sky_cube"), "sky_projection": sampled("sky_projected"),
                         "linear_clamp": sampler("linear_clamp")},
            "draws": [fullscreen("sky pixels")], "wait": ["direct_lit"],
        })));
}
