//! Barrier derivation: walking passes in DAG order with each subresource unit's D3D12 state, it
//! emits the transitions and UAV barriers a D3D12 frame needs at each pass boundary, batched per
//! resource and range, placed on a queue that may hold both states, with split-barrier
//! opportunities, the fences cross-queue dependencies need, and Vulkan's equivalents (image
//! layouts, stage and access masks filtered by what each queue can run, queue-family ownership
//! transfers).
//!
//! States at the start of the frame are the steady state: what the previous frame left, found by
//! walking the frame once before deriving.

use std::cmp::Reverse;
use std::collections::BTreeMap;

use serde::Serialize;

use super::graph::PassGraph;
use super::model::{FrameModel, State, Units};
use crate::capture::format::QueueType;
use crate::capture::model::Subresources;
use petgraph::visit::EdgeRef;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BarrierKind {
    Transition,
    Uav,
    Aliasing,
}

/// Where a barrier executes: before a pass on its queue, or after a pass on that pass's queue
/// (a release, when the consuming queue cannot hold the old state).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    Before(u32),
    After(u32),
}

impl Placement {
    pub fn pass(self) -> u32 {
        match self {
            Placement::Before(p) | Placement::After(p) => p,
        }
    }
}

/// Vulkan's view of one side of a barrier.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct VkScope {
    /// Image layout (`None` for buffers).
    pub layout: Option<&'static str>,
    pub stages: Vec<&'static str>,
    pub access: Vec<&'static str>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Barrier {
    pub kind: BarrierKind,
    pub placement: Placement,
    /// The queue it is recorded on.
    pub queue: u32,
    /// The pass whose access needs it.
    pub for_pass: u32,
    pub resource: u32,
    /// Aliasing barriers: the resource that stops using the memory.
    pub resource_before: Option<u32>,
    pub range: Subresources,
    pub before: State,
    pub after: State,
    /// A split barrier could begin right after this pass (passes run in between).
    pub split_begin_after: Option<u32>,
    /// An end-of-frame transition that prepares the resource for `for_pass` of the next frame,
    /// whose queue cannot hold the state this frame leaves it in.
    pub next_frame: bool,
}

impl Barrier {
    /// Vulkan's source and destination scopes for this barrier (computed on demand: reports
    /// need them, the derivation does not).
    pub fn vulkan(&self, model: &FrameModel) -> (VkScope, VkScope) {
        let qtype = model.queues[self.queue as usize].queue_type;
        let buffer = model.resources[self.resource as usize].is_buffer;
        let src_pass = self.split_begin_after.unwrap_or(self.placement.pass());
        let src = vk_scope(
            self.before,
            qtype,
            buffer,
            model.passes[src_pass as usize].raster,
        );
        let dst = vk_scope(
            self.after,
            qtype,
            buffer,
            model.passes[self.for_pass as usize].raster,
        );
        (src, dst)
    }
}

/// A fence a cross-queue dependency needs.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct FenceNeed {
    pub signal_after: u32,
    pub wait_before: u32,
    /// Declared in the capture, or derived here because nothing else orders the two passes.
    pub declared: bool,
}

