//! `framelab mcp` held by a client that is not ours (the official Python SDK, in
//! `tests/mcp/session.py`): every tool's answer equals the command line's `--json` for the
//! same capture, bad input gets a tool error naming it and the session goes on. A second test
//! speaks the protocol by hand: a malformed message gets a JSON-RPC error, only protocol
//! reaches stdout, and closing stdin ends the server with exit 0.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

use serde_json::{Value, json};

use crate::common::{framelab, json, repo};

const DAY: &str = "captures/night_city/main_street_day.json";
const EXAMPLE: &str = "captures/example/frame.json";
const SYNC: &str = "captures/example/frame_sync.json";

fn cli(args: &[&str]) -> Value {
    let out = framelab(args);
    assert!(out.status.success(), "{args:?}: {out:?}");
    json(&out)
}

/// The session's answers, as `session.py` prints them.
fn session() -> Value {
    let out = Command::new("python3")
        .arg(repo().join("tests/mcp/session.py"))
        .arg(env!("CARGO_BIN_EXE_framelab"))
        .arg(repo())
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
    let s = session();
    assert_eq!(s["server"], "framelab");
    assert_eq!(
        s["tools"],
        json!([
            "analyze",
            "close_capture",
            "diff",
            "list_passes",
            "list_resources",
            "open_capture",
            "pass_details"
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
}

/// Sends `lines` (then closes stdin) and returns every stdout line as JSON and the exit code.
fn raw_session(lines: &[&str]) -> (Vec<Value>, Option<i32>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_framelab"))
        .arg("mcp")
        .current_dir(repo())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
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
    let (answers, code) = raw_session(&[
        r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"protocolVersion":"2025-06-18","capabilities":{},"clientInfo":{"name":"raw","version":"1"}}}"#,
        r#"{"jsonrpc":"2.0","method":"notifications/initialized"}"#,
        "this is not json",
        r#"{"jsonrpc":"2.0","id":2}"#,
        r#"[1, 2, 3]"#,
        r#"{"jsonrpc":"2.0","id":3,"method":"tools/list"}"#,
        r#"{"jsonrpc":"2.0","id":4,"method":"tools/call","params":{"name":"no_such_tool","arguments":{}}}"#,
        r#"{"jsonrpc":"2.0","id":5,"method":"tools/call","params":{"name":"open_capture","arguments":{"path":"captures/example/frame.json"}}}"#,
    ]);
    assert_eq!(code, Some(0), "closing stdin ends the server cleanly");
    assert!(answers.iter().all(|a| a["jsonrpc"] == "2.0"), "{answers:?}");
    assert_eq!(answers[0]["result"]["serverInfo"]["name"], "framelab");
    assert_eq!(answers[1]["error"]["code"], -32700);
    assert_eq!(answers[2]["error"]["code"], -32600);
    assert_eq!(answers[2]["id"], 2);
    assert_eq!(answers[3]["error"]["code"], -32600);
    assert_eq!(answers[4]["id"], 3);
    assert_eq!(answers[4]["result"]["tools"].as_array().unwrap().len(), 7);
    assert_eq!(answers[5]["id"], 4);
    assert!(answers[5].get("error").is_some() || answers[5]["result"]["isError"] == true);
    assert_eq!(answers[6]["result"]["structuredContent"]["capture"], "c1");
    assert_eq!(answers.len(), 7, "{answers:?}");
}
