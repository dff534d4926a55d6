//! The analysis stages run on synthetic frames: the threaded `derive_frame` against the stages
//! one by one, and the recorded order against the topological one.

use framelab_core::analysis::graph::{build, recorded_order, topological_order};
use framelab_core::analysis::model::{MPass, MQueue, MResource};
use framelab_core::analysis::units::Units;
use framelab_core::analysis::{barriers, derive_frame, graph, memory, model};
use framelab_testkit::synthetic;

/// What `derive_frame` returns must not depend on which threads did the work.
fn same_as_one_thread(model: &model::FrameModel) {
    let units = Units::new(model);
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
    extra.queue = MQueue::new(model.queues.len());
    extra.accesses.truncate(1);
    extra.accesses[0].resource = MResource::new(model.resources.len());
    model.resources.push(model.resources[0].clone());
    model.queues.push(model.queues[1].clone());
    model.passes.push(extra);
    model
        .fences
        .push((MPass::new(model.passes.len() - 1), MPass(0)));
    assert!(graph::recorded_order(&model).is_none());
    let derived = derive_frame(&model, true).unwrap();
    assert_eq!(derived.order[0].index(), model.passes.len() - 1);
    same_as_one_thread(&model);
}

#[test]
fn recorded_order_is_the_topological_order_when_no_fence_points_back() {
    for seed in 0..20 {
        let mut m = synthetic::frame(300, 400, seed);
        // Forward fences between queues keep the recorded order valid.
        m.fences = [(3, 250), (10, 11), (100, 180)]
            .map(|(a, b)| (MPass(a), MPass(b)))
            .to_vec();
        let units = Units::new(&m);
        let g = build(&m, &units);
        let recorded = recorded_order(&m).expect("every fence points forward");
        assert_eq!(topological_order(&m, &g).unwrap(), recorded, "seed {seed}");
    }
}
