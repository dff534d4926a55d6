//! Vulkan's synchronization rules applied to the imported command stream, command by command,
//! as the specification's synchronization chapter defines them: each access (a draw's or a
//! dispatch's descriptors, vertex, index and indirect buffers; a copy's source and destination;
//! a render pass's load and store operations; an image layout transition, which is a write)
//! happens at a pipeline stage with an access type, and two accesses to the same memory of
//! which one writes need a dependency between them: an execution dependency whose first
//! synchronization scope reaches the earlier access and whose second reaches the later one,
//! and, after a write, a memory dependency that makes the write available (its access in the
//! first access scope, or an earlier barrier that did, chained) and visible to the later
//! access (in the second access scope).
//!
//! Pipeline barriers, a render pass's external dependencies and its layout transitions order
//! accesses; between submissions, semaphores, acquires, presents, host waits and queue family
//! ownership transfers do (`queues.rs`). Image layouts are followed and every use held
//! against them. Accesses to one
//! attachment inside one render pass instance are ordered by the load and store operations
//! and rasterization order, which the specification guarantees within a subpass only: two
//! render passes on the same attachment need a dependency of their own. What existed before
//! the imported frames is initial contents, not an access.
//!
//! Images are tracked per mip and layer, buffers by byte range: each buffer's bytes are split
//! into the ranges its accesses and barriers name, so accesses to disjoint ranges of one
//! buffer need no dependency (`buffer_keys`). Vertex, index and indirect reads and the buffer
//! side of a copy to or from an image are taken from their offset to the buffer's end (their
//! own extent is in the draw's parameters or the image region), which is coarser, never
//! finer. A finding names the command by its index in the captured stream, the resource and
//! subresource, and both accesses.

use std::collections::BTreeMap;

use super::{HashMap, HashSet};

mod chains;
mod layouts;
mod queues;
mod ranges;
mod stages;
mod state;

use queues::SIGNALS_KEPT;
use stages::{earlier, later, shader_stages, stages_of};
use state::{Dep, Read, Write};

use std::borrow::Cow;
use std::fmt;

use super::commands::{BarrierCmd, BarrierTarget, Cmd, Origin, RenderInstance, TransferCmd, Use};
use super::pipelines::{Pipelines, StorageUse};
use super::record::{Recording, Recordings};
use super::state::{Descriptor, Objects, storage_descriptor};
use crate::capture::format::{HazardKind, SyncHazard};
use crate::capture::vulkan::{AccessFlags as A, ImageLayout, PipelineStages as S};

/// Most subresources (mips x layers) of one image tracked one by one; an image with more is
/// tracked as its first mip and layer stand for all.
const MAX_UNITS: u32 = 4096;
/// Most findings kept; the rest are counted.
const MAX_HAZARDS: usize = 10_000;
/// Most ranges one buffer is split into; past them its accesses take every range it has
/// (coarser, never missing a hazard the ranges would show).
const MAX_RANGES: usize = 256;

/// One access: where, what, by which command.
#[derive(Clone, Debug)]
struct Access {
    stage: S,
    access: A,
    command: Origin,
    what: What,
}

/// The command a recording lacks an origin for (none does: every command records one).
static UNKNOWN: Origin = Origin::none("(command)");