/// A Vulkan queue-family ownership transfer (release on one queue, acquire on the other).
#[derive(Clone, Debug, Serialize)]
pub struct OwnershipTransfer {
    pub resource: u32,
    pub range: Subresources,
    pub release_after: u32,
    pub acquire_before: u32,
    pub from_queue: u32,
    pub to_queue: u32,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct BarrierPlan {
    pub barriers: Vec<Barrier>,
    pub fences: Vec<FenceNeed>,
    pub transfers: Vec<OwnershipTransfer>,
    /// State of every unit at the start of the frame (steady state).
    #[serde(skip)]
    pub initial_states: Vec<State>,
}

/// What one pass needs of one unit.
#[derive(Clone, Copy, Debug)]
struct Need {
    unit: usize,
    resource: u32,
    state: State,
    reads: bool,
    writes: bool,
    uav: bool,
}

/// The state each unit must be in for `pass`: read states of several accesses combine; a write
/// state wins (the pass orders its own accesses internally).
fn needs(model: &FrameModel, units: &Units, pass: usize, out: &mut Vec<Need>) {
    out.clear();
    for a in &model.passes[pass].accesses {
        units.for_each(model, a, |unit| {
            out.push(Need {
                unit,
                resource: a.resource,
                state: a.state,
                reads: a.reads,
                writes: a.writes,
                uav: a.uav,
            })
        });
    }
    out.sort_unstable_by_key(|n| n.unit);
    let mut w = 0;
    for r in 0..out.len() {
        let n = out[r];
        if w > 0 && out[w - 1].unit == n.unit {
            let m = &mut out[w - 1];
            m.state = match (m.state.is_write(), n.state.is_write()) {
                (true, _) => m.state,
                (false, true) => n.state,
                (false, false) => m.state.union(n.state),
            };
            m.reads |= n.reads;
            m.writes |= n.writes;
            m.uav |= n.uav;
        } else {
            out[w] = n;
            w += 1;
        }
    }
    out.truncate(w);
}

/// Per-unit tracking while walking the order.
#[derive(Clone, Copy)]
struct UnitTrack {
    state: State,
    /// Position in the order and pass of the last access.
    last_pos: Option<u32>,
    last_pass: u32,
    /// Queues (bit per queue index) with an unordered-access write / read since the last
    /// barrier: a UAV barrier orders accesses on one queue; other queues are ordered by fences.
    pending_uav_write: u64,
    pending_uav_read: u64,
}

const NO_PASS: u32 = u32::MAX;

fn queue_bit(queue: u32) -> u64 {
    1u64 << queue.min(63)
}

/// One unit's transition or UAV barrier before batching.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Pending {
    placement: Placement,
    queue: u32,
    for_pass: u32,
    kind: BarrierKind,
    resource: u32,
    before: State,
    after: State,
    split: Option<u32>,
    next_frame: bool,
    // Unit within the resource (mip-major for textures, interval index for buffers).
    mip: u32,
    layer: u32,
}

pub fn derive(model: &FrameModel, units: &Units, graph: &PassGraph, order: &[u32]) -> BarrierPlan {
    // First walk: the state each unit is left in, which is where the next frame starts, unless
    // the first queue to touch it next frame cannot hold that state: then the frame ends with a
    // transition to what that first access needs.
    let mut initial: Vec<State> = vec![State::COMMON; units.total];
    for (r, res) in model.resources.iter().enumerate() {
        let base = units.base(r as u32);
        let count = units.count(r as u32);
        initial[base..base + count].fill(res.initial_state);
    }
    let mut last: Vec<State> = initial.clone();
    let mut first: Vec<Option<(u32, State)>> = vec![None; units.total];
    let mut scratch = Vec::new();
    for &p in order {
        needs(model, units, p as usize, &mut scratch);
        for n in &scratch {
            last[n.unit] = n.state;
            first[n.unit].get_or_insert((p, n.state));
        }
    }
    // Previous-frame copies end their frame where the resource they copy ends it.
    for (r, res) in model.resources.iter().enumerate() {
        if let Some(of) = res.previous_of {
            let (base, of_base) = (units.base(r as u32), units.base(of));
            for i in 0..units.count(r as u32) {
                last[base + i] = last[of_base + i];
            }
        }
    }
    let mut steady = last.clone();
    let mut end_of_frame: Vec<Option<u32>> = vec![None; units.total];
    for u in 0..units.total {
        if let Some((p0, need)) = first[u] {
            let queue = model.queue_type(p0 as usize);
            if !last[u].allowed_on(queue) {
                steady[u] = need;
                end_of_frame[u] = Some(p0);
            }
        }
    }
    let (mut plan, requires) = walk(model, units, order, &steady, &end_of_frame);
    plan.initial_states = steady;
    plan.fences = fences(model, graph, order, requires);
    plan
}

/// Whether a unit in state `have` serves an access needing `need` on a queue of type `queue`:
/// the same state, or a read state that includes it, and one the queue may hold.
pub(crate) fn serves(have: State, need: State, queue: QueueType) -> bool {
    (have == need || (need.is_read_only() && have.is_read_only() && have.contains(need)))
        && have.allowed_on(queue)
}

