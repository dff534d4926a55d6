//! Block-compressed textures read back through the adapter's own decoder: a compute pass
//! loads every texel of each mip and layer and stores it, decoded, into an uncompressed
//! texture that the ordinary read-back then copies out. The images are exactly what the
//! replay's shaders sampled (a CPU decoder could differ from the driver's in BC6H/BC7 corner
//! cases), and no decoder is linked into framelab for it.

use framelab_core::plan::TextureSpec;

/// The uncompressed format a BC format is read back in: 8-bit UNORM for the unsigned LDR
/// formats (sRGB ones re-encoded, so the bytes are the texture's own), 32-bit float for HDR
/// (BC6H) and signed ones.
pub fn decompressed_format(format: wgpu::TextureFormat) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat as F;
    match format {
        F::Bc6hRgbUfloat | F::Bc6hRgbFloat | F::Bc4RSnorm | F::Bc5RgSnorm => Some(F::Rgba32Float),
        F::Bc1RgbaUnorm
        | F::Bc1RgbaUnormSrgb
        | F::Bc2RgbaUnorm
        | F::Bc2RgbaUnormSrgb
        | F::Bc3RgbaUnorm
        | F::Bc3RgbaUnormSrgb
        | F::Bc4RUnorm
        | F::Bc5RgUnorm
        | F::Bc7RgbaUnorm
        | F::Bc7RgbaUnormSrgb => Some(F::Rgba8Unorm),
        _ => None,
    }
}

fn shader(store: &str, srgb: bool) -> String {
    // textureLoad returns linear values for an sRGB view; encoding them again gives back the
    // texture's own bytes in the 8-bit target.
    let encode = if srgb {
        "c = vec4<f32>(select(1.055 * pow(c.rgb, vec3<f32>(1.0 / 2.4)) - 0.055, c.rgb * 12.92, c.rgb <= vec3<f32>(0.0031308)), c.a);"
    } else {
        ""
    };
    format!(
        "@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<{store}, write>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let size = textureDimensions(dst);
    if (id.x >= size.x || id.y >= size.y) {{ return; }}
    var c = textureLoad(src, id.xy, 0);
    {encode}
    textureStore(dst, id.xy, c);
}}"
    )
}

/// Why a block-compressed texture cannot be decoded on the GPU.
#[derive(Debug, thiserror::Error)]
pub enum DecompressError {
    #[error("block-compressed textures are 2D")]
    NotTwoDimensional,
    #[error("the replay never samples it, so it cannot be decoded on the GPU")]
    NeverSampled,
}

/// Decodes every mip and layer of the 2D (array or cube) BC texture into a new texture of
/// `target` format (from [`decompressed_format`]) and returns it with its spec.
pub fn decompress(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    target: wgpu::TextureFormat,
) -> Result<(wgpu::Texture, TextureSpec), DecompressError> {
    if spec.dimension != wgpu::TextureDimension::D2 {
        return Err(DecompressError::NotTwoDimensional);
    }
    if !spec.usage.contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(DecompressError::NeverSampled);
    }
    let store = if target == wgpu::TextureFormat::Rgba32Float {
        "rgba32float"
    } else {
        "rgba8unorm"
    };
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("bc decode"),
        source: wgpu::ShaderSource::Wgsl(shader(store, spec.format.is_srgb()).into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("bc decode"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let out_spec = TextureSpec {
        name: spec.name.clone(),
        format: target,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        initial: None,
        history: false,
        view_formats: Vec::new(),
        ..spec.clone()
    };
    let out = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bc decoded"),
        size: spec.size,
        mip_level_count: spec.mip_levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: target,
        usage: out_spec.usage,
        view_formats: &[],
    });
    let layout = pipeline.get_bind_group_layout(0);
    let mut encoder = device.create_command_encoder(&Default::default());
    for mip in 0..spec.mip_levels {
        let (w, h) = (
            (spec.size.width >> mip).max(1),
            (spec.size.height >> mip).max(1),
        );
        for layer in 0..spec.size.depth_or_array_layers {
            let view = |t: &wgpu::Texture| {
                t.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_mip_level: mip,
                    mip_level_count: Some(1),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            };
            let (src, dst) = (view(texture), view(&out));
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("bc decode"),
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&src),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&dst),
                    },
                ],
            });
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
    }
    queue.submit([encoder.finish()]);
    Ok((out, out_spec))
}
