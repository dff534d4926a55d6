//! `framelab diff` end to end: the text, JSON and Markdown outputs on fixed reports, the exit
//! codes of the gate, refused inputs, and real comparisons replayed on the available adapter.

use crate::common::{Scratch, framelab, json, repo, stderr, stdout};

const A: &str = "tests/fixtures/timing/a.json";
const B: &str = "tests/fixtures/timing/b.json";

#[test]
fn diff_outputs_are_stable() {
    let text = framelab(&["diff", A, B]);
    assert_eq!(text.status.code(), Some(1), "{}", stderr(&text));
    insta::assert_snapshot!("diff_text", stdout(&text));
    insta::assert_snapshot!("diff_json", stdout(&framelab(&["diff", A, B, "--json"])));
    insta::assert_snapshot!(
        "diff_markdown",
        stdout(&framelab(&["diff", A, B, "--markdown"]))
    );
}

#[test]
fn the_gate_follows_fail_on_regression() {
    let d = json(&framelab(&["diff", A, B, "--json"]));
    let verdict = |name: &str| {
        d["rows"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == name && r["kind"] == "pass")
            .unwrap()["verdict"]
            .clone()
    };
    assert_eq!(verdict("lighting"), "regression");
    assert_eq!(verdict("tonemap"), "improvement");
    assert_eq!(verdict("gbuffer"), "unchanged");
    assert_eq!(d["added"][0], "gfx/Frame/Post/bloom");
    // lighting is +16% and the frame +10%: a 20% gate lets them through, a 12% one does not.
    assert_eq!(
        framelab(&["diff", A, B, "--fail-on-regression", "20"])
            .status
            .code(),
        Some(0)
    );
    assert_eq!(
        framelab(&["diff", A, B, "--fail-on-regression", "12"])
            .status
            .code(),
        Some(1)
    );
    assert_eq!(framelab(&["diff", A, A]).status.code(), Some(0));
}

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-diff-{name}"))
}

