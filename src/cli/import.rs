//! `framelab import`: a GFXReconstruct or RenderDoc capture, or a JSON Lines stream, to a
//! capture by core's import journey (`import::import_file`: validated before it is written,
//! atomically, so an import gives a capture every command accepts or nothing), and a summary
//! of what was found and what was left out.

use framelab_core::text::{one_line, one_line_within};
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use framelab_core::capture::Options;
use framelab_core::capture::format::RawCapture;
use framelab_core::import::gfxr::edit::FieldEdit;
use framelab_core::import::{
    FileImportError, ImportOptions, Imported, Summary, Written, import_file,
};

use super::{count, print_diagnostics, print_stdout};

/// `N` or `A-B` (0-based, inclusive).
pub(crate) fn parse_frames(text: &str) -> anyhow::Result<(u32, u32)> {
    let num = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| anyhow::anyhow!("\"{s}\" is not a frame number"))
    };
    match text.split_once('-') {
        Some((a, b)) => {
            let (a, b) = (num(a)?, num(b)?);
            if a > b {
                return Err(anyhow::anyhow!("frame range {a}-{b} is empty"));
            }
            Ok((a, b))
        }
        None => num(text).map(|n| (n, n)),
    }
}

/// Imports `input` into `out` and the side files beside it, written only if the capture
/// validates (core's one import journey); the import and the path written (a device path
/// resolved). A capture that does not validate has its problems printed, naming `out`.
pub(super) fn import_to(
    input: &Path,
    out: &Path,
    frames: Option<(u32, u32)>,
) -> anyhow::Result<(Imported, std::path::PathBuf)> {
    let options = ImportOptions {
        frames,
        ..ImportOptions::default()
    };
    match import_file(input, out, &options) {
        Ok(Written { imported, path }) => Ok((imported, path)),
        Err(FileImportError::Invalid { name, diagnostics }) => {
            print_diagnostics(&diagnostics, out);
            anyhow::bail!(
                "the capture imported from {name} does not validate ({} problems above); nothing was written",
                diagnostics.len()
            )
        }
        Err(e) => Err(e.into()),
    }
}

pub fn run(
    input: &Path,
    out: &Path,
    frames: Option<(u32, u32)>,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let (imported, out) = import_to(input, out, frames)?;
    let out = &out;
    if json {
        print_stdout(&(serde_json::to_string_pretty(&imported.summary)? + "\n"))?;
    } else {
        print_stdout(&render(&imported.summary, out))?;
        if imported.summary.not_replayable.is_none() {
            print_stdout(&format!(
                "replays: {}\n",
                replay_verdict(out, imported.capture)
            ))?;
        }
    }
    let _ = std::io::stderr().flush();
    Ok(ExitCode::SUCCESS)
}

/// Whether the written capture lowers to a replay plan on a device with every feature
/// framelab asks for: "yes", or "no" with the pass, the draw and the class that stop it, so
/// what replay cannot do is said at import and not first at `replay`.
fn replay_verdict(out: &Path, capture: RawCapture) -> String {
    // The capture in memory, its side files now beside `out` where its paths lead.
    let lowered = framelab_core::pipeline::Loaded::from_raw(out, capture)
        .validate(&Options::default())
        .and_then(|v| v.analyse(framelab_core::analysis::report::AnalyzeOptions { cull: false }))
        .and_then(|a| {
            a.lower_with(
                framelab_core::lower::wanted_features(),
                "any adapter",
                framelab_core::lower::Texels::LeaveOut,
            )
        });
    match lowered {
        Ok(l) => {
            let unknown = framelab_core::pipeline::unknown_reads(l.capture(), &l.pass_ids);
            let mut yes = "yes (on an adapter with the features framelab asks for)".to_owned();
            if let Some((resource, pass)) = unknown.first() {
                yes += &format!(
                    ", but {} it reads before writing start{} cleared: the capture holds no contents for {} (first \"{resource}\", read by pass \"{pass}\"; `replay` names each)",
                    count(unknown.len(), "resource", "resources"),
                    if unknown.len() == 1 { "s" } else { "" },
                    if unknown.len() == 1 { "it" } else { "them" },
                );
            }
            yes
        }
        Err(e) => format!("no — {}", one_line_within(&e.to_string(), 600)),
    }
}

