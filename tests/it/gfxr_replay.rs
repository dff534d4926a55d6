//! Real programs' frames replayed: each binary capture is imported, replayed through wgpu on
//! the available adapter, and the image it presents (the manifest entry marked `presented`)
//! compared with the screenshot `gfxrecon-replay --screenshot-all` took of the same capture on
//! the same device, with the golden metric and tolerance. What the replay cannot do is an
//! error naming the pass, the shader and the feature; a damaged module never reaches the
//! driver; the Khronos validation layer reports nothing on the replay of any of them.

use std::path::{Path, PathBuf};

use crate::common::{Scratch, framelab, gfxr_fixture, stderr};

/// Captures whose presented image is compared with `<name>.ref.png`.
const REPLAYED: [&str; 45] = [
    "vkcube_f3",
    "vkcube_staging",
    "vkcube_f3_zstd",
    "vkcubepp_f3",
    "vkd3d_triangle_f1",
    "vkd3d_gears_f2",
    "mpv_testsrc_f5",
    "mpv_hq_f5",
    "framelab_inspect_f3",
    "warzone_menu_f120",
    "qtquick_f30",
    "mpv_testsrc2_f30",
    "vkbasalt_f100",
    "mangohud_f30",
    "qt6quick_f30",
    "gtk4_f30",
    "gtk4_whole",
    "gstreamer_f30",
    "qt6_msaa_f30",
    "qt6_quick3d_f30",
    "vkbasalt_all_f30",
    "chromium_angle_f60",
    "vkmark_effect2d_f30",
    "sdl_testvulkan_f30",
    "vkbasalt_reshade_f30",
    "zink_es2gears_f30",
    "glmark2_zink_ideas_f30",
    "mpv_gpunext_f30",
    "vlc_zink_f40",
    "vkbasalt_rgb10a2_f30",
    "zeroad_zink_menu_f60",
    "kitty_zink_f40",
    "vkbasalt_mrt_f30",
    "love_zink_min_f10",
    "glxgears_zink_unassisted_f30",
    "qt6_layer_samples8b_f30",
    "vkbasalt_lut_size2_f30",
    "vkbasalt_fn_sampler_param_f30",
    "mpv_next_rgb48_f40",
    "qt6_q3d_2dirshadow_f30",
    "vkbasalt_depth_qt3d_f30",
    "libreoffice_skia_f60",
    "qt6_video_p010le_f60",
    "qt5_hellovulkanwindow_f30",
    "mame_menu_f60",
];

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-gfxr-replay-{name}"))
}

/// The frame imported from whole captures (trimmed ones hold one): `vkcube_staging`'s last,
/// whose texture a copy from a staging buffer in its first frame made.
fn frame_of(name: &str) -> &'static [&'static str] {
    match name {
        "vkcube_staging" => &["--frame", "2"],
        // The 30th frame, as the trimmed `gtk4_f30` holds one (of another run).
        "gtk4_whole" => &["--frame", "29"],
        _ => &[],
    }
}

/// Imports `name` into `dir`, returning the capture's path.
fn import(name: &str, dir: &Path) -> PathBuf {
    import_frames(name, dir, frame_of(name))
}

/// Imports the frames `frames` (`import`'s frame options) of `name` into `dir`.
fn import_frames(name: &str, dir: &Path, frames: &[&str]) -> PathBuf {
    let capture = dir.join(format!("{name}.json"));
    let fixture = gfxr_fixture(&format!("{name}.gfxr"));
    let mut args = vec![
        "import",
        fixture.to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ];
    args.extend(frames);
    let out = framelab(&args);
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    capture
}

