//! Imported passes at wgpu level: each draw and dispatch keeps the Vulkan pipeline it was
//! recorded with. The pipeline's shaders are reflected (`crate::spirv`) to learn which
//! descriptors they use; those become bind group layout entries (a combined image sampler
//! becomes a texture and a sampler), the SPIR-V is rewritten to match (`shaders`), and the
//! draw's descriptors, vertex and index buffers, viewport, scissor and push constants become
//! its plan operation. Pipelines, layouts and rewritten shaders are shared between draws that
//! agree on them.
//!
//! wgpu numbers bindings its own way: `Role::Whole` and `Role::SplitImage` of Vulkan binding
//! `b` take wgpu binding `2b`, `Role::SplitSampler` takes `2b + 1`.

mod bindings;
mod blanks;
mod capabilities;
mod clears;
mod dynamic;
mod extended;
mod feedback;
mod frame_writes;
mod provoking;
mod shaders;
mod states;
mod strides;

use std::collections::{BTreeMap, HashMap};

use wgpu_types as wgpu;

use super::{LowerError, Lowering, PassError, formats};
use crate::capture::model::*;
use crate::capture::vk_model::*;
use crate::plan::*;
use crate::spirv::Reflection;

/// Why an imported draw or dispatch cannot be replayed. Messages name the shader and the
/// feature; `LowerError::Vulkan` adds the pass and the draw.
#[derive(Debug, thiserror::Error)]
pub enum VkProblem {
    #[error("uses {feature}, which the replay cannot do")]
    Unsupported { feature: String },
    #[error("shader {shader}: {error}")]
    Spirv {
        shader: String,
        error: crate::spirv::SpirvError,
    },
    #[error(
        "shader module \"{module}\" has no code in the capture (a JSON Lines import holds none)"
    )]
    NoCode { module: String },
    #[error("{0}")]
    Missing(String),
}

/// What the lowering of imported passes shares between draws.
#[derive(Default)]
pub(super) struct VkLowering {
    reflections: BTreeMap<(usize, String), Reflection>,
    shaders: HashMap<shaders::ShaderKey, usize>,
    pipelines: HashMap<PipelineKey, usize>,
    /// (Vulkan sampler, made nearest) -> plan sampler.
    samplers: BTreeMap<(usize, bool), usize>,
    /// Whether each shader module decorates anything flat (by module index).
    flat_modules: BTreeMap<usize, bool>,
    /// What the frame's passes write (`provoking::written`), found on first need.
    written: Option<provoking::Written>,
    /// Each shader module's uniform blocks laid out past std140 (by module index).
    beyond_std140: BTreeMap<usize, Vec<crate::spirv::BeyondStd140>>,
    /// Each shader module's words with its descriptor arrays split (`spirv::arrays`), where
    /// it has any (by module index).
    split_words: BTreeMap<usize, Option<std::sync::Arc<Vec<u32>>>>,
    /// (texture, level, layer) of a colour attachment -> the copy draws that read it bind.
    attachment_copies: HashMap<(usize, u32, u32), usize>,
    /// Vertex buffers copied to a layout wgpu takes (`strides`), by buffer, offset, stride and
    /// layout.
    repacked: HashMap<(ResourceId, u64, u32, strides::Relayout), usize>,
}

#[derive(Clone, PartialEq, Eq, Hash)]
struct PipelineKey {
    pipeline: usize,
    flip: bool,
    groups: Vec<Option<usize>>,
    targets: Vec<wgpu::TextureFormat>,
    depth: Option<wgpu::TextureFormat>,
    strip_index: Option<wgpu::IndexFormat>,
    /// Uniform texel buffers' formats, which the rewritten shaders read in.
    texel_formats: Vec<(u32, u32, rspirv::spirv::ImageFormat)>,
    /// Samplers' LOD bias the rewritten shaders add (set, binding, bits).
    lod_bias: Vec<(u32, u32, u32)>,
    /// Sampled views' swizzles the rewritten shaders apply (set, binding, codes).
    swizzles: Vec<(u32, u32, [u8; 4])>,
    /// The dynamic state baked into this variant (`dynamic::Baked::key`).
    baked: Option<String>,
    /// Drawn as a rearranged triangle list (`provoking`).
    listed: bool,
}

/// The wgpu stage and SPIR-V execution model of a `VK_SHADER_STAGE_*_BIT`.
/// Whether a draw under `g` produces no fragments: every polygon culled (`FRONT_AND_BACK`, which
/// culls triangles whatever their polygon mode, and not points or lines), or the rasterizer
/// discarding every primitive. wgpu has neither state; the draw is replayed as one of no
/// vertices, which writes what it does: nothing.
fn rasterizes_nothing(g: &crate::capture::format::GraphicsState) -> bool {
    g.rasterizer_discard || (g.cull_mode == 3 && g.topology.contains("TRIANGLE"))
}

