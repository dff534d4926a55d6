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
use super::model::{FrameModel, MPass, MQueue, MResource, OptPass, State, Unit};
use super::units::{UnitUse, Units};
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
    Before(MPass),
    After(MPass),
}

impl Placement {
    pub fn pass(self) -> MPass {
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
    pub queue: MQueue,
    /// The pass whose access needs it.
    pub for_pass: MPass,
    pub resource: MResource,
    pub range: Subresources,
    pub before: State,
    pub after: State,
    /// A split barrier could begin right after this pass (passes run in between).
    pub split_begin_after: Option<MPass>,
    /// An end-of-frame transition that prepares the resource for `for_pass` of the next frame,
    /// whose queue cannot hold the state this frame leaves it in.
    pub next_frame: bool,
}

impl Barrier {
    /// Vulkan's source and destination scopes for this barrier (computed on demand: reports
    /// need them, the derivation does not).
    pub fn vulkan(&self, model: &FrameModel) -> (VkScope, VkScope) {
        let qtype = model.queues[self.queue.index()].queue_type;
        let buffer = model.resources[self.resource.index()].is_buffer;
        let src_pass = self.split_begin_after.unwrap_or(self.placement.pass());
        let src = vk_scope(
            self.before,
            qtype,
            buffer,
            model.passes[src_pass.index()].raster,
        );
        let dst = vk_scope(
            self.after,
            qtype,
            buffer,
            model.passes[self.for_pass.index()].raster,
        );
        (src, dst)
    }
}

/// A fence a cross-queue dependency needs.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct FenceNeed {
    pub signal_after: MPass,
    pub wait_before: MPass,
    /// Declared in the capture, or derived here because nothing else orders the two passes.
    pub declared: bool,
}

/// A Vulkan queue-family ownership transfer (release on one queue, acquire on the other).
#[derive(Clone, Debug, Serialize)]
pub struct OwnershipTransfer {
    pub resource: MResource,
    pub range: Subresources,
    pub release_after: MPass,
    pub acquire_before: MPass,
    pub from_queue: MQueue,
    pub to_queue: MQueue,
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

/// Per-unit tracking while walking the order.
#[derive(Clone, Copy)]
struct UnitTrack {
    state: State,
    /// Position in the order (`NO_POS` before the first access) and pass of the last access
    /// (meaningless before it).
    last_pos: u32,
    last_pass: MPass,
    /// The unit's last barrier: the pass it is placed at and the queue it is recorded on.
    anchor_pass: OptPass,
    anchor_queue: MQueue,
    /// Queues (bit per queue index) with an unordered-access write / read since the last
    /// barrier: a UAV barrier orders accesses on one queue; other queues are ordered by fences.
    pending_uav_write: u32,
    pending_uav_read: u32,
}

impl UnitTrack {
    /// Records an access to the unit by pass `p` at position `pos` on queue bit `qbit`, after
    /// any barrier the walk placed for it.
    #[inline]
    fn record(
        &mut self,
        n: &UnitUse,
        pos: u32,
        p: MPass,
        qbit: u32,
        barrier: bool,
        transition: bool,
    ) {
        if barrier {
            self.pending_uav_write = 0;
            self.pending_uav_read = 0;
        }
        if transition {
            self.state = n.state;
        }
        if n.uav {
            if n.writes {
                // The latest write supersedes earlier ones, which were ordered before it.
                self.pending_uav_write = qbit;
                self.pending_uav_read = 0;
            } else {
                self.pending_uav_read |= qbit;
            }
        }
        self.last_pos = pos;
        self.last_pass = p;
    }
}

/// No position in the order yet. Positions stay bare `u32`s in the per-unit track (a
/// sentinel, not `Option`, keeps `UnitTrack` as small as before).
const NO_POS: u32 = u32::MAX;

/// Queues past the 32nd share a bit: more UAV barriers among them, never fewer.
fn queue_bit(queue: MQueue) -> u32 {
    1u32 << queue.0.min(31)
}

/// What barriers are batched by: one unit's barriers with equal keys in one pass boundary merge
/// into ranges.
#[derive(Clone, Copy, PartialEq, Eq)]
struct BatchKey {
    placement: Placement,
    queue: MQueue,
    for_pass: MPass,
    kind: BarrierKind,
    resource: MResource,
    before: State,
    after: State,
    split: Option<MPass>,
    next_frame: bool,
}

/// Merges per-unit barriers into rectangles of mips x layers (or runs of byte intervals for
/// buffers) as they are found. Barriers arrive in pass order and, within a pass, in unit order,
/// so a resource's barriers with equal keys are adjacent: runs are grouped without sorting.
struct Batcher<'a> {
    model: &'a FrameModel,
    units: &'a Units,
    key: Option<BatchKey>,
    /// The current run's units within the resource (mip-major for textures, interval index
    /// for buffers).
    cells: Vec<(u32, u32)>,
    out: Vec<Barrier>,
}

