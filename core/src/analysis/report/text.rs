//! `framelab analyze` as readable tables: order, barriers per boundary, fences, memory per heap
//! type, lints, and the critical path with async-compute overlap.

use std::fmt::Write as _;

use super::{Report, ratio};
use crate::analysis::barriers::BarrierKind;
use crate::analysis::lints::LintSeverity;
use crate::text::{human_bytes, table};

pub fn render_text(r: &Report) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "capture {}: {} passes in order, {} culled\n",
        r.capture,
        r.order.len(),
        r.culled.len()
    );
    let order: Vec<Vec<String>> = r
        .barriers
        .iter()
        .map(|b| {
            vec![
                b.position.to_string(),
                b.pass.clone(),
                b.queue.clone(),
                b.barriers.len().to_string(),
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Order\n{}",
        table(&["#", "pass", "queue", "barriers"], &order)
    );
    if !r.culled.is_empty() {
        let _ = writeln!(
            out,
            "Culled (results never reach an output): {}\n",
            r.culled.join(", ")
        );
    }
    let rows = barrier_rows(r);
    let _ = writeln!(
        out,
        "Barriers ({})\n{}",
        rows.len(),
        table(
            &[
                "boundary",
                "kind",
                "resource",
                "subresource",
                if r.vulkan_terms {
                    "layouts; stages / access"
                } else {
                    "states"
                },
                "queue",
                "placement"
            ],
            &rows
        )
    );
    if !r.fences.is_empty() {
        let f: Vec<Vec<String>> = r
            .fences
            .iter()
            .map(|f| {
                vec![
                    f.signal_after.clone(),
                    f.wait_before.clone(),
                    if f.declared { "declared" } else { "NEEDED" }.to_owned(),
                ]
            })
            .collect();
        let _ = writeln!(
            out,
            "Fences\n{}",
            table(&["signal after", "wait before", "source"], &f)
        );
    }
    if !r.queue_transfers.is_empty() {
        let t: Vec<Vec<String>> = r
            .queue_transfers
            .iter()
            .map(|t| {
                vec![
                    t.resource.clone(),
                    t.subresource.describe(),
                    format!("{} -> {}", t.from_queue, t.to_queue),
                    t.release_after.clone(),
                    t.acquire_before.clone(),
                ]
            })
            .collect();
        let _ = writeln!(
            out,
            "Queue ownership transfers ({})\n{}",
            t.len(),
            table(
                &[
                    "resource",
                    "subresource",
                    "queues",
                    "release after",
                    "acquire before"
                ],
                &t
            )
        );
    }
    memory(&mut out, r);
    lints(&mut out, r);
    let cp = &r.critical_path;
    let path = path_text(&cp.passes);
    // Zero only when no pass is timed (the schedule then weighs every pass one).
    if cp.length_ns == 0 {
        let _ = writeln!(
            out,
            "Critical path (no pass times in the capture: the longest chain of dependent \
             passes, {} of {})\n  {path}",
            cp.passes.len(),
            r.order.len(),
        );
    } else {
        let _ = writeln!(
            out,
            "Critical path ({} timings): {:.3} ms of {:.3} ms serial\n  {path}",
            cp.timing_source,
            cp.length_ns as f64 / 1e6,
            cp.serial_ns as f64 / 1e6,
        );
    }
    for o in &r.async_compute {
        let _ = writeln!(
            out,
            "  async compute: {} can overlap {}",
            o.pass,
            match (o.overlaps.is_empty(), o.more) {
                (true, _) => "nothing".to_owned(),
                (false, 0) => o.overlaps.join(", "),
                (false, more) => format!("{} and {more} more", o.overlaps.join(", ")),
            }
        );
    }
    out
}

/// The passes of a path on one line; a long one (a single queue's whole frame) shows its
/// ends and counts the middle (`--json` lists every pass).
fn path_text(passes: &[String]) -> String {
    const ENDS: usize = 4;
    if passes.len() <= 3 * ENDS {
        return passes.join(" -> ");
    }
    format!(
        "{} -> ... {} more ... -> {}",
        passes[..ENDS].join(" -> "),
        passes.len() - 2 * ENDS,
        passes[passes.len() - ENDS..].join(" -> ")
    )
}

/// One row per barrier: boundary, kind, resource, subresource, states, queue, placement.
fn barrier_rows(r: &Report) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for b in &r.barriers {
        for x in &b.barriers {
            let sub = x.subresource.describe();
            let kind = match x.kind {
                BarrierKind::Transition => "transition",
                BarrierKind::Uav => "uav",
                BarrierKind::Aliasing => "aliasing",
            };
            let states = match x.kind {
                BarrierKind::Aliasing => format!(
                    "{} -> {}",
                    x.resource_before.as_deref().unwrap_or("?"),
                    x.resource
                ),
                _ if r.vulkan_terms => x.vulkan.describe(),
                _ => format!("{} -> {}", x.before, x.after),
            };
            let mut note = x.placement.clone();
            if let Some(s) = &x.split_begin_after {
                let _ = write!(note, "; split from {s}");
            }
            if x.next_frame {
                note.push_str("; for next frame");
            }
            rows.push(vec![
                b.pass.clone(),
                kind.to_owned(),
                x.resource.clone(),
                sub,
                states,
                x.queue.clone(),
                note,
            ]);
        }
    }
    rows
}

fn memory(out: &mut String, r: &Report) {
    let mut mem: Vec<Vec<String>> = r
        .memory
        .heap_types
        .iter()
        .map(|(k, t)| {
            vec![
                k.clone(),
                human_bytes(t.unaliased_bytes),
                human_bytes(t.aliased_bytes),
                human_bytes(t.lower_bound_bytes),
                format!("{:.3}", ratio(t)),
            ]
        })
        .collect();
    let t = &r.memory.total;
    mem.push(vec![
        "total".into(),
        human_bytes(t.unaliased_bytes),
        human_bytes(t.aliased_bytes),
        human_bytes(t.lower_bound_bytes),
        format!("{:.3}", ratio(t)),
    ]);
    let _ = writeln!(
        out,
        "Memory\n{}",
        table(
            &[
                "heap type",
                "unaliased",
                "aliased plan",
                "lower bound",
                "plan / bound"
            ],
            &mem
        )
    );
}

fn lints(out: &mut String, r: &Report) {
    let lints: Vec<Vec<String>> = r
        .lints
        .iter()
        .map(|l| {
            let sev = match l.severity {
                LintSeverity::Error => "error",
                LintSeverity::Warning => "warning",
                LintSeverity::Info => "info",
            };
            vec![
                l.code.to_owned(),
                sev.to_owned(),
                l.name.to_owned(),
                match &l.fix {
                    // What `what-if --fix CODE` would change.
                    Some(fix) => format!("{} (fixable: {fix})", l.message),
                    None => l.message.clone(),
                },
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Lints ({})\n{}",
        lints.len(),
        table(&["code", "severity", "lint", "message"], &lints)
    );
}
