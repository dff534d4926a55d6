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

impl<R: Read + Seek> Members<R> {
    pub fn new(reader: R) -> Result<Self, String> {
        let zip = ZipArchive::new(reader).map_err(|e| format!("not a readable zip: {e}"))?;
        Ok(Members { zip, read: 0 })
    }

    /// The bytes of member `index`, which the XML says holds `len` bytes.
    pub fn bytes(&mut self, index: &str, len: u64) -> Result<Vec<u8>, String> {
        let number: u64 = index
            .trim()
            .parse()
            .map_err(|_| format!("buffer reference \"{}\" is not a number", index.trim()))?;
        let name = format!("{number:06}");
        if len > MAX_MEMBER_BYTES {
            return Err(format!(
                "member {name} is said to hold {len} bytes, more than the {} GiB framelab reads for one resource",
                MAX_MEMBER_BYTES >> 30
            ));
        }
        if self.read.saturating_add(len) > MAX_TOTAL_BYTES {
            return Err(format!(
                "the members read so far and {name} hold more than {} GiB",
                MAX_TOTAL_BYTES >> 30
            ));
        }
        let member = self
            .zip
            .by_name(&name)
            .map_err(|e| format!("member {name} (byteLength {len}): {e}"))?;
        if member.size() != len {
            return Err(format!(
                "member {name} holds {} bytes, but the XML says {len}",
                member.size()
            ));
        }
        let mut out = Vec::new();
        out.try_reserve_exact(len as usize)
            .map_err(|_| format!("cannot hold the {len} bytes of member {name}"))?;
        member
            .take(len + 1)
            .read_to_end(&mut out)
            .map_err(|e| format!("member {name}: {e}"))?;
        if out.len() as u64 != len {
            return Err(format!(
                "member {name} unpacks to {} bytes, but the XML says {len}",
                out.len()
            ));
        }
        self.read += len;
        Ok(out)
    }
}
