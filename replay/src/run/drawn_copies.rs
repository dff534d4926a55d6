//! What the copies the replay draws instead of copying share (16-bit packed texels in
//! `unpack`, depth in `depth_copy`): the buffer range each layer of a copy reads as storage
//! and where it lands, and the bind group that hands a fragment shader that range and the
//! region's words.

use framelab_core::plan::{CopyEnd, CopyOp};

use super::Session;

/// Where one layer of a drawn copy reads and writes.
#[derive(Debug, PartialEq)]
pub(super) struct Region {
    /// The bound range of the buffer: from a 256-byte multiple, whole words.
    pub bind_offset: u64,
    pub bind_size: u64,
    /// The layer's first byte within the bound range.
    pub first: u32,
    /// Bytes from one row to the next.
    pub pitch: u32,
    /// The destination's origin, and the scissor the draw is cut to.
    pub scissor: (u32, u32, u32, u32),
}

/// The ends of a copy from a buffer into a texture: (buffer, texture, mip, first layer).
pub(super) fn buffer_into_texture(c: &CopyOp) -> Option<(usize, usize, u32, u32)> {
    match (&c.src, &c.dst) {
        (
            CopyEnd::Buffer { buffer, .. },
            CopyEnd::Texture {
                texture,
                mip,
                layer,
                ..
            },
        ) => Some((*buffer, *texture, *mip, *layer)),
        _ => None,
    }
}

/// The regions of `c` (texels of `texel_bytes` in the buffer), one per layer; none where the
/// copy is empty, and none for a layer that runs past the buffer.
pub(super) fn regions(c: &CopyOp, texel_bytes: u32, buffer_size: u64) -> Vec<Region> {
    let (
        CopyEnd::Buffer {
            offset,
            bytes_per_row,
            ..
        },
        CopyEnd::Texture { origin, .. },
    ) = (&c.src, &c.dst)
    else {
        return Vec::new();
    };
    let [w, h, layers] = c.extent;
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let pitch = u64::from(bytes_per_row.unwrap_or(w * texel_bytes));
    let image = pitch * u64::from(h);
    let mut out = Vec::new();
    for z in 0..u64::from(layers.max(1)) {
        let first = offset + z * image;
        // Storage bindings start at 256-byte multiples and span whole words.
        let bind_offset = first & !255;
        let end =
            (first + (u64::from(h) - 1) * pitch + u64::from(w * texel_bytes)).next_multiple_of(4);
        if end > buffer_size {
            continue;
        }
        out.push(Region {
            bind_offset,
            bind_size: end - bind_offset,
            first: (first - bind_offset) as u32,
            pitch: pitch as u32,
            scissor: (origin[0], origin[1], w, h),
        });
    }
    out
}

/// Draws region `r` with `pipeline` and its bind group `group`: one triangle over the
/// destination, cut to the region by the scissor.
pub(super) fn draw_region(
    rp: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
    r: &Region,
) {
    rp.set_pipeline(pipeline);
    rp.set_bind_group(0, group, &[]);
    let (x, y, w, h) = r.scissor;
    rp.set_scissor_rect(x, y, w, h);
    rp.draw(0..3, 0..1);
}

impl Session {
    /// The bind group of a drawn copy's region: the buffer range as storage (binding 0) and
    /// `words` as a uniform (binding 1).
    pub(super) fn storage_group(
        &self,
        pipeline: &wgpu::RenderPipeline,
        source: &wgpu::Buffer,
        r: &Region,
        words: &[u32],
    ) -> wgpu::BindGroup {
        let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("drawn copy region"),
            size: std::mem::size_of_val(words) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        self.queue.write_buffer(&uniform, 0, &bytes);
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("drawn copy"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: source,
                        offset: r.bind_offset,
                        size: std::num::NonZeroU64::new(r.bind_size),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniform.as_entire_binding(),
                },
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn copy(offset: u64, bytes_per_row: Option<u32>, extent: [u32; 3]) -> CopyOp {
        CopyOp {
            src: CopyEnd::Buffer {
                buffer: 0,
                offset,
                bytes_per_row,
            },
            dst: CopyEnd::Texture {
                texture: 0,
                mip: 0,
                layer: 0,
                origin: [2, 3, 0],
            },
            unpack: None,
            depth: false,
            extent,
            bytes: 0,
        }
    }

    /// Each layer binds from a 256-byte multiple and reads from its first byte, rows a pitch
    /// apart (the texels' own bytes without one); a region past the buffer is left out.
    #[test]
    fn each_layer_binds_from_a_256_byte_multiple_and_reads_from_its_first_byte() {
        let r = regions(&copy(300, Some(16), [4, 2, 2]), 2, 4096);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].bind_offset, r[0].first, r[0].pitch), (256, 44, 16));
        // The second layer starts two rows of 16 bytes later.
        assert_eq!((r[1].bind_offset, r[1].first), (256, 76));
        assert_eq!(r[0].bind_size, (300 + 16 + 8 - 256_u64).next_multiple_of(4));
        assert_eq!(r[0].scissor, (2, 3, 4, 2));
        assert_eq!(regions(&copy(0, None, [8, 1, 1]), 2, 64)[0].pitch, 16);
        assert_eq!(regions(&copy(0, None, [8, 1, 1]), 4, 64)[0].pitch, 32);
        assert!(regions(&copy(0, None, [8, 8, 1]), 2, 64).is_empty());
        let words = regions(&copy(300, Some(32), [4, 2, 2]), 4, 4096);
        assert_eq!(words[0].bind_size, 300 + 32 + 16 - 256);
        assert_eq!(words[1].first, 108);
    }
}
