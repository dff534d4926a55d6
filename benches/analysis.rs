//! Analysis benchmarks: build + order + barriers + aliasing on synthetic frames of 1k and 10k
//! passes over 50k resources, and load + validate of a large capture against serde_json's
//! untyped parse of the same bytes.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use framelab::analysis::synthetic;

/// The allocator the `framelab` binary uses, so the figures are the binary's
/// (`--features system-alloc` measures with the system allocator instead).
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::hint::black_box;

fn pipeline(model: &framelab::analysis::model::FrameModel) -> usize {
    framelab::analysis::derive_frame(model, true).map_or(0, |d| {
        d.plan.barriers.len() + d.memory.map_or(0, |m| m.aliasing_barriers.len())
    })
}

fn analysis(c: &mut Criterion) {
    let mut group = c.benchmark_group("analysis");
    group.sample_size(20);
    for passes in [1_000usize, 10_000] {
        let model = synthetic::frame(passes, 50_000, 7);
        group.throughput(Throughput::Elements(passes as u64));
        group.bench_with_input(
            BenchmarkId::new("build+order+barriers+aliasing", passes),
            &model,
            |b, m| b.iter(|| black_box(pipeline(m))),
        );
    }
    group.finish();
}

fn loading(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("framelab-bench-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let shader = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/compute.wgsl");
    let _ = std::fs::copy(shader, dir.join("compute.wgsl"));
    let text = synthetic::capture_json(20_000, 20_000, 3);
    let path = dir.join("large.json");
    let _ = std::fs::write(&path, &text);
    let bytes = text.into_bytes();
    let mut group = c.benchmark_group("load");
    group.sample_size(10);
    group.throughput(Throughput::Bytes(bytes.len() as u64));
    group.bench_function("serde_json::Value", |b| {
        b.iter(|| {
            black_box(serde_json::from_slice::<serde_json::Value>(&bytes).map(|v| v.is_object()))
        })
    });
    let options = framelab::capture::Options::default();
    group.bench_function("framelab load+validate", |b| {
        b.iter(|| {
            let raw = framelab::capture::load::parse(&path, &bytes);
            black_box(
                raw.map(|r| framelab::capture::validate::validate(&r, &path, &options).is_ok()),
            )
        })
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, analysis, loading);
criterion_main!(benches);
