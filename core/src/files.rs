//! Every file framelab reads whole is read here, for a stated purpose with its own size limit.
//!
//! A path on the command line or in a capture can name anything: `/dev/zero` never ends, a
//! named pipe blocks the reader until someone writes to it, and a sparse file claims many GiB
//! it would take to read. So a file is asked what it is (its metadata) before it is opened, and
//! only a regular file is opened at all; its size is checked against the limit for its kind,
//! and it is read through `Read::take(limit + 1)`, so a file that grows while it is read cannot
//! pass the limit either. Streams read incrementally (an import) are opened through `open`,
//! which makes the same check of what the file is.
//!
//! The limits (also in docs/capture-format.md, where files are read):
//!
//! | file                       | limit                                         |
//! |----------------------------|-----------------------------------------------|
//! | a capture (JSON)           | 256 MiB                                       |
//! | a WGSL shader              | 16 MiB                                        |
//! | a side file of contents    | the size the capture declares, at most 4 GiB  |
//! | a timing report            | 256 MiB                                       |
//! | an export manifest         | 16 MiB                                        |

use std::fs::{File, FileType, Metadata};
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::text::human_bytes;

const MIB: u64 = 1024 * 1024;
const GIB: u64 = 1024 * MIB;

/// The most a side file of contents (a buffer's or texture's initial contents, a mesh's
/// streams and indices) may hold, whatever size the capture declares.
pub const SIDE_FILE_CAP: u64 = 4 * GIB;

/// What a file is read as, and the most it may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// The kind of file, as messages name it ("a capture").
    pub what: &'static str,
    pub bytes: u64,
}

/// A capture file (JSON): the largest bundled one is a few MiB.
pub const CAPTURE: Limit = Limit {
    what: "a capture",
    bytes: 256 * MIB,
};

/// A WGSL shader a capture names.
pub const SHADER: Limit = Limit {
    what: "a WGSL shader",
    bytes: 16 * MIB,
};

/// A timing report (`replay --timings`, read by `diff` and `inspect`): 1,000 frames of a large
/// capture are a few MiB.
pub const TIMING_REPORT: Limit = Limit {
    what: "a timing report",
    bytes: 256 * MIB,
};

/// The manifest of an export folder (`replay --export`).
pub const MANIFEST: Limit = Limit {
    what: "an export manifest",
    bytes: 16 * MIB,
};

/// A side file of contents: the size the capture declares for it, at most `SIDE_FILE_CAP`.
pub fn side_file(declared: u64) -> Limit {
    Limit {
        what: "this side file (the size the capture declares, at most 4 GiB)",
        bytes: declared.min(SIDE_FILE_CAP),
    }
}

/// Why a file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file system refused (not found, no permission) or the read failed. The reason is
    /// part of the message rather than an error source: the commands print the message alone.
    #[error("cannot read {}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// A directory, named pipe, socket or device.
    #[error("cannot read {}: it is {kind}, not a regular file", path.display())]
    NotRegular { path: PathBuf, kind: &'static str },
    #[error(
        "{}: {} is over the {} limit for {}",
        path.display(),
        human_bytes(*size),
        human_bytes(*limit),
        what
    )]
    TooLarge {
        path: PathBuf,
        /// What the file holds (or, when it grew while read, at least this much).
        size: u64,
        limit: u64,
        what: &'static str,
    },
}

impl FileError {
    pub fn path(&self) -> &Path {
        match self {
            FileError::Io { path, .. }
            | FileError::NotRegular { path, .. }
            | FileError::TooLarge { path, .. } => path,
        }
    }
}

/// What a file that is not a regular one is, in words ("a named pipe (FIFO)").
pub fn kind(t: &FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> FileError + '_ {
    move |error| FileError::Io {
        path: path.to_owned(),
        error,
    }
}

fn regular(path: &Path, meta: &Metadata) -> Result<(), FileError> {
    if meta.is_file() {
        Ok(())
    } else {
        Err(FileError::NotRegular {
            path: path.to_owned(),
            kind: kind(&meta.file_type()),
        })
    }
}

/// Opens a regular file to be read as a stream, after checking what it is (so a named pipe is
/// refused rather than blocking the open).
pub fn open(path: &Path) -> Result<File, FileError> {
    let meta = std::fs::metadata(path).map_err(io(path))?;
    regular(path, &meta)?;
    let file = File::open(path).map_err(io(path))?;
    // Replaced between the two looks? Ask the open file too.
    regular(path, &file.metadata().map_err(io(path))?)?;
    Ok(file)
}

