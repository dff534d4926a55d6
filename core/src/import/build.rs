//! Submissions become passes: each queue's command buffers are walked in the order they were
//! submitted, render pass instances (per subpass) become raster passes, runs of dispatches
//! between barriers compute passes, every transfer its own pass; barriers recorded before a
//! pass are attached to it, debug labels become marker groups, semaphores between submissions
//! become fences, presents end frames.

use std::collections::{BTreeMap, BTreeSet};

use super::HashMap;

use super::commands::{
    BarrierCmd, BarrierTarget, Cmd, DispatchCmd, DrawCmd, LevelRange, Origin, Region,
    RenderInstance, TransferCmd,
};
use super::pipelines::Pipelines;
use super::record::{MAX_EXECUTE_DEPTH, Recording, Recordings};
use super::state::Objects;
use crate::capture::dxgi;
use crate::capture::format::{
    BarrierType, Clear, ColorAttachment, Copy, CopyLocation, DepthStencilAttachment, Dispatch,
    Draw, DrawCount, IndirectArgs, LoadOp, Pass, PassKind, QueueType, Range, RecordedBarrier,
    Resolve, SplitFlag, StoreOp, VkImageView, VkIndexBuffer, VkVertexBuffer, VulkanBarrier,
};

mod attachment_clears;
mod copies;

/// The format of `view` where it differs from its image's (an sRGB view of a UNORM image
/// renders encoding, a UNORM view of an sRGB one does not), as the capture names formats.
fn view_format(objects: &Objects, view: u64) -> Option<String> {
    let (_, format, _) = objects.view_kinds.get(&view)?;
    let image = objects.images.get(&objects.views.get(&view)?.image)?;
    (*format != image.format)
        .then(|| dxgi::lookup_vk(format).map(|f| f.name.to_owned()))
        .flatten()
}
mod walk;
/// What tells two bindings of a pass apart: the pass, the resource's handle, the access and
/// the part of the resource bound.
pub(super) type BindingIdentity = (
    usize,
    u64,
    crate::capture::format::Access,
    Option<Range>,
    Option<Range>,
    Option<crate::capture::format::ByteRange>,
);

/// Most draws, dispatches, copies and recorded barriers one import emits: a real frame has
/// tens of thousands; each takes about a kilobyte of the capture, which framelab reads up
/// to 256 MiB.
pub const MAX_WORK: u64 = 1 << 17;

/// Most passes one import produces: a real frame has hundreds to a few thousand (the
/// 37,000-call benchmark stream 1,440), and one submission may list a command buffer any
/// number of times, so without a ceiling a few bytes of stream make a capture larger than
/// framelab reads (256 MiB).
pub const MAX_PASSES: usize = 1 << 16;
/// Most recorded barriers waiting on one queue for the pass they precede.
const MAX_PENDING_BARRIERS: usize = 1 << 16;

