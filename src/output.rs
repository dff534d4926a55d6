//! Writing results: files are written to a temporary name in the same folder and renamed, so
//! an interrupted run never leaves a half-written file; SVG comes from Graphviz when present.

use std::io::Write;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write {path}: {source}")]
    Write {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "Graphviz's `dot` was not found ({0}); install graphviz (apt-get install graphviz) or write DOT with --dot FILE"
    )]
    NoGraphviz(String),
    #[error("Graphviz's `dot` failed: {0}")]
    Graphviz(String),
}

/// Writes `bytes` to `path` via a temporary file and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let err = |source| OutputError::Write {
        path: path.display().to_string(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(err)
}

/// Runs `dot -Tsvg` on DOT text.
pub fn render_svg(dot: &str) -> Result<Vec<u8>, OutputError> {
    let mut child = std::process::Command::new("dot")
        .arg("-Tsvg")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| OutputError::NoGraphviz(e.to_string()))?;
    if let Some(mut stdin) = child.stdin.take() {
        stdin
            .write_all(dot.as_bytes())
            .map_err(|e| OutputError::Graphviz(e.to_string()))?;
    }
    let out = child
        .wait_with_output()
        .map_err(|e| OutputError::Graphviz(e.to_string()))?;
    if !out.status.success() {
        return Err(OutputError::Graphviz(
            String::from_utf8_lossy(&out.stderr).into_owned(),
        ));
    }
    Ok(out.stdout)
}