/// Reads a regular file of at most `limit.bytes` bytes whole.
pub fn read(path: &Path, limit: Limit) -> Result<Vec<u8>, FileError> {
    let too_large = |size: u64| FileError::TooLarge {
        path: path.to_owned(),
        size,
        limit: limit.bytes,
        what: limit.what,
    };
    let meta = std::fs::metadata(path).map_err(io(path))?;
    regular(path, &meta)?;
    if meta.len() > limit.bytes {
        return Err(too_large(meta.len()));
    }
    let file = open(path)?;
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io(path))?;
    let read = bytes.len() as u64;
    if read > limit.bytes {
        return Err(too_large(read));
    }
    Ok(bytes)
}

/// Reads `wanted` bytes (at most `limit.bytes`) from `offset` of a regular file that holds
/// them there (a file of many resources' contents); fewer is an error naming what is missing.
pub fn read_range(
    path: &Path,
    offset: u64,
    wanted: u64,
    limit: Limit,
) -> Result<Vec<u8>, FileError> {
    use std::io::{Seek, SeekFrom};
    if wanted > limit.bytes {
        return Err(FileError::TooLarge {
            path: path.to_owned(),
            size: wanted,
            limit: limit.bytes,
            what: limit.what,
        });
    }
    let mut file = open(path)?;
    let len = file.metadata().map_err(io(path))?.len();
    if offset.checked_add(wanted).is_none_or(|end| end > len) {
        return Err(FileError::Io {
            path: path.to_owned(),
            error: std::io::Error::new(
                std::io::ErrorKind::UnexpectedEof,
                format!("it holds {len} bytes, and {wanted} are wanted from byte {offset}"),
            ),
        });
    }
    file.seek(SeekFrom::Start(offset)).map_err(io(path))?;
    let mut bytes = vec![0; usize::try_from(wanted).unwrap_or(usize::MAX)];
    file.read_exact(&mut bytes).map_err(io(path))?;
    Ok(bytes)
}

/// Reads a regular file of at most `limit.bytes` bytes of UTF-8 text whole.
pub fn read_to_string(path: &Path, limit: Limit) -> Result<String, FileError> {
    String::from_utf8(read(path, limit)?).map_err(|_| FileError::Io {
        path: path.to_owned(),
        // The words `std::fs::read_to_string` uses.
        error: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file of its own in the temporary folder (each test removes it), with no folder left
    /// behind.
    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("framelab-files-{}-{name}", std::process::id()))
    }

    #[test]
    fn a_file_within_its_limit_is_read_whole() {
        let p = temp("small.txt");
        std::fs::write(&p, "hello").unwrap();
        let limit = Limit {
            what: "a test",
            bytes: 5,
        };
        assert_eq!(read_to_string(&p, limit).unwrap(), "hello");
        std::fs::remove_file(p).unwrap();
    }

    #[test]
    fn a_file_over_its_limit_names_its_size_and_the_limit() {
        let p = temp("sparse.bin");
        let f = File::create(&p).unwrap();
        f.set_len(64 * GIB).unwrap();
        let e = read(&p, CAPTURE).unwrap_err();
        assert!(matches!(e, FileError::TooLarge { size, .. } if size == 64 * GIB));
        assert_eq!(
            e.to_string(),
            format!(
                "{}: 64.0 GiB is over the 256.0 MiB limit for a capture",
                p.display()
            )
        );
        std::fs::remove_file(p).unwrap();
    }

    #[test]
    fn directories_and_devices_are_refused_before_reading() {
        let dir = std::env::temp_dir();
        let e = read(&dir, CAPTURE).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("it is a directory, not a regular file"),
            "{e}"
        );
        #[cfg(unix)]
        {
            let e = read(Path::new("/dev/zero"), CAPTURE).unwrap_err();
            assert_eq!(
                e.to_string(),
                "cannot read /dev/zero: it is a device, not a regular file"
            );
            assert!(open(Path::new("/dev/zero")).is_err());
        }
    }

    #[test]
    fn invalid_utf8_reads_as_std_says_it() {
        let p = temp("latin1.txt");
        std::fs::write(&p, [0xff, 0xfe]).unwrap();
        let e = read_to_string(&p, SHADER).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("stream did not contain valid UTF-8"),
            "{e}"
        );
        std::fs::remove_file(p).unwrap();
    }
}
