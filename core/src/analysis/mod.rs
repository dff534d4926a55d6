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
pub mod traffic;
pub mod units;

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
    pub units: units::Units,
    pub graph: graph::PassGraph,
    pub order: Vec<model::MPass>,
    pub plan: barriers::BarrierPlan,
    /// `None` unless asked for.
    pub memory: Option<memory::MemoryPlan>,
}

fn parallel() -> bool {
    std::thread::available_parallelism().is_ok_and(|n| n.get() > 1)
}

/// Whether the frame can be ordered at all, without deriving anything from the order: the
/// graph is built only when a fence points backwards, since otherwise the recorded order
/// stands (see `graph::recorded_order`). `validate` asks this, so a capture it accepts is
/// one `analyze` can order.
pub fn check_order(capture: &crate::capture::model::Capture) -> Result<(), graph::CycleError> {
    let model = model::from_capture(capture);
    if graph::recorded_order(&model).is_some() {
        return Ok(());
    }
    let units = units::Units::new(&model);
    let g = graph::build(&model, &units);
    graph::topological_order(&model, &g).map(drop)
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
            let units = units::Units::new(model);
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
    let units = units::Units::new(model);
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
    units: &units::Units,
    graph: &graph::PassGraph,
    order: &[model::MPass],
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
