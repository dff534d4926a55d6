//! The meta-data commands a capture carries besides API calls: what the application wrote
//! into mapped memory, and the buffer and image contents of a trimmed capture's state
//! snapshot. Each is read into a plain record; the rest are named and counted.

use super::blocks::Block;
use super::compress::{self, Compression};

/// What a compressed payload is about to fill, for the importer to check against what the
/// capture made room for before the payload is decompressed: a few kilobytes may claim
/// gigabytes, and only the objects the capture created say whether that is true.
#[derive(Clone, Copy, Debug)]
pub enum Fills {
    /// `size` bytes at `offset` in device memory `memory`.
    Memory {
        memory: u64,
        offset: u64,
        size: u64,
    },
    Buffer {
        buffer: u64,
        size: u64,
    },
    Image {
        image: u64,
        size: u64,
    },
}

impl Fills {
    /// The bytes the payload says it decompresses to.
    pub fn size(self) -> u64 {
        match self {
            Fills::Memory { size, .. } | Fills::Buffer { size, .. } | Fills::Image { size, .. } => {
                size
            }
        }
    }
}

/// Why the capture has no room for a payload (the importer's answer to a `Fills`).
#[derive(Debug, thiserror::Error)]
pub enum NoRoom {
    #[error("fills {size} bytes of memory {memory:#x}, which the capture never allocated")]
    MemoryNeverAllocated { size: u64, memory: u64 },
    #[error(
        "fills {size} bytes at offset {offset} of memory {memory:#x}, which holds {holds} bytes"
    )]
    PastMemory {
        size: u64,
        offset: u64,
        memory: u64,
        holds: u64,
    },
    #[error("holds {size} bytes of contents for {what}, which the capture never created")]
    NeverCreated { size: u64, what: String },
    #[error("holds {size} bytes of contents for {what}, more than the {holds} bytes of {there}")]
    PastBound {
        size: u64,
        what: String,
        holds: u64,
        there: &'static str,
    },
}

/// The importer's answer to a `Fills`: why the payload cannot be, if it cannot.
pub type Room<'a> = &'a dyn Fn(Fills) -> Result<(), NoRoom>;

/// Why a meta-data command cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum MetaError {
    #[error("meta-data command needs {needs} more bytes at byte {at}, {left} left")]
    Short {
        needs: usize,
        at: usize,
        left: usize,
    },
    #[error("meta-data command says {size} bytes of data, the block holds {holds}")]
    PayloadSize { size: u64, holds: usize },
    #[error("init image command lists {levels} mip levels, more than the block holds")]
    TooManyLevels { levels: u32 },
    #[error(
        "init image command: the mip level sizes {level_sizes:?} do not add up to its {size} bytes"
    )]
    LevelSum { level_sizes: Vec<u64>, size: u64 },
    #[error("memory properties command lists {types} memory types, more than Vulkan's 32")]
    TooManyTypes { types: u32 },
    #[error(transparent)]
    NoRoom(#[from] NoRoom),
    #[error(transparent)]
    Decompress(#[from] super::compress::DecompressError),
}

/// A meta-data command framelab uses.
#[derive(Debug)]
pub enum Meta {
    /// Bytes the application wrote to mapped memory, at an offset from the start of the
    /// mapping.
    FillMemory {
        memory: u64,
        offset: u64,
        data: Vec<u8>,
    },
    /// A buffer's contents from the state snapshot.
    InitBuffer { buffer: u64, data: Vec<u8> },
    /// One aspect of an image from the state snapshot: each mip level tightly packed, all
    /// layers, one after the other.
    InitImage {
        image: u64,
        aspect: u32,
        /// The `VkImageLayout` the snapshot restores the image to.
        layout: u32,
        level_sizes: Vec<u64>,
        data: Vec<u8>,
    },
    /// The property flags of each memory type of the capturing device: a trimmed capture
    /// records them here rather than as the application's query.
    MemoryProperties { type_flags: Vec<u32> },
    /// The capturing device: its vendor and name (`VkPhysicalDeviceProperties`), which say
    /// how its driver lays out image texels in memory.
    DeviceProperties { vendor_id: u32, device_name: String },
    /// Anything else, by name.
    Other(&'static str),
}

impl Meta {
    /// The bytes of memory or resource contents the command carries.
    pub fn payload_len(&self) -> u64 {
        match self {
            Meta::FillMemory { data, .. }
            | Meta::InitBuffer { data, .. }
            | Meta::InitImage { data, .. } => data.len() as u64,
            Meta::MemoryProperties { .. } | Meta::DeviceProperties { .. } | Meta::Other(_) => 0,
        }
    }

    /// What the command is, for counts.
    pub fn name(&self) -> &'static str {
        match self {
            Meta::FillMemory { .. } => "fill memory",
            Meta::InitBuffer { .. } => "init buffer",
            Meta::InitImage { .. } => "init image",
            Meta::MemoryProperties { .. } => "set device memory properties",
            Meta::DeviceProperties { .. } => "set device properties",
            Meta::Other(name) => name,
        }
    }
}

fn name(kind: u32) -> &'static str {
    match kind {
        1 => "display message",
        4 => "swapchain image state",
        3 | 13 => "resize window",
        5 => "begin resource init",
        6 => "end resource init",
        9 | 24 | 35 => "create hardware buffer",
        10 => "destroy hardware buffer",
        11 => "set device properties",
        12 => "set device memory properties",
        14 => "set opaque address",
        15 => "set ray tracing shader group handles",
        16 => "create heap allocation",
        17 => "init subresource",
        18 => "executable file info",
        20 => "fill memory resource value",
        22 => "driver info",
        27 => "parent to child dependency",
        28..=30 => "acceleration structure command",
        32 => "set environment variables",
        _ => "unknown meta-data command",
    }
}

