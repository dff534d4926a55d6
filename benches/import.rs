//! `framelab import` on real binary captures, side by side with reading and decompressing
//! the same file's blocks without decoding a call (the floor an import cannot go below).
//! Throughput is in bytes of the capture file per second.

#![allow(clippy::expect_used)]

use std::hint::black_box;
use std::io::Cursor;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framelab_core::import::{ImportOptions, gfxr};

const CAPTURES: [&str; 3] = ["framelab_inspect_f3", "mpv_testsrc_f5", "vkd3d_gears_f2"];

fn bench(c: &mut Criterion) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gfxr");
    let mut group = c.benchmark_group("import");
    for name in CAPTURES {
        let bytes = std::fs::read(dir.join(format!("{name}.gfxr"))).expect("fixture");
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
