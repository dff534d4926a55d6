//! `framelab diff`: compares two frames' per-pass GPU timings. Given two timing reports it
//! compares them; given two captures it replays both on one device, interleaved frame by frame
//! (A B, B A, ...) so clock and thermal drift and any cost of running second hit both alike,
//! warm-up frames first and discarded. Exit codes:
//! 0 no significant regression beyond the gate, 1 a regression, 2 bad usage or input.
//! `--structure` compares two captures' passes, resources and memory instead (exit 0 or 2).
//! `--work` compares the passes' work counters (`replay --counters`): exact counts, one frame
//! each, exit 1 when a counter grew past `--fail-on-increase`.

use framelab_core::text::printable;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use framelab_core::structure::Frame;
use framelab_core::timing::diff::{DiffOptions, diff};
use framelab_core::timing::{TimingReport, render};
use framelab_core::{files, lower};

use super::stages;
use super::{parse_percent, parse_scale, print_stdout};
use framelab_replay::Replaying;

#[derive(Debug, Clone, clap::Args)]
pub struct DiffArgs {
    /// Timing report (`replay --timings`) or capture: the baseline.
    pub a: PathBuf,
    /// Timing report or capture: the candidate.
    pub b: PathBuf,
    /// Measured frames per capture when replaying.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(2..=100000))]
    pub frames: u32,
    /// Frames run first and discarded when replaying (clocks ramp up on real GPUs).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(0..=10000))]
    pub warmup: u32,
    /// Output-resolution multiplier when replaying.
    #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
    pub scale: f64,
    /// A change counts only when its whole 95% interval lies beyond this, in percent.
    #[arg(long, default_value_t = 3.0, value_parser = parse_percent)]
    pub threshold: f64,
    /// Exit 1 only for significant regressions larger than this, in percent.
    #[arg(long, value_parser = parse_percent)]
    pub fail_on_regression: Option<f64>,
    /// Print the diff as JSON.
    #[arg(long, conflicts_with = "markdown")]
    pub json: bool,
    /// Print the diff as a Markdown table (for a pull-request comment).
    #[arg(long)]
    pub markdown: bool,
    /// Also draw each pass's change and its interval into this SVG file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Compare the two captures' structure instead of their timings (nothing is replayed):
    /// passes, resources, queues, fences, counts and memory.
    #[arg(long, conflicts_with_all = ["plot", "fail_on_regression"])]
    pub structure: bool,
    /// Compare the passes' work counters instead of their timings (pipeline statistics and
    /// submitted work, which do not scatter): two reports written with `replay --counters`,
    /// or two captures, each replayed for one counted frame.
    #[arg(long, conflicts_with_all = ["plot", "fail_on_regression", "structure"])]
    pub work: bool,
    /// With --work: exit 1 when a GPU counter of the frame or of a pass grew by more than this,
    /// in percent (0 fails on any growth).
    #[arg(long, requires = "work", value_parser = parse_percent)]
    pub fail_on_increase: Option<f64>,
    /// Use the adapter whose name contains this text when replaying.
    #[arg(long)]
    pub adapter: Option<String>,
}

/// A file is a timing report when it parses as one; anything else is taken for a capture.
fn as_report(path: &Path) -> anyhow::Result<Option<TimingReport>> {
    // Either kind of file may come here, so the larger of their limits.
    let limit = files::Limit {
        what: "a capture or timing report",
        bytes: files::CAPTURE.bytes.max(files::TIMING_REPORT.bytes),
    };
    let bytes = files::read(path, limit)?;
    if let Some(what) = framelab_core::capture::load::foreign(&bytes) {
        return Err(framelab_core::capture::CaptureError::NeedsImport {
            path: path.to_owned(),
            what,
        }
        .into());
    }
    let value: serde_json::Value = serde_json::from_slice(&bytes)
        .map_err(|e| anyhow::anyhow!("{}: not JSON: {e}", path.display()))?;
    if value.get("capture_sha256").is_some() && value.get("backend").is_some() {
        Ok(Some(TimingReport::from_value(
            &path.display().to_string(),
            value,
        )?))
    } else {
        Ok(None)
    }
}

/// Replays both captures on one device, alternating frames, and returns their reports
/// (counted, one frame each, with `--work`).
fn replay_both(args: &DiffArgs) -> anyhow::Result<(TimingReport, TimingReport)> {
    let a = stages::for_replay(&args.a, args.scale, false)?;
    let b = stages::for_replay(&args.b, args.scale, false)?;
    let ctx = framelab_replay::open_device(args.adapter.as_deref(), lower::wanted_features())?;
    let (la, lb) = (stages::lower(a, &ctx)?, stages::lower(b, &ctx)?);
    let mut ra = Replaying::start(&ctx, la)?;
    let mut rb = Replaying::start(&ctx, lb)?;
    if args.work {
        if !(ra.session.set_counting(true) && rb.session.set_counting(true)) {
            anyhow::bail!(
                "{} has no pipeline statistics queries: work counters cannot be measured on it",
                ctx.summary.name
            );
        }
        ra.frame(0, None)?;
        rb.frame(0, None)?;
        return Ok((ra.report(0), rb.report(0)));
    }
    framelab_replay::replaying::interleaved(&mut ra, &mut rb, 0..args.warmup + args.frames)?;
    Ok((ra.report(args.warmup), rb.report(args.warmup)))
}

