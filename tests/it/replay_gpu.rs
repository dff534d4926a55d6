//! Replay on the available Vulkan adapter (Mesa's lavapipe on CI): every pass kind with exact
//! readback values for float, integer, depth and packed formats, the example frame against its
//! golden image, timings and trace files, and errors (shader errors with file:line:col, unknown
//! adapters). There is no skip: without an adapter these tests fail with the install hint.

use std::path::{Path, PathBuf};

use crate::common::{Scratch, exr_image, framelab, repo, stderr};

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-{name}"))
}

fn png(path: &Path) -> image::DynamicImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn exr_pixel(path: &Path, x: usize, y: usize) -> [f32; 4] {
    let (w, pixels) = exr_image(path);
    pixels[y * w + x]
}

#[test]
fn every_pass_kind_replays_with_exact_values() {
    let dir = temp("kinds");
    let out = dir.join("out");
    let timings = dir.join("timings.json");
    let trace = dir.join("trace.json");
    let run = framelab(&[
        "replay",
        "tests/fixtures/replay_kinds/kinds.json",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--timings",
        timings.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));

    // Clear, then a texture-to-texture copy: 8-bit colour.
    for file in ["color.png", "color_copy.png"] {
        let img = png(&out.join(file)).to_rgba8();
        assert!(
            img.pixels().all(|p| p.0 == [64, 128, 191, 255]),
            "{file}: {:?}",
            img.get_pixel(0, 0)
        );
    }
    // Compute storage writes: integers (normalised to their range in the PNG) and half floats.
    let ids = png(&out.join("ids.png")).to_rgba16();
    let expected = |x: u32, y: u32| ((f64::from(x + 16 * y) / 255.0) * 65535.0).round() as u16;
    assert_eq!(ids.get_pixel(3, 5)[0], expected(3, 5));
    assert_eq!(ids.get_pixel(15, 15)[0], 65535);
    assert_eq!(
        exr_pixel(&out.join("hdr.exr"), 3, 5),
        [3.0 / 16.0, 5.0 / 16.0, 2.5, -1.0]
    );
    // Buffer-to-texture copy on the copy queue.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let entry = |name: &str| {
        manifest["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["file"] == name)
            .unwrap_or_else(|| panic!("{name} not exported"))
            .clone()
    };
    assert_eq!(
        (
            entry("from_buffer.png")["min"].as_f64(),
            entry("from_buffer.png")["max"].as_f64()
        ),
        (Some(7.0), Some(7.0))
    );
    assert_eq!(entry("ids.png")["encoding"], "png16-normalised");
    // Raster pass: packed 10:10:10:2 colour and the depth it wrote.
    let packed = png(&out.join("packed.png")).to_rgba16();
    let p = packed.get_pixel(16, 16);
    assert_eq!(p[0], 65535);
    assert!((i32::from(p[1]) - 32800).abs() < 200, "{p:?}");
    assert_eq!(p[2], 0);
    assert_eq!(exr_pixel(&out.join("depth.exr"), 7, 9)[0], 0.25);
    // Mip generation keeps an exact checker (8-pixel cells box-filtered down twice).
    let mip2 = png(&out.join("checker_mip2.png")).to_rgba8();
    assert_eq!(mip2.dimensions(), (16, 16));
    assert!(
        mip2.pixels().all(|p| p[0] == 0 || p[0] == 255),
        "mip 2 is not a clean checker"
    );
    assert_ne!(mip2.get_pixel(0, 0)[0], mip2.get_pixel(2, 0)[0]);
    // Resolve of a 4x MSAA clear.
    assert!(
        png(&out.join("resolved.png"))
            .to_rgba8()
            .pixels()
            .all(|p| p.0 == [0, 255, 0, 255])
    );
    assert_eq!(manifest["skipped"][0]["resource"], "msaa");

    // A timing entry for every pass, with GPU time where the adapter has timestamps.
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&timings).unwrap()).unwrap();
    let passes = t["passes"].as_array().unwrap();
    assert_eq!(passes.len(), 9);
    for p in passes {
        assert_eq!(p["gpu_ns"].as_array().unwrap().len(), 2, "{p}");
        assert!(
            p["gpu_ns"]
                .as_array()
                .unwrap()
                .iter()
                .all(|v| v.as_u64().is_some_and(|ns| ns > 0)),
            "{p}"
        );
        assert!(p["cpu_ns"][0].as_u64().unwrap() > 0);
    }
    assert_eq!(t["frames"], 2);
    assert_eq!(t["timestamps"], "chained");
    assert_eq!(t["capture_sha256"].as_str().unwrap().len(), 64);
    // The trace is Chrome trace-event JSON with one named track per queue.
    let tr: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let events = tr["traceEvents"].as_array().unwrap();
    let tracks: Vec<&str> = events
        .iter()
        .filter(|e| e["ph"] == "M")
        .map(|e| e["args"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(tracks, ["async", "dma", "gfx"]);
    assert_eq!(events.iter().filter(|e| e["ph"] == "X").count(), 18);
    // Each pass's start is the previous pass's end stamp (n+1 stamps per frame), so a frame's
    // passes lie end to end on the GPU timeline, in submission order.
    let frame0: Vec<(f64, f64)> = events
        .iter()
        .filter(|e| e["ph"] == "X" && e["args"]["frame"] == 0)
        .map(|e| (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap()))
        .collect();
    assert_eq!(frame0[0].0, 0.0);
    for pair in frame0.windows(2) {
        let ((ts, dur), (next, _)) = (pair[0], pair[1]);
        assert!(
            (ts + dur - next).abs() < 0.002,
            "gap or overlap: {frame0:?}"
        );
    }
}

#[test]
fn example_frame_matches_its_golden() {
    let dir = temp("example");
    let out = dir.join("out");
    let run = framelab(&[
        "replay",
        "captures/example/frame.json",
        "--quiet",
        "--scale",
        "0.25",
        "--out",
        out.to_str().unwrap(),
        "--resource",
        "ldr",
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    crate::golden::assert_matches_golden(
        &out.join("ldr.png"),
        &repo().join("tests/goldens/example_ldr_scale0.25.png"),
    );
}

#[test]
fn after_exports_an_earlier_point_of_the_frame() {
    let dir = temp("after");
    let out = dir.join("out");
    let run = framelab(&[
        "replay",
        "tests/fixtures/replay_kinds/kinds.json",
        "--quiet",
        "--frames",
        "1",
        "--out",
        out.to_str().unwrap(),
        "--after",
        "clear_target",
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    // The raster pass has not run yet: its target holds nothing drawn.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let packed = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "packed.png")
        .unwrap()
        .clone();
    assert_eq!(packed["max"].as_f64(), Some(0.0));
    assert_eq!(manifest["after"], "clear_target");
}

#[test]
fn shader_errors_name_file_line_and_column() {
    let dir = temp("badshader");
    let fixture = repo().join("tests/fixtures/replay_kinds");
    std::fs::copy(fixture.join("kinds.json"), dir.join("kinds.json")).unwrap();
    let source = std::fs::read_to_string(fixture.join("kinds.wgsl")).unwrap();
    std::fs::write(
        dir.join("kinds.wgsl"),
        source.replace("return params.color;", "return params.colour;"),
    )
    .unwrap();
    let run = framelab(&[
        "replay",
        dir.join("kinds.json").to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(run.status.code(), Some(1));
    let err = stderr(&run);
    let line = source
        .lines()
        .position(|l| l.contains("return params.color;"))
        .unwrap()
        + 1;
    assert!(err.contains(&format!("kinds.wgsl:{line}:")), "{err}");
    assert!(
        err.contains("params.colour"),
        "the source line is shown: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn unknown_adapters_are_named() {
    let run = framelab(&[
        "replay",
        "tests/fixtures/replay_kinds/kinds.json",
        "--quiet",
        "--adapter",
        "no such gpu",
    ]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains("no adapter matches \"no such gpu\""),
        "{}",
        stderr(&run)
    );
}

#[test]
fn export_refuses_to_replace_a_foreign_folder() {
    let dir = temp("foreign");
    std::fs::write(dir.join("precious.txt"), "keep me").unwrap();
    let run = framelab(&[
        "replay",
        "tests/fixtures/replay_kinds/kinds.json",
        "--quiet",
        "--frames",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1));
    assert!(dir.join("precious.txt").exists());
}

#[test]
fn golden_metric_detects_differences() {
    let a = image::RgbaImage::from_fn(32, 32, |x, y| {
        image::Rgba([(x * 8) as u8, (y * 8) as u8, 128, 255])
    });
    let same = crate::golden::compare(&a, &a);
    assert_eq!((same.mean, same.p99), (0.0, 0.0));
    let mut b = a.clone();
    for p in b.pixels_mut() {
        p[0] = p[0].saturating_add(80);
    }
    let c = crate::golden::compare(&a, &b);
    assert!(c.mean > crate::golden::MEAN_TOLERANCE && c.p99 > crate::golden::P99_TOLERANCE);
}

#[test]
fn a_missing_device_feature_names_the_pass() {
    let dir = temp("feature");
    let capture = r#"{"format_version": 1, "name": "needs16bit", "resolution": {"width": 8, "height": 8},
        "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov_y_degrees": 60},
        "resources": [{"name": "height", "kind": "texture_2d", "format": "R16_UNORM", "width": 8, "height": 8, "flags": ["ALLOW_RENDER_TARGET"]}],
        "queues": [{"name": "gfx", "type": "graphics"}],
        "passes": [{"name": "clear_height", "queue": "gfx", "kind": "clear", "clears": [{"resource": "height"}]}]}"#;
    std::fs::write(dir.join("c.json"), capture).unwrap();
    let analysed = framelab_core::pipeline::Analysed::load(
        &dir.join("c.json"),
        &Default::default(),
        Default::default(),
    )
    .unwrap();
    let err = analysed
        .lower(framelab_replay::wgpu::Features::empty(), "test adapter")
        .unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("clear_height")
            && message.contains("needs Features::TEXTURE_FORMAT_16BIT_NORM,")
            && !message.contains("features_wgpu")
            && message.contains("test adapter"),
        "{message}"
    );
}

/// A history resource read (previous frame) and written (this frame) in one pass: after N
/// frames texel x holds N * (1 + x), which only holds if the two copies swap every frame.
#[test]
fn history_resources_ping_pong_between_frames() {
    for frames in [1u32, 3] {
        let dir = temp(&format!("history{frames}"));
        let out = dir.join("out");
        let run = framelab(&[
            "replay",
            "tests/fixtures/history/history.json",
            "--quiet",
            "--frames",
            &frames.to_string(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap())
                .unwrap();
        let f = &manifest["files"][0];
        assert_eq!(
            (f["min"].as_f64(), f["max"].as_f64()),
            (Some(f64::from(frames)), Some(f64::from(4 * frames))),
            "{frames} frames"
        );
    }
}

/// A texture no pass uses whose contents cannot be generated (BC1 has no generator) is skipped
/// with a note instead of failing the replay.
#[test]
fn unused_textures_without_contents_are_noted_not_fatal() {
    let dir = temp("ungenerated");
    let capture = dir.join("frame.json");
    std::fs::write(
        &capture,
        r#"{"format_version": 1, "name": "ungenerated",
            "resolution": {"width": 16, "height": 16},
            "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov_y_degrees": 60},
            "queues": [{"name": "gfx", "type": "graphics"}],
            "resources": [
              {"name": "atlas", "kind": "texture_2d", "format": "BC1_UNORM", "width": 64, "height": 64,
               "initial": {"generator": {"name": "noise", "seed": 1}}},
              {"name": "target", "kind": "texture_2d", "format": "R8G8B8A8_UNORM", "width": 16,
               "height": 16, "flags": ["ALLOW_RENDER_TARGET"], "output": true}],
            "passes": [{"name": "clear", "queue": "gfx", "kind": "clear",
                        "clears": [{"resource": "target", "value": [1, 0, 0, 1]}]}]}"#,
    )
    .unwrap();
    let out = dir.join("out");
    let run = framelab(&[
        "replay",
        capture.to_str().unwrap(),
        "--frames",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("note: \"atlas\" is not replayed"),
        "{}",
        stderr(&run)
    );
    assert!(out.join("target.png").exists());
}

/// Replays a Night City capture at quarter resolution for `frames` frames into `out` and
/// returns the export manifest's file list.
fn replay_night_city(capture: &str, frames: &str, out: &Path) -> Vec<serde_json::Value> {
    let run = framelab(&[
        "replay",
        capture,
        "--scale",
        "0.25",
        "--frames",
        frames,
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{capture}: {}", stderr(&run));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    manifest["files"].as_array().unwrap().clone()
}

/// The pixels of `resource`'s top mip (an EXR export) in a replay's export folder.
fn exported_exr(files: &[serde_json::Value], folder: &Path, resource: &str) -> Vec<[f32; 4]> {
    let file = files
        .iter()
        .find(|f| f["resource"] == resource && f["mip"] == 0 && f["layer"] == 0)
        .unwrap_or_else(|| panic!("{resource} was not exported"));
    exr_image(&folder.join(file["file"].as_str().unwrap())).1
}

/// Pixels where TAA's output is not the composite it was given.
fn taa_changed(files: &[serde_json::Value], folder: &Path) -> (usize, usize) {
    let taa = exported_exr(files, folder, "taa_output");
    let composite = exported_exr(files, folder, "composite");
    let changed = taa
        .iter()
        .zip(&composite)
        // Half-float rounding aside (about 0.1%), relative to the pixel: the night is dark.
        .filter(|(a, b)| (0..3).any(|c| (a[c] - b[c]).abs() > 0.02 * b[c].abs() + 1e-4))
        .count();
    (changed, taa.len())
}

/// Every texture some pass of `capture` writes, by name.
fn written_textures(capture: &str) -> std::collections::BTreeSet<String> {
    let model = framelab_core::pipeline::Validated::load(
        &repo().join(capture),
        &framelab_core::capture::Options {
            scale: 0.25,
            ..Default::default()
        },
    )
    .unwrap()
    .capture;
    let mut written = std::collections::BTreeSet::new();
    for pass in &model.passes {
        for a in pass.accesses.iter().filter(|a| a.writes) {
            let r = model.resource(a.resource);
            if r.is_texture() {
                written.insert(r.name.clone());
            }
        }
    }
    written
}

/// Both Night City captures at quarter resolution, one frame and then two:
/// - every texture a pass writes ends the frame with content (not one uniform value), except
///   `lod_ids`, which its pass clips by design;
/// - the presented image matches its golden (FLIP, the one golden helper);
/// - temporal passes use real history: on the first frame TAA passes the composite through and
///   SSR reflects nothing (there is no previous frame), on the second TAA blends history in,
///   SSR finds the previous frame's image, and the presented image differs as the camera moved.
#[test]
fn night_city_frames_have_content_history_and_match_their_goldens() {
    for (capture, golden) in [
        (
            "captures/night_city/main_street_day.json",
            "tests/goldens/main_street_day_scale0.25.png",
        ),
        (
            "captures/night_city/river_bank_night.json",
            "tests/goldens/river_bank_night_scale0.25.png",
        ),
    ] {
        let stem = Path::new(capture).file_stem().unwrap().to_string_lossy();
        let dir = temp(&format!("nightcity-{stem}"));
        let (first_dir, second_dir) = (dir.join("first"), dir.join("second"));
        let first = replay_night_city(capture, "1", &first_dir);
        let files = replay_night_city(capture, "2", &second_dir);

        let written = written_textures(capture);
        assert!(written.len() >= 70, "{capture}: {written:?}");
        let mut flat = Vec::new();
        for name in &written {
            let mine: Vec<&serde_json::Value> =
                files.iter().filter(|f| f["resource"] == **name).collect();
            assert!(!mine.is_empty(), "{capture}: {name} was not exported");
            let has_content = mine.iter().any(|f| f["uniform"] == false);
            if name == "lod_ids" {
                assert!(
                    !has_content,
                    "lod_ids should stay cleared: its draws are clipped"
                );
            } else if !has_content {
                flat.push(name.clone());
            }
        }
        assert!(flat.is_empty(), "{capture}: uniform targets: {flat:?}");

        crate::golden::assert_matches_golden(
            &second_dir.join("swapchain.png"),
            &repo().join(golden),
        );

        let ssr = |files: &[serde_json::Value]| {
            files
                .iter()
                .find(|f| f["resource"] == "ssr_reflectivity")
                .unwrap()["max"]
                .as_f64()
                .unwrap()
        };
        let (changed, _) = taa_changed(&first, &first_dir);
        assert_eq!(
            changed, 0,
            "{capture}: TAA changed {changed} pixels without history"
        );
        assert_eq!(
            ssr(&first),
            0.0,
            "{capture}: SSR reflected with no previous frame"
        );
        let (changed, total) = taa_changed(&files, &second_dir);
        assert!(
            changed * 10 > total,
            "{capture}: TAA changed only {changed} of {total} pixels with history"
        );
        assert!(
            ssr(&files) > 0.1,
            "{capture}: SSR found nothing in the previous frame"
        );
        let one = png(&first_dir.join("swapchain.png")).to_rgba8();
        let two = png(&second_dir.join("swapchain.png")).to_rgba8();
        let moved = crate::golden::compare(&one, &two);
        assert!(
            moved.mean > crate::golden::MEAN_TOLERANCE,
            "{capture}: the second frame looks like the first (FLIP mean {:.4})",
            moved.mean
        );
    }
}

/// Several frames of the example replay without a pathological one. The example once spent
/// over three minutes in one frame on lavapipe (8x anisotropic filtering of a texture with one
/// mip, sampled by tiny primitives); this is a hang guard with a deadline far above the few
/// seconds the frames take, not a timing.
#[test]
fn several_example_frames_replay_without_a_pathological_frame() {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_framelab"))
        .args([
            "replay",
            "captures/example/frame.json",
            "--scale",
            "0.5",
            "--frames",
            "4",
            "--quiet",
        ])
        .current_dir(repo())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(90);
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "replay failed: {status}");
            break;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            panic!("four frames of the example at scale 0.5 took over 90 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
}

/// An export replaces its folder only when the folder holds nothing but what the earlier
/// export listed; anything else is refused before the device opens, and nothing is deleted.
#[test]
fn export_never_replaces_files_it_did_not_write() {
    let out = temp("foreign");
    let export = |quiet: bool| {
        let mut args = vec![
            "replay",
            "captures/example/frame.json",
            "--scale",
            "0.25",
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
        ];
        if quiet {
            args.push("--quiet");
        }
        framelab(&args)
    };
    assert!(export(true).status.success());
    // Again over its own export: fine.
    assert!(export(true).status.success());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let refused = export(false);
    assert_eq!(refused.status.code(), Some(1));
    let message = stderr(&refused);
    assert!(message.contains("notes.txt"), "{message}");
    assert!(
        !message.contains("adapter:"),
        "refused only after opening a device: {message}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(out.join("manifest.json").is_file());
}

/// Both bundled captures (and the example's synchronous twin) replay two frames under the
/// Khronos validation layer with no error or warning. The layer writes its log file when it
/// loads, so an empty file that exists proves it ran and found nothing; a missing layer fails.
#[test]
fn bundled_captures_are_clean_under_the_validation_layer() {
    let dir = temp("validation-layer");
    for (capture, scale) in [
        ("captures/example/frame.json", "0.25"),
        ("captures/example/frame_sync.json", "0.25"),
        ("captures/night_city/main_street_day.json", "0.125"),
        ("captures/night_city/river_bank_night.json", "0.125"),
    ] {
        crate::common::assert_clean_under_validation_layer(
            &dir,
            &[
                "replay",
                capture,
                "--scale",
                scale,
                "--frames",
                "2",
                "--quiet",
                // Counting too: its queries around every pass are checked with the rest.
                "--counters",
            ],
        );
    }
}

#[test]
fn block_compressed_textures_export_decoded_by_the_gpu() {
    // Four hand-made BC1 blocks: all colour0 (red), all colour1 (blue), all colour0 (green),
    // all index 2 (two thirds of white over black).
    let dir = temp("bc");
    let out = dir.join("out");
    let run = framelab(&[
        "replay",
        "tests/fixtures/bc/bc.json",
        "--quiet",
        "--frames",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["skipped"], serde_json::json!([]));
    let file = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["resource"] == "blocks")
        .unwrap();
    assert_eq!(
        (file["format"].as_str(), file["read_as"].as_str()),
        (Some("BC1_UNORM"), Some("Rgba8Unorm"))
    );
    let image = png(&out.join("blocks.png")).to_rgba8();
    let at = |x, y| image.get_pixel(x, y).0;
    assert_eq!(at(1, 1), [255, 0, 0, 255]);
    assert_eq!(at(6, 2), [0, 0, 255, 255]);
    assert_eq!(at(2, 6), [0, 255, 0, 255]);
    let grey = at(5, 5);
    assert!(
        (169..=171).contains(&grey[0]) && grey[0] == grey[1] && grey[1] == grey[2],
        "{grey:?}"
    );
}

/// A capture of `passes` clears over a few small textures, written to `dir`.
fn many_clears(dir: &Path, passes: usize) -> PathBuf {
    let resources: Vec<serde_json::Value> = (0..8)
        .map(|i| serde_json::json!({"name": format!("t{i}"), "kind": "texture_2d", "format": "R8G8B8A8_UNORM", "width": 4, "height": 4, "flags": ["ALLOW_RENDER_TARGET"], "output": i == 0}))
        .collect();
    let list: Vec<serde_json::Value> = (0..passes)
        .map(|i| serde_json::json!({"name": format!("clear_{i}"), "queue": "gfx", "kind": "clear", "clears": [{"resource": format!("t{}", i % 8), "value": [0, 0, 0, 0]}]}))
        .collect();
    let capture = serde_json::json!({"format_version": 1, "name": "many_clears", "resolution": {"width": 64, "height": 64},
        "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov_y_degrees": 60},
        "queues": [{"name": "gfx", "type": "graphics"}], "resources": resources, "passes": list});
    let path = dir.join("many_clears.json");
    std::fs::write(&path, capture.to_string()).unwrap();
    path
}

/// More timestamps than one query set holds (4,096): 4,200 passes chained (4,201 stamps) and
/// 2,100 as pairs (4,200 stamps, a pair kept in one set) replay with every pass timed.
#[test]
fn frames_with_more_stamps_than_a_query_set_holds_are_timed_whole() {
    let dir = temp("many-clears");
    for (passes, pairs) in [(4200, false), (2100, true)] {
        let capture = many_clears(&dir, passes);
        let timings = dir.join("t.json");
        let capture_arg = capture.to_str().unwrap();
        let timings_arg = timings.to_str().unwrap();
        let mut args = vec!["replay", capture_arg, "--frames", "1", "--quiet"];
        args.extend(["--timings", timings_arg]);
        if pairs {
            args.push("--timestamp-pairs");
        }
        let out = framelab(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let t: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&timings).unwrap()).unwrap();
        assert_eq!(t["timestamps"], if pairs { "pairs" } else { "chained" });
        let passes_json = t["passes"].as_array().unwrap();
        assert_eq!(passes_json.len(), passes);
        let untimed: Vec<&str> = passes_json
            .iter()
            .filter(|p| p["gpu_ns"][0].as_u64().is_none())
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        assert!(untimed.is_empty(), "untimed: {untimed:?}");
    }
}

/// An indirect draw whose count the GPU reads (`indirect.count`, replayed by wgpu's
/// `multi_draw_indirect_count`): the example's orb draw given a count buffer that its reset
/// pass clears to 1 draws the frame as the example does, pixel for pixel; cleared to 0, as
/// the example without the orb draw. Both under the validation layer without a message.
#[test]
fn indirect_draw_counts_are_read_on_the_gpu() {
    use serde_json::json;
    let dir = temp("draw-count");
    let variant = |name: &str, change: &dyn Fn(&mut serde_json::Value)| -> PathBuf {
        let at = dir.join(name);
        let mut capture = crate::common::example_copy(&at);
        change(&mut capture);
        let file = at.join("frame.json");
        std::fs::write(&file, serde_json::to_string_pretty(&capture).unwrap()).unwrap();
        file
    };
    let counted = |n: u32| {
        move |c: &mut serde_json::Value| {
            c["resources"].as_array_mut().unwrap().push(json!({
                "name": "draw_count", "kind": "buffer", "buffer_kind": "byte_address",
                "size": 4, "flags": ["ALLOW_UNORDERED_ACCESS"]
            }));
            let reset = &mut c["passes"][2];
            assert_eq!(reset["name"], "reset_args");
            reset["clears"]
                .as_array_mut()
                .unwrap()
                .push(json!({"resource": "draw_count", "value": [n, n, n, n]}));
            let orb = &mut c["passes"][4]["draws"][1];
            assert_eq!(orb["mesh"], "orb");
            orb["indirect"]["count"] = json!({"buffer": "draw_count", "max_draws": 1});
        }
    };
    let ldr = |capture: &Path, name: &str| {
        let out = dir.join(format!("{name}_out"));
        crate::common::replay_export(capture, &out);
        png(&out.join("ldr.png")).to_rgba8()
    };
    let example = variant("example", &|_| {});
    let one = variant("one", &counted(1));
    let zero = variant("zero", &counted(0));
    let without = variant("without", &|c| {
        c["passes"][4]["draws"].as_array_mut().unwrap().remove(1);
    });
    let (a, b) = (ldr(&example, "example"), ldr(&one, "one"));
    assert!(a == b, "a count of 1 draws the orbs as the example does");
    let (c, d) = (ldr(&zero, "zero"), ldr(&without, "without"));
    assert!(
        c == d,
        "a count of 0 draws what the frame without the draw does"
    );
    assert!(a != c, "the orbs are drawn at all");
    for capture in [&one, &zero] {
        let out = dir.join("layer_out");
        crate::common::assert_clean_under_validation_layer(
            &dir,
            &[
                "replay",
                capture.to_str().unwrap(),
                "--frames",
                "1",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ],
        );
    }
}
