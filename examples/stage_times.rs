//! Prints the time of each analysis stage on a synthetic frame: `cargo run --release --example
//! stage_times -- PASSES RESOURCES`.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
    if std::env::var_os("LOAD").is_some() {
        load_profile();
        return;
    }
    let model = synthetic::frame(passes, resources, 7);
    {
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let accesses: usize = model.passes.iter().map(|p| p.accesses.len()).sum();
        let order = graph::order(&model, &g).unwrap_or_default();
        let plan = barriers::derive(&model, &units, &g, &order);
        println!(
            "{accesses} accesses, {} units, {} edges, {} barriers, {} transfers, {} fences",
            units.total,
            g.graph.edge_count(),
            plan.barriers.len(),
            plan.transfers.len(),
            plan.fences.len()
        );
    }
    if std::env::var_os("FRAME").is_some() {
        let mut best = f64::MAX;
        let mut times = Vec::new();
        for _ in 0..40 {
            let t = Instant::now();
            std::hint::black_box(framelab::analysis::derive_frame(&model, true).ok());
            let e = t.elapsed().as_secs_f64() * 1e3;
            times.push(e);
            best = best.min(e);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "derive_frame: best {best:.2} ms, median {:.2} ms",
            times[times.len() / 2]
        );
        return;
    }
    if std::env::var_os("ONLY_UNITS").is_some() {
        for _ in 0..50 {
            std::hint::black_box(Units::new(&model));
        }
        return;
    }
    if std::env::var_os("ONLY_BUILD").is_some() {
        let units = Units::new(&model);
        for _ in 0..50 {
            std::hint::black_box(graph::build(&model, &units));
        }
        return;
    }
    if std::env::var_os("MEMORY_PARTS").is_some() {
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let order = graph::order(&model, &g).unwrap_or_default();
        memory_parts(&model, &order);
        return;
    }
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
    let mut best = [f64::MAX; 6];
    let mut counts = (0, 0);
    for _ in 0..15 {
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
        counts = (plan.barriers.len(), mem.aliasing_barriers.len());
        let parts = [
            t_units,
            t_build - t_units,
            t_order - t_build,
            t_barriers - t_order,
            t_memory - t_barriers,
            t_memory,
        ];
        for (b, v) in best.iter_mut().zip(parts) {
            *b = b.min(v.as_secs_f64() * 1e3);
        }
    }
    println!(
        "{passes} passes, {resources} resources, best of 15 (ms): units {:.2}, build {:.2}, order {:.2}, barriers {:.2} ({}), memory {:.2} ({} aliasing); total {:.2}",
        best[0], best[1], best[2], best[3], counts.0, best[4], counts.1, best[5]
    );
}

#[allow(dead_code)]
pub fn memory_parts(model: &framelab::analysis::model::FrameModel, order: &[u32]) {
    use framelab::analysis::memory::*;
    let mut best = [f64::MAX; 5];
    for _ in 0..30 {
        let t = Instant::now();
        let l = lifetimes(model, order);
        let t1 = t.elapsed().as_secs_f64();
        let end = order.len() as u32 - 1;
        let items: Vec<Item> = model
            .resources
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                let lt = l[i]?;
                let persistent = r.history || r.initialised || r.output;
                let (first, last) = if persistent {
                    (0, end)
                } else {
                    (lt.first, lt.last)
                };
                Some(Item {
                    id: i as u32,
                    bytes: r.aligned_bytes,
                    alignment: r.alignment,
                    first,
                    last,
                })
            })
            .collect();
        let t2 = t.elapsed().as_secs_f64();
        std::hint::black_box(place_timeline(&items));
        let t3 = t.elapsed().as_secs_f64();
        std::hint::black_box(lower_bound(&items));
        let t4 = t.elapsed().as_secs_f64();
        std::hint::black_box(plan(model, order));
        let t5 = t.elapsed().as_secs_f64();
        for (b, v) in best
            .iter_mut()
            .zip([t1, t2 - t1, t3 - t2, t4 - t3, t5 - t4])
        {
            *b = b.min(v * 1e3);
        }
    }
    println!(
        "memory parts (ms): lifetimes {:.3} items {:.3} timeline {:.3} lower_bound {:.3} plan {:.3}",
        best[0], best[1], best[2], best[3], best[4]
    );
}

#[allow(dead_code)]
pub fn load_profile() {
    let dir = std::env::temp_dir().join("framelab-loadprof");
    let _ = std::fs::create_dir_all(&dir);
    let shader = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/compute.wgsl");
    let _ = std::fs::copy(shader, dir.join("compute.wgsl"));
    let text = synthetic::capture_json(20_000, 20_000, 3);
    let path = dir.join("large.json");
    let _ = std::fs::write(&path, &text);
    let bytes = text.into_bytes();
    let options = framelab::capture::Options::default();
    for _ in 0..10 {
        let t = Instant::now();
        let raw = framelab::capture::load::parse(&path, &bytes);
        let t1 = t.elapsed();
        let ok = raw.map(|r| framelab::capture::validate::validate(&r, &path, &options).is_ok());
        let t2 = t.elapsed();
        let v = serde_json::from_slice::<serde_json::Value>(&bytes).map(|v| v.is_object());
        println!(
            "parse {:?} validate {:?} ({:?}) value {:?} ({:?})",
            t1,
            t2 - t1,
            ok.is_ok(),
            t.elapsed() - t2,
            v.is_ok()
        );
    }
}
