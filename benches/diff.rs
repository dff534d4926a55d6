//! The timing diff on reports of benchmark size: two reports of 100 passes x 1,000 frames each,
//! matching, tests, Holm adjustment and the bootstrap intervals included.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use framelab_core::timing::diff::{DiffOptions, diff};
use framelab_core::timing::{FORMAT_VERSION, PassTiming, TimingReport};

fn report(seed: u64, shift: f64) -> TimingReport {
    // A small xorshift keeps the inputs fixed without another dependency.
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let passes = (0..100)
        .map(|i| {
            let base = 50_000.0 + 10_000.0 * i as f64;
            let m = if i == 42 { base * shift } else { base };
            PassTiming {
                name: format!("pass{i}"),
                queue: if i % 5 == 0 { "compute" } else { "graphics" }.into(),
                marker_path: format!("Frame/Group{}/pass{i}", i / 10),
                kind: "raster".into(),
                writes: vec![format!("target{i}")],
                gpu_ns: (0..1000)
                    .map(|_| Some((m * (0.97 + 0.06 * next())) as u64))
                    .collect(),
                cpu_ns: vec![10_000; 1000],
                bytes_read: 8_000_000,
                bytes_written: 4_000_000,
                gpu_untrusted: None,
                ..PassTiming::default()
            }
        })
        .collect();
    TimingReport {
        format_version: FORMAT_VERSION,
        adapter: "bench".into(),
        backend: "vulkan".into(),
        capture: "bench".into(),
        capture_sha256: String::new(),
        scale: 1.0,
        frames: 1000,
        warmup: 0,
        timestamp_period_ns: 1.0,
        timestamps: framelab_core::timing::StampLayout::Chained,
        passes,
    }
}

fn diffing(c: &mut Criterion) {
    let (a, b) = (report(1, 1.0), report(2, 1.1));
    let options = DiffOptions::default();
    let mut group = c.benchmark_group("diff");
    group.sample_size(10);
    group.bench_function("100 passes x 1000 frames", |bench| {
        bench.iter(|| black_box(diff(&a, &b, &options).map(|d| d.rows.len())))
    });
    group.finish();
}

criterion_group!(benches, diffing);
criterion_main!(benches);
