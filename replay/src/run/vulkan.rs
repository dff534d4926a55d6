//! The GPU objects of an imported frame's Vulkan pipelines, and encoding its passes. A
//! pipeline takes the naga path when every stage has a module naga accepted and wgpu accepts
//! the pipeline made from them (wgpu checks the stages against the explicit layouts and
//! against each other); otherwise its stages go to the driver as they are (passthrough),
//! which is why the core validated and rewrote them first. The path each shader took is kept
//! for the summary. Bind groups are made once per distinct set of bindings and shared by every
//! draw and dispatch that binds the same.

use std::borrow::Cow;
use std::collections::HashMap;

use framelab_core::plan::{
    ShaderPath, SpirvShader, VkComputeOp, VkGroup, VkPipelineKind, VkPipelineSpec, VkRasterOp,
    VkResource,
};

use super::{ReplayError, Session, close, scope};

pub(super) enum VkGpuPipeline {
    Render(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

/// An imported frame's pipelines and bind groups, and the path each shader took.
#[derive(Default)]
pub(super) struct VkObjects {
    pub(super) pipelines: Vec<VkGpuPipeline>,
    pub(super) groups: Vec<wgpu::BindGroup>,
    group_index: HashMap<VkGroup, usize>,
    pub(super) paths: Vec<(String, ShaderPath)>,
    /// Buffer ranges bound at offsets below wgpu's alignment, copied into buffers of their
    /// own (`Shadow`); the shadows each group binds, parallel to `groups`.
    shadows: Vec<Shadow>,
    shadow_index: HashMap<(usize, u64, u64), usize>,
    group_shadows: Vec<Vec<usize>>,
}

/// A buffer range a Vulkan program bound at an offset its device allowed and wgpu does not
/// (Vulkan devices align uniform offsets to as little as 16 bytes; wgpu asks 32 or more), or
/// that runs past its buffer's end (a uniform block rounded up to its whole size): the range
/// is copied into a buffer of its own before each pass that binds it, bound there at offset
/// 0, and copied back after the pass where the shader may write it.
struct Shadow {
    source: usize,
    offset: u64,
    size: u64,
    writable: bool,
    buffer: wgpu::Buffer,
}

/// Shader modules made so far, per path.
#[derive(Default)]
struct Modules {
    naga: HashMap<usize, wgpu::ShaderModule>,
    passthrough: HashMap<usize, wgpu::ShaderModule>,
}

/// Bind group indices of each draw or dispatch of a pass, by set.
pub(super) type WorkGroups = Vec<Vec<Option<usize>>>;

/// The draws one wgpu render pass of an imported pass records: all of them, or a piece of a
/// pass split where its draws read what it renders (`fetch`).
pub(super) struct Segment {
    pub draws: std::ops::Range<usize>,
    pub first: bool,
    pub last: bool,
}

/// The one place framelab hands the driver code wgpu has not checked.
#[allow(unsafe_code)]
fn passthrough(device: &wgpu::Device, s: &SpirvShader) -> wgpu::ShaderModule {
    // SAFETY: the words were loaded, reflected and rewritten by framelab's SPIR-V module
    // (`framelab_core::spirv`), which refuses malformed modules and what the replay cannot
    // do; every binding they use is in the layout made from that reflection.
    unsafe {
        device.create_shader_module_passthrough(wgpu::ShaderModuleDescriptorPassthrough {
            label: Some(&s.name),
            entry_points: Cow::Owned(vec![wgpu::PassthroughShaderEntryPoint {
                name: Cow::Borrowed(&s.entry),
                workgroup_size: (s.workgroup[0], s.workgroup[1], s.workgroup[2]),
            }]),
            spirv: Some(Cow::Borrowed(&s.passthrough)),
            ..Default::default()
        })
    }
}

fn setup(what: String, message: String) -> ReplayError {
    ReplayError::Setup { what, message }
}

fn shaders_of(p: &VkPipelineSpec) -> Vec<usize> {
    match &p.kind {
        VkPipelineKind::Compute { shader } => vec![*shader],
        VkPipelineKind::Render(r) => std::iter::once(r.vertex).chain(r.fragment).collect(),
    }
}

impl Session {
    /// Creates every bind group layout and pipeline of the plan's Vulkan half, with the shader
    /// modules they use.
    pub(super) fn create_vk(&mut self) -> Result<(), ReplayError> {
        if self.plan.vk.is_empty() {
            return Ok(());
        }
        let layouts: Vec<wgpu::BindGroupLayout> = self
            .plan
            .vk
            .group_layouts
            .iter()
            .map(|entries| {
                self.device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: None,
                        entries,
                    })
            })
            .collect();
        let mut modules = Modules::default();
        let mut pipelines = Vec::new();
        let mut paths = Vec::new();
        for p in &self.plan.vk.pipelines {
            let stages = shaders_of(p);
            let naga = stages
                .iter()
                .all(|&s| self.plan.vk.shaders[s].naga.is_some());
            let mut tried = Vec::new();
            let mut made = None;
            for path in [ShaderPath::Naga, ShaderPath::Passthrough] {
                if path == ShaderPath::Naga && !naga {
                    continue;
                }
                let scopes = scope(&self.device);
                let pipeline = self.vk_pipeline(p, &layouts, &mut modules, path);
                match close(scopes) {
                    None => {
                        made = Some((pipeline, path));
                        break;
                    }
                    Some(message) => tried.push(format!("{} path: {message}", path.name())),
                }
            }
            let Some((pipeline, path)) = made else {
                return Err(setup(format!("pipeline {}", p.name), tried.join("; ")));
            };
            for &s in &stages {
                paths.push((self.plan.vk.shaders[s].name.clone(), path));
            }
            pipelines.push(pipeline);
        }
        paths.sort_by(|a, b| a.0.cmp(&b.0));
        paths.dedup();
        self.vk.pipelines = pipelines;
        self.vk.paths = paths;
        self.vk_layouts = layouts;
        Ok(())
    }

