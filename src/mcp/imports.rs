//! `open_capture` on what `framelab import` reads (a GFXReconstruct `.gfxr` or JSON Lines
//! stream, a RenderDoc `.rdc`): imported by the same code as the command, then written with
//! its side files (SPIR-V modules, memory contents) into the server's own scratch folder under
//! the system's temporary directory, never beside the input, and opened from there like any
//! capture. The folder goes when the capture is closed and when the server ends.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use framelab_core::import::{ImportOptions, Imported, gfxr, import, rdc};

/// Whether `path` is one `framelab import` reads rather than a framelab capture: a binary
/// GFXReconstruct or RenderDoc capture by its header, a JSON Lines stream by its extension.
pub fn is_import(path: &Path) -> Result<bool, String> {
    let file = framelab_core::files::open(path).map_err(|e| e.to_string())?;
    let mut reader = BufReader::new(file);
    let head = reader
        .fill_buf()
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(gfxr::is_gfxr(head) || rdc::is_rdc(head) || path.extension().is_some_and(|x| x == "jsonl"))
}

/// The server's scratch folder.
pub fn scratch() -> PathBuf {
    std::env::temp_dir().join(format!("framelab-mcp-{}", std::process::id()))
}

/// Imports `path` and writes the capture and its side files into `dir` (made anew); returns
/// the capture file written there.
pub fn import_into(path: &Path, dir: &Path) -> Result<PathBuf, String> {
    let stem = path.file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    let _ = std::fs::remove_dir_all(dir);
    let capture = dir.join(format!("{stem}.json"));
    import_to(path, &capture)?;
    Ok(capture)
}

/// Imports `path` and writes the capture at `capture`, its side files beside it.
pub fn import_to(path: &Path, capture: &Path) -> Result<(), String> {
    let name = path.display().to_string();
    let dir = capture.parent().unwrap_or(Path::new("."));
    let stem = capture.file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    let file = framelab_core::files::open(path).map_err(|e| e.to_string())?;
    let len = file.metadata().ok().map(|m| m.len());
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let head = reader
        .fill_buf()
        .map_err(|e| format!("cannot read {name}: {e}"))?;
    let options = ImportOptions::default();
    let imported: Imported = if gfxr::is_gfxr(head) {
        gfxr::import(reader, len, &name, &stem, &options)
    } else if rdc::is_rdc(head) {
        drop(reader);
        rdc::import_file(path, &name, &stem, &options)
    } else {
        import(reader, &name, &options)
    }
    .map_err(|e| e.to_string())?;
    let parent = |p: &Path| -> Result<(), String> {
        match p.parent() {
            Some(parent) => std::fs::create_dir_all(parent)
                .map_err(|e| format!("cannot create {}: {e}", parent.display())),
            None => Ok(()),
        }
    };
    for f in &imported.side_files {
        let p = dir.join(&f.path);
        parent(&p)?;
        f.write(&p)
            .map_err(|e| format!("cannot write {}: {e}", p.display()))?;
    }
    let text = serde_json::to_string_pretty(&imported.capture)
        .map_err(|e| format!("the imported capture does not serialise: {e}"))?;
    parent(capture)?;
    std::fs::write(capture, text.as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", capture.display()))
}