/// What an access is, spelt only for a finding: the check makes one for every command and
/// descriptor, and reports few.
#[derive(Clone, Debug)]
enum What {
    Text(&'static str),
    /// A use in a layout (`descriptor in` `SHADER_READ_ONLY_OPTIMAL`).
    InLayout(&'static str, ImageLayout),
    /// A use in a layout by a command, judged when its command buffer is submitted.
    InLayoutAt(&'static str, ImageLayout, Origin),
    Transition(ImageLayout, ImageLayout),
    /// A descriptor a draw or dispatch reaches, with its type without `VK_DESCRIPTOR_TYPE_`.
    Binding {
        set: u32,
        binding: u32,
        kind: Cow<'static, str>,
    },
    Spelt(String),
}

impl fmt::Display for What {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            What::Text(t) => f.write_str(t),
            What::InLayout(what, l) => write!(f, "{what} {l}"),
            What::InLayoutAt(what, l, at) => write!(f, "{what} {l} at {at}"),
            What::Transition(from, to) => write!(f, "layout transition {from} -> {to}"),
            What::Binding { set, binding, kind } => {
                write!(f, "set {set} binding {binding} ({kind})")
            }
            What::Spelt(s) => f.write_str(s),
        }
    }
}

/// How an acquire's read is named (and recognised).
pub(super) const ACQUIRE_READ: &str = "presentation engine read (acquire)";

impl Access {
    /// What happens at no pipeline stage: a layout transition, the presentation engine's
    /// read, a layout a command expects.
    fn event(command: &Origin, what: What) -> Self {
        Access {
            stage: S::EMPTY,
            access: A::EMPTY,
            command: command.clone(),
            what,
        }
    }