fn walk(
    model: &FrameModel,
    units: &Units,
    order: &[u32],
    initial: &[State],
    end_of_frame: &[Option<u32>],
) -> (BarrierPlan, Vec<Vec<u32>>) {
    let mut track: Vec<UnitTrack> = initial
        .iter()
        .map(|&state| UnitTrack {
            state,
            last_pos: None,
            last_pass: 0,
            pending_uav_write: 0,
            pending_uav_read: 0,
        })
        .collect();
    // Passes that accessed each unit since its last barrier, and where that barrier sits.
    // The latest pass on each queue that accessed each unit since its last barrier (flat,
    // unit-major); only the latest per queue matters, queue order covers the earlier ones.
    let nq = model.queues.len();
    let mut since_sync: Vec<u32> = vec![NO_PASS; units.total * nq];
    let mut anchor: Vec<Option<(Placement, u32)>> = vec![None; units.total];
    // requires[b] lists passes that must happen before pass b starts.
    let mut requires: Vec<Vec<u32>> = vec![Vec::new(); model.passes.len()];
    let mut pending: Vec<Pending> = Vec::new();
    let mut transfers: Vec<(u32, u32, u32, u32, u32, u32, u32)> = Vec::new();
    let mut scratch = Vec::new();
    for (pos, &p) in order.iter().enumerate() {
        let pos = pos as u32;
        let queue = model.passes[p as usize].queue;
        let qtype = model.queues[queue as usize].queue_type;
        needs(model, units, p as usize, &mut scratch);
        // `needs` merged accesses per unit, so each unit is seen once per pass.
        for n in &scratch {
            let t = track[n.unit];
            let resource = n.resource;
            let (mip, layer) = units.cell(model, resource, n.unit);
            let transition = !serves(t.state, n.state, qtype);
            let qbit = queue_bit(queue);
            let uav_barrier = !transition
                && n.uav
                && (t.pending_uav_write & qbit != 0
                    || (n.writes && t.pending_uav_read & qbit != 0));
            let last_queue = t.last_pos.map(|_| model.passes[t.last_pass as usize].queue);
            if transition || uav_barrier {
                let on_consumer = t.state.allowed_on(qtype) && n.state.allowed_on(qtype);
                let (placement, barrier_queue) = match last_queue {
                    Some(lq) if transition && !on_consumer && lq != queue => {
                        (Placement::After(t.last_pass), lq)
                    }
                    _ => (Placement::Before(p), queue),
                };
                let split = match (placement, t.last_pos) {
                    (Placement::Before(_), Some(lp))
                        if transition && pos > lp + 1 && last_queue == Some(queue) =>
                    {
                        Some(t.last_pass)
                    }
                    _ => None,
                };
                // The barrier acts like a write: earlier accesses on other queues come first.
                let target = placement.pass();
                let accessors = &mut since_sync[n.unit * nq..(n.unit + 1) * nq];
                for (q, a) in accessors.iter().enumerate() {
                    if *a != NO_PASS && q as u32 != barrier_queue && *a != target {
                        requires[target as usize].push(*a);
                    }
                }
                accessors.fill(NO_PASS);
                if let Placement::After(q) = placement {
                    requires[p as usize].push(q);
                }
                anchor[n.unit] = Some((placement, barrier_queue));
                pending.push(Pending {
                    placement,
                    queue: barrier_queue,
                    for_pass: p,
                    kind: if transition {
                        BarrierKind::Transition
                    } else {
                        BarrierKind::Uav
                    },
                    resource,
                    before: t.state,
                    after: n.state,
                    split,
                    next_frame: false,
                    mip,
                    layer,
                });
            } else if let Some((placement, barrier_queue)) = anchor[n.unit] {
                // The state this access relies on was set by that barrier: it must come first.
                if barrier_queue != queue && placement.pass() != p {
                    requires[p as usize].push(placement.pass());
                }
            }
            if let (Some(lq), true) = (last_queue, n.reads)
                && model.queues[lq as usize].queue_type != qtype
            {
                transfers.push((resource, t.last_pass, p, lq, queue, mip, layer));
            }
            let t = &mut track[n.unit];
            if transition || uav_barrier {
                t.pending_uav_write = 0;
                t.pending_uav_read = 0;
            }
            if transition {
                t.state = n.state;
            }
            if n.uav {
                if n.writes {
                    // The latest write supersedes earlier ones, which were ordered before it.
                    t.pending_uav_write = qbit;
                    t.pending_uav_read = 0;
                } else {
                    t.pending_uav_read |= qbit;
                }
            }
            t.last_pos = Some(pos);
            t.last_pass = p;
            since_sync[n.unit * nq + queue as usize] = p;
        }
    }
    for (u, next) in end_of_frame.iter().enumerate() {
        let (Some(p0), Some(_)) = (next, track[u].last_pos) else {
            continue;
        };
        let t = track[u];
        let (resource, mip, layer) = units.locate(model, u);
        let queue = model.passes[t.last_pass as usize].queue;
        for (q, &a) in since_sync[u * nq..(u + 1) * nq].iter().enumerate() {
            if a != NO_PASS && q as u32 != queue && a != t.last_pass {
                requires[t.last_pass as usize].push(a);
            }
        }
        pending.push(Pending {
            placement: Placement::After(t.last_pass),
            queue,
            for_pass: *p0,
            kind: BarrierKind::Transition,
            resource,
            before: t.state,
            after: initial[u],
            split: None,
            next_frame: true,
            mip,
            layer,
        });
    }
    let barriers = batch(model, units, pending);
    let transfers = batch_transfers(model, units, transfers);
    (
        BarrierPlan {
            barriers,
            fences: Vec::new(),
            transfers,
            initial_states: Vec::new(),
        },
        requires,
    )
}

