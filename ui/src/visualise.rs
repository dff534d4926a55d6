//! The texture viewer's display pass, on the device that replays the frame: it reads one
//! subresource of a replayed texture and writes an `Rgba8Unorm` image, gamma-encoded as egui
//! expects, which is read back as pixels for the UI's renderer on its own device. One
//! pipeline per way of reading texels (float, depth, unsigned, signed; 2D or a 3D slice),
//! built when first needed.

use std::collections::BTreeMap;

use crate::model::Sampling;

const SHADER: &str = include_str!("visualise.wgsl");

/// The format of the displayed image.
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What the viewer's controls ask of the display.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controls {
    /// Channels shown, R G B A; exactly one shows as grey.
    pub channels: [bool; 4],
    pub black: f32,
    pub white: f32,
    /// Stops: values are multiplied by 2^exposure.
    pub exposure: f32,
    pub encode_srgb: bool,
    pub invert: bool,
    /// NaN magenta, infinity cyan, negative blue.
    pub overlay: bool,
    /// Stencil: the bits shown (a value is masked with them before black and white apply).
    pub stencil_bits: u32,
}

impl Default for Controls {
    fn default() -> Self {
        Controls {
            channels: [true, true, true, false],
            black: 0.0,
            white: 1.0,
            exposure: 0.0,
            encode_srgb: false,
            invert: false,
            overlay: false,
            stencil_bits: 0xff,
        }
    }
}

/// The subresource shown: a mip, and an array layer (or the slice of a 3D texture).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Subresource {
    pub mip: u32,
    pub layer: u32,
}

