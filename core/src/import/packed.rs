//! Where the texel blocks of a colour image lie in its packed contents (levels in order,
//! each level's layers and depth slices in order, rows tightly packed), and where those of
//! a copy's buffer footprint lie: the addressing every copy to, from and between images
//! carried out on imported contents shares.

use super::commands::Region;
use super::contents::MAX_BLOCK_BYTES;
use super::state::ImageInfo;
use crate::capture::dxgi::{self, FormatInfo};

/// A single-sample colour image as packed bytes.
pub(super) struct Packed {
    format: &'static FormatInfo,
    /// Block width and height in texels, bytes per block.
    pub bw: u64,
    pub bh: u64,
    pub bpb: u64,
    extent: [u32; 3],
    mips: u32,
    layers: u64,
}

/// A box of texels in one level: its first layer and origin, its extent and layer count.
#[derive(Clone, Copy, Debug)]
pub(super) struct TexelBox {
    pub mip: u32,
    pub layer: u32,
    pub origin: [u32; 3],
    pub extent: [u32; 3],
    pub layers: u32,
}

impl TexelBox {
    /// The image side of a copy region: its source's (`source`) or its destination's.
    /// `None` for a region without an extent (buffer to buffer).
    pub fn of(r: &Region, source: bool) -> Option<TexelBox> {
        let (mip, layer, origin) = if source {
            (r.src_mip, r.src_layer, r.src_origin)
        } else {
            (r.dst_mip, r.dst_layer, r.dst_origin)
        };
        Some(TexelBox {
            mip,
            layer,
            origin,
            extent: r.extent?,
            layers: r.layers,
        })
    }
}

impl Packed {
    /// `None` for formats whose contents the import cannot place: depth, stencil, planar or
    /// unknown ones, and multisampled images.
    pub fn of(img: &ImageInfo) -> Option<Packed> {
        let f = dxgi::lookup_vk(&img.format)?;
        let bpb = u64::from(f.bits_per_element) / 8;
        if f.depth_bits > 0 || f.stencil_bits > 0 || bpb == 0 || img.samples > 1 {
            return None;
        }
        // Every offset below lies inside the image, whose size is bounded here.
        let size = f.texture_bytes(
            (img.extent[0], img.extent[1], img.extent[2]),
            img.layers.max(1),
            img.mips.min(32),
            1,
        )?;
        if size > MAX_BLOCK_BYTES {
            return None;
        }
        Some(Packed {
            format: f,
            bw: u64::from(f.block_width.max(1)),
            bh: u64::from(f.block_height.max(1)),
            bpb,
            extent: img.extent,
            mips: img.mips,
            layers: u64::from(img.layers.max(1)),
        })
    }

    /// Whether blocks of the two can be copied one for one (`vkCmdCopyImage` between
    /// size-compatible formats).
    pub fn same_blocks(&self, other: &Packed) -> bool {
        (self.bw, self.bh, self.bpb) == (other.bw, other.bh, other.bpb)
    }

    fn dims(&self, mip: u32) -> [u64; 3] {
        self.extent.map(|d| u64::from((d >> mip).max(1)))
    }

    /// Bytes before level `mip`.
    fn level_at(&self, mip: u32) -> Option<u64> {
        let mut at = 0u64;
        for l in 0..mip {
            let [w, h, d] = self.dims(l);
            let bytes = self.format.texture_bytes(
                (w as u32, h as u32, d as u32),
                self.layers as u32,
                1,
                1,
            )?;
            at = at.checked_add(bytes)?;
        }
        Some(at)
    }

    /// Where the block rows of `b` lie (slices in order, rows in order within each);
    /// `None` when the box lies outside the image or does not start on a block.
    pub fn rows(&self, b: &TexelBox) -> Option<Rows> {
        if b.mip >= self.mips {
            return None;
        }
        let level_at = self.level_at(b.mip)?;
        let [lw, lh, ld] = self.dims(b.mip);
        let [x, y, z] = b.origin.map(u64::from);
        let [w, h, d] = b.extent.map(u64::from);
        let layers = u64::from(b.layers.max(1));
        if w == 0
            || h == 0
            || d == 0
            || x + w > lw
            || y + h > lh
            || z + d > ld
            || (layers > 1 && ld > 1)
            || u64::from(b.layer) + layers > self.layers
            || x % self.bw != 0
            || y % self.bh != 0
        {
            return None;
        }
        let row = lw.div_ceil(self.bw) * self.bpb;
        Some(Rows {
            start: level_at
                + (u64::from(b.layer) * ld + z) * row * lh.div_ceil(self.bh)
                + y / self.bh * row
                + x / self.bw * self.bpb,
            per_slice: h.div_ceil(self.bh),
            row,
            slice: row * lh.div_ceil(self.bh),
            count: layers * d * h.div_ceil(self.bh),
            run: w.div_ceil(self.bw) * self.bpb,
        })
    }

    /// Where the block rows of `b` lie in a buffer laid out as a copy's region says
    /// (`bufferRowLength` and `bufferImageHeight` in texels, 0 for tightly packed), from the
    /// region's buffer offset, in the order `rows` gives; `Rows::span` is the bytes it spans.
    pub fn footprint(&self, b: &TexelBox, row_texels: u32, image_rows: u32) -> Rows {
        let [w, h, d] = b.extent.map(u64::from);
        let row_texels = if row_texels == 0 {
            w
        } else {
            u64::from(row_texels)
        };
        let image_rows = if image_rows == 0 {
            h
        } else {
            u64::from(image_rows)
        };
        // Saturating: a footprint past any buffer is refused by its span.
        let row = row_texels.div_ceil(self.bw).saturating_mul(self.bpb);
        let per_slice = h.div_ceil(self.bh);
        Rows {
            start: 0,
            per_slice,
            row,
            slice: row.saturating_mul(image_rows.div_ceil(self.bh)),
            count: u64::from(b.layers.max(1))
                .saturating_mul(d)
                .saturating_mul(per_slice),
            run: w.div_ceil(self.bw).saturating_mul(self.bpb),
        }
    }
}

/// Block rows of a box: `count` runs of `run` bytes, `per_slice` of them `row` bytes apart
/// in each slice, slices `slice` bytes apart. A box's layers and depth slices follow each
/// other in both the packed image and a buffer footprint, so one stride covers both.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rows {
    start: u64,
    per_slice: u64,
    row: u64,
    slice: u64,
    pub count: u64,
    pub run: u64,
}

impl Rows {
    /// The byte range of row `i`.
    pub fn at(&self, i: u64) -> std::ops::Range<usize> {
        let per_slice = self.per_slice.max(1);
        let from = self.start + i / per_slice * self.slice + i % per_slice * self.row;
        from as usize..(from + self.run) as usize
    }

    /// Bytes from the first row's start to the end of the last slice.
    pub fn span(&self) -> u64 {
        self.count
            .div_ceil(self.per_slice.max(1))
            .saturating_mul(self.slice)
    }
}