/// Merges per-unit barriers with the same key into rectangles of mips x layers (or runs of
/// byte intervals for buffers).
fn batch(model: &FrameModel, units: &Units, pending: Vec<Pending>) -> Vec<Barrier> {
    // Pending barriers arrive in pass order and, within a pass, in unit order, so a resource's
    // barriers with equal keys are adjacent: group runs without sorting.
    let mut out = Vec::new();
    let mut i = 0;
    while i < pending.len() {
        let key = |x: &Pending| {
            (
                x.placement,
                x.queue,
                x.for_pass,
                x.kind,
                x.resource,
                x.before,
                x.after,
                x.split,
                x.next_frame,
            )
        };
        let mut j = i;
        while j < pending.len() && key(&pending[j]) == key(&pending[i]) {
            j += 1;
        }
        let group = &pending[i..j];
        let head = group[0];
        for range in rectangles(
            model,
            units,
            head.resource,
            group.iter().map(|x| (x.mip, x.layer)),
        ) {
            out.push(Barrier {
                kind: head.kind,
                placement: head.placement,
                queue: head.queue,
                for_pass: head.for_pass,
                resource: head.resource,
                resource_before: None,
                range,
                before: head.before,
                after: head.after,
                split_begin_after: head.split,
                next_frame: head.next_frame,
            });
        }
        i = j;
    }
    out
}

fn batch_transfers(
    model: &FrameModel,
    units: &Units,
    mut t: Vec<(u32, u32, u32, u32, u32, u32, u32)>,
) -> Vec<OwnershipTransfer> {
    t.sort_unstable();
    t.dedup();
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let mut j = i;
        let key = |x: &(u32, u32, u32, u32, u32, u32, u32)| (x.0, x.1, x.2, x.3, x.4);
        while j < t.len() && key(&t[j]) == key(&t[i]) {
            j += 1;
        }
        let (resource, release_after, acquire_before, from_queue, to_queue, _, _) = t[i];
        for range in rectangles(model, units, resource, t[i..j].iter().map(|x| (x.5, x.6))) {
            out.push(OwnershipTransfer {
                resource,
                range,
                release_after,
                acquire_before,
                from_queue,
                to_queue,
            });
        }
        i = j;
    }
    out
}