#[derive(Debug, Default)]
pub struct Builder {
    pub passes: Vec<Pass>,
    /// Current frame (0-based) and the selected range.
    pub frame: u32,
    pub selection: Option<(u32, u32)>,
    /// Frames that ended (presented or marked) so far.
    pub frames_seen: u32,
    /// Resource handles referenced by emitted passes, with their frozen names.
    pub names: BTreeMap<u64, String>,
    pub(super) taken: BTreeSet<String>,
    pub(super) pass_names: BTreeSet<String>,
    /// Next number to try per pass-name stem, and per (pass, binding stem); bindings already
    /// on each pass. These keep naming linear in the number of passes and descriptors.
    stem_next: HashMap<String, u32>,
    pub(super) binding_next: HashMap<(usize, String), u32>,
    pub(super) binding_seen: super::HashSet<BindingIdentity>,
    pub queue_names: BTreeMap<u64, (String, QueueType)>,
    pub(super) pending_barriers: HashMap<u64, Vec<RecordedBarrier>>,
    /// The pass each command's work went into, by the index of its call (`vkCmdDispatch
    /// #205` -> 205 -> pass index), so a finding that names a command can be shown on its
    /// pass. Barriers are found by their origin in the passes' own lists.
    pub(super) pass_of_command: HashMap<u64, usize>,
    pub(super) pending_waits: HashMap<u64, Vec<String>>,
    labels: HashMap<u64, Vec<String>>,
    pub(super) last_pass_on: HashMap<u64, usize>,
    /// Semaphore -> the fence of its latest queue signal and the queue that signalled it.
    semaphore_fence: HashMap<u64, (String, u64)>,
    fence_count: BTreeMap<u64, u32>,
    /// Each signalled semaphore's stem for its fences, unique among semaphores: two an
    /// application gave the same debug name must not signal the same fence.
    fence_stem: HashMap<u64, String>,
    fence_stems: super::HashSet<String>,
    pub fences: BTreeSet<String>,
    pub waited: BTreeSet<String>,
    /// Why things were skipped, with how often.
    pub notes: BTreeMap<String, u64>,
    /// Work of the imported frames the replay cannot reproduce, with how often: a frame with
    /// any is imported for analysis and refused by `replay`.
    pub refused: BTreeMap<String, u64>,
    pub recorded_barriers: u64,
    /// Draws, dispatches, copies and recorded barriers emitted so far (`MAX_WORK`).
    work: u64,
    /// Block index of the first submission whose passes are imported.
    pub first_submit: Option<u64>,
    pub draws: u64,
    pub dispatches: u64,
    /// Block index of the last submission whose passes are imported.
    pub last_submit: Option<u64>,
    /// Pipelines the imported draws and dispatches bound.
    pub pipelines_used: BTreeSet<u64>,
    /// Image views their descriptors name.
    pub views_used: BTreeMap<u64, VkImageView>,
    /// Bytes the host wrote into mapped memory after the imported frames began, by the name
    /// of the buffer that holds them for the replay: `host_write` passes copy them into place
    /// at the point of the frame where the application wrote them.
    pub uploads: Vec<(String, Vec<u8>)>,
    /// The queue of the latest pass, for passes no queue records (host writes).
    pub(super) last_queue: Option<u64>,
}

fn load_op(op: &str) -> LoadOp {
    if op.ends_with("CLEAR") || op == "1" {
        LoadOp::Clear
    } else if op.ends_with("DONT_CARE") || op == "2" {
        LoadOp::Discard
    } else {
        LoadOp::Load
    }
}

fn store_op(op: &str) -> StoreOp {
    if op.ends_with("DONT_CARE") || op == "1" {
        StoreOp::Discard
    } else {
        StoreOp::Store
    }
}

/// What the importer knows that a submission's command buffers are walked with.
#[derive(Clone, Copy, Debug)]
pub struct Known<'a> {
    pub objects: &'a Objects,
    pub pipelines: &'a Pipelines,
    pub recordings: &'a Recordings,
}

impl Builder {
    pub fn new(selection: Option<(u32, u32)>) -> Self {
        Builder {
            selection,
            ..Builder::default()
        }
    }

    pub fn emitting(&self) -> bool {
        self.selection
            .is_none_or(|(a, b)| (a..=b).contains(&self.frame))
    }

    /// Whether every selected frame has ended, so reading can stop.
    pub fn done(&self) -> bool {
        self.selection.is_some_and(|(_, b)| self.frame > b)
    }

    /// Barriers recorded after the last pass on their queue precede nothing in the imported
    /// frames: said, rather than lost without a word.
    pub fn note_trailing_barriers(&mut self) {
        let n: usize = self.pending_barriers.values().map(Vec::len).sum();
        if n > 0 {
            self.note_n(
                "barriers after the last pass on their queue (no imported pass follows them): left out",
                n as u64,
            );
        }
    }

    pub fn note(&mut self, why: impl Into<String>) {
        self.note_n(why, 1);
    }

    /// `why` noted `n` times at once.
    fn note_n(&mut self, why: impl Into<String>, n: u64) {
        *self.notes.entry(why.into()).or_default() += n;
    }

    /// The frame ends (a present, or a converter's frame marker after work).
    pub fn end_frame(&mut self) {
        self.frame = self.frame.saturating_add(1);
        self.frames_seen = self.frames_seen.max(self.frame);
        self.labels.clear();
    }

