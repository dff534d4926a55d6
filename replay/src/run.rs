//! Running a plan: a `Session` owns the GPU resources, shader modules, pipelines and bind
//! groups of a plan, and `run_frame` encodes every pass (each in its own command encoder and
//! error scope, so a validation error names its pass) with a timestamp pair around it where the
//! adapter can, submits, and returns per-pass GPU and CPU times.
//!
//! Pipelines use automatic layouts (wgpu derives them from naga's reflection of the entry
//! points), and bind groups are filled by WGSL variable name: `frame` gets the frame constants,
//! `params` the pass's packed parameters, every other variable the capture's binding.
//! Resources marked `history` have two copies that swap every frame.

use std::collections::{BTreeMap, BTreeSet};
use std::time::Instant;

use crate::device::GpuContext;
use crate::plan::*;
use crate::shader::{ShaderError, ValidatedShader};
use crate::uniforms::{self, UniformError};

#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("{0}")]
    Shader(#[from] Box<ShaderError>),
    #[error("pass \"{pass}\": {message}")]
    Pass { pass: String, message: String },
    #[error("pass \"{pass}\": parameters")]
    Params {
        pass: String,
        #[source]
        source: UniformError,
    },
    #[error("pass \"{pass}\": the GPU reported: {message}")]
    Gpu { pass: String, message: String },
    #[error("creating {what}: the GPU reported: {message}")]
    Setup { what: String, message: String },
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    #[error("reading timestamps back: {0}")]
    Readback(#[from] crate::readback::ReadbackError),
}

/// Times of one pass in one frame.
#[derive(Clone, Debug, Default)]
pub struct PassTime {
    /// GPU time from the timestamp pair, when the adapter supports timestamps for this pass.
    pub gpu_ns: Option<u64>,
    /// Time spent encoding the pass on the CPU.
    pub cpu_ns: u64,
    /// GPU start relative to the frame's first timestamp (for traces).
    pub gpu_start_ns: Option<u64>,
}

struct Module {
    module: wgpu::ShaderModule,
    reflection: std::sync::Arc<ValidatedShader>,
    frame_buffer: Option<(wgpu::Buffer, u64)>,
}

struct GpuMesh {
    streams: Vec<(u32, wgpu::Buffer)>,
    index: Option<(wgpu::Buffer, wgpu::IndexFormat, u32)>,
    vertex_count: u32,
    instance_count: u32,
}

/// Bind groups of one pipeline for frame parity 0 and 1 (history copies swap).
type Groups = [Vec<(u32, wgpu::BindGroup)>; 2];

enum Prepared {
    Raster {
        pipelines: BTreeMap<String, wgpu::RenderPipeline>,
        /// Bind groups per vertex entry point, per draw (draws with their own parameters get
        /// their own groups; index 0 is the pass's).
        groups: BTreeMap<String, Vec<Groups>>,
        draw_groups: Vec<usize>,
    },
    Compute {
        pipelines: BTreeMap<String, wgpu::ComputePipeline>,
        groups: BTreeMap<String, Vec<Groups>>,
        dispatch_groups: Vec<usize>,
    },
    Other,
}

/// Views and blit bind groups made once and reused every frame: (texture, copy, mip, layer,
/// view format).
type ViewKey = (usize, usize, u32, u32, Option<wgpu::TextureFormat>);

pub struct Session {
    faults: crate::device::Faults,
    views: std::cell::RefCell<std::collections::HashMap<ViewKey, wgpu::TextureView>>,
    mip_groups: std::cell::RefCell<std::collections::HashMap<ViewKey, wgpu::BindGroup>>,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub plan: Plan,
    textures: Vec<[wgpu::Texture; 2]>,
    buffers: Vec<[wgpu::Buffer; 2]>,
    samplers: Vec<wgpu::Sampler>,
    meshes: Vec<GpuMesh>,
    modules: Vec<Module>,
    prepared: Vec<Prepared>,
    mip_pipelines: BTreeMap<String, (wgpu::RenderPipeline, wgpu::Sampler)>,
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer, bool)>,
    timestamp_period: f32,
    frames_run: u64,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("passes", &self.plan.passes.len())
            .field("frames_run", &self.frames_run)
            .finish()
    }
}

/// Validation and out-of-memory error scopes. Fields drop in declaration order, so the
/// validation scope (pushed last) is popped first even when an early return drops the pair.
struct Scopes {
    validation: wgpu::ErrorScopeGuard,
    oom: wgpu::ErrorScopeGuard,
}

fn scope(device: &wgpu::Device) -> Scopes {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    Scopes { validation, oom }
}

fn close(scopes: Scopes) -> Option<String> {
    let Scopes { validation, oom } = scopes;
    let v = pollster::block_on(validation.pop());
    let o = pollster::block_on(oom.pop());
    v.or(o).map(|e| e.to_string())
}

/// The WGSL global variable named `variable`.
fn global<'m>(module: &'m naga::Module, variable: &str) -> Option<&'m naga::GlobalVariable> {
    module
        .global_variables
        .iter()
        .find(|(_, v)| v.name.as_deref() == Some(variable))
        .map(|(_, v)| v)
}

