//! What the application's CPU writes through a mapping while the imported frames run (vkd3d's
//! vertex data, egui's staging buffers, per-frame constants, GTK's glyphs and icons written
//! into linear images): each write becomes a `host_write` copy pass at its place in the frame,
//! from a buffer holding the bytes into every buffer bound over the memory written, and into
//! the texels of every linear image there whose row pitch the driver gave
//! (`vkGetImageSubresourceLayout`). The copies are marked `host`: the next submission makes
//! host writes visible, so they need no barrier and take none of the queue's.

use super::Importer;
use super::build::Builder;
use super::state::{ImageInfo, Objects};
use crate::capture::dxgi;
use crate::capture::format::{Copy, CopyLocation, PassKind};

/// Bytes a host write puts in a rectangle of a linear image's texels: the bytes from the
/// rectangle's first texel, rows `pitch` apart.
#[derive(Debug)]
pub struct ImageWrite {
    pub bytes: Vec<u8>,
    pub origin: [u32; 3],
    pub extent: [u32; 3],
    pub pitch: u32,
}

impl Importer {
    /// Host writes of `data` at `offset` in `memory`, into every buffer bound over them and
    /// every linear image whose texels they reach (`linear`: an image's row pitch and the
    /// offset of its first texel in its binding, where the driver gave them).
    pub(super) fn host_write(
        &mut self,
        memory: u64,
        offset: u64,
        data: &[u8],
        linear: &dyn Fn(u64) -> Option<(u64, u64)>,
    ) {
        self.buffer_host_write(memory, offset, data);
        let mut images: Vec<u64> = self
            .objects
            .images
            .iter()
            .filter(|(_, i)| i.destroyed_at.is_none() && i.bound.is_some_and(|b| b.0 == memory))
            .map(|(h, _)| *h)
            .collect();
        images.sort_unstable();
        for image in images {
            let (Some(img), Some(layout)) = (self.objects.images.get(&image), linear(image)) else {
                continue;
            };
            match image_writes(img, layout, offset, data) {
                Ok(writes) if writes.is_empty() => {}
                Ok(writes) => self.builder.upload_image(&self.objects, image, writes),
                Err(why) => {
                    let queue = self.builder.last_queue.unwrap_or_default();
                    self.builder.refuse(queue, None, &why.to_string());
                }
            }
        }
    }

    /// Host writes of `data` at `offset` in `memory`, into every buffer bound over them.
    fn buffer_host_write(&mut self, memory: u64, offset: u64, data: &[u8]) {
        let end = offset.saturating_add(data.len() as u64);
        let bound = self
            .objects
            .buffers_in
            .get(&memory)
            .map_or(&[][..], Vec::as_slice);
        let mut targets: Vec<(u64, u64, u64)> = bound
            .iter()
            .filter_map(|h| Some((*h, self.objects.buffers.get(h)?)))
            .filter(|(_, b)| b.destroyed_at.is_none())
            .filter_map(|(h, b)| {
                let (m, at) = b.bound?;
                let (from, to) = (offset.max(at), end.min(at.saturating_add(b.size)));
                (m == memory && from < to).then_some((h, from, to))
            })
            .collect();
        targets.sort_unstable();
        targets.dedup();
        for (buffer, from, to) in targets {
            let at = self
                .objects
                .buffers
                .get(&buffer)
                .and_then(|b| b.bound)
                .map_or(0, |(_, a)| a);
            let bytes = data[(from - offset) as usize..(to - offset) as usize].to_vec();
            self.builder.upload(&self.objects, buffer, from - at, bytes);
        }
    }
}

