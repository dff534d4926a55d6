//! Creating a plan's GPU objects: textures and buffers (two copies for history resources)
//! with their initial contents, samplers, mesh buffers, shader modules and timestamp queries.

use framelab_core::plan::{Plan, TextureSpec};
use framelab_core::uniforms;

use super::{GpuMesh, Module, ReplayError, Scopes, close, scope};
/// Uploads every mip's contents.
pub(super) fn write_texture(
    queue: &wgpu::Queue,
    t: &wgpu::Texture,
    spec: &TextureSpec,
    mips: &[Vec<u8>],
) {
    let (bw, bh) = spec.format.block_dimensions();
    let block_bytes = spec
        .format
        .block_copy_size(Some(wgpu::TextureAspect::All))
        .unwrap_or(4);
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    for (mip, data) in mips.iter().enumerate().take(spec.mip_levels as usize) {
        let m = mip as u32;
        let (w, h) = (
            (spec.size.width >> m).max(1),
            (spec.size.height >> m).max(1),
        );
        let d = if d3 {
            (spec.size.depth_or_array_layers >> m).max(1)
        } else {
            spec.size.depth_or_array_layers
        };
        // Block-compressed mips are padded to whole blocks.
        let (pw, ph) = (w.div_ceil(bw) * bw, h.div_ceil(bh) * bh);
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: t,
                mip_level: m,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w.div_ceil(bw) * block_bytes),
                rows_per_image: Some(h.div_ceil(bh)),
            },
            wgpu::Extent3d {
                width: pw,
                height: ph,
                depth_or_array_layers: d,
            },
        );
    }
}

pub(super) fn extent(e: [u32; 3]) -> wgpu::Extent3d {
    wgpu::Extent3d {
        width: e[0].max(1),
        height: e[1].max(1),
        depth_or_array_layers: e[2].max(1),
    }
}

pub(super) fn texel<'a>(
    t: &'a wgpu::Texture,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
    origin: [u32; 3],
) -> wgpu::TexelCopyTextureInfo<'a> {
    let z = if spec.dimension == wgpu::TextureDimension::D3 {
        origin[2]
    } else {
        layer
    };
    wgpu::TexelCopyTextureInfo {
        texture: t,
        mip_level: mip,
        origin: wgpu::Origin3d {
            x: origin[0],
            y: origin[1],
            z,
        },
        aspect: wgpu::TextureAspect::All,
    }
}

/// Turns what an error scope caught while creating `what` into an error.
pub(super) fn setup(what: &str, guards: Scopes) -> Result<(), ReplayError> {
    match close(guards) {
        Some(message) => Err(ReplayError::Setup {
            what: what.to_owned(),
            message,
        }),
        None => Ok(()),
    }
}

/// Every texture of the plan, twice for history textures, with its initial contents.
pub(super) fn textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
) -> Result<Vec<[wgpu::Texture; 2]>, ReplayError> {
    let mut textures = Vec::new();
    let mut depth = super::depth_upload::uploads();
    for t in &plan.textures {
        let g = scope(device);
        let make = |suffix: &str| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(&format!("{}{suffix}", t.name)),
                size: t.size,
                mip_level_count: t.mip_levels,
                sample_count: t.samples,
                dimension: t.dimension,
                format: t.format,
                usage: t.usage,
                view_formats: &t.view_formats,
            })
        };
        let a = make("");
        let b = if t.history {
            make(" (previous frame)")
        } else {
            a.clone()
        };
        if let Some(data) = &t.initial {
            for tex in if t.history { vec![&a, &b] } else { vec![&a] } {
                if super::depth_upload::drawn(t) {
                    super::depth_upload::draw(&mut depth, device, queue, tex, t, data);
                } else {
                    write_texture(queue, tex, t, data);
                }
            }
        }
        setup(&format!("texture \"{}\"", t.name), g)?;
        textures.push([a, b]);
    }
    Ok(textures)
}