/// Covers a set of (mip, layer) units (or buffer interval indices in `layer`) with ranges:
/// runs of layers per mip, merged across consecutive mips with the same runs.
fn rectangles(
    model: &FrameModel,
    units: &Units,
    resource: u32,
    cells: impl Iterator<Item = (u32, u32)>,
) -> Vec<Subresources> {
    let r = &model.resources[resource as usize];
    let cells: Vec<(u32, u32)> = cells.collect();
    let all = if r.is_buffer {
        units.count(resource)
    } else {
        (r.mips * r.layers) as usize
    };
    if cells.len() == all && all > 1 {
        // Cells are distinct units, so all of them is the whole resource.
        return vec![r.whole()];
    }
    if let [(mip, layer)] = cells[..] {
        // The common case: one unit, no merging.
        return vec![if r.is_buffer {
            let (begin, end) = units.buffer_interval(model, resource, layer);
            Subresources {
                mip_base: 0,
                mip_count: 1,
                layer_base: 0,
                layer_count: 1,
                byte_offset: begin,
                byte_size: end - begin,
            }
        } else {
            Subresources {
                mip_base: mip,
                mip_count: 1,
                layer_base: layer,
                layer_count: 1,
                byte_offset: 0,
                byte_size: 0,
            }
        }];
    }
    let mut by_mip: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (mip, layer) in cells {
        by_mip.entry(mip).or_default().push(layer);
    }
    let mut runs_by_mip: Vec<(u32, Vec<(u32, u32)>)> = Vec::new();
    for (mip, mut layers) in by_mip {
        layers.sort_unstable();
        layers.dedup();
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for l in layers {
            match runs.last_mut() {
                Some((start, count)) if *start + *count == l => *count += 1,
                _ => runs.push((l, 1)),
            }
        }
        runs_by_mip.push((mip, runs));
    }
    let mut out = Vec::new();
    let mut i = 0;
    while i < runs_by_mip.len() {
        let mut j = i + 1;
        while j < runs_by_mip.len()
            && runs_by_mip[j].0 == runs_by_mip[j - 1].0 + 1
            && runs_by_mip[j].1 == runs_by_mip[i].1
        {
            j += 1;
        }
        let (mip, runs) = &runs_by_mip[i];
        let mip_count = (j - i) as u32;
        for &(start, count) in runs {
            if r.is_buffer {
                let (begin, _) = units.buffer_interval(model, resource, start);
                let (_, end) = units.buffer_interval(model, resource, start + count - 1);
                out.push(Subresources {
                    mip_base: 0,
                    mip_count: 1,
                    layer_base: 0,
                    layer_count: 1,
                    byte_offset: begin,
                    byte_size: end - begin,
                });
            } else {
                out.push(Subresources {
                    mip_base: *mip,
                    mip_count,
                    layer_base: start,
                    layer_count: count,
                    byte_offset: 0,
                    byte_size: 0,
                });
            }
        }
        i = j;
    }
    out
}

