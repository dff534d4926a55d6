//! The import journey every front end takes, from a file to a written capture: the input is
//! told apart by its first bytes (a GFXReconstruct binary capture, a RenderDoc capture, a
//! JSON Lines stream), imported, and written with its side files only after the capture
//! validates where it will lie, so that an import gives a capture every command accepts or
//! nothing. The CLI's `import`, the MCP server's `open_capture` and `what-if`'s scratch
//! imports call [`import_file`] and only say what it returned.

use std::collections::BTreeSet;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use super::{ImportError, ImportOptions, Imported, gfxr, import, rdc};
use crate::capture::diag::Diagnostic;
use crate::capture::validate::validate;
use crate::capture::{CaptureError, Options};
use crate::files::{self, FileError};
use crate::output::OutputError;
use crate::text::{first_few, human_bytes};

/// What a file to import is, by its first bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// A GFXReconstruct binary capture (`GFXR`).
    Gfxr,
    /// A RenderDoc capture (`RDOC`).
    Rdc,
    /// A JSON Lines stream, as `gfxrecon-convert` writes it.
    JsonLines,
}

/// Why an import read or wrote nothing.
#[derive(Debug, thiserror::Error)]
pub enum FileImportError {
    #[error("{} is not a regular file: it is {kind}", path.display())]
    NotRegular { path: PathBuf, kind: &'static str },
    #[error(transparent)]
    File(FileError),
    #[error("cannot read {name}: {error}")]
    Read { name: String, error: std::io::Error },
    #[error("{name}: {why}")]
    NotAStream { name: String, why: &'static str },
    #[error(transparent)]
    Import(#[from] ImportError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(
        "{name}: the imported capture would be {}, over the {} framelab reads; import fewer frames (--frame N or --frames A-B)",
        human_bytes(*size),
        human_bytes(*limit)
    )]
    TooLarge { name: String, size: u64, limit: u64 },
    #[error(
        "{} is a device, and the capture imported from {name} has side files to go beside it; choose a file",
        out.display()
    )]
    SideFilesToDevice { out: PathBuf, name: String },
    /// The capture does not validate: nothing was written. The diagnostics name the capture
    /// as it would have been written.
    #[error(
        "the capture imported from {name} does not validate ({} problems); nothing was written",
        diagnostics.len()
    )]
    Invalid {
        name: String,
        diagnostics: Vec<Diagnostic>,
    },
    #[error(transparent)]
    Capture(Box<CaptureError>),
    #[error("{} is in the way of the import's side files: it is {kind}", path.display())]
    InTheWay { path: PathBuf, kind: &'static str },
    #[error(
        "{} holds {} entr{} an import does not write ({}); an import replaces the whole folder, so choose another -o or move them",
        folder.display(),
        foreign.len(),
        if foreign.len() == 1 { "y" } else { "ies" },
        first_few(foreign)
    )]
    Foreign {
        folder: PathBuf,
        foreign: Vec<String>,
    },
    #[error("{what} {}: {error}", path.display())]
    Io {
        what: &'static str,
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("the imported capture does not serialise: {0}")]
    Serialise(#[from] serde_json::Error),
}

/// An import written: what it found and made, and the path the capture went to (a link
/// followed to its file).
pub struct Written {
    pub imported: Imported,
    pub path: PathBuf,
}

impl std::fmt::Debug for Written {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Written")
            .field("path", &self.path)
            .field("summary", &self.imported.summary)
            .finish_non_exhaustive()
    }
}

/// What the first bytes of a file say it is, or why they cannot begin any capture `import`
/// reads (told before reading on).
pub fn sniff(head: &[u8]) -> Result<Source, &'static str> {
    // A byte-order mark before a JSON Lines stream is an editor's, not the stream's.
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    if let Some(why) = not_a_stream(head) {
        return Err(why);
    }
    if gfxr::is_gfxr(head) {
        Ok(Source::Gfxr)
    } else if rdc::is_rdc(head) {
        Ok(Source::Rdc)
    } else if head
        .iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|b| *b != b'{' && *b != b'[')
    {
        Err(
            "neither a GFXReconstruct binary capture (it does not start with `GFXR`), a RenderDoc capture (`RDOC`) nor a JSON Lines stream (gfxrecon-convert)",
        )
    } else {
        Ok(Source::JsonLines)
    }
}

/// What `path` is, by its first bytes.
pub fn sniff_file(path: &Path) -> Result<Source, FileImportError> {
    let (mut reader, name) = open_input(path)?;
    let head = head(&mut reader, &name)?;
    sniff(head).map_err(|why| FileImportError::NotAStream { name, why })
}

