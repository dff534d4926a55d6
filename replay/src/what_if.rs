//! What if, on a device: a frame and its variant (`framelab_core::whatif`) judged statically,
//! then replayed on one device, one counted frame each where the adapter counts and then
//! interleaved frame by frame as a timing diff replays two captures, and reported: time with the
//! diff's statistics, work counters, memory, every texture compared after the last frame and
//! after every pass, and one line that says it all. The command line and the MCP server format
//! this report; neither measures on its own.

use std::collections::BTreeMap;

use serde::Serialize;

use framelab_core::pipeline::{Analysed, StageError};
use framelab_core::timing::diff::{DiffError, DiffOptions, DiffReport, RowKind, Verdict, diff};
use framelab_core::timing::work_diff::{WorkDiff, WorkDiffError, work_diff};
use framelab_core::whatif::{Pair, StaticVerdict, merged_into};

use crate::compare::{
    PassComparison, TextureComparison, TextureState, after_each_pass, compare_textures,
};
use crate::device::GpuContext;
use crate::replaying::{Replaying, interleaved};
use crate::run::ReplayError;

/// How a what-if measures.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Measured frames per side (at least 2).
    pub frames: u32,
    /// Frames run first and discarded.
    pub warmup: u32,
    /// A time change counts only when its whole interval lies beyond this, in percent.
    pub threshold_pct: f64,
    /// Mean FLIP at or below which a changed image is within tolerance.
    pub tolerance: f64,
    /// Compare textures after the last frame only, not also after every pass.
    pub final_only: bool,
}

