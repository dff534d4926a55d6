//! The timing diff as people read it: a table sorted by absolute change with the frame total
//! first (colours on a terminal), and the same table as Markdown for a pull-request comment.

use super::diff::{DiffReport, Row, RowKind, Verdict};
use crate::text::table;

fn ms(ns: f64) -> String {
    if ns.is_finite() {
        format!("{:.3}", ns / 1e6)
    } else {
        "-".to_owned()
    }
}

/// Megabytes (10^6) moved: B's, with A's first where they differ.
fn megabytes(r: &Row) -> String {
    let mb = |b: u64| format!("{:.1}", b as f64 / 1e6);
    match r.bytes_moved {
        [0, 0] => "-".to_owned(),
        [a, b] if a == b => mb(b),
        [a, b] => format!("{} -> {}", mb(a), mb(b)),
    }
}

/// Achieved bandwidth, A -> B.
fn bandwidth(r: &Row) -> String {
    let gbs = |g: Option<f64>| g.map_or("-".to_owned(), |g| format!("{g:.1}"));
    match r.bandwidth_gbps {
        [None, None] => "-".to_owned(),
        [a, b] => format!("{} -> {}", gbs(a), gbs(b)),
    }
}

fn verdict(v: &Verdict) -> String {
    match v {
        Verdict::Regression => "REGRESSION".to_owned(),
        Verdict::Improvement => "improvement".to_owned(),
        Verdict::Unchanged => "unchanged".to_owned(),
        Verdict::Inconclusive { needed: Some(n) } => format!("inconclusive (~{n} frames needed)"),
        Verdict::Inconclusive { needed: None } => "inconclusive".to_owned(),
        Verdict::Untimed => "not timed".to_owned(),
    }
}

fn what(r: &Row) -> String {
    let name = match &r.renamed_from {
        Some(old) => format!("{} (was {old})", r.name),
        None => r.name.clone(),
    };
    match r.kind {
        RowKind::Total => name,
        RowKind::Queue => format!("queue {name}"),
        RowKind::Marker => format!("group {name}"),
        RowKind::Pass => name,
    }
}

fn cells(r: &Row) -> Vec<String> {
    vec![
        what(r),
        r.queue.clone(),
        ms(r.median_a_ns),
        ms(r.median_b_ns),
        format!("{:+.1}%", r.change_pct),
        r.interval_pct
            .map_or("-".to_owned(), |[lo, hi]| format!("{lo:+.1}%..{hi:+.1}%")),
        r.p_adjusted.map_or("-".to_owned(), |p| format!("{p:.3}")),
        verdict(&r.verdict),
        megabytes(r),
        bandwidth(r),
    ]
}

/// Where the verdict is in a row's cells.
const VERDICT: usize = 7;

const HEADERS: [&str; 10] = [
    "pass",
    "queue",
    "A ms",
    "B ms",
    "change",
    "95% interval",
    "adj. p",
    "verdict",
    "MB moved",
    "GB/s",
];

fn summary(d: &DiffReport) -> String {
    let mut out = format!(
        "{} (A) against {} (B) on {}, scale {}: {} and {} measured frames, threshold {}%\n",
        d.a.capture,
        d.b.capture,
        d.a.adapter,
        d.a.scale,
        d.a.frames.saturating_sub(d.a.warmup),
        d.b.frames.saturating_sub(d.b.warmup),
        d.threshold_pct
    );
    for (label, list) in [("added in B", &d.added), ("removed from A", &d.removed)] {
        if !list.is_empty() {
            out.push_str(&format!("{label}: {}\n", list.join(", ")));
        }
    }
    out
}

/// The diff as a text table; `color` marks regressions red and improvements green.
pub fn text(d: &DiffReport, color: bool) -> String {
    let rows: Vec<Vec<String>> = d.rows.iter().map(cells).collect();
    let mut body = table(&HEADERS, &rows);
    if color {
        // The table's first two lines are the header and its rule; then one line per row.
        let mut coloured = String::new();
        for (i, line) in body.lines().enumerate() {
            let code = match i
                .checked_sub(2)
                .and_then(|r| d.rows.get(r))
                .map(|r| &r.verdict)
            {
                Some(Verdict::Regression) => Some("31"),
                Some(Verdict::Improvement) => Some("32"),
                _ => None,
            };
            match code {
                Some(c) => coloured.push_str(&format!("\x1b[{c}m{line}\x1b[0m\n")),
                None => {
                    coloured.push_str(line);
                    coloured.push('\n');
                }
            }
        }
        body = coloured;
    }
    format!("{}{body}", summary(d))
}

/// The diff as a Markdown table.
pub fn markdown(d: &DiffReport) -> String {
    let mut out = format!(
        "### Frame timing diff\n\n{}\n",
        summary(d).replace('\n', "  \n")
    );
    out.push_str(&format!("| {} |\n", HEADERS.join(" | ")));
    out.push_str(&format!("|{}\n", " --- |".repeat(HEADERS.len())));
    for r in &d.rows {
        let mut c = cells(r);
        if r.verdict == Verdict::Regression {
            c[VERDICT] = format!("**{}**", c[VERDICT]);
        }
        out.push_str(&format!("| {} |\n", c.join(" | ").replace('\n', " ")));
    }
    out
}
