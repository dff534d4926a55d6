//! Writing results: files go through `crate::atomic` (a temporary name in the same
//! folder, then a rename), so an interrupted run never leaves a half-written file; SVG comes
//! from Graphviz when present.

use std::io::Write;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(transparent)]
    Write(#[from] crate::atomic::WriteError),
    #[error(
        "Graphviz's `dot` was not found ({0}); install graphviz (apt-get install graphviz) or write DOT with --dot FILE"
    )]
    NoGraphviz(String),
    #[error("Graphviz's `dot` failed: {0}")]
    Graphviz(String),
    #[error("{output} is also what this command reads; choose another output")]
    IsInput { output: String },
}

/// Checks, before any work, that each output can be written (nothing but a regular file or a
/// link to one is there) and is none of the command's inputs, which writing it would destroy.
pub fn check_outputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), OutputError> {
    let inputs: Vec<_> = inputs
        .iter()
        .filter_map(|p| p.canonicalize().ok())
        .collect();
    for out in outputs {
        let at = crate::atomic::destination(out)?;
        if at.canonicalize().is_ok_and(|c| inputs.contains(&c)) {
            return Err(OutputError::IsInput {
                output: out.display().to_string(),
            });
        }
    }
    Ok(())
}

/// Writes `bytes` to `path` via a temporary file and a rename (`crate::atomic`, the
/// one helper every written file goes through).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    Ok(crate::atomic::write(path, bytes)?)
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
