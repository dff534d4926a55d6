//! Shader-side classes of Vulkan on small synthetic edits of vkcube's capture: its fragment
//! shader replaced by hand-written SPIR-V (`tests/fixtures/subpass/`) that reads an input
//! attachment, or samples through a sampler of unnormalized coordinates; each pixel the cube
//! covers is checked against the texture it reads.

use std::path::Path;

use serde_json::json;

use crate::vk_classes::{
    draw_and_state, edit, point_the_texture_at_the_pass_target, replay_fails, temp, vkcube,
};

/// vkcube's fragment shader replaced by one that writes `subpassLoad` of an input attachment
/// at set 0 binding 1 (`tests/fixtures/subpass/subpass_load.spvasm`), the attachment being
/// vkcube's texture, which an earlier subpass would have written: every pixel the cube covers
/// is the texture's texel at the same position (black past the texture's 256x256, where a
/// fetch is out of bounds). The same input attachment pointed at the image the pass renders
/// to (framebuffer fetch) reads the attachment as it was before the draw: the clear colour,
/// so the cube, drawn with what is under it, is not seen.
#[test]
fn input_attachments_are_read_at_the_fragments_position() {
    let dir = temp("input-attachment");
    let capture = vkcube(&dir);
    let original = crate::common::replay_presented(&capture, &dir.join("original"));
    let spv = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/subpass/subpass_load.spv");
    let shaders = dir.join("vkcube.shaders");
    std::fs::copy(&spv, shaders.join("module_38.spv")).unwrap();
    let size = std::fs::metadata(&spv).unwrap().len();
    edit(&capture, |v| {
        let binding = &mut v["vulkan"]["set_layouts"][0]["bindings"][1];
        binding["descriptor_type"] = json!("VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT");
        for m in v["vulkan"]["shader_modules"].as_array_mut().unwrap() {
            if m["name"] == json!("module_38") {
                m["size"] = json!(size);
            }
        }
        let (draw, _) = draw_and_state(v);
        for d in draw["descriptors"].as_array_mut().unwrap() {
            if d["binding"] == json!(1) {
                d["descriptor_type"] = json!("INPUT_ATTACHMENT");
                d.as_object_mut().unwrap().remove("sampler");
            }
        }
    });
    let (inside, outside, wrong) = texels_at_pixels(&capture, &original, &dir.join("read"), false);
    assert!(inside > 10_000 && outside > 10_000, "{inside} {outside}");
    assert_eq!(
        wrong, 0,
        "{wrong} covered pixels are not the texel at their position"
    );

    point_the_texture_at_the_pass_target(&capture);
    let fetched = crate::common::replay_presented(&capture, &dir.join("fetched"));
    let background = *original.get_pixel(0, 0);
    let seen = fetched
        .pixels()
        .filter(|p| p.0[..3] != background.0[..3])
        .count();
    assert_eq!(seen, 0, "{seen} pixels are not the clear colour under them");
}

/// Replays `capture` into `out` and compares every pixel vkcube's cube covers in `original`
/// with vkcube's texture (`image_24`) at the same position: past the texture's edge, black
/// (an out-of-bounds fetch) or, `clamped`, the edge texel. (pixels inside, outside, wrong).
fn texels_at_pixels(
    capture: &Path,
    original: &image::RgbaImage,
    out: &Path,
    clamped: bool,
) -> (usize, usize, usize) {
    let image = crate::common::replay_presented(capture, out);
    let texture = image::open(out.join("image_24.png")).unwrap().to_rgba8();
    let background = *original.get_pixel(0, 0);
    let (mut inside, mut outside, mut wrong) = (0, 0, 0);
    for (x, y, p) in original.enumerate_pixels() {
        if *p == background {
            continue;
        }
        let got = image.get_pixel(x, y);
        let (w, h) = (texture.width(), texture.height());
        let want = if x < w && y < h {
            inside += 1;
            *texture.get_pixel(x, y)
        } else {
            outside += 1;
            if clamped {
                *texture.get_pixel(x.min(w - 1), y.min(h - 1))
            } else {
                image::Rgba([0, 0, 0, got[3]])
            }
        };
        if got.0[..3] != want.0[..3] {
            wrong += 1;
        }
    }
    (inside, outside, wrong)
}

/// vkcube's fragment shader replaced by one that samples its texture at
/// `gl_FragCoord.xy`, level 0 (`tests/fixtures/subpass/unnormalized.spvasm`), through a sampler
/// of unnormalized coordinates (nearest, clamped to the edge, as Vulkan requires of one): every
/// pixel the cube covers is the texel at its position, the edge texel past the texture. The
/// original shader's implicit-LOD sample through such a sampler, which Vulkan does not allow,
/// is refused by name.
#[test]
fn unnormalized_sampler_coordinates_are_texels() {
    let dir = temp("unnormalized");
    let capture = vkcube(&dir);
    let original = crate::common::replay_presented(&capture, &dir.join("original"));
    edit(&capture, |v| {
        let s = &mut v["vulkan"]["samplers"][0];
        s["unnormalized_coordinates"] = json!(true);
        for k in ["mag_filter", "min_filter"] {
            s[k] = json!("VK_FILTER_NEAREST");
        }
        s["mipmap_mode"] = json!("VK_SAMPLER_MIPMAP_MODE_NEAREST");
        s["min_lod"] = json!(0.0);
        s["max_lod"] = json!(0.0);
        for k in ["address_mode_u", "address_mode_v", "address_mode_w"] {
            s[k] = json!("VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE");
        }
    });
    let err = replay_fails(&capture);
    for part in [
        "draw 0",
        "unnormalized coordinates",
        "ImageSampleImplicitLod",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
    let spv = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/subpass/unnormalized.spv");
    std::fs::copy(&spv, dir.join("vkcube.shaders/module_38.spv")).unwrap();
    let size = std::fs::metadata(&spv).unwrap().len();
    edit(&capture, |v| {
        for m in v["vulkan"]["shader_modules"].as_array_mut().unwrap() {
            if m["name"] == json!("module_38") {
                m["size"] = json!(size);
            }
        }
    });
    let (inside, outside, wrong) = texels_at_pixels(&capture, &original, &dir.join("read"), true);
    assert!(inside > 10_000 && outside > 10_000, "{inside} {outside}");
    assert_eq!(
        wrong, 0,
        "{wrong} covered pixels are not the texel at their position"
    );
}
