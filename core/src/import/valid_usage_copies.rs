//! The regions of copies between buffers and images, by the rules of `VkBufferImageCopy`
//! and the copy commands: a row length shorter than the region's width
//! (`VUID-VkBufferImageCopy-bufferRowLength-00195`) or an image height shorter than its height
//! (`-bufferImageHeight-00196`), and a buffer too small for the bytes the region addresses
//! (`VUID-vkCmdCopyBufferToImage-pRegions-00171`, `VUID-vkCmdCopyImageToBuffer-pRegions-00183`;
//! Qt's P010 upload gives rows of 159 texels for a plane 318 wide, and so runs past its
//! staging buffer). The `2` commands' regions are `VkBufferImageCopy2` in their `*Info2`.

use super::state::Objects;
use super::valid_usage_params::holder;
use super::value::{Arg, Got};
use crate::capture::dxgi;
use crate::capture::format::ValidUsageFinding;

/// What a buffer-image copy command names: the `*Info2` argument holding its arguments (the
/// `2` commands), the buffer argument, the image argument, the region structure and the
/// command's own rule on the buffer's size.
struct Shape {
    info: Option<&'static str>,
    buffer: &'static str,
    image: &'static str,
    structure: &'static str,
    size_rule: &'static str,
}

fn shape(call: &str) -> Option<Shape> {
    let to_image = |info, structure, size_rule| Shape {
        info,
        buffer: "srcBuffer",
        image: "dstImage",
        structure,
        size_rule,
    };
    let to_buffer = |info, structure, size_rule| Shape {
        info,
        buffer: "dstBuffer",
        image: "srcImage",
        structure,
        size_rule,
    };
    Some(match call {
        "vkCmdCopyBufferToImage" => to_image(
            None,
            "VkBufferImageCopy",
            "vkCmdCopyBufferToImage-pRegions-00171",
        ),
        "vkCmdCopyBufferToImage2" | "vkCmdCopyBufferToImage2KHR" => to_image(
            Some("pCopyBufferToImageInfo"),
            "VkBufferImageCopy2",
            "VkCopyBufferToImageInfo2-pRegions-00171",
        ),
        "vkCmdCopyImageToBuffer" => to_buffer(
            None,
            "VkBufferImageCopy",
            "vkCmdCopyImageToBuffer-pRegions-00183",
        ),
        "vkCmdCopyImageToBuffer2" | "vkCmdCopyImageToBuffer2KHR" => to_buffer(
            Some("pCopyImageToBufferInfo"),
            "VkBufferImageCopy2",
            "VkCopyImageToBufferInfo2-pRegions-00183",
        ),
        _ => return None,
    })
}

const DEPTH_ASPECT: u64 = 0x2;
const STENCIL_ASPECT: u64 = 0x4;

/// The bytes of one texel block of `format` as a copy of `aspect` lays it out in a buffer,
/// and the block's width and height: a depth aspect takes 2 bytes (16-bit depth) or 4, a
/// stencil aspect 1, whatever the image packs them into. `None` for a format framelab does
/// not know.
fn element(format: &str, aspect: u64) -> Option<(u64, u32, u32)> {
    let f = dxgi::lookup_vk(format)?;
    let bytes = if aspect & STENCIL_ASPECT != 0 {
        1
    } else if aspect & DEPTH_ASPECT != 0 {
        if f.depth_bits == 16 { 2 } else { 4 }
    } else {
        u64::from(f.bits_per_element / 8)
    };
    (bytes > 0).then_some((bytes, f.block_width.max(1), f.block_height.max(1)))
}

