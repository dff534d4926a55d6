//! Blits (Vulkan's `vkCmdBlitImage`), which wgpu has no command for, drawn: one triangle over the
//! destination mip, cut to the destination region by the scissor, whose fragments map their
//! texel centre linearly from the destination corners to the source corners (the
//! specification's formula, so swapped corners mirror) and read the source there: the texel
//! under the point, clamped to the edge, for nearest; a bilinear sample with clamp-to-edge for
//! linear. Sampling decodes sRGB and rendering encodes it, the conversions a blit makes.

use std::collections::BTreeMap;

use framelab_core::plan::BlitOp;

use super::Session;

const SHADER: &str = "
struct Map { s0: vec2<f32>, s1: vec2<f32>, d0: vec2<f32>, d1: vec2<f32>, size: vec2<f32>, pad: vec2<f32> }
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var<uniform> m: Map;
@group(0) @binding(2) var smp: sampler;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}
fn source(p: vec2<f32>) -> vec2<f32> { return m.s0 + (p - m.d0) * (m.s1 - m.s0) / (m.d1 - m.d0); }
@fragment fn nearest(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let hi = vec2<i32>(textureDimensions(src)) - vec2<i32>(1);
    return textureLoad(src, clamp(vec2<i32>(floor(source(p.xy))), vec2<i32>(0), hi), 0);
}
@fragment fn linear(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return textureSampleLevel(src, smp, source(p.xy) / m.size, 0.0);
}
";

/// The pipelines blits draw with, by destination format and filter, and the one sampler.
#[derive(Default)]
pub(super) struct BlitPipelines {
    pipelines: BTreeMap<(String, bool), wgpu::RenderPipeline>,
    layouts: Option<[wgpu::BindGroupLayout; 2]>,
    module: Option<wgpu::ShaderModule>,
    sampler: Option<wgpu::Sampler>,
}

/// One prepared blit: its mapping constants.
pub(super) struct PreparedBlit {
    uniform: wgpu::Buffer,
}

/// The mapping's constants, in the shader's `Map` layout.
fn constants(b: &BlitOp, src_size: (u32, u32)) -> [f32; 12] {
    let c = |xy: [u32; 2]| [xy[0] as f32, xy[1] as f32];
    let [s0, s1] = b.src_corners.map(c);
    let [d0, d1] = b.dst_corners.map(c);
    [
        s0[0],
        s0[1],
        s1[0],
        s1[1],
        d0[0],
        d0[1],
        d1[0],
        d1[1],
        src_size.0 as f32,
        src_size.1 as f32,
        0.0,
        0.0,
    ]
}

/// The destination region as a scissor (x, y, width, height); `None` when it is empty.
fn scissor(b: &BlitOp) -> Option<(u32, u32, u32, u32)> {
    let [a, z] = b.dst_corners;
    let (x0, x1) = (a[0].min(z[0]), a[0].max(z[0]));
    let (y0, y1) = (a[1].min(z[1]), a[1].max(z[1]));
    let [sa, sz] = b.src_corners;
    let source_empty = sa[0] == sz[0] || sa[1] == sz[1];
    (x1 > x0 && y1 > y0 && !source_empty).then_some((x0, y0, x1 - x0, y1 - y0))
}