    /// The name a resource is known by from its first use on; `None` (and a note) for one
    /// framelab cannot represent.
    /// Names every image and buffer alive during the imported frames (created before their
    /// last submission, not destroyed before their first), so the capture holds what the
    /// application really had resident even where no pass touches it.
    pub fn keep_alive(&mut self, objects: &Objects) {
        let (Some(first), Some(last)) = (self.first_submit, self.last_submit) else {
            return;
        };
        let alive = |created: u64, destroyed: Option<u64>| {
            created <= last && destroyed.is_none_or(|d| d > first)
        };
        let mut handles: Vec<u64> = objects
            .images
            .iter()
            .filter(|(_, i)| alive(i.created_at, i.destroyed_at))
            .map(|(h, _)| *h)
            .chain(
                objects
                    .buffers
                    .iter()
                    .filter(|(_, b)| alive(b.created_at, b.destroyed_at))
                    .map(|(h, _)| *h),
            )
            .collect();
        handles.sort_unstable();
        for h in handles {
            self.resource(objects, h);
        }
    }

    pub(super) fn resource(&mut self, objects: &Objects, handle: u64) -> Option<String> {
        if let Some(n) = self.names.get(&handle) {
            return Some(n.clone());
        }
        let base = if let Some(img) = objects.images.get(&handle) {
            if dxgi::lookup_vk(&img.format).is_none() {
                self.note(format!(
                    "images of format {} (no DXGI or Vulkan-only entry): not represented",
                    img.format
                ));
                return None;
            }
            match (objects.names.get(&handle), img.swapchain) {
                (Some(n), _) => n.clone(),
                (None, Some((chain, i))) if objects.swapchains.len() > 1 => {
                    format!("swapchain_{chain}_{i}")
                }
                (None, Some((_, i))) => format!("swapchain_{i}"),
                (None, None) => format!("image_{handle}"),
            }
        } else if objects.buffers.contains_key(&handle) {
            objects
                .names
                .get(&handle)
                .cloned()
                .unwrap_or_else(|| format!("buffer_{handle}"))
        } else {
            self.note("uses of images or buffers the stream never created: skipped");
            return None;
        };
        let name = if self.taken.contains(&base) {
            format!("{base}#{handle}")
        } else {
            base
        };
        self.taken.insert(name.clone());
        self.names.insert(handle, name.clone());
        Some(name)
    }

    /// The stem of semaphore `sem`'s fences: its debug name, or `semaphore_<handle>`, with the
    /// handle added where another semaphore already has that stem.
    fn fence_stem(&mut self, objects: &Objects, sem: u64) -> String {
        if let Some(stem) = self.fence_stem.get(&sem) {
            return stem.clone();
        }
        let name = match objects.names.get(&sem) {
            Some(n) => n.clone(),
            None => format!("semaphore_{sem}"),
        };
        let stem = if self.fence_stems.contains(&name) {
            format!("{name}@{sem}")
        } else {
            name
        };
        self.fence_stems.insert(stem.clone());
        self.fence_stem.insert(sem, stem.clone());
        stem
    }

    fn queue(&mut self, objects: &Objects, queue: u64) -> String {
        if let Some((n, _)) = self.queue_names.get(&queue) {
            return n.clone();
        }
        let family = objects.queues.get(&queue).map(|(f, _)| *f);
        let flags = family.and_then(|f| objects.queue_family_flags.get(f as usize).copied());
        let qt = match flags {
            Some(f) if f & 0x1 != 0 => QueueType::Graphics,
            Some(f) if f & 0x2 != 0 => QueueType::Compute,
            Some(f) if f & 0x4 != 0 => QueueType::Copy,
            _ => {
                self.note("queues whose family's capabilities the stream does not give: taken as graphics");
                QueueType::Graphics
            }
        };
        let base = qt.name().to_owned();
        let taken = self.queue_names.values().filter(|(_, t)| *t == qt).count();
        let name = if taken == 0 {
            base
        } else {
            format!("{base}_{taken}")
        };
        self.queue_names.insert(queue, (name.clone(), qt));
        name
    }

