//! Work counters end to end: `replay --counters` counts what each pass did on the adapter, the
//! counts agree with the work the pass submitted, two replays count the same, and `diff --work`
//! names a pass that does more work and fails the gate for it.

use std::path::Path;

use serde_json::Value;

use crate::common::{Scratch, framelab, stderr, stdout};

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-counters-{name}"))
}

/// Replays `capture` with counters and returns its timing report.
fn counted(capture: &Path, scale: &str, frames: &str, report: &Path, extra: &[&str]) -> Value {
    let run = framelab(
        &[
            &[
                "replay",
                capture.to_str().unwrap(),
                "--scale",
                scale,
                "--frames",
                frames,
                "--counters",
                "--timings",
                report.to_str().unwrap(),
            ][..],
            extra,
        ]
        .concat(),
    );
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap()
}

fn pass<'r>(report: &'r Value, name: &str) -> &'r Value {
    report["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no pass {name}"))
}

fn last(p: &Value, counter: &str) -> u64 {
    p["counters"][counter]
        .as_array()
        .and_then(|v| v.last())
        .and_then(Value::as_u64)
        .unwrap_or_else(|| panic!("{}: no {counter}", p["name"]))
}

#[test]
fn counters_agree_with_the_work_each_pass_submitted() {
    let dir = temp("example");
    let trace = dir.join("trace.json");
    let report = counted(
        Path::new("captures/example/frame.json"),
        "0.25",
        "2",
        &dir.join("report.json"),
        &["--trace", trace.to_str().unwrap()],
    );
    assert_eq!(report["format_version"], 2);
    // Compute: one invocation per thread dispatched, and nothing else counted.
    for name in ["simulate", "tonemap"] {
        let p = pass(&report, name);
        let threads = p["work"]["threads"].as_u64().unwrap();
        assert!(threads > 0, "{name}");
        assert_eq!(last(p, "compute_invocations"), threads, "{name}");
        assert_eq!(last(p, "fragment_invocations"), 0, "{name}");
        assert_eq!(last(p, "vertex_invocations"), 0, "{name}");
    }
    // A fullscreen triangle: three vertices, one primitive in, and every pixel of the render
    // area shaded once, plus the helper lanes of the 2x2 quads lavapipe shades past the
    // triangle's clipped edges (17% of an 80x45 target).
    let bloom = pass(&report, "bloom_extract");
    assert_eq!(bloom["work"]["draws"], 1);
    assert_eq!(bloom["work"]["vertices"], 3);
    assert_eq!(last(bloom, "vertex_invocations"), 3);
    assert_eq!(last(bloom, "clipper_invocations"), 1);
    let area = bloom["work"]["render_area"].as_u64().unwrap();
    let fragments = last(bloom, "fragment_invocations");
    assert!(
        fragments >= area && fragments < area + area / 4,
        "{fragments} fragments over {area} pixels"
    );
    // Passes without draws or dispatches have no counters; every frame has a value.
    assert!(pass(&report, "upload_noise").get("counters").is_none());
    let scene = pass(&report, "scene");
    assert_eq!(
        scene["counters"]["fragment_invocations"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    assert!(last(scene, "fragment_invocations") > 0);
    // The trace carries them as args of each pass's slice.
    let trace: Value = serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let slice = trace["traceEvents"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == "bloom_extract" && e["args"]["frame"] == 1)
        .unwrap();
    assert_eq!(slice["args"]["fragment_invocations"], fragments);
    // Without --counters nothing is counted, and the printed table says what was.
    let plain = framelab(&[
        "replay",
        "captures/example/frame.json",
        "--scale",
        "0.25",
        "--frames",
        "1",
        "--timings",
        dir.join("plain.json").to_str().unwrap(),
    ]);
    assert_eq!(plain.status.code(), Some(0), "{}", stderr(&plain));
    let plain: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("plain.json")).unwrap()).unwrap();
    assert!(pass(&plain, "bloom_extract").get("counters").is_none());
    assert!(pass(&plain, "bloom_extract")["work"]["draws"] == 1);
    let printed = framelab(&[
        "replay",
        "captures/example/frame.json",
        "--scale",
        "0.25",
        "--frames",
        "1",
        "--counters",
    ]);
    let text = stdout(&printed);
    assert!(text.contains("work counters (last frame)"), "{text}");
    let (_, table) = text.split_once("work counters (last frame)").unwrap();
    let row: Vec<&str> = table
        .lines()
        .find(|l| l.starts_with("bloom_extract"))
        .unwrap_or_else(|| panic!("{text}"))
        .split_whitespace()
        .collect();
    // Pass, draws and dispatches, then vertex and clipper invocations.
    assert_eq!(row[1..4], ["1", "3", "1"], "{text}");
}

/// Every bundled capture, replayed twice, counts the same work in every frame.
#[test]
fn two_replays_of_each_bundled_capture_count_the_same() {
    let dir = temp("determinism");
    for (i, (capture, scale)) in [
        ("captures/example/frame.json", "0.25"),
        ("captures/example/frame_sync.json", "0.25"),
        ("captures/night_city/main_street_day.json", "0.125"),
        ("captures/night_city/river_bank_night.json", "0.125"),
    ]
    .into_iter()
    .enumerate()
    {
        let runs: Vec<Value> = (0..2)
            .map(|k| {
                counted(
                    Path::new(capture),
                    scale,
                    "2",
                    &dir.join(format!("{i}-{k}.json")),
                    &[],
                )
            })
            .collect();
        let counters = |r: &Value| -> Vec<(String, Value)> {
            r["passes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    (
                        p["name"].as_str().unwrap().to_owned(),
                        p["counters"].clone(),
                    )
                })
                .collect()
        };
        let (a, b) = (counters(&runs[0]), counters(&runs[1]));
        assert!(
            a.iter().filter(|(_, c)| !c.is_null()).count() >= 3,
            "{capture}"
        );
        assert!(
            a.iter().any(|(_, c)| c["fragment_invocations"]
                .as_array()
                .is_some_and(|v| v[0] != 0)),
            "{capture}"
        );
        for ((name, x), (_, y)) in a.iter().zip(&b) {
            assert_eq!(x, y, "{capture}: pass {name} counted differently");
        }
    }
}

