//! An independent hazard checker. Given an order, a list of barriers and the fences, it replays
//! every access per subresource unit and reports unsynchronised read-after-write,
//! write-after-read and write-after-write pairs, accesses made in the wrong state, transitions
//! whose "before" state is wrong or that race with earlier accesses, and barriers on a queue
//! that cannot hold their states.
//!
//! It shares no code with the derivation (`barriers.rs`): it has its own rules, stated here,
//! so that a property test can hold one against the other.
//! - Two accesses conflict when at least one writes. They are synchronised when the first
//!   happens before the second (queue order and fences, transitively) and, on one queue, a
//!   barrier on the unit sits between them (or both are in the same non-UAV write state, which
//!   D3D12 orders implicitly: render target, depth, copy and resolve writes).
//! - A barrier acts like a write: every access since the unit's previous barrier must happen
//!   before it, and it must happen before the accesses that rely on the state it sets.
//! - An access needs the unit in its state, or in a read state that includes its read state,
//!   and the state must be one the access's queue may hold.

use serde::Serialize;

use super::clocks::Clocks;
use super::model::{FrameModel, MPass, MQueue, MResource, State, Unit};
use super::units::Units;
use crate::capture::format::QueueType;
use crate::capture::model::Subresources;

/// A barrier as the checker sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct SyncBarrier {
    /// Executes before this pass (`after == false`) or right after it (`after == true`).
    pub pass: MPass,
    pub after: bool,
    pub queue: MQueue,
    /// A UAV barrier changes no state.
    pub uav: bool,
    pub resource: MResource,
    pub range: Subresources,
    pub before: State,
    pub after_state: State,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HazardKind {
    ReadAfterWrite,
    WriteAfterRead,
    WriteAfterWrite,
    /// An access races with a barrier (the barrier's layout change is a write).
    BarrierRace,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Hazard {
    pub kind: HazardKind,
    pub earlier: MPass,
    pub later: MPass,
    pub resource: MResource,
    pub mip: u32,
    pub layer: u32,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StateError {
    WrongState {
        pass: MPass,
        resource: MResource,
        mip: u32,
        layer: u32,
        have: State,
        need: State,
    },
    WrongBefore {
        barrier: usize,
        have: State,
        recorded: State,
    },
    QueueCannotHold {
        barrier: usize,
        queue: MQueue,
        state: State,
    },
    UnorderedState {
        pass: MPass,
        resource: MResource,
        barrier: usize,
    },
    /// The frame leaves a unit in a state other than the one the next frame starts with.
    FrameEndMismatch {
        resource: MResource,
        mip: u32,
        layer: u32,
        end: State,
        start: State,
    },
}

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CheckReport {
    pub hazards: Vec<Hazard>,
    pub state_errors: Vec<StateError>,
}

impl CheckReport {
    pub fn is_clean(&self) -> bool {
        self.hazards.is_empty() && self.state_errors.is_empty()
    }
}

/// Happens-before over queue order and fences.
type HappensBefore = Clocks;

fn happens_before(model: &FrameModel, order: &[MPass], fences: &[(MPass, MPass)]) -> HappensBefore {
    let n = model.passes.len();
    let mut preds: Vec<Vec<MPass>> = vec![Vec::new(); n];
    for &(a, b) in fences {
        if let Some(list) = preds.get_mut(b.index()) {
            list.push(a);
        }
    }
    let queue_of = model.passes.iter().map(|p| p.queue).collect();
    Clocks::new(model.queues.len(), queue_of, order, |p| {
        preds[p.index()].clone()
    })
}

#[derive(Clone, Copy)]
struct Use {
    pass: MPass,
    queue: MQueue,
    state: State,
    time: u32,
}

#[derive(Clone, Copy)]
struct Applied {
    barrier: usize,
    time: u32,
}

/// Whether barrier `b` lies between access `a` and pass `later` in happens-before terms.
fn barrier_between(hb: &HappensBefore, b: &SyncBarrier, a: MPass, later: MPass) -> bool {
    if b.after {
        hb.before_or_same(a, b.pass) && hb.before(b.pass, later)
    } else {
        hb.before(a, b.pass) && hb.before_or_same(b.pass, later)
    }
}

/// Whether the barrier happens before pass `p`'s accesses.
fn barrier_before(hb: &HappensBefore, b: &SyncBarrier, p: MPass) -> bool {
    if b.after {
        hb.before(b.pass, p)
    } else {
        hb.before_or_same(b.pass, p)
    }
}

fn implicitly_ordered(a: State, b: State) -> bool {
    a == b
        && [
            State::RENDER_TARGET,
            State::DEPTH_WRITE,
            State::COPY_DEST,
            State::RESOLVE_DEST,
        ]
        .contains(&a)
}

fn holds(queue: QueueType, s: State) -> bool {
    let graphics_only = State::RENDER_TARGET.0
        | State::DEPTH_WRITE.0
        | State::DEPTH_READ.0
        | State::PIXEL_SHADER_RESOURCE.0
        | State::INDEX_BUFFER.0
        | State::RESOLVE_DEST.0
        | State::RESOLVE_SOURCE.0
        | State::PRESENT.0;
    match queue {
        QueueType::Graphics => true,
        QueueType::Compute => s.0 & graphics_only == 0,
        QueueType::Copy => s.0 & !(State::COPY_DEST.0 | State::COPY_SOURCE.0) == 0,
    }
}

/// Replays the frame and reports every unsynchronised pair and state error.
pub fn check(
    model: &FrameModel,
    units: &Units,
    order: &[MPass],
    barriers: &[SyncBarrier],
    fences: &[(MPass, MPass)],
    initial: &[State],
) -> CheckReport {
    let mut before_pass: Vec<Vec<usize>> = vec![Vec::new(); model.passes.len()];
    let mut after_pass: Vec<Vec<usize>> = vec![Vec::new(); model.passes.len()];
    for (i, b) in barriers.iter().enumerate() {
        if b.after {
            after_pass[b.pass.index()].push(i)
        } else {
            before_pass[b.pass.index()].push(i)
        }
    }
    let mut c = Checker {
        model,
        units,
        barriers,
        hb: happens_before(model, order, fences),
        report: CheckReport::default(),
        state: initial.to_vec(),
        last_write: vec![None; units.total],
        reads: vec![Vec::new(); units.total],
        since_barrier: vec![Vec::new(); units.total],
        applied: vec![Vec::new(); units.total],
        time: 0,
    };
    for &p in order {
        for &i in &before_pass[p.index()] {
            c.apply(i);
        }
        c.time += 1;
        let need = c.need(p);
        c.check_pass(p, &need);
        c.record(p, &need);
        c.time += 1;
        for &i in &after_pass[p.index()] {
            c.apply(i);
        }
        c.time += 1;
    }
    c.frame_end(initial);
    c.report
}

/// A pass's combined need of one unit: (unit, state, reads, writes).
type Need = (Unit, State, bool, bool);

/// The walk's state: what each unit holds, who last used it, which barriers reached it.
struct Checker<'a> {
    model: &'a FrameModel,
    units: &'a Units,
    barriers: &'a [SyncBarrier],
    hb: HappensBefore,
    report: CheckReport,
    state: Vec<State>,
    last_write: Vec<Option<Use>>,
    reads: Vec<Vec<Use>>,
    since_barrier: Vec<Vec<Use>>,
    applied: Vec<Vec<Applied>>,
    time: u32,
}

impl Checker<'_> {
    /// Applies barrier `i`: its states must be ones its queue can hold and its before-state
    /// the unit's; every use since the last barrier must happen before it.
    fn apply(&mut self, i: usize) {
        let (model, units, hb, time) = (self.model, self.units, &self.hb, self.time);
        let b = &self.barriers[i];
        let report = &mut self.report;
        let qtype = model.queues[b.queue.index()].queue_type;
        if !b.uav {
            for s in [b.before, b.after_state] {
                if !holds(qtype, s) {
                    report.state_errors.push(StateError::QueueCannotHold {
                        barrier: i,
                        queue: b.queue,
                        state: s,
                    });
                }
            }
        }
        let access = super::model::ModelAccess {
            resource: b.resource,
            range: b.range,
            state: b.after_state,
            reads: false,
            writes: false,
            uav: false,
        };
        let (state, since, applied) = (&mut self.state, &mut self.since_barrier, &mut self.applied);
        units.for_each(model, &access, |unit| {
            let u = unit.index();
            if !b.uav {
                if state[u] != b.before {
                    report.state_errors.push(StateError::WrongBefore {
                        barrier: i,
                        have: state[u],
                        recorded: b.before,
                    });
                }
                state[u] = b.after_state;
            }
            for a in since[u].drain(..) {
                let ordered = if b.after {
                    hb.before_or_same(a.pass, b.pass)
                } else {
                    hb.before(a.pass, b.pass)
                };
                if !ordered {
                    let (resource, mip, layer) = units.locate(model, unit);
                    report.hazards.push(Hazard {
                        kind: HazardKind::BarrierRace,
                        earlier: a.pass,
                        later: b.pass,
                        resource,
                        mip,
                        layer,
                    });
                }
            }
            applied[u].push(Applied { barrier: i, time });
        });
    }

    /// The pass's combined need per unit: read states add up; a write state stands alone.
    fn need(&self, p: MPass) -> Vec<Need> {
        let mut need: Vec<Need> = Vec::new();
        for a in &self.model.passes[p.index()].accesses {
            self.units.for_each(self.model, a, |u| {
                if let Some(e) = need.iter_mut().find(|e| e.0 == u) {
                    if a.state.is_write() {
                        e.1 = a.state;
                    } else if !e.1.is_write() {
                        e.1 = State(e.1.0 | a.state.0);
                    }
                    e.2 |= a.reads;
                    e.3 |= a.writes;
                } else {
                    need.push((u, a.state, a.reads, a.writes));
                }
            });
        }
        need
    }

    /// Each unit the pass uses must be in a state that serves it, set by a barrier ordered
    /// before the pass, and every earlier conflicting use must be synchronised with it.
    fn check_pass(&mut self, p: MPass, need: &[Need]) {
        let (model, units, hb, barriers) = (self.model, self.units, &self.hb, self.barriers);
        let queue = model.passes[p.index()].queue;
        let qtype = model.queues[queue.index()].queue_type;
        for &(unit, s, r, w) in need {
            let (resource, mip, layer) = units.locate(model, unit);
            let u = unit.index();
            let have = self.state[u];
            let ok = have == s
                || (!s.is_write()
                    && s != State::COMMON
                    && !have.is_write()
                    && have != State::COMMON
                    && have.0 & s.0 == s.0);
            if !ok || !holds(qtype, have) {
                self.report.state_errors.push(StateError::WrongState {
                    pass: p,
                    resource,
                    mip,
                    layer,
                    have,
                    need: s,
                });
            }
            let applied = &self.applied[u];
            if let Some(last) = applied.last()
                && !barrier_before(hb, &barriers[last.barrier], p)
            {
                self.report.state_errors.push(StateError::UnorderedState {
                    pass: p,
                    resource,
                    barrier: last.barrier,
                });
            }
            let synced = |earlier: &Use| -> bool {
                if !hb.before(earlier.pass, p) {
                    return false;
                }
                if earlier.queue != queue {
                    return true;
                }
                implicitly_ordered(earlier.state, s)
                    || applied.iter().any(|x| {
                        x.time > earlier.time
                            && barrier_between(hb, &barriers[x.barrier], earlier.pass, p)
                    })
            };
            let mut found = Vec::new();
            if let Some(wr) = self.last_write[u].filter(|wr| wr.pass != p) {
                if r && !synced(&wr) {
                    found.push((HazardKind::ReadAfterWrite, wr.pass));
                } else if w && !r && !synced(&wr) {
                    found.push((HazardKind::WriteAfterWrite, wr.pass));
                }
            }
            if w {
                for rd in self.reads[u].iter().filter(|rd| rd.pass != p) {
                    if !synced(rd) {
                        found.push((HazardKind::WriteAfterRead, rd.pass));
                    }
                }
            }
            for (kind, earlier) in found {
                self.report.hazards.push(Hazard {
                    kind,
                    earlier,
                    later: p,
                    resource,
                    mip,
                    layer,
                });
            }
        }
    }

    /// Records the pass's uses for the passes after it.
    fn record(&mut self, p: MPass, need: &[Need]) {
        let queue = self.model.passes[p.index()].queue;
        for &(unit, s, r, w) in need {
            let u = unit.index();
            let use_ = Use {
                pass: p,
                queue,
                state: s,
                time: self.time,
            };
            if w {
                self.last_write[u] = Some(use_);
                self.reads[u].clear();
            } else if r {
                self.reads[u].push(use_);
            }
            self.since_barrier[u].push(use_);
        }
    }

    /// Frames repeat: the next one starts where this one ends.
    fn frame_end(&mut self, initial: &[State]) {
        for (u, (&end, &start)) in self.state.iter().zip(initial).enumerate() {
            if end != start {
                let (resource, mip, layer) = self.units.locate(self.model, Unit::new(u));
                self.report.state_errors.push(StateError::FrameEndMismatch {
                    resource,
                    mip,
                    layer,
                    end,
                    start,
                });
            }
        }
    }
}

/// Barriers that can be removed without introducing a hazard or a state error.
pub fn redundant(
    model: &FrameModel,
    units: &Units,
    order: &[MPass],
    barriers: &[SyncBarrier],
    fences: &[(MPass, MPass)],
    initial: &[State],
) -> Vec<usize> {
    (0..barriers.len())
        .filter(|&i| {
            let mut fewer = barriers.to_vec();
            fewer.remove(i);
            check(model, units, order, &fewer, fences, initial).is_clean()
        })
        .collect()
}