/// A host write into a linear image's texels that the replay cannot carry out: the frame is
/// refused, never replayed with the image as it was.
#[derive(Debug, thiserror::Error)]
pub enum LinearWrite {
    /// Part of the texel is the write's and the rest is not known.
    #[error(
        "a host write that ends inside a texel of a linear {format} image (row {row}, bytes {from}..{to} of the row)"
    )]
    InsideTexel {
        format: String,
        row: u32,
        from: u64,
        to: u64,
    },
    /// Laid out by more than the row pitch of its first level and layer, which is all the
    /// driver was asked for, or with rows the pitch cannot hold.
    #[error(
        "a host write into a linear {format} image {what}, whose texels the replay cannot place"
    )]
    Unplaced { format: String, what: String },
}

/// The rectangles of `img`'s texels a host write of `data` at `offset` of its memory reaches:
/// its whole rows as one, each row it reaches in part as one of its own. Only a 2D image of
/// one level, one layer and one sample, of a format of whole texels, is laid out by the pitch
/// alone; a write that reaches any other linear image (up to where its subresources could
/// reach at that pitch) is refused, and so is a write that ends inside a texel.
fn image_writes(
    img: &ImageInfo,
    (pitch, first): (u64, u64),
    offset: u64,
    data: &[u8],
) -> Result<Vec<ImageWrite>, LinearWrite> {
    let Some((_, at)) = img.bound else {
        return Ok(Vec::new());
    };
    let [width, rows, depth] = img.extent;
    let end = offset.saturating_add(data.len() as u64);
    let base = at.saturating_add(first);
    let f = dxgi::lookup_vk(&img.format);
    let texel = f.map_or(0, |f| u64::from(f.bits_per_element / 8));
    let row_bytes = u64::from(width) * texel;
    let unplaced = |what: String| LinearWrite::Unplaced {
        format: img.format.clone(),
        what,
    };
    let why = if f.is_none() {
        Some("of a format framelab does not know".to_owned())
    } else if f.is_some_and(|f| f.block_width > 1) {
        Some("of compressed blocks".to_owned())
    } else if img.mips != 1 || img.layers != 1 || depth != 1 || img.samples > 1 {
        Some(format!(
            "of {} levels, {} layers, depth {depth} and {} samples",
            img.mips, img.layers, img.samples
        ))
    } else if texel == 0 || row_bytes == 0 || pitch < row_bytes || u32::try_from(pitch).is_err() {
        Some(format!(
            "with a row pitch of {pitch} bytes for rows of {row_bytes}"
        ))
    } else {
        None
    };
    if let Some(what) = why {
        // Every subresource at the first one's pitch, and the levels below it in as much again.
        let span = pitch
            .max(row_bytes)
            .saturating_mul(u64::from(rows.max(1)))
            .saturating_mul(u64::from(depth.max(1)) * u64::from(img.layers.max(1)))
            .saturating_mul(if img.mips > 1 { 2 } else { 1 });
        let reached = offset < base.saturating_add(span.max(1)) && end > base;
        return if reached {
            Err(unplaced(what))
        } else {
            Ok(Vec::new())
        };
    }
    let pitch32 = u32::try_from(pitch).unwrap_or(u32::MAX);
    let bytes = |from: u64, len: u64| {
        data[(from - offset) as usize..(from - offset + len) as usize].to_vec()
    };
    let mut out = Vec::new();
    let mut whole: Option<(u32, u32)> = None;
    for r in 0..rows {
        let start = base.saturating_add(u64::from(r) * pitch);
        let stop = start + row_bytes;
        let (from, to) = (offset.max(start), end.min(stop));
        if from >= to {
            continue;
        }
        if from == start && to == stop {
            whole = Some(whole.map_or((r, r + 1), |(a, _)| (a, r + 1)));
            continue;
        }
        if (from - start) % texel != 0 || (to - start) % texel != 0 {
            return Err(LinearWrite::InsideTexel {
                format: img.format.clone(),
                row: r,
                from: from - start,
                to: to - start,
            });
        }
        let x = ((from - start) / texel) as u32;
        out.push(ImageWrite {
            bytes: bytes(from, to - from),
            origin: [x, r, 0],
            extent: [((to - from) / texel) as u32, 1, 1],
            pitch: pitch32,
        });
    }
    if let Some((a, b)) = whole {
        let from = base + u64::from(a) * pitch;
        let len = u64::from(b - a - 1) * pitch + row_bytes;
        out.push(ImageWrite {
            bytes: bytes(from, len),
            origin: [0, a, 0],
            extent: [width, b - a, 1],
            pitch: pitch32,
        });
    }
    Ok(out)
}

