//! Frame analysis: the pass DAG and what is derived from it (order, culling, barriers, memory
//! aliasing, lints, async compute and the critical path). Nothing here uses wgpu or egui.

pub mod barriers;
pub mod clocks;
pub mod graph;
pub mod hazards;
pub mod lints;
pub mod memory;
pub mod model;
pub mod report;
pub mod schedule;
pub mod synthetic;
pub mod traffic;

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

/// A frame's units, pass graph and order, and what is derived from the order.
#[derive(Debug)]
pub struct Derived {
    pub units: model::Units,
    pub graph: graph::PassGraph,
    pub order: Vec<u32>,
    pub plan: barriers::BarrierPlan,
    /// `None` unless asked for.
    pub memory: Option<memory::MemoryPlan>,
}

fn parallel() -> bool {
    std::thread::available_parallelism().is_ok_and(|n| n.get() > 1)
}

/// Builds the pass graph, orders it and derives barriers (and the memory plan when asked).
///
/// When the recorded order is the order (no fence points backwards, see
/// `graph::recorded_order`), the memory plan needs nothing else and is derived on a second
/// thread from the start, beside units, graph and barriers; otherwise it waits for the order
/// and runs beside the barriers.
pub fn derive_frame(
    model: &model::FrameModel,
    with_memory: bool,
) -> Result<Derived, graph::CycleError> {
    if with_memory
        && parallel()
        && let Some(order) = graph::recorded_order(model)
    {
        let (units, graph, plan, memory) = std::thread::scope(|s| {
            let memory = s.spawn(|| memory::plan(model, &order));
            let units = model::Units::new(model);
            let graph = graph::build(model, &units);
            let plan = barriers::derive(model, &units, &graph, &order);
            // A panic in the planner is a bug: carry it on to this thread.
            let memory = memory
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e));
            (units, graph, plan, memory)
        });
        return Ok(Derived {
            units,
            graph,
            order,
            plan,
            memory: Some(memory),
        });
    }
    let units = model::Units::new(model);
    let graph = graph::build(model, &units);
    let order = graph::order(model, &graph)?;
    let (plan, memory) = if with_memory {
        let (plan, memory) = barriers_and_memory(model, &units, &graph, &order);
        (plan, Some(memory))
    } else {
        (barriers::derive(model, &units, &graph, &order), None)
    };
    Ok(Derived {
        units,
        graph,
        order,
        plan,
        memory,
    })
}

/// Barriers and the memory plan of one ordered frame. They depend on the order but not on each
/// other, so they are derived on two threads when the machine has two cores.
pub fn barriers_and_memory(
    model: &model::FrameModel,
    units: &model::Units,
    graph: &graph::PassGraph,
    order: &[u32],
) -> (barriers::BarrierPlan, memory::MemoryPlan) {
    if !parallel() {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// What `derive_frame` returns must not depend on which threads did the work.
    fn same_as_one_thread(model: &model::FrameModel) {
        let units = model::Units::new(model);
        let g = graph::build(model, &units);
        let order = graph::order(model, &g).unwrap();
        let plan = barriers::derive(model, &units, &g, &order);
        let mem = memory::plan(model, &order);
        let derived = derive_frame(model, true).unwrap();
        assert_eq!(derived.order, order);
        assert_eq!(derived.graph.graph.edge_count(), g.graph.edge_count());
        assert_eq!(
            serde_json::to_string(&derived.plan).unwrap(),
            serde_json::to_string(&plan).unwrap()
        );
        assert_eq!(
            serde_json::to_string(&derived.memory).unwrap(),
            serde_json::to_string(&Some(mem)).unwrap()
        );
        assert!(derive_frame(model, false).unwrap().memory.is_none());
    }

    #[test]
    fn derive_frame_matches_the_stages_run_one_by_one() {
        let mut model = synthetic::frame(400, 600, 3);
        same_as_one_thread(&model);
        // A last pass on a queue of its own, on a resource of its own, that the first pass
        // waits for: the recorded order is no longer the order, and the other path runs.
        let mut extra = model.passes[0].clone();
        extra.name = "extra".into();
        extra.queue = model.queues.len() as u32;
        extra.accesses.truncate(1);
        extra.accesses[0].resource = model.resources.len() as u32;
        model.resources.push(model.resources[0].clone());
        model.queues.push(model.queues[1].clone());
        model.passes.push(extra);
        model.fences.push((model.passes.len() as u32 - 1, 0));
        assert!(graph::recorded_order(&model).is_none());
        let derived = derive_frame(&model, true).unwrap();
        assert_eq!(derived.order[0] as usize, model.passes.len() - 1);
        same_as_one_thread(&model);
    }
}
