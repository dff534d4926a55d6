//! Copies from a buffer into a texture held as RGBA8 for a 16-bit packed format
//! (`framelab_core::lower::packed16`), which wgpu cannot copy, drawn: one triangle over the
//! destination mip and layer, cut to the copied region by the scissor, whose fragments read
//! their texel's 16-bit word from the buffer (bound as storage, from the region's first word)
//! and widen each channel from its bits; a channel the format lacks reads 1.

use framelab_core::plan::{CopyEnd, CopyOp, Packed16};

use super::Session;

const SHADER: &str = "
struct U { offset: u32, pitch: u32, origin: vec2<u32>, shift: vec4<u32>, bits: vec4<u32> }
@group(0) @binding(0) var<storage, read> words: array<u32>;
@group(0) @binding(1) var<uniform> u: U;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}
@fragment fn unpack(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = vec2<u32>(p.xy) - u.origin;
    let at = u.offset + xy.y * u.pitch + xy.x * 2u;
    let word = (words[at >> 2u] >> ((at & 2u) * 8u)) & 0xffffu;
    let top = (vec4<u32>(1u) << u.bits) - vec4<u32>(1u);
    let v = (vec4<u32>(word) >> u.shift) & top;
    return select(vec4<f32>(v) / vec4<f32>(max(top, vec4<u32>(1u))), vec4<f32>(1.0), u.bits == vec4<u32>(0u));
}
";

/// The one pipeline unpacking copies draw with (their destination is always RGBA8).
#[derive(Default)]
pub(super) struct UnpackPipeline {
    pipeline: Option<wgpu::RenderPipeline>,
}

/// Where one layer of a copy reads and writes: the bound range of the buffer, the uniform's
/// words and the scissor.
struct Region {
    bind_offset: u64,
    bind_size: u64,
    words: [u32; 12],
    scissor: (u32, u32, u32, u32),
}

/// The regions of `c`, one per layer; none where the copy is empty.
fn regions(c: &CopyOp, layout: Packed16, buffer_size: u64) -> Vec<Region> {
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
    let pitch = u64::from(bytes_per_row.unwrap_or(w * 2));
    let image = pitch * u64::from(h);
    let mut out = Vec::new();
    for z in 0..u64::from(layers.max(1)) {
        let first = offset + z * image;
        // Storage bindings start at 256-byte multiples and span whole words.
        let bind_offset = first & !255;
        let end = (first + (u64::from(h) - 1) * pitch + u64::from(w) * 2).next_multiple_of(4);
        if end > buffer_size {
            continue;
        }
        let [s, b] = [0, 1].map(|i| {
            layout
                .fields
                .map(|f| u32::from(if i == 0 { f.0 } else { f.1 }))
        });
        out.push(Region {
            bind_offset,
            bind_size: end - bind_offset,
            words: [
                (first - bind_offset) as u32,
                pitch as u32,
                origin[0],
                origin[1],
                s[0],
                s[1],
                s[2],
                s[3],
                b[0],
                b[1],
                b[2],
                b[3],
            ],
            scissor: (origin[0], origin[1], w, h),
        });
    }
    out
}

impl Session {
    /// The unpacking pipeline, made on first use.
    pub(super) fn unpack_pipeline(&mut self) {
        if self.unpacks.pipeline.is_some() {
            return;
        }
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("unpack 16-bit texels"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
        let pipeline = super::pipelines::fullscreen_pipeline(
            &self.device,
            "unpack 16-bit texels",
            (&module, "unpack"),
            None,
            wgpu::TextureFormat::Rgba8Unorm,
        );
        self.unpacks.pipeline = Some(pipeline);
    }

    /// Draws copy `c` into its destination, each texel unpacked from the buffer in `layout`.
    pub(super) fn encode_unpack(
        &self,
        c: &CopyOp,
        layout: Packed16,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let (
            CopyEnd::Buffer { buffer, .. },
            CopyEnd::Texture {
                texture,
                mip,
                layer,
                ..
            },
        ) = (&c.src, &c.dst)
        else {
            return;
        };
        let Some(pipeline) = &self.unpacks.pipeline else {
            return;
        };
        let source = &self.buffers[*buffer][parity];
        for (z, r) in regions(c, layout, source.size()).into_iter().enumerate() {
            let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("unpack region"),
                size: std::mem::size_of_val(&r.words) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bytes: Vec<u8> = r.words.iter().flat_map(|w| w.to_le_bytes()).collect();
            self.queue.write_buffer(&uniform, 0, &bytes);
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("unpack 16-bit texels"),
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
            });
            let dst = self.view(*texture, parity, *mip, layer + z as u32, None);
            let mut rp = super::encode::one_target(
                encoder,
                "unpack 16-bit texels",
                &dst,
                wgpu::LoadOp::Load,
            );
            rp.set_pipeline(pipeline);
            rp.set_bind_group(0, &group, &[]);
            let (x, y, w, h) = r.scissor;
            rp.set_scissor_rect(x, y, w, h);
            rp.draw(0..3, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn copy(offset: u64, bytes_per_row: Option<u32>, extent: [u32; 3]) -> CopyOp {
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

    #[test]
    fn each_layer_binds_from_a_256_byte_multiple_and_reads_from_its_first_word() {
        let layout = Packed16 {
            fields: [(11, 5), (5, 6), (0, 5), (0, 0)],
        };
        let r = regions(&copy(300, Some(16), [4, 2, 2]), layout, 4096);
        assert_eq!(r.len(), 2);
        assert_eq!(
            (r[0].bind_offset, r[0].words[0], r[0].words[1]),
            (256, 44, 16)
        );
        // The second layer starts two rows of 16 bytes later.
        assert_eq!((r[1].bind_offset, r[1].words[0]), (256, 76));
        assert_eq!(r[0].bind_size, (300 + 16 + 8 - 256_u64).next_multiple_of(4));
        assert_eq!(r[0].scissor, (2, 3, 4, 2));
        assert_eq!(&r[0].words[4..], &[11, 5, 0, 0, 5, 6, 5, 0]);
        // Tightly packed rows without a pitch; a region past the buffer is left out.
        assert_eq!(
            regions(&copy(0, None, [8, 1, 1]), layout, 64)[0].words[1],
            16
        );
        assert!(regions(&copy(0, None, [8, 8, 1]), layout, 64).is_empty());
    }
}