    /// Starts a pass on `queue`: barriers and waits pending there are its own.
    pub(super) fn new_pass(
        &mut self,
        objects: &Objects,
        queue: u64,
        kind: PassKind,
        base: &str,
    ) -> Option<usize> {
        if !self.emitting() {
            self.pending_barriers.remove(&queue);
            return None;
        }
        if self.passes.len() >= MAX_PASSES {
            self.cut(format!(
                "passes beyond the limit of {MAX_PASSES}: not imported"
            ));
            self.pending_barriers.remove(&queue);
            return None;
        }
        let labels = self.labels.get(&queue).cloned().unwrap_or_default();
        // An empty label names nothing: the innermost one with a name names the pass.
        let labels: Vec<String> = labels
            .into_iter()
            .filter(|l| !l.trim().is_empty())
            .collect();
        let stem = labels.last().map_or(base, String::as_str).to_owned();
        let stem = if self.frame > 0 {
            format!("{stem} (frame {})", self.frame)
        } else {
            stem
        };
        let mut name = stem.clone();
        while self.pass_names.contains(&name) {
            let k = self.stem_next.entry(stem.clone()).or_insert(2);
            name = format!("{stem} {k}");
            *k += 1;
        }
        self.pass_names.insert(name.clone());
        let mut markers = vec![format!("frame {}", self.frame)];
        markers.extend(labels);
        let queue_name = self.queue(objects, queue);
        let pass = Pass {
            name,
            queue: queue_name,
            kind,
            markers,
            shader: None,
            bindings: BTreeMap::new(),
            color_attachments: Vec::new(),
            depth_stencil: None,
            state: None,
            draws: Vec::new(),
            attachment_clears: Vec::new(),
            dispatches: Vec::new(),
            copies: Vec::new(),
            clears: Vec::new(),
            blits: Vec::new(),
            resolve: None,
            generate_mips: None,
            present: None,
            params: BTreeMap::new(),
            barriers: self.pending_barriers.remove(&queue).unwrap_or_default(),
            signal: Vec::new(),
            wait: self.pending_waits.remove(&queue).unwrap_or_default(),
            timing: None,
        };
        self.recorded_barriers += pass.barriers.len() as u64;
        self.passes.push(pass);
        let index = self.passes.len() - 1;
        self.last_pass_on.insert(queue, index);
        self.last_queue = Some(queue);
        Some(index)
    }

    /// One queue submission: waits, command buffers in order, signals.
    pub fn submit(
        &mut self,
        known: Known<'_>,
        queue: u64,
        waits: &[u64],
        command_buffers: &[u64],
        signals: &[u64],
    ) {
        let objects = known.objects;
        self.wait(queue, waits);
        if self.emitting() {
            self.last_submit = Some(objects.at);
            self.last_queue = Some(queue);
        }
        if self.emitting() && self.first_submit.is_none() {
            self.first_submit = Some(objects.at);
        }
        for cb in command_buffers {
            match known.recordings.get(cb) {
                Some(r) => self.walk(known, queue, r, 0, None),
                None => self.refuse(
                    queue,
                    None,
                    "submitted command buffers the stream never recorded (their work is not in the capture)",
                ),
            }
        }
        for sem in signals {
            let Some(&pass) = self.last_pass_on.get(&queue) else {
                continue;
            };
            if !self.emitting() {
                continue;
            }
            let k = *self
                .fence_count
                .entry(*sem)
                .and_modify(|k| *k += 1)
                .or_insert(1);
            let base = self.fence_stem(objects, *sem);
            let fence = format!("{base}#{k}");
            self.passes[pass].signal.push(fence.clone());
            self.fences.insert(fence.clone());
            self.semaphore_fence.insert(*sem, (fence, queue));
        }
    }