fn inputs(args: &DiffArgs) -> anyhow::Result<(TimingReport, TimingReport)> {
    match (as_report(&args.a)?, as_report(&args.b)?) {
        (Some(a), Some(b)) => Ok((a, b)),
        (None, None) => replay_both(args),
        _ => anyhow::bail!(
            "compare two timing reports or two captures, not one of each ({} and {})",
            args.a.display(),
            args.b.display()
        ),
    }
}

/// The structural diff of two captures, printed; input errors exit 2.
fn structure(args: &DiffArgs) -> anyhow::Result<()> {
    for path in [&args.a, &args.b] {
        if as_report(path)?.is_some() {
            anyhow::bail!(
                "{} is a timing report: --structure compares two captures",
                path.display()
            );
        }
    }
    let a = stages::analysed_for_device(&args.a, args.scale, false)?;
    let b = stages::analysed_for_device(&args.b, args.scale, false)?;
    let d = framelab_core::structure::diff(
        Frame {
            capture: &a.capture,
            analysis: &a.analysis,
        },
        Frame {
            capture: &b.capture,
            analysis: &b.analysis,
        },
    );
    let text = if args.json {
        serde_json::to_string_pretty(&d)? + "\n"
    } else if args.markdown {
        framelab_core::structure::render::markdown(&d)
    } else {
        framelab_core::structure::render::text(&d)
    };
    print_stdout(&text)
}

/// The work diff of two reports or captures, printed; whether it passed the gate.
fn work(args: &DiffArgs) -> anyhow::Result<bool> {
    use framelab_core::timing::work_diff;
    let (a, b) = inputs(args)?;
    let d = work_diff::work_diff(&a, &b)?;
    let text = if args.json {
        serde_json::to_string_pretty(&d)? + "\n"
    } else if args.markdown {
        work_diff::markdown(&d)
    } else {
        work_diff::text(&d)
    };
    print_stdout(&text)?;
    let Some(pct) = args.fail_on_increase else {
        return Ok(true);
    };
    let offenders = d.offenders(pct);
    for r in &offenders {
        let grown: Vec<String> = r
            .counters
            .iter()
            .filter(|(_, c)| c.grew_past(pct))
            .map(|(k, c)| format!("{k} {} -> {}", c.a, c.b))
            .collect();
        let _ = writeln!(
            std::io::stderr(),
            "work grew past {pct}%: {}: {}",
            r.name,
            grown.join(", ")
        );
    }
    Ok(offenders.is_empty())
}

/// Reports `e` and gives diff's exit code for an error (1 means a regression).
fn failed(e: impl std::fmt::Display) -> ExitCode {
    let _ = writeln!(std::io::stderr(), "error: {}", printable(&format!("{e:#}")));
    ExitCode::from(2)
}

pub fn run(args: &DiffArgs) -> ExitCode {
    if let Some(plot) = &args.plot
        && let Err(e) = framelab_core::output::check_output(plot, &[&args.a, &args.b])
    {
        return failed(e);
    }
    if args.work {
        return match work(args) {
            Ok(true) => ExitCode::SUCCESS,
            Ok(false) => ExitCode::from(1),
            Err(e) => failed(e),
        };
    }
    if args.structure {
        return match structure(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => failed(e),
        };
    }
    let (a, b) = match inputs(args) {
        Ok(reports) => reports,
        Err(e) => {
            return failed(e);
        }
    };
    let options = DiffOptions {
        threshold_pct: args.threshold,
        fail_on_regression_pct: args.fail_on_regression,
        ..DiffOptions::default()
    };
    let report = match diff(&a, &b, &options) {
        Ok(r) => r,
        Err(e) => {
            return failed(e);
        }
    };
    let color = !args.json
        && !args.markdown
        && std::io::stdout().is_terminal()
        && std::env::var_os("NO_COLOR").is_none();
    let text = if args.json {
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n"
    } else if args.markdown {
        render::markdown(&report)
    } else {
        render::text(&report, color)
    };
    if let Some(file) = &args.plot {
        let written = framelab_core::timing::plot::svg(&report)
            .map_err(anyhow::Error::from)
            .and_then(|svg| {
                Ok(framelab_core::output::write_atomically(
                    file,
                    svg.as_bytes(),
                )?)
            });
        if let Err(e) = written {
            return failed(e);
        }
    }
    let printed = if color {
        super::print_stdout_styled(&text)
    } else {
        print_stdout(&text)
    };
    if let Err(e) = printed {
        let _ = writeln!(std::io::stderr(), "error: {}", printable(&format!("{e:#}")));
        return ExitCode::from(2);
    }
    if report.fails(args.fail_on_regression.unwrap_or(args.threshold)) {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
