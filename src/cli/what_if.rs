//! `framelab what-if`: a frame changed by edits (a lint's fix, a pass culled, a recorded
//! barrier dropped, a format changed), judged statically first (exit 1, before anything runs,
//! on an error the edits introduce), then replayed beside the frame on one device, interleaved
//! frame by frame as `diff` replays two captures, and reported: time with the diff's
//! statistics, work counters where the adapter counts, bytes moved and memory, and every
//! texture compared after the last frame (FLIP of each changed one). Exit 2 on a bad edit or
//! input, nothing written.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use serde::Serialize;

use framelab_core::analysis::report::{AnalyzeOptions, LintReport};
use framelab_core::capture::Options;
use framelab_core::pipeline::{Analysed, Loaded};
use framelab_core::text::printable;
use framelab_core::timing::diff::{DiffOptions, DiffReport, RowKind, Verdict, diff};
use framelab_core::timing::work_diff::{WorkDiff, work_diff};
use framelab_core::whatif::{Edit, StaticVerdict, apply, static_verdict};
use framelab_replay::Replaying;
use framelab_replay::compare::{TextureComparison, TextureState, compare_textures};

use super::{parse_percent, parse_scale, print_stdout, stages};

#[derive(Debug, Clone, clap::Args)]
pub struct WhatIfArgs {
    /// The capture (JSON).
    pub capture: PathBuf,
    /// Apply the fix of every finding of lint CODE (`FL005`), or of those about one pass or
    /// resource (`FL005:ssao`); `analyze` marks the fixable findings.
    #[arg(long = "fix", value_name = "CODE[:WHERE]", value_parser = Edit::fix)]
    pub fix: Vec<Edit>,
    /// Drop a pass.
    #[arg(long, value_name = "PASS", value_parser = Edit::cull)]
    pub cull: Vec<Edit>,
    /// Drop a pass's recorded barrier N (its place in the pass's list, from 0).
    #[arg(long = "drop-barrier", value_name = "PASS:N", value_parser = Edit::drop_barrier)]
    pub drop_barrier: Vec<Edit>,
    /// Give a texture another format (DXGI's name).
    #[arg(long, value_name = "RESOURCE=FORMAT", value_parser = Edit::format)]
    pub format: Vec<Edit>,
    /// On a GFXReconstruct capture: set a number in one call, as `framelab edit` does
    /// (BLOCK:PATH=VALUE); the stream and its edited copy are both imported and compared.
    #[arg(long = "set", value_name = "BLOCK:PATH=VALUE")]
    pub set: Vec<framelab_core::import::gfxr::edit::FieldEdit>,
    /// On a GFXReconstruct capture: the frame to import (0-based).
    #[arg(long, value_parser = super::import::parse_frames)]
    pub frame: Option<(u32, u32)>,
    /// Measured frames per side.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(2..=100000))]
    pub frames: u32,
    /// Frames run first and discarded.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=10000))]
    pub warmup: u32,
    /// Output-resolution multiplier.
    #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
    pub scale: f64,
    /// A time change counts only when its whole 95% interval lies beyond this, in percent.
    #[arg(long, default_value_t = 3.0, value_parser = parse_percent)]
    pub threshold: f64,
    /// Mean FLIP at or below which a changed image is within tolerance.
    #[arg(long, default_value_t = 0.01)]
    pub tolerance: f64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the report and, for each changed texture, both images and the FLIP map here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Use the adapter whose name contains this text.
    #[arg(long)]
    pub adapter: Option<String>,
}

impl WhatIfArgs {
    fn edits(&self) -> Vec<Edit> {
        [&self.fix, &self.cull, &self.drop_barrier, &self.format]
            .into_iter()
            .flatten()
            .cloned()
            .collect()
    }
}

/// A texture that changed, with the first pass (in the frame's order) that writes it.
#[derive(Debug, Serialize)]
struct Changed<'a> {
    #[serde(flatten)]
    texture: &'a TextureComparison,
    first_written_by: Option<String>,
}

