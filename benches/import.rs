//! `framelab import` on real binary captures, side by side with reading and decompressing
//! the same file's blocks without decoding a call (the floor an import cannot go below).
//! Throughput is in bytes of the capture file per second. Besides the small fixtures, the
//! synthetic 1,440-pass stream the synchronization benchmark uses: 37,000 calls, the
//! call-heavy case where decoding, not decompression, is the work.

#![allow(clippy::expect_used)]

use std::hint::black_box;
use std::io::Cursor;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framelab_core::import::{ImportOptions, gfxr};

/// The allocator the `framelab` binary uses, so the figures are the binary's
/// (`--features system-alloc` measures with the system allocator instead).
#[cfg(not(feature = "system-alloc"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "common/sync_stream.rs"]
mod sync_stream;

const CAPTURES: [&str; 3] = ["framelab_inspect_f3", "mpv_testsrc_f5", "vkd3d_gears_f2"];

fn bench(c: &mut Criterion) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gfxr");
    let mut group = c.benchmark_group("import");
    let files = CAPTURES
        .iter()
        .map(|name| (*name, dir.join(format!("{name}.gfxr"))))
        .chain([("sync_bench", sync_stream::stream())]);
    for (name, path) in files {
        let bytes = std::fs::read(path).expect("capture");
        let len = Some(bytes.len() as u64);
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function(format!("{name}/decompress"), |b| {
            b.iter(|| gfxr::decompress_only(Cursor::new(black_box(&bytes)), len).expect("reads"));
        });
        group.bench_function(format!("{name}/import"), |b| {
            b.iter(|| {
                gfxr::import(
                    Cursor::new(black_box(&bytes)),
                    len,
                    name,
                    name,
                    &ImportOptions::default(),
                )
                .expect("imports")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