/// Every buffer of the plan, twice for history buffers, padded to 4 bytes.
pub(super) fn buffers(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
) -> Result<Vec<[wgpu::Buffer; 2]>, ReplayError> {
    let mut buffers = Vec::new();
    for b in &plan.buffers {
        let g = scope(device);
        let size = b.size.div_ceil(4) * 4;
        let make = |suffix: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{}{suffix}", b.name)),
                size,
                usage: b.usage,
                mapped_at_creation: false,
            })
        };
        let x = make("");
        let y = if b.history {
            make(" (previous frame)")
        } else {
            x.clone()
        };
        if let Some(data) = &b.initial {
            let mut padded = data.clone();
            padded.resize(size as usize, 0);
            queue.write_buffer(&x, 0, &padded);
            if b.history {
                queue.write_buffer(&y, 0, &padded);
            }
        }
        setup(&format!("buffer \"{}\"", b.name), g)?;
        buffers.push([x, y]);
    }
    Ok(buffers)
}

/// Every sampler of the plan; one that clamps to a border colour on an adapter without
/// wgpu's `ADDRESS_MODE_CLAMP_TO_BORDER` is refused by name before anything is created.
pub(super) fn samplers(
    device: &wgpu::Device,
    plan: &Plan,
) -> Result<Vec<wgpu::Sampler>, ReplayError> {
    let border = wgpu::Features::ADDRESS_MODE_CLAMP_TO_BORDER;
    if let Some(s) = plan.samplers.iter().find(|s| s.border.is_some())
        && !device.features().contains(border)
    {
        return Err(ReplayError::Setup {
            what: format!("sampler \"{}\"", s.name),
            message: "it clamps to a border colour, and this adapter lacks wgpu's ADDRESS_MODE_CLAMP_TO_BORDER".to_owned(),
        });
    }
    Ok(plan
        .samplers
        .iter()
        .map(|s| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(&s.name),
                address_mode_u: s.address[0],
                address_mode_v: s.address[1],
                address_mode_w: s.address[2],
                mag_filter: s.mag,
                min_filter: s.min,
                mipmap_filter: s.mip,
                lod_min_clamp: s.lod.0,
                lod_max_clamp: s.lod.1,
                compare: s.compare,
                anisotropy_clamp: s.anisotropy.max(1),
                border_color: s.border,
            })
        })
        .collect())
}

pub(super) fn meshes(device: &wgpu::Device, queue: &wgpu::Queue, plan: &Plan) -> Vec<GpuMesh> {
    plan.meshes
        .iter()
        .map(|m| {
            let buffer = |label: &str, data: &[u8], usage: wgpu::BufferUsages| {
                let size = (data.len() as u64).div_ceil(4).max(1) * 4;
                let b = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: usage | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let mut padded = data.to_vec();
                padded.resize(size as usize, 0);
                queue.write_buffer(&b, 0, &padded);
                b
            };
            GpuMesh {
                streams: m
                    .streams
                    .iter()
                    .map(|s| {
                        (
                            s.slot,
                            buffer(
                                &format!("{} VB{}", m.name, s.slot),
                                &s.data,
                                wgpu::BufferUsages::VERTEX,
                            ),
                        )
                    })
                    .collect(),
                index: m.indices.as_ref().map(|(data, f, n)| {
                    (
                        buffer(&format!("{} IB", m.name), data, wgpu::BufferUsages::INDEX),
                        *f,
                        *n,
                    )
                }),
                vertex_count: m.vertex_count,
                instance_count: m.instance_count,
            }
        })
        .collect()
}

/// Shader modules from WGSL the plan's builder validated, with a frame-constant buffer for
/// those that declare `frame`.
pub(super) fn modules(device: &wgpu::Device, plan: &Plan) -> Result<Vec<Module>, ReplayError> {
    let mut modules = Vec::new();
    for s in &plan.shaders {
        let reflection = s.validated.clone();
        let g = scope(device);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&s.name),
            source: wgpu::ShaderSource::Wgsl(s.source.as_str().into()),
        });
        setup(&format!("shader {}", s.name), g)?;
        let frame_buffer =
            uniforms::uniform_struct(&reflection.module, "frame").map(|(size, _)| {
                let size = u64::from(size).max(16);
                (
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("frame constants"),
                        size,
                        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    }),
                    size,
                )
            });
        modules.push(Module {
            module,
            reflection,
            frame_buffer,
        });
    }
    Ok(modules)
}
