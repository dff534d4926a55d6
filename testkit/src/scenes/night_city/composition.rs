//! Passes 37-44 of the frame: screen-space reflections, indirect light, the light composition,
//! the transparent LUT, skin and eyes, GI/AO shadowing, the volumetric fog composition and the
//! water reflection; and the scene-drawn transparent pass (48), which `post` places in the
//! chain. Same passes in both variants; the night leans more on indirect light.

use serde_json::{Value, json};

use super::helpers::{
    GBUFFER, color, compute, cover, fullscreen_pass, groups, raster, sampled, sampled_each,
    sampler, stencil_view, storage, with,
};
use super::scene::{
    LIGHTS, SceneError, World, d, depth_attach, scene_bindings, scene_defaults, world_draws,
};

/// Where the street probe of pass 30 sits, and the radius it is trusted within.
const STREET_PROBE: [f64; 4] = [-6.0, 6.0, 40.0, 90.0];

/// Passes 37-44.
pub(super) fn passes(out: &mut Vec<Value>, day: bool) {
    ssr(out);
    // 38: local indirect light from the probes.
    out.push(compute(
        "indirect_light",
        LIGHTS,
        "composition.wgsl",
        "cs_indirect",
        vec![cover("indirect", 0)],
        json!({
            "bindings": with(
                sampled_each(&[&GBUFFER[..], &["env_dual_paraboloid", "sky_cube", "gi_probe_indices", "ao"]].concat()),
                json!({"linear_clamp": sampler("linear_clamp"),
                       "indirect_out": storage("indirect", "storage_write")}),
            ),
            "params": {"street_probe": STREET_PROBE, "indirect_scale": if day { 1.0 } else { 1.6 }},
            "wait": ["ssr_done"],
            "signal": ["indirect_ready"],
        }),
    ));
    // 39: composition, specular on RT1.
    out.push(fullscreen_pass(
        "light_composition",
        LIGHTS,
        ("composition.wgsl", "fs_compose"),
        vec![color("composite"), color("composite_specular")],
        json!({
            "lit_diffuse": sampled("lit_diffuse"),
            "lit_specular": sampled("lit_specular"),
            "indirect": sampled("indirect"),
            "ssr": sampled("ssr"),
            "ssr_reflectivity": sampled("ssr_reflectivity"),
        }),
        json!({"wait": ["indirect_ready"]}),
    ));
    // 40: transparent LUTs, on the compute queue while the graphics queue composes.
    out.push(compute(
        "transparent_lut",
        LIGHTS,
        "composition.wgsl",
        "cs_transparent_lut",
        vec![groups(16, 16, 1)],
        json!({
            "bindings": {"transparent_lut_out": storage("transparent_lut", "storage_write")},
            "signal": ["transparent_lut_ready"],
        }),
    ));
    // 41: skin irradiance and eyes where the stencil marks body and face.
    out.push(fullscreen_pass(
        "skin_and_eyes",
        LIGHTS,
        ("composition.wgsl", "fs_skin"),
        vec![color("skin_irradiance")],
        json!({
            "composite": sampled("composite"),
            "composite_specular": sampled("composite_specular"),
            "depth_r32": sampled("depth_r32"),
            "stencil": stencil_view(),
            "gbuffer_normal": sampled("gbuffer_normal"),
            "head_mask": sampled("head_mask"),
            "sky_cube": sampled("sky_cube"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({}),
    ));
    // 42: GI/AO shadowing (and the skin written back), premultiplied over the composite.
    let over = |resource: &str| json!({"resource": resource, "load": "load", "blend": "premultiplied_alpha"});
    out.push(fullscreen_pass(
        "gi_shadow",
        LIGHTS,
        ("composition.wgsl", "fs_gi_shadow"),
        vec![over("composite")],
        json!({
            "ao": sampled("ao"),
            "gbuffer_albedo": sampled("gbuffer_albedo"),
            "stencil": stencil_view(),
            "skin_irradiance": sampled("skin_irradiance"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({}),
    ));
    // 43: the froxel fog applied by depth.
    out.push(fullscreen_pass(
        "volumetric_fog",
        LIGHTS,
        ("composition.wgsl", "fs_fog_apply"),
        vec![over("composite")],
        json!({
            "fog_volume": sampled("fog_volume"),
            "depth_r32": sampled("depth_r32"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({}),
    ));
    // 44: the water's reflection at half resolution.
    out.push(fullscreen_pass(
        "water_reflection",
        LIGHTS,
        ("composition.wgsl", "fs_water_reflection"),
        vec![color("water_reflection")],
        json!({
            "composite": sampled("composite"),
            "ocean_height": sampled("ocean_height"),
            "stencil_half": sampled("stencil_half"),
            "depth_r32": sampled("depth_r32"),
            "gbuffer_normal": sampled("gbuffer_normal"),
            "sky_cube": sampled("sky_cube"),
            "linear_clamp": sampler("linear_clamp"),
            "linear_wrap": sampler("linear_wrap"),
        }),
        json!({}),
    ));
}

/// Pass 37: the tile mask, then the trace against the previous frame's downscaled TAA.
fn ssr(out: &mut Vec<Value>) {
    let steps = &["Lights and shadows", "ssr"];
    out.push(fullscreen_pass(
        "ssr_tile_mask",
        steps,
        ("ssr.wgsl", "fs_ssr_tiles"),
        vec![color("ssr_tiles")],
        json!({"reflection_mask": sampled("reflection_mask")}),
        json!({}),
    ));
    out.push(fullscreen_pass(
        "ssr_trace",
        steps,
        ("ssr.wgsl", "fs_ssr"),
        vec![color("ssr"), color("ssr_reflectivity")],
        json!({
            "reflection_mask": sampled("reflection_mask"),
            "ssr_tiles": sampled("ssr_tiles"),
            "depth_r32": sampled("depth_r32"),
            "depth_half": sampled("depth_half"),
            "noised_normal": sampled("noised_normal"),
            "gbuffer_material": sampled("gbuffer_material"),
            "motion_vectors": sampled("motion_vectors"),
            "motion_stencil": sampled("motion_stencil"),
            "taa_downscaled": sampled("taa_downscaled"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({"signal": ["ssr_done"]}),
    ));
}

/// Pass 48: the holographic signs again, additive, the water surface with its reflection, and
/// a glow around each of the `lights` lights, tested against the scene's depth without writing
/// it.
pub(super) fn transparent_holo(groups_: &[&str], lights: u32) -> Result<Value, SceneError> {
    let world = world_draws(World::ALL);
    let find = |label: &str| {
        world
            .iter()
            .find(|dr| dr["label"] == label)
            .cloned()
            .ok_or_else(|| SceneError::NoDraw {
                label: label.to_owned(),
            })
    };
    let signs = with(find("holographic signs")?, json!({"label": "holograms"}));
    let water = find("water")?;
    let glow = with(
        d(
            "light glow",
            "decal_quad",
            "vs_light_glow",
            json!({"material": 9}),
        ),
        json!({ "instances": lights }),
    );
    let draws = vec![signs, water, glow];
    scene_bindings(raster(
        "transparent_holo",
        groups_,
        "scene.wgsl",
        ("vs_instanced", Some("fs_transparent")),
        vec![json!({"resource": "composite_post", "load": "load", "blend": "premultiplied_alpha"})],
        json!({
            "depth_stencil": depth_attach(json!({"read_only": true})),
            "state": {"depth_compare": "less_equal", "depth_write": false, "cull": "none"},
            "params": scene_defaults(),
            "draws": draws,
            "wait": ["transparent_lut_ready"],
            "signal": ["scene_done"],
        }),
    ))
}