impl Builder {
    /// A host write of `bytes` into `buffer` at `offset` during the imported frames: a copy
    /// pass from a buffer holding the bytes, on the queue of the latest pass.
    pub fn upload(&mut self, objects: &Objects, buffer: u64, offset: u64, bytes: Vec<u8>) {
        let Some(dst) = self.resource(objects, buffer) else {
            return;
        };
        let Some(pass) = self.host_pass(objects) else {
            return;
        };
        let name = self.host_source();
        let size = Some(bytes.len() as u64);
        let at = |resource: String, offset: u64| CopyLocation {
            resource,
            mip: 0,
            layer: 0,
            origin: [0; 3],
            offset,
            size,
            bytes_per_row: None,
        };
        self.passes[pass].copies.push(Copy {
            src: at(name.clone(), 0),
            dst: at(dst, offset),
            extent: None,
            host: true,
        });
        self.uploads.push((name, bytes));
    }

    /// A host write into the texels of linear `image` during the imported frames: a copy
    /// pass from a buffer holding each rectangle's bytes, rows as far apart as in the image.
    pub fn upload_image(&mut self, objects: &Objects, image: u64, writes: Vec<ImageWrite>) {
        let Some(dst) = self.resource(objects, image) else {
            return;
        };
        let Some(pass) = self.host_pass(objects) else {
            return;
        };
        for w in writes {
            let name = self.host_source();
            self.passes[pass].copies.push(Copy {
                src: CopyLocation {
                    resource: name.clone(),
                    mip: 0,
                    layer: 0,
                    origin: [0; 3],
                    offset: 0,
                    size: None,
                    bytes_per_row: Some(w.pitch),
                },
                dst: CopyLocation {
                    resource: dst.clone(),
                    mip: 0,
                    layer: 0,
                    origin: w.origin,
                    offset: 0,
                    size: None,
                    bytes_per_row: None,
                },
                extent: Some(w.extent),
                host: true,
            });
            self.uploads.push((name, w.bytes));
        }
    }

    /// The pass a host write becomes, on the queue of the latest pass; `None` where no queue
    /// was seen yet (noted) or no pass can be made.
    fn host_pass(&mut self, objects: &Objects) -> Option<usize> {
        let Some(queue) = self
            .last_queue
            .or_else(|| self.queue_names.keys().next().copied())
        else {
            self.note("host writes before any queue was seen: not imported");
            return None;
        };
        // Barriers and waits recorded for the queue belong to its next GPU pass, not to this.
        let barriers = self.pending_barriers.remove(&queue);
        let waits = self.pending_waits.remove(&queue);
        let pass = self.new_pass(objects, queue, PassKind::Copy, "host_write");
        if let Some(b) = barriers {
            self.pending_barriers.insert(queue, b);
        }
        if let Some(w) = waits {
            self.pending_waits.insert(queue, w);
        }
        pass
    }

    /// A fresh name for a buffer holding host-written bytes.
    fn host_source(&mut self) -> String {
        let mut k = self.uploads.len();
        let mut name = format!("host_write_{k}");
        while !self.taken.insert(name.clone()) {
            k += 1;
            name = format!("host_write_{k}");
        }
        name
    }

