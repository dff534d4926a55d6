//! Contents made on the GPU before the imported frames, where a whole capture (not a trimmed
//! one, which saves them) only holds what the application wrote on the host. The command
//! buffers submitted before the frames are walked in submission order: buffer-to-buffer and
//! buffer-to-image copies are carried out on the contents known so far (a staging buffer's
//! mapped writes become the texture they were copied into), and every other write (draws'
//! attachments and storage bindings, dispatches, clears, fills, blits, resolves, copies from
//! an image or from bytes not known) makes its destination unknown, so its contents are
//! named as earlier GPU work rather than given stale.
//!
//! What copies produce counts against the same allowance as every other contents (what the
//! capture wrote plus a fixed amount for zeros), so a capture that copies one small buffer
//! into many large images cannot make the import hold more.

use super::commands::{Cmd, Region, TransferCmd, Use};
use super::contents::{Contents, packed_size};
use super::packed::{Packed, Rows, TexelBox};
use super::record::{Recording, Recordings};
use super::state::{Descriptor, ImageInfo, Objects, storage_descriptor};

impl Contents {
    /// Carries out what command buffer `cb`, submitted before the imported frames, did to
    /// the contents known so far.
    pub fn submitted_before(&mut self, objects: &Objects, recordings: &Recordings, cb: u64) {
        if let Some(r) = recordings.get(&cb).filter(|_| !self.frozen) {
            self.walk(objects, recordings, r, 0);
        }
    }

