//! Taking frame N of a running Vulkan program with GFXReconstruct's capture layer (Debian's
//! `gfxreconstruct`): the program runs with the layer on, in the folder of the file asked
//! for, until the layer logs (on the program's stdout) that the frame is written; then it is
//! stopped. `framelab capture` and the MCP server's `capture_program` both take frames here.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The layer's manifest, where Debian's package installs it.
const LAYER_MANIFESTS: &[&str] = &[
    "/usr/share/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
    "/usr/local/share/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
    "/etc/vulkan/explicit_layer.d/VkLayer_gfxreconstruct.json",
];

/// What the layer logs once the trimmed frames are written and the file closed.
const FINISHED: &str = "Finished recording graphics API capture";

/// Why no frame was taken.
#[derive(Debug, thiserror::Error)]
pub enum TakeError {
    #[error("GFXReconstruct's capture layer is not installed (apt-get install gfxreconstruct)")]
    NoLayer,
    #[error("no program to run")]
    NoProgram,
    #[error("cannot create {}: {error}", dir.display())]
    Folder { dir: PathBuf, error: std::io::Error },
    #[error("cannot run {program}: {error}")]
    Run {
        program: String,
        error: std::io::Error,
    },
    #[error("waiting for the program: {0}")]
    Wait(std::io::Error),
    #[error("{program} exited ({status}) before frame {frame} was captured")]
    Exited {
        program: String,
        status: std::process::ExitStatus,
        frame: u32,
    },
    #[error("{program} did not reach frame {frame} within {timeout} s (--timeout); it was stopped")]
    TimedOut {
        program: String,
        frame: u32,
        timeout: u64,
    },
    #[error("the capture layer reported frame {frame} written, but {} is not there", path.display())]
    Missing { frame: u32, path: PathBuf },
}

/// Whether the capture layer is installed, with the error that names its package.
pub fn layer_installed() -> Result<(), TakeError> {
    if LAYER_MANIFESTS.iter().any(|m| Path::new(m).exists()) {
        Ok(())
    } else {
        Err(TakeError::NoLayer)
    }
}

/// Runs `program` (with its arguments) under the layer, in the folder of `gfxr`, until it has
/// written frame `frame`, then stops it; returns the file the layer wrote there. The
/// program's stdout is read here (the layer logs on it), its stderr is the caller's.
pub fn take(
    program: &[String],
    frame: u32,
    timeout: u64,
    gfxr: &Path,
) -> Result<PathBuf, TakeError> {
    layer_installed()?;
    let Some((name, arguments)) = program.split_first() else {
        return Err(TakeError::NoProgram);
    };
    let dir = match gfxr.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|error| TakeError::Folder {
        dir: dir.clone(),
        error,
    })?;
    let base = dir.join(format!(".framelab-capture-{}.gfxr", std::process::id()));
    let program = name.clone();
    let mut child = Command::new(&program)
        .args(arguments)
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_LUNARG_gfxreconstruct")
        .env("GFXRECON_CAPTURE_FILE", &base)
        .env("GFXRECON_CAPTURE_FILE_TIMESTAMP", "false")
        .env("GFXRECON_CAPTURE_FRAMES", frame.to_string())
        .env("GFXRECON_LOG_LEVEL", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|error| TakeError::Run {
            program: program.clone(),
            error,
        })?;
    // The layer's log is on the program's stdout: watched on a thread, so the wait below
    // can time out.
    let (tx, finished) = mpsc::channel();
    if let Some(stdout) = child.stdout.take() {
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if line.contains(FINISHED) {
                    let _ = tx.send(());
                }
            }
        });
    }
    let deadline = Instant::now() + Duration::from_secs(timeout);
    let outcome = loop {
        if finished.try_recv().is_ok() {
            break Ok(());
        }
        match child.try_wait() {
            Err(e) => break Err(TakeError::Wait(e)),
            Ok(Some(status)) => {
                // The layer may finish the frame as the program exits.
                if finished.recv_timeout(Duration::from_millis(200)).is_ok() {
                    break Ok(());
                }
                break Err(TakeError::Exited {
                    program,
                    status,
                    frame,
                });
            }
            Ok(None) => {}
        }
        if Instant::now() >= deadline {
            break Err(TakeError::TimedOut {
                program,
                frame,
                timeout,
            });
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let _ = child.kill();
    let _ = child.wait();
    let written = dir.join(format!(
        ".framelab-capture-{}_frame_{frame}.gfxr",
        std::process::id()
    ));
    if let Err(e) = outcome {
        let _ = std::fs::remove_file(&written);
        return Err(e);
    }
    if !written.exists() {
        return Err(TakeError::Missing {
            frame,
            path: written,
        });
    }
    Ok(written)
}