#[test]
fn real_frames_replay_to_the_image_they_presented() {
    let mut failures = Vec::new();
    for name in REPLAYED {
        let dir = temp(name);
        let capture = import(name, &dir);
        let image = crate::common::replay_presented(&capture, &dir.join("out"));
        let reference = image::open(gfxr_fixture(&format!("{name}.ref.png")))
            .unwrap()
            .to_rgba8();
        if let Err(e) = crate::golden::within(name, &image, &reference) {
            failures.push(e);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Each real frame replays two frames under the Khronos validation layer with no error or
/// warning (the layer writes its log file when it loads: an empty file proves it ran).
#[test]
fn real_frames_are_clean_under_the_validation_layer() {
    let dir = temp("validation-layer");
    let mut captures = REPLAYED.to_vec();
    captures.extend([
        "template_compute",
        "write_after_read",
        "ffmpeg_chain",
        "ffmpeg_overlay",
        "ffmpeg_bgra_gblur",
        "ffmpeg_rgba_scale_yuv",
    ]);
    crate::common::replays_clean_under_validation_layer(&dir, &captures, import);
}

/// `tools/template-compute` (descriptors written through update templates, into a set and
/// pushed, `input` filled through a mapping) replayed from its binary capture: the storage
/// image each of its two dispatches writes is, texel for texel, what its shader computes from
/// the program's input.
#[test]
fn frames_bound_through_update_templates_compute_what_the_program_did() {
    let dir = temp("template_compute");
    let capture = import("template_compute", &dir);
    let out = dir.join("out");
    let m = crate::common::replay_one_frame(&capture, &out);
    let images: Vec<&str> = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["file"].as_str().filter(|n| n.ends_with(".png")))
        .collect();
    assert_eq!(images.len(), 2, "both storage images exported: {images:?}");
    let unorm = |v: f64| (v * 255.0).round() as i32;
    for file in images {
        let image = image::open(out.join(file)).unwrap().to_rgba8();
        assert_eq!(image.dimensions(), (16, 16));
        let mut wrong = 0;
        for (x, y, p) in image.enumerate_pixels() {
            let input = (y * 16 + x) * 5 + 1;
            let want = [
                unorm(f64::from(x) / 15.0),
                unorm(f64::from(y) / 15.0),
                unorm(f64::from(input % 7) / 6.0),
                255,
            ];
            if want
                .iter()
                .zip(p.0)
                .any(|(w, g)| (w - i32::from(g)).abs() > 1)
            {
                wrong += 1;
            }
        }
        assert_eq!(
            wrong, 0,
            "{file}: {wrong} of 256 texels differ from the shader's result"
        );
    }
}

/// FFmpeg 5.1's `gblur_vulkan` on BGRA frames (one plane): its shaders read the frame through
/// an array of one combined image sampler, which the replay splits like longer arrays so that
/// the sampler can be split from the image. The second video frame's blurred image is, byte
/// for byte, the one FFmpeg itself wrote out (`-f rawvideo`, the reference PNG).
#[test]
fn one_plane_frames_read_through_arrays_of_one_are_what_ffmpeg_wrote() {
    let name = "ffmpeg_bgra_gblur";
    let dir = temp(name);
    let capture = import(name, &dir);
    let out = dir.join("out");
    let m = crate::common::replay_one_frame(&capture, &out);
    let file = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["resource"] == "image_74")
        .and_then(|f| f["file"].as_str())
        .expect("the blurred image exported");
    let ours = image::open(out.join(file)).unwrap().to_rgb8();
    let theirs = image::open(gfxr_fixture(&format!("{name}.ref.png")))
        .unwrap()
        .to_rgb8();
    assert_eq!(ours.dimensions(), theirs.dimensions());
    let differing = ours
        .pixels()
        .zip(theirs.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differing, 0, "{differing} pixels differ from FFmpeg's");
}

/// FFmpeg 5.1's `scale_vulkan` from RGBA to YUV 4:2:0 (after `vflip_vulkan` and
/// `flip_vulkan`): its shader writes an output array of three plane images, of which FFmpeg
/// binds the first and leaves the other two null (the layer reports
/// `VUID-vkCmdDispatch-None-02699`; the program never writes its U and V planes, and its own
/// output there is whatever the memory held). The replay binds a blank image for each empty
/// element, named in a note, as Vulkan's null descriptors behave; the Y plane of the second
/// video frame is, byte for byte, the one FFmpeg wrote out.
#[test]
fn empty_storage_descriptors_stand_in_as_blank_images() {
    let name = "ffmpeg_rgba_scale_yuv";
    let dir = temp(name);
    let capture = import(name, &dir);
    let out = dir.join("out");
    let (m, said) = crate::common::replay_export(&capture, &out);
    for element in [1, 2] {
        let note = format!(
            "pass \"dispatch 3\": set 0 binding 1 element {element} is empty in the captured descriptor set; a blank storage image stands in"
        );
        assert!(said.contains(&note), "missing {note:?} in:\n{said}");
    }
    let file = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["resource"] == "image_132")
        .and_then(|f| f["file"].as_str())
        .expect("the Y plane exported");
    let ours = image::open(out.join(file)).unwrap().to_rgba8();
    let theirs = image::open(gfxr_fixture(&format!("{name}.ref.y.png")))
        .unwrap()
        .to_luma8();
    assert_eq!(ours.dimensions(), theirs.dimensions());
    let differing = ours
        .pixels()
        .zip(theirs.pixels())
        .filter(|(a, b)| a.0[0] != b.0[0])
        .count();
    assert_eq!(differing, 0, "{differing} texels of the Y plane differ");
}

