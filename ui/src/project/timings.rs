//! Timings for the inspector's model: a report's medians laid out per queue, and the timing
//! diff against a second report per pass (renames matched, moves shown, scales warned about).

use framelab_core::timing::diff::{DiffOptions, RowKind, Verdict};
use framelab_core::timing::{TimingReport, stats};
use std::collections::BTreeMap;

use crate::model::{Compare, CompareRow, Inspection, PassTime, Timings};

/// Per model pass, its median GPU time in a report, laid out per queue in order (a report
/// keeps durations, not start times): a pass starts when the previous one on its queue ends,
/// and not before the passes it waits on.
pub(super) fn timings_from(model: &Inspection, t: &TimingReport, source: &str) -> Timings {
    let by_name: BTreeMap<(&str, &str), &framelab_core::timing::PassTiming> = t
        .passes
        .iter()
        .map(|p| ((p.queue.as_str(), p.name.as_str()), p))
        .collect();
    let mut queue_end = vec![0.0f64; model.queues.len()];
    let mut ends: Vec<f64> = Vec::with_capacity(model.passes.len());
    let mut out = Vec::with_capacity(model.passes.len());
    // The passes each pass waits on, gathered once.
    let mut waits_on: Vec<Vec<usize>> = vec![Vec::new(); model.passes.len()];
    for &(from, to) in &model.fences {
        if let Some(list) = waits_on.get_mut(to) {
            list.push(from);
        }
    }
    for (i, p) in model.passes.iter().enumerate() {
        let timing = by_name.get(&(model.queues[p.queue].as_str(), p.name.as_str()));
        // A pass the adapter could not time keeps its place, unmeasured.
        let measured = timing.is_none_or(|pt| pt.gpu_untrusted.is_none());
        let ms = timing
            .and_then(|pt| stats::gpu_ms_median_min(pt, t.warmup))
            .map(|(median, _)| median * 1e6);
        let waits = waits_on[i]
            .iter()
            .map(|&from| ends.get(from).copied().unwrap_or(0.0))
            .fold(0.0f64, f64::max);
        let counters = timing
            .and_then(|pt| pt.counters.as_ref())
            .and_then(|c| c.last())
            .map(|(c, _)| c);
        let start = queue_end[p.queue].max(waits);
        let end = start + ms.unwrap_or(0.0);
        queue_end[p.queue] = end;
        ends.push(end);
        out.push(match (ms, measured) {
            (Some(gpu_ns), _) => Some(PassTime {
                start_ns: start,
                gpu_ns,
                measured: true,
                counters,
            }),
            (None, false) => Some(PassTime {
                start_ns: start,
                gpu_ns: 0.0,
                measured: false,
                counters,
            }),
            (None, true) => None,
        });
    }
    let work = model
        .passes
        .iter()
        .map(|p| {
            let timing = by_name.get(&(model.queues[p.queue].as_str(), p.name.as_str()));
            timing.and_then(|pt| pt.work.clone())
        })
        .collect();
    Timings {
        source: source.to_owned(),
        passes: out,
        note: t.passes.iter().find_map(|p| p.gpu_untrusted.clone()),
        work,
    }
}

/// A pass the timing diff left unmatched that runs there on another queue under the same marker
/// path and name (the structural diff's "moved"): its time there is shown, but no change or
/// verdict, as times on different queues do not compare.
fn moved(model: &Inspection, p: &crate::model::Pass, b: &TimingReport) -> Option<CompareRow> {
    let here = model.queues[p.queue].as_str();
    let path = if p.markers.is_empty() {
        p.name.clone()
    } else {
        format!("{}/{}", p.markers.join("/"), p.name)
    };
    let there = b.passes.iter().find(|t| {
        t.name == p.name && t.queue != here && (t.marker_path == path || t.marker_path.is_empty())
    })?;
    let samples: Vec<f64> = there.gpu_ns.iter().flatten().map(|&n| n as f64).collect();
    if samples.is_empty() {
        return None;
    }
    Some(CompareRow {
        other_ms: stats::median(&samples) / 1e6,
        change_pct: 0.0,
        verdict: "moved".into(),
        renamed: None,
        moved: Some(there.queue.clone()),
    })
}

pub(super) fn compare_from(
    model: &Inspection,
    a: &TimingReport,
    b: &TimingReport,
    source: &str,
) -> Result<Compare, framelab_core::timing::diff::DiffError> {
    // Reports taken at different scales are compared all the same, under a warning: the
    // inspector shows what there is, the diff command refuses to give a verdict on it.
    let note = (a.scale != b.scale).then(|| {
        format!(
            "the reports were taken at different scales ({} here, {} in {source}): their times \
             are not comparable",
            a.scale, b.scale
        )
    });
    let rescaled;
    let b = if a.scale == b.scale {
        b
    } else {
        rescaled = TimingReport {
            scale: a.scale,
            ..b.clone()
        };
        &rescaled
    };
    let d = framelab_core::timing::diff::diff(a, b, &DiffOptions::default())?;
    // Keyed by the pass's name here (in A): a pass renamed there is matched by the diff's
    // rename detection (same shader, queue and outputs) and found under its old name.
    let rows: BTreeMap<(&str, &str), &framelab_core::timing::diff::Row> = d
        .rows
        .iter()
        .filter(|r| r.kind == RowKind::Pass)
        .map(|r| {
            let here = r.renamed_from.as_deref().unwrap_or(r.name.as_str());
            ((r.queue.as_str(), here), r)
        })
        .collect();
    let passes = model
        .passes
        .iter()
        .map(|p| {
            let Some(r) = rows.get(&(model.queues[p.queue].as_str(), p.name.as_str())) else {
                return moved(model, p, b);
            };
            Some(CompareRow {
                other_ms: r.median_b_ns / 1e6,
                change_pct: r.change_pct,
                verdict: match r.verdict {
                    Verdict::Regression => "regression",
                    Verdict::Improvement => "improvement",
                    Verdict::Unchanged => "unchanged",
                    Verdict::Inconclusive { .. } => "inconclusive",
                    Verdict::Untimed => "untimed",
                }
                .to_owned(),
                renamed: r.renamed_from.as_ref().map(|_| r.name.clone()),
                moved: None,
            })
        })
        .collect();
    Ok(Compare {
        source: source.to_owned(),
        passes,
        note,
    })
}
