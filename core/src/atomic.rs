//! Writing files so that an interrupted or failed run never leaves a half-written one: the
//! content goes to a hidden temporary name in the same folder, which is renamed over the
//! destination only once it is complete. Every file framelab writes goes through here.

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
    dir.join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Lets `write` create the file at a temporary path, then renames it to `path`. Whatever
/// `write` fails with is kept as the message: callers write through encoders with error
/// types of their own.
pub fn write_with<E: std::fmt::Display>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), WriteError> {
    let tmp = temporary(path);
    let failure = match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, path).err().map(|e| e.to_string()),
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
        std::fs::File::create(tmp).and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_neither_file_nor_temporary() {
        let dir = std::env::temp_dir().join(format!("framelab-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.bin");
        std::fs::write(&path, b"old").unwrap();
        let err = write_with(&path, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err("disk full")
        })
        .unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        write(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
