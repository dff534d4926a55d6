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
        let block_height = |src: u64, dst: u64| {
            [src, dst]
                .iter()
                .find_map(|h| objects.images.get(h))
                .and_then(|i| dxgi::lookup_vk(&i.format))
                .map_or(1, |f| f.block_height.max(1))
        };
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
        // Rows closer than a row's width (or slices closer than a slice's height) overlap as a
        // driver addresses them: invalid, but every driver reads or writes each texel at the
        // offset Vulkan's formula gives, so one copy a row of blocks reproduces it exactly.
        let footprint_blocks = footprint.map(|(bytes, bw)| (bytes, bw, block_height(src, dst)));
        let mut overlapping = 0u64;
        let mut too_many = None;
        let per_layer: Vec<Region> = per_layer
            .into_iter()
            .flat_map(|r| match footprint_blocks {
                Some(f) if !both_buffers && overlaps(&r) => {
                    overlapping += 1;
                    rows_apart(&r, f, src_is_buffer).unwrap_or_else(|| {
                        too_many = Some(r);
                        Vec::new()
                    })
                }
                _ => vec![r],
            })
            .collect();
        if let Some(r) = too_many {
            let what = format!(
                "{name} with overlapping buffer rows (a bufferRowLength of {} texels for {:?}; VUID-VkBufferImageCopy-bufferRowLength-00195) in more than {MAX_ROWS_APART} rows, each of which would be its own copy",
                r.row_texels,
                r.extent.unwrap_or_default()
            );
            self.refuse(queue, None, &what);
        }
        if overlapping > 0 {
            self.note_n(
                format!("{name} regions whose buffer rows or slices overlap (VUID-VkBufferImageCopy-bufferRowLength-00195, -bufferImageHeight-00196): copied a row at a time, at the offsets a driver reads"),
                overlapping,
            );
        }
        // A buffer side that runs past its buffer's end (to its last texel, as Vulkan addresses
        // it) reads or writes bytes the buffer does not have.
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
        let (past_end, mut per_layer): (Vec<Region>, Vec<Region>) =
            per_layer.into_iter().partition(|r| buffer_end(r).is_some());
        // Reading past the end reads whatever the memory holds there, which Vulkan leaves
        // undefined: the rows and texels inside the buffer are copied, the rest of the image
        // keeps what it held, and the import says so. Writing past it would overwrite what
        // else the memory holds, which no copy can be given: refused.
        let (clipped, past_end): (Vec<Region>, Vec<Region>) = past_end
            .into_iter()
            .partition(|_| src_is_buffer && footprint_blocks.is_some());
        if let (Some(f), Some(first)) = (footprint_blocks, clipped.first()) {
            let size = objects.buffers.get(&src).map_or(0, |b| b.size);
            let texels = clipped
                .iter()
                .map(|r| {
                    r.extent.map_or(0, |e| {
                        u64::from(e[0]) * u64::from(e[1]) * u64::from(e[2].max(1))
                    })
                })
                .sum::<u64>();
            let kept: Vec<Region> = clipped
                .iter()
                .flat_map(|r| rows_apart(r, f, true).unwrap_or_default())
                .filter_map(|r| inside(r, f, size))
                .collect();
            let copied = kept
                .iter()
                .map(|r| r.extent.map_or(0, |e| u64::from(e[0]) * u64::from(e[1])))
                .sum::<u64>();
            let (offset, needed, _) = buffer_end(first).unwrap_or_default();
            self.note(format!(
                "{name} reading past the end of its buffer ({needed} bytes from offset {offset} of {size}; VUID-vkCmdCopyBufferToImage-pRegions-00171): {} of {texels} texels, whose bytes are undefined, keep what the image held",
                texels.saturating_sub(copied)
            ));
            per_layer.extend(kept);
        }
        if let Some((offset, needed, size)) = past_end.first().and_then(buffer_end) {
            let what = format!(
                "{name} whose region runs past the end of its buffer ({needed} bytes from offset {offset} of {size}; VUID-vkCmdCopyImageToBuffer-pRegions-00183): it would overwrite what else the memory holds"
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

/// One row of a buffer side that starts inside a buffer of `size` bytes, cut to the whole
/// blocks before its end; `None` where not one block is inside.
fn inside(mut r: Region, (bytes, bw, _): (u64, u32, u32), size: u64) -> Option<Region> {
    let e = r.extent.as_mut()?;
    let room = size.checked_sub(r.src_offset)? / bytes.max(1);
    let blocks = u64::from(e[0].div_ceil(bw)).min(room);
    if blocks == 0 {
        return None;
    }
    e[0] = e[0].min(u32::try_from(blocks).ok()? * bw);
    Some(r)
}

/// The most copies one region with overlapping rows becomes: an image 16,384 rows tall.
const MAX_ROWS_APART: u64 = 16_384;

/// Whether a buffer side's rows are closer than a row (`bufferRowLength` below the width), or
/// its slices closer than a slice (`bufferImageHeight` below the height, with several slices).
fn overlaps(r: &Region) -> bool {
    r.extent.is_some_and(|e| {
        (r.row_texels != 0 && r.row_texels < e[0])
            || (r.image_rows != 0 && r.image_rows < e[1] && e[2] > 1)
    })
}

/// `r` as one region a row of blocks a slice, each at the offset Vulkan's addressing gives
/// that row (rows `bufferRowLength` apart, slices `bufferImageHeight` rows apart), and at the
/// image side's matching origin: overlapping rows read and written as a driver does, in
/// order.
fn rows_apart(
    r: &Region,
    (bytes, bw, bh): (u64, u32, u32),
    src_is_buffer: bool,
) -> Option<Vec<Region>> {
    let [w, h, d] = r.extent?;
    if u64::from(h.div_ceil(bh)) * u64::from(d.max(1)) > MAX_ROWS_APART {
        return None;
    }
    let pitch_texels = if r.row_texels == 0 { w } else { r.row_texels };
    let pitch = u64::from(pitch_texels.div_ceil(bw)) * bytes;
    let slice_rows = u64::from(if r.image_rows == 0 { h } else { r.image_rows }.div_ceil(bh));
    let mut rows = Vec::new();
    for z in 0..d.max(1) {
        for by in 0..h.div_ceil(bh) {
            let skip = (u64::from(z) * slice_rows + u64::from(by)) * pitch;
            let mut one = r.clone();
            one.extent = Some([w, bh.min(h - by * bh), 1]);
            one.row_texels = 0;
            one.image_rows = 0;
            let (offset, origin) = if src_is_buffer {
                (&mut one.src_offset, &mut one.dst_origin)
            } else {
                (&mut one.dst_offset, &mut one.src_origin)
            };
            *offset += skip;
            origin[1] += by * bh;
            origin[2] += z;
            rows.push(one);
        }
    }
    Some(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn region(extent: [u32; 3], row_texels: u32, image_rows: u32) -> Region {
        Region {
            src_mip: 0,
            src_layer: 0,
            src_origin: [0; 3],
            src_offset: 100,
            dst_mip: 0,
            dst_layer: 0,
            dst_origin: [2, 3, 0],
            dst_offset: 0,
            size: None,
            extent: Some(extent),
            row_texels,
            image_rows,
            layers: 1,
        }
    }

    /// Rows `bufferRowLength` apart and slices `bufferImageHeight` rows apart, each its own
    /// copy at the image's matching row and slice; block rows for compressed formats.
    #[test]
    fn overlapping_rows_are_one_copy_a_row_at_vulkans_offsets() {
        let r = region([8, 3, 2], 4, 2);
        assert!(overlaps(&r));
        let rows = rows_apart(&r, (4, 1, 1), true).unwrap();
        let at: Vec<(u64, [u32; 3], [u32; 3])> = rows
            .iter()
            .map(|r| (r.src_offset, r.dst_origin, r.extent.unwrap()))
            .collect();
        assert_eq!(
            at,
            [
                (100, [2, 3, 0], [8, 1, 1]),
                (116, [2, 4, 0], [8, 1, 1]),
                (132, [2, 5, 0], [8, 1, 1]),
                (132, [2, 3, 1], [8, 1, 1]),
                (148, [2, 4, 1], [8, 1, 1]),
                (164, [2, 5, 1], [8, 1, 1]),
            ]
        );
        assert!(rows.iter().all(|r| r.row_texels == 0 && r.image_rows == 0));
        // 4x4 blocks of 16 bytes: a 12x10 region is three block rows, the last two texels tall.
        let blocks = rows_apart(&region([12, 10, 1], 8, 0), (16, 4, 4), false).unwrap();
        let at: Vec<(u64, u32, u32)> = blocks
            .iter()
            .map(|r| (r.dst_offset, r.src_origin[1], r.extent.unwrap()[1]))
            .collect();
        assert_eq!(at, [(0, 0, 4), (32, 4, 4), (64, 8, 2)]);
        assert!(
            !overlaps(&region([8, 3, 1], 8, 2)),
            "one slice: nothing overlaps"
        );
        assert!(rows_apart(&region([8, 20_000, 1], 4, 0), (4, 1, 1), true).is_none());
    }

    /// A row reaching past the buffer's end keeps its whole blocks inside; one starting at or
    /// past the end keeps nothing.
    #[test]
    fn rows_are_cut_at_the_buffers_end() {
        let r = region([8, 1, 1], 0, 0);
        assert_eq!(
            inside(r.clone(), (4, 1, 1), 130).unwrap().extent,
            Some([7, 1, 1])
        );
        assert_eq!(
            inside(r.clone(), (4, 1, 1), 200).unwrap().extent,
            Some([8, 1, 1])
        );
        assert!(inside(r.clone(), (4, 1, 1), 103).is_none());
        assert!(inside(r, (4, 1, 1), 50).is_none());
    }
}
