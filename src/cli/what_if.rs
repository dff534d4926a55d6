//! `framelab what-if`: the edits parsed, a GFXReconstruct capture and its edited copy imported
//! (`--set`), the frame and its variant made (`framelab_core::whatif`), judged and measured
//! (`framelab_replay::what_if`), and the report printed as text or JSON, with `--out` holding
//! it and the changed textures' images. Exit 1 on an error the edits introduce (before anything
//! runs) or a replay that fails, 2 on a bad edit or input, nothing written.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;

use framelab_core::analysis::report::LintReport;
use framelab_core::capture::Options;
use framelab_core::pipeline::Loaded;
use framelab_core::text::printable;
use framelab_core::whatif::{Edit, Pair, variant};
use framelab_replay::compare::{PassComparison, TextureComparison, TextureState};
use framelab_replay::what_if::{self, Changed, WhatIf, judge, measure};

use super::{parse_percent, parse_scale, print_stdout, stages};

/// The edits `what-if` makes, which `inspect` takes too to open the comparison.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct EditArgs {
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
    /// Run a pass on another queue (which then needs fences where it meets the others' work).
    #[arg(long, value_name = "PASS=QUEUE", value_parser = Edit::queue)]
    pub queue: Vec<Edit>,
    /// Multiply a texture's width and height by F (relative sizes stay relative).
    #[arg(long = "scale-resource", value_name = "RESOURCE=F", value_parser = Edit::scale_resource)]
    pub scale_resource: Vec<Edit>,
    /// Make two raster passes one render pass, the second's draws after the first's (they
    /// need the same attachments, and the second must load them).
    #[arg(long, value_name = "FIRST+SECOND", value_parser = Edit::merge)]
    pub merge: Vec<Edit>,
}

impl EditArgs {
    /// Every edit given, in the order of the kinds above.
    pub fn edits(&self) -> Vec<Edit> {
        [
            &self.fix,
            &self.cull,
            &self.drop_barrier,
            &self.format,
            &self.queue,
            &self.scale_resource,
            &self.merge,
        ]
        .into_iter()
        .flatten()
        .cloned()
        .collect()
    }
}

