//! End-to-end tests of the `framelab` command on the bundled captures: exit codes, the info
//! report against the Night City manifest, scaling, the committed schema, and robustness.

use crate::common::{Scratch, framelab, json, repo, stderr, stdout};

#[test]
fn bundled_captures_are_valid() {
    for capture in [
        "captures/example/frame.json",
        "captures/night_city/main_street_day.json",
        "captures/night_city/river_bank_night.json",
    ] {
        let out = framelab(&["validate", capture]);
        assert_eq!(out.status.code(), Some(0), "{capture}: {}", stderr(&out));
        assert!(stdout(&out).contains("valid"), "{}", stdout(&out));
    }
}

#[test]
fn validate_json_reports_a_valid_capture() {
    let report = json(&framelab(&[
        "validate",
        "--json",
        "captures/example/frame.json",
    ]));
    assert_eq!(report["valid"], true);
    assert_eq!(report["errors"], 0);
}

const NIGHT_CITY: [&str; 2] = [
    "captures/night_city/main_street_day.json",
    "captures/night_city/river_bank_night.json",
];

/// Passes of the manifest the night capture does not have: the billboard copies and the dead
/// LOD pass.
const DAY_ONLY: [&str; 2] = ["billboard_copies", "unknown_color_01"];

/// The machine-readable copy of NIGHT_CITY_PASSES.md, and `info --json` of a capture.
fn night_city_manifest_and_info(capture: &str) -> (serde_json::Value, serde_json::Value) {
    let manifest = serde_json::from_str(
        &std::fs::read_to_string(repo().join("tests/fixtures/night_city_manifest.json")).unwrap(),
    )
    .unwrap();
    let info = json(&framelab(&["info", "--json", capture]));
    (manifest, info)
}

/// The expected resources, typed from NIGHT_CITY_PASSES.md at 1920x1080 (absolute sizes), are
/// compared with what the loader resolves from the capture's relative sizes.
#[test]
fn night_city_info_lists_every_manifest_resource() {
    for capture in NIGHT_CITY {
        night_city_resources_match(capture);
    }
}