fn stage_of(stage: &str) -> Result<(wgpu::ShaderStages, rspirv::spirv::ExecutionModel), VkProblem> {
    use rspirv::spirv::ExecutionModel as M;
    Ok(match stage {
        "VK_SHADER_STAGE_VERTEX_BIT" => (wgpu::ShaderStages::VERTEX, M::Vertex),
        "VK_SHADER_STAGE_FRAGMENT_BIT" => (wgpu::ShaderStages::FRAGMENT, M::Fragment),
        "VK_SHADER_STAGE_COMPUTE_BIT" => (wgpu::ShaderStages::COMPUTE, M::GLCompute),
        other => {
            return Err(VkProblem::Unsupported {
                feature: format!("a {other} stage (wgpu has vertex, fragment and compute)"),
            });
        }
    })
}

fn vk_error(p: &PassDesc, work: String, problem: VkProblem) -> LowerError {
    LowerError::Vulkan {
        pass: p.name.clone(),
        work,
        problem,
    }
}

/// Bytes of push constants wgpu is given: the layout's, rounded up to whole words.
fn immediate_size(layout: &VkPipelineLayout) -> u32 {
    layout.push_size.div_ceil(4) * 4
}

impl<'c> Lowering<'c> {
    /// Whether the pipeline's vertex shader declares a storage buffer or image it may write
    /// (wgpu's `VERTEX_WRITABLE_STORAGE`).
    fn vertex_writes_storage(&mut self, pipe: &VkPipeline) -> Result<bool, Fail> {
        for stage in &pipe.stages {
            if stage.stage != "VK_SHADER_STAGE_VERTEX_BIT" {
                continue;
            }
            let reflection = self.vk_reflect(stage.module, &stage.entry)?;
            if reflection.resources.iter().any(|r| {
                !r.non_writable
                    && matches!(
                        r.kind,
                        crate::spirv::ResourceKind::StorageBuffer
                            | crate::spirv::ResourceKind::StorageImage(_)
                    )
            }) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    fn vk_model(&self) -> Result<&'c VkModel, LowerError> {
        self.capture.vulkan.as_ref().ok_or_else(|| {
            LowerError::NotReplayable("an imported pass has no `vulkan` section".to_owned())
        })
    }

    pub(super) fn vk_raster(&mut self, p: &'c PassDesc) -> Result<PassOp, LowerError> {
        let color = self.color_targets(p)?;
        let mut depth = self.depth_target(p)?;
        // A depth or stencil aspect in a read-only layout that `vkCmdClearAttachments` clears
        // anyway (zink clears OpenArena's depth under each 3D HUD icon while the attachment is
        // DEPTH_STENCIL_READ_ONLY_OPTIMAL; drivers clear it): writable for the pass, which
        // changes nothing else, since no valid draw writes a read-only aspect.
        let cleared_read_only = depth.as_mut().is_some_and(|d| {
            let depth_cleared = p.attachment_clears.iter().any(|c| c.depth.is_some());
            let stencil_cleared = p.attachment_clears.iter().any(|c| c.stencil.is_some());
            let widen = depth_cleared && d.read_only || stencil_cleared && d.stencil_read_only;
            if widen {
                d.read_only &= !depth_cleared;
                d.stencil_read_only &= !stencil_cleared;
            }
            widen
        });
        let size = color
            .first()
            .map(|c| (c.texture, c.mip))
            .or(depth.as_ref().map(|d| (d.texture, d.mip)))
            .map(|(t, mip)| {
                let s = self.plan.textures[t].size;
                ((s.width >> mip).max(1), (s.height >> mip).max(1))
            })
            .unwrap_or((1, 1));
        let targets: Vec<wgpu::TextureFormat> = color.iter().map(|c| c.format).collect();
        let depth_format = depth.as_ref().map(|d| d.format);
        let mut draws = Vec::new();
        for (i, d) in p.draws.iter().enumerate() {
            let work = format!("draw {i}");
            let op = self
                .vk_draw(p, d, &targets, depth_format, size)
                .map_err(|e| match e {
                    Fail::Problem(problem) => vk_error(p, work, problem),
                    Fail::Lower(e) => e,
                })?;
            draws.push(op);
        }
        let fetches =
            self.vk_fetches(p, &mut draws, (&color, depth.as_ref()), cleared_read_only)?;
        if cleared_read_only {
            self.notes.push(format!(
                "pass \"{}\": vkCmdClearAttachments clears its depth/stencil attachment, which is in a read-only layout; the replay makes the attachment writable for the pass, as drivers clear it",
                p.name
            ));
        }
        let mut clears = Vec::new();
        for (i, c) in p.attachment_clears.iter().enumerate() {
            let op = clears::clear_op(c, &color, depth.as_ref(), size).map_err(|problem| {
                let work = format!("attachment clear {i} (before draw {})", c.before_draw);
                vk_error(p, work, problem)
            })?;
            clears.push(op);
        }
        let samples = color
            .first()
            .map(|c| c.texture)
            .or(depth.as_ref().map(|d| d.texture))
            .map_or(1, |t| self.plan.textures[t].samples);
        Ok(PassOp::VkRaster(VkRasterOp {
            color,
            depth,
            draws,
            clears,
            extent: [size.0, size.1],
            samples,
            fetches,
        }))
    }

    pub(super) fn vk_compute(&mut self, p: &'c PassDesc) -> Result<PassOp, LowerError> {
        let mut dispatches = Vec::new();
        for (i, d) in p.dispatches.iter().enumerate() {
            let work = format!("dispatch {i}");
            let op = self.vk_dispatch(p, d).map_err(|e| match e {
                Fail::Problem(problem) => vk_error(p, work, problem),
                Fail::Lower(e) => e,
            })?;
            dispatches.push(op);
        }
        Ok(PassOp::VkCompute(VkComputeOp { dispatches }))
    }

    fn vk_draw(
        &mut self,
        p: &'c PassDesc,
        d: &DrawDesc,
        targets: &[wgpu::TextureFormat],
        depth: Option<wgpu::TextureFormat>,
        (width, height): (u32, u32),
    ) -> Result<VkDrawOp, Fail> {
        let model = self.vk_model()?;
        let work = d.vk.as_deref().ok_or_else(|| {
            VkProblem::Missing("the draw names no pipeline (none was bound)".to_owned())
        })?;
        let pipe = &model.pipelines[work.pipeline];
        let g = pipe.graphics.as_deref().ok_or_else(|| {
            VkProblem::Missing(format!("pipeline {} has no graphics state", pipe.name))
        })?;
        // Where clamping depth changes nothing (`extended`): no depth attachment, or a
        // fixed-point one, and the depth range [0, 1].
        let clamp_moot = !matches!(
            depth,
            Some(wgpu::TextureFormat::Depth32Float | wgpu::TextureFormat::Depth32FloatStencil8)
        ) && work.viewport.is_none_or(|v| v[4] == 0.0 && v[5] == 1.0);
        let mut baked = dynamic::bake(pipe, g, work.dynamic.as_deref(), clamp_moot)?;
        let nothing = rasterizes_nothing(&baked.state);
        if nothing {
            self.no_writes_before_rasterization(pipe)?;
            let state = baked.state.to_mut();
            state.cull_mode = 0;
            state.rasterizer_discard = false;
            baked.key = Some(format!(
                "{}, rasterizes nothing",
                baked.key.unwrap_or_default()
            ));
        }
        let rebound = self.vk_vertex_layout(p, work, &mut baked)?;
        let g = &*baked.state;
        let (viewport, flip, scissor) = viewport_and_scissor(pipe, g, work, (width, height))?;
        let index = work
            .index_buffer
            .map(|(b, offset, wide)| {
                Ok::<_, Fail>((
                    self.buf(p, b)?,
                    offset,
                    if wide {
                        wgpu::IndexFormat::Uint32
                    } else {
                        wgpu::IndexFormat::Uint16
                    },
                ))
            })
            .transpose()?;
        // Flat inputs from the last vertex, and fans, are drawn as a rearranged list.
        let last = g.provoking_vertex_last && self.fragment_has_flat(pipe);
        let listed = if !nothing && (last || g.topology.ends_with("TRIANGLE_FAN")) {
            Some(self.as_triangle_list(p, d, work, g, last)?)
        } else {
            None
        };
        let (index, first, count, base_vertex) = match &listed {
            Some(l) => (Some(l.index), l.first, l.count, l.base_vertex),
            None => (index, d.first, d.count.unwrap_or(0), d.base_vertex),
        };
        let (groups, sets) = self.vk_groups(p, pipe, work)?;
        if g.blend.iter().any(states::uses_second_source) {
            *self.pass_features.entry(&p.name).or_default() |= wgpu::Features::DUAL_SOURCE_BLENDING;
        }
        // Polygons drawn as lines or points (zink's glPolygonMode) need the adapter's feature.
        let mode = match g.polygon_mode.trim_start_matches("VK_POLYGON_MODE_") {
            "LINE" if g.topology.contains("TRIANGLE") => wgpu::Features::POLYGON_MODE_LINE,
            "POINT" if g.topology.contains("TRIANGLE") => wgpu::Features::POLYGON_MODE_POINT,
            _ => wgpu::Features::empty(),
        };
        *self.pass_features.entry(&p.name).or_default() |= mode;
        if self.vertex_writes_storage(pipe)? {
            *self.pass_features.entry(&p.name).or_default() |=
                wgpu::Features::VERTEX_WRITABLE_STORAGE;
        }
        let key = PipelineKey {
            pipeline: work.pipeline,
            flip,
            groups: groups
                .iter()
                .map(|g| g.as_ref().map(|g| g.layout))
                .collect(),
            targets: targets.to_vec(),
            depth,
            strip_index: index.map(|i| i.2).filter(|_| listed.is_none()),
            texel_formats: sets.texel_formats.clone(),
            lod_bias: sets.lod_bias.clone(),
            swizzles: sets.swizzles.clone(),
            baked: baked.key.clone(),
            listed: listed.is_some(),
        };
        let pipeline = match self.vk.pipelines.get(&key) {
            Some(&i) => i,
            None => {
                let spec = self.vk_render_pipeline(pipe, g, &key, &sets)?;
                self.plan.vk.pipelines.push(spec);
                let i = self.plan.vk.pipelines.len() - 1;
                self.vk.pipelines.insert(key, i);
                i
            }
        };
        let vertex_buffers = work
            .vertex_buffers
            .iter()
            .map(
                |&(slot, b, offset)| match rebound.iter().find(|r| r.0 == slot) {
                    Some(&(_, copy)) => Ok((slot, copy, 0)),
                    None => Ok::<_, Fail>((slot, self.buf(p, b)?, offset)),
                },
            )
            .collect::<Result<Vec<_>, _>>()?;
        let layout = &model.pipeline_layouts[pipe.layout];
        Ok(VkDrawOp {
            pipeline,
            groups,
            vertex_buffers,
            index,
            viewport: Some(viewport),
            scissor,
            immediates: self.immediates(pipe, layout, work)?,
            blend_constant: g.blend.iter().any(states::uses_constant).then(|| {
                work.blend_constants
                    .unwrap_or(g.blend_constants)
                    .map(f64::from)
            }),
            stencil_reference: self.stencil_reference(pipe, g, work)?,
            // A draw that rasterizes nothing is one of no vertices.
            count: if nothing { 0 } else { count },
            instances: if nothing { 0 } else { d.instances },
            first,
            first_instance: d.first_instance,
            base_vertex,
            indirect: if nothing {
                None
            } else {
                self.indirect(p, d.indirect)?
            },
            draw_count: if nothing {
                None
            } else {
                self.draw_count(p, d.draw_count)?
            },
        })
    }

    /// The draw's vertex bindings as wgpu takes them: each attribute's binding has a buffer,
    /// and bindings wgpu does not take as laid out read a repacked copy, the baked state
    /// changed to match (binding, plan buffer of the copy).
    fn vk_vertex_layout(
        &mut self,
        p: &'c PassDesc,
        work: &VkWork,
        baked: &mut dynamic::Baked<'_>,
    ) -> Result<Vec<(u32, usize)>, Fail> {
        // An attribute reads its binding's buffer; with none bound (a null buffer, which the
        // nullDescriptor feature lets read zeros, or none ever bound) wgpu has nothing to
        // read from.
        for b in &baked.state.vertex_bindings {
            let reading: Vec<u32> = baked
                .state
                .vertex_attributes
                .iter()
                .filter(|a| a.binding == b.binding)
                .map(|a| a.location)
                .collect();
            if !reading.is_empty() && !work.vertex_buffers.iter().any(|v| v.0 == b.binding) {
                return Err(VkProblem::Unsupported {
                feature: format!(
                    "vertex binding {} with no buffer bound (null, or never bound), which the attributes at locations {reading:?} read",
                    b.binding
                ),
            }
            .into());
            }
        }
        // Bindings wgpu does not take as laid out (a stride not a multiple of 4, three
        // 8- or 16-bit channels) read a copy laid out as it does (`strides`).
        let mut rebound: Vec<(u32, usize)> = Vec::new();
        let mut relayouts = Vec::new();
        for b in &baked.state.vertex_bindings {
            let attributes = baked
                .state
                .vertex_attributes
                .iter()
                .filter(|a| a.binding == b.binding)
                .map(|a| {
                    let size = strides::widened(&a.format).map_or_else(
                        || states::vertex_format(&a.format).map(|f| f.size() as u32),
                        |(_, channel)| Ok(3 * channel),
                    )?;
                    Ok((a, size))
                })
                .collect::<Result<Vec<_>, VkProblem>>()?;
            if let Some(layout) = strides::relayout(b.stride, &attributes) {
                relayouts.push((b.binding, b.stride, layout));
            }
        }
        for (binding, stride, layout) in relayouts {
            let Some(&(_, buffer, offset)) = work.vertex_buffers.iter().find(|v| v.0 == binding)
            else {
                continue;
            };
            rebound.push((
                binding,
                self.vk_repacked(p, buffer, offset, stride, &layout)?,
            ));
            let state = baked.state.to_mut();
            for b in state
                .vertex_bindings
                .iter_mut()
                .filter(|b| b.binding == binding)
            {
                b.stride = layout.stride;
            }
            let mine = state
                .vertex_attributes
                .iter_mut()
                .filter(|a| a.binding == binding);
            for (a, (at, format)) in mine.zip(&layout.attributes) {
                a.offset = *at;
                a.format.clone_from(format);
            }
            baked.key = Some(format!(
                "{}, binding {binding} laid out as {:?}",
                baked.key.take().unwrap_or_default(),
                layout
            ));
        }
        Ok(rebound)
    }

    /// A draw that rasterizes nothing still runs its vertex stage, whose storage writes would
    /// be lost with the draw: refused where a stage before rasterization writes storage.
    fn no_writes_before_rasterization(&mut self, pipe: &VkPipeline) -> Result<(), Fail> {
        let model = self.vk_model()?;
        for stage in &pipe.stages {
            let (s, _) = stage_of(&stage.stage)?;
            if s == wgpu::ShaderStages::FRAGMENT {
                continue;
            }
            let shader = model.modules[stage.module].name.clone();
            for var in &self.vk_reflect(stage.module, &stage.entry)?.resources {
                let storage = matches!(
                    var.kind,
                    crate::spirv::ResourceKind::StorageBuffer
                        | crate::spirv::ResourceKind::StorageImage(_)
                        | crate::spirv::ResourceKind::StorageTexelBuffer(_)
                );
                if storage && !var.non_writable {
                    return Err(VkProblem::Unsupported {
                        feature: format!(
                            "a draw that rasterizes nothing (every polygon culled, or the rasterizer discarding) whose shader {shader} writes set {} binding {} before rasterization",
                            var.set, var.binding
                        ),
                    }
                    .into());
                }
            }
        }
        Ok(())
    }

    fn vk_dispatch(&mut self, p: &'c PassDesc, d: &DispatchDesc) -> Result<VkDispatchOp, Fail> {
        let model = self.vk_model()?;
        let work = d.vk.as_deref().ok_or_else(|| {
            VkProblem::Missing("the dispatch names no pipeline (none was bound)".to_owned())
        })?;
        let pipe = &model.pipelines[work.pipeline];
        let (groups, sets) = self.vk_groups(p, pipe, work)?;
        let key = PipelineKey {
            pipeline: work.pipeline,
            flip: false,
            groups: groups
                .iter()
                .map(|g| g.as_ref().map(|g| g.layout))
                .collect(),
            targets: Vec::new(),
            depth: None,
            strip_index: None,
            texel_formats: sets.texel_formats.clone(),
            lod_bias: sets.lod_bias.clone(),
            swizzles: sets.swizzles.clone(),
            baked: None,
            listed: false,
        };
        let pipeline = match self.vk.pipelines.get(&key) {
            Some(&i) => i,
            None => {
                let stage = pipe
                    .stages
                    .iter()
                    .find(|s| s.stage == "VK_SHADER_STAGE_COMPUTE_BIT")
                    .ok_or_else(|| {
                        VkProblem::Missing(format!("pipeline {} has no compute stage", pipe.name))
                    })?;
                let shader = self.vk_shader(pipe, stage, (false, false), &sets, None, &[])?;
                let layout = &model.pipeline_layouts[pipe.layout];
                self.plan.vk.pipelines.push(VkPipelineSpec {
                    name: pipe.name.clone(),
                    groups: key.groups.clone(),
                    immediate_size: immediate_size(layout),
                    kind: VkPipelineKind::Compute { shader },
                });
                let i = self.plan.vk.pipelines.len() - 1;
                self.vk.pipelines.insert(key, i);
                i
            }
        };
        let layout = &model.pipeline_layouts[pipe.layout];
        Ok(VkDispatchOp {
            pipeline,
            groups,
            immediates: self.immediates(pipe, layout, work)?,
            workgroups: d.groups,
            indirect: self.indirect(p, d.indirect)?,
        })
    }

    /// The stencil reference a draw tests with: set by the command buffer where the pipeline
    /// makes it dynamic, else the pipeline's. wgpu has one reference for both faces.
    fn stencil_reference(
        &self,
        pipe: &VkPipeline,
        g: &crate::capture::format::GraphicsState,
        work: &VkWork,
    ) -> Result<Option<u32>, Fail> {
        let Some(ds) = g.depth_stencil.as_ref().filter(|s| s.stencil_test) else {
            return Ok(None);
        };
        let dynamic = g
            .dynamic_states
            .iter()
            .any(|s| s.ends_with("STENCIL_REFERENCE"));
        let [front, back] = if dynamic {
            work.stencil_reference.ok_or_else(|| {
                VkProblem::Missing(format!(
                    "pipeline {} has a dynamic stencil reference the draw never set",
                    pipe.name
                ))
            })?
        } else {
            [
                ds.front.as_ref().map_or(0, |f| f.reference),
                ds.back.as_ref().map_or(0, |f| f.reference),
            ]
        };
        if front != back {
            return Err(VkProblem::Unsupported {
                feature: format!("different stencil references per face ({front}, {back})"),
            }
            .into());
        }
        Ok(Some(front))
    }

    /// The push-constant bytes a draw or dispatch gives wgpu: the recorded ones, zero-padded
    /// to the layout's size.
    fn immediates(
        &self,
        pipe: &VkPipeline,
        layout: &VkPipelineLayout,
        work: &VkWork,
    ) -> Result<Vec<u8>, Fail> {
        let size = immediate_size(layout) as usize;
        if size == 0 {
            return Ok(Vec::new());
        }
        let model = self.vk_model()?;
        // A layout may declare push constants no stage reads (Mesa's zink declares them on
        // every pipeline); then there is nothing to give but the bytes wgpu asks for.
        let read = pipe.stages.iter().any(|s| {
            model.modules[s.module]
                .words
                .as_deref()
                .is_none_or(|w| crate::spirv::reads_push_constants(w))
        });
        let mut bytes = match work.push_constants.clone() {
            Some(bytes) => bytes,
            None if !read => Vec::new(),
            None => {
                return Err(VkProblem::Missing(format!(
                    "pipeline {} reads {} bytes of push constants and the capture holds no values",
                    pipe.name, layout.push_size
                ))
                .into());
            }
        };
        bytes.resize(size, 0);
        Ok(bytes)
    }

    /// Whether `pipe`'s fragment shader has flat inputs, whose value the provoking vertex
    /// decides. A module that does not parse counts as having some.
    fn fragment_has_flat(&mut self, pipe: &VkPipeline) -> bool {
        let Ok(model) = self.vk_model() else {
            return true;
        };
        let mut flat = false;
        for stage in &pipe.stages {
            if !stage.stage.contains("FRAGMENT") {
                continue;
            }
            let words = model.modules[stage.module]
                .words
                .as_deref()
                .map_or(&[][..], |w| &w[..]);
            flat |= *self
                .vk
                .flat_modules
                .entry(stage.module)
                .or_insert_with(|| crate::spirv::has_flat(words));
        }
        flat
    }

    /// Draw `d` as an indexed triangle list, each triangle from its provoking vertex
    /// (`provoking`); `last`: the last vertex provokes.
    fn as_triangle_list(
        &mut self,
        p: &'c PassDesc,
        d: &DrawDesc,
        work: &VkWork,
        g: &crate::capture::format::GraphicsState,
        last: bool,
    ) -> Result<provoking::Listed, Fail> {
        let indices = match work.index_buffer {
            Some((b, offset, wide)) => {
                let (start, end) =
                    provoking::index_bytes(offset, d.first, d.count.unwrap_or(0), wide);
                let held = !self.vk_frame_changes(b, start, end);
                let plan = self.buf(p, b)?;
                let bytes = self.plan.buffers[plan].initial.as_deref().filter(|_| held);
                Some((bytes, offset, wide))
            }
            None => None,
        };
        let draw = provoking::Draw {
            topology: &g.topology,
            primitive_restart: g.primitive_restart,
            count: d.count.unwrap_or(0),
            first: d.first,
            base_vertex: d.base_vertex,
            indirect: d.indirect.is_some(),
            indices,
        };
        let (indices, base_vertex) = provoking::list_indices(&draw, last)?;
        let name = format!("{}: indices as a triangle list", p.name);
        Ok(provoking::index_buffer(
            &mut self.plan.buffers,
            name,
            &indices,
            base_vertex,
        ))
    }

    fn vk_render_pipeline(
        &mut self,
        pipe: &VkPipeline,
        g: &crate::capture::format::GraphicsState,
        key: &PipelineKey,
        sets: &bindings::Bound,
    ) -> Result<VkPipelineSpec, Fail> {
        let model = self.vk_model()?;
        let listed;
        let g = if key.listed {
            listed = crate::capture::format::GraphicsState {
                topology: "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST".to_owned(),
                primitive_restart: false,
                ..g.clone()
            };
            &listed
        } else {
            g
        };
        // Attributes in scaled and packed formats are fetched as integers and converted in
        // the shader.
        let mut scaled = Vec::new();
        for a in &g.vertex_attributes {
            if let Some(fetch) = states::integer_fetch(&a.format) {
                scaled.push((a.location, fetch));
            }
        }
        let mut vertex = None;
        let mut fragment = None;
        // Attachment i takes the output at location i.
        let attached = u32::try_from(key.targets.len())
            .ok()
            .and_then(|n| 1u32.checked_shl(n))
            .map_or(u32::MAX, |bit| bit - 1);
        for stage in &pipe.stages {
            let (s, _) = stage_of(&stage.stage)?;
            let shader = self.vk_shader(
                pipe,
                stage,
                (key.flip, g.depth_negative_one_to_one),
                sets,
                Some(attached),
                &scaled,
            )?;
            if s == wgpu::ShaderStages::VERTEX {
                vertex = Some(shader);
            } else if s == wgpu::ShaderStages::FRAGMENT {
                fragment = Some(shader);
            }
        }
        let vertex = vertex.ok_or_else(|| {
            VkProblem::Missing(format!("pipeline {} has no vertex stage", pipe.name))
        })?;
        let mut buffers = Vec::new();
        for b in &g.vertex_bindings {
            let mut attributes = Vec::new();
            for a in g
                .vertex_attributes
                .iter()
                .filter(|a| a.binding == b.binding)
            {
                attributes.push(wgpu::VertexAttribute {
                    format: states::vertex_format(&a.format)?,
                    offset: u64::from(a.offset),
                    shader_location: a.location,
                });
            }
            buffers.push(VkVertexLayout {
                slot: b.binding,
                stride: u64::from(b.stride),
                step: if b.input_rate.ends_with("INSTANCE") {
                    wgpu::VertexStepMode::Instance
                } else {
                    wgpu::VertexStepMode::Vertex
                },
                attributes,
            });
        }
        let samples = g
            .samples
            .trim_start_matches("VK_SAMPLE_COUNT_")
            .trim_end_matches("_BIT")
            .parse::<u32>()
            .map_err(|_| VkProblem::Unsupported {
                feature: format!("sample count {}", g.samples),
            })?;
        if g.logic_op.is_some() {
            return Err(VkProblem::Unsupported {
                feature: format!("logic ops (pipeline {})", pipe.name),
            }
            .into());
        }
        if g.alpha_to_one {
            return Err(VkProblem::Unsupported {
                feature: format!("alpha to one (pipeline {}): wgpu has none", pipe.name),
            }
            .into());
        }
        let targets = key
            .targets
            .iter()
            .enumerate()
            .map(|(i, &f)| states::color_target(f, g.blend.get(i)).map(Some))
            .collect::<Result<Vec<_>, _>>()?;
        let layout = &model.pipeline_layouts[pipe.layout];
        let bias = key.depth.and_then(|_| states::bias_rounding(g));
        for note in bias
            .into_iter()
            .chain(states::restart_note(g, key.strip_index))
            .chain(states::lines(g)?)
        {
            let note = format!("pipeline {}: {note}", pipe.name);
            if !self.notes.contains(&note) {
                self.notes.push(note);
            }
        }
        Ok(VkPipelineSpec {
            name: pipe.name.clone(),
            groups: key.groups.clone(),
            immediate_size: immediate_size(layout),
            kind: VkPipelineKind::Render(Box::new(VkRenderPipeline {
                vertex,
                fragment,
                buffers,
                primitive: states::primitive(g, key.strip_index)?,
                depth_stencil: key.depth.map(|f| states::depth_stencil(g, f)).transpose()?,
                targets,
                samples,
                alpha_to_coverage: g.alpha_to_coverage,
                sample_mask: g.sample_mask.map_or(!0, u64::from),
            })),
        })
    }

    /// The plan sampler of a Vulkan sampler, added on first use; `nearest`: with every filter
    /// nearest and no anisotropy (`vk_sampler_entry` says when).
    fn vk_sampler(&mut self, s: usize, nearest: bool) -> Result<usize, Fail> {
        if let Some(&i) = self.vk.samplers.get(&(s, nearest)) {
            return Ok(i);
        }
        let model = self.vk_model()?;
        let mut spec = states::sampler(&model.samplers[s])?;
        if nearest {
            spec.name = format!("{} (nearest)", spec.name);
            spec.mag = wgpu::FilterMode::Nearest;
            spec.min = wgpu::FilterMode::Nearest;
            spec.mip = wgpu::MipmapFilterMode::Nearest;
            spec.anisotropy = 1;
        }
        if let Some(note) = states::anisotropic_nearest(&model.samplers[s]) {
            self.notes.push(note);
        }
        self.plan.samplers.push(spec);
        let i = self.plan.samplers.len() - 1;
        self.vk.samplers.insert((s, nearest), i);
        Ok(i)
    }

    /// The wgpu format a `VK_FORMAT_*` view of texture `t` reads through.
    /// How view `v` of a 16-bit packed image held as RGBA8 reads the image's channels, where
    /// its layout orders the same bit fields otherwise (`packed16::view_permutation`).
    pub(super) fn vk_view_permutation(&self, v: usize) -> Option<[u8; 4]> {
        let model = self.vk_model().ok()?;
        let view = &model.views[v];
        let image = self.capture.resource(view.image).format?.name;
        let (held, seen) = (
            super::packed16::layout(image)?,
            super::packed16::layout(&view.format)?,
        );
        (held != seen).then(|| super::packed16::view_permutation(held, seen))?
    }

    fn vk_view_format(
        &self,
        p: &PassDesc,
        t: usize,
        vk: &str,
    ) -> Result<wgpu::TextureFormat, Fail> {
        let info = crate::capture::dxgi::lookup_vk(vk).ok_or_else(|| VkProblem::Unsupported {
            feature: format!("view format {vk}"),
        })?;
        let texture = &self.plan.textures[t];
        let view = formats::twin(info.name)
            .map_err(|e| super::passes::pass_error(p, PassError::ViewFormat(e)))?;
        // A 16-bit packed image held as RGBA8 is viewed in a layout of its own bit fields
        // (read through a swizzle, `vk_view_permutation`) or not at all.
        if let Some(&(image, formats::Repack::Unpack16(held))) = self.repacked.get(&t)
            && let Some(layout) = super::packed16::layout(info.name)
            && layout != held
            && super::packed16::view_permutation(held, layout).is_none()
        {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a {vk} view of \"{}\" ({image}): its bit fields are not the image's",
                    texture.name
                ),
            }
            .into());
        }
        // A Vulkan view may reinterpret a mutable-format image's bits in any format of its
        // size class; wgpu views a texture only in its own format or its sRGB twin (listed at
        // its creation, `view_formats`). Anything else would read other numbers: refused.
        if view.remove_srgb_suffix() == texture.format.remove_srgb_suffix() {
            return Ok(view);
        }
        Err(VkProblem::Unsupported {
            feature: format!(
                "a {vk} view of \"{}\" ({:?}): wgpu views a texture only in its own format or its sRGB twin",
                texture.name, texture.format
            ),
        }
        .into())
    }
}

