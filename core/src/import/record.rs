//! Recording: the commands of each command buffer as the stream records them, with the
//! descriptor sets, vertex and index buffers bound at each draw and dispatch resolved on the
//! spot (what the GPU will read), and render pass instances resolved to the views they use
//! and the layout transitions their attachment descriptions imply.

use std::borrow::Cow;
use std::collections::BTreeMap;

use super::calls::CmdFunc;
use super::calls::SetState;
use super::commands::{
    BarrierCmd, BarrierTarget, Cmd, DispatchCmd, DrawCmd, DrawCountCmd, MAX_INDIRECT_DRAWS, Origin,
    TransferCmd, Use,
};
use super::render_pass;
use super::set_slots::SetSlots;
use super::state::{Descriptor, Objects, debug_text};
use super::subresources::range;
use super::transfer_calls::{blit, clear_attachments, clear_image, copy};
use super::value::{Arg, Got, Skip};
use crate::capture::format::{VkCommandState, VkDynamicValues, VkStencilOps};
use crate::capture::vulkan::MAX_PUSH_CONSTANT_BYTES;
use crate::capture::vulkan::{AccessFlags, PipelineStages};

/// Bindings in effect while recording one command buffer.
#[derive(Default, Debug)]
struct Bound {
    /// (bind point is compute, set index) -> descriptors with dynamic offsets applied.
    sets: BTreeMap<(bool, u32), Vec<Use>>,
    /// Binding -> (buffer, offset).
    vertex: BTreeMap<u32, (u64, u64)>,
    /// (buffer, offset, `VK_INDEX_TYPE_*`).
    index: Option<(u64, u64, String)>,
    /// Bind point is compute -> the pipeline bound.
    pipelines: BTreeMap<bool, u64>,
    viewport: Option<[f32; 6]>,
    scissor: Option<[i64; 4]>,
    blend_constants: Option<[f32; 4]>,
    /// (front, back) references.
    stencil_reference: (Option<u32>, Option<u32>),
    /// The other dynamic state set so far.
    dynamic: VkDynamicValues,
    /// Push-constant bytes written so far; `None` once a push's values were not in the
    /// source.
    push: Option<Vec<u8>>,
    pushed: bool,
    /// Graphics (0) and compute (1): the sets bound as their layouts define them.
    slots: [SetSlots; 2],
    /// The dynamic states `vkCmdSet*` calls set since the graphics pipeline was bound.
    set_states: std::collections::BTreeSet<&'static str>,
    /// Dynamic states whose latest `vkCmdSet*` could not be read, with that call and why:
    /// the value the draws after it hold is not known.
    unread: BTreeMap<&'static str, Box<str>>,
}

/// Command buffers' recordings by handle, boxed so that moving one is a pointer's copy.
pub type Recordings = super::HashMap<u64, Box<Recording>>;

/// Deepest nesting of secondary command buffers any walk of a submission follows.
pub const MAX_EXECUTE_DEPTH: u32 = 4;

/// How many commands walking `cbs` visits, secondary command buffers expanded where they
/// are executed (to `MAX_EXECUTE_DEPTH`), counted without walking: each recording is sized
/// once per depth, so a command buffer executing another a thousand times at each of four
/// levels is told to be a trillion commands in a few thousand steps.
pub fn expanded(recordings: &Recordings, cbs: &[u64]) -> u64 {
    fn size(
        recordings: &Recordings,
        cb: u64,
        depth: u32,
        memo: &mut super::HashMap<(u64, u32), u64>,
    ) -> u64 {
        if let Some(&n) = memo.get(&(cb, depth)) {
            return n;
        }
        let Some(r) = recordings.get(&cb) else {
            return 0;
        };
        let mut n = r.cmds.len() as u64;
        let mut nested = false;
        if depth < MAX_EXECUTE_DEPTH {
            for cmd in &r.cmds {
                if let Cmd::Execute(list) = cmd {
                    nested = true;
                    for &sub in list {
                        n = n.saturating_add(size(recordings, sub, depth + 1, memo));
                    }
                }
            }
        }
        // Only what executes others is worth remembering: a plain recording is sized by its
        // length, and a submission of plain ones allocates nothing.
        if nested {
            memo.insert((cb, depth), n);
        }
        n
    }
    let mut memo = super::HashMap::default();
    cbs.iter().fold(0u64, |n, &cb| {
        n.saturating_add(size(recordings, cb, 0, &mut memo))
    })
}

