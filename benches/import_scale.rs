//! `framelab import` as a capture grows, side by side with `gfxrecon-convert` of the same
//! file: synthetic frames of 10,000, 30,000 and 100,000 buffers (the largest 1.2 million
//! calls), each made once by replaying a framelab frame under GFXReconstruct's capture layer,
//! as the synchronization benchmark makes its stream. Both tools run as whole processes, in
//! turn, best of three, with each process's peak resident memory as GNU time reports it. Time
//! and memory per call should stay flat as the capture grows: anything quadratic in resources,
//! barriers or passes shows as a per-call cost that climbs.
//!
//! `cargo bench --bench import_scale` prints the table; `FRAMELAB_SCALE=10000` keeps the
//! sizes whose buffer count is listed (comma-separated).

#![allow(clippy::expect_used)]

// Only its capturing is used here, not the stream it is named for.
#[allow(dead_code)]
#[path = "common/sync_stream.rs"]
mod sync_stream;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Buffers and passes of each size: each copy pass copies between 200 pairs of buffers drawn
/// at random, and one pass in ten is a compute pass instead. The two larger frames hold more
/// copies and barriers than one import emits (`MAX_WORK`): every call is still read, every
/// object tracked and every command walked, but passes stop being emitted at the ceiling and
/// the frame is refused for replay; the table says how much work each import kept.
const SIZES: [(usize, usize); 3] = [(10_000, 200), (30_000, 600), (100_000, 2_000)];
const COPIES: usize = 200;
const ROUNDS: usize = 3;

/// A framelab frame of `buffers` buffers and `passes` passes, the buffers drawn by a fixed
/// linear congruential sequence.
fn frame_json(buffers: usize, passes: usize) -> String {
    let mut x: u64 = 12345;
    let mut pair = || {
        let mut next = || {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (x >> 33) as usize % buffers
        };
        let a = next();
        let b = next();
        (a, if a == b { (a + 1) % buffers } else { b })
    };
    let resources: Vec<String> = (0..buffers)
        .map(|i| format!(r#"{{"name":"buf{i}","kind":"buffer","buffer_kind":"structured","stride":16,"size":256,"flags":["ALLOW_UNORDERED_ACCESS"]}}"#))
        .collect();
    let passes: Vec<String> = (0..passes)
        .map(|p| {
            if p % 10 == 0 {
                let (a, b) = pair();
                return format!(
                    r#"{{"name":"pass{p}","queue":"gfx","kind":"compute","shader":{{"file":"compute.wgsl","compute":"cs_main"}},"bindings":{{"particles":{{"resource":"buf{a}","access":"storage_read_write"}},"draw_args":{{"resource":"buf{b}","access":"storage_read_write"}}}},"dispatches":[{{"groups":[1,1,1]}}]}}"#
                );
            }
            let copies: Vec<String> = (0..COPIES)
                .map(|_| {
                    let (a, b) = pair();
                    format!(r#"{{"src":{{"resource":"buf{a}","size":256}},"dst":{{"resource":"buf{b}","size":256}}}}"#)
                })
                .collect();
            format!(
                r#"{{"name":"copy{p}","queue":"gfx","kind":"copy","copies":[{}]}}"#,
                copies.join(",")
            )
        })
        .collect();
    format!(
        r#"{{"format_version":1,"name":"scale","resolution":{{"width":64,"height":64}},"camera":{{"position":[0,2,-10],"target":[0,0,0],"fov_y_degrees":60}},"queues":[{{"name":"gfx","type":"graphics"}}],"resources":[{}],"passes":[{}]}}"#,
        resources.join(","),
        passes.join(",")
    )
}

/// One run of `program` with `args` under GNU time (Debian's `time`): its wall time, peak
/// resident memory in bytes and standard output.
fn run(program: &str, args: &[&std::ffi::OsStr]) -> (Duration, u64, String) {
    let report = std::env::temp_dir().join(format!("framelab-scale-{}.time", std::process::id()));
    let start = Instant::now();
    let out = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%M")
        .arg("-o")
        .arg(&report)
        .arg(program)
        .args(args)
        .stderr(std::process::Stdio::null())
        .output()
        .expect("/usr/bin/time (Debian package `time`)");
    let took = start.elapsed();
    assert!(out.status.success(), "{program} {args:?} failed");
    // GNU time's `%M` is the peak resident set in KiB.
    let kib: u64 = std::fs::read_to_string(&report)
        .ok()
        .and_then(|t| t.trim().parse().ok())
        .unwrap_or(0);
    let _ = std::fs::remove_file(&report);
    (
        took,
        kib * 1024,
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// Best time and largest peak of `ROUNDS` runs, with the first run's output.
fn best(
    program: &str,
    args: &[&std::ffi::OsStr],
    mut before: impl FnMut(),
) -> (Duration, u64, String) {
    let mut out = (Duration::MAX, 0, String::new());
    for i in 0..ROUNDS {
        before();
        let (t, peak, text) = run(program, args);
        out.0 = out.0.min(t);
        out.1 = out.1.max(peak);
        if i == 0 {
            out.2 = text;
        }
    }
    out
}

/// The number before `what` in an import's summary (`139300 calls`, `10006 buffers`).
fn count(summary: &str, what: &str) -> u64 {
    let words: Vec<&str> = summary.split_whitespace().collect();
    words
        .windows(2)
        .find_map(|w| {
            (w[1].trim_end_matches([',', ';']) == what)
                .then(|| w[0].parse().ok())
                .flatten()
        })
        .unwrap_or(0)
}

fn main() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("import-scale");
    let only: Option<Vec<usize>> = std::env::var("FRAMELAB_SCALE")
        .ok()
        .map(|v| v.split(',').filter_map(|s| s.trim().parse().ok()).collect());
    println!(
        "| buffers | calls | MB | passes emitted | import | peak | gfxrecon-convert | peak | import / convert | import per call |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (buffers, passes) in SIZES {
        if only.as_ref().is_some_and(|o| !o.contains(&buffers)) {
            continue;
        }
        let file = sync_stream::capture_frame(&dir, &format!("scale_{buffers}"), &|| {
            frame_json(buffers, passes)
        });
        let out = dir.join(format!("scale_{buffers}_import"));
        let written = out.join("f.json");
        let (t, peak, summary) = best(
            env!("CARGO_BIN_EXE_framelab"),
            &[
                "import".as_ref(),
                file.as_os_str(),
                "-o".as_ref(),
                written.as_os_str(),
            ],
            || {
                let _ = std::fs::remove_dir_all(&out);
                std::fs::create_dir_all(&out).expect("output folder");
            },
        );
        let jsonl = dir.join(format!("scale_{buffers}.jsonl"));
        let (ct, cpeak, _) = best(
            "gfxrecon-convert",
            &["--output".as_ref(), jsonl.as_os_str(), file.as_os_str()],
            || (),
        );
        let n = count(&summary, "calls");
        let cut = if summary.contains("beyond the limit of") {
            " (ceiling)"
        } else {
            ""
        };
        let mb = |b: u64| b as f64 / 1e6;
        println!(
            "| {} | {n} | {:.1} | {}{cut} | {:.2} s | {:.0} MB | {:.2} s | {:.0} MB | {:.2}x | {:.2} us |",
            count(&summary, "buffers"),
            mb(std::fs::metadata(&file).map_or(0, |m| m.len())),
            count(&summary, "passes"),
            t.as_secs_f64(),
            mb(peak),
            ct.as_secs_f64(),
            mb(cpeak),
            t.as_secs_f64() / ct.as_secs_f64(),
            t.as_secs_f64() * 1e6 / n.max(1) as f64,
        );
    }
}
