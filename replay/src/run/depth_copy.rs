//! Copies from a buffer into a depth texture without stencil that WebGPU copies no buffer into
//! (`Depth32Float`, `Depth24Plus`), drawn: one triangle over the destination mip and layer, cut
//! to the copied region by the scissor, whose fragments read their texel's word from the
//! buffer (bound as storage, from the region's first word) and write it as their depth, every
//! test passing: a float as it is, 24 normalized bits as the float they stand for.

use std::collections::BTreeMap;

use framelab_core::plan::{CopyEnd, CopyOp};

use super::Session;

const SHADER: &str = "
struct U { offset: u32, pitch: u32, origin: vec2<u32>, float_words: u32, pad0: u32, pad1: u32, pad2: u32 }
@group(0) @binding(0) var<storage, read> words: array<u32>;
@group(0) @binding(1) var<uniform> u: U;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    let xy = vec2<u32>(p.xy) - u.origin;
    let w = words[(u.offset + xy.y * u.pitch + xy.x * 4u) >> 2u];
    if u.float_words == 1u {
        return bitcast<f32>(w);
    }
    return f32(w & 0xffffffu) / 16777215.0;
}
";

/// The pipelines depth copies draw with, one a depth format, made before the first frame.
#[derive(Default)]
pub(super) struct DepthCopyPipelines {
    pipelines: BTreeMap<String, wgpu::RenderPipeline>,
}

/// Where one layer of a copy reads and writes: the bound range of the buffer, the uniform's
/// words and the scissor.
#[derive(Debug, PartialEq)]
struct Region {
    bind_offset: u64,
    bind_size: u64,
    words: [u32; 8],
    scissor: (u32, u32, u32, u32),
}

/// The regions of `c`, one per layer, each texel a 4-byte word; none where the copy is empty
/// or runs past the buffer.
fn regions(c: &CopyOp, float_words: bool, buffer_size: u64) -> Vec<Region> {
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
    let pitch = u64::from(bytes_per_row.unwrap_or(w * 4));
    let image = pitch * u64::from(h);
    let mut out = Vec::new();
    for z in 0..u64::from(layers.max(1)) {
        let first = offset + z * image;
        // Storage bindings start at 256-byte multiples and span whole words.
        let bind_offset = first & !255;
        let end = first + (u64::from(h) - 1) * pitch + u64::from(w) * 4;
        if end > buffer_size {
            continue;
        }
        out.push(Region {
            bind_offset,
            bind_size: end - bind_offset,
            words: [
                (first - bind_offset) as u32,
                pitch as u32,
                origin[0],
                origin[1],
                u32::from(float_words),
                0,
                0,
                0,
            ],
            scissor: (origin[0], origin[1], w, h),
        });
    }
    out
}

impl Session {
    /// The depth copy pipeline for `format`, made on first use.
    pub(super) fn depth_copy_pipeline(&mut self, format: wgpu::TextureFormat) {
        let key = format!("{format:?}");
        if self.depth_copies.pipelines.contains_key(&key) {
            return;
        }
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("depth copy"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
        let pipeline = self
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("depth copy"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Always),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                multiview_mask: None,
                cache: None,
            });
        self.depth_copies.pipelines.insert(key, pipeline);
    }

    /// Draws copy `c` into its depth destination, each texel's depth read from the buffer.
    pub(super) fn encode_depth_copy(
        &self,
        c: &CopyOp,
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
        let format = self.plan.textures[*texture].format;
        let Some(pipeline) = self.depth_copies.pipelines.get(&format!("{format:?}")) else {
            return;
        };
        let float_words = format == wgpu::TextureFormat::Depth32Float;
        let source = &self.buffers[*buffer][parity];
        for (z, r) in regions(c, float_words, source.size())
            .into_iter()
            .enumerate()
        {
            let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("depth copy region"),
                size: std::mem::size_of_val(&r.words) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bytes: Vec<u8> = r.words.iter().flat_map(|w| w.to_le_bytes()).collect();
            self.queue.write_buffer(&uniform, 0, &bytes);
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("depth copy"),
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
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("depth copy"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &dst,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
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
            depth: true,
            extent,
            bytes: 0,
        }
    }

    /// Each layer binds from a 256-byte multiple and reads from its first word, rows a pitch
    /// apart (4 bytes a texel without one); a region past the buffer is left out.
    #[test]
    fn each_layer_reads_its_words_from_where_the_copy_says() {
        let r = regions(&copy(300, Some(32), [4, 2, 2]), true, 4096);
        assert_eq!(r.len(), 2);
        assert_eq!(
            (
                r[0].bind_offset,
                r[0].words[0],
                r[0].words[1],
                r[0].words[4]
            ),
            (256, 44, 32, 1)
        );
        assert_eq!((r[1].bind_offset, r[1].words[0]), (256, 108));
        assert_eq!(r[0].bind_size, 300 + 32 + 16 - 256);
        assert_eq!(r[0].scissor, (2, 3, 4, 2));
        assert_eq!(
            regions(&copy(0, None, [8, 1, 1]), false, 64)[0].words[1],
            32
        );
        assert!(regions(&copy(0, None, [8, 8, 1]), false, 64).is_empty());
    }
}
