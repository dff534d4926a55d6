//! Replay benchmarks on the available adapter:
//! - CPU cost of one frame (encode + submit, pipelines created beforehand) of the pass-kinds
//!   capture through framelab's `Session`, against a hand-written minimal wgpu loop doing the
//!   same nine passes with resources, views and bind groups made once;
//! - the cost of timestamp instrumentation: whole frames without timestamps (submit, wait)
//!   and with them (submit, wait, read back), chained and as a pair per pass.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use framelab_replay::wgpu;

struct HandWritten {
    color: wgpu::TextureView,
    color_tex: wgpu::Texture,
    color_copy: wgpu::Texture,
    texel_data: wgpu::Buffer,
    from_buffer: wgpu::Texture,
    fill: wgpu::ComputePipeline,
    fill_group: wgpu::BindGroup,
    draw: wgpu::RenderPipeline,
    draw_group: wgpu::BindGroup,
    packed: wgpu::TextureView,
    depth: wgpu::TextureView,
    blit: wgpu::RenderPipeline,
    mip_groups: Vec<wgpu::BindGroup>,
    mip_targets: Vec<wgpu::TextureView>,
    msaa: wgpu::TextureView,
    resolved: wgpu::TextureView,
}

const BLIT: &str = "
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var smp: sampler;
struct V { @builtin(position) p: vec4<f32>, @location(0) uv: vec2<f32> }
@vertex fn vs(@builtin(vertex_index) i: u32) -> V {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return V(vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0), uv);
}
@fragment fn fs(v: V) -> @location(0) vec4<f32> { return textureSample(src, smp, v.uv); }
";

