//! The block layer of a GFXReconstruct capture: the file header with its options, then one
//! block after another, each decompressed when its type says so. Everything read is checked
//! against what is left of the file and against fixed ceilings before memory is taken for it,
//! so a corrupt size is an error naming the block, never an allocation of whatever it says.

use std::io::Read;

use super::compress::{self, Compression};

/// `GFXR` as the little-endian four-character code.
const FOURCC: &[u8; 4] = b"GFXR";
/// Most bytes one block may hold, compressed or not; larger sizes are corrupt data.
pub const MAX_BLOCK_BYTES: u64 = 4 << 30;
/// Most file options a header may list.
const MAX_OPTIONS: u32 = 64;
const COMPRESSED_BIT: u32 = 0x8000_0000;
/// Most bytes a call's compressed parameters may claim: the largest any Vulkan call carries
/// (shader code, pipeline cache data) are megabytes, and a few bytes of zstd may claim
/// gigabytes. Contents (meta-data commands) are held to the objects they fill instead.
const MAX_CALL_BYTES: u64 = 256 << 20;

/// Where something went wrong: the block's number (0-based, counted as `gfxrecon-convert`
/// counts its `index`, so the two can be set side by side) and the byte offset of its header
/// in the file. The file header is `None`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct At {
    pub block: u64,
    pub offset: u64,
}

/// A failure to read a block (or, `at: None`, the file header), located.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockError {
    pub at: Option<At>,
    pub message: String,
}

/// What a block is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    FrameMarker,
    StateMarker,
    MetaData,
    FunctionCall,
    Annotation,
    MethodCall,
    Unknown(u32),
}

impl Kind {
    fn of(raw: u32) -> Kind {
        match raw & !COMPRESSED_BIT {
            1 => Kind::FrameMarker,
            2 => Kind::StateMarker,
            3 => Kind::MetaData,
            4 => Kind::FunctionCall,
            5 => Kind::Annotation,
            6 => Kind::MethodCall,
            _ => Kind::Unknown(raw),
        }
    }
}

/// One block, its payload decompressed.
#[derive(Debug)]
pub struct Block {
    pub at: At,
    pub kind: Kind,
    /// Function calls: the API call id. Meta-data: the meta-data id. Markers: the marker type.
    pub id: u32,
    /// Whether the block's type had the compressed bit. Calls are decompressed here;
    /// meta-data payloads are decompressed by the meta-data layer, which knows where their
    /// fixed fields end.
    pub compressed: bool,
    /// The block's bytes after the id (and, for compressed blocks, after the uncompressed
    /// size), decompressed where the block was compressed. Function calls: the thread id
    /// comes first.
    pub body: Vec<u8>,
}

/// The file header.
#[derive(Clone, Debug)]
pub struct Header {
    pub version: (u32, u32),
    pub compression: Compression,
}

/// Reads blocks one at a time from a capture of `len` bytes (when known).
pub struct Blocks<R> {
    reader: R,
    pub header: Header,
    offset: u64,
    len: Option<u64>,
    block: u64,
}

fn err(at: At, message: impl Into<String>) -> BlockError {
    BlockError {
        at: Some(at),
        message: message.into(),
    }
}

fn header_err(message: impl Into<String>) -> BlockError {
    BlockError {
        at: None,
        message: message.into(),
    }
}

/// Reads exactly `buf.len()` bytes; `Ok(false)` at a clean end of file before the first byte.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> std::io::Result<bool> {
    let mut got = 0;
    while got < buf.len() {
        match reader.read(&mut buf[got..]) {
            Ok(0) if got == 0 => return Ok(false),
            Ok(0) => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::UnexpectedEof,
                    format!("the file ends {got} bytes into {} expected", buf.len()),
                ));
            }
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(true)
}

fn u32_at(b: &[u8], i: usize) -> u32 {
    let mut a = [0; 4];
    a.copy_from_slice(&b[i..i + 4]);
    u32::from_le_bytes(a)
}

fn u64_at(b: &[u8], i: usize) -> u64 {
    let mut a = [0; 8];
    a.copy_from_slice(&b[i..i + 8]);
    u64::from_le_bytes(a)
}

/// Whether `head` starts like a GFXReconstruct capture.
pub fn is_gfxr(head: &[u8]) -> bool {
    head.starts_with(FOURCC)
}

impl<R: Read> Blocks<R> {
    /// Reads the file header; `len` is the file's size when known, to refuse blocks that run
    /// past its end before reading them.
    pub fn new(mut reader: R, len: Option<u64>) -> Result<Self, BlockError> {
        let mut head = [0u8; 16];
        match read_full(&mut reader, &mut head) {
            Ok(true) => {}
            Ok(false) => return Err(header_err("empty file: not a GFXReconstruct capture")),
            Err(e) => return Err(header_err(format!("cannot read the file header: {e}"))),
        }
        if !is_gfxr(&head) {
            return Err(header_err(
                "no `GFXR` file header: not a GFXReconstruct capture",
            ));
        }
        let version = (u32_at(&head, 4), u32_at(&head, 8));
        let options = u32_at(&head, 12);
        if options > MAX_OPTIONS {
            return Err(header_err(format!(
                "the header lists {options} file options; at most {MAX_OPTIONS} are read"
            )));
        }
        let mut compression = Compression::None;
        for _ in 0..options {
            let mut pair = [0u8; 8];
            if !read_full(&mut reader, &mut pair)
                .map_err(|e| header_err(format!("cannot read the file options: {e}")))?
            {
                return Err(header_err("the file ends inside the header's options"));
            }
            let (key, value) = (u32_at(&pair, 0), u32_at(&pair, 4));
            if key == 1 {
                compression = Compression::from_tag(value).ok_or_else(|| {
                    header_err(format!(
                            "unknown compression type {value} in the file header (known: 0 none, 1 LZ4, 2 zlib, 3 zstd)"
                        ),
                    )
                })?;
            }
        }
        Ok(Blocks {
            reader,
            header: Header {
                version,
                compression,
            },
            offset: 16 + 8 * u64::from(options),
            len,
            block: 0,
        })
    }

