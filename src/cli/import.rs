//! `framelab import`: a GFXReconstruct JSON Lines stream to a capture, validated before it is
//! written (atomically) so that an import either gives a capture every command accepts or
//! nothing, and a summary of what was found and what was left out.

use std::io::{BufReader, Write};
use std::path::Path;
use std::process::ExitCode;

use framelab_core::capture::validate::validate;
use framelab_core::capture::{CaptureError, Options};
use framelab_core::files::{self, FileError};
use framelab_core::import::{ImportOptions, Summary, import};

use super::{print_diagnostics, print_stdout};

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

pub fn run(
    input: &Path,
    out: &Path,
    frames: Option<(u32, u32)>,
    json: bool,
) -> anyhow::Result<ExitCode> {
    // Read line by line, so no size limit; but only a regular file (a named pipe would block,
    // a device never end).
    let file = files::open(input).map_err(|e| match e {
        FileError::NotRegular { path, kind } => {
            anyhow::anyhow!("{} is not a regular file: it is {kind}", path.display())
        }
        e => anyhow::anyhow!("{e}"),
    })?;
    let name = input.display().to_string();
    let imported = import(BufReader::new(file), &name, &ImportOptions { frames })?;
    let text = serde_json::to_string_pretty(&imported.capture)? + "\n";
    // Validate what would be written, resolving against the output's folder.
    match validate(&imported.capture, out, &Options::default()) {
        Ok(_) => {}
        Err(CaptureError::Invalid { diagnostics, .. }) => {
            print_diagnostics(&diagnostics, out);
            anyhow::bail!(
                "the capture imported from {name} does not validate ({} problems above); nothing was written",
                diagnostics.len()
            );
        }
        Err(e) => return Err(e.into()),
    }
    framelab_core::output::write_atomically(out, text.as_bytes())?;
    if json {
        print_stdout(&(serde_json::to_string_pretty(&imported.summary)? + "\n"))?;
    } else {
        print_stdout(&render(&imported.summary, out))?;
    }
    let _ = std::io::stderr().flush();
    Ok(ExitCode::SUCCESS)
}

fn render(s: &Summary, out: &Path) -> String {
    let mut t = String::new();
    let frames = if s.frames_imported.0 == s.frames_imported.1 {
        format!("frame {}", s.frames_imported.0)
    } else {
        format!("frames {}-{}", s.frames_imported.0, s.frames_imported.1)
    };
    t += &format!(
        "{}: {} ({} dialect), {} lines, {} calls, {} frame(s)\n",
        s.file, s.tool, s.dialect, s.lines, s.calls, s.frames_in_stream
    );
    let kinds: Vec<String> = s
        .passes_by_kind
        .iter()
        .map(|(k, n)| format!("{n} {k}"))
        .collect();
    t += &format!(
        "imported {frames} to {}: {} passes ({}), {} draws, {} dispatches\n",
        out.display(),
        s.passes,
        kinds.join(", "),
        s.draws,
        s.dispatches
    );
    t += &format!(
        "  {} images, {} buffers in {} heaps, {} queues, {} recorded barriers, {} fences\n",
        s.images, s.buffers, s.heaps, s.queues, s.recorded_barriers, s.fences
    );
    if !s.skipped.is_empty() {
        t += "left out or approximated:\n";
        for k in &s.skipped {
            let at = k
                .first_line
                .map(|l| format!(" (first at line {l})"))
                .unwrap_or_default();
            t += &format!("  {}x {}{at}\n", k.count, k.what);
        }
    }
    if !s.not_modelled.is_empty() {
        let total: u64 = s.not_modelled.values().sum();
        let mut top: Vec<(&String, &u64)> = s.not_modelled.iter().collect();
        top.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let shown: Vec<String> = top
            .iter()
            .take(6)
            .map(|(n, c)| format!("{n} {c}"))
            .collect();
        t += &format!(
            "  {total} calls of {} functions create or record nothing framelab models ({}{})\n",
            s.not_modelled.len(),
            shown.join(", "),
            if top.len() > 6 { ", ..." } else { "" }
        );
    }
    t
}
