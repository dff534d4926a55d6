//! `framelab import`: a GFXReconstruct JSON Lines stream to a capture, validated before it is
//! written (atomically) so that an import either gives a capture every command accepts or
//! nothing, and a summary of what was found and what was left out.

use framelab_core::text::{one_line, one_line_within};
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use framelab_core::capture::format::RawCapture;
use framelab_core::capture::validate::validate;
use framelab_core::capture::{CaptureError, Options};
use framelab_core::files::{self, FileError};
use framelab_core::import::gfxr::edit::FieldEdit;
use framelab_core::import::{ImportOptions, Imported, Summary, gfxr, import, rdc};

use super::{count, print_diagnostics, print_stdout};

/// `N` or `A-B` (0-based, inclusive).
pub(crate) fn parse_frames(text: &str) -> Result<(u32, u32), String> {
    let num = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("\"{s}\" is not a frame number"))
    };
    match text.split_once('-') {
        Some((a, b)) => {
            let (a, b) = (num(a)?, num(b)?);
            if a > b {
                return Err(format!("frame range {a}-{b} is empty"));
            }
            Ok((a, b))
        }
        None => num(text).map(|n| (n, n)),
    }
}

/// Imports `input` into `out` and the side files beside it, written only if the capture
/// validates; the import and the path written (a device path resolved).
pub(super) fn import_to(
    input: &Path,
    out: &Path,
    frames: Option<(u32, u32)>,
) -> anyhow::Result<(Imported, std::path::PathBuf)> {
    // Side files go beside the file the capture lands in, where its relative paths lead.
    let at = framelab_core::output::check_output(out, &[input])?;
    let out = &at.path.clone();
    // Read line by line, so no size limit; but only a regular file (a named pipe would block,
    // a device never end).
    let file = files::open(input).map_err(|e| match e {
        FileError::NotRegular { path, kind } => {
            anyhow::anyhow!("{} is not a regular file: it is {kind}", path.display())
        }
        e => anyhow::anyhow!("{e}"),
    })?;
    let name = input.display().to_string();
    let len = file.metadata().ok().map(|m| m.len());
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let head = reader
        .fill_buf()
        .map_err(|e| anyhow::anyhow!("cannot read {name}: {e}"))?;
    // A byte-order mark before a JSON Lines stream is an editor's, not the stream's.
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    let options = ImportOptions {
        frames,
        ..ImportOptions::default()
    };
    let stem = out.file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    if let Some(why) = not_a_stream(head) {
        anyhow::bail!("{name}: {why}");
    }
    let imported = if gfxr::is_gfxr(head) {
        gfxr::import(reader, len, &name, &stem, &options)?
    } else if rdc::is_rdc(head) {
        drop(reader);
        rdc::import_file(input, &name, &stem, &options)?
    } else if head
        .iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|b| *b != b'{' && *b != b'[')
    {
        anyhow::bail!(
            "{name}: neither a GFXReconstruct binary capture (it does not start with `GFXR`), a RenderDoc capture (`RDOC`) nor a JSON Lines stream (gfxrecon-convert)"
        );
    } else {
        import(reader, &name, &options)?
    };
    let text = serde_json::to_string_pretty(&imported.capture)? + "\n";
    // A capture framelab could not read back is not written.
    let limit = framelab_core::files::CAPTURE.bytes;
    if text.len() as u64 > limit {
        anyhow::bail!(
            "{name}: the imported capture would be {}, over the {} framelab reads; import fewer frames (--frame N or --frames A-B)",
            framelab_core::text::human_bytes(text.len() as u64),
            framelab_core::text::human_bytes(limit)
        );
    }
    if imported.side_files.is_empty() {
        check(&imported.capture, out, out, &name)?;
        framelab_core::output::write_atomically(out, text.as_bytes())?;
    } else if at.device {
        anyhow::bail!(
            "{} is a device, and the capture imported from {name} has side files to go beside it; choose a file",
            out.display()
        );
    } else {
        write_with_side_files(&imported, out, &text, &name)?;
    }
    Ok((imported, at.path))
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
        .and_then(|a| a.lower(framelab_core::lower::wanted_features(), "any adapter"));
    match lowered {
        Ok(_) => "yes (on an adapter with the features framelab asks for)".to_owned(),
        Err(e) => format!("no — {}", one_line_within(&e.to_string(), 600)),
    }
}

