//! The analyses handle frames of benchmark size, and the loader accepts the synthetic capture
//! the load benchmark uses (so the benchmark measures a successful validation).

use framelab_core::analysis::units::Units;
use framelab_core::analysis::{barriers, graph, memory};
use framelab_testkit::synthetic;

use crate::common::Scratch;

#[test]
fn large_synthetic_frame_analyses() {
    let model = synthetic::frame(10_000, 50_000, 7);
    let units = Units::new(&model);
    let g = graph::build(&model, &units);
    let order = graph::order(&model, &g).unwrap();
    assert_eq!(order.len(), 10_000);
    let plan = barriers::derive(&model, &units, &g, &order);
    assert!(!plan.barriers.is_empty());
    let mem = memory::plan(&model, &order);
    assert!(mem.total.aliased_bytes >= mem.total.lower_bound_bytes);
    assert!(mem.total.aliased_bytes < mem.total.unaliased_bytes);
}

#[test]
fn synthetic_capture_is_valid() {
    let dir = Scratch::temp("framelab-synth");
    std::fs::copy(
        concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/compute.wgsl"),
        dir.join("compute.wgsl"),
    )
    .unwrap();
    let path = dir.join("large.json");
    std::fs::write(&path, synthetic::capture_json(2_000, 2_000, 3)).unwrap();
    let result = framelab_core::pipeline::Validated::load(&path, &Default::default());
    let v = result.unwrap_or_else(|e| {
        panic!(
            "{:#?}",
            e.diagnostics().into_iter().take(5).collect::<Vec<_>>()
        )
    });
    assert_eq!(v.capture.passes.len(), 2_000);
}