/// Everything a what-if found.
#[derive(Debug, Serialize)]
struct Report<'a> {
    capture: String,
    edits: Vec<String>,
    changes: Vec<String>,
    #[serde(rename = "static")]
    verdict: &'a StaticVerdict,
    safe: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    timing: Option<&'a DiffReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    work: Option<&'a WorkDiff>,
    /// Memory the frame's resources take, unaliased and with aliasing, before and after.
    memory_bytes: Option<[[u64; 2]; 2]>,
    textures_compared: usize,
    textures_identical: usize,
    changed: Vec<Changed<'a>>,
    not_compared: Vec<&'a TextureComparison>,
    presented: Option<String>,
    tolerance: f64,
    summary: String,
}

/// Bad input or a bad edit: exit 2.
struct Usage(anyhow::Error);

impl<E: Into<anyhow::Error>> From<E> for Usage {
    fn from(e: E) -> Self {
        Usage(e.into())
    }
}

fn analyse(loaded: Loaded, scale: f64) -> Result<Analysed, Usage> {
    let v = loaded
        .validate(&Options {
            scale,
            ..Options::default()
        })
        .map_err(stages::device_error)?;
    Ok(v.analyse(AnalyzeOptions { cull: false })
        .map_err(stages::device_error)?)
}

/// A folder of this run's own, removed when dropped.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The captures to compare: the frame, and where the edits start from (the frame itself, or
/// the import of a GFXReconstruct capture's edited stream).
struct Inputs {
    frame: PathBuf,
    edited: Option<PathBuf>,
    _scratch: Option<Scratch>,
}

/// The capture as given, or for a `.gfxr` the imports of it and of its copy with the `--set`
/// edits made, in a scratch folder.
fn inputs(args: &WhatIfArgs) -> Result<Inputs, Usage> {
    let mut head = [0u8; 4];
    let is_gfxr = std::fs::File::open(&args.capture)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok()
        && framelab_core::import::gfxr::is_gfxr(&head);
    if !is_gfxr {
        if !args.set.is_empty() || args.frame.is_some() {
            return Err(Usage(anyhow::anyhow!(
                "--set and --frame edit and import a GFXReconstruct capture; {} is not one",
                args.capture.display()
            )));
        }
        return Ok(Inputs {
            frame: args.capture.clone(),
            edited: None,
            _scratch: None,
        });
    }
    let dir = std::env::temp_dir().join(format!("framelab-what-if-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let scratch = Scratch(dir.clone());
    let bytes = std::fs::read(&args.capture)
        .with_context(|| format!("reading {}", args.capture.display()))?;
    let edited = framelab_core::import::gfxr::edit::apply(&bytes, &args.set)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.capture.display()))?;
    let stream = dir.join("edited.gfxr");
    std::fs::write(&stream, edited).with_context(|| format!("writing {}", stream.display()))?;
    let (a, b) = (
        dir.join("frame").join("frame.json"),
        dir.join("edited").join("edited.json"),
    );
    for (from, to) in [(&args.capture, &a), (&stream, &b)] {
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent)?;
        }
        super::import::import_to(from, to, args.frame)
            .with_context(|| format!("importing {}", from.display()))?;
    }
    Ok(Inputs {
        frame: a,
        edited: Some(b),
        _scratch: Some(scratch),
    })
}

/// The frame and its variant, analysed, with the changes made in words.
fn frames(
    args: &WhatIfArgs,
    inputs: &Inputs,
    edits: &[Edit],
) -> Result<(Analysed, Analysed, Vec<String>), Usage> {
    let loaded = Loaded::read_hashed(&inputs.frame).map_err(stages::device_error)?;
    let mut raw = loaded.raw.clone();
    let frame = analyse(loaded, args.scale)?;
    let mut said: Vec<String> = args.set.iter().map(|e| format!("set {e}")).collect();
    if let Some(edited) = &inputs.edited {
        raw = Loaded::read(edited).map_err(stages::device_error)?.raw;
    }
    let (edited, changes) = apply(&raw, &frame.capture, &frame.analysis.lints, edits)?;
    said.extend(changes);
    let at = inputs.edited.as_ref().unwrap_or(&inputs.frame);
    let variant = analyse(Loaded::from_raw(at, edited), args.scale)
        .map_err(|Usage(e)| Usage(e.context("the edited frame is not a valid capture")))?;
    Ok((frame, variant, said))
}

