//! Writing files so that an interrupted or failed run never leaves a half-written one: the
//! content goes to a hidden temporary name in the same folder, which is renamed over the
//! destination only once it is complete. Every file framelab writes goes through here.
//!
//! A rename replaces whatever has the name, so the destination is looked at first: a symbolic
//! link is followed (the file it points to is written and the link stays a link), a character
//! device (`/dev/null`) is written in place, and anything else but a regular file there (a
//! folder, a named pipe, which would block until read) is refused rather than replaced.

use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
#[error("cannot write {path}: {message}")]
pub struct WriteError {
    pub path: String,
    pub message: String,
}

/// The temporary sibling `path` is written through.
fn temporary(path: &Path) -> PathBuf {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Numbered per write too, so that two threads of one process never share a temporary.
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Links followed at most before a destination counts as a loop.
const MAX_LINKS: usize = 40;

fn refused(path: &Path, message: impl Into<String>) -> WriteError {
    WriteError {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// A character device (`/dev/null`, a terminal) is written in place: there is nothing to
/// replace atomically, and renaming over it would put a file where the device was.
fn is_char_device(meta: &std::fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        meta.file_type().is_char_device()
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        false
    }
}

/// Where writing a path lands.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Destination {
    /// The path itself, or the file its symbolic links lead to (which need not exist yet).
    pub path: PathBuf,
    /// A character device, written in place.
    pub device: bool,
}

/// Where writing `path` lands. An error names `path` when something other than a regular
/// file or a character device is there, or the links loop.
pub fn destination(path: &Path) -> Result<Destination, WriteError> {
    let mut at = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&at) {
            Ok(meta) => meta,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Destination {
                    path: at,
                    device: false,
                });
            }
            Err(e) => return Err(refused(path, e.to_string())),
        };
        if meta.is_file() || is_char_device(&meta) {
            return Ok(Destination {
                path: at,
                device: !meta.is_file(),
            });
        }
        if !meta.file_type().is_symlink() {
            return Err(refused(
                path,
                format!(
                    "it is {}; framelab writes only regular files",
                    crate::files::kind(&meta.file_type())
                ),
            ));
        }
        let target = std::fs::read_link(&at).map_err(|e| refused(path, e.to_string()))?;
        at = match at.parent() {
            Some(dir) if target.is_relative() => dir.join(target),
            _ => target,
        };
    }
    Err(refused(
        path,
        format!("more than {MAX_LINKS} symbolic links lead from it (a loop?)"),
    ))
}

/// Lets `write` create the file at a temporary path, then renames it to `path` (to the file a
/// symbolic link at `path` leads to). Whatever
/// `write` fails with is kept as the message: callers write through encoders with error
/// types of their own.
pub fn write_with<E: std::fmt::Display>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), WriteError> {
    let Destination {
        path: target,
        device,
    } = destination(path)?;
    if device {
        return write(&target).map_err(|e| refused(path, e.to_string()));
    }
    let tmp = temporary(&target);
    let failure = match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, &target).err().map(|e| e.to_string()),
        Err(e) => Some(e.to_string()),
    };
    match failure {
        None => Ok(()),
        Some(message) => {
            let _ = std::fs::remove_file(&tmp);
            Err(WriteError {
                path: path.display().to_string(),
                message,
            })
        }
    }
}

/// Writes `bytes` to `path`, synced to disk before the rename.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_with(path, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes)?;
        // A device has nothing to sync (and says so with an error).
        if f.metadata()?.is_file() {
            f.sync_all()?;
        }
        Ok::<(), std::io::Error>(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch folder of this test process, removed when the test ends, passed or not.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir().join(format!("framelab-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn a_failed_write_leaves_neither_file_nor_temporary() {
        let scratch = Scratch::new("atomic");
        let dir = &scratch.0;
        let path = dir.join("out.bin");
        std::fs::write(&path, b"old").unwrap();
        let err = write_with(&path, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err("disk full")
        })
        .unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
        write(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_written_through_a_device_in_place_and_a_pipe_or_folder_is_refused() {
        let scratch = Scratch::new("atomic-dest");
        let dir = &scratch.0;
        std::fs::create_dir_all(dir.join("real")).unwrap();
        std::fs::write(dir.join("real/target.json"), b"old").unwrap();
        std::os::unix::fs::symlink("real/target.json", dir.join("link.json")).unwrap();
        write(&dir.join("link.json"), b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(dir.join("link.json"))
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(dir.join("real/target.json")).unwrap(), b"new");
        // A dangling link makes the file it names.
        std::os::unix::fs::symlink("real/made.json", dir.join("dangling.json")).unwrap();
        write(&dir.join("dangling.json"), b"made").unwrap();
        assert_eq!(std::fs::read(dir.join("real/made.json")).unwrap(), b"made");
        std::os::unix::fs::symlink("loop.json", dir.join("loop.json")).unwrap();
        let e = write(&dir.join("loop.json"), b"x").unwrap_err();
        assert!(e.message.contains("symbolic links"), "{e}");
        write(Path::new("/dev/null"), b"gone").unwrap();
        assert!(destination(Path::new("/dev/null")).unwrap().device);
        assert!(is_char_device(&std::fs::metadata("/dev/null").unwrap()));
        let e = write(&dir.join("real"), b"x").unwrap_err();
        assert!(e.to_string().contains("it is a directory"), "{e}");
        let fifo = dir.join("pipe.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.unwrap().success(), "mkfifo (coreutils) makes the pipe");
        let e = write(&fifo, b"x").unwrap_err();
        assert!(e.to_string().contains("named pipe"), "{e}");
        use std::os::unix::fs::FileTypeExt;
        assert!(
            std::fs::symlink_metadata(&fifo)
                .unwrap()
                .file_type()
                .is_fifo()
        );
    }
}