/// The example against itself does the same work; with its bloom threshold pass drawn eight
/// times over, the work diff names that pass's counters and the gate fails.
#[test]
fn the_work_diff_names_the_pass_that_does_more() {
    let dir = temp("work-diff");
    let heavier = crate::common::example_with_bloom_drawn_eight_times(&dir);
    let example = "captures/example/frame.json";
    let scale = ["--scale", "0.25"];

    let same = framelab(
        &[
            &[
                "diff",
                example,
                example,
                "--work",
                "--fail-on-increase",
                "0",
            ][..],
            &scale,
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
    assert!(
        stdout(&same).contains("no pass does different work"),
        "{}",
        stdout(&same)
    );

    let more = framelab(
        &[
            &[
                "diff",
                example,
                heavier.to_str().unwrap(),
                "--work",
                "--fail-on-increase",
                "5",
                "--json",
            ][..],
            &scale,
        ]
        .concat(),
    );
    assert_eq!(
        more.status.code(),
        Some(1),
        "{}{}",
        stdout(&more),
        stderr(&more)
    );
    let d: Value = serde_json::from_str(&stdout(&more)).unwrap();
    let row = d["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "bloom_extract")
        .unwrap();
    let fragments = &row["counters"]["fragment_invocations"];
    assert_eq!(
        fragments["b"].as_u64().unwrap(),
        8 * fragments["a"].as_u64().unwrap()
    );
    assert_eq!(row["work"]["draws"]["b"], 8);
    assert_eq!(row["counters"]["compute_invocations"]["change_pct"], 0.0);
    assert!(
        stderr(&more).contains("work grew past 5%: bloom_extract: "),
        "{}",
        stderr(&more)
    );
    // Only bloom_extract and the frame changed.
    let changed: Vec<&str> = d["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| {
            r["counters"]
                .as_object()
                .unwrap()
                .values()
                .any(|c| c["a"] != c["b"])
        })
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert_eq!(changed, ["(frame)", "bloom_extract"]);
    // Less work never fails the gate; Markdown names the change.
    let less = framelab(
        &[
            &[
                "diff",
                heavier.to_str().unwrap(),
                example,
                "--work",
                "--fail-on-increase",
                "0",
                "--markdown",
            ][..],
            &scale,
        ]
        .concat(),
    );
    assert_eq!(less.status.code(), Some(0), "{}", stderr(&less));
    assert!(
        stdout(&less).contains("| bloom_extract |"),
        "{}",
        stdout(&less)
    );
    assert!(stdout(&less).contains("(-87.5%)"), "{}", stdout(&less));

    // Reports: those written with --counters compare; one without is refused by name.
    let a = dir.join("a.json");
    counted(Path::new(example), "0.25", "1", &a, &[]);
    let bare = dir.join("bare.json");
    let run = framelab(&[
        "replay",
        example,
        "--scale",
        "0.25",
        "--frames",
        "1",
        "--quiet",
        "--timings",
        bare.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let (a, bare) = (a.to_str().unwrap(), bare.to_str().unwrap());
    let out = framelab(&["diff", a, a, "--work", "--fail-on-increase", "0"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = framelab(&["diff", a, bare, "--work"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("has no counters: replay it with --counters"),
        "{}",
        stderr(&out)
    );
    let out = framelab(&["diff", a, bare, "--fail-on-increase", "3"]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "--fail-on-increase needs --work"
    );
}

/// A dispatch that covers a texture runs one thread per texel (rounded up to its workgroup) at
/// whatever scale the frame is replayed: the example's tonemap, given `cover` instead of its
/// 1080p-sized group counts, runs 230400 threads at scale 1 as before, and 15360 at 0.25
/// (160x90 texels in 8x8 groups) where the fixed counts ran 230400.
#[test]
fn a_covering_dispatch_shrinks_with_the_scale() {
    let dir = temp("cover");
    let covered = crate::common::example_changed(&dir, "tonemap", |tonemap| {
        tonemap["dispatches"] = serde_json::json!([{"cover": {"resource": "ldr"}}]);
    });
    let threads = |capture: &Path, scale: &str, name: &str| {
        let r = counted(capture, scale, "1", &dir.join(format!("{name}.json")), &[]);
        let p = pass(&r, "tonemap");
        (
            p["work"]["threads"].as_u64().unwrap(),
            last(p, "compute_invocations"),
        )
    };
    let example = Path::new("captures/example/frame.json");
    assert_eq!(threads(example, "1", "fixed1"), (230_400, 230_400));
    assert_eq!(threads(&covered, "1", "cover1"), (230_400, 230_400));
    assert_eq!(threads(example, "0.25", "fixed025"), (230_400, 230_400));
    assert_eq!(threads(&covered, "0.25", "cover025"), (15_360, 15_360));
}
