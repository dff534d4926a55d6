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
use super::record::{Recording, Recordings};
use super::state::{Descriptor, ImageInfo, Objects, storage_descriptor};
use crate::capture::dxgi;

/// Deepest nesting of secondary command buffers followed.
const MAX_DEPTH: u32 = 4;

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
                Cmd::Execute(secondaries) if depth < MAX_DEPTH => {
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
                let done = match (objects.buffers.contains_key(src), objects.images.get(dst)) {
                    (true, None) if objects.buffers.contains_key(dst) => {
                        self.copy_buffer(objects, *src, *dst, regions)
                    }
                    (true, Some(img)) => self.upload(objects, *src, *dst, img, regions),
                    _ => false,
                };
                if !done {
                    self.gpu_wrote(*dst);
                }
            }
            TransferCmd::Clear { target, .. } => self.gpu_wrote(*target),
            TransferCmd::Fill { buffer, .. } => self.gpu_wrote(*buffer),
            TransferCmd::Resolve { dst, .. } => self.gpu_wrote(*dst),
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
        let Some((memory, at)) = objects.buffers.get(&dst).and_then(|b| b.bound) else {
            return false;
        };
        for r in regions {
            let Some(size) = r.size else { return false };
            let Some(bytes) = self.buffer_range(objects, src, r.src_offset, size) else {
                return false;
            };
            let Some(to) = at.checked_add(r.dst_offset) else {
                return false;
            };
            if !self.spend(size) {
                return false;
            }
            if let Some(d) = self.buffers.get_mut(&dst)
                && let Some(place) = d.get_mut(r.dst_offset as usize..)
                && place.len() >= bytes.len()
            {
                place[..bytes.len()].copy_from_slice(&bytes);
            }
            self.memory.entry(memory).or_default().write(to, bytes);
        }
        self.gpu_written.remove(&dst);
        true
    }

    /// `vkCmdCopyBufferToImage` into a colour image: each region's texel blocks are placed in
    /// the image's packed contents (levels in order, each level's layers and slices in
    /// order). `false` for formats the import cannot place (depth, stencil, planar) or a
    /// region outside the image or its source.
    fn upload(
        &mut self,
        objects: &Objects,
        src: u64,
        dst: u64,
        img: &ImageInfo,
        regions: &[Region],
    ) -> bool {
        let Some(f) = dxgi::lookup_vk(&img.format) else {
            return false;
        };
        let (bw, bh, bpb) = (
            u64::from(f.block_width.max(1)),
            u64::from(f.block_height.max(1)),
            u64::from(f.bits_per_element) / 8,
        );
        if f.depth_bits > 0 || f.stencil_bits > 0 || bpb == 0 || img.samples > 1 {
            return false;
        }
        let Some(size) = packed_size(img) else {
            return false;
        };
        if !self.uploaded.contains_key(&dst) {
            if size > super::contents::MAX_BLOCK_BYTES || !self.spend(size) {
                return false;
            }
            // What is not uploaded stays as the snapshot had it, else zeros.
            let start = self
                .image_snapshot(dst, img, size)
                .unwrap_or_else(|| vec![0; size as usize]);
            self.uploaded.insert(dst, start);
        }
        let dim = |d: u32, m: u32| u64::from((d >> m).max(1));
        for r in regions {
            let Some(ext) = r.extent else { return false };
            let m = r.dst_mip;
            if m >= img.mips {
                return false;
            }
            let mut level_at = 0u64;
            for l in 0..m {
                let Some(s) = f.texture_bytes(
                    (
                        dim(img.extent[0], l) as u32,
                        dim(img.extent[1], l) as u32,
                        dim(img.extent[2], l) as u32,
                    ),
                    img.layers.max(1),
                    1,
                    1,
                ) else {
                    return false;
                };
                level_at += s;
            }
            let (lw, lh, ld) = (
                dim(img.extent[0], m),
                dim(img.extent[1], m),
                dim(img.extent[2], m),
            );
            let [x, y, z] = r.dst_origin.map(u64::from);
            let [w, h, d] = ext.map(u64::from);
            let layers = u64::from(r.layers.max(1));
            if x + w > lw
                || y + h > lh
                || z + d > ld
                || u64::from(r.dst_layer) + layers > u64::from(img.layers.max(1))
                || x % bw != 0
                || y % bh != 0
            {
                return false;
            }
            let dst_row = lw.div_ceil(bw) * bpb;
            let slab = dst_row * lh.div_ceil(bh);
            let row_texels = if r.row_texels == 0 {
                w
            } else {
                u64::from(r.row_texels)
            };
            let image_rows = if r.image_rows == 0 {
                h
            } else {
                u64::from(r.image_rows)
            };
            let src_row = row_texels.div_ceil(bw) * bpb;
            let slice = src_row * image_rows.div_ceil(bh);
            let run = w.div_ceil(bw) * bpb;
            let rows = h.div_ceil(bh);
            let slices = layers * d;
            let Some(source) = self.buffer_range(objects, src, r.src_offset, slices * slice) else {
                return false;
            };
            let Some(data) = self.uploaded.get_mut(&dst) else {
                return false;
            };
            for s in 0..slices {
                let (layer, zz) = (u64::from(r.dst_layer) + s / d, z + s % d);
                for row in 0..rows {
                    let from = (s * slice + row * src_row) as usize;
                    let to = (level_at
                        + (layer * ld + zz) * slab
                        + (y / bh + row) * dst_row
                        + x / bw * bpb) as usize;
                    let (Some(a), Some(b)) = (
                        source.get(from..from + run as usize),
                        data.get_mut(to..to + run as usize),
                    ) else {
                        return false;
                    };
                    b.copy_from_slice(a);
                }
            }
        }
        self.gpu_written.remove(&dst);
        true
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

    fn copy(src: u64, dst: u64, src_offset: u64, dst_offset: u64, size: u64) -> TransferCmd {
        TransferCmd::Copy {
            name: "copy_buffer".to_owned(),
            src,
            dst,
            regions: vec![Region {
                src_mip: 0,
                src_layer: 0,
                src_origin: [0; 3],
                src_offset,
                dst_mip: 0,
                dst_layer: 0,
                dst_origin: [0; 3],
                dst_offset,
                size: Some(size),
                extent: None,
                row_texels: 0,
                image_rows: 0,
                layers: 1,
            }],
            layouts: (None, None),
        }
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
            },
        );
        assert_eq!(c.buffer_bytes(1, &objects), None);
        // Nor is what is copied from it.
        submit(&mut c, &objects, copy(1, 2, 0, 0, 4));
        assert_eq!(c.buffer_bytes(2, &objects), None);
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