/// Validates the capture as it would be written at `at`; messages name `out`.
fn check(capture: &RawCapture, at: &Path, out: &Path, name: &str) -> anyhow::Result<()> {
    match validate(capture, at, &Options::default()) {
        Ok(_) => Ok(()),
        Err(CaptureError::Invalid { diagnostics, .. }) => {
            print_diagnostics(&diagnostics, out);
            anyhow::bail!(
                "the capture imported from {name} does not validate ({} problems above); nothing was written",
                diagnostics.len()
            );
        }
        Err(e) => Err(e.into()),
    }
}

/// Writes the capture and its side files so that a failure leaves nothing half-written: all
/// of it goes to a staging folder beside `out` first and is validated there; then each side
/// folder replaces the one of the same name and the capture is written last.
fn write_with_side_files(
    imported: &Imported,
    out: &Path,
    text: &str,
    name: &str,
) -> anyhow::Result<()> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let file_name = out
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{} names no file", out.display()))?;
    let staging = dir.join(format!(
        ".{}.import-{}",
        file_name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> anyhow::Result<()> {
        let mut folders = std::collections::BTreeSet::new();
        for f in &imported.side_files {
            let path = staging.join(&f.path);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)
                    .with_context(|| format!("cannot create {}", parent.display()))?;
            }
            f.write(&path)
                .with_context(|| format!("cannot write {}", path.display()))?;
            if let Some(top) = Path::new(&f.path).components().next() {
                folders.insert(top.as_os_str().to_owned());
            }
        }
        check(&imported.capture, &staging.join(file_name), out, name)?;
        for folder in &folders {
            replaceable(&dir.join(folder))?;
        }
        for folder in folders {
            let target = dir.join(&folder);
            if target.is_dir() {
                std::fs::remove_dir_all(&target)
                    .with_context(|| format!("cannot replace {}", target.display()))?;
            }
            std::fs::rename(staging.join(&folder), &target)
                .with_context(|| format!("cannot move side files to {}", target.display()))?;
        }
        framelab_core::output::write_atomically(out, text.as_bytes())?;
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&staging);
    result
}

/// Whether the side folder `folder` may be replaced by a new import's: absent, or holding only
/// files of the kind an import writes there (an import replaces the whole folder, so anything
/// else in it would be lost).
fn replaceable(folder: &Path) -> anyhow::Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(folder) else {
        return Ok(());
    };
    if !meta.is_dir() {
        anyhow::bail!(
            "{} is in the way of the import's side files: it is {}",
            folder.display(),
            files::kind(&meta.file_type())
        );
    }
    let written = match folder.extension().and_then(|e| e.to_str()) {
        Some("shaders") => "spv",
        _ => "bin",
    };
    let mut foreign = Vec::new();
    for entry in
        std::fs::read_dir(folder).with_context(|| format!("reading {}", folder.display()))?
    {
        let entry = entry.with_context(|| format!("reading {}", folder.display()))?;
        let path = entry.path();
        let ours = entry.file_type().is_ok_and(|t| t.is_file())
            && path.extension().is_some_and(|e| e == written);
        if !ours {
            foreign.push(entry.file_name().to_string_lossy().into_owned());
        }
    }
    if foreign.is_empty() {
        return Ok(());
    }
    foreign.sort();
    anyhow::bail!(
        "{} holds {} entr{} an import does not write ({}); an import replaces the whole folder, so choose another -o or move them",
        folder.display(),
        foreign.len(),
        if foreign.len() == 1 { "y" } else { "ies" },
        super::first_few(&foreign),
    )
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

/// Why the file's first bytes cannot begin any capture `import` reads, where that can be told
/// before reading on: an empty file, a framelab capture (which needs no import), or a JSON
/// document spread over lines (a JSON Lines stream has one object per line).
fn not_a_stream(head: &[u8]) -> Option<&'static str> {
    let text = head.trim_ascii_start();
    if text.is_empty() {
        return Some("the file is empty");
    }
    let window = &text[..text.len().min(4096)];
    if window.windows(16).any(|w| w == b"\"format_version\"") {
        return Some(
            "already a framelab capture (it has `format_version`): validate, analyze, replay and inspect read it as it is",
        );
    }
    let first = text.split(|&b| b == b'\n').next().unwrap_or_default();
    matches!(first.trim_ascii(), b"{" | b"[")
        .then_some("a JSON document over several lines, not a JSON Lines stream (gfxrecon-convert writes one object per line)")
}