fn night_city_resources_match(capture: &str) {
    let (manifest, info) = night_city_manifest_and_info(capture);
    let resources = info["resources"].as_array().unwrap();
    let mut problems = Vec::new();
    for row in manifest["resources"].as_array().unwrap() {
        let row = row.as_array().unwrap();
        let name = row[0].as_str().unwrap();
        let Some(r) = resources.iter().find(|r| r["name"] == name) else {
            problems.push(format!("{name}: missing"));
            continue;
        };
        assert_eq!(r["kind"], row[2], "{name}");
        if row[2] == "buffer" {
            continue;
        }
        let got = [
            &r["format"],
            &r["width"],
            &r["height"],
            &r["depth"],
            &r["array_layers"],
            &r["mip_levels"],
        ];
        let want = [&row[1], &row[3], &row[4], &row[5], &row[6], &row[7]];
        if got != want {
            problems.push(format!("{name}: got {got:?}, manifest says {want:?}"));
        }
    }
    assert!(problems.is_empty(), "{capture}:\n{}", problems.join("\n"));
    assert_eq!(info["width"], 1920);
    assert_eq!(info["height"], 1080);
    let queues: Vec<&str> = info["queues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| q["type"].as_str().unwrap())
        .collect();
    assert_eq!(queues, ["graphics", "compute", "copy"]);
    let cbv = info["descriptor_heaps"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["type"] == "CBV_SRV_UAV")
        .unwrap();
    assert_eq!(cbv["capacity"], 500_000);
}

/// Every pass 1-57 of NIGHT_CITY_PASSES.md exists in both captures (but the day-only ones at
/// night), by its name or as the marker grouping its steps, on the manifest's queues, writing
/// and reading what the manifest says.
#[test]
fn night_city_info_lists_every_manifest_pass() {
    for capture in NIGHT_CITY {
        night_city_passes_match(capture);
    }
}

fn night_city_passes_match(capture: &str) {
    let night = capture.contains("night.json");
    let (manifest, info) = night_city_manifest_and_info(capture);
    let passes = info["passes"].as_array().unwrap();
    let manifest_resources: std::collections::BTreeSet<String> = manifest["resources"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r[0].as_str().unwrap().to_owned())
        .collect();
    let strings = |v: &serde_json::Value| -> std::collections::BTreeSet<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_owned())
            .collect()
    };
    let day_only_writes: std::collections::BTreeSet<String> = manifest["passes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|row| DAY_ONLY.contains(&row[1].as_str().unwrap()))
        .flat_map(|row| strings(&row[3]))
        .collect();
    let mut problems = Vec::new();
    for row in manifest["passes"].as_array().unwrap() {
        let number = row[0].as_u64().unwrap();
        let name = row[1].as_str().unwrap();
        let steps: Vec<&serde_json::Value> = passes
            .iter()
            .filter(|p| {
                p["name"] == name
                    || p["marker_path"]
                        .as_str()
                        .unwrap()
                        .split('/')
                        .any(|m| m == name)
            })
            .collect();
        if night && DAY_ONLY.contains(&name) {
            if !steps.is_empty() {
                problems.push(format!("pass {number} {name}: is day only"));
            }
            continue;
        }
        if steps.is_empty() {
            problems.push(format!("pass {number} {name}: missing"));
            continue;
        }
        let mut queues = std::collections::BTreeSet::new();
        let mut writes = std::collections::BTreeSet::new();
        let mut reads = std::collections::BTreeSet::new();
        for s in &steps {
            queues.insert(s["queue_type"].as_str().unwrap().to_owned());
            writes.extend(strings(&s["writes"]));
            reads.extend(strings(&s["reads"]));
        }
        if queues != strings(&row[2]) {
            problems.push(format!(
                "pass {number} {name}: queues {queues:?}, manifest {}",
                row[2]
            ));
        }
        // Exactly the manifest's writes among the manifest's resources; helpers of our own (a
        // depth buffer for the environment capture) may come on top.
        let declared: std::collections::BTreeSet<String> = writes
            .iter()
            .filter(|w| manifest_resources.contains(*w))
            .cloned()
            .collect();
        if declared != strings(&row[3]) {
            problems.push(format!(
                "pass {number} {name}: writes {declared:?}, manifest {}",
                row[3]
            ));
        }
        // At night nothing writes what the day-only passes would have written.
        let missing: Vec<String> = strings(&row[4])
            .difference(&reads)
            .filter(|r| !(night && day_only_writes.contains(*r)))
            .cloned()
            .collect();
        if !missing.is_empty() {
            problems.push(format!("pass {number} {name}: does not read {missing:?}"));
        }
    }
    assert!(problems.is_empty(), "{capture}:\n{}", problems.join("\n"));
    assert_eq!(manifest["passes"].as_array().unwrap().len(), 57);
}

#[test]
fn scale_resolves_relative_sizes_only() {
    let info = json(&framelab(&[
        "info",
        "--json",
        "--scale",
        "0.25",
        "captures/night_city/main_street_day.json",
    ]));
    let find = |n: &str| {
        info["resources"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == n)
            .unwrap()
            .clone()
    };
    assert_eq!(
        (info["width"].as_u64(), info["height"].as_u64()),
        (Some(480), Some(270))
    );
    let depth = find("depth");
    assert_eq!(
        (depth["width"].as_u64(), depth["height"].as_u64()),
        (Some(480), Some(270))
    );
    let ao = find("ao");
    assert_eq!(
        (ao["width"].as_u64(), ao["height"].as_u64()),
        (Some(240), Some(135))
    );
    // Absolute sizes do not follow the output.
    let csm = find("csm");
    assert_eq!(csm["width"], 4096);
    // Tile grids round up: 480/32 = 15, 270/32 = 8.4 -> 9.
    let clusters = find("cluster_light_index");
    assert_eq!(
        (clusters["width"].as_u64(), clusters["height"].as_u64()),
        (Some(15), Some(9))
    );
}