impl Session {
    /// The pipeline for `format` and filter, made on first use.
    pub(super) fn blit_pipeline(&mut self, format: wgpu::TextureFormat, linear: bool) {
        let key = (format!("{format:?}"), linear);
        if self.blits.pipelines.contains_key(&key) {
            return;
        }
        let device = &self.device;
        let module = self.blits.module.get_or_insert_with(|| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("blit"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            })
        });
        let layouts = self.blits.layouts.get_or_insert_with(|| {
            let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty,
                count: None,
            };
            let texture = |filterable| wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            };
            let uniform = wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            };
            let make = |entries: &[wgpu::BindGroupLayoutEntry]| {
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("blit"),
                    entries,
                })
            };
            [
                make(&[entry(0, texture(false)), entry(1, uniform)]),
                make(&[
                    entry(0, texture(true)),
                    entry(1, uniform),
                    entry(
                        2,
                        wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    ),
                ]),
            ]
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("blit"),
            bind_group_layouts: &[Some(&layouts[usize::from(linear)])],
            immediate_size: 0,
        });
        let pipeline = super::pipelines::fullscreen_pipeline(
            device,
            "blit",
            (module, if linear { "linear" } else { "nearest" }),
            Some(&layout),
            format,
        );
        self.blits.pipelines.insert(key, pipeline);
        if linear && self.blits.sampler.is_none() {
            self.blits.sampler = Some(device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("blit"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }));
        }
    }

    /// Pipelines and constants of a blit pass.
    pub(super) fn prepare_blits(&mut self, blits: &[BlitOp]) -> Vec<PreparedBlit> {
        let mut out = Vec::with_capacity(blits.len());
        for b in blits {
            self.blit_pipeline(self.plan.textures[b.dst].format, b.linear);
            let size = self.plan.textures[b.src].size;
            let mip = |n: u32| (n >> b.src_mip).max(1);
            let words = constants(b, (mip(size.width), mip(size.height)));
            let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("blit mapping"),
                size: std::mem::size_of_val(&words) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
            self.queue.write_buffer(&uniform, 0, &bytes);
            out.push(PreparedBlit { uniform });
        }
        out
    }

    /// Draws each blit into its destination, keeping what lies outside the region.
    pub(super) fn encode_blits(
        &self,
        name: &str,
        blits: &[BlitOp],
        prepared: &[PreparedBlit],
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), super::encode::EncodeError> {
        for (b, p) in blits.iter().zip(prepared) {
            let Some((x, y, w, h)) = scissor(b) else {
                continue;
            };
            let format = self.plan.textures[b.dst].format;
            let pipeline = self
                .blits
                .pipelines
                .get(&(format!("{format:?}"), b.linear))
                .ok_or_else(|| {
                    super::encode::EncodeError::NoPipeline(format!("blit {format:?}"))
                })?;
            let src = self.view(b.src, parity, b.src_mip, b.src_layer, None);
            let dst = self.view(b.dst, parity, b.dst_mip, b.dst_layer, None);
            let mut entries = vec![
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&src),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: p.uniform.as_entire_binding(),
                },
            ];
            if b.linear {
                let sampler = self.blits.sampler.as_ref().ok_or_else(|| {
                    super::encode::EncodeError::NoPipeline("blit sampler".to_owned())
                })?;
                entries.push(wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(sampler),
                });
            }
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(name),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let mut rp = super::encode::one_target(encoder, name, &dst, wgpu::LoadOp::Load);
            rp.set_pipeline(pipeline);
            rp.set_bind_group(0, &group, &[]);
            rp.set_scissor_rect(x, y, w, h);
            rp.draw(0..3, 0..1);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn op(src: [[u32; 2]; 2], dst: [[u32; 2]; 2]) -> BlitOp {
        BlitOp {
            src: 0,
            src_mip: 0,
            src_layer: 0,
            src_corners: src,
            dst: 1,
            dst_mip: 0,
            dst_layer: 0,
            dst_corners: dst,
            linear: false,
        }
    }

    #[test]
    fn the_scissor_is_the_destination_region_in_either_corner_order() {
        assert_eq!(
            scissor(&op([[0, 0], [4, 4]], [[2, 6], [10, 1]])),
            Some((2, 1, 8, 5))
        );
        assert_eq!(scissor(&op([[0, 0], [4, 4]], [[3, 3], [3, 9]])), None);
        assert_eq!(scissor(&op([[2, 0], [2, 4]], [[0, 0], [8, 8]])), None);
    }

    #[test]
    fn the_constants_keep_the_corner_order() {
        let words = constants(&op([[4, 0], [0, 2]], [[0, 0], [8, 4]]), (4, 2));
        assert_eq!(
            &words[..10],
            &[4.0, 0.0, 0.0, 2.0, 0.0, 0.0, 8.0, 4.0, 4.0, 2.0]
        );
    }
}