fn view_dimension(module: &naga::Module, variable: &str) -> Option<wgpu::TextureViewDimension> {
    let var = global(module, variable)?;
    match module.types[var.ty].inner {
        naga::TypeInner::Image { dim, arrayed, .. } => Some(match (dim, arrayed) {
            (naga::ImageDimension::D1, _) => wgpu::TextureViewDimension::D1,
            (naga::ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
            (naga::ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
            (naga::ImageDimension::D3, _) => wgpu::TextureViewDimension::D3,
            (naga::ImageDimension::Cube, false) => wgpu::TextureViewDimension::Cube,
            (naga::ImageDimension::Cube, true) => wgpu::TextureViewDimension::CubeArray,
        }),
        _ => None,
    }
}

/// Whether a texture variable samples unsigned integers: on a depth-stencil texture that is a
/// view of the stencil aspect (D3D12's X32_TYPELESS_G8X24_UINT / X24_TYPELESS_G8_UINT SRVs).
fn samples_uint(module: &naga::Module, variable: &str) -> bool {
    global(module, variable).is_some_and(|v| {
        matches!(
            module.types[v.ty].inner,
            naga::TypeInner::Image {
                class: naga::ImageClass::Sampled {
                    kind: naga::ScalarKind::Uint,
                    ..
                },
                ..
            }
        )
    })
}

fn binding_slot(module: &naga::Module, variable: &str) -> Option<(u32, u32)> {
    global(module, variable).and_then(|v| v.binding.as_ref().map(|b| (b.group, b.binding)))
}

fn has_stencil(f: wgpu::TextureFormat) -> bool {
    matches!(
        f,
        wgpu::TextureFormat::Depth24PlusStencil8
            | wgpu::TextureFormat::Depth32FloatStencil8
            | wgpu::TextureFormat::Stencil8
    )
}

impl Session {
    /// Creates every resource, module, pipeline and bind group of the plan.
    pub fn new(ctx: &GpuContext, plan: Plan) -> Result<Self, ReplayError> {
        let device = ctx.device.clone();
        let queue = ctx.queue.clone();
        let setup = |what: &str, guards| match close(guards) {
            Some(message) => Err(ReplayError::Setup {
                what: what.to_owned(),
                message,
            }),
            None => Ok(()),
        };

        let mut textures = Vec::new();
        for t in &plan.textures {
            let g = scope(&device);
            let make = |suffix: &str| {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(&format!("{}{suffix}", t.name)),
                    size: t.size,
                    mip_level_count: t.mip_levels,
                    sample_count: t.samples,
                    dimension: t.dimension,
                    format: t.format,
                    usage: t.usage,
                    view_formats: &[],
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
                    write_texture(&queue, tex, t, data);
                }
            }
            setup(&format!("texture \"{}\"", t.name), g)?;
            textures.push([a, b]);
        }
        let mut buffers = Vec::new();
        for b in &plan.buffers {
            let g = scope(&device);
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
        let samplers = plan
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
                    border_color: None,
                })
            })
            .collect();
        let meshes = plan
            .meshes
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
            .collect();
        let mut modules = Vec::new();
        for s in &plan.shaders {
            let reflection = s.validated.clone();
            let g = scope(&device);
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
        let features = device.features();
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            let count = (plan.passes.len() as u32 * 2).max(2);
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            });
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: u64::from(count) * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (
                set,
                resolve,
                features.contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
            )
        });
        let timestamp_period = queue.get_timestamp_period();
        let mut session = Session {
            faults: ctx.faults.clone(),
            views: Default::default(),
            mip_groups: Default::default(),
            device,
            queue,
            plan,
            textures,
            buffers,
            samplers,
            meshes,
            modules,
            prepared: Vec::new(),
            mip_pipelines: BTreeMap::new(),
            timestamps,
            timestamp_period,
            frames_run: 0,
        };
        for i in 0..session.plan.passes.len() {
            let p = session.prepare(i)?;
            session.prepared.push(p);
        }
        session.check_faults("setting up the replay")?;
        Ok(session)
    }

    /// Encodes passes `0..=last` again, each in its own error scope and without submitting,
    /// and returns the first pass's error (encoding is deterministic, so it recurs).
    fn attribute(&self, parity: usize, last: usize, with_timestamps: bool) -> Option<ReplayError> {
        let timestamps = self.timestamps.as_ref().filter(|_| with_timestamps);
        let inside_encoders = timestamps.is_some_and(|t| t.2);
        for i in 0..=last.min(self.plan.passes.len().saturating_sub(1)) {
            let guards = scope(&self.device);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(&self.plan.passes[i].name),
                });
            let stamps = timestamps.map(|(set, _, _)| (set, 2 * i as u32));
            let encoded = self.encode(i, parity, &mut encoder, stamps, inside_encoders);
            drop(encoder.finish());
            let scoped = close(guards);
            if let Err(e) = encoded {
                return Some(e);
            }
            if let Some(message) = scoped {
                return Some(ReplayError::Gpu {
                    pass: self.plan.passes[i].name.clone(),
                    message,
                });
            }
        }
        None
    }

    /// A cached single-mip, single-layer view of copy `copy` of texture `texture`.
    fn view(
        &self,
        texture: usize,
        copy: usize,
        mip: u32,
        layer: u32,
        format: Option<wgpu::TextureFormat>,
    ) -> wgpu::TextureView {
        self.views
            .borrow_mut()
            .entry((texture, copy, mip, layer, format))
            .or_insert_with(|| {
                single_view(
                    &self.textures[texture][copy],
                    &self.plan.textures[texture],
                    mip,
                    layer,
                    format,
                )
            })
            .clone()
    }

    /// Turns errors recorded outside error scopes, or a lost device, into an error.
    pub fn check_faults(&self, during: &str) -> Result<(), ReplayError> {
        if let Some(reason) = self.faults.lost() {
            return Err(ReplayError::DeviceLost(reason));
        }
        let errors = self.faults.take_uncaptured();
        if errors.is_empty() {
            Ok(())
        } else {
            Err(ReplayError::Setup {
                what: during.to_owned(),
                message: errors.join("; "),
            })
        }
    }

    pub fn texture(&self, index: usize) -> &wgpu::Texture {
        // The copy written by the last frame.
        &self.textures[index][self.parity(self.frames_run.saturating_sub(1))]
    }

    pub fn buffer(&self, index: usize) -> &wgpu::Buffer {
        &self.buffers[index][self.parity(self.frames_run.saturating_sub(1))]
    }

    fn parity(&self, frame: u64) -> usize {
        (frame % 2) as usize
    }

    /// Globals any of `entries` uses (missing entry points are reported by the caller).
    fn used_by<'e>(
        &self,
        module: usize,
        entries: impl Iterator<Item = &'e String>,
    ) -> BTreeSet<String> {
        entries
            .filter_map(|e| self.modules[module].reflection.globals_used_by(e))
            .flatten()
            .collect()
    }

    /// The packed `params` uniform, when the pass's entry points use one.
    fn params_buffer(
        &self,
        pass: &str,
        module: usize,
        params: &Params,
        used: &BTreeSet<String>,
    ) -> Result<Option<wgpu::Buffer>, ReplayError> {
        let m = &self.modules[module].reflection.module;
        if uniforms::uniform_struct(m, "params").is_none() || !used.contains("params") {
            if let Some(k) = params.keys().next() {
                return Err(ReplayError::Pass {
                    pass: pass.to_owned(),
                    message: format!(
                        "parameter \"{k}\" given but the shader declares no `params` uniform"
                    ),
                });
            }
            return Ok(None);
        }
        let bytes =
            uniforms::pack(m, "params", params, true).map_err(|source| ReplayError::Params {
                pass: pass.to_owned(),
                source,
            })?;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{pass} params")),
            size: (bytes.len() as u64).max(16),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&buffer, 0, &bytes);
        Ok(Some(buffer))
    }

    /// Bind groups for a pipeline whose entry points use `used`, for both frame parities.
    fn bind_groups(
        &self,
        pass: &str,
        module: usize,
        used: &BTreeSet<String>,
        bindings: &[Binding],
        params: Option<&wgpu::Buffer>,
        layout: impl Fn(u32) -> wgpu::BindGroupLayout,
    ) -> Result<Groups, ReplayError> {
        let m = &self.modules[module];
        let err = |message: String| ReplayError::Pass {
            pass: pass.to_owned(),
            message,
        };
        let mut by_group: BTreeMap<u32, Vec<(u32, &str)>> = BTreeMap::new();
        for var in used {
            if let Some((g, b)) = binding_slot(&m.reflection.module, var) {
                by_group.entry(g).or_default().push((b, var.as_str()));
            }
        }
        let mut out: Groups = [Vec::new(), Vec::new()];
        for (parity, slot_groups) in out.iter_mut().enumerate() {
            for (&group, entries) in &by_group {
                let mut views: Vec<(u32, wgpu::TextureView)> = Vec::new();
                let mut resources: Vec<(u32, wgpu::BindingResource<'_>)> = Vec::new();
                for &(slot, var) in entries {
                    if var == "frame" {
                        let (buffer, _) = m
                            .frame_buffer
                            .as_ref()
                            .ok_or_else(|| err("`frame` is not a uniform struct".into()))?;
                        resources.push((slot, buffer.as_entire_binding()));
                        continue;
                    }
                    if var == "params" {
                        let buffer = params
                            .ok_or_else(|| err("the shader's `params` has no values".into()))?;
                        resources.push((slot, buffer.as_entire_binding()));
                        continue;
                    }
                    let b = bindings.iter().find(|b| b.variable == var).ok_or_else(|| {
                        err(format!("shader variable `{var}` (group {group}, binding {slot}) has no binding in the capture"))
                    })?;
                    match &b.target {
                        BindTarget::Texture {
                            texture,
                            format,
                            base_mip,
                            mips,
                            base_layer,
                            layers,
                            previous_frame,
                        } => {
                            let copy = if *previous_frame { 1 - parity } else { parity };
                            let tex = &self.textures[*texture][copy];
                            let spec = &self.plan.textures[*texture];
                            let dimension = view_dimension(&m.reflection.module, var);
                            let aspect = if has_stencil(*format)
                                && samples_uint(&m.reflection.module, var)
                            {
                                wgpu::TextureAspect::StencilOnly
                            } else if format.has_depth_aspect() && has_stencil(*format) {
                                wgpu::TextureAspect::DepthOnly
                            } else {
                                wgpu::TextureAspect::All
                            };
                            let layer_count = if spec.dimension == wgpu::TextureDimension::D3 {
                                None
                            } else {
                                Some(*layers)
                            };
                            let view_format = if format.has_depth_aspect() {
                                None
                            } else {
                                Some(*format)
                            };
                            views.push((
                                slot,
                                tex.create_view(&wgpu::TextureViewDescriptor {
                                    label: Some(var),
                                    format: view_format,
                                    dimension,
                                    usage: None,
                                    aspect,
                                    base_mip_level: *base_mip,
                                    mip_level_count: Some(*mips),
                                    base_array_layer: *base_layer,
                                    array_layer_count: layer_count,
                                }),
                            ));
                        }
                        BindTarget::Buffer {
                            buffer,
                            offset,
                            size,
                            previous_frame,
                        } => {
                            let copy = if *previous_frame { 1 - parity } else { parity };
                            resources.push((
                                slot,
                                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                    buffer: &self.buffers[*buffer][copy],
                                    offset: *offset,
                                    size: size.and_then(wgpu::BufferSize::new),
                                }),
                            ));
                        }
                        BindTarget::Sampler(s) => resources
                            .push((slot, wgpu::BindingResource::Sampler(&self.samplers[*s]))),
                    }
                }
                let mut entries: Vec<wgpu::BindGroupEntry<'_>> = resources
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                for (binding, view) in &views {
                    entries.push(wgpu::BindGroupEntry {
                        binding: *binding,
                        resource: wgpu::BindingResource::TextureView(view),
                    });
                }
                entries.sort_by_key(|e| e.binding);
                let bgl = layout(group);
                let bg = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(pass),
                    layout: &bgl,
                    entries: &entries,
                });
                slot_groups.push((group, bg));
            }
        }
        Ok(out)
    }

    fn prepare(&mut self, index: usize) -> Result<Prepared, ReplayError> {
        let pass = self.plan.passes[index].clone();
        let name = pass.name.clone();
        let g = scope(&self.device);
        let prepared = match &pass.op {
            PassOp::Raster(r) => self.prepare_raster(&name, r)?,
            PassOp::Compute(c) => self.prepare_compute(&name, c)?,
            PassOp::GenerateMips { texture, .. } => {
                let format = self.plan.textures[*texture].format;
                self.mip_pipeline(format);
                Prepared::Other
            }
            _ => Prepared::Other,
        };
        match close(g) {
            Some(message) => Err(ReplayError::Gpu {
                pass: name,
                message,
            }),
            None => Ok(prepared),
        }
    }

    fn prepare_raster(&self, name: &str, r: &RasterOp) -> Result<Prepared, ReplayError> {
        let m = &self.modules[r.shader];
        let err = |message: String| ReplayError::Pass {
            pass: name.to_owned(),
            message,
        };
        // Pipelines only for the vertex entry points some draw uses (the pass's default entry
        // may be overridden by every draw, and then has no mesh to take a layout from).
        let mut entries: BTreeSet<String> = r
            .draws
            .iter()
            .map(|d| d.vertex.clone().unwrap_or_else(|| r.vertex.clone()))
            .collect();
        if entries.is_empty() {
            entries.insert(r.vertex.clone());
        }
        let targets: Vec<Option<wgpu::ColorTargetState>> = r
            .color
            .iter()
            .map(|c| {
                Some(wgpu::ColorTargetState {
                    format: c.format,
                    blend: c.blend,
                    write_mask: c.write_mask,
                })
            })
            .collect();
        let samples = r
            .color
            .first()
            .map(|c| self.plan.textures[c.texture].samples)
            .or(r
                .depth
                .as_ref()
                .map(|d| self.plan.textures[d.texture].samples))
            .unwrap_or(1);
        let mut pipelines = BTreeMap::new();
        let mut groups = BTreeMap::new();
        let all_used = self.used_by(r.shader, entries.iter().chain(r.fragment.iter()));
        let pass_params = self.params_buffer(name, r.shader, &r.params, &all_used)?;
        for vertex in &entries {
            let mut used = m
                .reflection
                .globals_used_by(vertex)
                .ok_or_else(|| err(format!("the shader has no vertex entry point `{vertex}`")))?;
            if let Some(f) = &r.fragment {
                used.extend(
                    m.reflection.globals_used_by(f).ok_or_else(|| {
                        err(format!("the shader has no fragment entry point `{f}`"))
                    })?,
                );
            }
            // Vertex buffers of the first mesh drawn with this entry point define the layout.
            let mesh = r
                .draws
                .iter()
                .find(|d| d.vertex.as_ref().unwrap_or(&r.vertex) == vertex)
                .and_then(|d| d.mesh);
            let streams: Vec<&StreamSpec> = mesh
                .map(|i| self.plan.meshes[i].streams.iter().collect())
                .unwrap_or_default();
            let attributes: Vec<Vec<wgpu::VertexAttribute>> = streams
                .iter()
                .map(|s| {
                    s.attributes
                        .iter()
                        .map(|(format, offset, location)| wgpu::VertexAttribute {
                            format: *format,
                            offset: *offset,
                            shader_location: *location,
                        })
                        .collect()
                })
                .collect();
            // Slots may have holes (VB0-VB3 and VB7 in the seed's layout).
            let slots = streams
                .iter()
                .map(|s| s.slot as usize + 1)
                .max()
                .unwrap_or(0);
            let mut layouts: Vec<Option<wgpu::VertexBufferLayout<'_>>> = vec![None; slots];
            for (s, a) in streams.iter().zip(&attributes) {
                layouts[s.slot as usize] = Some(wgpu::VertexBufferLayout {
                    array_stride: s.stride,
                    step_mode: s.step,
                    attributes: a,
                });
            }
            let pipeline = self
                .device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(name),
                    layout: None,
                    vertex: wgpu::VertexState {
                        module: &m.module,
                        entry_point: Some(vertex),
                        compilation_options: Default::default(),
                        buffers: &layouts,
                    },
                    primitive: r.primitive,
                    depth_stencil: r.depth_stencil.clone(),
                    multisample: wgpu::MultisampleState {
                        count: samples,
                        mask: !0,
                        alpha_to_coverage_enabled: false,
                    },
                    fragment: r.fragment.as_ref().map(|f| wgpu::FragmentState {
                        module: &m.module,
                        entry_point: Some(f),
                        compilation_options: Default::default(),
                        targets: &targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                });
            let own = r
                .draws
                .iter()
                .filter(|d| {
                    !d.params.is_empty() && d.vertex.as_ref().unwrap_or(&r.vertex) == vertex
                })
                .map(|d| &d.params);
            let layout = |g| pipeline.get_bind_group_layout(g);
            let sets = self.group_sets(
                name,
                r.shader,
                (&used, &all_used),
                &r.bindings,
                (&r.params, pass_params.as_ref()),
                own,
                &layout,
            )?;
            groups.insert(vertex.clone(), sets);
            pipelines.insert(vertex.clone(), pipeline);
        }
        let draw_groups = set_indices(r.draws.iter().map(|d| {
            (
                d.vertex.as_deref().unwrap_or(&r.vertex),
                !d.params.is_empty(),
            )
        }));
        Ok(Prepared::Raster {
            pipelines,
            groups,
            draw_groups,
        })
    }

    fn prepare_compute(&self, name: &str, c: &ComputeOp) -> Result<Prepared, ReplayError> {
        let m = &self.modules[c.shader];
        let err = |message: String| ReplayError::Pass {
            pass: name.to_owned(),
            message,
        };
        let mut entries: BTreeSet<String> = BTreeSet::new();
        for d in &c.dispatches {
            entries.insert(d.entry.clone().unwrap_or_else(|| c.entry.clone()));
        }
        let all_used = self.used_by(c.shader, entries.iter());
        let pass_params = self.params_buffer(name, c.shader, &c.params, &all_used)?;
        let mut pipelines = BTreeMap::new();
        let mut groups = BTreeMap::new();
        for entry in &entries {
            let used = m
                .reflection
                .globals_used_by(entry)
                .ok_or_else(|| err(format!("the shader has no compute entry point `{entry}`")))?;
            let pipeline = self
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(name),
                    layout: None,
                    module: &m.module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                });
            let own = c
                .dispatches
                .iter()
                .filter(|d| !d.params.is_empty() && d.entry.as_ref().unwrap_or(&c.entry) == entry)
                .map(|d| &d.params);
            let layout = |g| pipeline.get_bind_group_layout(g);
            let sets = self.group_sets(
                name,
                c.shader,
                (&used, &all_used),
                &c.bindings,
                (&c.params, pass_params.as_ref()),
                own,
                &layout,
            )?;
            groups.insert(entry.clone(), sets);
            pipelines.insert(entry.clone(), pipeline);
        }
        let dispatch_groups = set_indices(
            c.dispatches
                .iter()
                .map(|d| (d.entry.as_deref().unwrap_or(&c.entry), !d.params.is_empty())),
        );
        Ok(Prepared::Compute {
            pipelines,
            groups,
            dispatch_groups,
        })
    }

    /// Bind-group sets of one pipeline: the pass's, then one per draw or dispatch that has its
    /// own parameters (merged over the pass's). `used`: globals of this pipeline, and of the pass.
    #[allow(clippy::too_many_arguments)]
    fn group_sets<'p, L: Fn(u32) -> wgpu::BindGroupLayout>(
        &self,
        name: &str,
        module: usize,
        (used, all_used): (&BTreeSet<String>, &BTreeSet<String>),
        bindings: &[Binding],
        (pass_params, pass_buffer): (&Params, Option<&wgpu::Buffer>),
        own: impl Iterator<Item = &'p Params>,
        layout: &L,
    ) -> Result<Vec<Groups>, ReplayError> {
        let mut sets = vec![self.bind_groups(name, module, used, bindings, pass_buffer, layout)?];
        for params in own {
            let mut merged = pass_params.clone();
            merged.extend(params.clone());
            let buffer = self.params_buffer(name, module, &merged, all_used)?;
            sets.push(self.bind_groups(name, module, used, bindings, buffer.as_ref(), layout)?);
        }
        Ok(sets)
    }

    /// A full-screen blit that downsamples one mip into the next.
    fn mip_pipeline(&mut self, format: wgpu::TextureFormat) {
        let key = format!("{format:?}");
        if self.mip_pipelines.contains_key(&key) {
            return;
        }
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("mip generation"),
                source: wgpu::ShaderSource::Wgsl(MIP_SHADER.into()),
            });
        let pipeline = self
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("mip generation"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
        let sampler = self.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("mip generation"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        self.mip_pipelines.insert(key, (pipeline, sampler));
    }

    /// Encodes every pass of one frame (up to `stop_after`) and submits it without waiting:
    /// the CPU side of a replay, which the benchmark measures. Times carry CPU encode time only.
    pub fn submit_frame(
        &mut self,
        frame_constants: &Params,
        stop_after: Option<usize>,
        with_timestamps: bool,
    ) -> Result<Vec<PassTime>, ReplayError> {
        let parity = self.parity(self.frames_run);
        for (i, m) in self.modules.iter().enumerate() {
            if let Some((buffer, size)) = &m.frame_buffer {
                let mut bytes =
                    uniforms::pack(&m.reflection.module, "frame", frame_constants, false).map_err(
                        |source| ReplayError::Params {
                            pass: format!("(frame constants in {})", self.plan.shaders[i].name),
                            source,
                        },
                    )?;
                bytes.resize(*size as usize, 0);
                self.queue.write_buffer(buffer, 0, &bytes);
            }
        }
        let last = stop_after
            .unwrap_or(self.plan.passes.len().saturating_sub(1))
            .min(self.plan.passes.len().saturating_sub(1));
        let mut command_buffers = Vec::new();
        let mut times = Vec::new();
        // One error scope for the frame keeps encoding cheap; if it catches anything, each pass
        // is encoded again in its own scope to name the one at fault.
        let frame_scope = scope(&self.device);
        let timestamps = self.timestamps.as_ref().filter(|_| with_timestamps);
        let inside_encoders = timestamps.is_some_and(|t| t.2);
        for i in 0..=last.min(self.plan.passes.len().saturating_sub(1)) {
            if self.plan.passes.is_empty() {
                break;
            }
            let start = Instant::now();
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(&self.plan.passes[i].name),
                });
            let stamps = timestamps.map(|(set, _, _)| (set, 2 * i as u32));
            self.encode(i, parity, &mut encoder, stamps, inside_encoders)?;
            command_buffers.push(encoder.finish());
            let cpu_ns = start.elapsed().as_nanos() as u64;
            times.push(PassTime {
                gpu_ns: None,
                cpu_ns,
                gpu_start_ns: None,
            });
        }
        if let Some((set, buffer, _)) = timestamps {
            let mut resolve_encoder =
                self.device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("timestamps"),
                    });
            let count = (2 * times.len() as u32).max(2);
            resolve_encoder.resolve_query_set(set, 0..count, buffer, 0);
            command_buffers.push(resolve_encoder.finish());
        }
        self.queue.submit(command_buffers);
        if let Some(message) = close(frame_scope) {
            return Err(self.attribute(parity, last, with_timestamps).unwrap_or(
                ReplayError::Gpu {
                    pass: "(frame)".into(),
                    message,
                },
            ));
        }
        self.frames_run += 1;
        Ok(times)
    }

    /// Runs one frame with the given frame constants (by member name), stopping after pass
    /// `stop_after` when given: encodes and submits, waits for the GPU, and returns per-pass
    /// times (GPU times from the timestamp pairs where the adapter has them).
    pub fn run_frame(
        &mut self,
        frame_constants: &Params,
        stop_after: Option<usize>,
    ) -> Result<Vec<PassTime>, ReplayError> {
        let mut times = self.submit_frame(frame_constants, stop_after, true)?;
        let inside_encoders = self.timestamps.as_ref().is_some_and(|t| t.2);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| ReplayError::DeviceLost(e.to_string()))?;
        if let Some((_, buffer, _)) = &self.timestamps {
            let bytes = crate::readback::read_buffer(
                &self.device,
                &self.queue,
                buffer,
                (2 * times.len() as u64).max(2) * 8,
                "timestamps",
            )?;
            let ticks: Vec<u64> = bytes
                .chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().unwrap_or_default()))
                .collect();
            let period = f64::from(self.timestamp_period);
            let origin = ticks
                .iter()
                .step_by(2)
                .copied()
                .filter(|&t| t != 0)
                .min()
                .unwrap_or(0);
            for (i, t) in times.iter_mut().enumerate() {
                let (a, b) = (ticks[2 * i], ticks[2 * i + 1]);
                let kind = &self.plan.passes[i].op;
                let stamped =
                    matches!(kind, PassOp::Raster(_) | PassOp::Compute(_)) || inside_encoders;
                if stamped && b >= a && a != 0 {
                    t.gpu_ns = Some(((b - a) as f64 * period) as u64);
                    t.gpu_start_ns = Some(((a - origin) as f64 * period) as u64);
                }
            }
        }
        self.check_faults(&format!("frame {}", self.frames_run))?;
        Ok(times)
    }

    fn encode(
        &self,
        i: usize,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        stamps: Option<(&wgpu::QuerySet, u32)>,
        inside_encoders: bool,
    ) -> Result<(), ReplayError> {
        let pass = &self.plan.passes[i];
        let err = |message: String| ReplayError::Pass {
            pass: pass.name.clone(),
            message,
        };
        let tex = |t: usize| &self.textures[t][parity];
        let buf = |b: usize| &self.buffers[b][parity];
        let stamp_encoder = |encoder: &mut wgpu::CommandEncoder, offset: u32| {
            if let (Some((set, base)), true) = (stamps, inside_encoders) {
                encoder.write_timestamp(set, base + offset);
            }
        };
        match (&pass.op, &self.prepared[i]) {
            (
                PassOp::Raster(r),
                Prepared::Raster {
                    pipelines,
                    groups,
                    draw_groups,
                },
            ) => {
                let color_views: Vec<wgpu::TextureView> = r
                    .color
                    .iter()
                    .map(|c| self.view(c.texture, parity, c.mip, c.layer, Some(c.format)))
                    .collect();
                let depth_view = r
                    .depth
                    .as_ref()
                    .map(|d| self.view(d.texture, parity, d.mip, d.layer, None));
                let attachments: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> = r
                    .color
                    .iter()
                    .zip(&color_views)
                    .map(|(c, view)| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: (self.plan.textures[c.texture].dimension
                                == wgpu::TextureDimension::D3)
                                .then_some(c.layer),
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: match c.load {
                                    Some(color) => wgpu::LoadOp::Clear(color),
                                    None if c.discard_load => {
                                        wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
                                    }
                                    None => wgpu::LoadOp::Load,
                                },
                                store: if c.store {
                                    wgpu::StoreOp::Store
                                } else {
                                    wgpu::StoreOp::Discard
                                },
                            },
                        })
                    })
                    .collect();
                let depth_attachment =
                    r.depth.as_ref().zip(depth_view.as_ref()).map(|(d, view)| {
                        let stencil = has_stencil(d.format);
                        wgpu::RenderPassDepthStencilAttachment {
                            view,
                            depth_ops: if d.read_only {
                                None
                            } else {
                                Some(wgpu::Operations {
                                    load: d
                                        .depth_clear
                                        .map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                                    store: if d.depth_store {
                                        wgpu::StoreOp::Store
                                    } else {
                                        wgpu::StoreOp::Discard
                                    },
                                })
                            },
                            stencil_ops: (stencil && !d.read_only).then(|| wgpu::Operations {
                                load: d
                                    .stencil_clear
                                    .map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                                store: if d.stencil_store {
                                    wgpu::StoreOp::Store
                                } else {
                                    wgpu::StoreOp::Discard
                                },
                            }),
                        }
                    });
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&pass.name),
                    color_attachments: &attachments,
                    depth_stencil_attachment: depth_attachment,
                    timestamp_writes: stamps.map(|(set, base)| wgpu::RenderPassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(base),
                        end_of_pass_write_index: Some(base + 1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_stencil_reference(r.stencil_reference);
                for (d, set) in r.draws.iter().zip(draw_groups) {
                    let vertex = d.vertex.as_ref().unwrap_or(&r.vertex);
                    let (Some(pipeline), Some(sets)) = (pipelines.get(vertex), groups.get(vertex))
                    else {
                        return Err(err(format!("no pipeline for `{vertex}`")));
                    };
                    rp.set_pipeline(pipeline);
                    for (g, bg) in &sets[*set][parity] {
                        rp.set_bind_group(*g, bg, &[]);
                    }
                    if let Some(reference) = d.stencil_reference {
                        rp.set_stencil_reference(reference);
                    }
                    let mesh = d.mesh.map(|m| &self.meshes[m]);
                    if let Some(mesh) = mesh {
                        for (slot, b) in &mesh.streams {
                            rp.set_vertex_buffer(*slot, b.slice(..));
                        }
                    }
                    match (mesh.and_then(|m| m.index.as_ref()), d.indirect) {
                        (Some((ib, format, _)), Some((b, offset))) => {
                            rp.set_index_buffer(ib.slice(..), *format);
                            rp.draw_indexed_indirect(buf(b), offset);
                        }
                        (None, Some((b, offset))) => rp.draw_indirect(buf(b), offset),
                        (Some((ib, format, n)), None) => {
                            rp.set_index_buffer(ib.slice(..), *format);
                            let count = d.count.unwrap_or(*n);
                            let instances = if d.instances == 1 {
                                mesh.map_or(1, |m| m.instance_count.max(1))
                            } else {
                                d.instances
                            };
                            rp.draw_indexed(
                                d.first..d.first + count,
                                d.base_vertex,
                                d.first_instance..d.first_instance + instances,
                            );
                        }
                        (None, None) => {
                            let count = d.count.or(mesh.map(|m| m.vertex_count)).unwrap_or(3);
                            let instances = if d.instances == 1 {
                                mesh.map_or(1, |m| m.instance_count.max(1))
                            } else {
                                d.instances
                            };
                            rp.draw(
                                d.first..d.first + count,
                                d.first_instance..d.first_instance + instances,
                            );
                        }
                    }
                }
            }
            (
                PassOp::Compute(c),
                Prepared::Compute {
                    pipelines,
                    groups,
                    dispatch_groups,
                },
            ) => {
                let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(&pass.name),
                    timestamp_writes: stamps.map(|(set, base)| wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(base),
                        end_of_pass_write_index: Some(base + 1),
                    }),
                });
                for (d, set) in c.dispatches.iter().zip(dispatch_groups) {
                    let entry = d.entry.as_ref().unwrap_or(&c.entry);
                    let (Some(pipeline), Some(sets)) = (pipelines.get(entry), groups.get(entry))
                    else {
                        return Err(err(format!("no pipeline for `{entry}`")));
                    };
                    cp.set_pipeline(pipeline);
                    for (g, bg) in &sets[*set][parity] {
                        cp.set_bind_group(*g, bg, &[]);
                    }
                    match (d.groups, d.indirect) {
                        (_, Some((b, offset))) => cp.dispatch_workgroups_indirect(buf(b), offset),
                        (Some([x, y, z]), None) => cp.dispatch_workgroups(x, y, z),
                        (None, None) => return Err(err("a dispatch without groups".into())),
                    }
                }
            }
            (PassOp::Copy(copies), _) => {
                stamp_encoder(encoder, 0);
                for c in copies {
                    match (&c.src, &c.dst) {
                        (
                            CopyEnd::Buffer {
                                buffer: a,
                                offset: oa,
                                ..
                            },
                            CopyEnd::Buffer {
                                buffer: b,
                                offset: ob,
                                ..
                            },
                        ) => {
                            encoder.copy_buffer_to_buffer(buf(*a), *oa, buf(*b), *ob, c.bytes);
                        }
                        (
                            CopyEnd::Texture {
                                texture: a,
                                mip: ma,
                                layer: la,
                                origin: oa,
                            },
                            CopyEnd::Texture {
                                texture: b,
                                mip: mb,
                                layer: lb,
                                origin: ob,
                            },
                        ) => {
                            encoder.copy_texture_to_texture(
                                texel(tex(*a), &self.plan.textures[*a], *ma, *la, *oa),
                                texel(tex(*b), &self.plan.textures[*b], *mb, *lb, *ob),
                                extent(c.extent),
                            );
                        }
                        (
                            CopyEnd::Buffer {
                                buffer,
                                offset,
                                bytes_per_row,
                            },
                            CopyEnd::Texture {
                                texture,
                                mip,
                                layer,
                                origin,
                            },
                        ) => {
                            encoder.copy_buffer_to_texture(
                                buffer_layout(
                                    buf(*buffer),
                                    *offset,
                                    *bytes_per_row,
                                    &self.plan.textures[*texture],
                                    c.extent,
                                ),
                                texel(
                                    tex(*texture),
                                    &self.plan.textures[*texture],
                                    *mip,
                                    *layer,
                                    *origin,
                                ),
                                extent(c.extent),
                            );
                        }
                        (
                            CopyEnd::Texture {
                                texture,
                                mip,
                                layer,
                                origin,
                            },
                            CopyEnd::Buffer {
                                buffer,
                                offset,
                                bytes_per_row,
                            },
                        ) => {
                            encoder.copy_texture_to_buffer(
                                texel(
                                    tex(*texture),
                                    &self.plan.textures[*texture],
                                    *mip,
                                    *layer,
                                    *origin,
                                ),
                                buffer_layout(
                                    buf(*buffer),
                                    *offset,
                                    *bytes_per_row,
                                    &self.plan.textures[*texture],
                                    c.extent,
                                ),
                                extent(c.extent),
                            );
                        }
                    }
                }
                stamp_encoder(encoder, 1);
            }
            (PassOp::Clear(clears), _) => {
                stamp_encoder(encoder, 0);
                for c in clears {
                    self.encode_clear(encoder, c, parity).map_err(err)?;
                }
                stamp_encoder(encoder, 1);
            }
            (PassOp::Resolve { src, dst }, _) => {
                let src_view = self.view(*src, parity, 0, 0, None);
                let dst_view = self.view(*dst, parity, 0, 0, None);
                let _rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&pass.name),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &src_view,
                        depth_slice: None,
                        resolve_target: Some(&dst_view),
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: stamps.map(|(set, base)| wgpu::RenderPassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(base),
                        end_of_pass_write_index: Some(base + 1),
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
            }
            (
                PassOp::GenerateMips {
                    texture,
                    base_layer,
                    layers,
                },
                _,
            ) => {
                stamp_encoder(encoder, 0);
                let spec = &self.plan.textures[*texture];
                let (pipeline, sampler) = self
                    .mip_pipelines
                    .get(&format!("{:?}", spec.format))
                    .ok_or_else(|| err("mip pipeline missing".into()))?;
                let layout = pipeline.get_bind_group_layout(0);
                for layer in *base_layer..*base_layer + *layers {
                    for mip in 1..spec.mip_levels {
                        let dst = self.view(*texture, parity, mip, layer, None);
                        let bg = self
                            .mip_groups
                            .borrow_mut()
                            .entry((*texture, parity, mip, layer, None))
                            .or_insert_with(|| {
                                let src = self.view(*texture, parity, mip - 1, layer, None);
                                self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                                    label: Some("mip source"),
                                    layout: &layout,
                                    entries: &[
                                        wgpu::BindGroupEntry {
                                            binding: 0,
                                            resource: wgpu::BindingResource::TextureView(&src),
                                        },
                                        wgpu::BindGroupEntry {
                                            binding: 1,
                                            resource: wgpu::BindingResource::Sampler(sampler),
                                        },
                                    ],
                                })
                            })
                            .clone();
                        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("mip"),
                            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                                view: &dst,
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
                        rp.set_pipeline(pipeline);
                        rp.set_bind_group(0, &bg, &[]);
                        rp.draw(0..3, 0..1);
                    }
                }
                stamp_encoder(encoder, 1);
            }
            (PassOp::Present { .. }, _) => {
                stamp_encoder(encoder, 0);
                stamp_encoder(encoder, 1);
            }
            _ => return Err(err("pass was not prepared".into())),
        }
        Ok(())
    }

    fn encode_clear(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        c: &ClearOp,
        parity: usize,
    ) -> Result<(), String> {
        match c {
            ClearOp::Attachment {
                texture,
                format,
                base_mip,
                mips,
                base_layer,
                layers,
                value,
                stencil,
            } => {
                let spec = &self.plan.textures[*texture];
                for mip in *base_mip..base_mip + mips {
                    for layer in *base_layer..base_layer + layers {
                        let view = self.view(
                            *texture,
                            parity,
                            mip,
                            layer,
                            if format.has_depth_aspect() {
                                None
                            } else {
                                Some(*format)
                            },
                        );
                        let depth = format.has_depth_aspect();
                        let color = [Some(wgpu::RenderPassColorAttachment {
                            view: &view,
                            depth_slice: (spec.dimension == wgpu::TextureDimension::D3)
                                .then_some(layer),
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color {
                                    r: value[0],
                                    g: value[1],
                                    b: value[2],
                                    a: value[3],
                                }),
                                store: wgpu::StoreOp::Store,
                            },
                        })];
                        let _rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("clear"),
                            color_attachments: if depth { &[] } else { &color },
                            depth_stencil_attachment: depth.then(|| {
                                wgpu::RenderPassDepthStencilAttachment {
                                    view: &view,
                                    depth_ops: Some(wgpu::Operations {
                                        load: wgpu::LoadOp::Clear(value[0] as f32),
                                        store: wgpu::StoreOp::Store,
                                    }),
                                    stencil_ops: has_stencil(*format).then_some(wgpu::Operations {
                                        load: wgpu::LoadOp::Clear(*stencil),
                                        store: wgpu::StoreOp::Store,
                                    }),
                                }
                            }),
                            timestamp_writes: None,
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                    }
                }
                Ok(())
            }
            ClearOp::Texture {
                texture,
                base_mip,
                mips,
                base_layer,
                layers,
                value,
            } => {
                if value.iter().any(|v| *v != 0.0) {
                    return Err(format!(
                        "clearing unordered-access texture \"{}\" to a non-zero value is not supported; clear it as a render target",
                        self.plan.textures[*texture].name
                    ));
                }
                let spec = &self.plan.textures[*texture];
                encoder.clear_texture(
                    &self.textures[*texture][parity],
                    &wgpu::ImageSubresourceRange {
                        aspect: wgpu::TextureAspect::All,
                        base_mip_level: *base_mip,
                        mip_level_count: Some(*mips),
                        base_array_layer: *base_layer,
                        array_layer_count: (spec.dimension != wgpu::TextureDimension::D3)
                            .then_some(*layers),
                    },
                );
                Ok(())
            }
            ClearOp::Buffer { buffer, value } => {
                let b = &self.buffers[*buffer][parity];
                if *value == 0 {
                    encoder.clear_buffer(b, 0, None);
                } else {
                    let words = vec![*value; (b.size() / 4) as usize];
                    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                    let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("clear value"),
                        size: b.size(),
                        usage: wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: true,
                    });
                    staging
                        .slice(..)
                        .get_mapped_range_mut()
                        .map_err(|e| e.to_string())?
                        .copy_from_slice(&bytes);
                    staging.unmap();
                    encoder.copy_buffer_to_buffer(&staging, 0, b, 0, b.size());
                }
                Ok(())
            }
        }
    }
}