/// FFmpeg 5.1's Vulkan filters (compute, no swapchain; each capture holds two video frames): each keeps a descriptor array of one image per plane and indexes it
/// with constants, through a function's parameter (gblur by value, chromaber through a
/// pointer) or from a loop over the planes (overlay), which the replay splits into one binding
/// per plane. The planes of the second video frame are, byte for byte, the ones FFmpeg itself
/// wrote out (`-f rawvideo`, the reference PNGs).
#[test]
fn media_filters_write_the_planes_ffmpeg_wrote() {
    for (name, planes) in [
        (
            "ffmpeg_chain",
            [("image_235", "y"), ("image_237", "u"), ("image_239", "v")],
        ),
        (
            "ffmpeg_overlay",
            [("image_147", "y"), ("image_149", "u"), ("image_151", "v")],
        ),
    ] {
        let dir = temp(name);
        let capture = import(name, &dir);
        let out = dir.join("out");
        let m = crate::common::replay_one_frame(&capture, &out);
        for (resource, plane) in planes {
            let file = m["files"]
                .as_array()
                .unwrap()
                .iter()
                .find(|f| f["resource"] == resource)
                .and_then(|f| f["file"].as_str())
                .unwrap_or_else(|| panic!("{name}: {resource} not exported"));
            let ours = image::open(out.join(file)).unwrap().to_rgba8();
            let theirs = image::open(gfxr_fixture(&format!("{name}.ref.{plane}.png")))
                .unwrap()
                .to_luma8();
            assert_eq!(ours.dimensions(), theirs.dimensions(), "{name} {plane}");
            let differing = ours
                .pixels()
                .zip(theirs.pixels())
                .filter(|(a, b)| a.0[0] != b.0[0])
                .count();
            assert_eq!(
                differing, 0,
                "{name}: {differing} texels of plane {plane} differ"
            );
        }
    }
}

