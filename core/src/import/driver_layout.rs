//! Where a capturing driver puts an image's texels in the memory bound to it, for the drivers
//! whose layout is known: lavapipe's (Mesa's llvmpipe textures). A trimmed capture may hold an
//! image's contents only as the bytes of its memory (GFXReconstruct 0.9.18 snapshots no image
//! whose layout it tracked as `UNDEFINED`, and it does not follow `vkCmdPipelineBarrier2`'s
//! transitions, so zink's textures come without a snapshot); its own replay restores the
//! memory on the same driver. framelab reads the texels out of those bytes where it knows the
//! layout, and leaves the image without contents (named) where it does not.
//!
//! llvmpipe's layout, per mip level from the binding's start: rows of texel blocks, the level's
//! width and height rounded up to 4 texels (1D images: height 1) and each row to 64 bytes (the
//! cache line; compressed formats neither); the level's slices (array layers or depth) one
//! after the other; each level at a 64-byte boundary. The snapshots lavapipe does give carry
//! the same padding (a 197x13 RGBA8 level in 13,312 bytes: 16 rows of 832).

use super::state::ImageInfo;
use crate::capture::dxgi;

/// How the capturing driver lays out images, where framelab knows it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DriverLayout {
    /// Not known: an image without a snapshot has no contents.
    #[default]
    Unknown,
    /// Mesa's lavapipe (llvmpipe textures).
    Lavapipe,
}

/// Where one (level, slice) of an image lies from its binding's start: its offset, row pitch,
/// rows, and bytes of texels in a row.
pub type Slice = (u64, u64, u64, u64);

/// Mesa's Vulkan vendor id (`VK_VENDOR_ID_MESA`).
const VENDOR_MESA: u32 = 0x10005;
/// llvmpipe's row and level alignment: the x86 cache line.
const ALIGN: u64 = 64;
/// llvmpipe's rasterization block: levels are whole 4x4 blocks of texels.
const BLOCK: u64 = 4;

impl DriverLayout {
    /// The layout of the device a capture was made on, by its vendor and name.
    pub fn of(vendor_id: u32, device_name: &str) -> Self {
        if vendor_id == VENDOR_MESA && device_name.starts_with("llvmpipe") {
            DriverLayout::Lavapipe
        } else {
            DriverLayout::Unknown
        }
    }

    /// Whether the device filters views of `VK_FORMAT_*` `format` linearly
    /// (`VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT`): `None` where framelab does not
    /// know. Lavapipe filters no depth or stencil format and no integer one.
    pub fn filters_linearly(self, format: &str) -> Option<bool> {
        if self != DriverLayout::Lavapipe {
            return None;
        }
        let name = format.strip_prefix("VK_FORMAT_").unwrap_or(format);
        let depth_stencil = name.starts_with('D') || name.starts_with("S8");
        let integer = ["_UINT", "_SINT", "_UINT_PACK32", "_SINT_PACK32"]
            .iter()
            .any(|t| name.ends_with(t));
        Some(!(depth_stencil || integer))
    }

    /// Where each (level, slice) of `img` lies (`Slice`), level by level, slice by slice,
    /// in the order of a packed image; with the bytes the binding spans. `None` where the
    /// layout is not known for this image (another driver, a depth or stencil format,
    /// several samples, an unknown format).
    pub fn slices(self, img: &ImageInfo) -> Option<(Vec<Slice>, u64)> {
        if self != DriverLayout::Lavapipe || img.samples > 1 {
            return None;
        }
        let f = dxgi::lookup_vk(&img.format)?;
        // Depth and stencil are held in planes of their own in places; left unknown.
        if img.format.starts_with("VK_FORMAT_D") || img.format.starts_with("VK_FORMAT_S8") {
            return None;
        }
        let block = u64::from(f.block_width.max(1));
        let bytes = u64::from(f.bits_per_element) / 8;
        if bytes == 0 {
            return None;
        }
        let compressed = block > 1;
        let one_d = img.image_type.ends_with("1D");
        let three_d = img.image_type.ends_with("3D");
        let (mut out, mut level_at) = (Vec::new(), 0u64);
        for l in 0..img.mips.min(32) {
            let dim = |d: u32| u64::from((d >> l).max(1));
            let (w, h) = (dim(img.extent[0]), dim(img.extent[1]));
            let (align_x, align_y) = match (compressed, one_d) {
                (true, _) => (1, 1),
                (false, true) => (BLOCK, 1),
                (false, false) => (BLOCK, BLOCK),
            };
            let across = w.next_multiple_of(align_x).div_ceil(block);
            let rows_padded = h.next_multiple_of(align_y).div_ceil(block);
            let pitch = if compressed {
                across * bytes
            } else {
                (across * bytes).next_multiple_of(ALIGN)
            };
            let slab = pitch.checked_mul(rows_padded)?;
            let slices = if three_d {
                dim(img.extent[2])
            } else {
                u64::from(img.layers.max(1))
            };
            let (rows, row) = (h.div_ceil(block), w.div_ceil(block) * bytes);
            for s in 0..slices {
                out.push((
                    level_at.checked_add(s.checked_mul(slab)?)?,
                    pitch,
                    rows,
                    row,
                ));
            }
            level_at = level_at
                .checked_add(slab.checked_mul(slices)?)?
                .next_multiple_of(ALIGN);
        }
        Some((out, level_at))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(format: &str, extent: [u32; 3], mips: u32) -> ImageInfo {
        crate::import::contents::tests::image(format, extent, mips, 1)
    }

    /// The padding lavapipe's own snapshots show: a 197x13 RGBA8 level spans 16 rows of 832
    /// bytes (13,312), 788 of them texels.
    #[test]
    fn rows_and_levels_are_padded_as_lavapipe_pads_them() {
        let layout = DriverLayout::of(0x10005, "llvmpipe (LLVM 15.0.6, 256 bits)");
        let (slices, size) = layout
            .slices(&image("VK_FORMAT_R8G8B8A8_UNORM", [197, 13, 1], 1))
            .unwrap();
        assert_eq!(slices, vec![(0, 832, 13, 788)]);
        assert_eq!(size, 13_312);
        // A 64x64 texture's small levels: 4x4 and below take 4 rows of 64 bytes.
        let (slices, _) = layout
            .slices(&image("VK_FORMAT_R8G8B8A8_UNORM", [64, 64, 1], 7))
            .unwrap();
        let offsets: Vec<u64> = slices.iter().map(|s| s.0).collect();
        assert_eq!(offsets, [0, 16384, 20480, 21504, 22016, 22272, 22528]);
        assert_eq!(slices[6], (22528, 64, 1, 4));
        assert_eq!(
            DriverLayout::of(0x10de, "NVIDIA H200").slices(&image(
                "VK_FORMAT_R8G8B8A8_UNORM",
                [4, 4, 1],
                1
            )),
            None
        );
    }
}
