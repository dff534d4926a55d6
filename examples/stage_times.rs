//! Times the analysis of a synthetic frame, stage by stage and as `framelab analyze` runs it:
//! `cargo run --release --example stage_times -- [PASSES [RESOURCES]]` (10,000 and 50,000 by
//! default). With `STAGE=units|build|barriers|memory` it only repeats that stage, for `perf`.

/// The allocator of the `framelab` binary, as in the benchmark.
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use framelab_core::analysis::model::{FrameModel, MPass};
use framelab_core::analysis::units::Units;
use framelab_core::analysis::{barriers, derive_frame, graph, memory};
use framelab_testkit::synthetic;
use std::hint::black_box;
use std::time::{Duration, Instant};

const RUNS: usize = 30;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let passes = args.first().copied().unwrap_or(10_000);
    let resources = args.get(1).copied().unwrap_or(50_000);
    let model = synthetic::frame(passes, resources, 7);
    let units = Units::new(&model);
    let g = graph::build(&model, &units);
    let Ok(order) = graph::order(&model, &g) else {
        eprintln!("the synthetic frame has a cycle");
        return;
    };
    if let Ok(stage) = std::env::var("STAGE") {
        repeat(&stage, &model, &units, &g, &order);
        return;
    }
    let plan = barriers::derive(&model, &units, &g, &order);
    let accesses: usize = model.passes.iter().map(|p| p.accesses.len()).sum();
    println!(
        "{passes} passes, {resources} resources: {accesses} accesses, {} units, {} uses, {} edges, \
         {} barriers, {} transfers, {} fences",
        units.total,
        units.use_count(),
        g.graph.edge_count(),
        plan.barriers.len(),
        plan.transfers.len(),
        plan.fences.len()
    );
    // Best of RUNS for each stage on one thread.
    let mut best = [Duration::MAX; 5];
    for _ in 0..RUNS {
        let t = Instant::now();
        let units = Units::new(&model);
        let t_units = t.elapsed();
        let g = graph::build(&model, &units);
        let t_build = t.elapsed();
        let order = graph::order(&model, &g).unwrap_or_default();
        let t_order = t.elapsed();
        black_box(barriers::derive(&model, &units, &g, &order));
        let t_barriers = t.elapsed();
        black_box(memory::plan(&model, &order));
        let t_memory = t.elapsed();
        let stages = [
            t_units,
            t_build - t_units,
            t_order - t_build,
            t_barriers - t_order,
            t_memory - t_barriers,
        ];
        for (b, s) in best.iter_mut().zip(stages) {
            *b = (*b).min(s);
        }
    }
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "one thread, best of {RUNS} (ms): units {:.2}, build {:.2}, order {:.2}, barriers {:.2}, memory {:.2}",
        ms(best[0]),
        ms(best[1]),
        ms(best[2]),
        ms(best[3]),
        ms(best[4])
    );
    let mut whole: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            black_box(derive_frame(&model, true).is_ok());
            ms(t.elapsed())
        })
        .collect();
    whole.sort_by(f64::total_cmp);
    println!(
        "derive_frame (as `analyze` runs it): best {:.2} ms, median {:.2} ms",
        whole[0],
        whole[RUNS / 2]
    );
}

fn repeat(stage: &str, model: &FrameModel, units: &Units, g: &graph::PassGraph, order: &[MPass]) {
    for _ in 0..200 {
        match stage {
            "units" => drop(black_box(Units::new(model))),
            "build" => drop(black_box(graph::build(model, units))),
            "barriers" => drop(black_box(barriers::derive(model, units, g, order))),
            "memory" => drop(black_box(memory::plan(model, order))),
            other => {
                eprintln!("STAGE must be units, build, barriers or memory, not {other:?}");
                return;
            }
        }
    }
}