    /// The path each imported shader took to the device, by shader name.
    pub fn shader_paths(&self) -> &[(String, ShaderPath)] {
        &self.vk.paths
    }

    fn vk_module<'m>(
        &self,
        modules: &'m mut Modules,
        s: usize,
        path: ShaderPath,
    ) -> &'m wgpu::ShaderModule {
        let shader = &self.plan.vk.shaders[s];
        match path {
            ShaderPath::Naga => modules.naga.entry(s).or_insert_with(|| {
                let words = shader.naga.as_deref().unwrap_or(&shader.passthrough);
                self.device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(&shader.name),
                        source: wgpu::ShaderSource::SpirV(Cow::Borrowed(words)),
                    })
            }),
            ShaderPath::Passthrough => modules
                .passthrough
                .entry(s)
                .or_insert_with(|| passthrough(&self.device, shader)),
        }
    }

    fn vk_pipeline(
        &self,
        p: &VkPipelineSpec,
        layouts: &[wgpu::BindGroupLayout],
        modules: &mut Modules,
        path: ShaderPath,
    ) -> VkGpuPipeline {
        let vk = &self.plan.vk;
        let groups: Vec<Option<&wgpu::BindGroupLayout>> =
            p.groups.iter().map(|g| g.map(|i| &layouts[i])).collect();
        let layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&p.name),
                bind_group_layouts: &groups,
                immediate_size: p.immediate_size,
            });
        match &p.kind {
            VkPipelineKind::Compute { shader } => {
                let module = self.vk_module(modules, *shader, path).clone();
                VkGpuPipeline::Compute(self.device.create_compute_pipeline(
                    &wgpu::ComputePipelineDescriptor {
                        label: Some(&p.name),
                        layout: Some(&layout),
                        module: &module,
                        entry_point: Some(&vk.shaders[*shader].entry),
                        compilation_options: Default::default(),
                        cache: None,
                    },
                ))
            }
            VkPipelineKind::Render(r) => {
                let mut slots: Vec<Option<wgpu::VertexBufferLayout<'_>>> = Vec::new();
                for b in &r.buffers {
                    let slot = b.slot as usize;
                    if slots.len() <= slot {
                        slots.resize(slot + 1, None);
                    }
                    slots[slot] = Some(wgpu::VertexBufferLayout {
                        array_stride: b.stride,
                        step_mode: b.step,
                        attributes: &b.attributes,
                    });
                }
                let vertex = self.vk_module(modules, r.vertex, path).clone();
                let fragment_module = r.fragment.map(|f| self.vk_module(modules, f, path).clone());
                let fragment = r.fragment.zip(fragment_module.as_ref()).map(|(f, module)| {
                    wgpu::FragmentState {
                        module,
                        entry_point: Some(&vk.shaders[f].entry),
                        compilation_options: Default::default(),
                        targets: &r.targets,
                    }
                });
                VkGpuPipeline::Render(self.device.create_render_pipeline(
                    &wgpu::RenderPipelineDescriptor {
                        label: Some(&p.name),
                        layout: Some(&layout),
                        vertex: wgpu::VertexState {
                            module: &vertex,
                            entry_point: Some(&vk.shaders[r.vertex].entry),
                            compilation_options: Default::default(),
                            buffers: &slots,
                        },
                        primitive: r.primitive,
                        depth_stencil: r.depth_stencil.clone(),
                        multisample: wgpu::MultisampleState {
                            count: r.samples,
                            mask: r.sample_mask,
                            alpha_to_coverage_enabled: r.alpha_to_coverage,
                        },
                        fragment,
                        multiview_mask: None,
                        cache: None,
                    },
                ))
            }
        }
    }

    /// Bind groups of every draw or dispatch of pass `i`, made on first use.
    pub(super) fn vk_work_groups(
        &mut self,
        name: &str,
        groups: Vec<&[Option<VkGroup>]>,
    ) -> Result<WorkGroups, ReplayError> {
        let mut out = Vec::new();
        for sets in groups {
            let mut indices = Vec::new();
            for g in sets {
                indices.push(match g {
                    Some(g) => Some(self.vk_group(name, g)?),
                    None => None,
                });
            }
            out.push(indices);
        }
        Ok(out)
    }

    fn vk_group(&mut self, pass: &str, g: &VkGroup) -> Result<usize, ReplayError> {
        if let Some(&i) = self.vk.group_index.get(g) {
            return Ok(i);
        }
        let scopes = scope(&self.device);
        // Views first: the entries borrow them.
        let views: Vec<Option<wgpu::TextureView>> = g
            .entries
            .iter()
            .map(|(_, r)| match r {
                VkResource::Texture {
                    texture,
                    format,
                    dimension,
                    aspect,
                    base_mip,
                    mips,
                    base_layer,
                    layers,
                } => Some(
                    self.textures[*texture][0].create_view(&wgpu::TextureViewDescriptor {
                        label: Some(&self.plan.textures[*texture].name),
                        format: *format,
                        dimension: Some(*dimension),
                        usage: None,
                        aspect: *aspect,
                        base_mip_level: *base_mip,
                        mip_level_count: *mips,
                        base_array_layer: *base_layer,
                        array_layer_count: *layers,
                    }),
                ),
                _ => None,
            })
            .collect();
        let shadowed = self.vk_shadows(g);
        let entries: Vec<wgpu::BindGroupEntry<'_>> = g
            .entries
            .iter()
            .zip(&views)
            .zip(&shadowed)
            .map(|(((binding, r), view), shadow)| wgpu::BindGroupEntry {
                binding: *binding,
                resource: match (r, view, shadow) {
                    (VkResource::Buffer { .. }, _, Some(i)) => {
                        let s = &self.vk.shadows[*i];
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &s.buffer,
                            offset: 0,
                            size: wgpu::BufferSize::new(s.size),
                        })
                    }
                    (
                        VkResource::Buffer {
                            buffer,
                            offset,
                            size,
                        },
                        _,
                        None,
                    ) => wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.buffers[*buffer][0],
                        offset: *offset,
                        size: size.and_then(wgpu::BufferSize::new),
                    }),
                    (VkResource::Sampler(s), _, _) => {
                        wgpu::BindingResource::Sampler(&self.samplers[*s])
                    }
                    (VkResource::Texture { .. }, Some(view), _) => {
                        wgpu::BindingResource::TextureView(view)
                    }
                    (VkResource::Texture { texture, .. }, None, _) => {
                        // Unreachable: a view was made above for every texture.
                        wgpu::BindingResource::Sampler(&self.samplers[*texture])
                    }
                },
            })
            .collect();
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(pass),
            layout: &self.vk_layouts[g.layout],
            entries: &entries,
        });
        if let Some(message) = close(scopes) {
            return Err(ReplayError::Pass {
                pass: pass.to_owned(),
                message: format!("making a bind group: {message}"),
            });
        }
        self.vk.groups.push(group);
        self.vk
            .group_shadows
            .push(shadowed.into_iter().flatten().collect());
        let i = self.vk.groups.len() - 1;
        self.vk.group_index.insert(g.clone(), i);
        Ok(i)
    }

    /// For each entry of `g`, the shadow it is bound through, made on first use: buffer
    /// ranges at offsets below the device's alignment for their binding type.
    fn vk_shadows(&mut self, g: &VkGroup) -> Vec<Option<usize>> {
        let limits = self.device.limits();
        let layout = &self.plan.vk.group_layouts[g.layout];
        let mut out = Vec::with_capacity(g.entries.len());
        for (binding, r) in &g.entries {
            let VkResource::Buffer {
                buffer,
                offset,
                size,
            } = r
            else {
                out.push(None);
                continue;
            };
            let ty = layout.iter().find(|e| e.binding == *binding).map(|e| e.ty);
            let (align, writable) = match ty {
                Some(wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    ..
                }) => (limits.min_uniform_buffer_offset_alignment, false),
                Some(wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only },
                    ..
                }) => (limits.min_storage_buffer_offset_alignment, !read_only),
                _ => (1, false),
            };
            // Whole words (the source's size is padded to words); a range past the source's
            // end (a uniform block rounded up to its whole size) gets zeros there.
            let total = self.buffers[*buffer][0].size();
            let size = size
                .unwrap_or(total.saturating_sub(*offset))
                .div_ceil(4)
                .saturating_mul(4)
                .max(4);
            let past_end = offset.saturating_add(size) > total;
            if offset % u64::from(align.max(1)) == 0 && !past_end {
                out.push(None);
                continue;
            }
            let key = (*buffer, *offset, size);
            let index = match self.vk.shadow_index.get(&key) {
                Some(&i) => {
                    self.vk.shadows[i].writable |= writable;
                    i
                }
                None => {
                    let shadow = self.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(&self.plan.buffers[*buffer].name),
                        size,
                        usage: wgpu::BufferUsages::UNIFORM
                            | wgpu::BufferUsages::STORAGE
                            | wgpu::BufferUsages::COPY_DST
                            | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    });
                    self.vk.shadows.push(Shadow {
                        source: *buffer,
                        offset: *offset,
                        size,
                        writable,
                        buffer: shadow,
                    });
                    self.vk.shadow_index.insert(key, self.vk.shadows.len() - 1);
                    self.vk.shadows.len() - 1
                }
            };
            out.push(Some(index));
        }
        out
    }

    /// The shadows the groups of a pass bind, each once.
    fn pass_shadows(&self, groups: &WorkGroups) -> Vec<usize> {
        // Most frames have none: nothing to walk each frame.
        if self.vk.shadows.is_empty() {
            return Vec::new();
        }
        let mut all: Vec<usize> = groups
            .iter()
            .flatten()
            .flatten()
            .flat_map(|&g| self.vk.group_shadows[g].iter().copied())
            .collect();
        all.sort_unstable();
        all.dedup();
        all
    }

    /// Fills the shadows a pass binds from their sources, before the pass.
    pub(super) fn shadows_in(&self, groups: &WorkGroups, encoder: &mut wgpu::CommandEncoder) {
        for i in self.pass_shadows(groups) {
            let s = &self.vk.shadows[i];
            let n = self.shadowed_bytes(s);
            if n > 0 {
                encoder.copy_buffer_to_buffer(
                    &self.buffers[s.source][0],
                    s.offset,
                    &s.buffer,
                    0,
                    n,
                );
            }
        }
    }

    /// Bytes of a shadow its source holds: all of it, or up to the source's end.
    fn shadowed_bytes(&self, s: &Shadow) -> u64 {
        let total = self.buffers[s.source][0].size();
        s.size.min(total.saturating_sub(s.offset) / 4 * 4)
    }

    /// Writes back the shadows a pass may have written, after the pass.
    pub(super) fn shadows_out(&self, groups: &WorkGroups, encoder: &mut wgpu::CommandEncoder) {
        for i in self.pass_shadows(groups) {
            let s = &self.vk.shadows[i];
            let n = self.shadowed_bytes(s);
            if s.writable && n > 0 {
                encoder.copy_buffer_to_buffer(
                    &s.buffer,
                    0,
                    &self.buffers[s.source][0],
                    s.offset,
                    n,
                );
            }
        }
    }

    /// One render pass of an imported pass: the draws of `segment` (all of them unless the
    /// pass reads its own attachments, `fetch`), with the attachment clears recorded among
    /// them, and the dynamic state the draws before it set (`carried`) set again first.
    pub(super) fn encode_vk_raster(
        &self,
        (pass, name): (usize, &str),
        r: &VkRasterOp,
        groups: &WorkGroups,
        mut rp: wgpu::RenderPass<'_>,
        stat: super::encode::Stat<'_>,
        (segment, carried): (&Segment, &mut super::clear_rects::Restore),
    ) {
        if let Some((set, q)) = stat {
            rp.begin_pipeline_statistics_query(set, q);
        }
        if !segment.first {
            carried.apply(&mut rp);
        }
        let buf = |b: usize| &self.buffers[b][0];
        let steps = self.steps();
        let (lo, hi) = (segment.draws.start, segment.draws.end);
        // Clears recorded before draw `lo` ran at the end of the segment before.
        let mut clears = r
            .clears
            .iter()
            .enumerate()
            .filter(|(_, c)| segment.first || c.before > lo)
            .peekable();
        for i in lo..hi.min(steps) {
            while let Some((k, _)) = clears.next_if(|(_, c)| c.before <= i) {
                self.encode_attachment_clear((pass, k), r, &mut rp, carried);
            }
            let (d, Some(sets)) = (&r.draws[i], groups.get(i)) else {
                continue;
            };
            let VkGpuPipeline::Render(pipeline) = &self.vk.pipelines[d.pipeline] else {
                continue;
            };
            rp.set_pipeline(pipeline);
            for (set, g) in sets.iter().enumerate() {
                if let Some(g) = g {
                    rp.set_bind_group(set as u32, &self.vk.groups[*g], &[]);
                }
            }
            for &(slot, b, offset) in &d.vertex_buffers {
                rp.set_vertex_buffer(slot, buf(b).slice(offset..));
            }
            if let Some([x, y, w, h, min, max]) = d.viewport {
                rp.set_viewport(x, y, w, h, min, max);
                carried.viewport = d.viewport;
            }
            if let Some([x, y, w, h]) = d.scissor {
                rp.set_scissor_rect(x, y, w, h);
                carried.scissor = d.scissor;
            }
            if !d.immediates.is_empty() {
                rp.set_immediates(0, &d.immediates);
            }
            if let Some([r, g, b, a]) = d.blend_constant {
                rp.set_blend_constant(wgpu::Color { r, g, b, a });
                carried.blend_constant = d.blend_constant;
            }
            if let Some(s) = d.stencil_reference {
                rp.set_stencil_reference(s);
                carried.stencil_reference = Some(s);
            }
            self.vk_draw_call(&mut rp, d);
        }
        // Clears before the next segment's first draw (so before its copies), or after the
        // last draw; none past the step the inspector stopped at.
        for (k, c) in clears {
            if !segment.last && c.before > hi {
                break;
            }
            if c.before < steps || steps >= r.draws.len() {
                self.encode_attachment_clear((pass, k), r, &mut rp, carried);
            }
        }
        if stat.is_some() {
            rp.end_pipeline_statistics_query();
        }
        let _ = name;
    }

    /// The draw call itself: direct or indirect, indexed or not, with a GPU count or not.
    fn vk_draw_call(&self, rp: &mut wgpu::RenderPass<'_>, d: &framelab_core::plan::VkDrawOp) {
        let buf = |b: usize| &self.buffers[b][0];
        match (d.index, d.indirect) {
            (Some((ib, offset, format)), Some((b, at))) => {
                rp.set_index_buffer(buf(ib).slice(offset..), format);
                match d.draw_count {
                    Some((c, c_at, most)) => {
                        rp.multi_draw_indexed_indirect_count(buf(b), at, buf(c), c_at, most);
                    }
                    None => rp.draw_indexed_indirect(buf(b), at),
                }
            }
            (None, Some((b, at))) => match d.draw_count {
                Some((c, c_at, most)) => {
                    rp.multi_draw_indirect_count(buf(b), at, buf(c), c_at, most);
                }
                None => rp.draw_indirect(buf(b), at),
            },
            (Some((ib, offset, format)), None) => {
                rp.set_index_buffer(buf(ib).slice(offset..), format);
                rp.draw_indexed(
                    d.first..d.first.saturating_add(d.count),
                    d.base_vertex,
                    d.first_instance..d.first_instance.saturating_add(d.instances),
                );
            }
            (None, None) => rp.draw(
                d.first..d.first.saturating_add(d.count),
                d.first_instance..d.first_instance.saturating_add(d.instances),
            ),
        }
    }

    pub(super) fn encode_vk_compute(
        &self,
        c: &VkComputeOp,
        groups: &WorkGroups,
        mut cp: wgpu::ComputePass<'_>,
        stat: super::encode::Stat<'_>,
    ) {
        if let Some((set, q)) = stat {
            cp.begin_pipeline_statistics_query(set, q);
        }
        for (d, sets) in c.dispatches.iter().zip(groups).take(self.steps()) {
            let VkGpuPipeline::Compute(pipeline) = &self.vk.pipelines[d.pipeline] else {
                continue;
            };
            cp.set_pipeline(pipeline);
            for (set, g) in sets.iter().enumerate() {
                if let Some(g) = g {
                    cp.set_bind_group(set as u32, &self.vk.groups[*g], &[]);
                }
            }
            if !d.immediates.is_empty() {
                cp.set_immediates(0, &d.immediates);
            }
            match (d.workgroups, d.indirect) {
                (_, Some((b, at))) => cp.dispatch_workgroups_indirect(&self.buffers[b][0], at),
                (Some([x, y, z]), None) => cp.dispatch_workgroups(x, y, z),
                (None, None) => {}
            }
        }
        if stat.is_some() {
            cp.end_pipeline_statistics_query();
        }
    }
}