    /// Semaphore waits become fence waits of the next pass on `queue`, when another queue
    /// signalled them (on the same queue, submission order already orders the work).
    fn wait(&mut self, queue: u64, waits: &[u64]) {
        // Waits of frames not imported are neither fences nor worth a note (their signals
        // were not kept either).
        if !self.emitting() {
            return;
        }
        for sem in waits {
            match self.semaphore_fence.remove(sem) {
                Some((f, from)) if from != queue => {
                    self.waited.insert(f.clone());
                    self.pending_waits.entry(queue).or_default().push(f);
                }
                Some(_) => self.note("semaphore waits on work of the same queue (queue order covers them): no fence"),
                None => self.note("semaphore waits with no queue signal in the imported frames (image acquire, or earlier frames): no fence"),
            }
        }
    }

    /// `vkQueuePresentKHR` (`command`) of `images` on `queue`: a present pass each.
    pub fn present(
        &mut self,
        objects: &Objects,
        queue: u64,
        waits: &[u64],
        images: &[(u64, u32)],
        command: &Origin,
    ) {
        self.wait(queue, waits);
        for &(chain, index) in images {
            let Some(&image) = objects
                .swapchain_images
                .get(&chain)
                .and_then(|v| v.get(index as usize))
            else {
                self.note("presents of swapchain images the stream never listed: skipped");
                continue;
            };
            let Some(name) = (if self.emitting() {
                self.resource(objects, image)
            } else {
                None
            }) else {
                continue;
            };
            if let Some(p) = self.new_pass(objects, queue, PassKind::Present, "present") {
                self.passes[p].present = Some(name);
                self.pass_of_command.insert(command.index, p);
            }
        }
        self.end_frame();
    }

    /// Barriers wait on their queue for the next pass, up to a ceiling (a command buffer
    /// submitted over and over with barriers and no pass would grow the list without end).
    fn pend(&mut self, queue: u64, barriers: Vec<RecordedBarrier>) {
        let pending = self.pending_barriers.entry(queue).or_default();
        let room = MAX_PENDING_BARRIERS.saturating_sub(pending.len());
        let over = barriers.len().saturating_sub(room);
        pending.extend(barriers.into_iter().take(room));
        if over > 0 {
            self.note_n(
                format!("barriers beyond {MAX_PENDING_BARRIERS} waiting for one pass: left out"),
                over as u64,
            );
        }
    }

    fn barriers(&mut self, objects: &Objects, bs: &[BarrierCmd]) -> Vec<RecordedBarrier> {
        let mut out = Vec::new();
        if !self.emitting() {
            return out;
        }
        for b in bs {
            let (resource, mips, layers) = match &b.target {
                BarrierTarget::Global => (None, None, None),
                BarrierTarget::Buffer { buffer, .. } => match self.resource(objects, *buffer) {
                    Some(n) => (Some(n), None, None),
                    None => continue,
                },
                BarrierTarget::Image {
                    image,
                    mips,
                    layers,
                } => match self.resource(objects, *image) {
                    Some(n) => {
                        let whole = |r: (u32, Option<u32>), total: u32| {
                            (r.0 != 0 || r.1.is_some_and(|c| c != total)).then_some(Range {
                                base: r.0,
                                count: r.1,
                            })
                        };
                        let Some(img) = objects.images.get(image) else {
                            self.note("image barriers naming a buffer: skipped");
                            continue;
                        };
                        (Some(n), whole(*mips, img.mips), whole(*layers, img.layers))
                    }
                    None => continue,
                },
            };
            out.push(RecordedBarrier {
                barrier_type: BarrierType::Vulkan,
                resource,
                resource_before: None,
                mips,
                layers,
                before: None,
                after: None,
                split: SplitFlag::None,
                vulkan: Some(VulkanBarrier {
                    origin: b.origin.to_string(),
                    src_stages: b.src_stages.names(),
                    src_access: b.src_access.names(),
                    dst_stages: b.dst_stages.names(),
                    dst_access: b.dst_access.names(),
                    old_layout: b.layouts.map(|l| l.0.name().into()),
                    new_layout: b.layouts.map(|l| l.1.name().into()),
                    src_queue_family: b.families.map(|f| f.0),
                    dst_queue_family: b.families.map(|f| f.1),
                }),
            });
        }
        out
    }

