//! Copy commands as copy passes: one copy a region and array layer, rows of buffer sides sized
//! from the image's format, as a capture's copies need them.

use super::*;

impl Builder {
    /// A copy pass with one copy per region; rows of buffer sides are sized from the image's
    /// format, as a capture's copies need them.
    pub(super) fn copy(
        &mut self,
        objects: &Objects,
        queue: u64,
        name: &str,
        (src, dst): (u64, u64),
        regions: &[Region],
    ) {
        let (Some(sn), Some(dn)) = (self.resource(objects, src), self.resource(objects, dst))
        else {
            return;
        };
        let texel_bytes = |h: u64| {
            objects
                .images
                .get(&h)
                .and_then(|i| dxgi::lookup_vk(&i.format))
                .map(|f| (u64::from(f.bits_per_element) / 8, f.block_width.max(1)))
        };
        let footprint = texel_bytes(src).or_else(|| texel_bytes(dst));
        let src_is_buffer = objects.buffers.contains_key(&src);
        let dst_is_buffer = objects.buffers.contains_key(&dst);
        let both_buffers = src_is_buffer && dst_is_buffer;
        let row = |r: &Region| {
            let (bytes, bw) = footprint?;
            let texels = if r.row_texels == 0 {
                r.extent?[0]
            } else {
                r.row_texels
            };
            u32::try_from(u64::from(texels.div_ceil(bw)) * bytes).ok()
        };
        // A region of several array layers is one copy a layer: the image side's layer
        // advances, and a buffer side by one layer's bytes (its rows at the row pitch, as
        // many as `bufferImageHeight` or the extent's height, in blocks).
        let per_layer: Vec<Region> = regions
            .iter()
            .flat_map(|r| {
                let layer_bytes = (|| {
                    let (_, bw) = footprint?;
                    let rows = if r.image_rows == 0 {
                        r.extent?[1]
                    } else {
                        r.image_rows
                    };
                    Some(u64::from(row(r)?) * u64::from(rows.div_ceil(bw)))
                })()
                .unwrap_or(0);
                (0..r.layers.max(1)).map(move |k| {
                    let mut one = r.clone();
                    one.layers = 1;
                    let skip = u64::from(k) * layer_bytes;
                    if src_is_buffer && !both_buffers {
                        one.src_offset += skip;
                    } else {
                        one.src_layer += k;
                    }
                    if dst_is_buffer && !both_buffers {
                        one.dst_offset += skip;
                    } else {
                        one.dst_layer += k;
                    }
                    one
                })
            })
            .collect();
        // Rows closer than a row's width overlap as a driver reads them: invalid, and nothing
        // the replay's copies can do, so the frame is refused where it copies so.
        let (overlapping, per_layer): (Vec<Region>, Vec<Region>) =
            per_layer.into_iter().partition(|r| {
                !both_buffers && r.row_texels != 0 && r.extent.is_some_and(|e| r.row_texels < e[0])
            });
        if let Some(r) = overlapping.first() {
            let what = format!(
                "{name} with a bufferRowLength of {} texels, shorter than the {} it copies a row (VUID-VkBufferImageCopy-bufferRowLength-00195): its rows overlap",
                r.row_texels,
                r.extent.map_or(0, |e| e[0])
            );
            self.refuse(queue, None, &what);
        }
        // A buffer side that runs past its buffer's end (to its last texel, as Vulkan addresses
        // it) reads or writes bytes the buffer does not have: undefined, and nothing a copy can
        // be given, so the frame is refused where it copies so.
        let buffer_end = |r: &Region| -> Option<(u64, u64, u64)> {
            let (buffer, offset) = match (src_is_buffer, dst_is_buffer) {
                (true, false) => (src, r.src_offset),
                (false, true) => (dst, r.dst_offset),
                _ => return None,
            };
            let size = objects.buffers.get(&buffer)?.size;
            let ((bytes, bw), e, pitch) = (footprint?, r.extent?, u64::from(row(r)?));
            let rows = u64::from(e[1].div_ceil(bw));
            let row_bytes = u64::from(e[0].div_ceil(bw)) * bytes;
            let needed = pitch * rows * u64::from(e[2].max(1) - 1)
                + pitch * rows.saturating_sub(1)
                + row_bytes;
            (offset.saturating_add(needed) > size).then_some((offset, needed, size))
        };
        let (past_end, per_layer): (Vec<Region>, Vec<Region>) =
            per_layer.into_iter().partition(|r| buffer_end(r).is_some());
        if let Some((offset, needed, size)) = past_end.first().and_then(buffer_end) {
            let vuid = if src_is_buffer {
                "VUID-vkCmdCopyBufferToImage-pRegions-00171"
            } else {
                "VUID-vkCmdCopyImageToBuffer-pRegions-00183"
            };
            let what = format!(
                "{name} whose region runs past the end of its buffer ({needed} bytes from offset {offset} of {size}; {vuid}): the bytes past it are undefined"
            );
            self.refuse(queue, None, &what);
        }
        if per_layer.is_empty() {
            return;
        }
        let Some(pass) = self.new_pass(objects, queue, PassKind::Copy, name) else {
            return;
        };
        for r in &per_layer {
            self.passes[pass].copies.push(Copy {
                src: CopyLocation {
                    resource: sn.clone(),
                    mip: r.src_mip,
                    layer: r.src_layer,
                    origin: r.src_origin,
                    offset: r.src_offset,
                    size: if both_buffers { r.size } else { None },
                    bytes_per_row: (src_is_buffer && !both_buffers).then(|| row(r)).flatten(),
                },
                dst: CopyLocation {
                    resource: dn.clone(),
                    mip: r.dst_mip,
                    layer: r.dst_layer,
                    origin: r.dst_origin,
                    offset: r.dst_offset,
                    size: if both_buffers { r.size } else { None },
                    bytes_per_row: (dst_is_buffer && !both_buffers).then(|| row(r)).flatten(),
                },
                extent: r.extent,
                host: false,
            });
        }
    }
}