#[derive(Debug, Clone, clap::Args)]
pub struct WhatIfArgs {
    /// The capture (JSON).
    pub capture: PathBuf,
    #[command(flatten)]
    pub edits: EditArgs,
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
    /// Compare the textures after the last frame only, not also after every pass (each pass
    /// compared replays the frame up to it on both sides).
    #[arg(long)]
    pub final_only: bool,
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

/// Bad input or a bad edit: exit 2.
struct Usage(anyhow::Error);

impl<E: Into<anyhow::Error>> From<E> for Usage {
    fn from(e: E) -> Self {
        Usage(e.into())
    }
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

/// The frame and its variant, validated and analysed, with the changes made in words.
fn frames(args: &WhatIfArgs, inputs: &Inputs, edits: &[Edit]) -> Result<Pair, Usage> {
    let loaded = Loaded::read_hashed(&inputs.frame).map_err(stages::device_error)?;
    let start = match &inputs.edited {
        Some(edited) => Some(Loaded::read(edited).map_err(stages::device_error)?),
        None => None,
    };
    let options = Options {
        scale: args.scale,
        ..Options::default()
    };
    let mut pair =
        variant(loaded, start, edits, &options).map_err(|e| Usage(stages::variant_error(e)))?;
    let set = args.set.iter().map(|e| format!("set {e}"));
    pair.changes = set.chain(pair.changes).collect();
    Ok(pair)
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

fn text(r: &WhatIf) -> String {
    let mut s = format!("what-if on {}: {}\n", r.capture, r.edits.join(" "));
    for c in &r.changes {
        s.push_str(&format!("  {c}\n"));
    }
    if r.safe {
        s.push_str("static: safe, no error introduced\n");
    } else {
        s.push_str("static: UNSAFE, the edits introduce:\n");
    }
    if let Some(note) = &r.verdict.note {
        s.push_str(&format!("  ({note})\n"));
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
    if let Some(t) = &r.timing {
        s.push('\n');
        s.push_str(&framelab_core::timing::render::text(t, false));
    }
    if let Some(w) = &r.work {
        s.push('\n');
        s.push_str(&framelab_core::timing::work_diff::text(w));
    }
    let [[ua, ub], [aa, ab]] = r.memory_bytes;
    {
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
    if let Some(passes) = &r.passes_changed {
        s.push_str(&format!(
            "compared after every pass: {} pass(es) whose outputs differ\n",
            passes.len()
        ));
        for p in passes {
            let what: Vec<String> = p
                .changed
                .iter()
                .map(|t| format!("{} ({})", t.name, state_text(&t.state)))
                .collect();
            s.push_str(&format!("  after \"{}\": {}\n", p.pass, what.join("; ")));
        }
    }
    s.push_str(&format!("\n{}\n", r.summary));
    s
}

/// Both images of a changed texture and their FLIP map, into `dir`.
fn save_images(dir: &Path, t: &TextureComparison) -> anyhow::Result<()> {
    let stem = &t.stem;
    if let Some((a, b, map)) = &t.images {
        a.save(dir.join(format!("{stem}.a.png")))?;
        b.save(dir.join(format!("{stem}.b.png")))?;
        if let Some(map) = map {
            map.save(dir.join(format!("{stem}.flip.png")))?;
        }
    }
    Ok(())
}

/// Writes the report and the changed textures' images into `out`, atomically (a staging
/// folder renamed at the end).
fn write_out(
    out: &Path,
    json: &str,
    changed: &[Changed],
    passes: &[PassComparison],
) -> anyhow::Result<()> {
    let staging = framelab_replay::export::staging_dir(out);
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging).with_context(|| format!("creating {}", staging.display()))?;
    let written = (|| -> anyhow::Result<()> {
        std::fs::write(staging.join("what_if.json"), json)?;
        for c in changed {
            save_images(&staging, &c.texture)?;
        }
        // After each pass whose outputs differ: passes/NNN_name/, in the frame's order.
        for (n, p) in passes.iter().enumerate() {
            let name: String = p
                .pass
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            let dir = staging.join("passes").join(format!("{n:03}_{name}"));
            std::fs::create_dir_all(&dir)?;
            for t in &p.changed {
                save_images(&dir, t)?;
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
    let edits = args.edits.edits();
    if edits.is_empty() && args.set.is_empty() {
        return failed(
            &anyhow::anyhow!(
                "what-if needs at least one edit (--fix, --cull, --drop-barrier, --format, --queue, --scale-resource, --merge, --set)"
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
    let pair = match frames(args, &inputs, &edits) {
        Ok(x) => x,
        Err(Usage(e)) => return failed(&e, 2),
    };
    let given = args
        .set
        .iter()
        .map(|e| format!("--set {e}"))
        .chain(edits.iter().map(Edit::spelling))
        .collect();
    let mut report = judge(
        &pair,
        args.capture.display().to_string(),
        given,
        args.tolerance,
    );
    if !report.safe {
        return finish(args, &report, 1);
    }
    let options = what_if::Options {
        frames: args.frames,
        warmup: args.warmup,
        threshold_pct: args.threshold,
        tolerance: args.tolerance,
        final_only: args.final_only,
    };
    let measured = framelab_replay::open_device(
        args.adapter.as_deref(),
        framelab_core::lower::wanted_features(),
    )
    .map_err(anyhow::Error::from)
    .and_then(|ctx| Ok(measure(&mut report, &ctx, pair, &options)?));
    match measured {
        Ok(()) => finish(args, &report, 0),
        Err(e) => failed(&e, 1),
    }
}

/// Prints the report (and writes `--out`); `code` is the exit code when that works.
fn finish(args: &WhatIfArgs, report: &WhatIf, code: u8) -> ExitCode {
    let json = serde_json::to_string_pretty(report).unwrap_or_default() + "\n";
    if let Some(out) = &args.out
        && let Err(e) = write_out(
            out,
            &json,
            &report.changed,
            report.passes_changed.as_deref().unwrap_or_default(),
        )
    {
        return failed(&e, 2);
    }
    let printed = print_stdout(&if args.json { json } else { text(report) });
    match printed {
        Ok(_) => ExitCode::from(code),
        Err(e) => failed(&e, 2),
    }
}