    /// The resource a view shows, with its first mip and layer.
    fn view(&mut self, objects: &Objects, view: u64) -> Option<(String, u32, u32)> {
        let Some(v) = objects.views.get(&view) else {
            self.note("image views the stream never created: skipped");
            return None;
        };
        let name = self.resource(objects, v.image)?;
        Some((name, v.base_mip, v.base_layer))
    }

    fn raster(
        &mut self,
        objects: &Objects,
        queue: u64,
        ri: &RenderInstance,
        sub: usize,
    ) -> Option<usize> {
        let s = ri.subpasses.get(sub)?;
        let pass = self.new_pass(objects, queue, PassKind::Raster, "render_pass")?;
        for c in &s.colors {
            let Some((name, mip, layer, ..)) = self.view(objects, c.view) else {
                continue;
            };
            let format = view_format(objects, c.view);
            self.passes[pass].color_attachments.push(ColorAttachment {
                resource: name,
                mip,
                layer,
                format,
                load: load_op(&c.load),
                store: store_op(&c.store),
                clear: c.clear,
                blend: None,
                write_mask: None,
            });
        }
        if let Some(d) = &s.depth
            && let Some((name, mip, layer)) = self.view(objects, d.view)
        {
            // Vulkan takes a clear depth outside [0, 1] only with
            // VK_EXT_depth_range_unrestricted (a valid-usage finding otherwise); wgpu takes
            // none. A value that is cleared is taken at the nearest end, said once per pass.
            let depth_clear = if (0.0..=1.0).contains(&d.depth_clear) {
                d.depth_clear
            } else {
                let clamped = if d.depth_clear > 1.0 { 1.0 } else { 0.0 };
                if load_op(&d.load) == LoadOp::Clear {
                    self.note(format!(
                        "depth clear value {} of \"{}\" outside [0, 1]: cleared to {clamped}",
                        d.depth_clear, self.passes[pass].name
                    ));
                }
                clamped
            };
            self.passes[pass].depth_stencil = Some(DepthStencilAttachment {
                resource: name,
                mip,
                layer,
                format: None,
                depth_load: load_op(&d.load),
                depth_store: store_op(&d.store),
                depth_clear,
                stencil_load: load_op(&d.stencil_load),
                stencil_store: store_op(&d.stencil_store),
                stencil_clear: d.stencil_clear,
                read_only: d.read_only,
                stencil_read_only: (d.stencil_read_only != d.read_only)
                    .then_some(d.stencil_read_only),
            });
        }
        Some(pass)
    }

    fn resolves(
        &mut self,
        objects: &Objects,
        queue: u64,
        ri: &RenderInstance,
        sub: usize,
        pass: Option<usize>,
    ) {
        if pass.is_none() {
            return;
        }
        let Some(s) = ri.subpasses.get(sub) else {
            return;
        };
        for &(src, dst) in &s.resolves {
            if self.single_sample_resolve(objects, queue, src, dst) {
                continue;
            }
            let (Some(src), Some(dst)) = (self.view(objects, src), self.view(objects, dst)) else {
                continue;
            };
            if let Some(p) = self.new_pass(objects, queue, PassKind::Resolve, "resolve") {
                self.passes[p].resolve = Some(Resolve {
                    src: src.0,
                    dst: dst.0,
                    format: None,
                });
            }
        }
    }

    /// A resolve attachment whose colour attachment has one sample: invalid
    /// (`VUID-VkSubpassDescription-pResolveAttachments-00848`, reported at the render pass's
    /// creation), but drivers take it and copy the texels (Qt asking for more samples than
    /// lavapipe has keeps the resolve of the single-sampled fallback), so the replay copies
    /// them too. `false` where the source is multisampled, or unknown.
    fn single_sample_resolve(&mut self, objects: &Objects, queue: u64, src: u64, dst: u64) -> bool {
        let (Some(sv), Some(dv)) = (objects.views.get(&src), objects.views.get(&dst)) else {
            return false;
        };
        let Some(image) = objects.images.get(&sv.image).filter(|i| i.samples <= 1) else {
            return false;
        };
        let extent = [
            (image.extent[0] >> sv.base_mip).max(1),
            (image.extent[1] >> sv.base_mip).max(1),
            1,
        ];
        let region = Region {
            src_mip: sv.base_mip,
            src_layer: sv.base_layer,
            src_origin: [0; 3],
            src_offset: 0,
            dst_mip: dv.base_mip,
            dst_layer: dv.base_layer,
            dst_origin: [0; 3],
            dst_offset: 0,
            size: None,
            extent: Some(extent),
            row_texels: 0,
            image_rows: 0,
            layers: 1,
        };
        self.copy(
            objects,
            queue,
            "resolve (single-sampled: a copy)",
            (sv.image, dv.image),
            &[region],
        );
        true
    }

