//! Depth contents wgpu cannot copy in: WebGPU copies into no depth format but `Depth16Unorm`,
//! so an imported frame's depth snapshot is drawn instead. Each texel's depth is decoded on
//! the CPU into a float texture, and one draw a mip level and layer writes it as the
//! fragment's depth (`frag_depth`, every test passing), which stores the same value a copy
//! would: a float as it is, a 24-bit normalized depth as the float it stands for, which the
//! attachment rounds back to the same 24 bits.

use std::collections::HashMap;

use framelab_core::plan::TextureSpec;

const SHADER: &str = r"
@group(0) @binding(0) var depth: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(xy * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) at: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(depth, vec2<i32>(at.xy), 0).r;
}
";

/// Whether `spec`'s contents are drawn by [`draw`] rather than copied.
pub(super) fn drawn(spec: &TextureSpec) -> bool {
    spec.format.is_depth_stencil_format() && spec.format != wgpu::TextureFormat::Depth16Unorm
}

/// Each texel's depth in `data` (one mip level of `texels` texels, in the capture's layout
/// for `format`: a float, or 24 normalized bits in the low bits of a 32-bit word).
fn depths(format: wgpu::TextureFormat, data: &[u8], texels: usize) -> Vec<f32> {
    let stride = data.len() / texels.max(1);
    let word = |c: &[u8]| u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    data.chunks_exact(stride.max(4))
        .take(texels)
        .map(|c| match format {
            wgpu::TextureFormat::Depth32Float | wgpu::TextureFormat::Depth32FloatStencil8 => {
                f32::from_bits(word(c))
            }
            _ => (word(c) & 0x00ff_ffff) as f32 / 16_777_215.0,
        })
        .collect()
}

/// A pipeline drawing one triangle (`module`'s `vs`) whose fragments (`fs`) write only their
/// depth into a `format` attachment, every test passing.
pub(super) fn depth_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module,
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
    })
}

/// Pipelines that write depth from a fragment shader (`depth_pipeline`), one a depth format,
/// made on first use: the depth uploads' and the depth copies'.
pub(super) struct DepthPipelines {
    label: &'static str,
    shader: &'static str,
    made: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

impl DepthPipelines {
    pub(super) fn new(label: &'static str, shader: &'static str) -> DepthPipelines {
        DepthPipelines {
            label,
            shader,
            made: HashMap::new(),
        }
    }

    /// The pipeline writing `format`, made now if it was not.
    pub(super) fn make(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> &wgpu::RenderPipeline {
        let (label, shader) = (self.label, self.shader);
        self.made.entry(format).or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(shader.into()),
            });
            depth_pipeline(device, label, &module, format)
        })
    }

    /// The pipeline writing `format`, if it was made.
    pub(super) fn get(&self, format: wgpu::TextureFormat) -> Option<&wgpu::RenderPipeline> {
        self.made.get(&format)
    }
}

/// The upload pipelines, made while the textures are made.
pub(super) fn uploads() -> DepthPipelines {
    DepthPipelines::new("framelab depth upload", SHADER)
}

/// Writes `mips` (the capture's bytes, one entry a mip level, its layers one after another)
/// into depth texture `t` by drawing them.
pub(super) fn draw(
    pipelines: &mut DepthPipelines,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    t: &wgpu::Texture,
    spec: &TextureSpec,
    mips: &[Vec<u8>],
) {
    let pipeline = pipelines.make(device, spec.format);
    upload(device, queue, pipeline, t, spec, mips);
}

/// Draws `mips` into `t` with `pipeline`, a float copy of each level its source.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipeline: &wgpu::RenderPipeline,
    t: &wgpu::Texture,
    spec: &TextureSpec,
    mips: &[Vec<u8>],
) {
    let layers = spec.size.depth_or_array_layers.max(1);
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("framelab depth upload"),
    });
    let mut sources = Vec::new();
    for (mip, data) in mips.iter().enumerate().take(spec.mip_levels as usize) {
        let m = mip as u32;
        let (w, h) = (
            (spec.size.width >> m).max(1),
            (spec.size.height >> m).max(1),
        );
        let texels = (w * h * layers) as usize;
        let values = depths(spec.format, data, texels);
        let source = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("framelab depth upload source"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        queue.write_texture(
            source.as_image_copy(),
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: layers,
            },
        );
        for layer in 0..layers {
            layer_pass(device, &mut encoder, pipeline, (t, &source), (m, layer));
        }
        sources.push(source);
    }
    queue.submit([encoder.finish()]);
}

/// One draw writing layer `layer` of `source` into mip `mip`, layer `layer` of `t`.
fn layer_pass(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    (t, source): (&wgpu::Texture, &wgpu::Texture),
    (mip, layer): (u32, u32),
) {
    let one = |base_mip_level, mip_level_count| wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_mip_level,
        mip_level_count: Some(mip_level_count),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    };
    let read = source.create_view(&one(0, 1));
    let target = t.create_view(&one(mip, 1));
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("framelab depth upload"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&read),
        }],
    });
    let stencil = t.format().has_stencil_aspect();
    let mut pass = depth_pass(
        encoder,
        "framelab depth upload",
        &target,
        wgpu::LoadOp::Clear(0.0),
        stencil,
    );
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &group, &[]);
    pass.draw(0..3, 0..1);
}

/// A render pass over depth attachment `view` alone, its depth loaded by `load` and stored;
/// a stencil aspect (`stencil`) is cleared and stored, so that the pass is valid on it.
pub(super) fn depth_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<f32>,
    stencil: bool,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: stencil.then_some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0),
                store: wgpu::StoreOp::Store,
            }),
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 24-bit depths are the low bits of each word, normalized; floats are taken as they are.
    #[test]
    fn depths_are_decoded_as_the_format_lays_them_out() {
        let words: Vec<u8> = [0xff00_0000u32, 0x00ff_ffff, 0x0080_0000]
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect();
        let d24 = depths(wgpu::TextureFormat::Depth24PlusStencil8, &words, 3);
        assert_eq!(d24[0], 0.0);
        assert_eq!(d24[1], 1.0);
        assert!((d24[2] - 0.5).abs() < 1e-6);
        let floats: Vec<u8> = [0.25f32, 1.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            depths(wgpu::TextureFormat::Depth32Float, &floats, 2),
            [0.25, 1.0]
        );
    }
}
