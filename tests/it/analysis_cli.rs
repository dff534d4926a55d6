//! `framelab graph` and `framelab analyze` end to end: snapshots of the JSON reports on small
//! captures, culling, cycles, DOT/SVG output, and the Night City capture.

use crate::common::{Scratch, framelab, json, stderr, stdout};

#[test]
fn analyze_json_snapshot_example() {
    let out = framelab(&["analyze", "--json", "captures/example/frame.json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    insta::assert_snapshot!("analyze_example", stdout(&out));
}

#[test]
fn graph_json_snapshot_example() {
    let out = framelab(&["graph", "--json", "captures/example/frame.json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    insta::assert_snapshot!("graph_example", stdout(&out));
}

#[test]
fn analyze_json_snapshot_culling() {
    let out = framelab(&["analyze", "--json", "--cull", "tests/fixtures/culling.json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    insta::assert_snapshot!("analyze_culling", stdout(&out));
}

#[test]
fn example_report_finds_what_was_planted() {
    let r = json(&framelab(&[
        "analyze",
        "--json",
        "captures/example/frame.json",
    ]));
    let codes: Vec<&str> = r["lints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["code"].as_str().unwrap())
        .collect();
    for code in ["FL001", "FL020", "FL021", "FL023", "FL024"] {
        assert!(codes.contains(&code), "{code} missing from {codes:?}");
    }
    // Every pass boundary is reported, in order.
    let order = r["order"].as_array().unwrap();
    let boundaries = r["barriers"].as_array().unwrap();
    assert_eq!(order.len(), boundaries.len());
    for (o, b) in order.iter().zip(boundaries) {
        assert_eq!(&b["pass"], o);
    }
    let total = &r["memory"]["total"];
    let (aliased, bound) = (
        total["aliased_bytes"].as_u64().unwrap(),
        total["lower_bound_bytes"].as_u64().unwrap(),
    );
    assert!(
        aliased as f64 <= 1.10 * bound as f64,
        "{aliased} vs {bound}"
    );
    assert!(r["critical_path"]["length_ns"].as_u64().unwrap() > 0);
    for key in [
        "order",
        "culled",
        "barriers",
        "memory",
        "lints",
        "critical_path",
    ] {
        assert!(r.get(key).is_some(), "top-level key {key}");
    }
}

#[test]
fn culling_finds_the_dead_pass_and_cull_drops_it() {
    let r = json(&framelab(&[
        "analyze",
        "--json",
        "tests/fixtures/culling.json",
    ]));
    assert_eq!(r["culled"], serde_json::json!(["debug_overlay"]));
    assert_eq!(r["order"].as_array().unwrap().len(), 4);
    let culled = json(&framelab(&[
        "analyze",
        "--json",
        "--cull",
        "tests/fixtures/culling.json",
    ]));
    assert_eq!(culled["culled"], serde_json::json!(["debug_overlay"]));
    assert_eq!(
        culled["order"],
        serde_json::json!(["draw_gbuffer", "compose", "present"])
    );
}

#[test]
fn cycles_are_errors_naming_passes_and_resources() {
    let out = framelab(&["analyze", "tests/fixtures/cycle.json"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    // Each pass once around the cycle, and why each must follow the one before: the data
    // hazard with its resource, and the fence with the JSON path of the wait.
    assert!(
        err.contains(
            "cycle: render_shadow -> copy_shadow -> render_shadow: copy_shadow reads shadow, which render_shadow writes; render_shadow waits on a fence copy_shadow signals ($.passes[0].wait)"
        ),
        "{err}"
    );
    assert_eq!(
        framelab(&["graph", "tests/fixtures/cycle.json"])
            .status
            .code(),
        Some(1)
    );
    // `validate` refuses what `analyze` cannot order, with the same cycle, as an error at
    // `$.passes` (JSON too), so a capture it accepts is one every later command can take.
    let v = framelab(&["validate", "tests/fixtures/cycle.json"]);
    assert_eq!(v.status.code(), Some(1));
    assert!(
        stderr(&v).contains("error[cycle] $.passes: the pass graph has a cycle: render_shadow -> copy_shadow -> render_shadow"),
        "{}",
        stderr(&v)
    );
    let j = framelab(&["validate", "--json", "tests/fixtures/cycle.json"]);
    let report: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    assert_eq!(report["valid"], false);
    assert_eq!(report["diagnostics"][0]["code"], "cycle");
}

#[test]
fn graph_writes_dot_with_queue_colours_and_clusters() {
    let dir = Scratch::temp("framelab-dot");
    let file = dir.join("frame.dot");
    let out = framelab(&[
        "graph",
        "captures/example/frame.json",
        "--dot",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let dot = std::fs::read_to_string(&file).unwrap();
    assert!(dot.starts_with("digraph frame {"));
    assert!(
        dot.contains("subgraph cluster_") && dot.contains("label=\"Bloom\""),
        "{dot}"
    );
    assert!(dot.contains("\"simulate\" -> \"scene\""));
    // Three queues, three colours.
    assert_eq!(
        ["#4e79a7", "#f28e2b", "#59a14f"]
            .iter()
            .filter(|c| dot.contains(*c))
            .count(),
        3
    );
    // SVG through Graphviz when it is installed; a clear message when it is not.
    let svg = dir.join("frame.svg");
    let out = framelab(&[
        "graph",
        "captures/example/frame.json",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    let has_dot = std::process::Command::new("dot").arg("-V").output().is_ok();
    if has_dot {
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    } else {
        assert_eq!(out.status.code(), Some(1));
        assert!(
            stderr(&out).contains("install graphviz"),
            "{}",
            stderr(&out)
        );
    }
}

/// Both Night City captures: the seed's dead passes culled by day (the night has only the
/// never-read CSM proxy), no hazard, no missing fence, no read of undefined contents, and an
/// aliasing plan within 10% of the lower bound.
#[test]
fn night_city_analyzes() {
    for (capture, dead) in [
        (
            "captures/night_city/main_street_day.json",
            serde_json::json!(["unknown_color_01", "csm_proxy"]),
        ),
        (
            "captures/night_city/river_bank_night.json",
            serde_json::json!(["csm_proxy"]),
        ),
    ] {
        let out = framelab(&["analyze", "--json", capture]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let r = json(&out);
        assert_eq!(r["culled"], dead, "{capture}");
        let lints = r["lints"].as_array().unwrap();
        let unused_uav: Vec<&str> = lints
            .iter()
            .filter(|l| l["code"] == "FL001")
            .map(|l| l["resource"].as_str().unwrap())
            .collect();
        assert!(unused_uav.contains(&"gbuffer_material"), "{unused_uav:?}");
        let errors: Vec<&serde_json::Value> =
            lints.iter().filter(|l| l["severity"] == "error").collect();
        assert!(errors.is_empty(), "{capture}: {errors:#?}");
        // One barrier batch per pass boundary, in order.
        let order = r["order"].as_array().unwrap();
        let boundaries: Vec<&serde_json::Value> = r["barriers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| &b["pass"])
            .collect();
        assert_eq!(boundaries, order.iter().collect::<Vec<_>>());
        let total = &r["memory"]["total"];
        let ratio =
            total["aliased_bytes"].as_f64().unwrap() / total["lower_bound_bytes"].as_f64().unwrap();
        assert!(
            ratio <= 1.10,
            "{capture}: aliasing plan is {ratio:.3}x the lower bound"
        );
        assert!(total["aliased_bytes"].as_u64() < total["unaliased_bytes"].as_u64());
    }
}

#[test]
fn anisotropic_sampling_of_a_single_mip_is_flagged() {
    let fl016 = |capture: &str| -> Vec<String> {
        let r = json(&framelab(&["analyze", "--json", capture]));
        r["lints"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|l| l["code"] == "FL016")
            .map(|l| l["pass"].as_str().unwrap().to_owned())
            .collect()
    };
    // Only the pass that samples the one-mip texture anisotropically: not the same sampler
    // over a mip chain, nor the one-mip texture through a plain sampler.
    assert_eq!(
        fl016("tests/fixtures/aniso/single_mip.json"),
        ["flat_aniso"]
    );
    // The example's ground is sampled anisotropically through its generated mip chain.
    assert!(fl016("captures/example/frame.json").is_empty());
}

/// `--deny` turns lints into a failing exit code, by severity, code or name; unknown lints are
/// a usage error.
#[test]
fn denied_lints_fail_analyze() {
    let example = "captures/example/frame.json";
    let code = |args: &[&str]| {
        framelab(&[&["analyze", example][..], args].concat())
            .status
            .code()
    };
    assert_eq!(code(&[]), Some(0));
    // The example records a barrier from the wrong state (FL024, an error).
    assert_eq!(code(&["--deny", "errors"]), Some(1));
    assert_eq!(code(&["--deny", "FL024"]), Some(1));
    assert_eq!(code(&["--deny", "barrier-wrong-before-state"]), Some(1));
    // No anisotropic sampling of a one-mip texture in it.
    assert_eq!(code(&["--deny", "FL016"]), Some(0));
    assert_eq!(code(&["--deny", "FL999"]), Some(2));
    let out = framelab(&["analyze", example, "--deny", "FL021"]);
    assert!(
        stderr(&out).contains("denied lint FL021 barrier-redundant"),
        "{}",
        stderr(&out)
    );
}

/// A compute pass ordered after graphics pass g9 and before g80 (fences) may overlap exactly
/// g10..=g79: the first 64 are listed in order, the other 6 counted.
#[test]
fn async_overlaps_are_the_unordered_range_and_long_lists_are_counted() {
    let dir = Scratch::temp("framelab-overlaps");
    std::fs::copy(
        crate::common::repo().join("tests/fixtures/compute.wgsl"),
        dir.join("compute.wgsl"),
    )
    .unwrap();
    let mut resources = vec![
        serde_json::json!({"name": "particles", "kind": "buffer", "size": 4096, "flags": ["ALLOW_UNORDERED_ACCESS"]}),
        serde_json::json!({"name": "args", "kind": "buffer", "size": 64, "flags": ["ALLOW_UNORDERED_ACCESS"]}),
    ];
    let mut passes = Vec::new();
    for i in 0..100 {
        resources.push(serde_json::json!({"name": format!("t{i}"), "kind": "texture_2d", "format": "R8G8B8A8_UNORM", "width": 4, "height": 4, "flags": ["ALLOW_RENDER_TARGET"]}));
        let mut pass = serde_json::json!({"name": format!("g{i}"), "queue": "gfx", "kind": "clear", "clears": [{"resource": format!("t{i}"), "value": [0, 0, 0, 0]}]});
        match i {
            9 => pass["signal"] = serde_json::json!(["ready"]),
            80 => pass["wait"] = serde_json::json!(["done"]),
            _ => {}
        }
        passes.push(pass);
        if i == 9 {
            passes.push(serde_json::json!({"name": "sim", "queue": "async", "kind": "compute", "wait": ["ready"], "signal": ["done"],
                "shader": {"file": "compute.wgsl", "compute": "cs_main"},
                "bindings": {"particles": {"resource": "particles", "access": "storage_read_write"}, "draw_args": {"resource": "args", "access": "storage_read_write"}},
                "dispatches": [{"groups": [1, 1, 1]}]}));
        }
    }
    let capture = serde_json::json!({"format_version": 1, "name": "overlaps", "resolution": {"width": 64, "height": 64},
        "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov_y_degrees": 60},
        "queues": [{"name": "gfx", "type": "graphics"}, {"name": "async", "type": "compute"}],
        "fences": [{"name": "ready"}, {"name": "done"}],
        "resources": resources, "passes": passes});
    let path = dir.join("overlaps.json");
    std::fs::write(&path, capture.to_string()).unwrap();
    let out = framelab(&["analyze", "--json", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let r = json(&out);
    let sim = &r["async_compute"][0];
    assert_eq!(sim["pass"], "sim");
    let listed: Vec<&str> = sim["overlaps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let expected: Vec<String> = (10..74).map(|i| format!("g{i}")).collect();
    assert_eq!(listed, expected);
    assert_eq!(sim["more"], 6);
    let text = stdout(&framelab(&["analyze", path.to_str().unwrap()]));
    assert!(text.contains("g73 and 6 more"), "{text}");
}

/// A frame imported from a Vulkan program is reported in Vulkan's terms, its idle swapchain
/// images are not "unused", and with no pass timed the critical path is its longest chain.
#[test]
fn an_imported_vulkan_frame_is_reported_in_vulkan_terms() {
    let dir = Scratch::temp("framelab-analyze-vulkan");
    let capture = imported(&dir, "vkcube_f3.gfxr");
    let capture = capture.as_str();
    let text = stdout(&framelab(&["analyze", capture]));
    assert!(
        text.contains("PRESENT_SRC_KHR -> COLOR_ATTACHMENT_OPTIMAL; BOTTOM_OF_PIPE / NONE"),
        "{text}"
    );
    assert!(!text.contains("PRESENT -> RENDER_TARGET"), "{text}");
    assert!(
        text.contains("longest chain of dependent passes, 2 of 2)\n  render_pass -> present"),
        "{text}"
    );
    let r = json(&framelab(&["analyze", "--json", capture]));
    let unused: Vec<&str> = r["lints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| l["code"] == "FL013")
        .map(|l| l["resource"].as_str().unwrap())
        .collect();
    // vkcube keeps a uniform buffer per swapchain image and uses one a frame: those are
    // reported; the swapchain images it does not present this frame are not.
    assert_eq!(unused, ["buffer_30", "buffer_32"]);
    assert_eq!(
        r["critical_path"]["passes"],
        serde_json::json!(["render_pass", "present"])
    );
    assert_eq!(r["critical_path"]["length_ns"], 0);
    // Its buffers take the alignment Vulkan reported (64 bytes), not D3D12's 64 KiB: what
    // the host-visible memory holds unaliased is what `info` counts in it.
    let info = json(&framelab(&["info", "--json", capture]));
    assert_eq!(
        r["memory"]["heap_types"]["CUSTOM"]["unaliased_bytes"],
        info["totals"]["CUSTOM"]["bytes"]
    );
    // Its sizes are the application's: `--scale` changes none, and says so.
    let info = framelab(&["info", "--json", capture, "--scale", "0.25"]);
    assert!(
        stderr(&info).contains("--scale 0.25 changes no size here"),
        "{}",
        stderr(&info)
    );
    let info = json(&info);
    assert_eq!(
        (&info["width"], &info["height"]),
        (&500.into(), &500.into())
    );
    assert_eq!(info["scale"], 1.0);
}

/// `tests/fixtures/gfxr/<file>` (a `.gfxr` capture or a JSON Lines stream) imported into
/// `dir`: the capture's path.
fn imported(dir: &std::path::Path, file: &str) -> String {
    let stem = file.rsplit_once('.').map_or(file, |(s, _)| s);
    let capture = dir.join(format!("{stem}.json"));
    let fixture = crate::common::gfxr_fixture(file);
    let out = framelab(&[
        "import",
        fixture.to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    capture.to_str().unwrap().to_owned()
}

/// Advice on an imported frame names Vulkan's usage flags and layouts, never D3D12's flags,
/// states or heaps.
#[test]
fn lints_on_an_imported_frame_give_vulkan_advice() {
    let dir = Scratch::temp("framelab-lints-vulkan");
    let mut messages = Vec::new();
    for name in ["vkd3d_triangle_f1", "vkd3d_gears_f2", "mpv_testsrc_f5"] {
        let r = json(&framelab(&[
            "analyze",
            "--json",
            &imported(&dir, &format!("{name}.gfxr")),
        ]));
        for l in r["lints"].as_array().unwrap() {
            messages.push(format!(
                "{name} {} {}",
                l["code"],
                l["message"].as_str().unwrap()
            ));
        }
    }
    let has = |code: &str, text: &str| {
        messages
            .iter()
            .any(|m| m.contains(code) && m.contains(text))
    };
    assert!(
        has(
            "FL001",
            "\"image_13\" was created with STORAGE usage but is never bound as a storage image"
        ),
        "{messages:#?}"
    );
    assert!(
        has(
            "FL001",
            "\"buffer_67\" was created with STORAGE usage but is never bound as a storage buffer"
        ),
        "{messages:#?}"
    );
    // gears' last pass loads and tests the depth its pipelines write: no advice, and no
    // derived transition of its depth to a read-only layout.
    assert!(!has("FL009", ""), "{messages:#?}");
    let gears = dir.join("vkd3d_gears_f2.json");
    let text = stdout(&framelab(&["analyze", gears.to_str().unwrap()]));
    assert!(!text.contains("DEPTH_STENCIL_READ_ONLY_OPTIMAL"), "{text}");
    // With its pipelines' depth writes off, the pass only tests it: FL009, in Vulkan's terms.
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&gears).unwrap()).unwrap();
    for p in c["vulkan"]["pipelines"].as_array_mut().unwrap() {
        p["graphics"]["depth_stencil"]["depth_write"] = false.into();
    }
    std::fs::write(&gears, c.to_string()).unwrap();
    let r = json(&framelab(&["analyze", "--json", gears.to_str().unwrap()]));
    let fl009: Vec<&str> = r["lints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| l["code"] == "FL009")
        .map(|l| l["message"].as_str().unwrap())
        .collect();
    assert_eq!(
        fl009,
        [
            "\"render_pass 3\" attaches \"image_68\" in a writable layout but no draw writes it: a read-only depth layout (DEPTH_STENCIL_READ_ONLY_OPTIMAL) lets other passes sample it meanwhile"
        ]
    );
    for d3d12 in [
        "ALLOW_",
        "DEPTH_READ",
        "UPLOAD heap",
        "DEFAULT heap",
        "read_only",
    ] {
        assert!(
            !messages.iter().any(|m| m.contains(d3d12)),
            "{d3d12}: {messages:#?}"
        );
    }
}

/// Queue-family ownership transfers are in the text as in `--json`.
#[test]
fn queue_ownership_transfers_are_listed_in_the_text() {
    let dir = Scratch::temp("framelab-analyze-transfers");
    let capture = imported(&dir, "v1_dynamic_rendering.jsonl");
    let capture = capture.as_str();
    let r = json(&framelab(&["analyze", "--json", capture]));
    let n = r["queue_transfers"].as_array().unwrap().len();
    assert!(n > 0, "{r}");
    let text = stdout(&framelab(&["analyze", capture]));
    assert!(
        text.contains(&format!("Queue ownership transfers ({n})")),
        "{text}"
    );
    assert!(
        text.contains("density   all          compute -> graphics  density            render_pass"),
        "{text}"
    );
}

/// FL006 names a read of contents nothing wrote: the example without its upload pass reads its
/// noise texture unwritten. Within one pass of several dispatches, whose order the pass's
/// accesses do not keep, what one writes another may read after it: FFmpeg's two-pass blurs
/// (one imported pass each, its first dispatch writing the image its second reads) are no
/// finding.
#[test]
fn reads_of_unwritten_contents_are_flagged_but_not_a_passs_own_writes() {
    let dir = Scratch::temp("framelab-fl006");
    let fl006 = |capture: &str| -> Vec<String> {
        let r = json(&framelab(&["analyze", "--json", capture]));
        r["lints"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|l| l["code"] == "FL006")
            .map(|l| l["resource"].as_str().unwrap_or_default().to_owned())
            .collect()
    };
    assert!(fl006("captures/example/frame.json").is_empty());
    let mut edited = crate::common::example_copy(&dir);
    let passes = edited["passes"].as_array_mut().unwrap();
    assert_eq!(passes[0]["name"], "upload_noise");
    passes.remove(0);
    // The pass after it waited on the upload's fence.
    passes[0]["wait"] = serde_json::json!([]);
    let file = dir.join("frame.json");
    std::fs::write(&file, serde_json::to_string_pretty(&edited).unwrap()).unwrap();
    assert_eq!(fl006(file.to_str().unwrap()), ["noise"]);
    let blurs = imported(&dir, "ffmpeg_chain.gfxr");
    assert!(fl006(&blurs).is_empty(), "{:?}", fl006(&blurs));
    // LibreOffice's cursor pass reads the image it renders (framebuffer fetch) with one draw.
    // Loading that image without contents reads what nothing wrote; clearing it at the pass's
    // start writes it before the draw reads it. A swapchain image whose contents the frame
    // discarded and then loads is the program's own business (undefined to it too).
    let skia = imported(&dir, "libreoffice_skia_f60.gfxr");
    let mut frame: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&skia).unwrap()).unwrap();
    for r in frame["resources"].as_array_mut().unwrap() {
        if r["name"] == "image_175" || r["name"] == "swapchain_0" {
            r.as_object_mut().unwrap().remove("initial");
        }
    }
    assert_eq!(
        frame["passes"][0]["color_attachments"][0]["resource"],
        "image_175"
    );
    assert_eq!(
        frame["passes"][1]["color_attachments"][0]["resource"],
        "swapchain_0"
    );
    let edited = |frame: &serde_json::Value, name: &str| -> Vec<String> {
        let file = dir.join(name);
        std::fs::write(&file, serde_json::to_string(frame).unwrap()).unwrap();
        fl006(file.to_str().unwrap())
    };
    assert_eq!(edited(&frame, "loaded.json"), ["image_175"]);
    frame["passes"][0]["color_attachments"][0]["load"] = "clear".into();
    frame["passes"][0]["color_attachments"][0]["clear"] = serde_json::json!([0.0, 0.0, 0.0, 0.0]);
    assert!(edited(&frame, "cleared.json").is_empty());
}