    fn draw(&mut self, objects: &Objects, pipelines: &Pipelines, pass: usize, d: &DrawCmd) {
        self.draws += 1;
        self.bind(objects, pass, &d.uses, d.pipeline.map(|p| (pipelines, p)));
        let vk_vertex: Vec<VkVertexBuffer> = d
            .vertex_buffers
            .iter()
            .filter_map(|&(binding, b, offset)| {
                Some(VkVertexBuffer {
                    binding,
                    resource: self.resource(objects, b)?,
                    offset,
                })
            })
            .collect();
        let vk_index = d.index_buffer.as_ref().and_then(|(b, offset, ty)| {
            Some(VkIndexBuffer {
                resource: self.resource(objects, *b)?,
                offset: *offset,
                index_type: ty.clone(),
            })
        });
        let mut vertex_buffers: Vec<String> = Vec::new();
        for v in &vk_vertex {
            if !vertex_buffers.contains(&v.resource) {
                vertex_buffers.push(v.resource.clone());
            }
        }
        let index_buffer = vk_index.as_ref().map(|i| i.resource.clone());
        let count = match &d.draw_count {
            Some(c) => match self.resource(objects, c.buffer) {
                Some(buffer) => Some(DrawCount {
                    buffer,
                    offset: c.offset,
                    max_draws: c.max_draws,
                }),
                None => return,
            },
            None => None,
        };
        let indirect = match d.indirect {
            Some((b, offset)) => match self.resource(objects, b) {
                Some(buffer) => Some(IndirectArgs {
                    buffer,
                    offset,
                    count,
                }),
                None => return,
            },
            None => None,
        };
        let (pipeline, mut vulkan_state) = self.vk_work(objects, d.pipeline, &d.state, &d.uses);
        vulkan_state.vertex_buffers = vk_vertex;
        vulkan_state.index_buffer = vk_index;
        self.passes[pass].draws.push(Draw {
            label: None,
            vertex: None,
            fragment: None,
            mesh: None,
            count: indirect.is_none().then_some(d.count),
            vertex_buffers,
            index_buffer,
            instances: if indirect.is_some() { 1 } else { d.instances },
            first: d.first,
            first_instance: d.first_instance,
            base_vertex: d.base_vertex,
            indirect,
            pipeline,
            vulkan_state,
            stencil_reference: None,
            depth_only: false,
            params: BTreeMap::new(),
        });
    }

    fn dispatch(&mut self, objects: &Objects, pipelines: &Pipelines, pass: usize, d: &DispatchCmd) {
        self.dispatches += 1;
        self.bind(objects, pass, &d.uses, d.pipeline.map(|p| (pipelines, p)));
        let indirect = match d.indirect {
            Some((b, offset)) => match self.resource(objects, b) {
                Some(buffer) => Some(IndirectArgs {
                    buffer,
                    offset,
                    count: None,
                }),
                None => return,
            },
            None => None,
        };
        let (pipeline, vulkan_state) = self.vk_work(objects, d.pipeline, &d.state, &d.uses);
        self.passes[pass].dispatches.push(Dispatch {
            label: None,
            entry: None,
            groups: d.groups,
            indirect,
            cover: None,
            pipeline,
            vulkan_state,
            params: BTreeMap::new(),
        });
    }