/// Why the measuring stopped.
#[derive(Debug, thiserror::Error)]
pub enum WhatIfError {
    #[error(transparent)]
    Stage(#[from] StageError),
    #[error(transparent)]
    Replay(#[from] ReplayError),
    #[error(transparent)]
    Diff(#[from] DiffError),
    #[error(transparent)]
    Work(#[from] WorkDiffError),
}

/// A texture that changed, with the first pass (in the frame's order) that writes it.
#[derive(Debug, Serialize)]
pub struct Changed {
    #[serde(flatten)]
    pub texture: TextureComparison,
    pub first_written_by: Option<String>,
}

/// Everything a what-if found.
#[derive(Debug, Serialize)]
pub struct WhatIf {
    pub capture: String,
    /// The edits as they were given.
    pub edits: Vec<String>,
    /// Each change they made, in words.
    pub changes: Vec<String>,
    #[serde(rename = "static")]
    pub verdict: StaticVerdict,
    pub safe: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing: Option<DiffReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work: Option<WorkDiff>,
    /// Memory the frame's resources take, [unaliased, aliased] x [frame, variant].
    pub memory_bytes: [[u64; 2]; 2],
    pub textures_compared: usize,
    pub textures_identical: usize,
    pub changed: Vec<Changed>,
    /// The passes whose outputs differ, compared after each, in order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub passes_changed: Option<Vec<PassComparison>>,
    pub not_compared: Vec<TextureComparison>,
    /// The texture the frame presents, or its output where it presents none.
    pub presented: Option<String>,
    pub tolerance: f64,
    pub summary: String,
}

/// The static verdict on `pair`: the report before anything runs (its summary says so where
/// the edits introduce an error).
pub fn judge(pair: &Pair, capture: String, edits: Vec<String>, tolerance: f64) -> WhatIf {
    let (a, b) = (&pair.frame, &pair.variant);
    let verdict = framelab_core::whatif::verdict(pair);
    let memory = |x: &Analysed| {
        let t = &x.analysis.memory.total;
        [t.unaliased_bytes, t.aliased_bytes]
    };
    let (ma, mb) = (memory(a), memory(b));
    let safe = verdict.safe();
    let summary = if safe {
        "safe; not measured".to_owned()
    } else {
        format!(
            "unsafe: {} error(s) introduced; nothing was replayed",
            verdict.errors().count()
        )
    };
    WhatIf {
        capture,
        edits,
        changes: pair.changes.clone(),
        verdict,
        safe,
        timing: None,
        work: None,
        memory_bytes: [[ma[0], mb[0]], [ma[1], mb[1]]],
        textures_compared: 0,
        textures_identical: 0,
        changed: Vec::new(),
        passes_changed: None,
        not_compared: Vec::new(),
        presented: None,
        tolerance,
        summary,
    }
}

/// Each resource the frame writes, with the first pass (in its order) that writes it: where a
/// change to that texture starts.
fn first_writers(a: &Analysed) -> BTreeMap<String, String> {
    let c = &a.capture;
    let mut out = BTreeMap::new();
    for &p in &a.analysis.order {
        let pass = c.pass(p);
        for x in pass.accesses.iter().filter(|x| x.writes) {
            out.entry(c.resource(x.resource).name.clone())
                .or_insert_with(|| pass.name.clone());
        }
    }
    out
}

/// The texture a replay presents last.
fn presented(r: &Replaying) -> Option<String> {
    let plan = &r.session.plan;
    plan.passes.iter().rev().find_map(|p| match p.op {
        framelab_core::plan::PassOp::Present { texture } => {
            Some(plan.textures[texture].name.clone())
        }
        _ => None,
    })
}

/// Replays both frames of a safe what-if on `ctx` and fills in what they measured.
pub fn measure(
    report: &mut WhatIf,
    ctx: &GpuContext,
    pair: Pair,
    o: &Options,
) -> Result<(), WhatIfError> {
    let writers = first_writers(&pair.frame);
    let renamed = merged_into(&pair.frame.capture, &pair.variant.capture);
    // The frame's output, where it presents none (it renders into its swapchain image and
    // marks it an output).
    let output = pair
        .frame
        .capture
        .resources
        .iter()
        .find(|r| r.output && r.is_texture())
        .map(|r| r.name.clone());
    let lower = |a: Analysed| -> Result<Replaying, WhatIfError> {
        let lowered = a
            .replayable()?
            .lower(ctx.device.features(), &ctx.summary.name)?;
        Ok(Replaying::start(ctx, lowered)?)
    };
    let (mut ra, mut rb) = (lower(pair.frame)?, lower(pair.variant)?);
    // One counted frame each first, where the adapter counts; then the timed frames.
    let mut skip = 0;
    if ra.session.set_counting(true) && rb.session.set_counting(true) {
        ra.frame(0, None)?;
        rb.frame(0, None)?;
        report.work = Some(work_diff(&ra.report(0), &rb.report(0))?);
        ra.session.set_counting(false);
        rb.session.set_counting(false);
        skip = 1;
    }
    let end = skip + o.warmup + o.frames;
    interleaved(&mut ra, &mut rb, skip..end)?;
    let options = DiffOptions {
        threshold_pct: o.threshold_pct,
        ..DiffOptions::default()
    };
    let timing = diff(
        &ra.report(skip + o.warmup),
        &rb.report(skip + o.warmup),
        &options,
    )?;
    for t in compare_textures(&ra.session, &rb.session) {
        report.textures_compared += 1;
        match t.state {
            TextureState::Identical => report.textures_identical += 1,
            TextureState::NotCompared { .. } => report.not_compared.push(t),
            _ => report.changed.push(Changed {
                first_written_by: writers.get(&t.name).cloned(),
                texture: t,
            }),
        }
    }
    // After the timing reports are taken: these frames are not timed.
    if !o.final_only {
        report.passes_changed = Some(after_each_pass(&mut ra, &mut rb, end - 1, &renamed)?);
    }
    report.presented = presented(&ra).or(output);
    let first = report
        .passes_changed
        .as_ref()
        .and_then(|p| p.first())
        .map_or(String::new(), |p| {
            format!("; outputs first differ after pass \"{}\"", p.pass)
        });
    report.summary = format!(
        "safe; {}; {}{first}",
        time_phrase(&timing),
        image_phrase(&report.changed, report.presented.as_deref(), o.tolerance)
    );
    report.timing = Some(timing);
    Ok(())
}

/// "12.4% faster (p=0.003)" and the like, from the frame total.
fn time_phrase(t: &DiffReport) -> String {
    let Some(total) = t.rows.iter().find(|r| r.kind == RowKind::Total) else {
        return "time not measured".into();
    };
    let amount = total.change_pct.abs();
    let way = if total.change_pct < 0.0 {
        "faster"
    } else {
        "slower"
    };
    let p = total
        .p_adjusted
        .map_or(String::new(), |p| format!("p={p:.3}"));
    match total.verdict {
        Verdict::Improvement | Verdict::Regression => format!("{amount:.1}% {way} ({p})"),
        Verdict::Unchanged => format!("time unchanged (within ±{}%)", t.threshold_pct),
        Verdict::Inconclusive { needed } => {
            let more = needed.map_or(String::new(), |n| {
                format!("; ~{n} frames a side would decide")
            });
            format!("{amount:.1}% {way} (not significant, {p}{more})")
        }
        Verdict::Untimed => "time not measured (the adapter times none of the passes)".into(),
    }
}

/// A changed texture judged against the tolerance.
fn judged(t: &TextureComparison, tolerance: f64) -> String {
    match t.state {
        TextureState::Changed {
            flip_mean: Some(m), ..
        } => format!(
            "FLIP mean {m:.4} ({} tolerance {tolerance})",
            if m <= tolerance { "within" } else { "over" }
        ),
        TextureState::Reshaped => "its size or subresources changed".into(),
        _ => "changed".into(),
    }
}

/// "images identical" or what changed, the presented image first.
fn image_phrase(changed: &[Changed], presented: Option<&str>, tolerance: f64) -> String {
    if changed.is_empty() {
        return "images identical".into();
    }
    let shown = presented.and_then(|p| changed.iter().find(|c| c.texture.name == p));
    let others = changed.len() - usize::from(shown.is_some());
    let mut s = match shown {
        Some(c) => format!("final image changed: {}", judged(&c.texture, tolerance)),
        None if presented.is_some() => "final image identical".into(),
        None => String::new(),
    };
    if others > 0 {
        if !s.is_empty() {
            s.push_str("; ");
        }
        let worst = changed
            .iter()
            .filter(|c| Some(c.texture.name.as_str()) != presented)
            .max_by(|x, y| flip_of(&x.texture).total_cmp(&flip_of(&y.texture)))
            .map(|c| {
                format!(
                    ", the most \"{}\": {}",
                    c.texture.name,
                    judged(&c.texture, tolerance)
                )
            })
            .unwrap_or_default();
        s.push_str(&format!("{others} other texture(s) changed{worst}"));
    }
    s
}

fn flip_of(t: &TextureComparison) -> f64 {
    match t.state {
        TextureState::Changed {
            flip_mean: Some(m), ..
        } => m,
        TextureState::Reshaped => f64::INFINITY,
        _ => 0.0,
    }
}
