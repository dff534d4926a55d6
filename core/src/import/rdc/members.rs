//! The binary data the XML's `<buffer>` elements point at: members of the zip written beside
//! it (`000000`, `000001`, ...), read one at a time when a chunk needs them. Each member is
//! checked against the length the XML gives before any memory is taken, and read no further
//! than that, so a damaged or hostile zip can neither hide a member nor make the import hold
//! more than the capture says it holds.

use std::io::{Read, Seek};

use zip::ZipArchive;

/// Largest member read: a single resource's contents.
pub const MAX_MEMBER_BYTES: u64 = 4 << 30;
/// Most bytes read from all members together.
pub const MAX_TOTAL_BYTES: u64 = 32 << 30;

pub struct Members<R> {
    zip: ZipArchive<R>,
    read: u64,
}

impl<R> std::fmt::Debug for Members<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Members")
            .field("read", &self.read)
            .finish_non_exhaustive()
    }
}

/// Why a member of the zip cannot be read: a damaged or hostile file.
#[derive(Debug, thiserror::Error)]
pub enum MemberError {
    #[error("not a readable zip: {0}")]
    NotZip(zip::result::ZipError),
    #[error("buffer reference \"{0}\" is not a number")]
    NotANumber(String),
    #[error(
        "member {name} is said to hold {len} bytes, more than the {} GiB framelab reads for one resource",
        MAX_MEMBER_BYTES >> 30
    )]
    PastMemberLimit { name: String, len: u64 },
    #[error("the members read so far and {name} hold more than {} GiB", MAX_TOTAL_BYTES >> 30)]
    PastTotalLimit { name: String },
    #[error("member {name} (byteLength {len}): {source}")]
    Missing {
        name: String,
        len: u64,
        source: zip::result::ZipError,
    },
    #[error("member {name} holds {holds} bytes, but the XML says {len}")]
    Size { name: String, holds: u64, len: u64 },
    #[error("cannot hold the {len} bytes of member {name}")]
    NoMemory { name: String, len: u64 },
    #[error("member {name}: {source}")]
    Read {
        name: String,
        source: std::io::Error,
    },
    #[error("member {name} unpacks to {got} bytes, but the XML says {len}")]
    Unpacked { name: String, got: usize, len: u64 },
}

impl<R: Read + Seek> Members<R> {
    pub fn new(reader: R) -> Result<Self, MemberError> {
        let zip = ZipArchive::new(reader).map_err(MemberError::NotZip)?;
        Ok(Members { zip, read: 0 })
    }

    /// The bytes of member `index`, which the XML says holds `len` bytes.
    pub fn bytes(&mut self, index: &str, len: u64) -> Result<Vec<u8>, MemberError> {
        let number: u64 = index
            .trim()
            .parse()
            .map_err(|_| MemberError::NotANumber(index.trim().to_owned()))?;
        let name = format!("{number:06}");
        if len > MAX_MEMBER_BYTES {
            return Err(MemberError::PastMemberLimit { name, len });
        }
        if self.read.saturating_add(len) > MAX_TOTAL_BYTES {
            return Err(MemberError::PastTotalLimit { name });
        }
        let member = match self.zip.by_name(&name) {
            Ok(m) => m,
            Err(source) => return Err(MemberError::Missing { name, len, source }),
        };
        if member.size() != len {
            let holds = member.size();
            return Err(MemberError::Size { name, holds, len });
        }
        let mut out = Vec::new();
        if out.try_reserve_exact(len as usize).is_err() {
            return Err(MemberError::NoMemory { name, len });
        }
        if let Err(source) = member.take(len + 1).read_to_end(&mut out) {
            return Err(MemberError::Read { name, source });
        }
        if out.len() as u64 != len {
            let got = out.len();
            return Err(MemberError::Unpacked { name, got, len });
        }
        self.read += len;
        Ok(out)
    }
}