    fn describe(&self) -> String {
        if self.stage.is_empty() {
            return self.what.to_string();
        }
        format!("{}/{} ({})", self.stage, self.access, self.what)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Key {
    /// The range of a buffer's bytes that starts at `start` (`Sync::ranges` holds its end).
    Buffer {
        buffer: u64,
        start: u64,
    },
    Image {
        image: u64,
        mip: u32,
        layer: u32,
    },
}

/// The checker's state across the imported frames' submissions.
#[derive(Debug, Default)]
pub struct Sync {
    states: chains::States,
    found: BTreeMap<(Origin, u64, HazardKind), (Key, Access, Access)>,
    dropped: u64,
    /// Submissions so far: each access carries the one it was made in.
    seq: u32,
    /// The submissions that signalled each semaphore (with the value, for a timeline
    /// semaphore), and the last that signalled each fence.
    signalled: HashMap<u64, Vec<(Option<u64>, u32)>>,
    fences: HashMap<u64, u32>,
    /// Swapchain images an acquire's semaphore, or its fence, orders after the
    /// presentation engine's read.
    acquire_semaphores: HashMap<u64, Vec<Key>>,
    acquire_fences: HashMap<u64, Vec<Key>>,
    /// Swapchain images whose last acquire a semaphore wait or a host wait on its fence has
    /// ordered: a write after it races the acquire's read, not the last present.
    acquires_waited: HashSet<Key>,
    /// Off: every call returns at once and nothing is found.
    enabled: bool,
    /// The queue family of the submission being walked, when the stream says.
    family: Option<u32>,
    /// The queue of the submission being walked.
    queue: u64,
    /// Resources any queue family may use (`VK_SHARING_MODE_CONCURRENT`).
    concurrent: std::collections::HashSet<u64>,
    /// Each image's layout before the imported frames where no command of theirs or before
    /// them set one: its creation's `initialLayout`, or the layout a trimmed capture's
    /// snapshot restores it to, with what said so.
    start: HashMap<u64, (ImageLayout, Origin)>,
    /// The walk of a primary command buffer under way (each walk its own number; 0: none,
    /// before the frames): a command buffer submitted again is another walk.
    walking: u64,
    walks: u64,
    /// The submission being walked.
    submission: Option<Origin>,
    /// Each buffer's tracked ranges: start to end, disjoint.
    ranges: HashMap<u64, BTreeMap<u64, u64>>,
}

impl Sync {
    pub fn new(enabled: bool) -> Self {
        Sync {
            enabled,
            ..Sync::default()
        }
    }

    pub fn enabled(&self) -> bool {
        self.enabled
    }
}

impl Sync {
    /// The mips and layers of `image` a range names (`None` counts: to the end).
    /// The keys of single subresources (mip, layer) of `image`, sorted, each once.
    fn subresource_keys(
        objects: &Objects,
        image: u64,
        subresources: impl Iterator<Item = (u32, u32)>,
    ) -> Vec<Key> {
        let mut k: Vec<Key> = subresources
            .flat_map(|(m, l)| Self::image_keys(objects, image, (m, Some(1)), (l, Some(1))))
            .collect();
        k.sort_unstable();
        k.dedup();
        k
    }

    fn image_keys(
        objects: &Objects,
        image: u64,
        mips: (u32, Option<u32>),
        layers: (u32, Option<u32>),
    ) -> Vec<Key> {
        let (total_mips, total_layers) = objects
            .images
            .get(&image)
            .map_or((1, 1), |i| (i.mips.max(1), i.layers.max(1)));
        if total_mips.saturating_mul(total_layers) > MAX_UNITS {
            return vec![Key::Image {
                image,
                mip: 0,
                layer: 0,
            }];
        }
        let m_end = mips
            .1
            .map_or(total_mips, |c| mips.0.saturating_add(c))
            .min(total_mips);
        let l_end = layers
            .1
            .map_or(total_layers, |c| layers.0.saturating_add(c))
            .min(total_layers);
        let mut out = Vec::new();
        for mip in mips.0..m_end {
            for layer in layers.0..l_end {
                out.push(Key::Image { image, mip, layer });
            }
        }
        out
    }

    fn view_keys(objects: &Objects, view: u64) -> Vec<Key> {
        match objects.views.get(&view) {
            Some(v) => Self::image_keys(
                objects,
                v.image,
                (v.base_mip, v.mip_count),
                (v.base_layer, v.layer_count),
            ),
            None => Vec::new(),
        }
    }

    fn note(
        &mut self,
        command: &Origin,
        key: Key,
        kind: HazardKind,
        access: Access,
        prior: Access,
    ) {
        let (kind, prior) = self.unwaited_acquire(key, kind, prior);
        let id = match key {
            Key::Buffer { buffer, .. } => buffer,
            Key::Image { image, .. } => image,
        };
        let k = (command.clone(), id, kind);
        if self.found.contains_key(&k) {
            return;
        }
        if self.found.len() >= MAX_HAZARDS {
            self.dropped += 1;
            return;
        }
        self.found.insert(k, (key, access, prior));
    }

    fn access(&mut self, keys: &[Key], write: bool, a: &Access) {
        for &key in keys {
            self.own(key, write, a);
            let st = self.states.entry(key);
            let hazards = if write {
                st.write(a.clone(), self.seq, self.queue)
            } else {
                st.read(a.clone(), self.seq).into_iter().collect()
            };
            for (kind, prior) in hazards {
                self.note(&a.command, key, kind, a.clone(), prior);
            }
        }
    }

    /// A write after an acquire whose semaphore and fence nothing has waited on yet is a
    /// write after the image's last present: the acquire orders nothing, so the presentation
    /// engine may still be reading what was presented (the validation layer's
    /// WRITE_AFTER_PRESENT too). Other hazards pass unchanged.
    fn unwaited_acquire(&self, key: Key, kind: HazardKind, prior: Access) -> (HazardKind, Access) {
        let acquired = matches!(prior.what, What::Text(t) if t == ACQUIRE_READ);
        let unwaited = !self.acquires_waited.contains(&key)
            && (self
                .acquire_semaphores
                .values()
                .any(|keys| keys.contains(&key))
                || self.acquire_fences.values().any(|keys| keys.contains(&key)));
        if kind == HazardKind::WriteAfterRead && acquired && unwaited {
            let what = What::Text(
                "presentation engine read (its last present; the acquire's semaphore and fence are not waited on)",
            );
            return (HazardKind::WriteAfterPresent, Access { what, ..prior });
        }
        (kind, prior)
    }

    /// What a barrier covers: its buffer's range, its image's subresources, or (a global
    /// memory barrier) everything tracked.
    fn barrier_keys(&mut self, objects: &Objects, target: &BarrierTarget) -> Vec<Key> {
        match target {
            BarrierTarget::Global => self.states.keys().copied().collect(),
            BarrierTarget::Buffer { buffer, range } => self.buffer_keys(objects, *buffer, *range),
            BarrierTarget::Image {
                image,
                mips,
                layers,
            } => Self::image_keys(objects, *image, *mips, *layers),
        }
    }

    /// A draw's or dispatch's indirect arguments, read at the draw-indirect stage.
    fn indirect(&mut self, objects: &Objects, (buffer, offset): (u64, u64), command: &Origin) {
        let a = Access {
            stage: S::DRAW_INDIRECT,
            access: A::INDIRECT_COMMAND_READ,
            command: command.clone(),
            what: What::Text("indirect arguments"),
        };
        let keys = self.buffer_keys(objects, buffer, (offset, u64::MAX));
        self.access(&keys, false, &a);
    }

    fn barrier(&mut self, objects: &Objects, b: &BarrierCmd, check_old: bool) {
        if let Some(families) = b.families {
            self.transfer_half(objects, b, families);
            return;
        }
        let d = Dep::of(b);
        let keys = self.barrier_keys(objects, &b.target);
        let transition = b.layouts.filter(|(from, to)| from != to);
        for &key in &keys {
            // With synchronization2 a barrier from a layout to itself is no transition and its
            // layouts are ignored (zink's depth barriers between draws); otherwise its old
            // layout must be the image's (VUID-VkImageMemoryBarrier-oldLayout-01197). Its
            // dependency holds either way.
            if let Some((from, to)) = b.layouts
                && !(from == to && objects.synchronization2)
            {
                if check_old && from != ImageLayout::Undefined {
                    self.expect_layout(key, from, &b.origin, What::InLayout("old layout", from));
                }
                self.set_layout(key, to, &b.origin);
            }
            let st = self.states.entry(key);
            match transition {
                Some((from, to)) => {
                    let a = Access::event(&b.origin, What::Transition(from, to));
                    for (kind, prior) in st.transition(&d, a.clone(), self.seq, self.queue) {
                        self.note(&b.origin, key, kind, a.clone(), prior);
                    }
                }
                None => st.depend(&d),
            }
        }
        // Its execution dependency reaches everything else (the states of a global
        // barrier's keys are all there are).
        if !matches!(b.target, BarrierTarget::Global) {
            self.states.order_all_but(&keys, &d);
        }
    }

    fn descriptor(
        &mut self,
        objects: &Objects,
        pipelines: &Pipelines,
        pipeline: Option<u64>,
        u: &Use,
        compute: bool,
        command: &Origin,
    ) {
        // An access happens at the stages whose code statically uses the binding, within
        // the set layout's stage flags; where the code is unknown, at every stage the
        // layout names.
        let declared = pipeline
            .and_then(|p| pipelines.binding_stages(p, u.set, u.binding))
            .unwrap_or(0);
        let flags = match pipeline.and_then(|p| pipelines.used_stages(p, u.set, u.binding)) {
            Some(0) => return,
            Some(used) if declared != 0 => used & declared,
            Some(used) => used,
            None => declared,
        };
        let stages = shader_stages(flags, compute);
        let (keys, ty) = match &u.descriptor {
            Descriptor::Image {
                view, ty, layout, ..
            } => {
                let keys = Self::view_keys(objects, *view);
                if let Some(l) = layout {
                    for &key in &keys {
                        self.expect_layout(key, *l, command, What::InLayout("descriptor in", *l));
                    }
                }
                (keys, ty)
            }
            Descriptor::Buffer {
                buffer,
                offset,
                range,
                ty,
            } => (self.buffer_keys(objects, *buffer, (*offset, *range)), ty),
            Descriptor::TexelBuffer { view, ty } => (
                match objects.buffer_views.get(view) {
                    Some(&(b, offset, range)) => self.buffer_keys(objects, b, (offset, range)),
                    None => Vec::new(),
                },
                ty,
            ),
            Descriptor::Sampler { .. } | Descriptor::Null { .. } => return,
        };
        // Whether a shader reads or writes a storage binding is in its code, which a binary
        // capture holds (`spirv::usage`). Where the code is unknown, a storage access is
        // satisfied by a dependency that covers either access and is not taken for a write,
        // so no hazard is claimed on an access the shader may not make.
        // Code is read only for storage bindings: reading it is most of an import of a
        // small capture whose pipelines bind none.
        let storage = || pipeline.and_then(|p| pipelines.storage_use(p, u.set, u.binding));
        let (access, write) = match ty.as_ref() {
            kind if storage_descriptor(kind) => match storage() {
                // Written (and maybe read): a write, as the layer takes it.
                Some(StorageUse { writes: true, .. }) => (A::SHADER_STORAGE_WRITE, true),
                Some(StorageUse { reads: true, .. }) => (A::SHADER_STORAGE_READ, false),
                // Bound but never touched by the code.
                Some(_) => return,
                None => (A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE, false),
            },
            "UNIFORM_BUFFER" | "UNIFORM_BUFFER_DYNAMIC" => (A::UNIFORM_READ, false),
            "INPUT_ATTACHMENT" => (A::INPUT_ATTACHMENT_READ, false),
            _ => (A::SHADER_SAMPLED_READ, false),
        };
        for stage in stages_of(stages) {
            let a = Access {
                stage,
                access,
                command: command.clone(),
                what: What::Binding {
                    set: u.set,
                    binding: u.binding,
                    kind: ty.clone(),
                },
            };
            self.access(&keys, write, &a);
        }
    }

    fn load_ops(&mut self, objects: &Objects, ri: &RenderInstance, command: &Origin) {
        let Some(first) = ri.subpasses.first() else {
            return;
        };
        for c in &first.colors {
            let keys = Self::view_keys(objects, c.view);
            let load = c.load.trim_start_matches("VK_ATTACHMENT_LOAD_OP_");
            let (access, write) = match load {
                "LOAD" => (A::COLOR_ATTACHMENT_READ, false),
                "NONE_EXT" | "NONE_KHR" | "NONE" => continue,
                _ => (A::COLOR_ATTACHMENT_WRITE, true),
            };
            let a = Access {
                stage: S::COLOR_ATTACHMENT_OUTPUT,
                access,
                command: command.clone(),
                what: What::Spelt(format!("load op {load}")),
            };
            self.access(&keys, write, &a);
        }
        if let Some(d) = &first.depth {
            let keys = Self::view_keys(objects, d.view);
            let load = d.load.trim_start_matches("VK_ATTACHMENT_LOAD_OP_");
            let (access, write) = match load {
                "LOAD" => (A::DEPTH_STENCIL_ATTACHMENT_READ, false),
                "NONE_EXT" | "NONE_KHR" | "NONE" => (A::EMPTY, false),
                _ => (A::DEPTH_STENCIL_ATTACHMENT_WRITE, true),
            };
            if !access.is_empty() {
                let a = Access {
                    stage: S::EARLY_FRAGMENT_TESTS,
                    access,
                    command: command.clone(),
                    what: What::Spelt(format!("depth load op {load}")),
                };
                self.access(&keys, write, &a);
            }
        }
    }

    /// Store operations write at the end of the render pass, ordered after the pass's own
    /// accesses by the render pass itself.
    fn store_ops(&mut self, objects: &Objects, ri: &RenderInstance, command: &Origin) {
        let Some(last) = ri.subpasses.last() else {
            return;
        };
        let mut stores = Vec::new();
        // Multisample resolves write their targets at the end of each subpass, at the colour
        // output stage as colour attachment writes (the specification's resolve operations).
        for sub in &ri.subpasses {
            for (_, target) in &sub.resolves {
                stores.push((
                    *target,
                    "RESOLVE".to_owned(),
                    S::COLOR_ATTACHMENT_OUTPUT,
                    A::COLOR_ATTACHMENT_WRITE,
                ));
            }
        }
        for c in &last.colors {
            stores.push((
                c.view,
                c.store.clone(),
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
            ));
        }
        if let Some(d) = &last.depth {
            stores.push((
                d.view,
                d.store.clone(),
                S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_WRITE,
            ));
        }
        for (view, store, stage, access) in stores {
            let store = store
                .trim_start_matches("VK_ATTACHMENT_STORE_OP_")
                .to_owned();
            if store.starts_with("NONE") {
                continue;
            }
            for key in Self::view_keys(objects, view) {
                let st = self.states.entry(key);
                st.write = Some(Write {
                    queue: self.queue,
                    access: Access {
                        stage,
                        access,
                        command: command.clone(),
                        what: if store == "RESOLVE" {
                            What::Text("resolve")
                        } else {
                            What::Spelt(format!("store op {store}"))
                        },
                    },
                    seq: self.seq,
                    exec: S::EMPTY,
                    visible: Vec::new(),
                });
                st.reads.clear();
            }
        }
    }

    fn transfer(&mut self, objects: &Objects, t: &TransferCmd, command: &Origin) {
        // Resolves name images only; anything else is taken whole.
        let mut buffer_or_image = |h: u64| -> Vec<Key> {
            if objects.images.contains_key(&h) {
                Self::image_keys(objects, h, (0, None), (0, None))
            } else {
                self.buffer_keys(objects, h, (0, u64::MAX))
            }
        };
        // The part of TRANSFER each command runs in, as synchronization2 names it (and the
        // validation layer reports it): copies and updates COPY, clears and fills CLEAR.
        let stage = match t {
            TransferCmd::Copy { .. } | TransferCmd::Fill { update: true, .. } => S::COPY,
            TransferCmd::Clear { .. } | TransferCmd::Fill { update: false, .. } => S::CLEAR,
            TransferCmd::Resolve { .. } => S::RESOLVE,
            TransferCmd::Blit { .. } => S::BLIT,
        };
        let mk = |access: A, what: &'static str| Access {
            stage,
            access,
            command: command.clone(),
            what: What::Text(what),
        };
        match t {
            TransferCmd::Copy {
                src,
                dst,
                regions,
                layouts,
                ..
            } => {
                let s = self.copy_keys(objects, *src, regions, true);
                let d = self.copy_keys(objects, *dst, regions, false);
                for (keys, layout, side) in [
                    (&s, layouts.0, "copy source in"),
                    (&d, layouts.1, "copy destination in"),
                ] {
                    if let Some(l) =
                        layout.filter(|_| matches!(keys.first(), Some(Key::Image { .. })))
                    {
                        for &key in keys {
                            self.expect_layout(key, l, command, What::InLayout(side, l));
                        }
                    }
                }
                self.access(&s, false, &mk(A::TRANSFER_READ, "copy source"));
                self.access(&d, true, &mk(A::TRANSFER_WRITE, "copy destination"));
            }
            TransferCmd::Clear {
                target,
                ranges,
                layout,
                ..
            } => {
                let keys: Vec<Key> = ranges
                    .iter()
                    .flat_map(|(m, l)| Self::image_keys(objects, *target, *m, *l))
                    .collect();
                if let Some(l) = layout {
                    for &key in &keys {
                        self.expect_layout(key, *l, command, What::InLayout("clear in", *l));
                    }
                }
                self.access(&keys, true, &mk(A::TRANSFER_WRITE, "clear"));
            }
            TransferCmd::Fill {
                buffer,
                update,
                range,
            } => {
                let what = if *update { "update" } else { "fill" };
                let keys = self.buffer_keys(objects, *buffer, *range);
                self.access(&keys, true, &mk(A::TRANSFER_WRITE, what));
            }
            TransferCmd::Blit {
                src,
                dst,
                regions,
                layouts,
                ..
            } => {
                let keys =
                    |h: u64, pick: &dyn Fn(&super::commands::BlitRegionCmd) -> (u32, u32)| {
                        Self::subresource_keys(objects, h, regions.iter().map(pick))
                    };
                let s = keys(*src, &|r| (r.src.0, r.src.1));
                let d = keys(*dst, &|r| (r.dst.0, r.dst.1));
                for (keys, layout, side) in [
                    (&s, layouts.0, "blit source in"),
                    (&d, layouts.1, "blit destination in"),
                ] {
                    if let Some(l) = layout {
                        for &key in keys {
                            self.expect_layout(key, l, command, What::InLayout(side, l));
                        }
                    }
                }
                self.access(&s, false, &mk(A::TRANSFER_READ, "blit source"));
                self.access(&d, true, &mk(A::TRANSFER_WRITE, "blit destination"));
            }
            TransferCmd::Resolve { src, dst } => {
                let (s, d) = (buffer_or_image(*src), buffer_or_image(*dst));
                self.access(&s, false, &mk(A::TRANSFER_READ, "resolve source"));
                self.access(&d, true, &mk(A::TRANSFER_WRITE, "resolve destination"));
            }
        }
    }

    fn walk(
        &mut self,
        objects: &Objects,
        pipelines: &Pipelines,
        recordings: &Recordings,
        r: &Recording,
        depth: u32,
    ) {
        let mut render: Option<(&RenderInstance, &Origin)> = None;
        for (i, cmd) in r.cmds.iter().enumerate() {
            let command = r.at.get(i).unwrap_or(&UNKNOWN);
            match cmd {
                Cmd::Barrier(bs) => {
                    for b in bs {
                        self.barrier(objects, b, true);
                    }
                }
                Cmd::BeginRender(ri) => {
                    self.expect_layouts(objects, ri, command);
                    for b in &ri.begin_barriers {
                        self.barrier(objects, b, false);
                    }
                    self.load_ops(objects, ri, command);
                    render = Some((ri, command));
                }
                Cmd::EndRender => {
                    if let Some((ri, _)) = render.take() {
                        self.store_ops(objects, ri, command);
                        // The transitions into finalLayout happen as the instance ends: they
                        // are the end command's (the layer names vkCmdEndRenderPass too).
                        for b in &ri.end_barriers {
                            let at_end = BarrierCmd {
                                origin: Origin {
                                    attachment: b.origin.attachment,
                                    ..command.clone()
                                },
                                ..b.clone()
                            };
                            self.barrier(objects, &at_end, false);
                        }
                        self.leave_layouts(objects, ri, command);
                    }
                }
                Cmd::Draw(d) => {
                    for u in &d.uses {
                        self.descriptor(objects, pipelines, d.pipeline, u, false, command);
                    }
                    let read = |access: A, what: What| Access {
                        stage: S::VERTEX_INPUT,
                        access,
                        command: command.clone(),
                        what,
                    };
                    // From the bound offset on: which vertices and indices a draw reads is
                    // its own parameters' business, and the bytes past them are not others'.
                    for (binding, buffer, offset) in &d.vertex_buffers {
                        let a = read(
                            A::VERTEX_ATTRIBUTE_READ,
                            What::Spelt(format!("vertex buffer {binding}")),
                        );
                        let keys = self.buffer_keys(objects, *buffer, (*offset, u64::MAX));
                        self.access(&keys, false, &a);
                    }
                    if let Some((buffer, offset, _)) = &d.index_buffer {
                        let a = read(A::INDEX_READ, What::Text("index buffer"));
                        let keys = self.buffer_keys(objects, *buffer, (*offset, u64::MAX));
                        self.access(&keys, false, &a);
                    }
                    if let Some(at) = d.indirect {
                        self.indirect(objects, at, command);
                    }
                    if let Some(c) = &d.draw_count {
                        self.indirect(objects, (c.buffer, c.offset), command);
                    }
                }
                Cmd::Dispatch(d) => {
                    for u in &d.uses {
                        self.descriptor(objects, pipelines, d.pipeline, u, true, command);
                    }
                    if let Some(at) = d.indirect {
                        self.indirect(objects, at, command);
                    }
                }
                Cmd::Transfer(t) => self.transfer(objects, t, command),
                Cmd::Execute(list) if depth < crate::import::record::MAX_EXECUTE_DEPTH => {
                    for cb in list {
                        if let Some(sub) = recordings.get(cb) {
                            self.walk(objects, pipelines, recordings, sub, depth + 1);
                        }
                    }
                }
                // Like the draws' own attachment writes, a clear of attachment rectangles is
                // ordered after the instance's load operations by the render pass itself.
                Cmd::ClearAttachments(_)
                | Cmd::NextSubpass
                | Cmd::BeginLabel(_)
                | Cmd::EndLabel
                | Cmd::Execute(_)
                | Cmd::Refused(_) => {}
            }
        }
    }

    /// One submission of the imported frames on a queue of `family`: semaphore waits (each
    /// with its stage mask, and its value for a timeline semaphore), the command buffers in
    /// order, then its signals (with their values) and fence.
    #[allow(clippy::too_many_arguments)]
    pub fn submit(
        &mut self,
        objects: &Objects,
        pipelines: &Pipelines,
        recordings: &Recordings,
        waits: &[(u64, S, Option<u64>)],
        command_buffers: &[u64],
        signals: &[(u64, Option<u64>)],
        fence: u64,
        (queue, family): (u64, Option<u32>),
        submission: &Origin,
    ) {
        if !self.enabled {
            return;
        }
        self.submission = Some(submission.clone());
        self.family = family;
        self.queue = queue;
        self.concurrent.clone_from(&objects.concurrent);
        for &(semaphore, mask, value) in waits {
            self.semaphore_wait(semaphore, mask, value);
        }
        self.seq += 1;
        for cb in command_buffers {
            if let Some(r) = recordings.get(cb) {
                self.walks += 1;
                self.walking = self.walks;
                self.walk(objects, pipelines, recordings, r, 0);
            }
        }
        self.walking = 0;
        for &(s, value) in signals {
            let list = self.signalled.entry(s).or_default();
            if list.len() >= SIGNALS_KEPT {
                list.remove(0);
            }
            list.push((value, self.seq));
        }
        if fence != 0 {
            self.fences.insert(fence, self.seq);
        }
    }

    /// The findings, in the order of the stream, with resources named by `name`, each with
    /// the command it names.
    pub fn hazards(
        &self,
        name: impl Fn(u64) -> Option<String>,
    ) -> (Vec<(Origin, SyncHazard)>, u64) {
        let mut out: Vec<(Origin, SyncHazard)> = self
            .found
            .iter()
            .map(|((command, id, kind), (key, access, prior))| {
                let (mip, layer) = match key {
                    Key::Image { mip, layer, .. } => (Some(*mip), Some(*layer)),
                    Key::Buffer { .. } => (None, None),
                };
                (
                    command.clone(),
                    SyncHazard {
                        kind: *kind,
                        command: command.to_string(),
                        resource: name(*id).unwrap_or_else(|| format!("object {id}")),
                        mip,
                        layer,
                        access: access.describe(),
                        prior: prior.describe(),
                        prior_command: prior.command.to_string(),
                        pass: None,
                    },
                )
            })
            .collect();
        out.sort_by(|a, b| {
            (a.0.index)
                .cmp(&b.0.index)
                .then_with(|| a.1.resource.cmp(&b.1.resource))
        });
        (out, self.dropped)
    }
}

#[cfg(test)]
mod tests;
