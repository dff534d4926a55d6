//! Prints the time of each analysis stage on a synthetic frame: `cargo run --release --example
//! stage_times -- PASSES RESOURCES`.

use framelab::analysis::model::Units;
use framelab::analysis::{barriers, graph, memory, synthetic};
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let (passes, resources) = (
        args.first().copied().unwrap_or(10_000),
        args.get(1).copied().unwrap_or(50_000),
    );
    let model = synthetic::frame(passes, resources, 7);
    if std::env::var_os("ONLY_MEMORY").is_some() {
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let order = graph::order(&model, &g).unwrap_or_default();
        for _ in 0..20 {
            std::hint::black_box(memory::plan(&model, &order));
        }
        return;
    }
    if std::env::var_os("ONLY_BARRIERS").is_some() {
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let order = graph::order(&model, &g).unwrap_or_default();
        for _ in 0..20 {
            std::hint::black_box(barriers::derive(&model, &units, &g, &order));
        }
        return;
    }
    for _ in 0..3 {
        let t = Instant::now();
        let units = Units::new(&model);
        let t_units = t.elapsed();
        let g = graph::build(&model, &units);
        let t_build = t.elapsed();
        let order = graph::order(&model, &g).unwrap_or_default();
        let t_order = t.elapsed();
        let plan = barriers::derive(&model, &units, &g, &order);
        let t_barriers = t.elapsed();
        let mem = memory::plan(&model, &order);
        let t_memory = t.elapsed();
        println!(
            "{passes} passes, {resources} resources: units {:?}, build {:?}, order {:?}, barriers {:?} ({}), memory {:?} ({} aliasing); total {:?}",
            t_units,
            t_build - t_units,
            t_order - t_build,
            t_barriers - t_order,
            plan.barriers.len(),
            t_memory - t_barriers,
            mem.aliasing_barriers.len(),
            t_memory
        );
    }
}
