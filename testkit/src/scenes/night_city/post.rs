//! Passes 45-57 of the frame, the post chain to the presented image: TAA and its blur chain,
//! low clouds, transparents, the post-TAA downscale and sharpen, the HDR LUTs, bloom, lens
//! flare, colour grading, the gamma LUT, the GUI, film grain and present. Work alternates
//! between the graphics and the async compute queue, each hand-off a fence.

use serde_json::{Value, json};

use super::composition::transparent_holo;
use super::helpers::{
    color, compute, cover, fullscreen_pass, groups, markers, object, sampled, sampler, storage,
    storage_mip, with,
};
use super::scene::SceneError;

const POST: &[&str] = &["Post-processing"];

/// Bloom levels: half resolution, then five more halvings.
const BLOOM_LEVELS: u32 = 6;

/// Groups of 8x8 covering `size` (at 1920x1080).
fn tiles(width: u32, height: u32) -> Value {
    groups(width.div_ceil(8), height.div_ceil(8), 1)
}

/// A sampled view of one mip.
fn mip_view(resource: &str, mip: u32) -> Value {
    with(
        sampled(resource),
        json!({"mips": {"base": mip, "count": 1}}),
    )
}

/// Passes 45-57.
pub(super) fn passes(out: &mut Vec<Value>, day: bool) -> Result<(), SceneError> {
    taa(out);
    // 47: low clouds over the sky, into the post-TAA image.
    out.push(fullscreen_pass(
        "cloud",
        POST,
        ("post.wgsl", "fs_clouds"),
        vec![color("composite_post")],
        json!({
            "taa_output": sampled("taa_output"),
            "depth_r32": sampled("depth_r32"),
            "cloud_distribution": sampled("cloud_distribution"),
            "linear_wrap": sampler("linear_wrap"),
        }),
        json!({"params": {"cloud_height": 900.0, "city_glow": if day { 0.0 } else { 0.05 }},
               "wait": ["taa_read"]}),
    ));
    // 48: holograms and the water surface.
    out.push(transparent_holo(POST, super::scene::light_count(day))?);
    post_taa(out);
    hdr(out, day);
    bloom(out);
    grade(out);
    gui_grain_present(out);
    Ok(())
}

