//! `open_capture` on what `framelab import` reads (a GFXReconstruct `.gfxr` or JSON Lines
//! stream, a RenderDoc `.rdc`): told apart and imported by core's one import journey
//! (`import::import_file`: sniffed by content, validated before anything is written, side
//! files staged and moved into place), written into the server's own scratch folder under the
//! system's temporary directory, never beside the input, and opened from there like any
//! capture. The folder goes when the capture is closed and when the server ends.

use std::path::{Path, PathBuf};

use framelab_core::import::{FileImportError, ImportOptions, import_file, sniff_file};

/// Whether `path` is one `framelab import` reads rather than a framelab capture, by its first
/// bytes: a file that cannot begin an import stream (a framelab capture among them) is left to
/// the capture loader, which says what is wrong with it.
pub fn is_import(path: &Path) -> anyhow::Result<bool> {
    match sniff_file(path) {
        Ok(_) => Ok(true),
        Err(FileImportError::NotAStream { .. }) => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// The server's scratch folder.
pub fn scratch() -> PathBuf {
    std::env::temp_dir().join(format!("framelab-mcp-{}", std::process::id()))
}

/// Imports `path` and writes the capture and its side files into `dir` (made anew); returns
/// the capture file written there.
pub fn import_into(path: &Path, dir: &Path) -> anyhow::Result<PathBuf> {
    let stem = path.file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    let _ = std::fs::remove_dir_all(dir);
    let capture = dir.join(format!("{stem}.json"));
    import_to(path, &capture)?;
    Ok(capture)
}

/// Imports `path` and writes the capture at `capture`, its side files beside it; a capture
/// that does not validate is refused with its first problems.
pub fn import_to(path: &Path, capture: &Path) -> anyhow::Result<()> {
    if let Some(parent) = capture.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", parent.display()))?;
    }
    match import_file(path, capture, &ImportOptions::default()) {
        Ok(_) => Ok(()),
        Err(FileImportError::Invalid { name, diagnostics }) => {
            let shown: Vec<String> = diagnostics.iter().take(5).map(|d| d.to_string()).collect();
            Err(anyhow::anyhow!(
                "the capture imported from {name} does not validate ({} problems; nothing was written): {}",
                diagnostics.len(),
                shown.join("; ")
            ))
        }
        Err(e) => Err(e.into()),
    }
}
