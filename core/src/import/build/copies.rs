//! Copy commands as copy passes: one copy a region and array layer, rows of buffer sides sized
//! from the image's format, as a capture's copies need them.

use super::*;

/// The two ends of a copy: which is a buffer, and the image's block footprint.
struct Sides {
    src: u64,
    dst: u64,
    src_is_buffer: bool,
    dst_is_buffer: bool,
    /// Bytes and width of the image's texel blocks.
    footprint: Option<(u64, u32)>,
    /// Height of the image's texel blocks.
    block_height: u32,
}

impl Sides {
    fn of(objects: &Objects, src: u64, dst: u64) -> Sides {
        let format = |h: u64| {
            objects
                .images
                .get(&h)
                .and_then(|i| dxgi::lookup_vk(&i.format))
        };
        let block = format(src).or_else(|| format(dst));
        Sides {
            src,
            dst,
            src_is_buffer: objects.buffers.contains_key(&src),
            dst_is_buffer: objects.buffers.contains_key(&dst),
            footprint: block.map(|f| (u64::from(f.bits_per_element) / 8, f.block_width.max(1))),
            block_height: block.map_or(1, |f| f.block_height.max(1)),
        }
    }

    fn both_buffers(&self) -> bool {
        self.src_is_buffer && self.dst_is_buffer
    }

    /// Bytes, width and height of the image's texel blocks.
    fn blocks(&self) -> Option<(u64, u32, u32)> {
        self.footprint
            .map(|(bytes, bw)| (bytes, bw, self.block_height))
    }

    /// The row pitch of region `r`'s buffer side, in bytes.
    fn row(&self, r: &Region) -> Option<u32> {
        let (bytes, bw) = self.footprint?;
        let texels = if r.row_texels == 0 {
            r.extent?[0]
        } else {
            r.row_texels
        };
        u32::try_from(u64::from(texels.div_ceil(bw)) * bytes).ok()
    }

    /// A region of several array layers as one a layer: the image side's layer advances, and
    /// a buffer side by one layer's bytes (its rows at the row pitch, as many as
    /// `bufferImageHeight` or the extent's height, in blocks).
    fn per_layer(&self, regions: &[Region]) -> Vec<Region> {
        let both_buffers = self.both_buffers();
        regions
            .iter()
            .flat_map(|r| {
                let layer_bytes = (|| {
                    let (_, bw) = self.footprint?;
                    let rows = if r.image_rows == 0 {
                        r.extent?[1]
                    } else {
                        r.image_rows
                    };
                    Some(u64::from(self.row(r)?) * u64::from(rows.div_ceil(bw)))
                })()
                .unwrap_or(0);
                (0..r.layers.max(1)).map(move |k| {
                    let mut one = r.clone();
                    one.layers = 1;
                    let skip = u64::from(k) * layer_bytes;
                    if self.src_is_buffer && !both_buffers {
                        one.src_offset += skip;
                    } else {
                        one.src_layer += k;
                    }
                    if self.dst_is_buffer && !both_buffers {
                        one.dst_offset += skip;
                    } else {
                        one.dst_layer += k;
                    }
                    one
                })
            })
            .collect()
    }

