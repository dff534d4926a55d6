//! `framelab mcp` held by a client that is not ours (the official Python SDK, in
//! `tests/mcp/session.py`): every tool's answer equals the command line's `--json` for the
//! same capture, bad input gets a tool error naming it and the session goes on. A second test
//! speaks the protocol by hand: a malformed message gets a JSON-RPC error, only protocol
//! reaches stdout, and closing stdin ends the server with exit 0.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

use serde_json::{Value, json};

use crate::common::{Scratch, framelab, json, repo};

const DAY: &str = "captures/night_city/main_street_day.json";
const EXAMPLE: &str = "captures/example/frame.json";
const SYNC: &str = "captures/example/frame_sync.json";

fn cli(args: &[&str]) -> Value {
    let out = framelab(args);
    assert!(out.status.success(), "{args:?}: {out:?}");
    json(&out)
}

/// The session's answers, as `session.py` prints them.
fn session(images: &std::path::Path, captures: &std::path::Path, display: &str) -> Value {
    let out = Command::new("python3")
        .arg(repo().join("tests/mcp/session.py"))
        .arg(env!("CARGO_BIN_EXE_framelab"))
        .arg(repo())
        .arg(images)
        .arg(captures)
        .env("DISPLAY", display)
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "the Python MCP client failed (is `mcp` installed: python3 -m pip install mcp?):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn ok<'a>(answer: &'a Value, what: &str) -> &'a Value {
    answer
        .get("ok")
        .unwrap_or_else(|| panic!("{what}: {answer}"))
}

fn error(answer: &Value) -> &str {
    answer["error"]
        .as_str()
        .unwrap_or_else(|| panic!("no error: {answer}"))
}