/// A lowering error, or a problem `vk_raster` and `vk_compute` turn into one naming the draw.
pub(super) enum Fail {
    Problem(VkProblem),
    Lower(LowerError),
}

impl From<VkProblem> for Fail {
    fn from(p: VkProblem) -> Self {
        Fail::Problem(p)
    }
}

impl From<LowerError> for Fail {
    fn from(e: LowerError) -> Self {
        Fail::Lower(e)
    }
}

/// A draw's viewport (x, y, width, height, min and max depth), whether its shader flips y,
/// and its scissor (x, y, width, height).
type DrawArea = ([f32; 6], bool, Option<[u32; 4]>);

/// The viewport a draw renders with (wgpu's clip space: a Vulkan viewport of negative height
/// turned over), whether the shader must flip y, and the scissor within the target.
fn viewport_and_scissor(
    pipe: &VkPipeline,
    g: &crate::capture::format::GraphicsState,
    work: &VkWork,
    (width, height): (u32, u32),
) -> Result<DrawArea, Fail> {
    // Vulkan's viewport may have a negative height (the application flips y itself):
    // then its clip space is already wgpu's, and the shader is left as it is.
    let viewport = match work.viewport {
        Some(v) => v,
        None => {
            let v = g.viewports.first().ok_or_else(|| {
                VkProblem::Missing(format!(
                    "pipeline {} has a dynamic viewport the draw never set",
                    pipe.name
                ))
            })?;
            [v[0], v[1], v[2], v[3], 0.0, 1.0]
        }
    };
    let flip = viewport[3] >= 0.0;
    let viewport = if flip {
        viewport
    } else {
        [
            viewport[0],
            viewport[1] + viewport[3],
            viewport[2],
            -viewport[3],
            viewport[4],
            viewport[5],
        ]
    };
    let scissor = work.scissor.or(g.scissors.first().copied()).map(|s| {
        let x0 = s[0].clamp(0, i64::from(width));
        let y0 = s[1].clamp(0, i64::from(height));
        let x1 = s[0].saturating_add(s[2]).clamp(x0, i64::from(width));
        let y1 = s[1].saturating_add(s[3]).clamp(y0, i64::from(height));
        [x0 as u32, y0 as u32, (x1 - x0) as u32, (y1 - y0) as u32]
    });
    Ok((viewport, flip, scissor))
}