    /// Drops the host writes after the imported frames' last GPU work. Nothing the import
    /// holds reads them, and a read-back through a mapping looks the same in a capture (the
    /// capture layer records the mapped memory when it is unmapped): kept, they would stand
    /// as the last writers of the results the CPU reads and hide the work that made them.
    pub fn drop_trailing_host_writes(&mut self) {
        let mut dropped = 0;
        while let Some(p) = self.passes.last() {
            if p.kind != PassKind::Copy || p.copies.is_empty() || !p.copies.iter().all(|c| c.host) {
                break;
            }
            let Some(p) = self.passes.pop() else { break };
            for c in &p.copies {
                self.uploads.retain(|(name, _)| *name != c.src.resource);
                self.taken.remove(&c.src.resource);
            }
            self.pass_names.remove(&p.name);
            dropped += 1;
        }
        let passes = self.passes.len();
        self.last_pass_on.retain(|_, p| *p < passes);
        for _ in 0..dropped {
            self.note("host writes after the frames' last GPU work: left out (nothing in them reads the bytes; a read-back through a mapping is captured the same way)");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4x3 RGBA8 linear image bound at 100, its first texel 16 bytes in, rows 32 apart.
    fn image() -> ImageInfo {
        let mut img =
            crate::import::contents::tests::image("VK_FORMAT_R8G8B8A8_UNORM", [4, 3, 1], 1, 1);
        img.bound = Some((7, 100));
        img
    }

    #[test]
    fn a_write_over_whole_rows_is_one_rectangle_at_the_pitch() {
        // From the image's first texel to the end of its last row: 2 x 32 + 16 bytes.
        let data: Vec<u8> = (0..80u8).collect();
        let w = image_writes(&image(), (32, 16), 116, &data).unwrap();
        assert_eq!(w.len(), 1);
        assert_eq!(
            (w[0].origin, w[0].extent, w[0].pitch),
            ([0, 0, 0], [4, 3, 1], 32)
        );
        assert_eq!(w[0].bytes, data);
    }

    #[test]
    fn rows_reached_in_part_are_rectangles_of_their_own() {
        // Bytes 124..160: texels 2-3 of row 0 (124..132), and row 1 whole (148..164) but for
        // its last texel, which the write stops before.
        let data = vec![9u8; 36];
        let w = image_writes(&image(), (32, 16), 124, &data).unwrap();
        let rects: Vec<([u32; 3], [u32; 3])> = w.iter().map(|w| (w.origin, w.extent)).collect();
        assert_eq!(rects, [([2, 0, 0], [2, 1, 1]), ([0, 1, 0], [3, 1, 1])]);
        // Writes that miss the texels (the padding between rows, or another binding) are none.
        assert!(
            image_writes(&image(), (32, 16), 132, &[1u8; 16])
                .unwrap()
                .is_empty()
        );
        assert!(
            image_writes(&image(), (32, 16), 0, &[1u8; 100])
                .unwrap()
                .is_empty()
        );
    }

    /// A linear image the pitch alone does not lay out (two layers, compressed blocks) is
    /// refused where a write reaches it, never left as it was; a write elsewhere is no matter.
    #[test]
    fn a_write_into_a_linear_image_the_pitch_does_not_place_is_refused() {
        let mut layers = image();
        layers.layers = 2;
        let why = image_writes(&layers, (32, 16), 116, &[0u8; 16])
            .unwrap_err()
            .to_string();
        assert!(why.contains("2 layers"), "{why}");
        // Past both layers at that pitch (2 x 3 rows of 32 bytes from 116).
        assert!(
            image_writes(&layers, (32, 16), 400, &[0u8; 16])
                .unwrap()
                .is_empty()
        );
        let mut blocks = image();
        blocks.format = "VK_FORMAT_BC1_RGB_UNORM_BLOCK".to_owned();
        let why = image_writes(&blocks, (32, 16), 116, &[0u8; 8])
            .unwrap_err()
            .to_string();
        assert!(why.contains("compressed blocks"), "{why}");
    }

    #[test]
    fn a_write_that_ends_inside_a_texel_is_refused() {
        let why = image_writes(&image(), (32, 16), 118, &[0u8; 6])
            .unwrap_err()
            .to_string();
        assert!(why.contains("ends inside a texel"), "{why}");
    }
}