    fn walk(&mut self, objects: &Objects, recordings: &Recordings, r: &Recording, depth: u32) {
        for cmd in &r.cmds {
            match cmd {
                Cmd::Transfer(t) => self.transfer(objects, t),
                Cmd::Draw(d) => self.written_through(objects, &d.uses),
                Cmd::Dispatch(d) => self.written_through(objects, &d.uses),
                Cmd::BeginRender(render) => {
                    for sp in &render.subpasses {
                        let views = sp
                            .colors
                            .iter()
                            .map(|c| c.view)
                            .chain(sp.depth.iter().map(|d| d.view))
                            .chain(sp.resolves.iter().map(|(_, to)| *to));
                        for view in views {
                            if let Some(v) = objects.views.get(&view) {
                                self.gpu_wrote(v.image);
                            }
                        }
                    }
                }
                Cmd::Execute(secondaries) if depth < super::record::MAX_EXECUTE_DEPTH => {
                    for cb in secondaries {
                        if let Some(s) = recordings.get(cb) {
                            self.walk(objects, recordings, s, depth + 1);
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// Storage bindings of a draw or dispatch: written as far as the import can tell.
    fn written_through(&mut self, objects: &Objects, uses: &[Use]) {
        for u in uses {
            match &u.descriptor {
                Descriptor::Image { view, ty, .. } if storage_descriptor(ty) => {
                    if let Some(v) = objects.views.get(view) {
                        self.gpu_wrote(v.image);
                    }
                }
                Descriptor::Buffer { buffer, ty, .. } if storage_descriptor(ty) => {
                    self.gpu_wrote(*buffer)
                }
                Descriptor::TexelBuffer { view, ty } if storage_descriptor(ty) => {
                    if let Some((buffer, _, _)) = objects.buffer_views.get(view) {
                        self.gpu_wrote(*buffer);
                    }
                }
                _ => {}
            }
        }
    }

    /// A resource the GPU wrote in a way the import does not carry out.
    fn gpu_wrote(&mut self, resource: u64) {
        self.uploaded.remove(&resource);
        self.gpu_written.insert(resource);
    }

    fn transfer(&mut self, objects: &Objects, t: &TransferCmd) {
        match t {
            TransferCmd::Copy {
                src, dst, regions, ..
            } => {
                let buffer = |h: &u64| objects.buffers.contains_key(h);
                let done = match (objects.images.get(src), objects.images.get(dst)) {
                    (None, None) if buffer(src) && buffer(dst) => {
                        self.copy_buffer(objects, *src, *dst, regions)
                    }
                    (None, Some(img)) if buffer(src) => {
                        self.upload(objects, *src, *dst, img, regions)
                    }
                    (Some(img), None) if buffer(dst) => {
                        self.read_back(objects, *src, img, *dst, regions)
                    }
                    (Some(from), Some(to)) => self.copy_image((*src, from), (*dst, to), regions),
                    _ => false,
                };
                if !done {
                    self.gpu_wrote(*dst);
                }
            }
            TransferCmd::Clear { target, .. } => self.gpu_wrote(*target),
            TransferCmd::Fill { buffer, .. } => self.gpu_wrote(*buffer),
            TransferCmd::Resolve { dst, .. } => self.gpu_wrote(*dst),
            TransferCmd::Blit { dst, .. } => self.gpu_wrote(*dst),
        }
    }

    /// Bytes [offset, offset + size) of buffer `buffer` as known now: from its snapshot, else
    /// from the memory it is bound to; `None` when they are not known.
    fn buffer_range(
        &self,
        objects: &Objects,
        buffer: u64,
        offset: u64,
        size: u64,
    ) -> Option<Vec<u8>> {
        if self.gpu_written.contains(&buffer) {
            return None;
        }
        let end = offset.checked_add(size)?;
        if end > objects.buffers.get(&buffer)?.size {
            return None;
        }
        if let Some(d) = self.buffers.get(&buffer) {
            return d.get(offset as usize..end as usize).map(<[u8]>::to_vec);
        }
        let (memory, at) = objects.buffers.get(&buffer)?.bound?;
        self.memory
            .get(&memory)?
            .read(at.checked_add(offset)?, size)
    }

    /// `vkCmdCopyBuffer`: each region's bytes, where known, land in the destination's memory
    /// (and its snapshot, if it has one). `false` when a region's source is not known.
    fn copy_buffer(&mut self, objects: &Objects, src: u64, dst: u64, regions: &[Region]) -> bool {
        for r in regions {
            let Some(size) = r.size else { return false };
            let Some(bytes) = self.buffer_range(objects, src, r.src_offset, size) else {
                return false;
            };
            if !self.spend(size) || !self.write_buffer(objects, dst, r.dst_offset, bytes) {
                return false;
            }
        }
        self.gpu_written.remove(&dst);
        true
    }

    /// Writes `bytes` at `offset` of buffer `buffer`: into the memory it is bound to, and
    /// its snapshot if it has one. `false` when it is bound to none.
    fn write_buffer(
        &mut self,
        objects: &Objects,
        buffer: u64,
        offset: u64,
        bytes: Vec<u8>,
    ) -> bool {
        let Some((memory, at)) = objects.buffers.get(&buffer).and_then(|b| b.bound) else {
            return false;
        };
        let Some(to) = at.checked_add(offset) else {
            return false;
        };
        if let Some(d) = self.buffers.get_mut(&buffer)
            && let Some(place) = d.get_mut(offset as usize..)
            && place.len() >= bytes.len()
        {
            place[..bytes.len()].copy_from_slice(&bytes);
        }
        self.memory.entry(memory).or_default().write(to, bytes);
        true
    }

    /// Makes the contents of image `handle` as known now the bytes copies work on, in
    /// `uploaded`. A source must be known (copied into before, or in the snapshot); a
    /// destination not known starts as zeros, counted against the allowance (what no copy
    /// writes stays as undefined as it was). `false` when neither holds.
    fn materialise(&mut self, handle: u64, img: &ImageInfo, destination: bool) -> bool {
        if self.uploaded.contains_key(&handle) {
            return true;
        }
        let Some(size) = packed_size(img).filter(|s| *s <= super::contents::MAX_BLOCK_BYTES) else {
            return false;
        };
        let known = if self.gpu_written.contains(&handle) {
            None
        } else {
            self.image_snapshot(handle, img, size)
        };
        let start = match known {
            Some(data) => data,
            None if destination && self.spend(size) => vec![0; size as usize],
            None => return false,
        };
        self.uploaded.insert(handle, start);
        true
    }

    /// `vkCmdCopyBufferToImage` into a colour image: each region's texel blocks, read from
    /// the buffer at the region's row length and image height, are placed in the image's
    /// packed contents. `false` for formats the import cannot place (depth, stencil, planar)
    /// or a region outside the image or its source.
    fn upload(
        &mut self,
        objects: &Objects,
        src: u64,
        dst: u64,
        img: &ImageInfo,
        regions: &[Region],
    ) -> bool {
        let Some(p) = Packed::of(img) else {
            return false;
        };
        if !self.materialise(dst, img, true) {
            return false;
        }
        for r in regions {
            let Some(b) = TexelBox::of(r, false) else {
                return false;
            };
            let Some(to) = p.rows(&b) else { return false };
            let from = p.footprint(&b, r.row_texels, r.image_rows);
            let Some(source) = self.buffer_range(objects, src, r.src_offset, from.span()) else {
                return false;
            };
            let Some(data) = self.uploaded.get_mut(&dst) else {
                return false;
            };
            for i in 0..to.count {
                let (Some(a), Some(b)) = (source.get(from.at(i)), data.get_mut(to.at(i))) else {
                    return false;
                };
                b.copy_from_slice(a);
            }
        }
        self.gpu_written.remove(&dst);
        true
    }

    /// `vkCmdCopyImageToBuffer` from a colour image whose contents are known: each region's
    /// texel blocks land in the buffer at the region's row length and image height.
    fn read_back(
        &mut self,
        objects: &Objects,
        src: u64,
        img: &ImageInfo,
        dst: u64,
        regions: &[Region],
    ) -> bool {
        let Some(p) = Packed::of(img) else {
            return false;
        };
        let Some(dst_size) = objects.buffers.get(&dst).map(|b| b.size) else {
            return false;
        };
        if !self.materialise(src, img, false) {
            return false;
        }
        for r in regions {
            let Some(b) = TexelBox::of(r, true) else {
                return false;
            };
            let Some(from) = p.rows(&b) else { return false };
            let to = p.footprint(&b, r.row_texels, r.image_rows);
            if r.dst_offset
                .checked_add(to.span())
                .is_none_or(|end| end > dst_size)
                || !self.spend(from.count.saturating_mul(from.run))
            {
                return false;
            }
            let Some(rows) = self.image_rows(src, &from) else {
                return false;
            };
            for (i, bytes) in (0..to.count).zip(rows) {
                let offset = r.dst_offset + to.at(i).start as u64;
                if !self.write_buffer(objects, dst, offset, bytes) {
                    return false;
                }
            }
        }
        self.gpu_written.remove(&dst);
        true
    }

    /// `vkCmdCopyImage` between colour images of the same block size whose source is known:
    /// each region's blocks are copied one for one (all of a region read before any is
    /// written, for a copy within one image).
    fn copy_image(
        &mut self,
        (src, from_img): (u64, &ImageInfo),
        (dst, to_img): (u64, &ImageInfo),
        regions: &[Region],
    ) -> bool {
        let (Some(sp), Some(dp)) = (Packed::of(from_img), Packed::of(to_img)) else {
            return false;
        };
        if !sp.same_blocks(&dp)
            || !self.materialise(src, from_img, false)
            || !self.materialise(dst, to_img, true)
        {
            return false;
        }
        for r in regions {
            let (Some(from), Some(to)) = (
                TexelBox::of(r, true).and_then(|b| sp.rows(&b)),
                TexelBox::of(r, false).and_then(|b| dp.rows(&b)),
            ) else {
                return false;
            };
            if from.count != to.count || from.run != to.run {
                return false;
            }
            let Some(rows) = self.image_rows(src, &from) else {
                return false;
            };
            let Some(out) = self.uploaded.get_mut(&dst) else {
                return false;
            };
            for (i, bytes) in (0..to.count).zip(rows) {
                let Some(place) = out.get_mut(to.at(i)) else {
                    return false;
                };
                place.copy_from_slice(&bytes);
            }
        }
        self.gpu_written.remove(&dst);
        true
    }

    /// The bytes of each of `rows` of image `image`'s contents in `uploaded`, read before
    /// anything is written (a copy may read and write one image).
    fn image_rows(&self, image: u64, rows: &Rows) -> Option<Vec<Vec<u8>>> {
        let data = self.uploaded.get(&image)?;
        (0..rows.count)
            .map(|i| data.get(rows.at(i)).map(<[u8]>::to_vec))
            .collect()
    }

    /// Takes `bytes` from what contents may still add up to; `false` when they would pass it.
    fn spend(&mut self, bytes: u64) -> bool {
        match self.copied.checked_add(bytes) {
            Some(total)
                if total <= self.written.saturating_add(super::contents::ZERO_ALLOWANCE) =>
            {
                self.copied = total;
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::state::BufferInfo;

    fn buffer(objects: &mut Objects, handle: u64, memory: u64, size: u64) {
        objects.buffers.insert(
            handle,
            BufferInfo {
                created_at: 0,
                destroyed_at: None,
                size,
                usage: 0,
                bound: Some((memory, 0)),
                alignment: None,
            },
        );
    }

    fn submit(contents: &mut Contents, objects: &Objects, cmd: TransferCmd) {
        let mut r = Recording::default();
        r.cmds.push(Cmd::Transfer(Box::new(cmd)));
        let recordings = super::super::HashMap::from_iter([(7, Box::new(r))]);
        contents.submitted_before(objects, &recordings, 7);
    }

    /// A copy `name` of one region, `region` given on top of a region of nothing: first mip
    /// and layer, no offsets.
    fn one_region(name: &str, (src, dst): (u64, u64), region: Region) -> TransferCmd {
        TransferCmd::Copy {
            name: name.to_owned(),
            src,
            dst,
            regions: vec![region],
            layouts: (None, None),
        }
    }

    const NO_REGION: Region = Region {
        src_mip: 0,
        src_layer: 0,
        src_origin: [0; 3],
        src_offset: 0,
        dst_mip: 0,
        dst_layer: 0,
        dst_origin: [0; 3],
        dst_offset: 0,
        size: None,
        extent: None,
        row_texels: 0,
        image_rows: 0,
        layers: 1,
    };

    fn copy(src: u64, dst: u64, src_offset: u64, dst_offset: u64, size: u64) -> TransferCmd {
        let region = Region {
            src_offset,
            dst_offset,
            size: Some(size),
            ..NO_REGION
        };
        one_region("copy_buffer", (src, dst), region)
    }

    #[test]
    fn a_copy_carries_host_writes_and_other_gpu_writes_make_contents_unknown() {
        let mut objects = Objects::default();
        buffer(&mut objects, 1, 10, 8);
        buffer(&mut objects, 2, 20, 8);
        let mut c = Contents::default();
        c.fill(10, 0, (1..=8).collect());
        submit(&mut c, &objects, copy(1, 2, 2, 4, 4));
        assert_eq!(
            c.buffer_bytes(2, &objects),
            Some(vec![0, 0, 0, 0, 3, 4, 5, 6])
        );
        // A fill's bytes are not in the command: what the buffer held is no longer known.
        submit(
            &mut c,
            &objects,
            TransferCmd::Fill {
                update: false,
                buffer: 1,
                range: (0, u64::MAX),
            },
        );
        assert_eq!(c.buffer_bytes(1, &objects), None);
        // Nor is what is copied from it.
        submit(&mut c, &objects, copy(1, 2, 0, 0, 4));
        assert_eq!(c.buffer_bytes(2, &objects), None);
    }

    fn image(objects: &mut Objects, handle: u64, width: u32, height: u32) {
        let info = super::super::contents::tests::image(
            "VK_FORMAT_R8G8B8A8_UNORM",
            [width, height, 1],
            1,
            1,
        );
        objects.images.insert(handle, info);
    }

    /// A copy between a buffer or image and an image: `origin` and `extent` in texels on
    /// the image side (the source's for a copy out of an image).
    fn image_copy(
        name: &str,
        ends: (u64, u64),
        (src_origin, dst_origin): ([u32; 3], [u32; 3]),
        extent: [u32; 3],
        row_texels: u32,
    ) -> TransferCmd {
        let region = Region {
            src_origin,
            dst_origin,
            extent: Some(extent),
            row_texels,
            ..NO_REGION
        };
        one_region(name, ends, region)
    }

    #[test]
    fn copies_out_of_and_between_images_carry_what_was_uploaded() {
        let mut objects = Objects::default();
        buffer(&mut objects, 1, 10, 64);
        image(&mut objects, 2, 4, 4);
        image(&mut objects, 3, 4, 4);
        buffer(&mut objects, 4, 40, 16);
        buffer(&mut objects, 5, 50, 16);
        image(&mut objects, 6, 4, 4);
        let mut c = Contents::default();
        c.fill(10, 0, (0..64).collect());
        let whole = [4, 4, 1];
        submit(
            &mut c,
            &objects,
            image_copy("copy_buffer_to_image", (1, 2), ([0; 3], [0; 3]), whole, 0),
        );
        assert_eq!(c.uploaded.get(&2), Some(&(0..64).collect::<Vec<u8>>()));
        // Texels (2..4, 0..2) of image 2 to (0..2, 2..4) of image 3; the rest stays zeros.
        submit(
            &mut c,
            &objects,
            image_copy("copy_image", (2, 3), ([2, 0, 0], [0, 2, 0]), [2, 2, 1], 0),
        );
        let mut expected = vec![0u8; 64];
        expected[32..40].copy_from_slice(&(8..16).collect::<Vec<u8>>());
        expected[48..56].copy_from_slice(&(24..32).collect::<Vec<u8>>());
        assert_eq!(c.uploaded.get(&3), Some(&expected));
        // Read back tightly packed, the same texels again.
        submit(
            &mut c,
            &objects,
            image_copy(
                "copy_image_to_buffer",
                (3, 4),
                ([0, 2, 0], [0; 3]),
                [2, 2, 1],
                0,
            ),
        );
        let back: Vec<u8> = (8..16).chain(24..32).collect();
        assert_eq!(c.buffer_bytes(4, &objects), Some(back));
        // An image nothing was copied into is not known, nor what is read back from it.
        submit(
            &mut c,
            &objects,
            image_copy(
                "copy_image_to_buffer",
                (6, 5),
                ([0; 3], [0; 3]),
                [2, 2, 1],
                0,
            ),
        );
        assert_eq!(c.buffer_bytes(5, &objects), None);
        // A region past the image makes the destination unknown rather than half-copied.
        submit(
            &mut c,
            &objects,
            image_copy("copy_image", (2, 3), ([3, 0, 0], [0; 3]), [2, 1, 1], 0),
        );
        assert!(c.gpu_written.contains(&3) && !c.uploaded.contains_key(&3));
        // A blit's result is not carried out: its destination is named as earlier GPU work.
        submit(
            &mut c,
            &objects,
            TransferCmd::Blit {
                src: 2,
                dst: 6,
                regions: Vec::new(),
                linear: false,
                layouts: (None, None),
                refused: None,
            },
        );
        assert!(c.gpu_written.contains(&6));
        assert!(c.uploaded.contains_key(&2));
    }

    #[test]
    fn texel_rows_of_a_box_and_of_a_buffer_footprint() {
        let mut objects = Objects::default();
        image(&mut objects, 1, 8, 4);
        let p = Packed::of(&objects.images[&1]).unwrap();
        let b = TexelBox {
            mip: 0,
            layer: 0,
            origin: [2, 1, 0],
            extent: [3, 2, 1],
            layers: 1,
        };
        let rows = p.rows(&b).unwrap();
        assert_eq!((rows.count, rows.run), (2, 12));
        assert_eq!((rows.at(0), rows.at(1)), (40..52, 72..84));
        // A row length of 5 texels: rows 20 bytes apart in the buffer.
        let f = p.footprint(&b, 5, 0);
        assert_eq!((f.at(0), f.at(1), f.span()), (0..12, 20..32, 40));
        let outside = TexelBox {
            origin: [6, 0, 0],
            ..b
        };
        assert!(p.rows(&outside).is_none());
    }

    #[test]
    fn copies_cannot_make_more_than_the_capture_wrote_and_the_allowance() {
        let mut objects = Objects::default();
        let big = super::super::contents::ZERO_ALLOWANCE;
        buffer(&mut objects, 1, 10, big);
        let mut c = Contents::default();
        c.fill(10, 0, vec![9; 16]);
        for dst in 2..5 {
            buffer(&mut objects, dst, 20 + dst, big);
        }
        // The first whole-buffer copy fits the allowance; the next ones do not.
        for dst in 2..5 {
            submit(&mut c, &objects, copy(1, dst, 0, 0, big / 2 + 16));
        }
        assert!(c.copied <= c.written + big);
        assert!(!c.gpu_written.contains(&2));
        assert!(c.gpu_written.contains(&3) && c.gpu_written.contains(&4));
    }
}
