//! Pipelines with automatic layouts for raster and compute passes (one per entry point), their
//! bind groups, and the blit pipeline that generates mips.

use std::collections::{BTreeMap, BTreeSet};

use framelab_core::plan::{ComputeOp, CopyEnd, DrawOp, PassOp, RasterOp, StreamSpec, TextureSpec};

use super::bindings::set_indices;
use super::{Prepared, ReplayError, Session, close, scope};
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

pub(super) fn buffer_layout<'a>(
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

/// The stages a raster draw's pipeline runs, which tell its pipelines apart: the draw's vertex
/// entry point (else the pass's) and its fragment entry point (the draw's own, else the
/// pass's; none for a depth-only draw).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Stages {
    pub vertex: String,
    pub fragment: Option<String>,
}

impl Stages {
    pub fn of(d: &DrawOp, r: &RasterOp) -> Stages {
        Stages {
            vertex: d.vertex.clone().unwrap_or_else(|| r.vertex.clone()),
            fragment: match d.depth_only {
                true => None,
                false => d.fragment.clone().or_else(|| r.fragment.clone()),
            },
        }
    }
}

impl std::fmt::Display for Stages {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.fragment {
            Some(fragment) => write!(f, "{} + {fragment}", self.vertex),
            None => write!(f, "{} (no fragment stage)", self.vertex),
        }
    }
}

impl Session {
    pub(super) fn prepare(&mut self, index: usize) -> Result<Prepared, ReplayError> {
        let pass = self.plan.passes[index].clone();
        let name = pass.name.clone();
        let g = scope(&self.device);
        let prepared = match &pass.op {
            PassOp::Raster(r) => self.prepare_raster(&name, r)?,
            PassOp::Compute(c) => self.prepare_compute(&name, c)?,
            PassOp::VkRaster(r) => Prepared::VkWork(
                self.vk_work_groups(&name, r.draws.iter().map(|d| &d.groups[..]).collect())?,
            ),
            PassOp::VkCompute(c) => Prepared::VkWork(
                self.vk_work_groups(&name, c.dispatches.iter().map(|d| &d.groups[..]).collect())?,
            ),
            PassOp::Blit(blits) => Prepared::Blit(self.prepare_blits(blits)),
            PassOp::Copy(copies) if copies.iter().any(|c| c.unpack.is_some() || c.depth) => {
                if copies.iter().any(|c| c.unpack.is_some()) {
                    self.unpack_pipeline();
                }
                for c in copies.iter().filter(|c| c.depth) {
                    if let CopyEnd::Texture { texture, .. } = c.dst {
                        self.depth_copies
                            .make(&self.device, self.plan.textures[texture].format);
                    }
                }
                Prepared::Other
            }
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

    /// The sample count of a raster pass: its first colour target's, else its depth
    /// target's, else one.
    fn raster_samples(&self, r: &RasterOp) -> u32 {
        r.color
            .first()
            .map(|c| self.plan.textures[c.texture].samples)
            .or(r
                .depth
                .as_ref()
                .map(|d| self.plan.textures[d.texture].samples))
            .unwrap_or(1)
    }

    pub(super) fn prepare_raster(&self, name: &str, r: &RasterOp) -> Result<Prepared, ReplayError> {
        let m = &self.modules[r.shader];
        let err = |message: String| ReplayError::Pass {
            pass: name.to_owned(),
            message,
        };
        // Pipelines only for the stages some draw uses (the pass's default entry may be
        // overridden by every draw, and then has no mesh to take a layout from).
        let mut entries: BTreeSet<Stages> = r.draws.iter().map(|d| Stages::of(d, r)).collect();
        if entries.is_empty() {
            entries.insert(Stages {
                vertex: r.vertex.clone(),
                fragment: r.fragment.clone(),
            });
        }
        let targets = color_targets(r);
        let samples = self.raster_samples(r);
        let mut pipelines = BTreeMap::new();
        let mut groups = BTreeMap::new();
        let all_used = self.used_by(
            r.shader,
            entries
                .iter()
                .flat_map(|s| std::iter::once(&s.vertex).chain(&s.fragment))
                .chain(r.fragment.iter()),
        );
        let pass_params = self.params_buffer(name, r.shader, &r.params, &all_used)?;
        for key in &entries {
            // A depth-only draw's pipeline has no fragment stage, so binds only what the
            // vertex stage reads.
            let (vertex, fragment) = (&key.vertex, key.fragment.as_ref());
            let mut used = m
                .reflection
                .globals_used_by(vertex)
                .ok_or_else(|| err(format!("the shader has no vertex entry point `{vertex}`")))?;
            if let Some(f) = fragment {
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
                    fragment: fragment.map(|f| wgpu::FragmentState {
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
                .filter(|d| !d.params.is_empty() && &Stages::of(d, r) == key)
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
            groups.insert(key.clone(), sets);
            pipelines.insert(key.clone(), pipeline);
        }
        let draw_groups = set_indices(
            r.draws
                .iter()
                .map(|d| (Stages::of(d, r), !d.params.is_empty())),
        );
        Ok(Prepared::Raster {
            pipelines,
            groups,
            draw_groups,
        })
    }

    pub(super) fn prepare_compute(
        &self,
        name: &str,
        c: &ComputeOp,
    ) -> Result<Prepared, ReplayError> {
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
            if let Some(why) = m
                .reflection
                .compute_limits_exceeded(entry, &self.device.limits())
            {
                return Err(err(why));
            }
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

    /// A full-screen blit that downsamples one mip into the next.
    pub(super) fn mip_pipeline(&mut self, format: wgpu::TextureFormat) {
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
        let pipeline = fullscreen_pipeline(
            &self.device,
            "mip generation",
            (&module, "fs"),
            None,
            format,
        );
        let sampler = self.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("mip generation"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        self.mip_pipelines.insert(key, (pipeline, sampler));
    }
}

/// A pipeline drawing one full-target triangle (vertex entry `vs`, no vertex buffers) into one
/// colour target of `format`, with `fragment` of `module`: mip generation and blits.
pub(super) fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    (module, fragment): (&wgpu::ShaderModule, &str),
    layout: Option<&wgpu::PipelineLayout>,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A raster pass's colour targets as its pipelines write them.
fn color_targets(r: &RasterOp) -> Vec<Option<wgpu::ColorTargetState>> {
    r.color
        .iter()
        .map(|c| {
            Some(wgpu::ColorTargetState {
                format: c.format,
                blend: c.blend,
                write_mask: c.write_mask,
            })
        })
        .collect()
}