/// Fences: every cross-queue data dependency, and every "must happen before" the barrier walk
/// found (accesses before a barrier on another queue, a barrier before the accesses relying on
/// it), must be ordered by queue order and fences. Vector clocks (per pass, the latest order
/// position on each queue known to happen before it) tell which are already covered; for the
/// rest one fence from the latest producer on each queue is added.
fn fences(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[u32],
    mut requires: Vec<Vec<u32>>,
) -> Vec<FenceNeed> {
    let nq = model.queues.len();
    let n = model.passes.len();
    let mut pos = vec![0u32; n];
    for (i, &p) in order.iter().enumerate() {
        pos[p as usize] = i as u32;
    }
    let mut declared_into: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(a, b) in &model.fences {
        declared_into[b as usize].push(a);
    }
    for e in graph.graph.edge_references() {
        if e.weight().kind.is_data() {
            let (a, b) = (e.source().index(), e.target().index());
            if model.passes[a].queue != model.passes[b].queue {
                requires[b].push(a as u32);
            }
        }
    }
    const NONE: i64 = -1;
    // Vector clocks, pass-major: clock[p * nq + q].
    let mut clock: Vec<i64> = vec![NONE; n * nq];
    let mut last_on_queue: Vec<Option<u32>> = vec![None; nq];
    let mut out = Vec::new();
    for &p in order {
        let q = model.passes[p as usize].queue as usize;
        let mut c = match last_on_queue[q] {
            Some(prev) => clock[prev as usize * nq..(prev as usize + 1) * nq].to_vec(),
            None => vec![NONE; nq],
        };
        for &a in &declared_into[p as usize] {
            for k in 0..nq {
                c[k] = c[k].max(clock[a as usize * nq + k]);
            }
            out.push(FenceNeed {
                signal_after: a,
                wait_before: p,
                declared: true,
            });
        }
        // Latest producers first: a fence from a later pass often covers earlier ones too.
        let mut producers = std::mem::take(&mut requires[p as usize]);
        producers.sort_unstable_by_key(|&a| Reverse(pos[a as usize]));
        producers.dedup();
        for a in producers {
            let aq = model.passes[a as usize].queue as usize;
            if c[aq] >= i64::from(pos[a as usize]) {
                continue;
            }
            for k in 0..nq {
                c[k] = c[k].max(clock[a as usize * nq + k]);
            }
            out.push(FenceNeed {
                signal_after: a,
                wait_before: p,
                declared: false,
            });
        }
        c[q] = i64::from(pos[p as usize]);
        clock[p as usize * nq..(p as usize + 1) * nq].copy_from_slice(&c);
        last_on_queue[q] = Some(p);
    }
    out.sort();
    out.dedup();
    out
}

/// Vulkan stages each queue type may name (the pipeline-stage / queue-capability table).
fn stage_allowed(stage: &str, queue: QueueType) -> bool {
    let graphics_only = matches!(
        stage,
        "VERTEX_INPUT"
            | "VERTEX_SHADER"
            | "FRAGMENT_SHADER"
            | "EARLY_FRAGMENT_TESTS"
            | "LATE_FRAGMENT_TESTS"
            | "COLOR_ATTACHMENT_OUTPUT"
    );
    let graphics_or_compute = matches!(stage, "DRAW_INDIRECT" | "COMPUTE_SHADER");
    match queue {
        QueueType::Graphics => true,
        QueueType::Compute => !graphics_only,
        QueueType::Copy => !graphics_only && !graphics_or_compute,
    }
}

