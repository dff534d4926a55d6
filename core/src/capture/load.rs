//! Reading a capture file: bytes to `RawCapture`, with syntax and structure errors located by
//! file, line and column (and JSON path for structure errors), and the format version checked
//! before anything else so that a newer file gets "unsupported version", not a field error.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::diag::Diagnostic;
use super::format::{FORMAT_VERSION, RawCapture};

/// Why a capture could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum CaptureError {
    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Not a regular file, or over the size limit for a capture.
    #[error(transparent)]
    File(crate::files::FileError),
    #[error("{}:{line}:{column}: JSON syntax error: {message}", path.display())]
    Syntax {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// Reported where a syntax error would be (1:1), as one: the file is not JSON text.
    #[error("{}:1:1: JSON syntax error: {problem}", path.display())]
    Encoding {
        path: PathBuf,
        problem: EncodingError,
    },
    #[error("{}:{line}:{column}: {json_path}: {message}", path.display())]
    Structure {
        path: PathBuf,
        json_path: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error(
        "{}: unsupported format_version {found}; this framelab reads version {supported}",
        path.display()
    )]
    UnsupportedVersion {
        path: PathBuf,
        found: u64,
        supported: u32,
    },
    /// A capture of another tool, which `framelab import` reads: said as such, since its bytes
    /// would otherwise be reported as broken JSON.
    #[error(
        "{}: {what}, not a framelab capture; bring it in first with `framelab import {} -o <capture.json>`",
        path.display(),
        path.display()
    )]
    NeedsImport { path: PathBuf, what: &'static str },
    #[error("{}: {} error(s) in capture", path.display(), count_errors(diagnostics))]
    Invalid {
        path: PathBuf,
        diagnostics: Vec<Diagnostic>,
    },
}

fn count_errors(diagnostics: &[Diagnostic]) -> usize {
    diagnostics
        .iter()
        .filter(|d| d.severity == super::diag::Severity::Error)
        .count()
}

impl CaptureError {
    /// Every problem as diagnostics, for uniform printing and `--json` output.
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        use super::diag::Severity::Error;
        let one = |code: &'static str, path: String, message: String| {
            vec![Diagnostic {
                severity: Error,
                code,
                path,
                message,
                suggestion: None,
            }]
        };
        match self {
            CaptureError::Read { source, .. } => one("read", "$".into(), source.to_string()),
            CaptureError::NeedsImport { what, .. } => one(
                "needs-import",
                "$".into(),
                format!("{what}: run `framelab import` on it first"),
            ),
            CaptureError::File(e) => one("read", "$".into(), e.to_string()),
            CaptureError::Syntax {
                line,
                column,
                message,
                ..
            } => one(
                "syntax",
                "$".into(),
                format!("line {line}, column {column}: {message}"),
            ),
            CaptureError::Encoding { problem, .. } => {
                one("syntax", "$".into(), format!("line 1, column 1: {problem}"))
            }
            CaptureError::Structure {
                json_path,
                line,
                column,
                message,
                ..
            } => one(
                "structure",
                json_path.clone(),
                format!("line {line}, column {column}: {message}"),
            ),
            CaptureError::UnsupportedVersion {
                found, supported, ..
            } => one(
                "format-version",
                "$.format_version".into(),
                format!("unsupported format_version {found}; this framelab reads {supported}"),
            ),
            CaptureError::Invalid { diagnostics, .. } => diagnostics.clone(),
        }
    }
}

#[derive(Deserialize)]
struct VersionProbe {
    format_version: Option<serde_json::Value>,
}

/// Why a capture's bytes are not UTF-8 text: UTF-16 and UTF-32 files otherwise fail with
/// "expected value" at 1:1, which does not say what is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EncodingError {
    /// A byte-order mark names the encoding, so the fix can be spelled out.
    #[error(
        "the file is {encoding}; captures are UTF-8 JSON (convert it: iconv -f {encoding} -t UTF-8)"
    )]
    Marked { encoding: &'static str },
    #[error(
        "the file is not UTF-8 (it starts with NUL bytes: UTF-16 or UTF-32?); captures are UTF-8 JSON"
    )]
    NulBytes,
}

/// The bytes without a UTF-8 byte-order mark (editors write one; JSON allows ignoring it),
/// or why they are not UTF-8 at all.
fn without_bom(bytes: &[u8]) -> Result<&[u8], EncodingError> {
    let marked = |encoding| Err(EncodingError::Marked { encoding });
    match bytes {
        [0xEF, 0xBB, 0xBF, rest @ ..] => Ok(rest),
        [0x00, 0x00, 0xFE, 0xFF, ..] => marked("UTF-32BE"),
        [0xFF, 0xFE, 0x00, 0x00, ..] => marked("UTF-32LE"),
        [0xFE, 0xFF, ..] => marked("UTF-16BE"),
        [0xFF, 0xFE, ..] => marked("UTF-16LE"),
        // No mark, but a NUL beside the first character: UTF-16 or UTF-32 all the same.
        [0, _, ..] | [_, 0, ..] => Err(EncodingError::NulBytes),
        _ => Ok(bytes),
    }
}

