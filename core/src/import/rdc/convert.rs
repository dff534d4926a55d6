//! Running `renderdoccmd convert -c zip.xml` on a capture, in a folder of its own that is
//! removed afterwards, with a time limit: RenderDoc's own reader turns its chunks into XML
//! with named, typed parameters, which framelab reads. Its output and messages go to files,
//! not pipes, so a chatty or stuck converter can neither block nor fill memory.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The program run, unless `FRAMELAB_RENDERDOCCMD` names another.
pub const PROGRAM: &str = "renderdoccmd";
/// Time the conversion may take, unless `FRAMELAB_RENDERDOC_TIMEOUT` (seconds) says otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(300);

/// The converted capture: the XML and the zip beside it, in a folder removed on drop.
#[derive(Debug)]
pub struct Converted {
    dir: PathBuf,
    pub xml: PathBuf,
    pub zip: PathBuf,
}

impl Drop for Converted {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Why a RenderDoc capture could not be converted.
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    #[error("FRAMELAB_RENDERDOC_TIMEOUT is \"{0}\", not a number of seconds")]
    Timeout(String),
    #[error("cannot create {}: {source}", .dir.display())]
    Folder {
        dir: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot create a log file: {0}")]
    Log(std::io::Error),
    #[error(
        "{0} was not found: reading a RenderDoc capture needs RenderDoc's command-line tool (Debian and Ubuntu: apt-get install renderdoc), or FRAMELAB_RENDERDOCCMD naming it"
    )]
    NotFound(String),
    #[error("cannot run {program}: {source}")]
    Run {
        program: String,
        source: std::io::Error,
    },
    #[error(
        "{program} convert did not finish within {:.0} s and was stopped (FRAMELAB_RENDERDOC_TIMEOUT sets the limit)",
        .limit.as_secs_f64()
    )]
    TimedOut { program: String, limit: Duration },
    #[error("cannot wait for {program}: {source}")]
    Wait {
        program: String,
        source: std::io::Error,
    },
    #[error("{program} convert failed ({status}): {messages}")]
    Failed {
        program: String,
        status: std::process::ExitStatus,
        messages: String,
    },
    #[error("{program} convert wrote no {xml} and {zip} ({messages})")]
    NoOutput {
        program: String,
        xml: String,
        zip: String,
        messages: String,
    },
}

/// The converter and its time limit, from the environment.
pub fn from_env() -> Result<(OsString, Duration), ConvertError> {
    let program = std::env::var_os("FRAMELAB_RENDERDOCCMD").unwrap_or_else(|| PROGRAM.into());
    let timeout = match std::env::var("FRAMELAB_RENDERDOC_TIMEOUT") {
        Ok(s) => Duration::from_secs_f64(
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite() && *t > 0.0 && *t < 1e6)
                .ok_or_else(|| ConvertError::Timeout(s.clone()))?,
        ),
        Err(_) => DEFAULT_TIMEOUT,
    };
    Ok((program, timeout))
}

/// The last lines of a converter's message file, for an error.
fn tail(path: &Path) -> String {
    let text = std::fs::read(path).unwrap_or_default();
    let from = text.len().saturating_sub(2000);
    let text = String::from_utf8_lossy(&text[from..]);
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(6)..].join(" | ")
}

/// Converts `rdc` with `program`, waiting at most `timeout`.
pub fn convert(
    rdc: &Path,
    program: &OsString,
    timeout: Duration,
) -> Result<Converted, ConvertError> {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let dir = std::env::temp_dir().join(format!("framelab-rdc-{}-{nanos:08x}", std::process::id()));
    if let Err(source) = std::fs::create_dir_all(&dir) {
        return Err(ConvertError::Folder { dir, source });
    }
    let converted = Converted {
        xml: dir.join("capture.zip.xml"),
        zip: dir.join("capture.zip"),
        dir,
    };
    let out = std::fs::File::create(converted.dir.join("stdout.txt")).map_err(ConvertError::Log)?;
    let err = std::fs::File::create(converted.dir.join("stderr.txt")).map_err(ConvertError::Log)?;
    let shown = Path::new(program).display().to_string();
    let mut child = Command::new(program)
        .arg("convert")
        .arg("-f")
        .arg(rdc)
        .arg("-c")
        .arg("zip.xml")
        .arg("-o")
        .arg(&converted.xml)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .spawn()
        .map_err(|source| match source.kind() {
            std::io::ErrorKind::NotFound => ConvertError::NotFound(shown.clone()),
            _ => ConvertError::Run {
                program: shown.clone(),
                source,
            },
        })?;
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() >= timeout => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(ConvertError::TimedOut {
                    program: shown,
                    limit: timeout,
                });
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(source) => {
                return Err(ConvertError::Wait {
                    program: shown,
                    source,
                });
            }
        }
    };
    let messages = || {
        let t = tail(&converted.dir.join("stderr.txt"));
        if t.is_empty() {
            tail(&converted.dir.join("stdout.txt"))
        } else {
            t
        }
    };
    if !status.success() {
        return Err(ConvertError::Failed {
            program: shown,
            status,
            messages: messages(),
        });
    }
    if !converted.xml.is_file() || !converted.zip.is_file() {
        let name = |p: &Path| {
            p.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        };
        return Err(ConvertError::NoOutput {
            program: shown,
            xml: name(&converted.xml),
            zip: name(&converted.zip),
            messages: messages(),
        });
    }
    Ok(converted)
}
