//! The work diff: two reports' per-pass counters (the last frame of each) compared exactly.
//! Counts do not scatter, so there are no samples, intervals or p-values: a count that changed
//! changed. Passes pair as the timing diff pairs them. The gate fails when a GPU counter of a
//! matched pass, or of the frame, grew by more than the given percentage.

use std::collections::BTreeMap;

use serde::Serialize;

use super::counters::{Counts, NAMES, Work};
use super::diff::match_passes;
use super::{PassTiming, TimingReport};

/// The version of the work diff's JSON shape.
pub const WORK_DIFF_FORMAT_VERSION: u32 = 1;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WorkDiffError {
    #[error("{0} has no counters: replay it with --counters")]
    NoCounters(String),
    #[error("the reports were replayed at different scales ({a} and {b}): compare like with like")]
    Scale { a: f64, b: f64 },
    #[error(
        "the reports were counted on different adapters (\"{a}\" and \"{b}\"): counts are exact per driver only"
    )]
    Adapter { a: String, b: String },
}

/// One counter of one row, in A and in B.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Change {
    pub a: u64,
    pub b: u64,
    /// (B - A) / A in percent; `None` when A is 0 (and B is not).
    pub change_pct: Option<f64>,
}

impl Change {
    fn of(a: u64, b: u64) -> Change {
        let change_pct = if a == b {
            Some(0.0)
        } else {
            (a > 0).then(|| (b as f64 - a as f64) / a as f64 * 100.0)
        };
        Change { a, b, change_pct }
    }

    /// Whether B grew past `pct` percent of A (any growth from 0 counts).
    pub fn grew_past(&self, pct: f64) -> bool {
        self.b > self.a && self.change_pct.is_none_or(|c| c > pct)
    }
}

/// A pass (or the frame total) with every counter and work figure that changed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorkRow {
    /// `"(frame)"` for the total.
    pub name: String,
    pub queue: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub renamed_from: Option<String>,
    /// The five GPU counters, by name.
    pub counters: BTreeMap<&'static str, Change>,
    /// Derived work (draws, dispatches, instances, indices, vertices, threads, bytes_moved)
    /// that changed, by name.
    pub work: BTreeMap<&'static str, Change>,
}

impl WorkRow {
    /// Whether any counter or work figure changed.
    pub fn changed(&self) -> bool {
        self.counters
            .values()
            .chain(self.work.values())
            .any(|c| c.a != c.b)
    }