/// A binding the set layout declares as another descriptor type than the shader reads stops
/// the replay before anything is created, naming the pass, the draw, the shader, both types and
/// the rule: here vkcube's set layout edited to say its texture is an input attachment.
#[test]
fn what_the_replay_cannot_do_is_named() {
    let dir = temp("unsupported");
    let capture = import("vkcube_f3", &dir);
    let text = std::fs::read_to_string(&capture).unwrap();
    let edited = text.replace(
        "\"descriptor_type\": \"VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER\"",
        "\"descriptor_type\": \"VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT\"",
    );
    assert_ne!(
        text, edited,
        "the set layout names a combined image sampler"
    );
    std::fs::write(&capture, edited).unwrap();
    let out = framelab(&["replay", capture.to_str().unwrap(), "--frames", "1"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    for part in [
        "pass \"render_pass\"",
        "draw 0",
        "INPUT_ATTACHMENT",
        "COMBINED_IMAGE_SAMPLER",
        "module_38",
        "VUID-VkGraphicsPipelineCreateInfo-layout-07990",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
}

/// A module damaged inside (an OpLoad reading an id nothing defines, the file still SPIR-V
/// of the declared size with its entry point) is refused before it reaches the driver, with
/// the pass, the draw, the shader and the word at fault.
#[test]
fn a_damaged_module_never_reaches_the_driver() {
    let dir = temp("damaged");
    let capture = import("vkcube_f3", &dir);
    let spv = dir.join("vkcube_f3.shaders/module_38.spv");
    let mut words: Vec<u32> = std::fs::read(&spv)
        .unwrap()
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let mut at = 5;
    let load = loop {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        if opcode == 61 {
            break at;
        }
        at += count;
    };
    // OpLoad: result type, result id, pointer.
    words[load + 3] = 0xffff;
    std::fs::write(
        &spv,
        words
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    let out = framelab(&["replay", capture.to_str().unwrap(), "--frames", "1"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    for part in ["pass \"render_pass\"", "draw 0", "module_38", "%65535"] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
}

/// `write_after_read` was captured from framelab's own replay of
/// `sources/write_after_read.json`, where wgpu uploaded each 4x4 R32 texture with rows 128
/// bytes apart (`bufferRowLength` 32): closer than the 256 wgpu asks of a copy it is given. The
/// imported frame replays anyway, each image texel for texel what the source capture's replay
/// exports.
#[test]
fn rows_closer_than_wgpu_takes_are_copied_row_by_row() {
    let dir = temp("write_after_read");
    let capture = import("write_after_read", &dir);
    let text = std::fs::read_to_string(&capture).unwrap();
    assert!(
        text.contains("\"bytes_per_row\": 128"),
        "the capture still copies rows 128 bytes apart"
    );
    let imported = crate::common::replay_one_frame(&capture, &dir.join("imported"));
    let source = crate::common::repo().join("tests/fixtures/gfxr/sources/write_after_read.json");
    let (original, _) = crate::common::replay_export(&source, &dir.join("source"));
    let images = |m: &serde_json::Value, at: &Path| -> Vec<image::DynamicImage> {
        m["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| image::open(at.join(f["file"].as_str().unwrap())).unwrap())
            .collect()
    };
    let (a, b) = (
        images(&imported, &dir.join("imported")),
        images(&original, &dir.join("source")),
    );
    assert_eq!(a.len(), 3);
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert_eq!(
            x.as_bytes(),
            y.as_bytes(),
            "image {i} differs from the source's"
        );
    }
}

/// es2gears through zink replays (it is in `REPLAYED`): its uniform block, an array of words
/// with stride 4 (std430), is bound as a read-only storage buffer. Planted here: the array's
/// stride made 2, which no layout a wgpu binding reads keeps; the replay refuses it by name,
/// with the binding and the rule, and writes nothing.
#[test]
fn a_uniform_block_past_std430_is_refused_by_name() {
    let dir = temp("zink-scalar");
    let capture = import("zink_es2gears_f30", &dir);
    let c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&capture).unwrap()).unwrap();
    let mut planted = 0;
    for m in c["vulkan"]["shader_modules"].as_array().unwrap() {
        let path = dir.join(m["file"].as_str().unwrap());
        let mut words: Vec<u32> = std::fs::read(&path)
            .unwrap()
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        // OpDecorate (4 words, opcode 71) %array ArrayStride (6) 4.
        let mut at = 5;
        while at + 3 < words.len() {
            let count = (words[at] >> 16) as usize;
            if words[at] == (4 << 16 | 71) && words[at + 2] == 6 && words[at + 3] == 4 {
                words[at + 3] = 2;
                planted += 1;
            }
            at += count.max(1);
        }
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(&path, bytes).unwrap();
    }
    assert!(planted > 0, "no word array in es2gears' modules");
    let frames = dir.join("out");
    let out = framelab(&[
        "replay",
        capture.to_str().unwrap(),
        "--frames",
        "1",
        "--out",
        frames.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let said = stderr(&out);
    for part in [
        "render_pass",
        "draw 0",
        "a uniform block in scalar layout (set 0 binding 0",
        "stride 2, not a multiple of its element's alignment 4",
    ] {
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }
    assert!(!frames.join("manifest.json").exists());
}

/// Qt's P010 upload copies rows at a pitch shorter than the rows it copies (invalid; drivers
/// read them overlapping, at the offsets Vulkan's formula gives), its last row running past its
/// buffer's end: the import says both, the frame replays (to the reference image, in
/// `REPLAYED`), and it says which texels keep what the image held.
#[test]
fn overlapping_buffer_rows_are_copied_a_row_at_a_time() {
    let dir = temp("overlapping-rows");
    let capture = dir.join("p010.json");
    let fixture = gfxr_fixture("qt6_video_p010le_f60.gfxr");
    let out = framelab(&[
        "import",
        fixture.to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout).to_string() + &stderr(&out);
    for part in [
        "replays: yes",
        "copy_buffer_to_image regions whose buffer rows or slices overlap (VUID-VkBufferImageCopy-bufferRowLength-00195",
        "copied a row at a time",
        "copy_buffer_to_image reading past the end of its buffer (1272 bytes from offset 150732 of 151424",
        "145 of 318 texels, whose bytes are undefined, keep what the image held",
    ] {
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }
    let c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&capture).unwrap()).unwrap();
    let upload = c["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["kind"] == "copy")
        .expect("the upload");
    let copies = upload["copies"].as_array().unwrap();
    assert_eq!(copies.len(), 238, "one copy a row");
    assert_eq!(copies[1]["src"]["offset"], 636, "rows 159 texels apart");
    assert_eq!(copies[1]["dst"]["origin"][1], 1);
    assert_eq!(
        copies[237]["extent"][0], 173,
        "the last row cut at the buffer's end"
    );
}

/// Edits the one blit of GStreamer's frame (its sink blits the converted frame into the
/// swapchain image) and returns the capture's path.
fn edited_blit(dir: &Path, edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let capture = import("gstreamer_f30", dir);
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&capture).unwrap()).unwrap();
    let blit = c["passes"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["kind"] == "blit")
        .expect("a blit pass");
    edit(&mut blit["blits"][0]);
    std::fs::write(&capture, serde_json::to_string_pretty(&c).unwrap()).unwrap();
    capture
}

/// A blit is drawn by Vulkan's formula: corners in reverse mirror the image exactly (each
/// destination texel centre lands on a source texel centre), and a linear blit to half size
/// lands each centre on the corner four source texels share, so it is their average. The
/// reference is GStreamer's own 1:1 blit, which replays pixel-identical.
#[test]
fn blits_mirror_and_filter_as_vulkan_specifies() {
    let reference = image::open(gfxr_fixture("gstreamer_f30.ref.png"))
        .unwrap()
        .to_rgba8();
    let (w, h) = reference.dimensions();
    let dir = temp("blit-mirror");
    let capture = edited_blit(&dir, |b| {
        b["dst"]["corners"] = serde_json::json!([[w, h], [0, 0]]);
    });
    let mirrored = crate::common::replay_presented(&capture, &dir.join("out"));
    let mut off = 0;
    for (x, y, p) in mirrored.enumerate_pixels() {
        let q = reference.get_pixel(w - 1 - x, h - 1 - y);
        off += usize::from(p.0[..3] != q.0[..3]);
    }
    assert_eq!(off, 0, "{off} pixels are not the reference mirrored");

    let dir = temp("blit-half");
    let capture = edited_blit(&dir, |b| {
        b["dst"]["corners"] = serde_json::json!([[0, 0], [w / 2, h / 2]]);
        b["filter"] = serde_json::json!("linear");
    });
    let half = crate::common::replay_presented(&capture, &dir.join("out"));
    let mut worst = 0;
    for y in 0..h / 2 {
        for x in 0..w / 2 {
            for c in 0..3 {
                let sum: u32 = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|(dx, dy)| u32::from(reference.get_pixel(2 * x + dx, 2 * y + dy).0[c]))
                    .sum();
                let got = i64::from(half.get_pixel(x, y).0[c]);
                worst = worst.max((got - i64::from(sum) / 4).abs());
            }
        }
    }
    // Bilinear weights of 1/4 in 8-bit arithmetic round either way.
    assert!(
        worst <= 1,
        "a texel is {worst}/255 from the average of its four"
    );
}

/// A blit whose corner lies outside its mip is refused at validation with its JSON path.
#[test]
fn a_blit_outside_its_mip_is_refused_with_its_path() {
    let dir = temp("blit-outside");
    let capture = edited_blit(&dir, |b| {
        b["dst"]["corners"] = serde_json::json!([[0, 0], [321, 240]]);
    });
    let out = framelab(&["validate", capture.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    for part in [
        "error[blit]",
        ".blits[0].dst.corners[1]",
        "outside mip 0 of \"swapchain_0\" (320x240)",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
}

/// vkcube's first frame (`--use_staging`: the logo copied from a buffer into the texture)
/// edited so that the texture is `B5G6R5_UNORM_PACK16` and the buffer holds the logo as
/// 16-bit words: the copy is drawn, each texel unpacked from the buffer's words. Read through
/// an `R5G6B5` view (the same bit fields, red and blue named the other way), the cube shows the
/// logo within the 5- and 6-bit steps (a few 255ths from the original replay); read through a
/// view of the image's own format, red and blue trade places.
#[test]
fn a_16_bit_packed_texture_copied_from_a_buffer_is_unpacked() {
    let dir = temp("packed16");
    let original = dir.join("vkcube.json");
    let fixture = gfxr_fixture("vkcube_staging.gfxr");
    let args = [
        "import",
        fixture.to_str().unwrap(),
        "-o",
        original.to_str().unwrap(),
    ];
    let out = framelab(&[&args[..], &["--frame", "0"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let reference = crate::common::replay_presented(&original, &dir.join("out"));
    let text = std::fs::read_to_string(&original).unwrap();
    let frame: serde_json::Value = serde_json::from_str(&text).unwrap();
    let staging = frame["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "buffer_24")
        .expect("the staging buffer");
    let file = &staging["initial"]["file"];
    let logo = std::fs::read(dir.join(file["path"].as_str().unwrap())).unwrap();
    // Red in the top five bits, as an R5G6B5 view reads them.
    let mut words: Vec<u8> = logo[..256 * 256 * 4]
        .chunks_exact(4)
        .flat_map(|p| {
            let c = |v: u8, bits: u32| u16::from(v) * ((1 << bits) - 1) / 255;
            ((c(p[0], 5) << 11) | (c(p[1], 6) << 5) | c(p[2], 5)).to_le_bytes()
        })
        .collect();
    // The buffer keeps its size; the copy reads its first half.
    words.resize(256 * 256 * 4, 0);
    std::fs::write(dir.join("packed.bin"), &words).unwrap();
    let edited = |view: &str| {
        let mut f = frame.clone();
        for r in f["resources"].as_array_mut().unwrap() {
            if r["name"] == "buffer_24" {
                r["initial"]["file"] = serde_json::json!({ "path": "packed.bin", "offset": 0 });
            }
            if r["name"] == "image_26" {
                r["format"] = "VK_FORMAT_B5G6R5_UNORM_PACK16".into();
            }
        }
        for p in f["passes"].as_array_mut().unwrap() {
            let copies = p.get_mut("copies").and_then(|c| c.as_array_mut());
            for c in copies.into_iter().flatten() {
                if c["dst"]["resource"] == "image_26" {
                    c["src"]["bytes_per_row"] = 512.into();
                }
            }
        }
        for v in f["vulkan"]["image_views"].as_array_mut().unwrap() {
            if v["image"] == "image_26" {
                v["format"] = view.into();
            }
        }
        let path = dir.join(format!("{view}.json"));
        std::fs::write(&path, serde_json::to_string(&f).unwrap()).unwrap();
        crate::common::replay_presented(&path, &dir.join(format!("out-{view}")))
    };
    let compare = |image: &image::RgbaImage| {
        let mut worst = 0;
        let mut changed = 0;
        for (a, b) in image.pixels().zip(reference.pixels()) {
            let d = (0..3).map(|i| a.0[i].abs_diff(b.0[i])).max().unwrap();
            worst = worst.max(d);
            changed += usize::from(d > 0);
        }
        (worst, changed)
    };
    let (worst, changed) = compare(&edited("VK_FORMAT_R5G6B5_UNORM_PACK16"));
    assert!(
        changed > 1000,
        "the logo went through 5- and 6-bit steps: {changed}"
    );
    assert!(worst <= 8, "within the steps of 5 bits: {worst}");
    let (worst, _) = compare(&edited("VK_FORMAT_B5G6R5_UNORM_PACK16"));
    assert!(worst > 64, "red and blue trade places: {worst}");
}

/// vkcube's first frame with its texture edited into each family of three-channel format
/// (`R8G8B8`, `B8G8R8`, `R32G32B32`), its contents rewritten in that format from the logo:
/// the replay holds each with a fourth channel of one and draws the cube as the original
/// does; the `B8G8R8` contents read as `R8G8B8` trade red and blue.
#[test]
fn three_channel_textures_are_held_with_a_fourth_channel() {
    let dir = temp("three-channel");
    let original = dir.join("vkcube.json");
    let fixture = gfxr_fixture("vkcube_f3.gfxr");
    let out = framelab(&[
        "import",
        fixture.to_str().unwrap(),
        "-o",
        original.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let reference = crate::common::replay_presented(&original, &dir.join("out"));
    let frame: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&original).unwrap()).unwrap();
    let texture = frame["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["format"] == "R8G8B8A8_UNORM")
        .expect("the logo texture");
    let name = texture["name"].as_str().unwrap().to_owned();
    let file = &texture["initial"]["file"];
    let pack = std::fs::read(dir.join(file["path"].as_str().unwrap())).unwrap();
    let at = file["offset"].as_u64().unwrap() as usize;
    let logo = &pack[at..at + 256 * 256 * 4];
    let edited = |tag: &str, format: &str, view: &str, texel: &dyn Fn(&[u8]) -> Vec<u8>| {
        let bytes: Vec<u8> = logo.chunks_exact(4).flat_map(texel).collect();
        std::fs::write(dir.join(format!("{tag}.bin")), &bytes).unwrap();
        let mut f = frame.clone();
        for r in f["resources"].as_array_mut().unwrap() {
            if r["name"] == name.as_str() {
                r["format"] = format.into();
                r["initial"]["file"] =
                    serde_json::json!({ "path": format!("{tag}.bin"), "offset": 0 });
                // Its own memory: 96-bit texels outgrow the heap the RGBA8 image was placed in.
                r.as_object_mut().unwrap().remove("placement");
            }
        }
        for v in f["vulkan"]["image_views"].as_array_mut().unwrap() {
            if v["image"] == name.as_str() {
                v["format"] = view.into();
            }
        }
        let path = dir.join(format!("{tag}.json"));
        std::fs::write(&path, serde_json::to_string(&f).unwrap()).unwrap();
        crate::common::replay_presented(&path, &dir.join(format!("out-{tag}")))
    };
    let worst = |image: &image::RgbaImage| {
        image
            .pixels()
            .zip(reference.pixels())
            .map(|(a, b)| (0..3).map(|i| a.0[i].abs_diff(b.0[i])).max().unwrap())
            .max()
            .unwrap()
    };
    let rgb = |p: &[u8]| p[..3].to_vec();
    let bgr = |p: &[u8]| vec![p[2], p[1], p[0]];
    let floats = |p: &[u8]| {
        p[..3]
            .iter()
            .flat_map(|&v| (f32::from(v) / 255.0).to_le_bytes())
            .collect()
    };
    let r8 = edited(
        "r8g8b8",
        "VK_FORMAT_R8G8B8_UNORM",
        "VK_FORMAT_R8G8B8_UNORM",
        &rgb,
    );
    assert_eq!(worst(&r8), 0, "R8G8B8 draws the cube as RGBA8 does");
    let b8 = edited(
        "b8g8r8",
        "VK_FORMAT_B8G8R8_UNORM",
        "VK_FORMAT_B8G8R8_UNORM",
        &bgr,
    );
    assert_eq!(worst(&b8), 0, "B8G8R8 draws the cube as RGBA8 does");
    let f32 = edited(
        "r32g32b32",
        "R32G32B32_FLOAT",
        "VK_FORMAT_R32G32B32_SFLOAT",
        &floats,
    );
    assert!(
        worst(&f32) <= 1,
        "R32G32B32 within a rounding: {}",
        worst(&f32)
    );
    let swapped = edited(
        "swapped",
        "VK_FORMAT_R8G8B8_UNORM",
        "VK_FORMAT_R8G8B8_UNORM",
        &bgr,
    );
    assert!(worst(&swapped) > 64, "red and blue trade places");
}

/// LibreOffice's stencil-only attachment (`VK_FORMAT_S8_UINT`) is exported as one file: its
/// one aspect is the stencil (it had been read back twice, once as the texture and once as its
/// stencil, and the two writes of one file raced).
#[test]
fn a_stencil_only_texture_is_exported_once() {
    let dir = temp("stencil-only");
    let capture = import("libreoffice_skia_f60", &dir);
    let m = crate::common::replay_one_frame(&capture, &dir.join("out"));
    let files: Vec<&str> = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["file"].as_str())
        .filter(|f| f.starts_with("image_445"))
        .collect();
    assert_eq!(files, ["image_445.stencil.png"]);
}

/// LibreOffice's cursor drawn with a stencil test that reads no reference, as Skia's
/// stencil-then-cover paths draw (ALWAYS, INVERT, write mask 1, on its `S8_UINT` attachment):
/// the image is the same, and the Khronos layer says nothing. wgpu had left the stencil
/// reference, a dynamic state of all its pipelines, unset (`VUID-vkCmdDraw-None-07839`, which
/// Debian 12's layer words as an unset line width).
#[test]
fn a_stencil_test_that_reads_no_reference_is_clean_under_the_validation_layer() {
    let dir = temp("stencil-no-reference");
    let capture = import("libreoffice_skia_f60", &dir);
    crate::vk_classes::edit(&capture, |v| {
        let face = serde_json::json!({
            "fail_op": "VK_STENCIL_OP_KEEP", "pass_op": "VK_STENCIL_OP_INVERT",
            "depth_fail_op": "VK_STENCIL_OP_KEEP", "compare_op": "VK_COMPARE_OP_ALWAYS",
            "compare_mask": 0, "write_mask": 1, "reference": 0,
        });
        let pipelines = v["vulkan"]["pipelines"].as_array_mut().unwrap();
        let cursor = pipelines
            .iter_mut()
            .find(|p| p["name"] == "pipeline_1036")
            .expect("the cursor's pipeline");
        let ds = &mut cursor["graphics"]["depth_stencil"];
        ds["stencil_test"] = serde_json::json!(true);
        ds["front"] = face.clone();
        ds["back"] = face;
    });
    let image = crate::common::replay_presented(&capture, &dir.join("out"));
    let reference = image::open(gfxr_fixture("libreoffice_skia_f60.ref.png"))
        .unwrap()
        .to_rgba8();
    crate::golden::within("libreoffice_skia_f60", &image, &reference).unwrap();
    crate::common::assert_clean_under_validation_layer(
        &dir,
        &[
            "replay",
            capture.to_str().unwrap(),
            "--frames",
            "2",
            "--quiet",
        ],
    );
}

/// GTK writes its glyphs, icons and spinner into linear images through mapped memory as its
/// frames run (images it creates in them, read at the row pitch the driver reported): each
/// such write is a host-write copy into the image's texels at its place in the frame. The
/// second frame of the untrimmed capture, imported with the first, presents what
/// `gfxrecon-replay` shows for it, pixel for pixel (without the copies, 306 pixels of the
/// spinner and icons were what the first frame, or nothing, left there), and no read before
/// a write (FL006) is left to report.
#[test]
fn linear_images_the_host_writes_while_the_frames_run_are_replayed_with_their_texels() {
    let dir = temp("linear-host-writes");
    let capture = import_frames("gtk4_whole", &dir, &["--frames", "0-1"]);
    let image = crate::common::replay_presented(&capture, &dir.join("out"));
    let reference = image::open(gfxr_fixture("gtk4_whole_f2.ref.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(image.dimensions(), reference.dimensions());
    let off = image
        .pixels()
        .zip(reference.pixels())
        .filter(|(a, b)| a.0[..3] != b.0[..3])
        .count();
    assert_eq!(
        off, 0,
        "pixels that differ from gfxrecon-replay's second frame"
    );
    let analysed = framelab(&["analyze", capture.to_str().unwrap(), "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&analysed.stdout).unwrap();
    let fl006 = report["lints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| l["code"] == "FL006")
        .count();
    assert_eq!(fl006, 0, "{}", report["lints"]);
}

/// Qt's window imported into `dir`, its depth-stencil attachment made `D32_SFLOAT` and loaded
/// and stored instead of cleared, its snapshot's file filled by `snapshot(x)` for every row;
/// the capture's path and JSON (written back by the caller).
fn loaded_depth_window(
    dir: &Path,
    snapshot: impl Fn(usize) -> f32,
) -> (PathBuf, serde_json::Value) {
    let capture = import("qt5_hellovulkanwindow_f30", dir);
    let text = std::fs::read_to_string(&capture)
        .unwrap()
        .replace("\"D24_UNORM_S8_UINT\"", "\"D32_FLOAT\"")
        .replace("VK_FORMAT_D24_UNORM_S8_UINT", "VK_FORMAT_D32_SFLOAT");
    let mut c: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ds = c["passes"][0]["depth_stencil"].as_object_mut().unwrap();
    ds.insert("depth_load".into(), "load".into());
    ds.insert("depth_store".into(), "store".into());
    for k in ["stencil_load", "stencil_store", "stencil_clear"] {
        ds.remove(k);
    }
    let depth = c["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["format"] == "D32_FLOAT")
        .expect("the depth attachment");
    assert_eq!(
        (depth["width"].as_u64(), depth["height"].as_u64()),
        (Some(1024), Some(768))
    );
    let file = dir.join(depth["initial"]["file"]["path"].as_str().unwrap());
    assert_eq!(depth["initial"]["file"]["offset"], 0);
    let row: Vec<u8> = (0..1024).flat_map(|x| snapshot(x).to_le_bytes()).collect();
    std::fs::write(&file, row.repeat(768)).unwrap();
    (capture, c)
}

/// Replays `capture` (written from `c`) one frame and returns the exported depth's pixels.
fn exported_depth(dir: &Path, capture: &Path, c: &serde_json::Value) -> Vec<[f32; 4]> {
    std::fs::write(capture, serde_json::to_string_pretty(c).unwrap()).unwrap();
    let out = dir.join("out");
    let m = crate::common::replay_one_frame(capture, &out);
    let exported = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["read_as"] == "Depth32Float")
        .expect("the depth texture exported");
    let (width, pixels) = crate::common::exr_image(&out.join(exported["file"].as_str().unwrap()));
    assert_eq!(width, 1024);
    pixels
}

/// A depth snapshot (wgpu copies into no depth format but `Depth16Unorm`) is drawn into the
/// texture: Qt's window with its depth loaded, its snapshot a gradient across each row,
/// exports exactly that gradient after the frame (it had been left out and read 0 everywhere).
#[test]
fn depth_snapshots_are_drawn_into_their_textures() {
    let dir = temp("depth-snapshot");
    let gradient = |x: usize| x as f32 / 1023.0;
    let (capture, c) = loaded_depth_window(&dir, gradient);
    let pixels = exported_depth(&dir, &capture, &c);
    for (x, y) in [(0, 0), (1, 5), (511, 300), (512, 767), (1023, 100)] {
        assert_eq!(pixels[y * 1024 + x][0], gradient(x), "texel {x},{y}");
    }
}

/// A copy from a buffer into a float depth texture (which WebGPU does not copy) is drawn:
/// a 64x32 region at (100, 50), rows 256 bytes apart, lands texel for texel, and the rest
/// keeps the snapshot (it had been refused by name).
#[test]
fn buffer_copies_into_depth_textures_are_drawn() {
    let dir = temp("depth-copy");
    let (capture, mut c) = loaded_depth_window(&dir, |_| 0.75);
    let value = |x: u32, y: u32| (x + 64 * y) as f32 / 4096.0;
    let words: Vec<u8> = (0..32)
        .flat_map(|y| (0..64).flat_map(move |x| value(x, y).to_le_bytes()))
        .collect();
    std::fs::write(dir.join("upload.bin"), &words).unwrap();
    let mut heap = c["heaps"][0].clone();
    heap["name"] = "upload".into();
    heap["size"] = 65536.into();
    c["heaps"].as_array_mut().unwrap().push(heap);
    c["resources"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({
            "name": "depth_upload", "kind": "buffer", "size": 8192,
            "placement": {"placed": {"heap": "upload", "offset": 0}},
            "initial": {"file": {"path": "upload.bin", "offset": 0}}
        }));
    let depth = c["passes"][0]["depth_stencil"]["resource"].clone();
    let queue = c["passes"][0]["queue"].clone();
    c["passes"].as_array_mut().unwrap().insert(
        0,
        serde_json::json!({
            "name": "upload_depth", "queue": queue, "kind": "copy",
            "copies": [{
                "src": {"resource": "depth_upload", "mip": 0, "layer": 0, "origin": [0, 0, 0],
                        "offset": 0, "bytes_per_row": 256},
                "dst": {"resource": depth, "mip": 0, "layer": 0, "origin": [100, 50, 0], "offset": 0},
                "extent": [64, 32, 1]
            }]
        }),
    );
    let pixels = exported_depth(&dir, &capture, &c);
    for (x, y) in [(0u32, 0u32), (1, 0), (63, 0), (0, 1), (17, 9), (63, 31)] {
        let at = (50 + y) as usize * 1024 + (100 + x) as usize;
        assert_eq!(pixels[at][0], value(x, y), "copied texel {x},{y}");
    }
    for (x, y) in [(99, 50), (164, 50), (100, 49), (100, 82), (0, 0)] {
        assert_eq!(pixels[y * 1024 + x][0], 0.75, "untouched texel {x},{y}");
    }
}
