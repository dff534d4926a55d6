//! `framelab import` on real binary captures, side by side with reading and decompressing
//! the same file's blocks without decoding a call (the floor an import cannot go below) and
//! with decoding every call the importer reads without importing it (how much of an import
//! is decoding). Throughput is in bytes of the capture file per second. Besides small
//! fixtures, the synthetic 1,440-pass stream the synchronization benchmark uses: 37,000
//! calls, the call-heavy case where decoding and the importer, not decompression, are the
//! work.
//!
//! `FRAMELAB_IMPORT_TABLE=1 cargo bench --bench import` instead prints one line per fixture
//! of `tests/fixtures/gfxr` (and the stream), the three measured in turn, best of five
//! rounds each: the whole table in one run. Any other value than `1` keeps only the
//! captures whose name contains it (`FRAMELAB_IMPORT_TABLE=vkd3d`).

#![allow(clippy::expect_used)]

use std::hint::black_box;
use std::io::Cursor;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framelab_core::import::{ImportOptions, gfxr};

/// The allocator the `framelab` binary uses, so the figures are the binary's
/// (`--features system-alloc` measures with the system allocator instead).
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "common/sync_stream.rs"]
mod sync_stream;

const CAPTURES: [&str; 4] = [
    "framelab_inspect_f3",
    "mpv_testsrc_f5",
    "vkd3d_gears_f2",
    "vkd3d_triangle_f1",
];

fn fixtures() -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gfxr")
}

fn import(bytes: &[u8], name: &str) -> framelab_core::import::Imported {
    let len = Some(bytes.len() as u64);
    gfxr::import(
        Cursor::new(bytes),
        len,
        name,
        name,
        &ImportOptions::default(),
    )
    .expect("imports")
}

/// The best time of `rounds` rounds of `n` runs of `f`, per run.
fn best(rounds: u32, n: u32, mut f: impl FnMut()) -> Duration {
    (0..rounds)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..n {
                f();
            }
            t.elapsed() / n
        })
        .min()
        .unwrap_or_default()
}

/// Every fixture, one line each: decompress, decode and import side by side.
fn table(only: &str) {
    let mut files: Vec<PathBuf> = std::fs::read_dir(fixtures())
        .expect("fixtures")
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "gfxr"))
        .collect();
    files.sort();
    files.push(sync_stream::stream());
    if only != "1" {
        files.retain(|p| {
            p.file_stem()
                .is_some_and(|s| s.to_string_lossy().contains(only))
        });
    }
    println!("| capture | KB | decompress | decode | import | import / decompress |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for path in files {
        let bytes = std::fs::read(&path).expect("capture");
        let len = Some(bytes.len() as u64);
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("capture");
        let n = u32::try_from((4_000_000 / bytes.len()).clamp(5, 2000)).unwrap_or(5);
        let d = best(5, n, || {
            black_box(gfxr::decompress_only(Cursor::new(&bytes), len).expect("reads"));
        });
        let c = best(5, n, || {
            black_box(gfxr::decode_only(Cursor::new(&bytes), len).expect("reads"));
        });
        let i = best(5, n, || {
            black_box(import(&bytes, name));
        });
        println!(
            "| `{name}` | {} | {d:.1?} | {c:.1?} | {i:.1?} | {:.2} |",
            bytes.len() / 1000,
            d.as_secs_f64() / i.as_secs_f64()
        );
    }
}

fn bench(c: &mut Criterion) {
    if let Ok(only) = std::env::var("FRAMELAB_IMPORT_TABLE") {
        table(&only);
        return;
    }
    let mut group = c.benchmark_group("import");
    let files = CAPTURES
        .iter()
        .map(|name| (*name, fixtures().join(format!("{name}.gfxr"))))
        .chain([("sync_bench", sync_stream::stream())]);
    for (name, path) in files {
        let bytes = std::fs::read(path).expect("capture");
        let len = Some(bytes.len() as u64);
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function(format!("{name}/decompress"), |b| {
            b.iter(|| gfxr::decompress_only(Cursor::new(black_box(&bytes)), len).expect("reads"));
        });
        group.bench_function(format!("{name}/decode"), |b| {
            b.iter(|| gfxr::decode_only(Cursor::new(black_box(&bytes)), len).expect("reads"));
        });
        group.bench_function(format!("{name}/import"), |b| {
            b.iter(|| import(black_box(&bytes), name));
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
