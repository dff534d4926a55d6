//! `framelab what-if` end to end on the example frame with recorded barriers: a safe fix
//! replayed with images identical, a format change measured and its changed images named, a
//! barrier the frame needs refused statically at its pass before anything runs, and bad edits
//! refused with exit 2 and nothing written; on Night City, two passes merged into one render
//! pass.

use crate::common::{Scratch, framelab, json, stderr};

const SYNC: &str = "captures/example/frame_sync.json";

fn row<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["timing"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == name)
        .unwrap()
}

#[test]
fn a_redundant_barrier_dropped_is_safe_and_changes_no_image() {
    let o = framelab(&[
        "what-if", SYNC, "--fix", "FL021", "--frames", "2", "--warmup", "0", "--scale", "0.25",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], true);
    assert_eq!(r["changes"][0], "dropped barrier 3 of pass \"scene\"");
    assert_eq!(r["static"]["resolved"][0]["code"], "FL021");
    assert!(r["static"]["introduced"].as_array().unwrap().is_empty());
    let compared = r["textures_compared"].as_u64().unwrap();
    assert!(compared >= 5, "{r}");
    assert_eq!(r["textures_identical"].as_u64().unwrap(), compared);
    assert_eq!(r["presented"], "ldr");
    // Compared after every pass too: none differs.
    assert_eq!(r["passes_changed"].as_array().unwrap().len(), 0);
    let summary = r["summary"].as_str().unwrap();
    assert!(
        summary.starts_with("safe; ") && summary.ends_with("images identical"),
        "{summary}"
    );
    assert_eq!(row(&r, "frame total")["samples"][0], 2);
}