#[derive(Default, Debug)]
pub struct Recording {
    pub cmds: Vec<Cmd>,
    /// Each command's call and its index in the stream (`vkCmdDraw #164`), for findings
    /// that name the command.
    pub at: Vec<Origin>,
    bound: Bound,
}

impl Recording {
    /// Empty again, keeping the storage of its lists.
    pub fn reset(&mut self) {
        self.cmds.clear();
        self.at.clear();
        self.bound = Bound::default();
    }
}

fn compute_point(a: &Arg<'_>) -> Got<bool> {
    let n = a.symbol()?;
    Ok(n.contains("COMPUTE") || n == "1")
}

impl Recording {
    /// Records one `vkCmd*` call; `Ok(false)` for commands that touch no resource framelab
    /// models (state setting, queries, ...).
    // `name` as the call holds it, so that the origins borrow a name the tables lend.
    #[allow(clippy::ptr_arg)]
    pub fn record(
        &mut self,
        func: CmdFunc,
        name: &Cow<'static, str>,
        call_index: u64,
        args: &Arg<'_>,
        objects: &Objects,
    ) -> Got<bool> {
        let Some(state) = crate::coverage::state_set_by(name) else {
            return self.record_cmd(func, name, call_index, args, objects);
        };
        self.bound.set_states.insert(state);
        let recorded = self.record_cmd(func, name, call_index, args, objects);
        // A setter that cannot be read leaves the state unknown, not at its earlier value:
        // draws whose pipeline takes it dynamically are refused rather than drawn with it.
        match &recorded {
            Ok(_) => self.bound.unread.remove(state),
            Err(Skip(why)) => self
                .bound
                .unread
                .insert(state, format!("{name} #{call_index}: {why}").into()),
        };
        recorded
    }

