//! Formats of 16-bit texels with 4-, 5- or 6-bit channels (`R5G6B5`, `B4G4R4A4`, `A1R5G5B5`, ...),
//! which WebGPU lacks: the replay holds them as RGBA8 (each channel widened to 8 bits, which
//! sampling reads within half a step of 255 of the program's value), unpacks their contents
//! on the way in (initial contents here; buffer-to-image copies on the GPU, where the replay
//! draws each texel from the buffer's words), and reads a view in another layout of the same
//! bit fields through a swizzle.

use crate::plan::Packed16;

/// The layout of the format `name` (a DXGI or `VK_FORMAT_*` name), if it is one of them.
pub fn layout(name: &str) -> Option<Packed16> {
    // (shift, bits) of R, G, B and A; bits 0 for a channel the format lacks (alpha reads 1).
    let fields: [(u8, u8); 4] = match name {
        // DXGI names the bits from the low end, Vulkan's PACK16 formats from the high end.
        "B5G6R5_UNORM" | "VK_FORMAT_R5G6B5_UNORM_PACK16" => [(11, 5), (5, 6), (0, 5), (0, 0)],
        "VK_FORMAT_B5G6R5_UNORM_PACK16" => [(0, 5), (5, 6), (11, 5), (0, 0)],
        "A4B4G4R4_UNORM" | "VK_FORMAT_R4G4B4A4_UNORM_PACK16" => [(12, 4), (8, 4), (4, 4), (0, 4)],
        "VK_FORMAT_B4G4R4A4_UNORM_PACK16" => [(4, 4), (8, 4), (12, 4), (0, 4)],
        "B4G4R4A4_UNORM" | "VK_FORMAT_A4R4G4B4_UNORM_PACK16" => [(8, 4), (4, 4), (0, 4), (12, 4)],
        "VK_FORMAT_A4B4G4R4_UNORM_PACK16" => [(0, 4), (4, 4), (8, 4), (12, 4)],
        "VK_FORMAT_R5G5B5A1_UNORM_PACK16" => [(11, 5), (6, 5), (1, 5), (0, 1)],
        "VK_FORMAT_B5G5R5A1_UNORM_PACK16" => [(1, 5), (6, 5), (11, 5), (0, 1)],
        "B5G5R5A1_UNORM" | "VK_FORMAT_A1R5G5B5_UNORM_PACK16" => [(10, 5), (5, 5), (0, 5), (15, 1)],
        "VK_FORMAT_A1B5G5R5_UNORM_PACK16" | "VK_FORMAT_A1B5G5R5_UNORM_PACK16_KHR" => {
            [(0, 5), (5, 5), (10, 5), (15, 1)]
        }
        _ => return None,
    };
    Some(Packed16 { fields })
}

/// One texel's channels as 8-bit UNORM values, each rounded to the nearest step.
pub fn unpack(p: Packed16, word: u16) -> [u8; 4] {
    p.fields.map(|(shift, bits)| {
        if bits == 0 {
            return 255;
        }
        let max = (1u32 << bits) - 1;
        let v = (u32::from(word) >> shift) & max;
        ((v * 255 + max / 2) / max) as u8
    })
}

/// Little-endian 16-bit texels widened to RGBA8.
pub fn unpack_bytes(p: Packed16, bytes: &[u8]) -> Vec<u8> {
    bytes
        .chunks_exact(2)
        .flat_map(|t| unpack(p, u16::from_le_bytes([t[0], t[1]])))
        .collect()
}

/// What each of a view's R, G, B and A reads of the texture held in `image`'s layout, where
/// the view's layout names the same bit fields in another order (a `R5G6B5` view of a
/// `B5G6R5` image): the channel of the image with the view channel's field, or None where a
/// field of the view is none of the image's.
pub fn view_permutation(image: Packed16, view: Packed16) -> Option<[u8; 4]> {
    let mut out = [0u8; 4];
    for (c, field) in view.fields.iter().enumerate() {
        out[c] = if field.1 == 0 {
            // A channel the view lacks: alpha reads 1 (`SWIZZLE_ONE` where it is composed).
            if c != 3 {
                return None;
            }
            crate::spirv::SWIZZLE_ONE
        } else {
            image.fields.iter().position(|f| f == field)? as u8
        };
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_are_read_where_each_format_keeps_them() {
        // R5G6B5: red 31 at the top, green 0, blue 1.
        let rgb = layout("VK_FORMAT_R5G6B5_UNORM_PACK16").unwrap();
        assert_eq!(unpack(rgb, (31 << 11) | 1), [255, 0, 8, 255]);
        let bgr = layout("VK_FORMAT_B5G6R5_UNORM_PACK16").unwrap();
        assert_eq!(unpack(bgr, (31 << 11) | 1), [8, 0, 255, 255]);
        // DXGI's B5G6R5 is Vulkan's R5G6B5.
        assert_eq!(layout("B5G6R5_UNORM"), Some(rgb));
        let argb = layout("VK_FORMAT_A1R5G5B5_UNORM_PACK16").unwrap();
        assert_eq!(unpack(argb, 0x8000 | (16 << 5)), [0, 132, 0, 255]);
        let rgba4 = layout("VK_FORMAT_R4G4B4A4_UNORM_PACK16").unwrap();
        assert_eq!(unpack(rgba4, 0x1234), [17, 34, 51, 68]);
        assert_eq!(layout("R8G8B8A8_UNORM"), None);
    }

    #[test]
    fn a_view_of_the_same_fields_in_another_order_is_a_permutation() {
        let rgb = layout("VK_FORMAT_R5G6B5_UNORM_PACK16").unwrap();
        let bgr = layout("VK_FORMAT_B5G6R5_UNORM_PACK16").unwrap();
        assert_eq!(
            view_permutation(bgr, rgb),
            Some([2, 1, 0, crate::spirv::SWIZZLE_ONE])
        );
        let rgba4 = layout("VK_FORMAT_R4G4B4A4_UNORM_PACK16").unwrap();
        let argb4 = layout("VK_FORMAT_A4R4G4B4_UNORM_PACK16").unwrap();
        assert_eq!(view_permutation(argb4, rgba4), Some([3, 0, 1, 2]));
        let a1 = layout("VK_FORMAT_A1R5G5B5_UNORM_PACK16").unwrap();
        assert_eq!(view_permutation(a1, rgb), None);
    }
}