#[test]
fn a_smaller_format_moves_fewer_bytes_and_its_images_are_measured() {
    let dir = Scratch::temp("what_if_format");
    let out = dir.join("out");
    let o = framelab(&[
        "what-if",
        SYNC,
        "--format",
        "bloom=R11G11B10_FLOAT",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--scale",
        "0.25",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(
        r["changes"][0],
        "\"bloom\" R16G16B16A16_FLOAT -> R11G11B10_FLOAT"
    );
    // bloom_mips reads and writes only bloom: eight bytes a texel become four.
    let bytes = &row(&r, "bloom_mips")["bytes_moved"];
    assert_eq!(bytes[0].as_u64().unwrap(), 2 * bytes[1].as_u64().unwrap());
    let changed = r["changed"].as_array().unwrap();
    let bloom = changed.iter().find(|c| c["name"] == "bloom").unwrap();
    assert_eq!(bloom["state"], "changed");
    assert_eq!(bloom["first_written_by"], "bright_pass");
    let flip = bloom["flip_mean"].as_f64().unwrap();
    assert!(flip > 0.0 && flip < 0.05, "{flip}");
    // The presented image takes bloom in: changed, and said so first.
    assert!(changed.iter().any(|c| c["name"] == "ldr"));
    let summary = r["summary"].as_str().unwrap();
    assert!(
        summary.contains("final image changed: FLIP mean"),
        "{summary}"
    );
    for f in [
        "what_if.json",
        "bloom.a.png",
        "bloom.b.png",
        "bloom.flip.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let map = image::open(out.join("bloom.flip.png")).unwrap();
    let a = image::open(out.join("bloom.a.png")).unwrap();
    assert_eq!((map.width(), map.height()), (a.width(), a.height()));
}

#[test]
fn a_barrier_the_frame_needs_is_refused_before_anything_runs() {
    let o = framelab(&["what-if", SYNC, "--drop-barrier", "simulate:0", "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], false);
    let introduced = r["static"]["introduced"].as_array().unwrap();
    assert_eq!(introduced.len(), 1, "{r}");
    assert_eq!(introduced[0]["code"], "FL020");
    assert_eq!(introduced[0]["pass"], "simulate");
    assert_eq!(introduced[0]["resource"], "particles");
    // Nothing was replayed.
    assert!(r.get("timing").is_none());
    assert!(r["summary"].as_str().unwrap().starts_with("unsafe"));
}

#[test]
fn bad_edits_exit_2_naming_them_and_write_nothing() {
    let dir = Scratch::temp("what_if_bad");
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let cases: [(&[&str], &str); 10] = [
        (
            &["--cull", "nope"],
            "--cull nope: the capture has no pass \"nope\"",
        ),
        (
            &["--drop-barrier", "scene:9"],
            "pass \"scene\" records 4 barriers",
        ),
        (
            &["--format", "particles=R32_FLOAT"],
            "\"particles\" is a buffer",
        ),
        (
            &["--format", "bloom=R9_NOPE"],
            "not a format framelab knows",
        ),
        (&["--fix", "FL005"], "the frame has no such finding"),
        (&["--fix", "FL004"], "none with a change to the frame"),
        (
            &["--format", "depth=R8G8B8A8_UNORM"],
            "the edited frame is not a valid capture",
        ),
        (
            &["--merge", "scene+bright_pass"],
            "--merge scene+bright_pass: \"scene\" renders to \"scene_color\" mip 0 layer 0, depth \"depth\" mip 0 layer 0 and \"bright_pass\" to \"bloom\" mip 0 layer 0: one render pass has one set of attachments",
        ),
        (
            &["--merge", "scene+tonemap"],
            "\"tonemap\" is a compute pass: only raster passes merge",
        ),
        (
            &["--merge", "scene+nope"],
            "the capture has no pass \"nope\"",
        ),
    ];
    for (edit, said) in cases {
        let mut args = vec!["what-if", SYNC, "--out", out_s];
        args.extend_from_slice(edit);
        let o = framelab(&args);
        assert_eq!(o.status.code(), Some(2), "{edit:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(said), "{edit:?}: {}", stderr(&o));
        assert!(!out.exists(), "{edit:?} wrote {}", out.display());
    }
    // Malformed edits and no edit at all are usage errors too.
    for args in [
        &["what-if", SYNC, "--drop-barrier", "scene"][..],
        &["what-if", SYNC, "--fix", "FL999"],
        &["what-if", SYNC, "--merge", "scene"],
        &["what-if", SYNC, "--merge", "scene+scene"],
        &["what-if", SYNC],
    ] {
        assert_eq!(framelab(args).status.code(), Some(2), "{args:?}");
    }
}

#[test]
fn an_edited_real_stream_is_judged_at_the_command_the_layer_names() {
    // The planted write-after-write of the synchronization tests: vkd3d-gears' transition to
    // PRESENT_SRC_KHR no longer makes the render pass's store available. The Khronos layer
    // reports WRITE_AFTER_WRITE at vkCmdPipelineBarrier #176 on that stream.
    let gears = crate::common::gfxr_fixture("vkd3d_gears_f2.gfxr");
    let gears = gears.to_str().unwrap();
    let o = framelab(&[
        "what-if",
        gears,
        "--set",
        "176:pImageMemoryBarriers[0].srcAccessMask=0",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let r = json(&o);
    let introduced = r["static"]["introduced"].as_array().unwrap();
    assert_eq!(introduced.len(), 1, "{r}");
    let message = introduced[0]["message"].as_str().unwrap();
    assert!(
        message
            .starts_with("vkCmdPipelineBarrier #176: WRITE_AFTER_WRITE hazard on \"swapchain_0\""),
        "{message}"
    );
    // Widening the same barrier's source accesses is safe: both replay, images identical.
    let o = framelab(&[
        "what-if",
        gears,
        "--set",
        "176:pImageMemoryBarriers[0].srcAccessMask=0x180",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], true);
    assert!(r["textures_compared"].as_u64().unwrap() >= 3, "{r}");
    assert_eq!(r["textures_identical"], r["textures_compared"]);
    // --set belongs to GFXReconstruct captures only.
    let o = framelab(&["what-if", SYNC, "--set", "1:x=0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is not one"), "{}", stderr(&o));
}

#[test]
fn every_fixable_finding_of_the_example_frame_fixed_at_once_is_safe() {
    let o = framelab(&[
        "what-if",
        "captures/example/frame.json",
        "--fix",
        "all",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--scale",
        "0.25",
        "--json",
        "--final-only",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], true);
    assert!(!r["changes"].as_array().unwrap().is_empty());
    // --final-only compares after the last frame only.
    assert!(r.get("passes_changed").is_none());
    // Removing a flag nothing uses changes no image.
    assert_eq!(r["textures_identical"], r["textures_compared"], "{r}");
    let after = framelab(&["analyze", "captures/example/frame.json", "--json"]);
    assert!(
        json(&after)["lints"]
            .as_array()
            .unwrap()
            .iter()
            .any(|l| l.get("fix").is_some())
    );
}

#[test]
fn a_pass_moved_to_the_async_queue_needs_fences_and_a_smaller_texture_is_reshaped() {
    let o = framelab(&["what-if", SYNC, "--queue", "simulate=async", "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let r = json(&o);
    let errors: Vec<&serde_json::Value> = r["static"]["introduced"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| l["severity"] == "error")
        .collect();
    assert!(
        !errors.is_empty() && errors.iter().all(|l| l["code"] == "FL014"),
        "{r}"
    );
    let o = framelab(&[
        "what-if",
        SYNC,
        "--scale-resource",
        "bloom=0.5",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--scale",
        "0.25",
        "--final-only",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    let bloom = r["changed"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "bloom")
        .unwrap();
    assert_eq!(bloom["state"], "reshaped");
    // A quarter of the texels: about a quarter of the bytes bloom_mips moves (each mip's size
    // rounds up on its own).
    let row = r["timing"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == "bloom_mips")
        .unwrap();
    let (a, b) = (
        row["bytes_moved"][0].as_u64().unwrap(),
        row["bytes_moved"][1].as_u64().unwrap(),
    );
    let ratio = (4 * b) as f64 / a as f64;
    assert!((0.97..1.03).contains(&ratio), "{a} {b}");
}

#[test]
fn two_passes_merged_into_one_render_pass_load_and_store_their_target_once() {
    let o = framelab(&[
        "what-if",
        "captures/night_city/main_street_day.json",
        "--merge",
        "gi_shadow+volumetric_fog",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--scale",
        "0.1",
        "--final-only",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], true);
    assert_eq!(
        r["changes"][0],
        "passes \"gi_shadow\" and \"volumetric_fog\" merged into one render pass \"gi_shadow+volumetric_fog\""
    );
    // The composite (R16G16B16A16_FLOAT, 192x108 at this scale) is loaded and stored once
    // instead of twice: eight bytes a texel, once read and once written.
    let bytes = &row(&r, "frame total")["bytes_moved"];
    let (a, b) = (bytes[0].as_u64().unwrap(), bytes[1].as_u64().unwrap());
    assert_eq!(a - b, 2 * 192 * 108 * 8, "{a} -> {b}");
    // The same draws run, so the same work; the image is the same.
    let frame = &r["work"]["rows"][0];
    assert_eq!(frame["name"], "(frame)");
    assert_eq!(frame["work"]["draws"]["a"], frame["work"]["draws"]["b"]);
    assert_eq!(
        frame["counters"]["fragment_invocations"]["a"],
        frame["counters"]["fragment_invocations"]["b"]
    );
    let compared = r["textures_compared"].as_u64().unwrap();
    assert!(compared > 50, "{compared}");
    assert_eq!(r["textures_identical"].as_u64().unwrap(), compared);
}

/// On an imported frame, an edit of the model is judged by the pass-level rules on both sides
/// (the import's command-by-command check read the stream as captured), and says so:
/// vkd3d-triangle's two render passes on the swapchain image, with the read-after-write between
/// them that the stream check and the Khronos layer report, merged into one, lose it.
#[test]
fn merging_an_imported_frames_render_passes_removes_the_hazard_between_them() {
    let o = framelab(&[
        "what-if",
        "tests/fixtures/gfxr/vkd3d_triangle_f1.gfxr",
        "--merge",
        "render_pass+render_pass 2",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--final-only",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["safe"], true);
    assert!(
        r["static"]["note"]
            .as_str()
            .unwrap()
            .starts_with("judged by framelab's pass-level rules on both frames"),
        "{r}"
    );
    assert!(r["static"]["introduced"].as_array().unwrap().is_empty());
    // The hazard goes, and with it the advice to merge (FL017).
    let resolved = r["static"]["resolved"].as_array().unwrap();
    let found = |code: &str| resolved.iter().find(|l| l["code"] == code);
    assert_eq!(resolved.len(), 2, "{r}");
    let hazard = found("FL020").unwrap();
    assert_eq!(hazard["pass"], "render_pass 2");
    assert_eq!(hazard["resource"], "swapchain_0");
    assert_eq!(found("FL017").unwrap()["pass"], "render_pass");
    let compared = r["textures_compared"].as_u64().unwrap();
    assert!(compared >= 1);
    assert_eq!(r["textures_identical"].as_u64().unwrap(), compared);
}
