//! Chrome trace-event JSON (opens in Perfetto and `chrome://tracing`): one track per capture
//! queue, frames laid end to end, each pass at its GPU start when the adapter timed it and
//! after the previous pass otherwise.

use super::{Sample, TimingReport};

/// The trace of `frames` (one `Sample` per pass of `report`, in the report's order).
pub fn chrome_trace(report: &TimingReport, frames: &[Vec<Sample>]) -> String {
    let mut queues: Vec<&str> = report.passes.iter().map(|p| p.queue.as_str()).collect();
    queues.sort_unstable();
    queues.dedup();
    let mut events = Vec::new();
    for (i, q) in queues.iter().enumerate() {
        events.push(serde_json::json!({"name": "thread_name", "ph": "M", "pid": 1, "tid": i + 1, "args": {"name": q}}));
    }
    let mut frame_start_us = 0.0f64;
    for (f, frame) in frames.iter().enumerate() {
        let mut cursor = 0.0f64;
        let mut frame_end = 0.0f64;
        for (p, t) in report.passes.iter().zip(frame) {
            let tid = queues.iter().position(|q| *q == p.queue).unwrap_or(0) + 1;
            let (start, dur) = match (t.gpu_start_ns, t.gpu_ns) {
                (Some(s), Some(d)) => (s as f64 / 1000.0, d as f64 / 1000.0),
                _ => (cursor, t.cpu_ns as f64 / 1000.0),
            };
            cursor = start + dur;
            frame_end = frame_end.max(start + dur);
            let mut args = serde_json::json!({"frame": f, "queue": p.queue, "gpu_ns": t.gpu_ns, "cpu_ns": t.cpu_ns});
            // Counters as args, so a trace viewer shows a pass's work beside its time.
            if let Some(c) = p.counters.as_ref().and_then(|c| c.frame(f)) {
                for (name, v) in super::counters::NAMES.iter().zip(c) {
                    args[*name] = v.into();
                }
            }
            events.push(serde_json::json!({
                "name": p.name, "cat": p.marker_path, "ph": "X", "pid": 1, "tid": tid,
                "ts": frame_start_us + start, "dur": dur.max(0.001),
                "args": args
            }));
        }
        frame_start_us += frame_end + 1.0;
    }
    serde_json::to_string_pretty(
        &serde_json::json!({"traceEvents": events, "displayTimeUnit": "ns"}),
    )
    .unwrap_or_default()
        + "\n"
}