/// Imports `input` and writes the capture at `out` with its side files beside it, each only if
/// the capture validates there; `out` may not be the input.
pub fn import_file(
    input: &Path,
    out: &Path,
    options: &ImportOptions,
) -> Result<Written, FileImportError> {
    // Side files go beside the file the capture lands in, where its relative paths lead.
    let at = crate::output::check_output(out, &[input])?;
    let out = at.path.as_path();
    let (mut reader, name) = open_input(input)?;
    let stem = out.file_stem().map_or_else(
        || "imported".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    let source = sniff(head(&mut reader, &name)?).map_err(|why| FileImportError::NotAStream {
        name: name.clone(),
        why,
    })?;
    let len = reader.get_ref().metadata().ok().map(|m| m.len());
    let imported = match source {
        Source::Gfxr => gfxr::import(reader, len, &name, &stem, options)?,
        Source::Rdc => {
            drop(reader);
            rdc::import_file(input, &name, &stem, options)?
        }
        Source::JsonLines => import(reader, &name, options)?,
    };
    let text = serde_json::to_string_pretty(&imported.capture)? + "\n";
    // A capture framelab could not read back is not written.
    let limit = files::CAPTURE.bytes;
    if text.len() as u64 > limit {
        return Err(FileImportError::TooLarge {
            name,
            size: text.len() as u64,
            limit,
        });
    }
    if imported.side_files.is_empty() {
        check(&imported, out, &name)?;
        crate::output::write_atomically(out, text.as_bytes())?;
    } else if at.device {
        return Err(FileImportError::SideFilesToDevice {
            out: out.to_path_buf(),
            name,
        });
    } else {
        write_with_side_files(&imported, out, &text, &name)?;
    }
    Ok(Written {
        imported,
        path: at.path,
    })
}

/// The input, read only if it is a regular file (a named pipe would block, a device never
/// end); read line by line, so no size limit.
fn open_input(input: &Path) -> Result<(BufReader<std::fs::File>, String), FileImportError> {
    let file = files::open(input).map_err(|e| match e {
        FileError::NotRegular { path, kind } => FileImportError::NotRegular { path, kind },
        e => FileImportError::File(e),
    })?;
    Ok((
        BufReader::with_capacity(1 << 20, file),
        input.display().to_string(),
    ))
}

fn head<'r>(
    reader: &'r mut BufReader<std::fs::File>,
    name: &str,
) -> Result<&'r [u8], FileImportError> {
    reader.fill_buf().map_err(|error| FileImportError::Read {
        name: name.to_owned(),
        error,
    })
}

/// Validates the capture as it would be written at `at`.
fn check(imported: &Imported, at: &Path, name: &str) -> Result<(), FileImportError> {
    match validate(&imported.capture, at, &Options::default()) {
        Ok(_) => Ok(()),
        Err(CaptureError::Invalid { diagnostics, .. }) => Err(FileImportError::Invalid {
            name: name.to_owned(),
            diagnostics,
        }),
        Err(e) => Err(FileImportError::Capture(Box::new(e))),
    }
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> FileImportError {
    let path = path.to_path_buf();
    move |error| FileImportError::Io { what, path, error }
}

/// Writes the capture and its side files so that a failure leaves nothing half-written: all
/// of it goes to a staging folder beside `out` first and is validated there; then each side
/// folder replaces the one of the same name and the capture is written last.
fn write_with_side_files(
    imported: &Imported,
    out: &Path,
    text: &str,
    name: &str,
) -> Result<(), FileImportError> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let file_name = out.file_name().ok_or_else(|| FileImportError::Io {
        what: "cannot write",
        path: out.to_path_buf(),
        error: std::io::Error::other("it names no file"),
    })?;
    let staging = dir.join(format!(
        ".{}.import-{}",
        file_name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut folders = BTreeSet::new();
        for f in &imported.side_files {
            let path = staging.join(&f.path);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(io("cannot create", parent))?;
            }
            f.write(&path).map_err(io("cannot write", &path))?;
            if let Some(top) = Path::new(&f.path).components().next() {
                folders.insert(top.as_os_str().to_owned());
            }
        }
        check(imported, &staging.join(file_name), name)?;
        for folder in &folders {
            replaceable(&dir.join(folder))?;
        }
        for folder in folders {
            let target = dir.join(&folder);
            if target.is_dir() {
                std::fs::remove_dir_all(&target).map_err(io("cannot replace", &target))?;
            }
            std::fs::rename(staging.join(&folder), &target)
                .map_err(io("cannot move side files to", &target))?;
        }
        crate::output::write_atomically(out, text.as_bytes())?;
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&staging);
    result
}

/// Whether the side folder `folder` may be replaced by a new import's: absent, or holding only
/// files of the kind an import writes there (an import replaces the whole folder, so anything
/// else in it would be lost).
fn replaceable(folder: &Path) -> Result<(), FileImportError> {
    let Ok(meta) = std::fs::symlink_metadata(folder) else {
        return Ok(());
    };
    if !meta.is_dir() {
        return Err(FileImportError::InTheWay {
            path: folder.to_path_buf(),
            kind: files::kind(&meta.file_type()),
        });
    }
    let written = match folder.extension().and_then(|e| e.to_str()) {
        Some("shaders") => "spv",
        _ => "bin",
    };
    let mut foreign = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(io("reading", folder))? {
        let entry = entry.map_err(io("reading", folder))?;
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
    Err(FileImportError::Foreign {
        folder: folder.to_path_buf(),
        foreign,
    })
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
