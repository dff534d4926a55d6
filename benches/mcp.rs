//! `framelab mcp` over stdio, as a client sees it: the server is the release binary, spawned
//! with its stdin and stdout piped; Night City's day frame at `--scale 0.5` is opened once,
//! then each question is asked 200 times and the round trip (request written, answer read)
//! timed: `list_passes` (a page of 100 rows), `pass_details` of every pass in turn, and
//! `analyze`. Figures: median and 95th percentile. Then `texture` (replayed on the available
//! adapter): `gbuffer_albedo` after `base_material` the first time (the replay up to it),
//! the same again 20 times (the frame is held there), and after each of the next passes in
//! turn (each replays one more pass).

// A benchmark that cannot set up (no binary, no capture) has nothing to measure: it stops with
// the reason.
#![allow(clippy::expect_used, clippy::unwrap_used)]

use std::io::{BufRead, BufReader, Write};
use std::process::{ChildStdin, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

const CAPTURE: &str = "captures/night_city/main_street_day.json";
const ROUNDS: usize = 200;

struct Client {
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    id: u64,
}

impl Client {
    fn call(&mut self, method: &str, params: Value) -> Value {
        self.id += 1;
        let request = json!({"jsonrpc": "2.0", "id": self.id, "method": method, "params": params});
        writeln!(self.stdin, "{request}").unwrap();
        self.stdin.flush().unwrap();
        let mut line = String::new();
        self.stdout.read_line(&mut line).expect("an answer");
        serde_json::from_str(&line).expect("a JSON-RPC message")
    }

    fn tool(&mut self, name: &str, arguments: Value) -> Value {
        let answer = self.call("tools/call", json!({"name": name, "arguments": arguments}));
        assert_ne!(answer["result"]["isError"], true, "{name}: {answer}");
        answer
    }
}

fn percentiles(mut times: Vec<Duration>) -> (Duration, Duration) {
    times.sort();
    (times[times.len() / 2], times[times.len() * 95 / 100])
}

fn main() {
    let root = env!("CARGO_MANIFEST_DIR");
    let binary = std::path::Path::new(root).join("target/release/framelab");
    assert!(
        binary.exists(),
        "build the release binary first: cargo build --release"
    );
    let mut child = Command::new(&binary)
        .arg("mcp")
        .current_dir(root)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("framelab mcp");
    let mut c = Client {
        stdin: child.stdin.take().unwrap(),
        stdout: BufReader::new(child.stdout.take().unwrap()),
        id: 0,
    };
    c.call(
        "initialize",
        json!({"protocolVersion": "2025-06-18", "capabilities": {}, "clientInfo": {"name": "bench", "version": "1"}}),
    );
    writeln!(
        c.stdin,
        r#"{{"jsonrpc":"2.0","method":"notifications/initialized"}}"#
    )
    .unwrap();
    let start = Instant::now();
    let opened = c.tool("open_capture", json!({"path": CAPTURE, "scale": 0.5}));
    let open_time = start.elapsed();
    let id = opened["result"]["structuredContent"]["capture"]
        .as_str()
        .unwrap()
        .to_owned();
    let page = c.tool("list_passes", json!({"capture": id, "limit": 1000}));
    let passes: Vec<String> = page["result"]["structuredContent"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap().to_owned())
        .collect();
    let time = |c: &mut Client, name: &str, args: &dyn Fn(usize) -> Value| {
        let times: Vec<Duration> = (0..ROUNDS)
            .map(|i| {
                let t = Instant::now();
                c.tool(name, args(i));
                t.elapsed()
            })
            .collect();
        let (median, p95) = percentiles(times);
        println!(
            "{name:<14} median {:>7.3} ms   p95 {:>7.3} ms",
            median.as_secs_f64() * 1e3,
            p95.as_secs_f64() * 1e3
        );
    };
    println!(
        "open_capture   {:.3} s (Night City day at 0.5, {} passes)",
        open_time.as_secs_f64(),
        passes.len()
    );
    time(
        &mut c,
        "list_passes",
        &|i| json!({"capture": id, "offset": (i * 7) % passes.len(), "limit": 100}),
    );
    time(
        &mut c,
        "pass_details",
        &|i| json!({"capture": id, "pass": passes[i % passes.len()]}),
    );
    time(&mut c, "analyze", &|_| json!({"capture": id}));
    let texture = |c: &mut Client, after: &str| {
        let t = Instant::now();
        c.tool(
            "texture",
            json!({"capture": id, "resource": "gbuffer_albedo", "after_pass": after}),
        );
        t.elapsed()
    };
    let first = texture(&mut c, "base_material");
    let (again, _) = percentiles((0..20).map(|_| texture(&mut c, "base_material")).collect());
    // The next passes in the replayed order.
    let analysis = c.tool("analyze", json!({"capture": id}));
    let order: Vec<String> = analysis["result"]["structuredContent"]["order"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_owned())
        .collect();
    let at = order.iter().position(|p| p == "base_material").unwrap();
    let (next, _) = percentiles(
        order[at + 1..at + 11]
            .iter()
            .map(|p| texture(&mut c, p))
            .collect(),
    );
    println!(
        "texture        first {:.3} s, same pass again median {:.1} ms, next pass median {:.1} ms",
        first.as_secs_f64(),
        again.as_secs_f64() * 1e3,
        next.as_secs_f64() * 1e3
    );
    drop(c);
    let _ = child.wait();
}