    /// The next block; `None` at the end of the file.
    pub fn next_block(&mut self) -> Option<Result<Block, BlockError>> {
        let at = At {
            block: self.block,
            offset: self.offset,
        };
        self.block += 1;
        let mut head = [0u8; 12];
        match read_full(&mut self.reader, &mut head) {
            Ok(false) => return None,
            Ok(true) => {}
            Err(e) => return Some(Err(err(at, format!("truncated block header: {e}")))),
        }
        Some(self.read_block(at, u64_at(&head, 0), u32_at(&head, 8)))
    }

    fn read_block(&mut self, at: At, size: u64, raw_kind: u32) -> Result<Block, BlockError> {
        let left = self.len.map(|l| l.saturating_sub(at.offset + 12));
        if size > MAX_BLOCK_BYTES {
            return Err(err(
                at,
                format!(
                    "block size {size} is over the {} GiB a block may hold",
                    MAX_BLOCK_BYTES >> 30
                ),
            ));
        }
        if let Some(left) = left
            && size > left
        {
            return Err(err(
                at,
                format!(
                    "block of {size} bytes runs past the end of the file ({left} bytes left): truncated capture"
                ),
            ));
        }
        // GFXReconstruct never writes type 0; a run of them is a zero-filled (or sparse) file,
        // which would otherwise be read 12 bytes at a time to its end.
        if raw_kind == 0 {
            return Err(err(
                at,
                format!(
                    "block type 0 (size {size}): GFXReconstruct writes no such block; the file is corrupt or zero-filled here"
                ),
            ));
        }
        let kind = Kind::of(raw_kind);
        let compressed = raw_kind & COMPRESSED_BIT != 0;
        if compressed && !matches!(kind, Kind::MetaData | Kind::FunctionCall | Kind::MethodCall) {
            return Err(err(
                at,
                format!("block type {raw_kind:#x} cannot be compressed"),
            ));
        }
        let mut data = Vec::new();
        data.try_reserve_exact(size as usize)
            .map_err(|e| err(at, format!("cannot hold a block of {size} bytes: {e}")))?;
        (&mut self.reader)
            .take(size)
            .read_to_end(&mut data)
            .map_err(|e| err(at, format!("cannot read the block: {e}")))?;
        if (data.len() as u64) < size {
            return Err(err(
                at,
                format!(
                    "block of {size} bytes is truncated: the file ends after {}",
                    data.len()
                ),
            ));
        }
        self.offset += 12 + size;
        if matches!(kind, Kind::Unknown(_)) {
            return Ok(Block {
                at,
                kind,
                id: 0,
                compressed,
                body: data,
            });
        }
        if data.len() < 4 {
            return Err(err(
                at,
                format!("block of {size} bytes is too short for its id"),
            ));
        }
        let id = u32_at(&data, 0);
        let body = if compressed {
            self.decompress(at, kind, &data)?
        } else {
            data.drain(..4);
            data
        };
        Ok(Block {
            at,
            kind,
            id,
            compressed,
            body,
        })
    }

    /// A compressed block: function and method calls keep their ids and thread uncompressed
    /// and give the uncompressed size; meta-data blocks keep their fixed header fields
    /// uncompressed, which only the meta-data layer knows, so their payload is split there.
    fn decompress(&self, at: At, kind: Kind, data: &[u8]) -> Result<Vec<u8>, BlockError> {
        let compression = self.header.compression;
        if compression == Compression::None {
            return Err(err(
                at,
                "compressed block in a capture whose header says it is not compressed",
            ));
        }
        match kind {
            Kind::FunctionCall | Kind::MethodCall => {
                // id, [object id,] thread id, uncompressed size, then the compressed parameters.
                let fixed = if kind == Kind::MethodCall { 28 } else { 20 };
                if data.len() < fixed {
                    return Err(err(
                        at,
                        format!("compressed call block of {} bytes is too short", data.len()),
                    ));
                }
                let size = u64_at(data, fixed - 8);
                if size > MAX_CALL_BYTES {
                    return Err(err(
                        at,
                        format!(
                            "compressed call parameters say {size} bytes, over the {} MiB a call may carry",
                            MAX_CALL_BYTES >> 20
                        ),
                    ));
                }
                let mut body = data[4..fixed - 8].to_vec();
                let params = compress::decompress(compression, &data[fixed..], size)
                    .map_err(|e| err(at, e.to_string()))?;
                body.extend_from_slice(&params);
                Ok(body)
            }
            _ => Ok(data[4..].to_vec()),
        }
    }
}
