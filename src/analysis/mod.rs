//! Frame analysis: the pass DAG and what is derived from it (order, culling, barriers, memory
//! aliasing, lints, async compute and the critical path). Nothing here uses wgpu or egui.

pub mod barriers;
pub mod graph;
pub mod hazards;
pub mod lints;
pub mod memory;
pub mod model;
pub mod report;
pub mod schedule;
pub mod synthetic;

use barriers::{Barrier, BarrierKind, Placement};
use hazards::SyncBarrier;

/// A derived barrier in the hazard checker's terms (aliasing barriers carry no state and are
/// checked by the memory plan, not here).
pub fn to_sync(b: &Barrier) -> Option<SyncBarrier> {
    let (pass, after) = match b.placement {
        Placement::Before(p) => (p, false),
        Placement::After(p) => (p, true),
    };
    match b.kind {
        BarrierKind::Aliasing => None,
        kind => Some(SyncBarrier {
            pass,
            after,
            queue: b.queue,
            uav: kind == BarrierKind::Uav,
            resource: b.resource,
            range: b.range,
            before: b.before,
            after_state: b.after,
        }),
    }
}

/// Barriers and the memory plan of one ordered frame. They depend on the order but not on each
/// other, so they are derived on two threads when the machine has two cores.
pub fn barriers_and_memory(
    model: &model::FrameModel,
    units: &model::Units,
    graph: &graph::PassGraph,
    order: &[u32],
) -> (barriers::BarrierPlan, memory::MemoryPlan) {
    let parallel = std::thread::available_parallelism().is_ok_and(|n| n.get() > 1);
    if !parallel {
        return (
            barriers::derive(model, units, graph, order),
            memory::plan(model, order),
        );
    }
    std::thread::scope(|s| {
        let memory = s.spawn(|| memory::plan(model, order));
        let plan = barriers::derive(model, units, graph, order);
        // A panic in the planner is a bug: carry it on to this thread.
        let memory = memory
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (plan, memory)
    })
}