    #[allow(clippy::ptr_arg)]
    fn record_cmd(
        &mut self,
        func: CmdFunc,
        name: &Cow<'static, str>,
        call_index: u64,
        args: &Arg<'_>,
        objects: &Objects,
    ) -> Got<bool> {
        let origin = || Origin::call(name, call_index);
        let cmd = match func {
            CmdFunc::BindPipeline => {
                let point = compute_point(&args.get("pipelineBindPoint")?)?;
                if !point {
                    self.bound.set_states.clear();
                }
                self.bound
                    .pipelines
                    .insert(point, args.get("pipeline")?.handle()?);
                return Ok(true);
            }
            CmdFunc::SetViewport
            | CmdFunc::SetScissor
            | CmdFunc::SetBlendConstants
            | CmdFunc::SetStencilReference => return self.set_fixed(func, args).map(|()| true),
            CmdFunc::PushConstants => return self.push_constants(args).map(|()| true),
            CmdFunc::BindDescriptorSets => return self.bind_sets(args, objects).map(|()| true),
            CmdFunc::PushDescriptorSet => return self.push_set(args, objects).map(|()| true),
            CmdFunc::BindVertexBuffers => return self.bind_vertex_buffers(args).map(|()| true),
            CmdFunc::BindIndexBuffer => {
                let b = args.get("buffer")?.handle()?;
                self.bound.index = if b == 0 {
                    None
                } else {
                    Some((
                        b,
                        args.get("offset")?.u64()?,
                        args.get("indexType")?.name()?,
                    ))
                };
                return Ok(true);
            }
            CmdFunc::Draw { indexed } => self.draw_call(indexed, args)?,
            CmdFunc::DrawIndirect { indexed } => {
                return self.draw_indirect(indexed, args, &origin()).map(|()| true);
            }
            CmdFunc::DrawIndirectCount { indexed } => {
                let indirect = (args.get("buffer")?.handle()?, args.get("offset")?.u64()?);
                Cmd::Draw(Box::new(DrawCmd {
                    draw_count: Some(DrawCountCmd {
                        buffer: args.get("countBuffer")?.handle()?,
                        offset: args.get("countBufferOffset")?.u64()?,
                        max_draws: args.get("maxDrawCount")?.u32()?,
                        stride: args.get("stride")?.u32()?,
                    }),
                    ..self.draw(indexed, Some(indirect))
                }))
            }
            CmdFunc::DrawMulti { indexed } => {
                return self.draw_multi(indexed, args, &origin()).map(|()| true);
            }
            CmdFunc::Dispatch => Cmd::Dispatch(Box::new(DispatchCmd {
                groups: Some([
                    args.get("groupCountX")?.u32()?,
                    args.get("groupCountY")?.u32()?,
                    args.get("groupCountZ")?.u32()?,
                ]),
                indirect: None,
                uses: self.uses(true),
                pipeline: self.bound.pipelines.get(&true).copied(),
                state: self.state(true),
            })),
            CmdFunc::DispatchIndirect => Cmd::Dispatch(Box::new(DispatchCmd {
                groups: None,
                indirect: Some((args.get("buffer")?.handle()?, args.get("offset")?.u64()?)),
                uses: self.uses(true),
                pipeline: self.bound.pipelines.get(&true).copied(),
                state: self.state(true),
            })),
            CmdFunc::PipelineBarrier => {
                let src_stages = args.get("srcStageMask")?.stages()?;
                let dst_stages = args.get("dstStageMask")?.stages()?;
                Cmd::Barrier(barriers(args, &origin(), Some((src_stages, dst_stages)))?)
            }
            CmdFunc::PipelineBarrier2 => {
                Cmd::Barrier(barriers(&args.get("pDependencyInfo")?, &origin(), None)?)
            }
            CmdFunc::WaitEvents2 => {
                let mut all = Vec::new();
                for info in args.list("pDependencyInfos")? {
                    all.extend(barriers(&info, &origin(), None)?);
                }
                Cmd::Barrier(all)
            }
            CmdFunc::BeginRenderPass => {
                let instance = render_pass::begin_render_pass(args, objects, origin())?;
                Cmd::BeginRender(Box::new(instance))
            }
            CmdFunc::NextSubpass => Cmd::NextSubpass,
            CmdFunc::EndRender => Cmd::EndRender,
            CmdFunc::BeginRendering => {
                let instance = render_pass::begin_rendering(&args.get("pRenderingInfo")?, objects)?;
                Cmd::BeginRender(Box::new(instance))
            }
            CmdFunc::Copy { kind, v2: false } => copy(kind, name, args)?,
            CmdFunc::Copy { kind, v2: true } => copy(kind, name, &args.get(kind.info_key())?)?,
            CmdFunc::ClearImage => clear_image(name, args, objects)?,
            CmdFunc::ClearAttachments => clear_attachments(args)?,
            CmdFunc::FillBuffer => {
                let update = name.contains("Update");
                let size = if update { "dataSize" } else { "size" };
                Cmd::Transfer(Box::new(TransferCmd::Fill {
                    update,
                    buffer: args.get("dstBuffer")?.handle()?,
                    range: byte_range(args, "dstOffset", size),
                }))
            }
            CmdFunc::ResolveImage => Cmd::Transfer(Box::new(TransferCmd::Resolve {
                src: args.get("srcImage")?.handle()?,
                dst: args.get("dstImage")?.handle()?,
            })),
            CmdFunc::BeginDebugLabel => Cmd::BeginLabel(debug_text(
                args.get("pLabelInfo")?.get("pLabelName")?.str()?,
            )),
            CmdFunc::BeginDebugMarker => Cmd::BeginLabel(debug_text(
                args.get("pMarkerInfo")?.get("pMarkerName")?.str()?,
            )),
            CmdFunc::EndLabel => Cmd::EndLabel,
            CmdFunc::ExecuteCommands => Cmd::Execute(
                args.list("pCommandBuffers")?
                    .iter()
                    .map(Arg::handle)
                    .collect::<Got<_>>()?,
            ),
            CmdFunc::Blit => blit(args.opt("pBlitImageInfo").unwrap_or(*args))?,
            CmdFunc::SetState(set) => return self.set_state(set, args).map(|()| true),
            // Kept, so that the frame that runs it is refused with its pass named.
            CmdFunc::Refused => Cmd::Refused(name.as_ref().into()),
            CmdFunc::PushDescriptorSetWithTemplate => {
                return self.push_template(args, objects).map(|()| true);
            }
            CmdFunc::Other => return Ok(false),
        };
        self.cmds.push(cmd);
        self.at.push(origin());
        Ok(true)
    }