/// The Vulkan image layout, pipeline stages and access flags equivalent to a D3D12 state.
pub fn vk_scope(state: State, queue: QueueType, buffer: bool, raster: bool) -> VkScope {
    let mut layout = None;
    let mut stages: Vec<&'static str> = Vec::new();
    let mut access: Vec<&'static str> = Vec::new();
    let shader_stages: &[&'static str] = if raster {
        &["VERTEX_SHADER", "FRAGMENT_SHADER"]
    } else {
        &["COMPUTE_SHADER"]
    };
    if state == State::COMMON {
        return VkScope {
            layout: (!buffer).then_some("GENERAL"),
            stages: vec!["ALL_COMMANDS"],
            access: vec!["MEMORY_READ", "MEMORY_WRITE"],
        };
    }
    for s in state.bits() {
        let (l, st, ac): (&'static str, &[&'static str], &[&'static str]) = match s {
            State::RENDER_TARGET => (
                "COLOR_ATTACHMENT_OPTIMAL",
                &["COLOR_ATTACHMENT_OUTPUT"],
                &["COLOR_ATTACHMENT_READ", "COLOR_ATTACHMENT_WRITE"],
            ),
            State::DEPTH_WRITE => (
                "DEPTH_STENCIL_ATTACHMENT_OPTIMAL",
                &["EARLY_FRAGMENT_TESTS", "LATE_FRAGMENT_TESTS"],
                &[
                    "DEPTH_STENCIL_ATTACHMENT_READ",
                    "DEPTH_STENCIL_ATTACHMENT_WRITE",
                ],
            ),
            State::DEPTH_READ => (
                "DEPTH_STENCIL_READ_ONLY_OPTIMAL",
                &["EARLY_FRAGMENT_TESTS", "LATE_FRAGMENT_TESTS"],
                &["DEPTH_STENCIL_ATTACHMENT_READ"],
            ),
            State::PIXEL_SHADER_RESOURCE => (
                "SHADER_READ_ONLY_OPTIMAL",
                &["FRAGMENT_SHADER"],
                &["SHADER_READ"],
            ),
            State::NON_PIXEL_SHADER_RESOURCE => (
                "SHADER_READ_ONLY_OPTIMAL",
                if raster {
                    &["VERTEX_SHADER"]
                } else {
                    &["COMPUTE_SHADER"]
                },
                &["SHADER_READ"],
            ),
            State::UNORDERED_ACCESS => ("GENERAL", shader_stages, &["SHADER_READ", "SHADER_WRITE"]),
            State::VERTEX_AND_CONSTANT_BUFFER => (
                "GENERAL",
                &[
                    "VERTEX_INPUT",
                    "VERTEX_SHADER",
                    "FRAGMENT_SHADER",
                    "COMPUTE_SHADER",
                ],
                &["VERTEX_ATTRIBUTE_READ", "UNIFORM_READ"],
            ),
            State::INDEX_BUFFER => ("GENERAL", &["VERTEX_INPUT"], &["INDEX_READ"]),
            State::INDIRECT_ARGUMENT => ("GENERAL", &["DRAW_INDIRECT"], &["INDIRECT_COMMAND_READ"]),
            State::COPY_SOURCE | State::RESOLVE_SOURCE => {
                ("TRANSFER_SRC_OPTIMAL", &["TRANSFER"], &["TRANSFER_READ"])
            }
            State::COPY_DEST | State::RESOLVE_DEST => {
                ("TRANSFER_DST_OPTIMAL", &["TRANSFER"], &["TRANSFER_WRITE"])
            }
            State::PRESENT => ("PRESENT_SRC_KHR", &["BOTTOM_OF_PIPE"], &[]),
            _ => ("GENERAL", &["ALL_COMMANDS"], &["MEMORY_READ"]),
        };
        // Combined read states share SHADER_READ_ONLY_OPTIMAL; depth read wins when sampled too.
        layout = Some(match (layout, l) {
            (Some("DEPTH_STENCIL_READ_ONLY_OPTIMAL"), _)
            | (_, "DEPTH_STENCIL_READ_ONLY_OPTIMAL") => "DEPTH_STENCIL_READ_ONLY_OPTIMAL",
            (Some(prev), _) if prev != l => "GENERAL",
            _ => l,
        });
        stages.extend(st.iter().copied().filter(|s| stage_allowed(s, queue)));
        access.extend_from_slice(ac);
    }
    stages.sort_unstable();
    stages.dedup();
    access.sort_unstable();
    access.dedup();
    if stages.is_empty() {
        stages.push("ALL_COMMANDS");
    }
    VkScope {
        layout: if buffer { None } else { layout },
        stages,
        access,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vulkan_scopes_respect_queue_capabilities() {
        let on_compute = vk_scope(
            State::NON_PIXEL_SHADER_RESOURCE,
            QueueType::Compute,
            false,
            false,
        );
        assert_eq!(on_compute.layout, Some("SHADER_READ_ONLY_OPTIMAL"));
        assert_eq!(on_compute.stages, ["COMPUTE_SHADER"]);
        let rt = vk_scope(State::RENDER_TARGET, QueueType::Graphics, false, true);
        assert_eq!(rt.stages, ["COLOR_ATTACHMENT_OUTPUT"]);
        // A graphics-only stage named for a copy queue is dropped.
        let vb = vk_scope(
            State::VERTEX_AND_CONSTANT_BUFFER,
            QueueType::Copy,
            true,
            false,
        );
        assert_eq!(vb.layout, None);
        assert!(
            !vb.stages
                .iter()
                .any(|s| s.contains("SHADER") || *s == "VERTEX_INPUT"),
            "{vb:?}"
        );
        let depth_sampled = vk_scope(
            State::DEPTH_READ.union(State::PIXEL_SHADER_RESOURCE),
            QueueType::Graphics,
            false,
            true,
        );
        assert_eq!(
            depth_sampled.layout,
            Some("DEPTH_STENCIL_READ_ONLY_OPTIMAL")
        );
    }
}