/// A pipeline per (sampling, volume).
#[derive(Debug, Default)]
pub struct Visualiser {
    pipelines: BTreeMap<(u8, bool), (wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
}

fn sampling_key(s: Sampling) -> u8 {
    match s {
        Sampling::Float => 0,
        Sampling::Depth => 1,
        Sampling::Uint => 2,
        Sampling::Sint => 3,
        Sampling::Stencil => 4,
    }
}

/// The WGSL for one way of reading texels.
fn source(sampling: Sampling, volume: bool) -> String {
    let (decl, load) = match (sampling, volume) {
        (Sampling::Float, false) => (
            "var src: texture_2d<f32>;",
            "textureLoad(src, p, 0)".to_owned(),
        ),
        (Sampling::Depth, _) => (
            "var src: texture_depth_2d;",
            "vec4<f32>(textureLoad(src, p, 0), 0.0, 0.0, 1.0)".to_owned(),
        ),
        (Sampling::Uint, false) => (
            "var src: texture_2d<u32>;",
            "vec4<f32>(textureLoad(src, p, 0))".to_owned(),
        ),
        (Sampling::Uint, true) => (
            "var src: texture_3d<u32>;",
            "vec4<f32>(textureLoad(src, vec3<i32>(p, i32(view.slice)), 0))".to_owned(),
        ),
        (Sampling::Sint, true) => (
            "var src: texture_3d<i32>;",
            "vec4<f32>(textureLoad(src, vec3<i32>(p, i32(view.slice)), 0))".to_owned(),
        ),
        (Sampling::Stencil, _) => (
            "var src: texture_2d<u32>;",
            "vec4<f32>(f32(textureLoad(src, p, 0).r & view.stencil_bits), 0.0, 0.0, 1.0)"
                .to_owned(),
        ),
        (Sampling::Sint, false) => (
            "var src: texture_2d<i32>;",
            "vec4<f32>(textureLoad(src, p, 0))".to_owned(),
        ),
        (Sampling::Float, true) => (
            "var src: texture_3d<f32>;",
            "textureLoad(src, vec3<i32>(p, i32(view.slice)), 0)".to_owned(),
        ),
    };
    SHADER
        .replace("SOURCE_DECL", &format!("@group(0) @binding(0) {decl}"))
        .replace("LOAD_EXPR", &load)
}

fn pack(c: &Controls, slice: u32, stride: u32) -> [u8; 48] {
    let mask = c.channels.map(|on| if on { 1.0f32 } else { 0.0 });
    let flags = u32::from(c.encode_srgb) | (u32::from(c.invert) << 1) | (u32::from(c.overlay) << 2);
    let mut out = [0u8; 48];
    let words: [u32; 12] = [
        mask[0].to_bits(),
        mask[1].to_bits(),
        mask[2].to_bits(),
        mask[3].to_bits(),
        c.black.to_bits(),
        c.white.to_bits(),
        c.exposure.to_bits(),
        flags,
        slice,
        c.stencil_bits,
        stride,
        0,
    ];
    for (i, w) in words.iter().enumerate() {
        out[i * 4..i * 4 + 4].copy_from_slice(&w.to_le_bytes());
    }
    out
}

impl Visualiser {
    fn pipeline(
        &mut self,
        device: &wgpu::Device,
        sampling: Sampling,
        volume: bool,
    ) -> &(wgpu::RenderPipeline, wgpu::BindGroupLayout) {
        // Depth and stencil textures are never 3D.
        let volume =
            volume && matches!(sampling, Sampling::Float | Sampling::Uint | Sampling::Sint);
        self.pipelines
            .entry((sampling_key(sampling), volume))
            .or_insert_with(|| {
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("framelab visualise"),
                    source: wgpu::ShaderSource::Wgsl(source(sampling, volume).into()),
                });
                let sample_type = match sampling {
                    Sampling::Float => wgpu::TextureSampleType::Float { filterable: false },
                    Sampling::Depth => wgpu::TextureSampleType::Depth,
                    Sampling::Uint | Sampling::Stencil => wgpu::TextureSampleType::Uint,
                    Sampling::Sint => wgpu::TextureSampleType::Sint,
                };
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("framelab visualise"),
                    entries: &[
                        wgpu::BindGroupLayoutEntry {
                            binding: 0,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Texture {
                                sample_type,
                                view_dimension: if volume {
                                    wgpu::TextureViewDimension::D3
                                } else {
                                    wgpu::TextureViewDimension::D2
                                },
                                multisampled: false,
                            },
                            count: None,
                        },
                        wgpu::BindGroupLayoutEntry {
                            binding: 1,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Buffer {
                                ty: wgpu::BufferBindingType::Uniform,
                                has_dynamic_offset: false,
                                min_binding_size: None,
                            },
                            count: None,
                        },
                    ],
                });
                let pipeline_layout =
                    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("framelab visualise"),
                        bind_group_layouts: &[Some(&layout)],
                        immediate_size: 0,
                    });
                let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("framelab visualise"),
                    layout: Some(&pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(DISPLAY_FORMAT.into())],
                    }),
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: None,
                    multisample: wgpu::MultisampleState::default(),
                    multiview_mask: None,
                    cache: None,
                });
                (pipeline, layout)
            })
    }

    /// Draws `sub` of `texture` into a new display image, one texel in `stride` along each
    /// axis (1: the subresource's size; more: a large texture drawn at the size it is seen, or
    /// a thumbnail), and returns it for `read_display`.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        (sampling, volume): (Sampling, bool),
        sub: Subresource,
        controls: &Controls,
        stride: u32,
    ) -> wgpu::Texture {
        let stride = stride.max(1);
        let mip = sub.mip.min(texture.mip_level_count().saturating_sub(1));
        let width = ((texture.width() >> mip).max(1)).div_ceil(stride);
        let height = ((texture.height() >> mip).max(1)).div_ceil(stride);
        let depth = if volume {
            (texture.depth_or_array_layers() >> mip).max(1)
        } else {
            1
        };
        let display = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("framelab display"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DISPLAY_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let aspect = match sampling {
            Sampling::Depth => wgpu::TextureAspect::DepthOnly,
            Sampling::Stencil => wgpu::TextureAspect::StencilOnly,
            _ => wgpu::TextureAspect::All,
        };
        let layers = texture.depth_or_array_layers();
        let source_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("framelab viewed subresource"),
            dimension: Some(if volume {
                wgpu::TextureViewDimension::D3
            } else {
                wgpu::TextureViewDimension::D2
            }),
            aspect,
            base_mip_level: mip,
            mip_level_count: Some(1),
            base_array_layer: if volume {
                0
            } else {
                sub.layer.min(layers.saturating_sub(1))
            },
            array_layer_count: Some(1),
            ..Default::default()
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("framelab view controls"),
            size: 48,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(
            &uniform,
            0,
            &pack(controls, sub.layer.min(depth - 1), stride),
        );
        let (pipeline, layout) = self.pipeline(device, sampling, volume);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("framelab visualise"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&source_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        let target = display.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("framelab visualise"),
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("framelab visualise"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        display
    }
}

/// Reads the display image `draw` made back as egui pixels (premultiplied, as the display pass
/// writes opaque or premultiplied values).
pub fn read_display(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    display: &wgpu::Texture,
) -> Result<egui::ColorImage, framelab_replay::ReadbackError> {
    let (width, height) = (display.width(), display.height());
    // Rows of a texture-to-buffer copy are padded to 256 bytes.
    let row = width * 4;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let size = u64::from(padded) * u64::from(height);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("framelab display read-back"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("framelab display read-back"),
    });
    encoder.copy_texture_to_buffer(
        display.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        display.size(),
    );
    queue.submit([encoder.finish()]);
    let bytes = framelab_replay::readback::map_read(device, &staging, size, "the display image")?;
    let pixels: Vec<u8> = bytes
        .chunks_exact(padded as usize)
        .flat_map(|r| &r[..row as usize])
        .copied()
        .collect();
    Ok(egui::ColorImage::from_rgba_premultiplied(
        [width as usize, height as usize],
        &pixels,
    ))
}