/// What another tool's capture is, told by its first bytes or its first line: GFXReconstruct's
/// and RenderDoc's files start with their four-character codes, and a JSON Lines stream's
/// first line is one object with a `header` or a call.
pub fn foreign(bytes: &[u8]) -> Option<&'static str> {
    if crate::import::gfxr::is_gfxr(bytes) {
        return Some("a GFXReconstruct capture (.gfxr)");
    }
    if crate::import::rdc::is_rdc(bytes) {
        return Some("a RenderDoc capture (.rdc)");
    }
    // Only a first line that is not the whole file, and short: a capture written on one line
    // is not parsed twice.
    let first = bytes.split(|&b| b == b'\n').next()?;
    if first.len() >= bytes.trim_ascii_end().len() || first.len() > 1 << 20 {
        return None;
    }
    let line: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(first).ok()?;
    ["header", "vkFunc", "function", "meta"]
        .iter()
        .any(|k| line.contains_key(*k))
        .then_some("a GFXReconstruct JSON Lines stream (gfxrecon-convert)")
}

/// Parses capture bytes. `path` is only used in messages.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<RawCapture, CaptureError> {
    if let Some(what) = foreign(bytes) {
        return Err(CaptureError::NeedsImport {
            path: path.to_owned(),
            what,
        });
    }
    let bytes = without_bom(bytes).map_err(|problem| CaptureError::Encoding {
        path: path.to_owned(),
        problem,
    })?;
    // Tracking the path of every field costs as much as the parse; most files are well formed,
    // so the path is only tracked when a second parse has to locate an error.
    let mut de = serde_json::Deserializer::from_slice(bytes);
    if let Ok(raw) = RawCapture::deserialize(&mut de)
        && de.end().is_ok()
    {
        return check_version(path, raw);
    }
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let result: Result<RawCapture, _> = serde_path_to_error::deserialize(&mut de);
    let raw = match result {
        Ok(raw) => {
            if let Err(inner) = de.end() {
                return Err(CaptureError::Syntax {
                    path: path.to_owned(),
                    line: inner.line(),
                    column: inner.column(),
                    message: strip_position(&inner.to_string()),
                });
            }
            raw
        }
        Err(err) => {
            let inner = err.inner();
            if inner.is_syntax() || inner.is_eof() {
                return Err(CaptureError::Syntax {
                    path: path.to_owned(),
                    line: inner.line(),
                    column: inner.column(),
                    message: strip_position(&inner.to_string()),
                });
            }
            // A structure error in a file of another version is reported as the version.
            if let Ok(VersionProbe {
                format_version: Some(v),
            }) = serde_json::from_slice(bytes)
                && let Some(found) = v.as_u64().filter(|&f| f != u64::from(FORMAT_VERSION))
            {
                return Err(unsupported(path, found));
            }
            let json_path = format!("$.{}", err.path()).replace(".[", "[");
            let json_path = if json_path == "$.." {
                "$".to_owned()
            } else {
                json_path
            };
            return Err(CaptureError::Structure {
                path: path.to_owned(),
                json_path,
                line: inner.line(),
                column: inner.column(),
                message: strip_position(&inner.to_string()),
            });
        }
    };
    check_version(path, raw)
}

fn check_version(path: &Path, raw: RawCapture) -> Result<RawCapture, CaptureError> {
    if raw.format_version != FORMAT_VERSION {
        return Err(unsupported(path, u64::from(raw.format_version)));
    }
    Ok(raw)
}

fn unsupported(path: &Path, found: u64) -> CaptureError {
    CaptureError::UnsupportedVersion {
        path: path.to_owned(),
        found,
        supported: FORMAT_VERSION,
    }
}

/// serde_json appends " at line L column C", which we report separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_order_marks_are_skipped_or_named() {
        let text = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../captures/example/frame.json"
        ))
        .unwrap();
        let mut bom = vec![0xEF, 0xBB, 0xBF];
        bom.extend_from_slice(&text);
        assert!(parse(Path::new("bom.json"), &bom).is_ok());
        let utf16: Vec<u8> = [0xFF, 0xFE]
            .into_iter()
            .chain(
                String::from_utf8(text)
                    .unwrap()
                    .encode_utf16()
                    .flat_map(u16::to_le_bytes),
            )
            .collect();
        let err = parse(Path::new("u16.json"), &utf16)
            .unwrap_err()
            .to_string();
        assert!(err.contains("the file is UTF-16LE"), "{err}");
        let err = parse(Path::new("nul.json"), b"{\0\"")
            .unwrap_err()
            .to_string();
        assert!(err.contains("not UTF-8"), "{err}");
    }

    #[test]
    fn syntax_errors_have_line_and_column() {
        let err = parse(
            Path::new("x.json"),
            b"{\n  \"format_version\": 1,\n  oops\n}",
        )
        .unwrap_err();
        match err {
            CaptureError::Syntax { line, column, .. } => assert_eq!((line, column), (3, 3)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn structure_errors_have_json_path() {
        let text = br#"{"format_version": 1, "name": "x", "resolution": {"width": 1, "height": 1},
            "camera": {"position": [0,0,0], "target": [0,0,1], "fov_y_degrees": 60},
            "queues": [{"name": "gfx", "type": "graphics"}],
            "resources": [{"name": "a", "kind": "texture_2d", "colour": 1}]}"#;
        let err = parse(Path::new("x.json"), text).unwrap_err();
        match err {
            CaptureError::Structure {
                json_path, message, ..
            } => {
                assert_eq!(json_path, "$.resources[0].colour");
                assert!(message.contains("unknown field `colour`"), "{message}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn newer_versions_are_named_as_such() {
        let err = parse(
            Path::new("x.json"),
            br#"{"format_version": 7, "future": true}"#,
        )
        .unwrap_err();
        assert!(
            matches!(err, CaptureError::UnsupportedVersion { found: 7, .. }),
            "{err:?}"
        );
    }
}