#[allow(clippy::too_many_arguments)]
fn texture(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    mips: u32,
    samples: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: mips,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn one_mip(t: &wgpu::Texture, mip: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        base_mip_level: mip,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

/// The pipeline drawing a full-screen triangle into a packed target with depth.
fn fullscreen_draw(device: &wgpu::Device, module: &wgpu::ShaderModule) -> wgpu::RenderPipeline {
    use wgpu::TextureFormat as F;
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: F::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_color"),
            compilation_options: Default::default(),
            targets: &[Some(F::Rgb10a2Unorm.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The pipeline sampling one mip into the next.
fn blit_pipeline(device: &wgpu::Device) -> wgpu::RenderPipeline {
    use wgpu::TextureFormat as F;
    let blit_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("blit"),
        source: wgpu::ShaderSource::Wgsl(BLIT.into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module: &blit_module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &blit_module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(F::Rgba8Unorm.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A bind group for each mip the blit reads (levels 0 and 1 of the checker).
fn mip_groups(
    device: &wgpu::Device,
    blit: &wgpu::RenderPipeline,
    checker: &wgpu::Texture,
    sampler: &wgpu::Sampler,
) -> Vec<wgpu::BindGroup> {
    (1..3)
        .map(|m| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &blit.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&one_mip(checker, m - 1)),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(sampler),
                    },
                ],
            })
        })
        .collect()
}

/// A buffer holding `bytes`: a uniform buffer, or one copied from and to.
fn buffer_of(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    bytes: &[u8],
    uniform: bool,
) -> wgpu::Buffer {
    let usage = if uniform {
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST
    } else {
        wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST
    };
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.len() as u64,
        usage,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytes);
    buffer
}

impl HandWritten {
    fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        use wgpu::TextureFormat as F;
        use wgpu::TextureUsages as U;
        let rt = U::RENDER_ATTACHMENT | U::COPY_SRC | U::COPY_DST;
        let color_tex = texture(device, "color", 32, 32, 1, 1, F::Rgba8Unorm, rt);
        let color_copy = texture(
            device,
            "color_copy",
            32,
            32,
            1,
            1,
            F::Rgba8Unorm,
            U::COPY_DST | U::COPY_SRC,
        );
        let ids = texture(
            device,
            "ids",
            16,
            16,
            1,
            1,
            F::R32Uint,
            U::STORAGE_BINDING | U::COPY_SRC,
        );
        let hdr = texture(
            device,
            "hdr",
            16,
            16,
            1,
            1,
            F::Rgba16Float,
            U::STORAGE_BINDING | U::COPY_SRC,
        );
        let from_buffer = texture(
            device,
            "from_buffer",
            64,
            4,
            1,
            1,
            F::R32Uint,
            U::COPY_DST | U::COPY_SRC,
        );
        let packed = texture(device, "packed", 32, 32, 1, 1, F::Rgb10a2Unorm, rt);
        let depth = texture(device, "depth", 32, 32, 1, 1, F::Depth32Float, rt);
        let checker = texture(
            device,
            "checker",
            64,
            64,
            3,
            1,
            F::Rgba8Unorm,
            rt | U::TEXTURE_BINDING,
        );
        let msaa = texture(
            device,
            "msaa",
            16,
            16,
            1,
            4,
            F::Rgba8Unorm,
            U::RENDER_ATTACHMENT,
        );
        let resolved = texture(device, "resolved", 16, 16, 1, 1, F::Rgba8Unorm, rt);
        let texel_data = buffer_of(device, queue, "texel_data", &[7u8; 1024], false);
        let source = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/replay_kinds/kinds.wgsl"
        ))
        .unwrap_or_default();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("kinds"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let fill = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: Some("cs_fill"),
            compilation_options: Default::default(),
            cache: None,
        });
        let fill_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &fill.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(
                        &ids.create_view(&Default::default()),
                    ),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(
                        &hdr.create_view(&Default::default()),
                    ),
                },
            ],
        });
        let values: Vec<u8> = [1.0f32, 0.5, 0.0, 1.0, 0.25, 0.0, 0.0, 0.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let params = buffer_of(device, queue, "params", &values, true);
        let draw = fullscreen_draw(device, &module);
        let draw_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &draw.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            }],
        });
        let blit = blit_pipeline(device);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let mip_groups = mip_groups(device, &blit, &checker, &sampler);
        Self {
            color: color_tex.create_view(&Default::default()),
            color_tex,
            color_copy,
            texel_data,
            from_buffer,
            fill,
            fill_group,
            draw,
            draw_group,
            packed: packed.create_view(&Default::default()),
            depth: depth.create_view(&Default::default()),
            blit,
            mip_groups,
            mip_targets: (1..3).map(|m| one_mip(&checker, m)).collect(),
            msaa: msaa.create_view(&Default::default()),
            resolved: resolved.create_view(&Default::default()),
        }
    }

    fn submit(&self, device: &wgpu::Device, queue: &wgpu::Queue) {
        fn clear<'a>(
            view: &'a wgpu::TextureView,
            color: wgpu::Color,
            resolve: Option<&'a wgpu::TextureView>,
            load: bool,
        ) -> wgpu::RenderPassColorAttachment<'a> {
            wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: if load {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(color)
                    },
                    store: wgpu::StoreOp::Store,
                },
            }
        }
        let pass = |encoder: &mut wgpu::CommandEncoder,
                    color: wgpu::RenderPassColorAttachment<'_>| {
            drop(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(color)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            }));
        };
        let mut buffers = Vec::new();
        let mut e = device.create_command_encoder(&Default::default());
        pass(
            &mut e,
            clear(
                &self.color,
                wgpu::Color {
                    r: 0.25,
                    g: 0.5,
                    b: 0.75,
                    a: 1.0,
                },
                None,
                false,
            ),
        );
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        {
            let mut cp = e.begin_compute_pass(&Default::default());
            cp.set_pipeline(&self.fill);
            cp.set_bind_group(0, &self.fill_group, &[]);
            cp.dispatch_workgroups(2, 2, 1);
        }
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        e.copy_texture_to_texture(
            self.color_tex.as_image_copy(),
            self.color_copy.as_image_copy(),
            wgpu::Extent3d {
                width: 32,
                height: 32,
                depth_or_array_layers: 1,
            },
        );
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        e.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: &self.texel_data,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(256),
                    rows_per_image: Some(4),
                },
            },
            self.from_buffer.as_image_copy(),
            wgpu::Extent3d {
                width: 64,
                height: 4,
                depth_or_array_layers: 1,
            },
        );
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        {
            let mut rp = e.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(clear(
                    &self.packed,
                    wgpu::Color::TRANSPARENT,
                    None,
                    false,
                ))],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(&self.draw);
            rp.set_bind_group(0, &self.draw_group, &[]);
            rp.draw(0..3, 0..1);
        }
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        for (group, target) in self.mip_groups.iter().zip(&self.mip_targets) {
            let mut rp = e.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(clear(target, wgpu::Color::BLACK, None, false))],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(&self.blit);
            rp.set_bind_group(0, group, &[]);
            rp.draw(0..3, 0..1);
        }
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        pass(&mut e, clear(&self.msaa, wgpu::Color::GREEN, None, false));
        buffers.push(e.finish());
        let mut e = device.create_command_encoder(&Default::default());
        pass(
            &mut e,
            clear(&self.msaa, wgpu::Color::BLACK, Some(&self.resolved), true),
        );
        buffers.push(e.finish());
        queue.submit(buffers);
    }
}