    /// Where region `r`'s buffer side runs past its buffer's end (to its last texel, as
    /// Vulkan addresses it): its offset, the bytes it reaches and the buffer's size.
    fn past_end(&self, objects: &Objects, r: &Region) -> Option<(u64, u64, u64)> {
        let (buffer, offset) = match (self.src_is_buffer, self.dst_is_buffer) {
            (true, false) => (self.src, r.src_offset),
            (false, true) => (self.dst, r.dst_offset),
            _ => return None,
        };
        let size = objects.buffers.get(&buffer)?.size;
        let ((bytes, bw), e, pitch) = (self.footprint?, r.extent?, u64::from(self.row(r)?));
        let rows = u64::from(e[1].div_ceil(bw));
        let row_bytes = u64::from(e[0].div_ceil(bw)) * bytes;
        let needed =
            pitch * rows * u64::from(e[2].max(1) - 1) + pitch * rows.saturating_sub(1) + row_bytes;
        (offset.saturating_add(needed) > size).then_some((offset, needed, size))
    }
}

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
        let sides = Sides::of(objects, src, dst);
        let per_layer = sides.per_layer(regions);
        let apart = self.rows_apart(queue, name, &sides, per_layer);
        let regions = self.inside_buffer(objects, queue, name, &sides, apart);
        if regions.is_empty() {
            return;
        }
        let Some(pass) = self.new_pass(objects, queue, PassKind::Copy, name) else {
            return;
        };
        let both_buffers = sides.both_buffers();
        let side = |resource: &String, is_buffer: bool, mip, layer, origin, offset, r: &Region| {
            CopyLocation {
                resource: resource.clone(),
                mip,
                layer,
                origin,
                offset,
                size: if both_buffers { r.size } else { None },
                bytes_per_row: (is_buffer && !both_buffers).then(|| sides.row(r)).flatten(),
            }
        };
        for r in &regions {
            self.passes[pass].copies.push(Copy {
                src: side(
                    &sn,
                    sides.src_is_buffer,
                    r.src_mip,
                    r.src_layer,
                    r.src_origin,
                    r.src_offset,
                    r,
                ),
                dst: side(
                    &dn,
                    sides.dst_is_buffer,
                    r.dst_mip,
                    r.dst_layer,
                    r.dst_origin,
                    r.dst_offset,
                    r,
                ),
                extent: r.extent,
                host: false,
            });
        }
    }

    /// Rows closer than a row's width (or slices closer than a slice's height) overlap as a
    /// driver addresses them: invalid, but every driver reads or writes each texel at the
    /// offset Vulkan's formula gives, so one copy a row of blocks reproduces it exactly.
    fn rows_apart(
        &mut self,
        queue: u64,
        name: &str,
        sides: &Sides,
        regions: Vec<Region>,
    ) -> Vec<Region> {
        let mut overlapping = 0u64;
        let mut too_many = None;
        let out: Vec<Region> = regions
            .into_iter()
            .flat_map(|r| match sides.blocks() {
                Some(f) if !sides.both_buffers() && overlaps(&r) => {
                    overlapping += 1;
                    rows_apart(&r, f, sides.src_is_buffer).unwrap_or_else(|| {
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
        out
    }

    /// The regions whose buffer side stays inside its buffer. Reading past the end reads
    /// whatever the memory holds there, which Vulkan leaves undefined: the rows and texels
    /// inside the buffer are copied, the rest of the image keeps what it held, and the import
    /// says so. Writing past it would overwrite what else the memory holds, which no copy can
    /// be given: refused.
    fn inside_buffer(
        &mut self,
        objects: &Objects,
        queue: u64,
        name: &str,
        sides: &Sides,
        regions: Vec<Region>,
    ) -> Vec<Region> {
        let (past_end, mut out): (Vec<Region>, Vec<Region>) = regions
            .into_iter()
            .partition(|r| sides.past_end(objects, r).is_some());
        let Some(first) = past_end.first() else {
            return out;
        };
        let (offset, needed, size) = sides.past_end(objects, first).unwrap_or_default();
        let Some(f) = sides.blocks().filter(|_| sides.src_is_buffer) else {
            let what = format!(
                "{name} whose region runs past the end of its buffer ({needed} bytes from offset {offset} of {size}; VUID-vkCmdCopyImageToBuffer-pRegions-00183): it would overwrite what else the memory holds"
            );
            self.refuse(queue, None, &what);
            return out;
        };
        let texels = past_end
            .iter()
            .map(|r| {
                r.extent.map_or(0, |e| {
                    u64::from(e[0]) * u64::from(e[1]) * u64::from(e[2].max(1))
                })
            })
            .sum::<u64>();
        let mut kept = Vec::new();
        for r in &past_end {
            let Some(rows) = rows_apart(r, f, true) else {
                let what = format!(
                    "{name} reading past the end of its buffer ({needed} bytes from offset {offset} of {size}; VUID-vkCmdCopyBufferToImage-pRegions-00171) in more than {MAX_ROWS_APART} rows, each of which would be its own copy"
                );
                self.refuse(queue, None, &what);
                return out;
            };
            kept.extend(rows.into_iter().filter_map(|r| inside(r, f, size)));
        }
        let copied = kept
            .iter()
            .map(|r| r.extent.map_or(0, |e| u64::from(e[0]) * u64::from(e[1])))
            .sum::<u64>();
        self.note(format!(
            "{name} reading past the end of its buffer ({needed} bytes from offset {offset} of {size}; VUID-vkCmdCopyBufferToImage-pRegions-00171): {} of {texels} texels, whose bytes are undefined, keep what the image held",
            texels.saturating_sub(copied)
        ));
        out.extend(kept);
        out
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