fn render(s: &Summary, out: &Path) -> String {
    let mut t = String::new();
    let unit = match s.dialect.as_str() {
        "binary" => "block",
        "renderdoc" => "chunk",
        _ => "line",
    };
    let frames = if s.frames_imported.0 == s.frames_imported.1 {
        format!("frame {}", s.frames_imported.0)
    } else {
        format!("frames {}-{}", s.frames_imported.0, s.frames_imported.1)
    };
    let read = if s.stopped_after_selection {
        format!("read up to the end of frame {}: ", s.frames_imported.1)
    } else {
        String::new()
    };
    // The binary route's tool line says "binary" already.
    let dialect = if s.dialect == "binary" {
        String::new()
    } else {
        format!(" ({} dialect)", s.dialect)
    };
    t += &format!(
        "{}: {}{dialect}, {read}{} {unit}s, {} calls, {} frame(s)\n",
        one_line(&s.file),
        one_line(&s.tool),
        s.lines,
        s.calls,
        s.frames_in_stream
    );
    let kinds: Vec<String> = s
        .passes_by_kind
        .iter()
        .map(|(k, n)| format!("{n} {k}"))
        .collect();
    t += &format!(
        "imported {frames} to {}: {} ({}), {}, {}\n",
        out.display(),
        count(s.passes, "pass", "passes"),
        kinds.join(", "),
        count(s.draws, "draw", "draws"),
        count(s.dispatches, "dispatch", "dispatches")
    );
    t += &format!(
        "  {}, {} in {}, {}, {}, {} (from semaphores between queues)\n",
        count(s.images, "image", "images"),
        count(s.buffers, "buffer", "buffers"),
        count(s.heaps, "heap", "heaps"),
        count(s.queues, "queue", "queues"),
        count(s.recorded_barriers, "recorded barrier", "recorded barriers"),
        count(s.fences, "fence", "fences")
    );
    if s.pipelines > 0 {
        t += &format!(
            "  {} bound by the draws and dispatches\n",
            count(s.pipelines, "Vulkan pipeline", "Vulkan pipelines")
        );
    }
    if let Some(n) = s.shader_modules {
        t += &format!(
            "  {}\n",
            count(n, "SPIR-V shader module", "SPIR-V shader modules")
        );
    }
    if let Some(c) = &s.contents {
        t += &format!(
            "  contents of {} resources at the start of the frame ({} bytes; {} mapped-memory writes before it)\n",
            c.resources, c.bytes, c.memory_writes
        );
    }
    if s.sync_hazards > 0 {
        t += &format!(
            "  {} synchronization hazard(s) found in the imported frames (`framelab analyze` lists them as FL020)\n",
            s.sync_hazards
        );
    }
    if s.valid_usage > 0 {
        t += &format!(
            "  {} valid-usage error(s) found in the calls (`framelab analyze` lists them as FL025 with their VUIDs)\n",
            s.valid_usage
        );
    }
    if !s.skipped.is_empty() || !s.not_modelled.is_empty() {
        t += "left out or approximated:\n";
        for k in &s.skipped {
            let at = k
                .first_line
                .map(|l| format!(" (first at {unit} {l})"))
                .unwrap_or_default();
            // A count only where something happened more than once: a note met once may
            // itself list several names.
            let times = if k.count > 1 {
                format!("{}x ", k.count)
            } else {
                String::new()
            };
            // A note is framelab's sentence quoting names from the stream (each at most
            // 256 characters): cut only where a note is far longer than any should be.
            t += &format!("  {times}{}{at}\n", one_line_within(&k.what, 1_000));
        }
    }
    if !s.not_modelled.is_empty() {
        let total: u64 = s.not_modelled.values().sum();
        let mut top: Vec<(&String, &u64)> = s.not_modelled.iter().collect();
        top.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let shown: Vec<String> = top
            .iter()
            .take(6)
            .map(|(n, c)| format!("{} {c}", one_line(n)))
            .collect();
        t += &format!(
            "  {total} calls of {} functions create or record nothing framelab models ({}{})\n",
            s.not_modelled.len(),
            shown.join(", "),
            if top.len() > 6 { ", ..." } else { "" }
        );
    }
    if let Some(why) = &s.not_replayable {
        t += &format!("not replayable yet: {why}\n");
    }
    t
}

/// `framelab edit`: the capture with the edits applied, written next to `out` and renamed
/// into place, so a failed edit leaves nothing behind.
pub fn edit(capture: &Path, out: &Path, edits: &[FieldEdit]) -> anyhow::Result<ExitCode> {
    let bytes =
        std::fs::read(capture).with_context(|| format!("cannot read {}", capture.display()))?;
    if !framelab_core::import::gfxr::is_gfxr(&bytes) {
        anyhow::bail!(
            "{}: not a GFXReconstruct binary capture (no `GFXR` header)",
            capture.display()
        );
    }
    let edited = framelab_core::import::gfxr::edit::apply(&bytes, edits)
        .map_err(|e| anyhow::anyhow!("{}: {e}", capture.display()))?;
    let staging = out.with_extension("gfxr.partial");
    std::fs::write(&staging, &edited)
        .with_context(|| format!("cannot write {}", staging.display()))?;
    std::fs::rename(&staging, out).with_context(|| format!("cannot write {}", out.display()))?;
    println!(
        "{}: {} edit(s) applied, written to {}",
        capture.display(),
        edits.len(),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
