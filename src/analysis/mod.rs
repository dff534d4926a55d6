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
