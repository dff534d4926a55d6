//! The three compressions a GFXReconstruct capture may use, through well-kept crates:
//! `lz4_flex` (LZ4 block format, as GFXReconstruct writes it), `flate2` (zlib) and `ruzstd`
//! (zstd, pure Rust, so the build needs no C library). Every payload states its uncompressed
//! size; the output is held to it, and memory is taken only as output really arrives (zlib,
//! zstd) or within LZ4's worst ratio of the input, so a lying size cannot take memory the data
//! does not back.

use std::io::Read;

/// How a capture's blocks are compressed (the file header's compression option).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    None,
    Lz4,
    Zlib,
    Zstd,
}

impl Compression {
    pub fn from_tag(tag: u32) -> Option<Compression> {
        match tag {
            0 => Some(Compression::None),
            1 => Some(Compression::Lz4),
            2 => Some(Compression::Zlib),
            3 => Some(Compression::Zstd),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Compression::None => "none",
            Compression::Lz4 => "LZ4",
            Compression::Zlib => "zlib",
            Compression::Zstd => "zstd",
        }
    }
}

/// LZ4's block format can expand one input byte to at most 255 output bytes.
const LZ4_MAX_RATIO: u64 = 255;

/// Why a compressed payload cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum DecompressError {
    #[error("payload marked compressed in an uncompressed capture")]
    NotCompressed,
    #[error(
        "corrupt LZ4 data: {compressed} compressed bytes cannot hold the {size} bytes the block says"
    )]
    PastLz4Ratio { compressed: usize, size: u64 },
    #[error("corrupt {} data: {why}", .how.name())]
    Corrupt { how: Compression, why: String },
    #[error("corrupt {} data: it decompresses to {got} bytes, the block says {size}", .how.name())]
    WrongSize {
        how: Compression,
        got: usize,
        size: u64,
    },
}

/// Decompresses `data` to exactly `size` bytes.
pub fn decompress(how: Compression, data: &[u8], size: u64) -> Result<Vec<u8>, DecompressError> {
    let corrupt = |why: &dyn std::fmt::Display| DecompressError::Corrupt {
        how,
        why: why.to_string(),
    };
    let out = match how {
        Compression::None => return Err(DecompressError::NotCompressed),
        Compression::Lz4 => {
            let bound = (data.len() as u64)
                .saturating_mul(LZ4_MAX_RATIO)
                .saturating_add(16);
            if size > bound {
                return Err(DecompressError::PastLz4Ratio {
                    compressed: data.len(),
                    size,
                });
            }
            lz4_flex::block::decompress(data, size as usize).map_err(|e| corrupt(&e))?
        }
        Compression::Zlib => {
            read_bounded(flate2::read::ZlibDecoder::new(data), size).map_err(|e| corrupt(&e))?
        }
        Compression::Zstd => {
            let decoder = ruzstd::decoding::StreamingDecoder::new(data).map_err(|e| corrupt(&e))?;
            read_bounded(decoder, size).map_err(|e| corrupt(&e))?
        }
    };
    if out.len() as u64 != size {
        return Err(DecompressError::WrongSize {
            how,
            got: out.len(),
            size,
        });
    }
    Ok(out)
}

/// Reads at most `size + 1` bytes (one more shows a payload longer than stated).
fn read_bounded(reader: impl Read, size: u64) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    reader.take(size.saturating_add(1)).read_to_end(&mut out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lz4_round_trip_and_lies() {
        let data: Vec<u8> = (0..4096u32).map(|i| (i % 251) as u8).collect();
        let packed = lz4_flex::block::compress(&data);
        assert_eq!(decompress(Compression::Lz4, &packed, 4096).unwrap(), data);
        assert!(decompress(Compression::Lz4, &packed, 4095).is_err());
        let huge = decompress(Compression::Lz4, &packed, u64::MAX).unwrap_err();
        assert!(
            matches!(huge, DecompressError::PastLz4Ratio { .. }),
            "{huge}"
        );
        assert!(decompress(Compression::Lz4, &[0xff, 0xff, 0x00], 300).is_err());
    }

    #[test]
    fn zlib_and_zstd_refuse_garbage_and_wrong_sizes() {
        use std::io::Write;
        let data = vec![7u8; 10_000];
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&data).unwrap();
        let packed = z.finish().unwrap();
        assert_eq!(
            decompress(Compression::Zlib, &packed, 10_000).unwrap(),
            data
        );
        assert!(decompress(Compression::Zlib, &packed, 9_999).is_err());
        assert!(decompress(Compression::Zlib, &packed, u64::MAX).is_err());
        assert!(decompress(Compression::Zlib, b"not zlib", 10).is_err());
        assert!(decompress(Compression::Zstd, b"not zstd at all", 10).is_err());
    }
}