    fn transfer(&mut self, objects: &Objects, queue: u64, t: &TransferCmd) {
        match t {
            TransferCmd::Copy {
                name,
                src,
                dst,
                regions,
                ..
            } => self.copy(objects, queue, name, (*src, *dst), regions),
            TransferCmd::Clear {
                depth_stencil,
                target,
                value,
                stencil,
                ranges,
                ..
            } => {
                let base = if *depth_stencil {
                    "clear_depth_stencil"
                } else {
                    "clear_color"
                };
                self.clear_image(objects, queue, base, *target, (*value, *stencil), ranges);
            }
            TransferCmd::Fill { update, buffer, .. } => {
                let base = if *update {
                    "update_buffer"
                } else {
                    "fill_buffer"
                };
                self.fill(objects, queue, base, *buffer);
            }
            TransferCmd::Resolve { src, dst } => self.resolve(objects, queue, *src, *dst),
            TransferCmd::Blit {
                src,
                dst,
                regions,
                linear,
                refused,
                ..
            } => match refused {
                Some(why) => self.refuse(queue, None, why),
                None => self.blit(objects, queue, (*src, *dst), regions, *linear),
            },
        }
    }

    /// A clear pass with one clear per subresource range; a range covering the whole image is
    /// left implicit.
    fn clear_image(
        &mut self,
        objects: &Objects,
        queue: u64,
        base: &str,
        target: u64,
        (value, stencil): ([f64; 4], u32),
        ranges: &[(LevelRange, LevelRange)],
    ) {
        let Some(name) = self.resource(objects, target) else {
            return;
        };
        let Some(pass) = self.new_pass(objects, queue, PassKind::Clear, base) else {
            return;
        };
        let img = objects.images.get(&target);
        let total = img.map_or((1, 1), |i| (i.mips, i.layers));
        for &((mb, mc), (lb, lc)) in ranges {
            let range = |base: u32, count: Option<u32>, all: u32| {
                (base != 0 || count.is_some_and(|c| c != all)).then_some(Range { base, count })
            };
            self.passes[pass].clears.push(Clear {
                resource: name.clone(),
                value,
                stencil,
                mips: range(mb, mc, total.0),
                layers: range(lb, lc, total.1),
            });
        }
    }

    /// A buffer fill or update: a clear pass over the whole buffer (its bytes are not known).
    fn fill(&mut self, objects: &Objects, queue: u64, base: &str, buffer: u64) {
        let Some(name) = self.resource(objects, buffer) else {
            return;
        };
        if let Some(pass) = self.new_pass(objects, queue, PassKind::Clear, base) {
            self.passes[pass].clears.push(Clear {
                resource: name,
                value: [0.0; 4],
                stencil: 0,
                mips: None,
                layers: None,
            });
        }
    }

    /// A blit pass with one blit per region and layer.
    fn blit(
        &mut self,
        objects: &Objects,
        queue: u64,
        (src, dst): (u64, u64),
        regions: &[super::commands::BlitRegionCmd],
        linear: bool,
    ) {
        let (Some(s), Some(d)) = (self.resource(objects, src), self.resource(objects, dst)) else {
            return;
        };
        let Some(p) = self.new_pass(objects, queue, PassKind::Blit, "blit_image") else {
            return;
        };
        use crate::capture::format::{Blit, BlitFilter, BlitRegion};
        let side = |resource: &str, (mip, layer, corners): (u32, u32, [[u32; 2]; 2])| BlitRegion {
            resource: resource.to_owned(),
            mip,
            layer,
            corners,
        };
        for r in regions {
            self.passes[p].blits.push(Blit {
                src: side(&s, r.src),
                dst: side(&d, r.dst),
                filter: if linear {
                    BlitFilter::Linear
                } else {
                    BlitFilter::Nearest
                },
            });
        }
    }

    fn resolve(&mut self, objects: &Objects, queue: u64, src: u64, dst: u64) {
        let (Some(s), Some(d)) = (self.resource(objects, src), self.resource(objects, dst)) else {
            return;
        };
        if let Some(p) = self.new_pass(objects, queue, PassKind::Resolve, "resolve_image") {
            self.passes[p].resolve = Some(Resolve {
                src: s,
                dst: d,
                format: None,
            });
        }
    }
}