impl<'a> Batcher<'a> {
    fn new(model: &'a FrameModel, units: &'a Units, capacity: usize) -> Self {
        Self {
            model,
            units,
            key: None,
            cells: Vec::new(),
            out: Vec::with_capacity(capacity),
        }
    }

    fn add(&mut self, key: BatchKey, unit: Unit) {
        if self.key != Some(key) {
            self.flush();
            self.key = Some(key);
        }
        let cell = self.units.cell(key.resource, unit);
        self.cells.push(cell);
    }

    fn flush(&mut self) {
        let Some(key) = self.key.take() else { return };
        let out = &mut self.out;
        rectangles(self.model, self.units, key.resource, &self.cells, |range| {
            out.push(Barrier {
                kind: key.kind,
                placement: key.placement,
                queue: key.queue,
                for_pass: key.for_pass,
                resource: key.resource,
                range,
                before: key.before,
                after: key.after,
                split_begin_after: key.split,
                next_frame: key.next_frame,
            })
        });
        self.cells.clear();
    }

    fn finish(mut self) -> Vec<Barrier> {
        self.flush();
        self.out
    }
}

pub fn derive(
    model: &FrameModel,
    units: &Units,
    graph: &PassGraph,
    order: &[MPass],
) -> BarrierPlan {
    // First walk: the state each unit is left in, which is where the next frame starts, unless
    // the first queue to touch it next frame cannot hold that state: then the frame ends with a
    // transition to what that first access needs.
    let mut steady: Vec<State> = vec![State::COMMON; units.total];
    for (r, resource) in model.resources.iter().enumerate() {
        // Only accessed resources have units; the others are not read at all.
        steady[units.span(MResource::new(r))].fill(resource.initial_state);
    }
    // The first pass to use each unit and the state it needs.
    let mut first: Vec<(OptPass, State)> = vec![(OptPass::NONE, State::COMMON); units.total];
    for &p in order {
        for n in units.uses(p) {
            let u = n.unit.index();
            steady[u] = n.state;
            if first[u].0.is_none() {
                first[u] = (OptPass::some(p), n.state);
            }
        }
    }
    // Previous-frame copies end their frame where the resource they copy ends it.
    for &(copy, of) in units.previous_copies() {
        let (base, of_base) = (units.base(copy).index(), units.base(of).index());
        for i in 0..units.count(copy).min(units.count(of)) {
            steady[base + i] = steady[of_base + i];
        }
    }
    // `steady` holds each unit's last state; where the first queue can't hold it, the frame
    // ends with a transition to what the first access needs.
    let mut end_of_frame: Vec<OptPass> = vec![OptPass::NONE; units.total];
    for (u, &(p0, need)) in first.iter().enumerate() {
        if let Some(p0) = p0.get()
            && !steady[u].allowed_on(model.queue_type(p0))
        {
            steady[u] = need;
            end_of_frame[u] = OptPass::some(p0);
        }
    }
    drop(first);
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

/// One unit's queue-ownership transfer before batching: (resource, release after, acquire
/// before, from queue, to queue, mip, layer).
type TransferCell = (MResource, MPass, MPass, MQueue, MQueue, u32, u32);

/// "Must happen before" constraints the walk finds, as (later pass, earlier pass).
type Requires = Vec<(MPass, MPass)>;

fn walk(
    model: &FrameModel,
    units: &Units,
    order: &[MPass],
    initial: &[State],
    end_of_frame: &[OptPass],
) -> (BarrierPlan, Requires) {
    let mut track: Vec<UnitTrack> = initial
        .iter()
        .map(|&state| UnitTrack {
            state,
            last_pos: NO_POS,
            last_pass: MPass(0),
            anchor_pass: OptPass::NONE,
            anchor_queue: MQueue(0),
            pending_uav_write: 0,
            pending_uav_read: 0,
        })
        .collect();
    let pass_queue: Vec<MQueue> = model.passes.iter().map(|p| p.queue).collect();
    // The latest pass on each queue that accessed each unit since its last barrier (flat,
    // unit-major); only the latest per queue matters, queue order covers the earlier ones.
    let nq = model.queues.len();
    let mut since_sync: Vec<OptPass> = vec![OptPass::NONE; units.total * nq];
    let mut requires: Requires = Vec::with_capacity(order.len() * 4);
    let mut batcher = Batcher::new(model, units, units.total * 2);
    let mut transfers: Vec<TransferCell> = Vec::with_capacity(units.use_count() / 2);
    for (pos, &p) in order.iter().enumerate() {
        let pos = pos as u32;
        let queue = pass_queue[p.index()];
        let qtype = model.queues[queue.index()].queue_type;
        let qbit = queue_bit(queue);
        // Uses are merged per unit, so each unit is seen once per pass.
        for n in units.uses(p) {
            let unit = n.unit.index();
            let t = track[unit];
            let resource = n.resource;
            let transition = !serves(t.state, n.state, qtype);
            let uav_barrier = !transition
                && n.uav
                && (t.pending_uav_write & qbit != 0
                    || (n.writes && t.pending_uav_read & qbit != 0));
            let last_queue = (t.last_pos != NO_POS).then(|| pass_queue[t.last_pass.index()]);
            if transition || uav_barrier {
                let on_consumer = t.state.allowed_on(qtype) && n.state.allowed_on(qtype);
                let (placement, barrier_queue) = match last_queue {
                    Some(lq) if transition && !on_consumer && lq != queue => {
                        (Placement::After(t.last_pass), lq)
                    }
                    _ => (Placement::Before(p), queue),
                };
                let split = (transition
                    && matches!(placement, Placement::Before(_))
                    && last_queue == Some(queue)
                    && pos > t.last_pos + 1)
                    .then_some(t.last_pass);
                // The barrier acts like a write: earlier accesses on other queues come first.
                let target = placement.pass();
                let accessors = &mut since_sync[unit * nq..(unit + 1) * nq];
                for (q, a) in accessors.iter_mut().enumerate() {
                    if let Some(a) = a.get()
                        && MQueue::new(q) != barrier_queue
                        && a != target
                    {
                        requires.push((target, a));
                    }
                    *a = OptPass::NONE;
                }
                if let Placement::After(q) = placement {
                    requires.push((p, q));
                }
                let t = &mut track[unit];
                t.anchor_pass = OptPass::some(target);
                t.anchor_queue = barrier_queue;
                batcher.add(
                    BatchKey {
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
                    },
                    n.unit,
                );
            } else if let Some(anchor) = t.anchor_pass.get()
                && t.anchor_queue != queue
                && anchor != p
            {
                // The state this access relies on was set by that barrier: it must come first.
                requires.push((p, anchor));
            }
            if let (Some(lq), true) = (last_queue, n.reads)
                && model.queues[lq.index()].queue_type != qtype
            {
                let (mip, layer) = units.cell(resource, n.unit);
                transfers.push((resource, t.last_pass, p, lq, queue, mip, layer));
            }
            track[unit].record(n, pos, p, qbit, transition || uav_barrier, transition);
            since_sync[unit * nq + queue.index()] = OptPass::some(p);
        }
    }
    end_of_frame_barriers(
        model,
        units,
        &track,
        &since_sync,
        initial,
        end_of_frame,
        &mut batcher,
        &mut requires,
    );
    let barriers = batcher.finish();
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

/// Transitions back to each unit's start-of-frame state after its last use (frames repeat),
/// ordered after every other queue's accesses since the unit's last barrier.
#[allow(clippy::too_many_arguments)]
fn end_of_frame_barriers(
    model: &FrameModel,
    units: &Units,
    track: &[UnitTrack],
    since_sync: &[OptPass],
    initial: &[State],
    end_of_frame: &[OptPass],
    batcher: &mut Batcher,
    requires: &mut Requires,
) {
    let pass_queue = |p: MPass| model.passes[p.index()].queue;
    let nq = model.queues.len();
    for (u, &p0) in end_of_frame.iter().enumerate() {
        let t = track[u];
        let Some(p0) = p0.get() else { continue };
        if t.last_pos == NO_POS {
            continue;
        }
        let unit = Unit::new(u);
        let (resource, _, _) = units.locate(model, unit);
        let queue = pass_queue(t.last_pass);
        for (q, &a) in since_sync[u * nq..(u + 1) * nq].iter().enumerate() {
            if let Some(a) = a.get()
                && MQueue::new(q) != queue
                && a != t.last_pass
            {
                requires.push((t.last_pass, a));
            }
        }
        batcher.add(
            BatchKey {
                placement: Placement::After(t.last_pass),
                queue,
                for_pass: p0,
                kind: BarrierKind::Transition,
                resource,
                before: t.state,
                after: initial[u],
                split: None,
                next_frame: true,
            },
            unit,
        );
    }
}

/// A stable counting sort into `buckets` buckets: item `i` of bucket `b` is
/// `sorted[start[b] as usize + i]`, and bucket `b` ends at `start[b + 1]`.
fn bucket_by<T: Copy + Default>(
    items: impl Iterator<Item = T> + Clone,
    buckets: usize,
    key: impl Fn(&T) -> usize,
) -> (Vec<u32>, Vec<T>) {
    let mut start = vec![0u32; buckets + 1];
    for x in items.clone() {
        start[key(&x) + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let mut fill = start.clone();
    let mut sorted: Vec<T> = vec![T::default(); start[buckets] as usize];
    for x in items {
        let b = key(&x);
        sorted[fill[b] as usize] = x;
        fill[b] += 1;
    }
    (start, sorted)
}

fn batch_transfers(
    model: &FrameModel,
    units: &Units,
    cells: Vec<TransferCell>,
) -> Vec<OwnershipTransfer> {
    // Sorted: bucketed by resource, then each resource's few sorted.
    let (start, mut t) = bucket_by(cells.iter().copied(), model.resources.len(), |x| {
        x.0.index()
    });
    for r in 0..model.resources.len() {
        let bucket = &mut t[start[r] as usize..start[r + 1] as usize];
        if bucket.len() > 1 {
            bucket.sort_unstable();
        }
    }
    t.dedup();
    let mut out = Vec::new();
    let mut cells: Vec<(u32, u32)> = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let mut j = i;
        let key = |x: &TransferCell| (x.0, x.1, x.2, x.3, x.4);
        while j < t.len() && key(&t[j]) == key(&t[i]) {
            j += 1;
        }
        let (resource, release_after, acquire_before, from_queue, to_queue, _, _) = t[i];
        cells.clear();
        cells.extend(t[i..j].iter().map(|x| (x.5, x.6)));
        rectangles(model, units, resource, &cells, |range| {
            out.push(OwnershipTransfer {
                resource,
                range,
                release_after,
                acquire_before,
                from_queue,
                to_queue,
            })
        });
        i = j;
    }
    out
}

/// Covers a set of (mip, layer) units (or buffer interval indices in `layer`) with ranges:
/// runs of layers per mip, merged across consecutive mips with the same runs.
fn rectangles(
    model: &FrameModel,
    units: &Units,
    resource: MResource,
    cells: &[(u32, u32)],
    mut emit: impl FnMut(Subresources),
) {
    // The resource itself is only read for a whole range: the units know its shape.
    let all = units.count(resource);
    let buffer = units.is_buffer(resource);
    if cells.len() == all && all > 1 {
        // Cells are distinct units, so all of them is the whole resource.
        emit(model.resources[resource.index()].whole());
        return;
    }
    if let [(mip, layer)] = cells[..] {
        // The common case: one unit, no merging.
        emit(if buffer {
            let (begin, end) = units.buffer_interval(resource, layer);
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
        });
        return;
    }
    let mut by_mip: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(mip, layer) in cells {
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
            if buffer {
                let (begin, _) = units.buffer_interval(resource, start);
                let (_, end) = units.buffer_interval(resource, start + count - 1);
                emit(Subresources {
                    mip_base: 0,
                    mip_count: 1,
                    layer_base: 0,
                    layer_count: 1,
                    byte_offset: begin,
                    byte_size: end - begin,
                });
            } else {
                emit(Subresources {
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
}

/// Fences: every cross-queue data dependency, and every "must happen before" the barrier walk
/// found (accesses before a barrier on another queue, a barrier before the accesses relying on
/// it), must be ordered by queue order and fences. Vector clocks (per pass, the latest order
/// position on each queue known to happen before it) tell which are already covered; for the
/// rest one fence from the latest producer on each queue is added.
fn fences(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[MPass],
    mut requires: Requires,
) -> Vec<FenceNeed> {
    let nq = model.queues.len();
    let n = model.passes.len();
    let pass_queue: Vec<MQueue> = model.passes.iter().map(|p| p.queue).collect();
    let mut pos = vec![0u32; n];
    for (i, &p) in order.iter().enumerate() {
        pos[p.index()] = i as u32;
    }
    for e in graph.graph.edge_references() {
        if e.weight().kind.is_data() {
            let (a, b) = (e.source().index(), e.target().index());
            if pass_queue[a] != pass_queue[b] {
                requires.push((MPass::new(b), MPass::new(a)));
            }
        }
    }
    // Producers of each pass as (pass, declared), grouped by the waiting pass; declared
    // fences come first in each group.
    let declared = model.fences.iter().map(|&(a, b)| (b, a, true));
    let derived = requires.iter().map(|&(b, a)| (b, a, false));
    let (start, producers) = bucket_by(declared.chain(derived), n, |x| x.0.index());
    let mut producers: Vec<(MPass, bool)> = producers.into_iter().map(|x| (x.1, x.2)).collect();
    const NONE: i64 = -1;
    // Vector clocks, pass-major: clock[p * nq + q].
    let mut clock: Vec<i64> = vec![NONE; n * nq];
    let mut c: Vec<i64> = vec![NONE; nq];
    let mut last_on_queue: Vec<Option<MPass>> = vec![None; nq];
    let mut out = Vec::new();
    for &p in order {
        let pi = p.index();
        let q = model.passes[pi].queue.index();
        match last_on_queue[q] {
            Some(prev) => {
                c.copy_from_slice(&clock[prev.index() * nq..(prev.index() + 1) * nq]);
            }
            None => c.fill(NONE),
        }
        let group = &mut producers[start[pi] as usize..start[pi + 1] as usize];
        let (declared, required) = group.split_at_mut(group.partition_point(|x| x.1));
        for &(a, _) in declared.iter() {
            for k in 0..nq {
                c[k] = c[k].max(clock[a.index() * nq + k]);
            }
            out.push(FenceNeed {
                signal_after: a,
                wait_before: p,
                declared: true,
            });
        }
        // Latest producers first: a fence from a later pass often covers earlier ones too.
        required.sort_unstable_by_key(|&(a, _)| Reverse(pos[a.index()]));
        let mut previous = None;
        for &(a, _) in required.iter() {
            if previous == Some(a) {
                continue;
            }
            previous = Some(a);
            let aq = pass_queue[a.index()].index();
            if c[aq] >= i64::from(pos[a.index()]) {
                continue;
            }
            for k in 0..nq {
                c[k] = c[k].max(clock[a.index() * nq + k]);
            }
            out.push(FenceNeed {
                signal_after: a,
                wait_before: p,
                declared: false,
            });
        }
        c[q] = i64::from(pos[pi]);
        clock[pi * nq..(pi + 1) * nq].copy_from_slice(&c);
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