    /// Viewport, scissor, blend constants and stencil reference, which every pipeline may
    /// take dynamically: the values the draws after them hold.
    fn set_fixed(&mut self, func: CmdFunc, args: &Arg<'_>) -> Got<()> {
        match func {
            CmdFunc::SetViewport => {
                if let Some(v) = args.list("pViewports")?.first() {
                    let f = |k: &str| -> Got<f32> { Ok(v.get(k)?.f64()? as f32) };
                    self.bound.viewport = Some([
                        f("x")?,
                        f("y")?,
                        f("width")?,
                        f("height")?,
                        f("minDepth")?,
                        f("maxDepth")?,
                    ]);
                }
            }
            CmdFunc::SetScissor => {
                if let Some(r) = args.list("pScissors")?.first() {
                    let (o, e) = (r.get("offset")?, r.get("extent")?);
                    self.bound.scissor = Some([
                        o.get("x")?.i64()?,
                        o.get("y")?.i64()?,
                        e.get("width")?.i64()?,
                        e.get("height")?.i64()?,
                    ]);
                }
            }
            CmdFunc::SetBlendConstants => {
                // Required: constants read as zero would blend a wrong image silently.
                let k = args.get("blendConstants")?.items()?;
                let mut c = [0.0f32; 4];
                for (i, v) in k.iter().take(4).enumerate() {
                    c[i] = v.f64()? as f32;
                }
                self.bound.blend_constants = Some(c);
            }
            CmdFunc::SetStencilReference => {
                // VkStencilFaceFlags: front 1, back 2.
                let faces = args.get("faceMask")?.u64()?;
                let reference = args.get("reference")?.u32()?;
                if faces & 1 != 0 {
                    self.bound.stencil_reference.0 = Some(reference);
                }
                if faces & 2 != 0 {
                    self.bound.stencil_reference.1 = Some(reference);
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Push constants: bytes at an offset, kept while every push so far had its values.
    fn push_constants(&mut self, args: &Arg<'_>) -> Got<()> {
        let offset = args.get("offset")?.u32()?;
        let size = args.get("size")?.u32()?;
        if offset.saturating_add(size) > MAX_PUSH_CONSTANT_BYTES {
            return Err(Skip(format!(
                "push constants at {offset}..{} are past the {MAX_PUSH_CONSTANT_BYTES} bytes any device takes",
                u64::from(offset) + u64::from(size)
            )));
        }
        let values = args.opt("pValues").filter(Arg::is_array);
        let first = !self.bound.pushed;
        self.bound.pushed = true;
        let Some(values) = values else {
            self.bound.push = None;
            return Ok(());
        };
        let bytes: Vec<u8> = values
            .items()?
            .iter()
            .map(|b| b.u32().map(|v| v as u8))
            .collect::<Got<_>>()?;
        if first {
            self.bound.push = Some(Vec::new());
        }
        if let Some(push) = &mut self.bound.push {
            let end = (offset as usize + bytes.len()).min(MAX_PUSH_CONSTANT_BYTES as usize);
            if push.len() < end {
                push.resize(end, 0);
            }
            push[offset as usize..end].copy_from_slice(&bytes[..end - offset as usize]);
        }
        Ok(())
    }

    /// The dynamic state and push constants a draw (or dispatch) runs with.
    fn state(&self, compute: bool) -> VkCommandState {
        VkCommandState {
            viewport: if compute { None } else { self.bound.viewport },
            scissor: if compute { None } else { self.bound.scissor },
            blend_constants: if compute {
                None
            } else {
                self.bound.blend_constants
            },
            stencil_reference: if compute {
                None
            } else {
                match self.bound.stencil_reference {
                    (Some(f), Some(b)) if f != b => Some([f, b]),
                    (Some(f), _) | (None, Some(f)) => Some([f, f]),
                    (None, None) => None,
                }
            },
            dynamic: (!compute && !self.bound.dynamic.is_empty())
                .then(|| Box::new(self.bound.dynamic.clone())),
            push_constants: self.bound.push.as_ref().map(hex::encode),
            descriptors: Vec::new(),
            vertex_buffers: Vec::new(),
            index_buffer: None,
        }
    }

    /// A `vkCmdSet*` of dynamic state: its values, for the draws after it.
    fn set_state(&mut self, set: SetState, args: &Arg<'_>) -> Got<()> {
        let d = &mut self.bound.dynamic;
        let flag = |key: &str| super::pipelines::boolean(args, key);
        let float = |key: &str| super::pipelines::float(args, key);
        // VkStencilFaceFlags: front 1, back 2; a face not named keeps its value.
        let faces = |old: Option<[u32; 2]>, value: u32, mask: u64| {
            let [f, b] = old.unwrap_or([value, value]);
            Some([
                if mask & 1 != 0 { value } else { f },
                if mask & 2 != 0 { value } else { b },
            ])
        };
        match set {
            SetState::DepthBias => {
                d.depth_bias = Some([
                    float("depthBiasConstantFactor")?,
                    float("depthBiasClamp")?,
                    float("depthBiasSlopeFactor")?,
                ]);
            }
            SetState::DepthBiasEnable => d.depth_bias_enable = Some(flag("depthBiasEnable")?),
            SetState::LineWidth => d.line_width = Some(float("lineWidth")?),
            SetState::DepthBounds => {
                d.depth_bounds = Some([float("minDepthBounds")?, float("maxDepthBounds")?]);
            }
            SetState::DepthBoundsTestEnable => {
                d.depth_bounds_test_enable = Some(flag("depthBoundsTestEnable")?);
            }
            SetState::StencilCompareMask => {
                let mask = args.get("faceMask")?.u64()?;
                d.stencil_compare_mask = faces(
                    d.stencil_compare_mask,
                    args.get("compareMask")?.u32()?,
                    mask,
                );
            }
            SetState::StencilWriteMask => {
                let mask = args.get("faceMask")?.u64()?;
                d.stencil_write_mask =
                    faces(d.stencil_write_mask, args.get("writeMask")?.u32()?, mask);
            }
            SetState::StencilOp => {
                let mask = args.get("faceMask")?.u64()?;
                let ops = VkStencilOps {
                    fail_op: args.get("failOp")?.name()?,
                    pass_op: args.get("passOp")?.name()?,
                    depth_fail_op: args.get("depthFailOp")?.name()?,
                    compare_op: args.get("compareOp")?.name()?,
                };
                let [f, b] = d
                    .stencil_op
                    .take()
                    .unwrap_or_else(|| [ops.clone(), ops.clone()]);
                d.stencil_op = Some([
                    if mask & 1 != 0 { ops.clone() } else { f },
                    if mask & 2 != 0 { ops } else { b },
                ]);
            }
            SetState::CullMode => d.cull_mode = Some(args.get("cullMode")?.u32()?),
            SetState::FrontFace => d.front_face = Some(args.get("frontFace")?.name()?),
            SetState::PrimitiveTopology => {
                d.topology = Some(args.get("primitiveTopology")?.name()?);
            }
            SetState::PrimitiveRestartEnable => {
                d.primitive_restart_enable = Some(flag("primitiveRestartEnable")?);
            }
            SetState::RasterizerDiscardEnable => {
                d.rasterizer_discard_enable = Some(flag("rasterizerDiscardEnable")?);
            }
            SetState::DepthTestEnable => d.depth_test_enable = Some(flag("depthTestEnable")?),
            SetState::DepthWriteEnable => d.depth_write_enable = Some(flag("depthWriteEnable")?),
            SetState::DepthCompareOp => {
                d.depth_compare_op = Some(args.get("depthCompareOp")?.name()?);
            }
            SetState::StencilTestEnable => {
                d.stencil_test_enable = Some(flag("stencilTestEnable")?);
            }
            SetState::ColorWriteEnable => {
                d.color_write_enable = Some(
                    args.list("pColorWriteEnables")?
                        .iter()
                        .map(|v| v.u64().map(|v| v != 0))
                        .collect::<Got<_>>()?,
                );
            }
            SetState::LogicOp => d.logic_op = Some(args.get("logicOp")?.name()?),
            other => super::extended_state::set(d.extended.get_or_insert_default(), other, args)?,
        }
        Ok(())
    }

    fn bind_vertex_buffers(&mut self, args: &Arg<'_>) -> Got<()> {
        let first = args.get("firstBinding")?.u32()?;
        // `vkCmdBindVertexBuffers2` with strides: VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE.
        if let Some(strides) = args.opt("pStrides").filter(Arg::is_array) {
            for (k, stride) in strides.items()?.iter().enumerate() {
                let slot = u64::from(first.saturating_add(k as u32));
                let stride = stride.u64()?;
                let list = &mut self.bound.dynamic.vertex_strides;
                match list.iter_mut().find(|s| s[0] == slot) {
                    Some(s) => s[1] = stride,
                    None => list.push([slot, stride]),
                }
            }
            self.bound.dynamic.vertex_strides.sort_unstable();
        }
        let offsets = args.list("pOffsets")?;
        for (k, b) in args.list("pBuffers")?.iter().enumerate() {
            let buffer = b.handle()?;
            let slot = first.saturating_add(k as u32);
            let offset = match offsets.get(k) {
                Some(o) => o.u64()?,
                None => 0,
            };
            if buffer == 0 {
                self.bound.vertex.remove(&slot);
            } else {
                self.bound.vertex.insert(slot, (buffer, offset));
            }
        }
        Ok(())
    }

    /// Binds descriptor sets as their contents are now, dynamic offsets applied in order.
    fn bind_sets(&mut self, args: &Arg<'_>, objects: &Objects) -> Got<()> {
        let compute = compute_point(&args.get("pipelineBindPoint")?)?;
        let first = args.get("firstSet")?.u32()?;
        let count = args.list("pDescriptorSets")?.len() as u32;
        self.bind_slots(compute, args, objects, first, count)?;
        let mut dynamic: Vec<u64> = args
            .list("pDynamicOffsets")?
            .iter()
            .map(Arg::u64)
            .collect::<Got<_>>()?;
        dynamic.reverse();
        for (k, s) in args.list("pDescriptorSets")?.iter().enumerate() {
            let set = s.handle()?;
            let index = first.saturating_add(k as u32);
            let contents = objects
                .sets
                .get(&set)
                .ok_or_else(|| Skip(format!("descriptor set {set} was never allocated")))?;
            let uses = contents
                .iter()
                .map(|(&(binding, element), d)| {
                    let mut descriptor = d.clone();
                    if let Descriptor::Buffer { offset, ty, .. } = &mut descriptor
                        && ty.ends_with("DYNAMIC")
                    {
                        *offset = offset.saturating_add(dynamic.pop().unwrap_or(0));
                    }
                    Use {
                        set: index,
                        binding,
                        element,
                        descriptor,
                    }
                })
                .collect();
            self.bound.sets.insert((compute, index), uses);
        }
        Ok(())
    }

    /// Sets `first..first + count` bound at a bind point through the call's `layout`.
    fn bind_slots(
        &mut self,
        compute: bool,
        args: &Arg<'_>,
        objects: &Objects,
        first: u32,
        count: u32,
    ) -> Got<()> {
        let layout = args.get("layout")?.handle()?;
        let compat = objects.layout_compat.get(&layout).map(|c| &c[..]);
        self.bound.slots[usize::from(compute)].bind(layout, compat, first, count);
        Ok(())
    }

    /// The sets bound at a bind point (`compute`), for what a draw or dispatch needs of them.
    pub fn set_slots(&self, compute: bool) -> &SetSlots {
        &self.bound.slots[usize::from(compute)]
    }

    /// The descriptors bound at a bind point (`compute`), set by set.
    pub fn bound_uses(&self, compute: bool) -> impl Iterator<Item = &Use> {
        self.bound
            .sets
            .iter()
            .filter(move |((c, _), _)| *c == compute)
            .flat_map(|(_, u)| u.iter())
    }

    /// The dynamic states set since the graphics pipeline was bound.
    pub fn states_set(&self) -> &std::collections::BTreeSet<&'static str> {
        &self.bound.set_states
    }

    /// The pipeline bound at a bind point.
    pub fn pipeline(&self, compute: bool) -> Option<u64> {
        self.bound.pipelines.get(&compute).copied()
    }

    /// Pushed descriptors replace the ones bound at the same binding and element.
    fn push_set(&mut self, args: &Arg<'_>, objects: &Objects) -> Got<()> {
        let compute = compute_point(&args.get("pipelineBindPoint")?)?;
        let set = args.get("set")?.u32()?;
        self.bind_slots(compute, args, objects, set, 1)?;
        let mut written = Vec::new();
        for w in args.list("pDescriptorWrites")? {
            written.extend(super::state::descriptor_writes(&w)?);
        }
        self.push(compute, set, written);
        Ok(())
    }

    /// `vkCmdPushDescriptorSetWithTemplateKHR`: the template's bind point, the call's set.
    fn push_template(&mut self, args: &Arg<'_>, objects: &Objects) -> Got<()> {
        let template = args.get("descriptorUpdateTemplate")?.handle()?;
        let written = objects.template_writes(template, &args.get("pData")?)?;
        let compute = objects.templates.get(&template).is_some_and(|t| t.compute);
        let set = args.get("set")?.u32()?;
        self.bind_slots(compute, args, objects, set, 1)?;
        self.push(compute, set, written);
        Ok(())
    }

    fn push(&mut self, compute: bool, set: u32, written: Vec<((u32, u32), Descriptor)>) {
        let mut uses = self.bound.sets.remove(&(compute, set)).unwrap_or_default();
        for ((binding, element), descriptor) in written {
            uses.retain(|u| (u.binding, u.element) != (binding, element));
            uses.push(Use {
                set,
                binding,
                element,
                descriptor,
            });
        }
        self.bound.sets.insert((compute, set), uses);
    }

    fn draw_call(&self, indexed: bool, args: &Arg<'_>) -> Got<Cmd> {
        let (count, first) = if indexed {
            (
                args.get("indexCount")?.u32()?,
                args.get("firstIndex")?.u32()?,
            )
        } else {
            (
                args.get("vertexCount")?.u32()?,
                args.get("firstVertex")?.u32()?,
            )
        };
        let base_vertex = if indexed {
            i32::try_from(args.get("vertexOffset")?.i64()?)
                .map_err(|_| Skip("`vertexOffset` out of range".to_owned()))?
        } else {
            0
        };
        let draw = self.draw(indexed, None);
        Ok(Cmd::Draw(Box::new(DrawCmd {
            count,
            instances: args.get("instanceCount")?.u32()?,
            first,
            base_vertex,
            first_instance: args.get("firstInstance")?.u32()?,
            ..draw
        })))
    }

    /// An indirect draw becomes one draw per record, each reading its own arguments.
    fn draw_indirect(&mut self, indexed: bool, args: &Arg<'_>, origin: &Origin) -> Got<()> {
        let buffer = args.get("buffer")?.handle()?;
        let offset = args.get("offset")?.u64()?;
        let draws = args.get("drawCount")?.u32()?;
        let stride = args.get("stride")?.u64()?;
        if draws > MAX_INDIRECT_DRAWS {
            return Err(Skip(format!(
                "`drawCount` {draws} is over the {MAX_INDIRECT_DRAWS} draws one indirect call is expanded into"
            )));
        }
        for k in 0..u64::from(draws) {
            let at = offset.saturating_add(k.saturating_mul(stride));
            self.cmds
                .push(Cmd::Draw(Box::new(self.draw(indexed, Some((buffer, at))))));
            self.at.push(origin.clone());
        }
        Ok(())
    }

    /// A multi-draw list (`VK_EXT_multi_draw`) becomes one draw per entry, each with the call's
    /// instances; an indexed list's `pVertexOffset`, when given, is every entry's vertex offset.
    fn draw_multi(&mut self, indexed: bool, args: &Arg<'_>, origin: &Origin) -> Got<()> {
        let draws = args.get("drawCount")?.u32()?;
        if draws > MAX_INDIRECT_DRAWS {
            return Err(Skip(format!(
                "`drawCount` {draws} is over the {MAX_INDIRECT_DRAWS} draws one multi-draw call is expanded into"
            )));
        }
        let entries = args.list(if indexed { "pIndexInfo" } else { "pVertexInfo" })?;
        if entries.len() != draws as usize {
            return Err(Skip(format!(
                "`drawCount` is {draws} but the capture holds {} entries",
                entries.len()
            )));
        }
        let instances = args.get("instanceCount")?.u32()?;
        let first_instance = args.get("firstInstance")?.u32()?;
        let offset_of = |a: Arg<'_>| -> Got<i32> {
            let a = if a.is_array() {
                a.items()?
                    .into_iter()
                    .next()
                    .ok_or_else(|| Skip("`pVertexOffset` is an empty array".to_owned()))?
            } else {
                a
            };
            i32::try_from(a.i64()?).map_err(|_| Skip("`vertexOffset` out of range".to_owned()))
        };
        let shared = match args.opt("pVertexOffset").filter(|_| indexed) {
            Some(a) => Some(offset_of(a)?),
            None => None,
        };
        for e in entries {
            let (count, first, base_vertex) = if indexed {
                let base = match shared {
                    Some(v) => v,
                    None => offset_of(e.get("vertexOffset")?)?,
                };
                (
                    e.get("indexCount")?.u32()?,
                    e.get("firstIndex")?.u32()?,
                    base,
                )
            } else {
                (
                    e.get("vertexCount")?.u32()?,
                    e.get("firstVertex")?.u32()?,
                    0,
                )
            };
            let draw = self.draw(indexed, None);
            self.cmds.push(Cmd::Draw(Box::new(DrawCmd {
                count,
                instances,
                first,
                base_vertex,
                first_instance,
                ..draw
            })));
            self.at.push(origin.clone());
        }
        Ok(())
    }

    fn uses(&self, compute: bool) -> Vec<Use> {
        self.bound
            .sets
            .iter()
            .filter(|((c, _), _)| *c == compute)
            .flat_map(|(_, u)| u.iter().cloned())
            .collect()
    }

    fn draw(&self, indexed: bool, indirect: Option<(u64, u64)>) -> DrawCmd {
        DrawCmd {
            count: 0,
            instances: 1,
            first: 0,
            base_vertex: 0,
            first_instance: 0,
            indirect,
            draw_count: None,
            uses: self.uses(false),
            vertex_buffers: self
                .bound
                .vertex
                .iter()
                .map(|(&slot, &(buffer, offset))| (slot, buffer, offset))
                .collect(),
            index_buffer: if indexed {
                self.bound.index.clone()
            } else {
                None
            },
            pipeline: self.bound.pipelines.get(&false).copied(),
            state: self.state(false),
            unread: self
                .bound
                .unread
                .iter()
                .map(|(&s, why)| (s, why.clone()))
                .collect(),
        }
    }
}

type Masks = (PipelineStages, PipelineStages, AccessFlags, AccessFlags);

fn barriers(
    args: &Arg<'_>,
    origin: &Origin,
    stages: Option<(PipelineStages, PipelineStages)>,
) -> Got<Vec<BarrierCmd>> {
    let masks = |b: &Arg<'_>| -> Got<Masks> {
        let (ss, ds) = match stages {
            Some(s) => s,
            None => (
                b.get("srcStageMask")?.stages()?,
                b.get("dstStageMask")?.stages()?,
            ),
        };
        Ok((
            ss,
            ds,
            b.get("srcAccessMask")?.access()?,
            b.get("dstAccessMask")?.access()?,
        ))
    };
    let families = |b: &Arg<'_>| -> Got<Option<(u32, u32)>> {
        let s = b.get("srcQueueFamilyIndex")?.u64()?;
        let d = b.get("dstQueueFamilyIndex")?.u64()?;
        // VK_QUEUE_FAMILY_IGNORED on either side: no ownership transfer.
        Ok(
            (s != d && s < u64::from(u32::MAX) && d < u64::from(u32::MAX))
                .then_some((s as u32, d as u32)),
        )
    };
    let mut out = Vec::new();
    for b in args.list("pMemoryBarriers")? {
        let (ss, ds, sa, da) = masks(&b)?;
        out.push(BarrierCmd {
            origin: origin.clone(),
            target: BarrierTarget::Global,
            src_stages: ss,
            dst_stages: ds,
            src_access: sa,
            dst_access: da,
            layouts: None,
            families: None,
        });
    }
    for b in args.list("pBufferMemoryBarriers")? {
        let (ss, ds, sa, da) = masks(&b)?;
        out.push(BarrierCmd {
            origin: origin.clone(),
            target: BarrierTarget::Buffer {
                buffer: b.get("buffer")?.handle()?,
                range: byte_range(&b, "offset", "size"),
            },
            src_stages: ss,
            dst_stages: ds,
            src_access: sa,
            dst_access: da,
            layouts: None,
            families: families(&b)?,
        });
    }
    for b in args.list("pImageMemoryBarriers")? {
        let (ss, ds, sa, da) = masks(&b)?;
        let (mips, layers) = range(&b.get("subresourceRange")?)?;
        out.push(BarrierCmd {
            origin: origin.clone(),
            target: BarrierTarget::Image {
                image: b.get("image")?.handle()?,
                mips,
                layers,
            },
            src_stages: ss,
            dst_stages: ds,
            src_access: sa,
            dst_access: da,
            layouts: Some((b.get("oldLayout")?.layout()?, b.get("newLayout")?.layout()?)),
            families: families(&b)?,
        });
    }
    Ok(out)
}

/// The bytes a command or barrier names by its `offset` and `size` members: the whole buffer
/// where either is missing or unreadable (the synchronization check is then as coarse as
/// before, never finer than the stream says).
fn byte_range(a: &Arg<'_>, offset: &str, size: &str) -> (u64, u64) {
    let get = |k: &str| a.get(k).and_then(|v| v.u64()).ok();
    match (get(offset), get(size)) {
        (Some(o), Some(s)) => (o, s),
        _ => (0, u64::MAX),
    }
}