/// The findings of buffer-image copy call `command` (named `call`).
pub fn regions(
    call: &str,
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    let Some(shape) = shape(call) else {
        return Ok(Vec::new());
    };
    let holder = holder(args, shape.info)?;
    let image = objects.images.get(&holder.get(shape.image)?.handle()?);
    let buffer = objects.buffers.get(&holder.get(shape.buffer)?.handle()?);
    let mut out = Vec::new();
    for (i, r) in holder.list("pRegions")?.iter().enumerate() {
        let extent = super::subresources::extent3(&r.get("imageExtent")?)?;
        let row = r.get("bufferRowLength")?.u64()?;
        let height = r.get("bufferImageHeight")?.u64()?;
        let structure = shape.structure;
        for (member, value, least, number) in [
            ("bufferRowLength", row, extent[0], "00195"),
            ("bufferImageHeight", height, extent[1], "00196"),
        ] {
            if value != 0 && value < u64::from(least) {
                out.push(ValidUsageFinding {
                    vuid: format!("VUID-{structure}-{member}-{number}"),
                    command: command.to_owned(),
                    detail: format!(
                        "pRegions[{i}]: {member} {value} is neither 0 nor at least the region's {least} texels"
                    ),
                });
            }
        }
        let (Some(image), Some(buffer)) = (image, buffer) else {
            continue;
        };
        let sub = r.get("imageSubresource")?;
        let aspect = sub.get("aspectMask")?.u64()?;
        let Some((bytes, bw, bh)) = element(&image.format, aspect) else {
            continue;
        };
        let layers = super::subresources::layer_count(&sub).max(1);
        let needed = addressed(
            r.get("bufferOffset")?.u64()?,
            extent,
            row,
            height,
            layers,
            (bytes, bw, bh),
        );
        if needed > buffer.size {
            out.push(ValidUsageFinding {
                vuid: format!("VUID-{}", shape.size_rule),
                command: command.to_owned(),
                detail: format!(
                    "pRegions[{i}] addresses the buffer's bytes up to {needed}, past its size of {} bytes",
                    buffer.size
                ),
            });
        }
    }
    Ok(out)
}

/// One past the last byte a region addresses in its buffer (Buffer and Image Addressing):
/// rows `bufferRowLength` blocks apart (or the extent's width), slices and layers
/// `bufferImageHeight` rows apart (or the extent's height), the last row only as wide as the
/// region.
fn addressed(
    offset: u64,
    extent: [u32; 3],
    row: u64,
    height: u64,
    layers: u32,
    (bytes, bw, bh): (u64, u32, u32),
) -> u64 {
    if extent.contains(&0) {
        return offset;
    }
    let blocks = |texels: u64, b: u32| texels.div_ceil(u64::from(b));
    let row = blocks(if row == 0 { u64::from(extent[0]) } else { row }, bw);
    let height = blocks(
        if height == 0 {
            u64::from(extent[1])
        } else {
            height
        },
        bh,
    );
    let (w, h) = (
        blocks(u64::from(extent[0]), bw),
        blocks(u64::from(extent[1]), bh),
    );
    let slices = u64::from(extent[2]) * u64::from(layers);
    let last = (slices - 1) * height * row + (h - 1) * row + w;
    offset.saturating_add(last.saturating_mul(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_addresses_up_to_its_last_rows_width() {
        // Qt's P010 chroma upload: 159 R16G16 texels a row, 318 wide, 119 rows.
        let rg16 = (4, 1, 1);
        assert_eq!(
            addressed(0, [318, 119, 1], 159, 0, 1, rg16),
            (118 * 159 + 318) * 4
        );
        // Tightly packed: exactly the region's bytes.
        assert_eq!(
            addressed(16, [4, 4, 1], 0, 0, 2, (4, 1, 1)),
            16 + 4 * 4 * 2 * 4
        );
        // BC1: 8 bytes a 4x4 block, rows of blocks.
        assert_eq!(addressed(0, [8, 8, 1], 0, 0, 1, (8, 4, 4)), 4 * 8);
        assert_eq!(addressed(0, [0, 8, 1], 0, 0, 1, (8, 4, 4)), 0);
    }

    #[test]
    fn depth_and_stencil_aspects_take_their_own_sizes() {
        assert_eq!(
            element("VK_FORMAT_D24_UNORM_S8_UINT", DEPTH_ASPECT)
                .unwrap()
                .0,
            4
        );
        assert_eq!(
            element("VK_FORMAT_D24_UNORM_S8_UINT", STENCIL_ASPECT)
                .unwrap()
                .0,
            1
        );
        assert_eq!(element("VK_FORMAT_D16_UNORM", DEPTH_ASPECT).unwrap().0, 2);
        assert_eq!(element("VK_FORMAT_R16G16_UNORM", 1).unwrap(), (4, 1, 1));
    }
}
