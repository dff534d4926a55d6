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
    #[error("cannot create the folder {folder} for {output}: {source}")]
    Folder {
        folder: String,
        output: String,
        #[source]
        source: std::io::Error,
    },
}

/// Checks, before any work, that `output` can be written (a regular file, a link to one or a
/// device, or nothing yet) and is none of the command's inputs, which writing it would
/// destroy, and makes its folder where there is none yet; where it lands.
pub fn check_output(
    output: &Path,
    inputs: &[&Path],
) -> Result<crate::atomic::Destination, OutputError> {
    let at = crate::atomic::destination(output)?;
    let same = |input: &&Path| {
        input
            .canonicalize()
            .is_ok_and(|i| at.path.canonicalize().is_ok_and(|o| o == i))
    };
    if inputs.iter().any(same) {
        return Err(OutputError::IsInput {
            output: output.display().to_string(),
        });
    }
    // Made now, as `import -o` and `replay --out` make theirs, so that a missing folder is
    // not found only after the work.
    if let Some(parent) = at.path.parent().filter(|p| !p.as_os_str().is_empty())
        && !parent.is_dir()
    {
        std::fs::create_dir_all(parent).map_err(|source| OutputError::Folder {
            folder: parent.display().to_string(),
            output: output.display().to_string(),
            source,
        })?;
    }
    Ok(at)
}

/// `check_output` for each of a command's outputs.
pub fn check_outputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), OutputError> {
    for output in outputs {
        check_output(output, inputs)?;
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