fn replay(c: &mut Criterion) {
    let capture_path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/replay_kinds/kinds.json"
    );
    let Ok(ctx) = framelab_replay::open_device(None, framelab_core::lower::wanted_features())
    else {
        eprintln!("no GPU adapter: replay benchmarks need one (install mesa-vulkan-drivers)");
        return;
    };
    eprintln!("adapter: {}", ctx.summary);
    // The same stages `framelab replay` walks: load, validate, analyse, lower, start.
    let replaying = framelab_core::pipeline::Analysed::for_replay(
        std::path::Path::new(capture_path),
        &Default::default(),
        Default::default(),
    )
    .and_then(|a| a.lower(ctx.device.features(), &ctx.summary.name))
    .map_err(|e| e.to_string())
    .and_then(|l| framelab_replay::Replaying::start(&ctx, l).map_err(|e| e.to_string()));
    let mut replaying = match replaying {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{e}");
            return;
        }
    };
    let constants = replaying.constants(0);
    let session = &mut replaying.session;
    let hand = HandWritten::new(&ctx.device, &ctx.queue);
    let wait = |device: &wgpu::Device| {
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
    };
    // CPU time of `submit` only; the GPU is waited for outside the measurement.
    let cpu_only = |b: &mut criterion::Bencher<'_>, submit: &mut dyn FnMut()| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t = Instant::now();
                submit();
                total += t.elapsed();
                wait(&ctx.device);
            }
            total
        })
    };
    let mut group = c.benchmark_group("replay_cpu");
    group.sample_size(50);
    for (name, stamps) in [
        ("framelab encode+submit", false),
        ("framelab encode+submit, with timestamps", true),
    ] {
        group.bench_function(name, |b| {
            cpu_only(b, &mut || {
                let _ = session.submit_frame(&constants, None, stamps);
            })
        });
    }
    group.bench_function("hand-written wgpu encode+submit", |b| {
        cpu_only(b, &mut || hand.submit(&ctx.device, &ctx.queue))
    });
    group.finish();
    // Whole frames as `replay` runs them: without timestamps (submit, wait), and with them
    // (submit, wait, read the stamps back), chained (n+1 stamps) and as a pair per pass (2n).
    let mut group = c.benchmark_group("replay_frame");
    group.sample_size(30);
    group.bench_function("without timestamps", |b| {
        b.iter(|| {
            let _ = session.submit_frame(&constants, None, false);
            wait(&ctx.device);
        })
    });
    for (name, pairs) in [
        ("with timestamps (chained)", false),
        ("with timestamps (a pair per pass)", true),
    ] {
        session.set_timestamp_pairs(pairs);
        group.bench_function(name, |b| {
            b.iter(|| {
                let _ = session.run_frame(&constants, None);
            })
        });
    }
    session.set_timestamp_pairs(false);
    group.finish();
}

criterion_group!(benches, replay);
criterion_main!(benches);