    /// The largest growth of a GPU counter, in percent (infinite from 0).
    fn worst_growth(&self) -> f64 {
        self.counters
            .values()
            .filter(|c| c.b > c.a)
            .map(|c| c.change_pct.unwrap_or(f64::INFINITY))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorkSide {
    pub capture: String,
    pub adapter: String,
    pub scale: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorkDiff {
    pub format_version: u32,
    pub a: WorkSide,
    pub b: WorkSide,
    /// The frame total first, then matched passes in B's order.
    pub rows: Vec<WorkRow>,
    /// Passes only in B, and only in A, with their counts.
    pub added: Vec<WorkRow>,
    pub removed: Vec<WorkRow>,
    /// Passes whose counts changed between the frames of one report (an animated frame).
    pub unsteady: Vec<String>,
}

impl WorkDiff {
    /// Whether a gate at `pct` fails: a GPU counter of the frame or of a matched pass grew
    /// by more than `pct` percent.
    pub fn fails(&self, pct: f64) -> bool {
        self.rows
            .iter()
            .any(|r| r.counters.values().any(|c| c.grew_past(pct)))
    }

    /// Rows past the gate at `pct`, the worst first.
    pub fn offenders(&self, pct: f64) -> Vec<&WorkRow> {
        let mut rows: Vec<&WorkRow> = self
            .rows
            .iter()
            .filter(|r| r.counters.values().any(|c| c.grew_past(pct)))
            .collect();
        rows.sort_by(|a, b| b.worst_growth().total_cmp(&a.worst_growth()));
        rows
    }
}

fn counts(p: &PassTiming) -> Counts {
    p.counters
        .as_ref()
        .and_then(|c| c.last())
        .map_or([0; 5], |(c, _)| c)
}

/// Work figures by name.
fn figures(p: &PassTiming) -> [(&'static str, u64); 7] {
    let w = p.work.clone().unwrap_or_default();
    let Work {
        draws,
        dispatches,
        instances,
        indices,
        vertices,
        threads,
        ..
    } = w;
    [
        ("draws", draws),
        ("dispatches", dispatches),
        ("instances", instances),
        ("indices", indices),
        ("vertices", vertices),
        ("threads", threads),
        ("bytes_moved", p.bytes_moved()),
    ]
}

fn row(name: String, queue: String, a: Option<&PassTiming>, b: Option<&PassTiming>) -> WorkRow {
    let (ca, cb) = (a.map_or([0; 5], counts), b.map_or([0; 5], counts));
    let fa = a.map(figures);
    let fb = b.map(figures);
    let counters = NAMES
        .iter()
        .enumerate()
        .map(|(k, n)| (*n, Change::of(ca[k], cb[k])))
        .collect();
    let work = (0..7)
        .filter_map(|k| {
            let name = fa.or(fb)?[k].0;
            let (x, y) = (fa.map_or(0, |f| f[k].1), fb.map_or(0, |f| f[k].1));
            Some((name, Change::of(x, y)))
        })
        .collect();
    WorkRow {
        name,
        queue,
        renamed_from: None,
        counters,
        work,
    }
}

fn sum(
    rows: &[WorkRow],
    pick: impl Fn(&WorkRow) -> &BTreeMap<&'static str, Change>,
) -> BTreeMap<&'static str, Change> {
    let mut total: BTreeMap<&'static str, (u64, u64)> = BTreeMap::new();
    for r in rows {
        for (k, c) in pick(r) {
            let t = total.entry(k).or_default();
            t.0 = t.0.saturating_add(c.a);
            t.1 = t.1.saturating_add(c.b);
        }
    }
    total
        .into_iter()
        .map(|(k, (a, b))| (k, Change::of(a, b)))
        .collect()
}

/// Compares the last frame's counters of `a` and `b`, which must both carry counters, at one
/// scale, from one adapter.
pub fn work_diff(a: &TimingReport, b: &TimingReport) -> Result<WorkDiff, WorkDiffError> {
    for r in [a, b] {
        if !r.passes.iter().any(|p| p.counters.is_some()) {
            return Err(WorkDiffError::NoCounters(r.capture.clone()));
        }
    }
    if a.scale != b.scale {
        return Err(WorkDiffError::Scale {
            a: a.scale,
            b: b.scale,
        });
    }
    if a.adapter != b.adapter {
        return Err(WorkDiffError::Adapter {
            a: a.adapter.clone(),
            b: b.adapter.clone(),
        });
    }
    let m = match_passes(&a.passes, &b.passes);
    let mut pairs = m.pairs.clone();
    pairs.sort_by_key(|&(_, j)| j);
    let matched: Vec<WorkRow> = pairs
        .iter()
        .map(|&(i, j)| {
            let (pa, pb) = (&a.passes[i], &b.passes[j]);
            let mut r = row(pb.name.clone(), pb.queue.clone(), Some(pa), Some(pb));
            if m.renamed.contains(&(i, j)) {
                r.renamed_from = Some(pa.name.clone());
            }
            r
        })
        .collect();
    let added: Vec<WorkRow> = m
        .added
        .iter()
        .map(|&j| {
            row(
                b.passes[j].name.clone(),
                b.passes[j].queue.clone(),
                None,
                Some(&b.passes[j]),
            )
        })
        .collect();
    let removed: Vec<WorkRow> = m
        .removed
        .iter()
        .map(|&i| {
            row(
                a.passes[i].name.clone(),
                a.passes[i].queue.clone(),
                Some(&a.passes[i]),
                None,
            )
        })
        .collect();
    let every: Vec<WorkRow> = matched
        .iter()
        .chain(&added)
        .chain(&removed)
        .cloned()
        .collect();
    let total = WorkRow {
        name: "(frame)".to_owned(),
        queue: String::new(),
        renamed_from: None,
        counters: sum(&every, |r| &r.counters),
        work: sum(&every, |r| &r.work),
    };
    let mut unsteady: Vec<String> = [a, b]
        .iter()
        .flat_map(|r| &r.passes)
        .filter(|p| {
            p.counters
                .as_ref()
                .and_then(|c| c.last())
                .is_some_and(|(_, s)| !s)
        })
        .map(|p| p.name.clone())
        .collect();
    unsteady.sort();
    unsteady.dedup();
    let side = |r: &TimingReport| WorkSide {
        capture: r.capture.clone(),
        adapter: r.adapter.clone(),
        scale: r.scale,
    };
    Ok(WorkDiff {
        format_version: WORK_DIFF_FORMAT_VERSION,
        a: side(a),
        b: side(b),
        rows: std::iter::once(total).chain(matched).collect(),
        added,
        removed,
        unsteady,
    })
}

fn change(c: &Change) -> String {
    match c.change_pct {
        Some(p) => format!("{} -> {} ({p:+.1}%)", c.a, c.b),
        None => format!("{} -> {} (new)", c.a, c.b),
    }
}

fn changed_cells(r: &WorkRow) -> Vec<String> {
    r.counters
        .iter()
        .chain(&r.work)
        .filter(|(_, c)| c.a != c.b)
        .map(|(k, c)| format!("{k} {}", change(c)))
        .collect()
}

/// Plain text: each changed row with what changed, then added and removed passes.
pub fn text(d: &WorkDiff) -> String {
    let mut out = format!(
        "work diff: {} -> {} on {} at scale {}\n",
        d.a.capture, d.b.capture, d.a.adapter, d.a.scale
    );
    let changed: Vec<&WorkRow> = d.rows.iter().filter(|r| r.changed()).collect();
    if changed.is_empty() {
        out += "no pass does different work\n";
    }
    for r in changed {
        let renamed = r
            .renamed_from
            .as_ref()
            .map_or(String::new(), |f| format!(" (was {f})"));
        out += &format!("{}{renamed}\n", r.name);
        for cell in changed_cells(r) {
            out += &format!("  {cell}\n");
        }
    }
    for (what, rows) in [("added", &d.added), ("removed", &d.removed)] {
        for r in rows {
            out += &format!(
                "{what}: {} ({} fragment, {} compute invocations)\n",
                r.name,
                r.counters["fragment_invocations"]
                    .a
                    .max(r.counters["fragment_invocations"].b),
                r.counters["compute_invocations"]
                    .a
                    .max(r.counters["compute_invocations"].b)
            );
        }
    }
    if !d.unsteady.is_empty() {
        out += &format!(
            "counted differently between frames (compared at the last): {}\n",
            d.unsteady.join(", ")
        );
    }
    out
}

/// A Markdown table of the changed rows, one column per GPU counter.
pub fn markdown(d: &WorkDiff) -> String {
    let mut out = format!(
        "**Work diff** `{}` → `{}` ({}, scale {})\n\n| pass |",
        d.a.capture, d.b.capture, d.a.adapter, d.a.scale
    );
    for n in NAMES {
        out += &format!(" {n} |");
    }
    out += " other changes |\n|---|";
    out += &"---:|".repeat(NAMES.len());
    out += "---|\n";
    for r in d.rows.iter().filter(|r| r.changed()) {
        out += &format!("| {} |", r.name);
        for n in NAMES {
            let c = &r.counters[n];
            out += &if c.a == c.b {
                format!(" {} |", c.a)
            } else {
                format!(
                    " {} → {} ({}) |",
                    c.a,
                    c.b,
                    c.change_pct
                        .map_or("new".to_owned(), |p| format!("{p:+.1}%"))
                )
            };
        }
        let other: Vec<String> = r
            .work
            .iter()
            .filter(|(_, c)| c.a != c.b)
            .map(|(k, c)| format!("{k} {}", change(c)))
            .collect();
        out += &format!(" {} |\n", other.join("; "));
    }
    for (what, rows) in [("added", &d.added), ("removed", &d.removed)] {
        if !rows.is_empty() {
            let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
            out += &format!("\n{what}: {}\n", names.join(", "));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timing::FORMAT_VERSION;
    use crate::timing::counters::Counters;

    fn pass(name: &str, fragments: u64, draws: u64) -> PassTiming {
        PassTiming {
            name: name.into(),
            queue: "graphics".into(),
            marker_path: format!("Frame/{name}"),
            kind: "raster".into(),
            writes: vec![format!("{name}_target")],
            gpu_ns: vec![Some(1)],
            cpu_ns: vec![1],
            counters: Counters::from_frames(&[Some([30, 10, 10, fragments, 0])]),
            work: Some(Work {
                draws,
                ..Work::default()
            }),
            ..PassTiming::default()
        }
    }

    fn report(passes: Vec<PassTiming>) -> TimingReport {
        TimingReport {
            format_version: FORMAT_VERSION,
            adapter: "llvmpipe".into(),
            backend: "vulkan".into(),
            capture: "c".into(),
            capture_sha256: String::new(),
            scale: 0.25,
            frames: 1,
            warmup: 0,
            timestamp_period_ns: 1.0,
            timestamps: super::super::StampLayout::Chained,
            passes,
        }
    }

    #[test]
    fn a_count_that_grew_fails_the_gate_and_an_equal_one_does_not() {
        let a = report(vec![pass("gbuffer", 1000, 4), pass("shadow", 500, 2)]);
        let same = work_diff(&a, &a).unwrap();
        assert!(same.rows.iter().all(|r| !r.changed()));
        assert!(!same.fails(0.0));
        let b = report(vec![pass("gbuffer", 1100, 4), pass("shadow", 250, 1)]);
        let d = work_diff(&a, &b).unwrap();
        let gbuffer = d.rows.iter().find(|r| r.name == "gbuffer").unwrap();
        assert_eq!(
            gbuffer.counters["fragment_invocations"].change_pct,
            Some(10.0)
        );
        let shadow = d.rows.iter().find(|r| r.name == "shadow").unwrap();
        assert_eq!(shadow.work["draws"].change_pct, Some(-50.0));
        // The frame total: 1500 -> 1350 fragments.
        assert_eq!(d.rows[0].counters["fragment_invocations"].b, 1350);
        assert!(d.fails(5.0));
        assert!(!d.fails(10.0));
        assert_eq!(d.offenders(5.0)[0].name, "gbuffer");
        assert!(markdown(&d).contains("1000 → 1100 (+10.0%)"));
        assert!(text(&d).contains("draws 2 -> 1 (-50.0%)"));
    }

    #[test]
    fn renamed_added_and_removed_passes_are_named() {
        let a = report(vec![pass("gbuffer", 1000, 4), pass("old", 5, 1)]);
        let mut renamed = pass("gbuffer_opaque", 1000, 4);
        renamed.writes = vec!["gbuffer_target".into()];
        let b = report(vec![renamed, pass("new", 7, 1)]);
        let d = work_diff(&a, &b).unwrap();
        assert_eq!(d.rows[1].renamed_from.as_deref(), Some("gbuffer"));
        assert_eq!(d.added[0].name, "new");
        assert_eq!(d.removed[0].name, "old");
        // The new pass's work counts in the frame total, and grows it past any gate.
        assert_eq!(d.rows[0].counters["fragment_invocations"].b, 1007);
    }

    #[test]
    fn reports_without_counters_elsewhere_or_at_other_scales_are_refused() {
        let a = report(vec![pass("p", 1, 1)]);
        let mut bare = a.clone();
        bare.passes[0].counters = None;
        assert_eq!(
            work_diff(&a, &bare),
            Err(WorkDiffError::NoCounters("c".into()))
        );
        let mut other = a.clone();
        other.adapter = "NVIDIA".into();
        assert!(matches!(
            work_diff(&a, &other),
            Err(WorkDiffError::Adapter { .. })
        ));
        let mut scaled = a.clone();
        scaled.scale = 0.5;
        assert!(matches!(
            work_diff(&a, &scaled),
            Err(WorkDiffError::Scale { .. })
        ));
    }
}
