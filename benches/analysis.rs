//! Analysis benchmarks: build + order + barriers + aliasing on synthetic frames of 1k and 10k
//! passes over 50k resources, load + validate of a large capture against serde_json's untyped
//! parse of the same bytes, and the whole analysis (lints, Vulkan barrier comparison, hazards,
//! schedule) of long imported captures at two sizes, to show it grows with the input.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use framelab_testkit::synthetic;

/// The allocator the `framelab` binary uses, so the figures are the binary's
/// (`--features system-alloc` measures with the system allocator instead).
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::hint::black_box;

fn pipeline(model: &framelab_core::analysis::model::FrameModel) -> usize {
    framelab_core::analysis::derive_frame(model, true).map_or(0, |d| {
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
    let options = framelab_core::capture::Options::default();
    group.bench_function("framelab load+validate", |b| {
        b.iter(|| {
            black_box(
                framelab_core::pipeline::Loaded::from_bytes(&path, &bytes)
                    .and_then(|l| l.validate(&options))
                    .is_ok(),
            )
        })
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// An imported Vulkan capture of `passes` clear passes over `passes / 10` images, each pass
/// with its recorded layout transition: what the Vulkan barrier comparison, the per-resource
/// lints, the hazard checker and the schedule see from a long GFXReconstruct stream.
fn imported_capture(passes: usize) -> String {
    let images = (passes / 10).max(1);
    let mut out = String::from(
        r#"{"format_version":1,"name":"imported","resolution":{"width":640,"height":480},"camera":{"position":[0,0,1],"target":[0,0,0],"fov_y_degrees":60},"source":{"tool":"bench","api":"vulkan","file":"generated","not_replayable":"no shader code"},"queues":[{"name":"graphics","type":"graphics"}],"resources":["#,
    );
    for i in 0..images {
        if i > 0 {
            out.push(',');
        }
        out.push_str(&format!(
            r#"{{"name":"img_{i}","kind":"texture_2d","format":"R8G8B8A8_UNORM","width":1,"height":1,"initial":{{"before_capture":{{}}}}}}"#
        ));
    }
    out.push_str(r#"],"passes":["#);
    for p in 0..passes {
        if p > 0 {
            out.push(',');
        }
        let r = p % images;
        out.push_str(&format!(
            r#"{{"name":"clear_{p}","queue":"graphics","kind":"clear","clears":[{{"resource":"img_{r}","value":[0,0,0,0]}}],"barriers":[{{"type":"vulkan","resource":"img_{r}","vulkan":{{"origin":"vkCmdPipelineBarrier #{p}","src_stages":["TOP_OF_PIPE"],"dst_stages":["TRANSFER"],"dst_access":["TRANSFER_WRITE"],"old_layout":"UNDEFINED","new_layout":"GENERAL"}}}}]}}"#
        ));
    }
    out.push_str("]}");
    out
}

fn report(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("framelab-bench-report-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let mut group = c.benchmark_group("analyze_imported");
    group.sample_size(10);
    for passes in [10_000usize, 40_000] {
        let path = dir.join(format!("imported_{passes}.json"));
        let _ = std::fs::write(&path, imported_capture(passes));
        let options = framelab_core::capture::Options::default();
        let Ok(validated) = framelab_core::pipeline::Validated::load(&path, &options) else {
            eprintln!("the generated imported capture does not validate");
            return;
        };
        group.throughput(Throughput::Elements(passes as u64));
        group.bench_with_input(
            BenchmarkId::new("lints+hazards+schedule", passes),
            &validated,
            |b, validated| {
                b.iter(|| {
                    black_box(
                        validated
                            .analysis(framelab_core::analysis::report::AnalyzeOptions::default())
                            .map(|a| a.lints.len()),
                    )
                })
            },
        );
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, analysis, loading, report);
criterion_main!(benches);
