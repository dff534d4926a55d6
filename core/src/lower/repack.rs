//! How a format the replay holds in another wgpu format has its bytes rearranged on the way
//! in (`Repack`): channels exchanged, 16-bit packed texels widened, three channels given a
//! fourth. A function of the format's name alone, so validation (which formats can be render
//! targets) and the lowering (which uploads to rearrange) ask the same question here.

/// How a format held in another wgpu format has its bytes rearranged: the replay holds the
/// channels as their names say, so the capture's bytes are rearranged on the way in, and a
/// copy between such a texture and a buffer (whose bytes would be the capture's) is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Repack {
    /// 32-bit words of 10-bit R, G, B and 2-bit A, R in the high bits (`A2R10G10B10`), held
    /// with R in the low bits (`Rgb10a2*`).
    SwapRb10,
    /// Bytes B, G, R, A held as R, G, B, A (`B8G8R8A8` integer and snorm formats, which wgpu
    /// has only in RGBA order).
    SwapRb8,
    /// 16-bit texels of 4-, 5- or 6-bit channels held as RGBA8 (`packed16`): twice the bytes.
    Unpack16(crate::plan::Packed16),
    /// Three channels of `channel_bytes` each (`R8G8B8`, `B8G8R8`, `R16G16B16`,
    /// `R32G32B32`), held as four: red, green and blue (exchanged from `B8G8R8` where
    /// `swap_rb`), then the little-endian bits of one in the format's numbers (`one`), which
    /// is what Vulkan reads as the alpha of a format without it.
    Widen3 {
        channel_bytes: u8,
        swap_rb: bool,
        one: u32,
    },
}

impl Repack {
    /// The repack of the format `name` (a DXGI or `VK_FORMAT_*` name), if it has one.
    pub fn of(name: &str) -> Option<Repack> {
        match name {
            "VK_FORMAT_A2R10G10B10_UNORM_PACK32" | "VK_FORMAT_A2R10G10B10_UINT_PACK32" => {
                Some(Repack::SwapRb10)
            }
            "VK_FORMAT_B8G8R8A8_SNORM" | "VK_FORMAT_B8G8R8A8_UINT" | "VK_FORMAT_B8G8R8A8_SINT" => {
                Some(Repack::SwapRb8)
            }
            _ => super::packed16::layout(name)
                .map(Repack::Unpack16)
                .or_else(|| widen3(name)),
        }
    }

    /// Rearranges `bytes` (whole texels) as the replay holds them; the in-place swaps are
    /// their own inverse.
    pub fn apply(self, bytes: &mut Vec<u8>) {
        match self {
            Repack::Unpack16(layout) => *bytes = super::packed16::unpack_bytes(layout, bytes),
            Repack::SwapRb10 => {
                for word in bytes.chunks_exact_mut(4) {
                    let w = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
                    let low = w & 0x3ff;
                    let high = (w >> 20) & 0x3ff;
                    let w = (w & !(0x3ff | (0x3ff << 20))) | (low << 20) | high;
                    word.copy_from_slice(&w.to_le_bytes());
                }
            }
            Repack::SwapRb8 => {
                for texel in bytes.chunks_exact_mut(4) {
                    texel.swap(0, 2);
                }
            }
            Repack::Widen3 {
                channel_bytes,
                swap_rb,
                one,
            } => {
                let c = usize::from(channel_bytes);
                let alpha = &one.to_le_bytes()[..c];
                let mut out = Vec::with_capacity(bytes.len() / 3 * 4);
                for texel in bytes.chunks_exact(3 * c) {
                    let (r, g, b) = (&texel[..c], &texel[c..2 * c], &texel[2 * c..]);
                    let (r, b) = if swap_rb { (b, r) } else { (r, b) };
                    for channel in [r, g, b, alpha] {
                        out.extend_from_slice(channel);
                    }
                }
                *bytes = out;
            }
        }
    }

    /// What the replay holds, for notes and errors.
    pub fn describe(self) -> &'static str {
        match self {
            Repack::SwapRb10 => "held as RGB10A2 with red and blue exchanged",
            Repack::SwapRb8 => "held as RGBA8 with red and blue exchanged",
            Repack::Unpack16(_) => "held as RGBA8, each 4-, 5- or 6-bit channel widened",
            Repack::Widen3 { .. } => "held with a fourth channel of one after its three",
        }
    }
}

/// How a three-channel format is held as four (`Repack::Widen3`), by its name: the channel
/// size, the order, and the bits of one in its numbers.
fn widen3(name: &str) -> Option<Repack> {
    let (channel_bytes, swap_rb, numbers) = match name {
        n if n.starts_with("R32G32B32_") => (4, false, &n["R32G32B32_".len()..]),
        n if n.starts_with("VK_FORMAT_R8G8B8_") => (1, false, &n["VK_FORMAT_R8G8B8_".len()..]),
        n if n.starts_with("VK_FORMAT_B8G8R8_") => (1, true, &n["VK_FORMAT_B8G8R8_".len()..]),
        n if n.starts_with("VK_FORMAT_R16G16B16_") => {
            (2, false, &n["VK_FORMAT_R16G16B16_".len()..])
        }
        _ => return None,
    };
    let one = match (numbers, channel_bytes) {
        ("UINT" | "SINT", _) => 1,
        ("UNORM" | "SRGB", 1) => 0xff,
        ("SNORM", 1) => 0x7f,
        ("UNORM", 2) => 0xffff,
        ("SNORM", 2) => 0x7fff,
        ("SFLOAT", 2) => 0x3c00,
        ("FLOAT" | "SFLOAT", 4) => 1.0f32.to_bits(),
        _ => return None,
    };
    Some(Repack::Widen3 {
        channel_bytes,
        swap_rb,
        one,
    })
}