/// Passes 45-46: TAA with history, then the blur chain on the compute queue.
fn taa(out: &mut Vec<Value>) {
    out.push(fullscreen_pass(
        "taa",
        POST,
        ("taa.wgsl", "fs_taa"),
        vec![color("taa_output")],
        json!({
            "composite": sampled("composite"),
            "history": sampled("taa_output"),
            "motion_vectors": sampled("motion_vectors"),
            "motion_stencil": sampled("motion_stencil"),
            "reflection_mask": sampled("reflection_mask"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({"signal": ["taa_done"]}),
    ));
    let steps = &["Post-processing", "taa_blur"];
    let mips =
        |resource: &str| object((0..3).map(|m| (format!("down_{m}"), storage_mip(resource, m))));
    out.push(compute(
        "taa_blur_downscale",
        steps,
        "taa.wgsl",
        "cs_taa_downscale",
        vec![with(tiles(240, 135), json!({"label": "1/2, 1/4, 1/8"}))],
        json!({
            "bindings": with(mips("taa_downscaled"), json!({
                "taa_output": sampled("taa_output"), "linear_clamp": sampler("linear_clamp")})),
            "wait": ["taa_done"],
            "signal": ["taa_read"],
        }),
    ));
    let per_mip = |to: &str| {
        (0..3u32)
            .map(|m| {
                with(
                    cover(to, m),
                    json!({"label": format!("mip {m}"), "params": {"mip": m}}),
                )
            })
            .collect::<Vec<_>>()
    };
    for (name, entry, from, to) in [
        (
            "taa_blur_horizontal",
            "cs_blur_horizontal",
            "taa_downscaled",
            "taa_blur_temp",
        ),
        (
            "taa_blur_vertical",
            "cs_blur_vertical",
            "taa_blur_temp",
            "taa_downscaled",
        ),
    ] {
        out.push(compute(
            name,
            steps,
            "taa.wgsl",
            entry,
            per_mip(to),
            json!({
                "bindings": with(mips(to), json!({"blur_source": sampled(from)})),
                "params": {"mip": 0},
            }),
        ));
    }
}

/// Pass 49: downscale to 1/2 and 1/4, then sharpen at full resolution.
fn post_taa(out: &mut Vec<Value>) {
    let steps = &["Post-processing", "post_taa"];
    out.push(compute(
        "post_taa_downscale",
        steps,
        "post.wgsl",
        "cs_post_downscale",
        vec![tiles(480, 270)],
        json!({
            "bindings": {
                "composite_post": sampled("composite_post"),
                "linear_clamp": sampler("linear_clamp"),
                "post_half_out": storage("post_half", "storage_write"),
                "post_quarter_out": storage("post_quarter", "storage_write"),
            },
            "wait": ["scene_done"],
        }),
    ));
    out.push(compute(
        "post_taa_sharpen",
        steps,
        "post.wgsl",
        "cs_post_sharpen",
        vec![cover("post_sharpened", 0)],
        json!({
            "bindings": {
                "composite_post": sampled("composite_post"),
                "post_half": sampled("post_half"),
                "linear_clamp": sampler("linear_clamp"),
                "post_sharpened_out": storage("post_sharpened", "storage_write"),
            },
        }),
    ));
}

/// Pass 50: three LUT dispatches, then the one that writes the parameters buffer.
fn hdr(out: &mut Vec<Value>, day: bool) {
    out.push(compute(
        "hdr_lut",
        POST,
        "tonemap.wgsl",
        "cs_hdr_lut_a",
        vec![
            with(groups(32, 32, 1), json!({"label": "local tonemap 256x256"})),
            with(
                groups(32, 8, 1),
                json!({"label": "Purkinje 256x64", "entry": "cs_hdr_lut_b"}),
            ),
            with(
                groups(4, 1, 1),
                json!({"label": "filmic curve 256x1", "entry": "cs_hdr_lut_c"}),
            ),
            with(
                groups(1, 1, 1),
                json!({"label": "exposure and settings", "entry": "cs_hdr_params"}),
            ),
        ],
        json!({
            "bindings": {
                "hdr_lut_a_out": storage("hdr_lut_a", "storage_write"),
                "hdr_lut_b_out": storage("hdr_lut_b", "storage_write"),
                "hdr_lut_c_out": storage("hdr_lut_c", "storage_write"),
                "hdr_params_out": storage("hdr_params", "storage_write"),
                "post_quarter": sampled("post_quarter"),
            },
            "params": {"bloom_threshold": 1.0, "bloom_intensity": if day { 0.08 } else { 0.16 },
                       "flare_intensity": if day { 0.02 } else { 0.05 }, "adaptation": 0.5},
        }),
    ));
}

/// Pass 51: six bloom levels, each from the one before.
fn bloom(out: &mut Vec<Value>) {
    let steps = &["Post-processing", "bloom"];
    for level in 0..BLOOM_LEVELS {
        let (w, h) = ((960 >> level).max(1), (540 >> level).max(1));
        let (entry, bindings) = if level == 0 {
            (
                "cs_bloom_prefilter",
                json!({"post_sharpened": sampled("post_sharpened"),
                       "hdr_params": storage("hdr_params", "storage_read")}),
            )
        } else {
            (
                "cs_bloom_downsample",
                json!({ "bloom_source": mip_view("bloom_chain", level - 1) }),
            )
        };
        let rest = if level == BLOOM_LEVELS - 1 {
            json!({"signal": ["bloom_done"]})
        } else {
            json!({})
        };
        out.push(compute(
            &format!("bloom_{level}"),
            steps,
            "post.wgsl",
            entry,
            vec![with(
                cover("bloom_chain", level),
                json!({"label": format!("{w}x{h} at 1080p")}),
            )],
            with(
                json!({
                    "bindings": with(bindings, json!({
                        "bloom_out": storage_mip("bloom_chain", level),
                        "linear_clamp": sampler("linear_clamp")})),
                }),
                rest,
            ),
        ));
    }
}

/// Passes 52-54: lens flare, colour grading, and the gamma LUT on the compute queue.
fn grade(out: &mut Vec<Value>) {
    out.push(fullscreen_pass(
        "lens_flare",
        POST,
        ("post.wgsl", "fs_lens_flare"),
        vec![color("lens_flare")],
        json!({"bloom_chain": sampled("bloom_chain"), "linear_clamp": sampler("linear_clamp")}),
        json!({"wait": ["bloom_done"]}),
    ));
    out.push(fullscreen_pass(
        "color_grading",
        POST,
        ("tonemap.wgsl", "fs_color_grading"),
        vec![color("ldr")],
        json!({
            "post_sharpened": sampled("post_sharpened"),
            "post_quarter": sampled("post_quarter"),
            "bloom_chain": sampled("bloom_chain"),
            "lens_flare": sampled("lens_flare"),
            "grading_lut": sampled("grading_lut"),
            "hdr_lut_a": sampled("hdr_lut_a"),
            "hdr_lut_b": sampled("hdr_lut_b"),
            "hdr_lut_c": sampled("hdr_lut_c"),
            "hdr_params": storage("hdr_params", "storage_read"),
            "linear_clamp": sampler("linear_clamp"),
        }),
        json!({}),
    ));
    out.push(compute(
        "gamma_correction",
        POST,
        "tonemap.wgsl",
        "cs_gamma_lut",
        vec![groups(57, 32, 1)],
        json!({"bindings": {"gamma_lut_out": storage("gamma_lut", "storage_write")}}),
    ));
}

/// Passes 55-57: the GUI and its glow, film grain, present.
fn gui_grain_present(out: &mut Vec<Value>) {
    let gui = &["Post-processing", "gui"];
    out.push(fullscreen_pass(
        "gui_overlay",
        gui,
        ("present.wgsl", "fs_gui_overlay"),
        vec![with(color("gui_overlay"), json!({"mip": 0}))],
        json!({"gui_elements": sampled("gui_elements"), "linear_clamp": sampler("linear_clamp"),
               "landscape_heat": sampled("landscape_heat"), "landscape_normal": sampled("landscape_normal")}),
        json!({"wait": ["gui_copied"]}),
    ));
    out.push(json!({
        "name": "gui_mips", "queue": "graphics", "kind": "generate_mips",
        "markers": markers(gui),
        "generate_mips": {"resource": "gui_overlay"},
        "signal": ["gui_ready"],
    }));
    out.push(compute(
        "gui_bloom",
        gui,
        "present.wgsl",
        "cs_gui_glow",
        vec![cover("gui_glow", 0)],
        json!({
            "bindings": {"gui_overlay": sampled("gui_overlay"), "linear_clamp": sampler("linear_clamp"),
                         "gui_glow_out": storage("gui_glow", "storage_write")},
            "wait": ["gui_ready"],
        }),
    ));
    let grain = &["Post-processing", "film_grain"];
    out.push(compute(
        "film_grain_lut",
        grain,
        "present.wgsl",
        "cs_grain_lut",
        vec![groups(32, 32, 1)],
        json!({"bindings": {"grain_lut_out": storage("grain_lut", "storage_write")}}),
    ));
    out.push(compute(
        "film_grain_apply",
        grain,
        "present.wgsl",
        "cs_film_grain",
        vec![cover("final", 0)],
        json!({
            "bindings": {
                "ldr": sampled("ldr"),
                "gamma_lut": sampled("gamma_lut"),
                "grain_lut": sampled("grain_lut"),
                "gui_overlay": sampled("gui_overlay"),
                "gui_glow": sampled("gui_glow"),
                "linear_clamp": sampler("linear_clamp"),
                "final_out": storage("final", "storage_write"),
            },
            // Row 146 of the gamma LUT is gamma 1.0, the default brightness.
            "params": {"brightness_row": 146, "grain": 0.05},
            "signal": ["final_ready"],
        }),
    ));
    out.push(fullscreen_pass(
        "present",
        POST,
        ("present.wgsl", "fs_present"),
        vec![color("swapchain")],
        json!({"final_image": sampled("final")}),
        json!({"wait": ["final_ready"]}),
    ));
}