#[test]
fn bad_inputs_exit_2_and_say_why() {
    let dir = temp("bad");
    let half = dir.join("half.json");
    let mut r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo().join(A)).unwrap()).unwrap();
    r["scale"] = serde_json::json!(0.5);
    std::fs::write(&half, r.to_string()).unwrap();
    let out = framelab(&["diff", A, half.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("different scales (1 and 0.5)"),
        "{}",
        stderr(&out)
    );
    let out = framelab(&["diff", A, "captures/example/frame.json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("not one of each"), "{}", stderr(&out));
    // Frame counts the samples do not back: refused at once, never walked.
    for (field, value, says) in [
        (
            "frames",
            4_294_967_295u64,
            "more than the 100000 a replay or a diff times",
        ),
        ("frames", 40, "samples, but the report says 40 frames"),
        ("warmup", 1000, "warmup 1000 is more than its"),
    ] {
        let mut r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(repo().join(A)).unwrap()).unwrap();
        r[field] = serde_json::json!(value);
        std::fs::write(&half, r.to_string()).unwrap();
        let out = framelab(&["diff", A, half.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{field}");
        assert!(stderr(&out).contains(says), "{field}: {}", stderr(&out));
    }
    // A name that would recolour or clear the terminal is refused where it stands.
    let mut r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo().join(A)).unwrap()).unwrap();
    r["passes"][1]["name"] = serde_json::json!("bloom\u{1b}[2J");
    std::fs::write(&half, r.to_string()).unwrap();
    let out = framelab(&["diff", A, half.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("$.passes[1].name holds a control character"),
        "{}",
        stderr(&out)
    );
    let out = framelab(&["diff", A, "no/such/report.json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("no/such/report.json"),
        "{}",
        stderr(&out)
    );
}

/// The example replayed against itself passes the gate; with its bloom threshold pass drawn
/// eight times over, that pass is named as a regression and the gate fails.
#[test]
fn replayed_captures_are_compared_interleaved() {
    let args = ["--scale", "0.25", "--frames", "30", "--warmup", "3"];
    let same = framelab(
        &[
            &[
                "diff",
                "captures/example/frame.json",
                "captures/example/frame.json",
            ][..],
            &args,
        ]
        .concat(),
    );
    assert_eq!(
        same.status.code(),
        Some(0),
        "{}{}",
        stdout(&same),
        stderr(&same)
    );

    let dir = temp("heavier");
    let heavier = crate::common::example_with_bloom_drawn_eight_times(&dir);
    let out = framelab(
        &[
            &[
                "diff",
                "captures/example/frame.json",
                heavier.to_str().unwrap(),
                "--json",
            ][..],
            &args,
        ]
        .concat(),
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    let d = json(&out);
    let bloom = d["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "bloom_extract" && r["kind"] == "pass")
        .unwrap();
    assert_eq!(bloom["verdict"], "regression", "{bloom}");
    // At scale 0.25 the pass samples the 160x90 RGBA16F scene (115,200 bytes) and writes mip 0
    // of the half-size R11G11B10 bloom (80x45x4 = 14,400 bytes); drawing it eight times moves
    // no more declared bytes, so its bandwidth drops.
    assert_eq!(bloom["bytes_moved"], serde_json::json!([129_600, 129_600]));
    let gbps: Vec<f64> = bloom["bandwidth_gbps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g.as_f64().unwrap())
        .collect();
    assert!(gbps[1] < gbps[0], "{bloom}");
}

#[test]
fn plot_draws_every_pass_into_an_svg() {
    let dir = temp("plot");
    let svg = dir.join("diff.svg");
    let out = framelab(&["diff", A, B, "--plot", svg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"), "{}", &text[..80.min(text.len())]);
    for name in ["frame total", "lighting", "tonemap", "hbao (was ssao)"] {
        assert!(text.contains(name), "{name} missing from the plot");
    }
    // Regressions red, improvements green.
    assert!(
        text.contains("#C81E1E") && text.contains("#1E8C3C"),
        "{text}"
    );
}

const EXAMPLE: &str = "captures/example/frame.json";
const SYNC: &str = "captures/example/frame_sync.json";

/// The example against its variant without async compute: the moved simulation, the renamed
/// bloom pass, the wider bloom format and the dropped fence are each reported, and nothing is
/// replayed (no adapter line on stderr).
#[test]
fn structure_diff_names_every_change() {
    let text = framelab(&["diff", "--structure", EXAMPLE, SYNC]);
    assert_eq!(text.status.code(), Some(0), "{}", stderr(&text));
    assert!(stderr(&text).is_empty(), "{}", stderr(&text));
    insta::assert_snapshot!("structure_text", stdout(&text));
    insta::assert_snapshot!(
        "structure_markdown",
        stdout(&framelab(&[
            "diff",
            "--structure",
            EXAMPLE,
            SYNC,
            "--markdown"
        ]))
    );
    let d = json(&framelab(&["diff", "--structure", EXAMPLE, SYNC, "--json"]));
    assert_eq!(d["format_version"], 1);
    let moved: Vec<&str> = d["passes"]["moved"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["pass"].as_str().unwrap())
        .collect();
    assert_eq!(
        moved,
        ["Frame/Simulation/reset_args", "Frame/Simulation/simulate"]
    );
    assert_eq!(
        d["passes"]["renamed"][0]["to"],
        "gfx/Frame/Post/Bloom/bright_pass"
    );
    let bloom = &d["resources"]["changed"][0];
    assert_eq!(bloom["name"], "bloom");
    assert!(
        bloom["changes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| c["field"] == "format" && c["b"] == "R16G16B16A16_FLOAT"),
        "{bloom}"
    );
    assert_eq!(d["fences"]["removed"], serde_json::json!(["simulated"]));
    let total = d["memory"].as_array().unwrap().last().unwrap();
    assert_eq!(total["heap_type"], "total");
    // RGBA16F is twice R11G11B10: the unaliased total grows by the old bloom's bytes.
    let unaliased = total["unaliased_bytes"].as_array().unwrap();
    assert!(unaliased[1].as_u64() > unaliased[0].as_u64(), "{total}");

    let same = framelab(&["diff", "--structure", EXAMPLE, EXAMPLE]);
    assert_eq!(same.status.code(), Some(0));
    assert!(
        stdout(&same).contains("no structural change"),
        "{}",
        stdout(&same)
    );
}

#[test]
fn structure_diff_refuses_timing_reports() {
    let out = framelab(&["diff", "--structure", A, B]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("is a timing report: --structure compares two captures"),
        "{}",
        stderr(&out)
    );
    let both = framelab(&["diff", "--structure", EXAMPLE, SYNC, "--plot", "x.svg"]);
    assert_eq!(both.status.code(), Some(2));
    // A capture whose pass graph has a cycle is named once, with the cycle.
    let cycle = "tests/fixtures/cycle.json";
    let out = framelab(&["diff", "--structure", cycle, cycle]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).matches("the pass graph has a cycle").count(),
        1,
        "{}",
        stderr(&out)
    );
}