/// Each resource the frame writes, with the first pass (in its order) that writes it: where a
/// change to that texture starts.
fn first_writers(a: &Analysed) -> std::collections::BTreeMap<String, String> {
    let c = &a.capture;
    let mut out = std::collections::BTreeMap::new();
    for &p in &a.analysis.order {
        let pass = c.pass(p);
        for x in pass.accesses.iter().filter(|x| x.writes) {
            out.entry(c.resource(x.resource).name.clone())
                .or_insert_with(|| pass.name.clone());
        }
    }
    out
}

/// What the replays measured.
struct Measured {
    timing: DiffReport,
    /// Where the adapter counts pipeline statistics.
    work: Option<WorkDiff>,
    textures: Vec<TextureComparison>,
    /// The texture the frame presents.
    presented: Option<String>,
}

/// Replays both, interleaved; the timing diff, the work diff and the textures compared.
fn measure(args: &WhatIfArgs, a: Analysed, b: Analysed) -> anyhow::Result<Measured> {
    let ctx = framelab_replay::open_device(
        args.adapter.as_deref(),
        framelab_core::lower::wanted_features(),
    )?;
    let (a, b) = (
        a.replayable().map_err(stages::device_error)?,
        b.replayable().map_err(stages::device_error)?,
    );
    let mut ra = Replaying::start(&ctx, stages::lower(a, &ctx)?)?;
    let mut rb = Replaying::start(&ctx, stages::lower(b, &ctx)?)?;
    // One counted frame each first, where the adapter counts; then the timed frames.
    let mut skip = 0;
    let mut work = None;
    if ra.session.set_counting(true) && rb.session.set_counting(true) {
        ra.frame(0, None)?;
        rb.frame(0, None)?;
        work = Some(work_diff(&ra.report(0), &rb.report(0))?);
        ra.session.set_counting(false);
        rb.session.set_counting(false);
        skip = 1;
    }
    framelab_replay::replaying::interleaved(
        &mut ra,
        &mut rb,
        skip..skip + args.warmup + args.frames,
    )?;
    let options = DiffOptions {
        threshold_pct: args.threshold,
        ..DiffOptions::default()
    };
    let timing = diff(
        &ra.report(skip + args.warmup),
        &rb.report(skip + args.warmup),
        &options,
    )?;
    let textures = compare_textures(&ra.session, &rb.session);
    let presented = ra
        .session
        .plan
        .passes
        .iter()
        .rev()
        .find_map(|p| match p.op {
            framelab_core::plan::PassOp::Present { texture } => {
                Some(ra.session.plan.textures[texture].name.clone())
            }
            _ => None,
        });
    Ok(Measured {
        timing,
        work,
        textures,
        presented,
    })
}