struct Fields<'a> {
    body: &'a [u8],
    pos: usize,
}

impl Fields<'_> {
    fn u32(&mut self) -> Result<u32, MetaError> {
        let b = self.bytes(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self) -> Result<u64, MetaError> {
        let b = self.bytes(8)?;
        let mut a = [0; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }

    fn bytes(&mut self, n: usize) -> Result<&[u8], MetaError> {
        let left = self.body.len() - self.pos;
        if n > left {
            return Err(MetaError::Short {
                needs: n,
                at: self.pos,
                left,
            });
        }
        self.pos += n;
        Ok(&self.body[self.pos - n..self.pos])
    }

    /// The payload after the fixed fields: `size` bytes, decompressed when the block is.
    fn payload(
        &mut self,
        block: &Block,
        how: Compression,
        fills: Fills,
        room: Room<'_>,
    ) -> Result<Vec<u8>, MetaError> {
        let size = fills.size();
        let rest = &self.body[self.pos..];
        if block.compressed {
            room(fills)?;
            return Ok(compress::decompress(how, rest, size)?);
        }
        if rest.len() as u64 != size {
            return Err(MetaError::PayloadSize {
                size,
                holds: rest.len(),
            });
        }
        Ok(rest.to_vec())
    }
}

/// The capturing device's vendor and name from a "set device properties" record.
fn device_properties(f: &mut Fields<'_>) -> Result<Meta, MetaError> {
    let (_thread, _device) = (f.u64()?, f.u64()?);
    let (_api, _driver) = (f.u32()?, f.u32()?);
    let vendor_id = f.u32()?;
    let (_device_id, _type) = (f.u32()?, f.u32()?);
    let _uuid = f.bytes(16)?;
    let len = f.u32()? as usize;
    let name = f.bytes(len)?;
    Ok(Meta::DeviceProperties {
        vendor_id,
        device_name: String::from_utf8_lossy(name)
            .trim_end_matches('\0')
            .to_owned(),
    })
}

/// Reads a meta-data block.
pub fn read(block: &Block, how: Compression, room: Room<'_>) -> Result<Meta, MetaError> {
    let mut f = Fields {
        body: &block.body,
        pos: 0,
    };
    let kind = block.id & 0xffff;
    Ok(match kind {
        2 => {
            let _thread = f.u64()?;
            let memory = f.u64()?;
            let offset = f.u64()?;
            let size = f.u64()?;
            let fills = Fills::Memory {
                memory,
                offset,
                size,
            };
            Meta::FillMemory {
                memory,
                offset,
                data: f.payload(block, how, fills, room)?,
            }
        }
        7 => {
            let (_thread, _device) = (f.u64()?, f.u64()?);
            let buffer = f.u64()?;
            let size = f.u64()?;
            Meta::InitBuffer {
                buffer,
                data: f.payload(block, how, Fills::Buffer { buffer, size }, room)?,
            }
        }
        8 => {
            let (_thread, _device) = (f.u64()?, f.u64()?);
            let image = f.u64()?;
            let size = f.u64()?;
            let aspect = f.u32()?;
            let layout = f.u32()?;
            let levels = f.u32()?;
            // Each level size takes 8 bytes; a count past what the block holds is corrupt.
            if u64::from(levels) * 8 > (f.body.len() - f.pos) as u64 {
                return Err(MetaError::TooManyLevels { levels });
            }
            let mut level_sizes = Vec::with_capacity(levels as usize);
            for _ in 0..levels {
                level_sizes.push(f.u64()?);
            }
            let sum = level_sizes.iter().try_fold(0u64, |a, b| a.checked_add(*b));
            if sum != Some(size) {
                return Err(MetaError::LevelSum { level_sizes, size });
            }
            let data = if size == 0 {
                Vec::new()
            } else {
                f.payload(block, how, Fills::Image { image, size }, room)?
            };
            Meta::InitImage {
                image,
                aspect,
                layout,
                level_sizes,
                data,
            }
        }
        12 => {
            let (_thread, _device) = (f.u64()?, f.u64()?);
            let types = f.u32()?;
            let _heaps = f.u32()?;
            // Vulkan has at most 32 memory types; each is its flags and its heap index.
            if types > 32 {
                return Err(MetaError::TooManyTypes { types });
            }
            let mut type_flags = Vec::with_capacity(types as usize);
            for _ in 0..types {
                type_flags.push(f.u32()?);
                let _heap = f.u32()?;
            }
            Meta::MemoryProperties { type_flags }
        }
        // Informational: a record this reader does not follow is counted, not an error.
        11 => device_properties(&mut f).unwrap_or(Meta::Other(name(11))),
        other => Meta::Other(name(other)),
    })
}