/// Which bind-group set each draw or dispatch uses: 0 (the pass's) or, when it has its own
/// parameters, the next one made for its pipeline (keyed by entry point).
fn set_indices<'k>(items: impl Iterator<Item = (&'k str, bool)>) -> Vec<usize> {
    let mut next: BTreeMap<&str, usize> = BTreeMap::new();
    items
        .map(|(key, own)| {
            if own {
                let n = next.entry(key).or_insert(0);
                *n += 1;
                *n
            } else {
                0
            }
        })
        .collect()
}

fn extent(e: [u32; 3]) -> wgpu::Extent3d {
    wgpu::Extent3d {
        width: e[0].max(1),
        height: e[1].max(1),
        depth_or_array_layers: e[2].max(1),
    }
}

fn texel<'a>(
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

fn buffer_layout<'a>(
    b: &'a wgpu::Buffer,
    offset: u64,
    bytes_per_row: Option<u32>,
    spec: &TextureSpec,
    e: [u32; 3],
) -> wgpu::TexelCopyBufferInfo<'a> {
    let (bw, bh) = spec.format.block_dimensions();
    let block_bytes = spec
        .format
        .block_copy_size(Some(wgpu::TextureAspect::All))
        .unwrap_or(4);
    let row = e[0].div_ceil(bw) * block_bytes;
    let bytes_per_row = bytes_per_row.unwrap_or(row.div_ceil(256) * 256);
    wgpu::TexelCopyBufferInfo {
        buffer: b,
        layout: wgpu::TexelCopyBufferLayout {
            offset,
            bytes_per_row: Some(bytes_per_row),
            rows_per_image: Some(e[1].div_ceil(bh)),
        },
    }
}

/// A view of one mip and one layer (or the whole depth of a 3D mip).
pub(crate) fn single_view(
    t: &wgpu::Texture,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
    format: Option<wgpu::TextureFormat>,
) -> wgpu::TextureView {
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some(&spec.name),
        format,
        dimension: Some(if d3 {
            wgpu::TextureViewDimension::D3
        } else {
            wgpu::TextureViewDimension::D2
        }),
        usage: None,
        aspect: wgpu::TextureAspect::All,
        base_mip_level: mip,
        mip_level_count: Some(1),
        base_array_layer: if d3 { 0 } else { layer },
        array_layer_count: Some(1),
    })
}

/// Uploads every mip's contents.
fn write_texture(queue: &wgpu::Queue, t: &wgpu::Texture, spec: &TextureSpec, mips: &[Vec<u8>]) {
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

const MIP_SHADER: &str = "
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var smp: sampler;
struct V { @builtin(position) p: vec4<f32>, @location(0) uv: vec2<f32> }
@vertex fn vs(@builtin(vertex_index) i: u32) -> V {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return V(vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0), uv);
}
@fragment fn fs(v: V) -> @location(0) vec4<f32> { return textureSample(src, smp, v.uv); }
";