/// "12.4% faster (p=0.003)" and the like, from the frame total.
fn time_phrase(t: &DiffReport) -> String {
    let Some(total) = t.rows.iter().find(|r| r.kind == RowKind::Total) else {
        return "time not measured".into();
    };
    let (amount, way) = (
        total.change_pct.abs(),
        if total.change_pct < 0.0 {
            "faster"
        } else {
            "slower"
        },
    );
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

/// "images identical" or what changed, the presented image first.
fn image_phrase(changed: &[Changed<'_>], presented: Option<&str>, tolerance: f64) -> String {
    if changed.is_empty() {
        return "images identical".into();
    }
    let judged = |t: &TextureComparison| match t.state {
        TextureState::Changed {
            flip_mean: Some(m), ..
        } => format!(
            "FLIP mean {m:.4} ({} tolerance {tolerance})",
            if m <= tolerance { "within" } else { "over" }
        ),
        TextureState::Reshaped => "its size or subresources changed".into(),
        _ => "changed".into(),
    };
    let shown = presented.and_then(|p| changed.iter().find(|c| c.texture.name == p));
    let others = changed.len() - usize::from(shown.is_some());
    let mut s = match shown {
        Some(c) => format!("final image changed: {}", judged(c.texture)),
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
            .max_by(|x, y| flip_of(x.texture).total_cmp(&flip_of(y.texture)))
            .map(|c| format!(", the most \"{}\": {}", c.texture.name, judged(c.texture)))
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

/// A texture's comparison in words.
fn state_text(state: &TextureState) -> String {
    match state {
        TextureState::Identical => "identical".into(),
        TextureState::Changed {
            texels,
            flip_mean: Some(m),
            flip_p99: Some(p),
        } => format!("{texels} texels differ, FLIP mean {m:.4}, 99th percentile {p:.4}"),
        TextureState::Changed { texels, .. } => format!("{texels} texels differ"),
        TextureState::Reshaped => "its size or subresources changed".into(),
        TextureState::NotCompared { why } => format!("not compared: {why}"),
    }
}

fn lint_line(l: &LintReport) -> String {
    format!("  {}  {}  {}", l.code, l.name, l.message)
}

fn text(r: &Report<'_>) -> String {
    let mut s = format!("what-if on {}: {}\n", r.capture, r.edits.join(" "));
    for c in &r.changes {
        s.push_str(&format!("  {c}\n"));
    }
    if r.safe {
        s.push_str("static: safe, no error introduced\n");
    } else {
        s.push_str("static: UNSAFE, the edits introduce:\n");
    }
    for l in &r.verdict.introduced {
        s.push_str(&format!("{}\n", lint_line(l)));
    }
    if !r.verdict.resolved.is_empty() {
        s.push_str(&format!("resolved ({}):\n", r.verdict.resolved.len()));
        for l in &r.verdict.resolved {
            s.push_str(&format!("{}\n", lint_line(l)));
        }
    }
    if let Some(t) = r.timing {
        s.push('\n');
        s.push_str(&framelab_core::timing::render::text(t, false));
    }
    if let Some(w) = r.work {
        s.push('\n');
        s.push_str(&framelab_core::timing::work_diff::text(w));
    }
    if let Some([[ua, ub], [aa, ab]]) = r.memory_bytes {
        let mb = |b: u64| b as f64 / 1e6;
        s.push_str(&format!(
            "\nmemory: {:.2} -> {:.2} MB unaliased, {:.2} -> {:.2} MB aliased\n",
            mb(ua),
            mb(ub),
            mb(aa),
            mb(ab)
        ));
    }
    if r.timing.is_some() {
        s.push_str(&format!(
            "textures: {} compared, {} identical, {} changed, {} not compared\n",
            r.textures_compared,
            r.textures_identical,
            r.changed.len(),
            r.not_compared.len()
        ));
        for c in &r.changed {
            let by = c
                .first_written_by
                .as_deref()
                .map_or(String::new(), |p| format!(" (first written by \"{p}\")"));
            s.push_str(&format!(
                "  {}{by}: {}\n",
                c.texture.name,
                state_text(&c.texture.state)
            ));
        }
    }
    s.push_str(&format!("\n{}\n", r.summary));
    s
}

/// Writes the report and the changed textures' images into `out`, atomically (a staging
/// folder renamed at the end).
fn write_out(out: &Path, json: &str, changed: &[Changed<'_>]) -> anyhow::Result<()> {
    let staging = framelab_replay::export::staging_dir(out);
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging).with_context(|| format!("creating {}", staging.display()))?;
    let written = (|| -> anyhow::Result<()> {
        std::fs::write(staging.join("what_if.json"), json)?;
        for c in changed {
            let stem = &c.texture.stem;
            if let Some((a, b, map)) = &c.texture.images {
                a.save(staging.join(format!("{stem}.a.png")))?;
                b.save(staging.join(format!("{stem}.b.png")))?;
                if let Some(map) = map {
                    map.save(staging.join(format!("{stem}.flip.png")))?;
                }
            }
        }
        Ok(())
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e);
    }
    if out.exists() {
        std::fs::remove_dir_all(out).with_context(|| format!("replacing {}", out.display()))?;
    }
    std::fs::rename(&staging, out).with_context(|| format!("moving into {}", out.display()))
}

fn failed(e: &anyhow::Error, code: u8) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "error: {}", printable(&format!("{e:#}")));
    ExitCode::from(code)
}

pub fn run(args: &WhatIfArgs) -> ExitCode {
    let edits = args.edits();
    if edits.is_empty() && args.set.is_empty() {
        return failed(
            &anyhow::anyhow!(
                "what-if needs at least one edit (--fix, --cull, --drop-barrier, --format, --set)"
            ),
            2,
        );
    }
    if let Some(out) = &args.out
        && let Err(e) = framelab_core::output::check_output(out, &[&args.capture])
    {
        return failed(&e.into(), 2);
    }
    let inputs = match inputs(args) {
        Ok(i) => i,
        Err(Usage(e)) => return failed(&e, 2),
    };
    let (a, b, changes) = match frames(args, &inputs, &edits) {
        Ok(x) => x,
        Err(Usage(e)) => return failed(&e, 2),
    };
    let verdict = static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints);
    let memory = |x: &Analysed| {
        let t = &x.analysis.memory.total;
        [t.unaliased_bytes, t.aliased_bytes]
    };
    let (ma, mb) = (memory(&a), memory(&b));
    let mut report = Report {
        capture: args.capture.display().to_string(),
        edits: args
            .set
            .iter()
            .map(|e| format!("--set {e}"))
            .chain(edits.iter().map(Edit::spelling))
            .collect(),
        changes,
        verdict: &verdict,
        safe: verdict.safe(),
        timing: None,
        work: None,
        memory_bytes: Some([[ma[0], mb[0]], [ma[1], mb[1]]]),
        textures_compared: 0,
        textures_identical: 0,
        changed: Vec::new(),
        not_compared: Vec::new(),
        presented: None,
        tolerance: args.tolerance,
        summary: String::new(),
    };
    if !report.safe {
        let n = verdict.errors().count();
        report.summary = format!("unsafe: {n} error(s) introduced; nothing was replayed");
        return finish(args, &report, 1);
    }
    let writers = first_writers(&a);
    // The frame's output, where it presents none (a frame that renders into its swapchain
    // image and marks it an output).
    let output = a
        .capture
        .resources
        .iter()
        .find(|r| r.output && r.is_texture())
        .map(|r| r.name.clone());
    let measured = measure(args, a, b);
    let Measured {
        timing,
        work,
        textures,
        presented,
    } = match measured {
        Ok(m) => m,
        Err(e) => return failed(&e, 1),
    };
    report.timing = Some(&timing);
    report.work = work.as_ref();
    report.presented = presented.or(output);
    report.textures_compared = textures.len();
    for t in &textures {
        match t.state {
            TextureState::Identical => report.textures_identical += 1,
            TextureState::NotCompared { .. } => report.not_compared.push(t),
            _ => report.changed.push(Changed {
                texture: t,
                first_written_by: writers.get(&t.name).cloned(),
            }),
        }
    }
    report.summary = format!(
        "safe; {}; {}",
        time_phrase(&timing),
        image_phrase(&report.changed, report.presented.as_deref(), args.tolerance)
    );
    finish(args, &report, 0)
}

/// Prints the report (and writes `--out`); `code` is the exit code when that works.
fn finish(args: &WhatIfArgs, report: &Report<'_>, code: u8) -> ExitCode {
    let json = serde_json::to_string_pretty(report).unwrap_or_default() + "\n";
    if let Some(out) = &args.out
        && let Err(e) = write_out(out, &json, &report.changed)
    {
        return failed(&e, 2);
    }
    let printed = print_stdout(&if args.json { json } else { text(report) });
    match printed {
        Ok(_) => ExitCode::from(code),
        Err(e) => failed(&e, 2),
    }
}