#[test]
fn an_independent_client_gets_what_the_command_line_prints() {
    let images = Scratch::temp("framelab-mcp-test");
    // capture_program writes where the client says, inside its roots: a folder in the
    // repository's (ignored) target folder; vkcube gets a virtual X server.
    let captures = Scratch::new(repo().join(format!("target/mcp-capture-{}", std::process::id())));
    let display = crate::common::start_display();
    let s = session(&images, &captures, &display.name);
    assert_eq!(s["server"], "framelab");
    assert_eq!(
        s["tools"],
        json!([
            "analyze",
            "capture_program",
            "close_capture",
            "diff",
            "list_passes",
            "list_resources",
            "open_capture",
            "pass_details",
            "read_buffer",
            "read_texels",
            "texture",
            "timings",
            "what_if"
        ])
    );
    // Every tool describes its input with a JSON Schema naming its fields.
    assert_eq!(
        s["schemas"]["pass_details"]["required"],
        json!(["capture", "pass"])
    );

    let day = cli(&["info", DAY, "--json", "--scale", "0.25"]);
    assert_eq!(day["passes"].as_array().unwrap().len(), 106);
    assert_eq!(
        s["day_passes"], day["passes"],
        "list_passes against info --json"
    );
    assert_eq!(ok(&s["open"]["day"], "open")["passes"], 106);
    let example = cli(&["info", EXAMPLE, "--json"]);
    assert_eq!(
        ok(&s["example_resources"], "list_resources")["rows"],
        example["resources"]
    );
    let csm: Vec<&Value> = day["passes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["name"].as_str().unwrap().contains("csm_"))
        .collect();
    let filtered = ok(&s["filtered"], "filter");
    assert_eq!(filtered["total"], csm.len());
    assert_eq!(filtered["rows"], json!(csm));

    assert_eq!(
        ok(&s["analyze"], "analyze"),
        &cli(&["analyze", EXAMPLE, "--json"])
    );
    assert_eq!(
        ok(&s["analyze_cull"], "analyze cull"),
        &cli(&["analyze", EXAMPLE, "--json", "--cull"])
    );
    // The server names files by their canonical path.
    let (a, b) = (repo().join(EXAMPLE), repo().join(SYNC));
    assert_eq!(
        ok(&s["diff"], "diff"),
        &cli(&[
            "diff",
            "--structure",
            "--json",
            a.to_str().unwrap(),
            b.to_str().unwrap()
        ])
    );

    // One pass: its barriers and DAG neighbours as analyze and graph print them.
    let ssr = ok(&s["ssr_trace"], "pass_details");
    let analysis = cli(&["analyze", DAY, "--json", "--scale", "0.25"]);
    let barriers: Vec<&Value> = analysis["barriers"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["pass"] == "ssr_trace")
        .collect();
    assert!(!barriers.is_empty());
    assert_eq!(ssr["derived_barriers"], json!(barriers));
    let graph = cli(&["graph", DAY, "--json"]);
    let before: Vec<&Value> = graph["edges"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["to"] == "ssr_trace")
        .collect();
    assert!(!before.is_empty());
    assert_eq!(ssr["dag"]["before"], json!(before));
    assert_eq!(ssr["recorded"]["name"], "ssr_trace");
    let row = day["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "ssr_trace")
        .unwrap();
    assert_eq!(&ssr["pass"], row);

    // Bad input: a tool error that names the problem, and the session goes on.
    let bad = &s["bad"];
    assert!(error(&bad["unknown_capture"]).contains("no capture id \"c99\""));
    assert!(error(&bad["unknown_pass"]).contains("did you mean \"ssr_trace\""));
    assert!(error(&bad["schema"]).contains("input schema"));
    assert!(error(&bad["unknown_field"]).contains("unknown field `colour`"));
    assert!(error(&bad["bad_mode"]).contains("unknown variant `pixels`"));
    assert!(error(&bad["outside_roots"]).contains("outside the client's roots"));
    assert!(error(&bad["does_not_load"]).contains("error[copy]"));
    assert!(error(&bad["too_many_rows"]).contains("1000 rows"));
    assert_eq!(
        ok(&s["after_bad"], "after")["rows"]
            .as_array()
            .unwrap()
            .len(),
        1
    );
    assert!(ok(&s["closed"], "close")["closed"].is_string());
    assert!(error(&s["after_close"]).contains("no capture id"));
    imports(&s["imports"], &images);
    textures(&s["textures"], &images);
    timings(&s);
    assert_eq!(
        ok(&s["after_cancel"], "after cancel")["rows"]
            .as_array()
            .unwrap()
            .len(),
        1
    );
    // The cancelled texture request stopped its replay between passes.
    let log = std::fs::read_to_string(images.join("server.log")).unwrap();
    assert!(
        log.contains("river_bank_night: replay cancelled before pass"),
        "{log}"
    );
    // capture_program: vkcube's frame 3 taken, imported into the folder and opened.
    let taken = ok(&s["capture_program"], "capture_program");
    assert!(captures.join("vkcube_frame3.gfxr").exists());
    assert!(captures.join("vkcube_frame3.json").exists());
    assert!(taken["passes"].as_u64().unwrap() >= 2);
    let info = cli(&[
        "info",
        captures.join("vkcube_frame3.json").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(
        ok(&s["captured_passes"], "captured")["rows"],
        info["passes"]
    );
    assert!(error(&s["capture_outside"]).contains("outside the client's roots"));
}

/// `texture` answers: the PNG equals what `replay --after` exports, a second request for the
/// same pass replays nothing, an earlier pass shows the frame's starting contents, progress
/// counts the passes, and bad requests are tool errors.
fn textures(t: &Value, images: &std::path::Path) {
    let ldr = ok(&t["ldr"], "texture ldr");
    assert_eq!(t["ldr"]["mime"], "image/png");
    assert_eq!(ldr["format"], "R8G8B8A8_UNORM");
    assert_eq!(ldr["written_this_frame"], true);
    let progress = t["ldr"]["progress"].as_array().unwrap();
    assert!(!progress.is_empty(), "no progress reported");
    let last = progress.last().unwrap();
    assert_eq!(last[0], last[1], "progress ends at its total: {last}");
    assert_eq!(
        t["ldr_again"]["progress"],
        json!([]),
        "the held frame replays nothing again"
    );
    let out = images.join("export");
    let exported = framelab(&[
        "replay",
        EXAMPLE,
        "--frames",
        "1",
        "--after",
        "tonemap",
        "--resource",
        "ldr",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(exported.status.success(), "{exported:?}");
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let file = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["resource"] == "ldr")
        .unwrap()["file"]
        .as_str()
        .unwrap()
        .to_owned();
    let want = image::open(out.join(file)).unwrap().to_rgba8();
    let got = image::open(images.join("ldr.png")).unwrap().to_rgba8();
    assert_eq!(got.dimensions(), want.dimensions());
    assert!(
        got == want,
        "the MCP texture differs from replay --after's export"
    );
    assert_eq!(ldr["width"], want.width());

    let albedo = ok(&t["albedo"], "albedo");
    let day = cli(&["info", DAY, "--json", "--scale", "0.25"]);
    let row = day["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "gbuffer_albedo")
        .unwrap();
    assert_eq!(albedo["width"], row["width"]);
    let png = image::open(images.join("albedo.png")).unwrap();
    assert_eq!(json!(png.width()), row["width"]);
    let small = image::open(images.join("albedo_small.png")).unwrap();
    assert_eq!(
        small.width().max(small.height()),
        100,
        "max_size bounds the longest side"
    );
    let before = ok(&t["albedo_before"], "before");
    assert_eq!(before["written_this_frame"], false);
    assert_eq!(
        before["max"],
        json!([0.0, 0.0, 0.0, 0.0]),
        "the frame's starting contents"
    );
    assert!(albedo["max"][0].as_f64().unwrap() > 0.5);
    assert!(error(&t["buffer"]).contains("is a buffer"));
    // The texels are the values the PNG shows (8-bit unorm: value x 255).
    let texels = ok(&t["texels"], "texels");
    assert_eq!(
        texels["region"],
        json!({"x": 10, "y": 20, "width": 3, "height": 2})
    );
    for (dy, row) in texels["values"].as_array().unwrap().iter().enumerate() {
        for (dx, v) in row.as_array().unwrap().iter().enumerate() {
            let p = got.get_pixel(10 + dx as u32, 20 + dy as u32);
            for c in 0..3 {
                let value = v[c].as_f64().unwrap();
                assert_eq!(
                    (value * 255.0).round() as u8,
                    p[c],
                    "texel ({dx},{dy}) channel {c}"
                );
            }
        }
    }
    assert!(error(&t["texels_too_many"]).contains("4096 texels"));
    assert!(error(&t["texels_outside"]).contains("outside"));
    assert!(error(&t["bad_mip"]).contains("mip 3"));
    buffers(t);
    assert!(error(&t["bad_size"]).contains("max_size"));
}

/// `open_capture` on a binary capture and a JSON Lines stream: the passes `framelab import`
/// then `info --json` give.
fn imports(i: &Value, scratch: &std::path::Path) {
    for name in ["vkcube_f3.gfxr", "vkcube_f3.jsonl"] {
        let opened = ok(&i[name]["open"], name);
        assert_eq!(opened["imported"], true);
        let out = scratch.join(format!("{name}.json"));
        let imported = framelab(&[
            "import",
            crate::common::gfxr_fixture(name).to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(imported.status.success(), "{imported:?}");
        let info = cli(&["info", out.to_str().unwrap(), "--json"]);
        assert_eq!(
            ok(&i[name]["passes"], name)["rows"],
            info["passes"],
            "{name}"
        );
        assert!(!info["passes"].as_array().unwrap().is_empty());
    }
}

/// `read_buffer`: the indirect arguments the simulation writes, read as the records they
/// are; particle rows decoded as the WGSL struct, equal to the hex bytes read as floats.
fn buffers(t: &Value) {
    let cleared = ok(&t["args_cleared"], "cleared");
    assert_eq!(
        cleared["hex"],
        "0".repeat(40),
        "reset_args clears the 20 bytes"
    );
    let args = ok(&t["args"], "draw_args");
    assert_eq!(args["as"]["type"], "DrawIndexedIndirectArgs");
    let row = &args["as"]["rows"][0]["fields"];
    // One instance per particle: 4096 bytes of 16-byte particles, every one alive.
    assert_eq!(row["instance_count"], "256");
    assert_eq!(row["first_index"], "0");
    let p = ok(&t["particles"], "particles");
    assert_eq!(p["as"]["type"], "Particle");
    assert_eq!(p["length"], 64);
    let hex = p["hex"].as_str().unwrap();
    let bytes: Vec<u8> = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect();
    let rows = p["as"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r["index"], 1 + k);
        let floats: Vec<f32> = bytes[k * 16..k * 16 + 16]
            .chunks(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let shown: Vec<f32> = r["fields"]["position_radius"]
            .as_str()
            .unwrap()
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(shown, floats, "row {k}");
    }
    assert!(error(&t["buffer_texture"]).contains("read it with read_texels"));
    assert!(error(&t["buffer_too_long"]).contains("65536 bytes"));
}

/// `timings`: the report `replay --timings` writes, for the same frames.
fn timings(s: &Value) {
    let report = ok(&s["timings"], "timings");
    let dir = Scratch::temp("framelab-mcp-t");
    let file = dir.join("t.json");
    let out = framelab(&[
        "replay",
        EXAMPLE,
        "--frames",
        "2",
        "--timings",
        file.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success(), "{out:?}");
    let cli: Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    for key in [
        "format_version",
        "capture",
        "capture_sha256",
        "frames",
        "scale",
        "adapter",
    ] {
        assert_eq!(report[key], cli[key], "{key}");
    }
    let names = |r: &Value| -> Vec<Value> {
        r["passes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].clone())
            .collect()
    };
    assert_eq!(names(report), names(&cli));
    assert_eq!(s["timings"]["progress"], json!([[1.0, 2.0], [2.0, 2.0]]));
    assert!(error(&s["timings_bad"]).contains("frames 1000"));
    // A timing diff: the report `framelab diff` prints for the same two captures (times
    // differ run to run; its shape and rows do not).
    let d = ok(&s["diff_timing"], "diff timing");
    // Exit 1 is a regression verdict, which noise over 3 frames may give.
    let out = framelab(&[
        "diff", EXAMPLE, SYNC, "--frames", "3", "--warmup", "0", "--json",
    ]);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{out:?}");
    let cli = json(&out);
    let keys = |v: &Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    assert_eq!(keys(d), keys(&cli));
    // Rows are ordered by their change, which noise moves: compared as sets.
    let rows = |v: &Value| -> Vec<String> {
        let mut names: Vec<String> = v["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["name"].as_str().unwrap().to_owned())
            .collect();
        names.sort();
        names
    };
    assert_eq!(rows(d), rows(&cli));
    assert!(!rows(d).is_empty());
    assert!(error(&s["diff_structure_frames"]).contains("timing only"));
    // Work: exact counts, so the server's diff is the command line's, value for value.
    let out = framelab(&["diff", EXAMPLE, SYNC, "--work", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert_eq!(ok(&s["diff_work"], "diff work"), &json(&out));
    // what_if: the command line's edits and verdicts, each changed texture as two PNGs.
    let what = ok(&s["what_if"], "what_if");
    assert_eq!(what["safe"], true);
    assert_eq!(
        what["changes"][0],
        "\"bloom\" R16G16B16A16_FLOAT -> R11G11B10_FLOAT"
    );
    let changed = what["changed"].as_array().unwrap();
    assert!(changed.iter().any(|c| c["name"] == "bloom"), "{what}");
    assert_eq!(
        s["what_if"]["images"].as_array().unwrap().len(),
        2 * changed.len()
    );
    assert_eq!(what["passes_changed"][0]["pass"], "bright_pass");
    let unsafe_edit = ok(&s["what_if_unsafe"], "what_if unsafe");
    assert_eq!(unsafe_edit["safe"], false);
    assert_eq!(unsafe_edit["static"]["introduced"][0]["code"], "FL020");
    assert!(unsafe_edit.get("timing").is_none());
    let bad = s["what_if_bad"]["error"].as_str().unwrap();
    assert!(bad.contains("no pass \"nope\""), "{bad}");
    let counted = ok(&s["timings_counted"], "timings with counters");
    let out = framelab(&[
        "replay",
        EXAMPLE,
        "--frames",
        "1",
        "--counters",
        "--timings",
        file.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let cli: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let counters = |r: &Value| -> Vec<Value> {
        r["passes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["counters"].clone())
            .collect()
    };
    assert_eq!(counters(counted), counters(&cli));
    assert!(
        counters(&cli)
            .iter()
            .any(|c| c["fragment_invocations"][0].as_u64() > Some(0))
    );
    assert!(
        counters(ok(&s["timings"], "timings"))
            .iter()
            .all(Value::is_null)
    );
}

/// `framelab mcp` with its stdin and stdout piped to the test.
fn server(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_framelab"))
        .arg("mcp")
        .args(args)
        .current_dir(repo())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Sends `lines` (then closes stdin) and returns every stdout line as JSON and the exit code.
fn raw_session(args: &[&str], lines: &[&str]) -> (Vec<Value>, Option<i32>) {
    let mut child = server(args);
    let mut stdin = child.stdin.take().unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let mut answers = Vec::new();
    let mut lines_out = stdout.lines();
    for line in lines {
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
        // Requests (with an id) and bad lines get an answer; wait for it before the next.
        let expects = serde_json::from_str::<Value>(line)
            .map_or(true, |v| !v.is_object() || v.get("id").is_some());
        if expects {
            let text = lines_out.next().unwrap().unwrap();
            answers.push(
                serde_json::from_str(&text)
                    .unwrap_or_else(|e| panic!("stdout line is not JSON ({e}): {text}")),
            );
        }
    }
    drop(stdin);
    for rest in lines_out {
        let text = rest.unwrap();
        answers.push(serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}")));
    }
    (answers, child.wait().unwrap().code())
}

#[test]
fn malformed_messages_get_json_rpc_errors_and_closing_stdin_exits_zero() {
    let (answers, code) = raw_session(
        &[],
        &[
            r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"protocolVersion":"2025-06-18","capabilities":{},"clientInfo":{"name":"raw","version":"1"}}}"#,
            r#"{"jsonrpc":"2.0","method":"notifications/initialized"}"#,
            "this is not json",
            r#"{"jsonrpc":"2.0","id":2}"#,
            r#"[1, 2, 3]"#,
            r#"{"jsonrpc":"2.0","id":3,"method":"tools/list"}"#,
            r#"{"jsonrpc":"2.0","id":4,"method":"tools/call","params":{"name":"no_such_tool","arguments":{}}}"#,
            r#"{"jsonrpc":"2.0","id":5,"method":"tools/call","params":{"name":"open_capture","arguments":{"path":"captures/example/frame.json"}}}"#,
        ],
    );
    assert_eq!(code, Some(0), "closing stdin ends the server cleanly");
    assert!(answers.iter().all(|a| a["jsonrpc"] == "2.0"), "{answers:?}");
    assert_eq!(answers[0]["result"]["serverInfo"]["name"], "framelab");
    assert_eq!(answers[1]["error"]["code"], -32700);
    assert_eq!(answers[2]["error"]["code"], -32600);
    assert_eq!(answers[2]["id"], 2);
    assert_eq!(answers[3]["error"]["code"], -32600);
    assert_eq!(answers[4]["id"], 3);
    assert_eq!(answers[4]["result"]["tools"].as_array().unwrap().len(), 13);
    assert_eq!(answers[5]["id"], 4);
    assert!(answers[5].get("error").is_some() || answers[5]["result"]["isError"] == true);
    assert_eq!(answers[6]["result"]["structuredContent"]["capture"], "c1");
    assert_eq!(answers.len(), 7, "{answers:?}");
}

/// `--root` bounds what the server reads, beside the client's roots: a capture outside it is
/// refused, one inside opens; a `--root` that does not exist stops the server at start.
#[test]
fn files_outside_the_servers_root_are_refused() {
    const INIT: &str = r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"protocolVersion":"2025-06-18","capabilities":{},"clientInfo":{"name":"raw","version":"1"}}}"#;
    let open = |path: &str| {
        format!(
            r#"{{"jsonrpc":"2.0","id":2,"method":"tools/call","params":{{"name":"open_capture","arguments":{{"path":"{path}"}}}}}}"#
        )
    };
    let (answers, code) = raw_session(&["--root", "captures/night_city"], &[INIT, &open(EXAMPLE)]);
    assert_eq!(code, Some(0));
    let text = answers[1]["result"]["content"][0]["text"].as_str().unwrap();
    assert_eq!(answers[1]["result"]["isError"], true);
    assert!(text.contains("outside the server's --root"), "{text}");
    let (answers, _) = raw_session(&["--root", "captures/night_city"], &[INIT, &open(DAY)]);
    assert_eq!(answers[1]["result"]["structuredContent"]["passes"], 106);
    let out = framelab(&["mcp", "--root", "no/such/folder"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(crate::common::stderr(&out).contains("--root no/such/folder"));
}

/// A seeded source of choices for the request fuzzer, so a failure can be replayed.
struct Rng(rand::rngs::StdRng);

impl Rng {
    fn next(&mut self) -> u64 {
        rand::RngExt::random(&mut self.0)
    }
    fn below(&mut self, n: usize) -> usize {
        rand::RngExt::random_range(&mut self.0, 0..n)
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// A value a hostile client puts where an argument goes.
fn hostile(rng: &mut Rng, depth: u32) -> Value {
    match rng.below(if depth > 3 { 9 } else { 11 }) {
        0 => Value::Null,
        1 => json!(rng.next() as i64),
        2 => json!(u64::MAX),
        3 => json!(-1e308),
        4 => json!(*rng.pick(&["c1", "c2", "c99", "", "scene", "ssr_trace", "bloom"])),
        5 => json!(*rng.pick(&[
            "captures/example/frame.json",
            "captures/night_city/river_bank_night.json",
            "/etc/passwd",
            "/dev/zero",
            "tests/invalid/copy_overrun.json",
            "../../../../etc/shadow",
            "captures",
        ])),
        6 => json!("x".repeat(rng.below(100_000))),
        7 => json!(rng.below(2) == 0),
        8 => json!(*rng.pick(&["structure", "timing", "work", "pixels"])),
        9 => Value::Array((0..rng.below(4)).map(|_| hostile(rng, depth + 1)).collect()),
        _ => {
            let mut m = serde_json::Map::new();
            for _ in 0..rng.below(4) {
                let key = *rng.pick(&[
                    "capture", "pass", "path", "limit", "offset", "mode", "a", "b", "cull",
                    "scale", "filter", "zz",
                ]);
                m.insert(key.to_owned(), hostile(rng, depth + 1));
            }
            Value::Object(m)
        }
    }
}

/// One line of the fuzz session, and whether the server owes an answer to it.
fn fuzz_line(rng: &mut Rng, id: u64) -> (String, bool) {
    const TOOLS: &[&str] = &[
        "open_capture",
        "list_passes",
        "list_resources",
        "pass_details",
        "analyze",
        "diff",
        "close_capture",
        "what_if",
        "no_such_tool",
    ];
    const KEYS: &[&str] = &[
        "capture",
        "pass",
        "path",
        "limit",
        "offset",
        "mode",
        "a",
        "b",
        "cull",
        "scale",
        "filter",
        "resource",
        "after_pass",
        "mip",
        "max_size",
    ];
    match rng.below(10) {
        // Bytes that are not JSON (no newline: the line ends where the test says).
        0 => {
            let n = rng.below(300);
            let text: String = (0..n)
                .map(|_| char::from(32 + rng.below(95) as u8))
                .collect();
            (format!("{{{text}"), true)
        }
        // JSON that is no JSON-RPC request.
        1 => (hostile(rng, 0).to_string(), true),
        // A request of a method the server does not have.
        2 => (
            json!({"jsonrpc": "2.0", "id": id, "method": rng.pick(&["resources/list", "x", "tools/lis"]), "params": hostile(rng, 1)}).to_string(),
            true,
        ),
        // A valid call of a tool, mutated half the time: a key dropped, a value replaced by
        // a hostile one, or a key no tool takes.
        _ => {
            // A texture replays: one call in a hundred, on the small example capture.
            let tool = if rng.below(100) == 0 {
                "texture"
            } else {
                *rng.pick(TOOLS)
            };
            let capture = json!(*rng.pick(&["c1", "c2"]));
            let mut args = match tool {
                "open_capture" => json!({"path": EXAMPLE, "scale": 0.25}),
                "list_passes" | "list_resources" => json!({
                    "capture": capture,
                    "offset": rng.below(120),
                    "limit": rng.below(200),
                    "filter": *rng.pick(&["", "s", "csm", "bloom"]),
                }),
                "pass_details" => json!({
                    "capture": capture,
                    "pass": *rng.pick(&["scene", "tonemap", "ssr_trace", "csm_cascade_0", "bloom_mips"]),
                }),
                "analyze" => json!({"capture": capture, "cull": rng.below(2) == 0}),
                "diff" => json!({"a": "c1", "b": capture, "mode": "structure"}),
                "close_capture" => json!({"capture": format!("c{}", 3 + rng.below(10))}),
                // Edits that name nothing: refused before anything replays.
                "what_if" => json!({
                    "capture": capture,
                    "cull": [*rng.pick(&["nope", "", "scene "])],
                    "drop_barrier": [*rng.pick(&["scene:99", "tonemap:7", "x"])],
                }),
                "texture" => json!({
                    "capture": "c1",
                    "resource": *rng.pick(&["ldr", "bloom", "scene_color", "depth"]),
                    "after_pass": *rng.pick(&["scene", "bloom_extract", "tonemap"]),
                    "max_size": 1 + rng.below(300),
                }),
                _ => json!({}),
            };
            if rng.below(2) == 0
                && let Some(map) = args.as_object_mut()
            {
                let keys: Vec<String> = map.keys().cloned().collect();
                match (rng.below(3), keys.is_empty()) {
                    (0, false) => {
                        map.remove(&keys[rng.below(keys.len())]);
                    }
                    (1, false) => {
                        let value = hostile(rng, 1);
                        map.insert(keys[rng.below(keys.len())].clone(), value);
                    }
                    _ => {
                        let value = hostile(rng, 1);
                        map.insert((*rng.pick(KEYS)).to_owned(), value);
                    }
                }
            }
            let params = if rng.below(50) == 0 {
                hostile(rng, 1)
            } else {
                json!({"name": tool, "arguments": args})
            };
            (
                json!({"jsonrpc": "2.0", "id": id, "method": "tools/call", "params": params})
                    .to_string(),
                true,
            )
        }
    }
}

/// 10,000 random and mutated requests in one session: every line gets an answer, the server
/// answers a normal request after them, its memory stays bounded, and closing stdin still
/// ends it with exit 0.
#[test]
fn ten_thousand_hostile_requests_leave_the_server_answering() {
    let mut child = server(&[]);
    let pid = child.id();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    // Answers are read on their own thread, so neither pipe fills while the other waits.
    let reader = std::thread::spawn(move || {
        stdout
            .lines()
            .map(|l| serde_json::from_str::<Value>(&l.unwrap()).expect("stdout is protocol"))
            .collect::<Vec<Value>>()
    });
    let mut stdin = child.stdin.take().unwrap();
    writeln!(stdin, r#"{{"jsonrpc":"2.0","id":0,"method":"initialize","params":{{"protocolVersion":"2025-06-18","capabilities":{{}},"clientInfo":{{"name":"fuzz","version":"1"}}}}}}"#).unwrap();
    writeln!(
        stdin,
        r#"{{"jsonrpc":"2.0","method":"notifications/initialized"}}"#
    )
    .unwrap();
    // Two captures open first, so that the ids the fuzzer sends (c1, c2) often name one.
    for (id, path) in [
        (-1, EXAMPLE),
        (-2, "captures/night_city/river_bank_night.json"),
    ] {
        writeln!(stdin, r#"{{"jsonrpc":"2.0","id":{id},"method":"tools/call","params":{{"name":"open_capture","arguments":{{"path":"{path}","scale":0.25}}}}}}"#).unwrap();
    }
    let mut rng = Rng(rand::SeedableRng::seed_from_u64(0x9e37_79b9_7f4a_7c15));
    let mut owed = 3;
    let cases = std::env::var("FRAMELAB_FUZZ_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(10_000u64);
    for id in 1..=cases {
        let (line, answered) = fuzz_line(&mut rng, id);
        writeln!(stdin, "{line}").unwrap();
        owed += usize::from(answered);
    }
    let last = cases + 1;
    writeln!(
        stdin,
        r#"{{"jsonrpc":"2.0","id":{last},"method":"tools/list"}}"#
    )
    .unwrap();
    owed += 1;
    stdin.flush().unwrap();
    // The peak memory of the server, read before it exits.
    std::thread::sleep(std::time::Duration::from_secs(2));
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    drop(stdin);
    let answers = reader.join().unwrap();
    let code = child.wait().unwrap().code();
    assert_eq!(code, Some(0), "the server did not exit cleanly");
    assert_eq!(
        answers.len(),
        owed,
        "every request and bad line answered once"
    );
    let final_answer = answers.iter().find(|a| a["id"] == last).unwrap();
    let answered = |ok: bool| {
        answers
            .iter()
            .filter(|a| a["result"]["content"].is_array() && (a["result"]["isError"] != true) == ok)
            .count()
    };
    // Both kinds happen: tools that answered and tool errors.
    assert!(
        answered(true) > 100,
        "{} tool calls answered",
        answered(true)
    );
    assert!(answered(false) > 1000, "{} tool errors", answered(false));
    assert_eq!(
        final_answer["result"]["tools"].as_array().unwrap().len(),
        13
    );
    let peak_kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches(" kB").trim().parse().ok())
        .unwrap_or(0);
    assert!(peak_kb > 0, "no VmHWM in /proc/{pid}/status");
    assert!(peak_kb < 1_000_000, "the server peaked at {peak_kb} kB");
}