#[test]
fn info_reports_bytes_and_totals() {
    let info = json(&framelab(&[
        "info",
        "--json",
        "captures/example/frame.json",
    ]));
    let bloom = info["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "bloom")
        .unwrap();
    // R11G11B10: 4 bytes per texel; 320x180 + 160x90 + 80x45.
    assert_eq!(bloom["bytes"], (320 * 180 + 160 * 90 + 80 * 45) * 4);
    assert_eq!(bloom["heap"], "render_targets");
    let passes = info["passes"].as_array().unwrap();
    let scene = passes.iter().find(|p| p["name"] == "scene").unwrap();
    assert_eq!(scene["marker_path"], "Frame/Scene/scene");
    assert_eq!(scene["queue_type"], "graphics");
    let total: u64 = info["resources"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["bytes"].as_u64().unwrap())
        .sum();
    let sum_of_totals: u64 = info["totals"]
        .as_object()
        .unwrap()
        .values()
        .map(|t| t["bytes"].as_u64().unwrap())
        .sum();
    assert_eq!(total, sum_of_totals);
    assert!(info["totals"]["UPLOAD"]["resources"] == 1);
}

#[test]
fn info_text_is_a_table() {
    let out = framelab(&["info", "captures/example/frame.json"]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(text.contains("Passes (9)"), "{text}");
    assert!(
        text.lines().any(|l| l.starts_with("scene_color")
            && l.contains("R16G16B16A16_FLOAT")
            && l.contains("640x360")),
        "{text}"
    );
}

#[test]
fn schema_matches_the_committed_copy() {
    let out = framelab(&["schema"]);
    assert_eq!(out.status.code(), Some(0));
    let committed =
        std::fs::read_to_string(repo().join(framelab_core::schema::COMMITTED_PATH)).unwrap();
    assert!(
        stdout(&out) == committed,
        "{} is stale: run `framelab schema > {}`",
        framelab_core::schema::COMMITTED_PATH,
        framelab_core::schema::COMMITTED_PATH
    );
    let schema: serde_json::Value = serde_json::from_str(&committed).unwrap();
    assert!(schema["$defs"]["Heap"].is_object());
}

#[test]
fn usage_errors_exit_2_and_input_errors_exit_1() {
    assert_eq!(framelab(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(framelab(&["validate"]).status.code(), Some(2));
    assert_eq!(
        framelab(&["info", "--scale", "-1", "captures/example/frame.json"])
            .status
            .code(),
        Some(2)
    );
    let missing = framelab(&["validate", "no/such/capture.json"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(
        stderr(&missing).contains("no/such/capture.json"),
        "{}",
        stderr(&missing)
    );
    let invalid_info = framelab(&["info", "tests/invalid/unknown_format.json"]);
    assert_eq!(invalid_info.status.code(), Some(1));
    assert!(stdout(&invalid_info).is_empty());
}

#[test]
fn garbage_input_never_panics() {
    let dir = Scratch::temp("framelab-garbage");
    let inputs: [&[u8]; 8] = [
        b"",
        b"\xff\xfe\x00garbage",
        b"[]",
        b"null",
        b"{\"format_version\": 1}",
        b"{\"format_version\": -1}",
        b"{\"format_version\": 1e400}",
        b"{\"format_version\":1,\"name\":\"x\",\"resolution\":{\"width\":4294967295,\"height\":4294967295},\"camera\":{\"position\":[0,0,0],\"target\":[0,0,1],\"fov_y_degrees\":60},\"queues\":[{\"name\":\"q\",\"type\":\"graphics\"}],\"resources\":[{\"name\":\"r\",\"kind\":\"texture_3d\",\"format\":\"R32G32B32A32_FLOAT\",\"width\":\"full\",\"height\":\"full\",\"depth\":4294967295,\"mip_levels\":\"full\"}]}",
    ];
    for (i, input) in inputs.iter().enumerate() {
        let file = dir.join(format!("garbage{i}.json"));
        std::fs::write(&file, input).unwrap();
        for cmd in ["validate", "info"] {
            let out = framelab(&[cmd, file.to_str().unwrap()]);
            assert_eq!(
                out.status.code(),
                Some(1),
                "{cmd} on input {i}: {}",
                stderr(&out)
            );
            assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
        }
    }
}

/// Device-opening commands print nothing of their own on stderr when all is well; on a headless
/// machine Mesa's device-select layer used to print an XDG_RUNTIME_DIR error twice.
#[test]
fn opening_the_device_prints_nothing_on_stderr() {
    let out = framelab(&["adapters"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
    let out = framelab(&[
        "replay",
        "captures/example/frame.json",
        "--scale",
        "0.25",
        "--frames",
        "1",
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
}

/// Names longer than a format width (65,535) print in full instead of panicking the tables.
#[test]
fn very_long_names_print_in_tables() {
    let mut capture: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("tests/fixtures/minimal.json")).unwrap(),
    )
    .unwrap();
    let long = format!("simulate_{}", "x".repeat(70_000));
    capture["passes"][0]["name"] = serde_json::Value::String(long.clone());
    capture["passes"][0]["markers"] = serde_json::json!([format!("group_{}", "y".repeat(70_000))]);
    let dir = Scratch::temp("framelab-long");
    std::fs::copy(
        repo().join("tests/fixtures/compute.wgsl"),
        dir.join("compute.wgsl"),
    )
    .unwrap();
    let path = dir.join("long.json");
    std::fs::write(&path, capture.to_string()).unwrap();
    for command in ["info", "analyze"] {
        let out = framelab(&[command, path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            String::from_utf8_lossy(&out.stdout).contains(&long),
            "{command}"
        );
    }
}

/// Every command's help carries an example and a description for each argument; `--version`
/// names the GPU stack; completions are generated; piped errors carry no colour codes.
#[test]
fn help_version_completions_and_plain_errors() {
    let commands = [
        "validate",
        "info",
        "graph",
        "analyze",
        "replay",
        "diff",
        "inspect",
        "schema",
        "adapters",
        "completions",
    ];
    for c in commands {
        let out = framelab(&["help", c]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains("Example: framelab"),
            "{c}: {text}"
        );
        // Long help puts each argument's description on the lines after it.
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let arg = line.starts_with("  <") || line.trim_start().starts_with("--");
            if arg
                && line.starts_with("  ")
                && !line.contains("--help")
                && !line.contains("--version")
            {
                let described = line.trim_start().contains("  ")
                    || lines.get(i + 1).is_some_and(|n| n.trim().len() > 1);
                assert!(described, "{c}: `{}` has no description", line.trim());
            }
        }
    }
    let version = framelab(&["--version"]);
    let text = String::from_utf8_lossy(&version.stdout);
    assert!(
        text.contains("wgpu 30.") && text.contains("naga 30."),
        "{text}"
    );
    let bash = framelab(&["completions", "bash"]);
    assert!(bash.status.success());
    assert!(String::from_utf8_lossy(&bash.stdout).contains("_framelab()"));
    // Piped (as here): no escape codes, even without NO_COLOR.
    let err = framelab(&["graph", "no/such/file.json"]);
    assert_eq!(err.status.code(), Some(1));
    assert!(
        !err.stderr.contains(&0x1b),
        "{}",
        String::from_utf8_lossy(&err.stderr)
    );
}

/// A side file that is a FIFO or a directory is named as such and refused without being read
/// (reading a FIFO would block forever).
#[test]
fn side_files_must_be_regular_files() {
    let dir = Scratch::temp("framelab-fifo");
    std::fs::create_dir_all(dir.join("shaders")).unwrap();
    let example = repo().join("captures/example");
    std::fs::copy(example.join("frame.json"), dir.join("frame.json")).unwrap();
    for f in ["scene.wgsl", "simulate.wgsl", "tonemap.wgsl"] {
        std::fs::copy(example.join("shaders").join(f), dir.join("shaders").join(f)).unwrap();
    }
    let fifo = std::process::Command::new("mkfifo")
        .arg(dir.join("shaders/bloom.wgsl"))
        .status()
        .unwrap();
    assert!(fifo.success());
    let out = framelab(&["validate", dir.join("frame.json").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("\"shaders/bloom.wgsl\" is a named pipe (FIFO), not a regular file"),
        "{err}"
    );
    std::fs::remove_file(dir.join("shaders/bloom.wgsl")).unwrap();
    std::fs::create_dir(dir.join("shaders/bloom.wgsl")).unwrap();
    let out = framelab(&["validate", dir.join("frame.json").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("is a directory, not a regular file"), "{err}");
}

/// Runs `framelab` under a 4 GB address-space limit and a 60 s clock, so that a regression that
/// reads a file without bound fails here instead of exhausting the machine, and one that blocks
/// on a named pipe fails instead of hanging the tests.
fn framelab_bounded(args: &[&str]) -> std::process::Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 4000000; exec timeout 60 "$0" "$@""#)
        .arg(env!("CARGO_BIN_EXE_framelab"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("run framelab")
}

/// Every command that reads a capture refuses a device, a named pipe, a directory and a sparse
/// file of 64 GiB: it exits with an error naming the file and what it is or the limit, without
/// reading it (a FIFO would block, `/dev/zero` and the sparse file would exhaust memory).
#[test]
fn captures_that_are_not_regular_files_or_too_large_are_refused_unread() {
    let dir = Scratch::temp("framelab-bounded");
    let fifo = dir.join("pipe.json");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let big = dir.join("big.json");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(64 << 30)
        .unwrap();
    let folder = dir.join("folder.json");
    std::fs::create_dir(&folder).unwrap();
    let cases = [
        (
            "/dev/zero".to_owned(),
            "cannot read /dev/zero: it is a device, not a regular file".to_owned(),
        ),
        (
            fifo.display().to_string(),
            format!(
                "cannot read {}: it is a named pipe (FIFO), not a regular file",
                fifo.display()
            ),
        ),
        (
            folder.display().to_string(),
            format!(
                "cannot read {}: it is a directory, not a regular file",
                folder.display()
            ),
        ),
        (
            big.display().to_string(),
            format!(
                "{}: 64.0 GiB is over the 256.0 MiB limit for a ",
                big.display()
            ),
        ),
    ];
    for (file, message) in &cases {
        every_reader_refuses(file, message);
    }
}

/// A shader the capture names that is a sparse file of 64 GiB is refused by its size, with the
/// shader limit, and not read.
#[test]
fn a_shader_over_its_limit_is_refused_unread() {
    let dir = Scratch::temp("framelab-big-wgsl");
    std::fs::create_dir_all(dir.join("shaders")).unwrap();
    let example = repo().join("captures/example");
    std::fs::copy(example.join("frame.json"), dir.join("frame.json")).unwrap();
    for f in ["scene.wgsl", "simulate.wgsl", "tonemap.wgsl"] {
        std::fs::copy(example.join("shaders").join(f), dir.join("shaders").join(f)).unwrap();
    }
    let bloom = dir.join("shaders/bloom.wgsl");
    std::fs::File::create(&bloom)
        .unwrap()
        .set_len(64 << 30)
        .unwrap();
    let capture = dir.join("frame.json");
    let capture = capture.to_str().unwrap();
    let message = format!(
        "{}: 64.0 GiB is over the 16.0 MiB limit for a WGSL shader",
        bloom.display()
    );
    every_reader_refuses(capture, &message);
}

/// `import` reads its stream line by line, but only from a regular file.
#[test]
fn import_refuses_a_named_pipe_and_a_device() {
    let dir = Scratch::temp("framelab-import-fifo");
    let fifo = dir.join("app.jsonl");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let out_file = dir.join("x.json");
    for (input, kind) in [
        (fifo.to_str().unwrap(), "a named pipe (FIFO)"),
        ("/dev/zero", "a device"),
    ] {
        let out = framelab_bounded(&["import", input, "-o", out_file.to_str().unwrap()]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{input}: {err}");
        assert!(
            err.contains(&format!("{input} is not a regular file: it is {kind}")),
            "{err}"
        );
        assert!(!out_file.exists());
    }
}

/// `validate`, `info`, `analyze`, `graph` and `diff --structure` (the file on either side) each
/// exit non-zero, without hanging or running out of memory, with `message` on stderr.
fn every_reader_refuses(file: &str, message: &str) {
    let example = "captures/example/frame.json";
    let runs: [Vec<&str>; 6] = [
        vec!["validate", file],
        vec!["info", file],
        vec!["analyze", file],
        vec!["graph", file],
        vec!["diff", "--structure", file, example],
        vec!["diff", "--structure", example, file],
    ];
    for args in &runs {
        let out = framelab_bounded(args);
        let err = stderr(&out);
        let code = out.status.code();
        assert!(
            code.is_some_and(|c| c != 0 && c != 124),
            "{args:?}: {code:?} {err}"
        );
        assert!(err.contains(message), "{args:?}: {err}");
    }
}

/// An output is written where it says, or refused before any work: never over one of the
/// command's inputs, never by replacing a pipe, and through a link to the file it leads to.
#[test]
fn outputs_never_replace_inputs_pipes_or_links() {
    let dir = Scratch::temp("framelab-outputs");
    let capture = dir.join("m.json");
    std::fs::copy(repo().join("tests/fixtures/minimal.json"), &capture).unwrap();
    std::fs::copy(
        repo().join("tests/fixtures/compute.wgsl"),
        dir.join("compute.wgsl"),
    )
    .unwrap();
    let original = std::fs::read(&capture).unwrap();
    let c = capture.to_str().unwrap();
    for args in [
        vec!["graph", c, "--dot", c],
        vec!["replay", c, "--timings", c],
        vec!["replay", c, "--trace", c],
    ] {
        let o = framelab(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("is also what this command reads"),
            "{args:?}: {}",
            stderr(&o)
        );
        assert_eq!(std::fs::read(&capture).unwrap(), original, "{args:?}");
    }
    // A missing folder is made before the work, as `import -o` and `replay --out` make theirs.
    let dot = dir.join("new/deeper/g.dot");
    let o = framelab(&["graph", c, "--dot", dot.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read_to_string(&dot)
            .unwrap()
            .starts_with("digraph")
    );
    let a = repo().join("tests/fixtures/timing/a.json");
    let b = dir.join("b.json");
    std::fs::copy(repo().join("tests/fixtures/timing/b.json"), &b).unwrap();
    let o = framelab(&[
        "diff",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--plot",
        b.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is also what this command reads"),
        "{}",
        stderr(&o)
    );

    let pipe = dir.join("pipe.dot");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&pipe)
            .status()
            .unwrap()
            .success()
    );
    let o = framelab(&["graph", c, "--dot", pipe.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("it is a named pipe"), "{}", stderr(&o));
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::symlink_metadata(&pipe)
            .unwrap()
            .file_type()
            .is_fifo()
    );

    std::os::unix::fs::symlink("graph.dot", dir.join("link.dot")).unwrap();
    let o = framelab(&["graph", c, "--dot", dir.join("link.dot").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(crate::common::is_symlink(&dir.join("link.dot")));
    assert!(
        std::fs::read_to_string(dir.join("graph.dot"))
            .unwrap()
            .starts_with("digraph")
    );
}
