//! The synchronization check on a long real command stream: a synthetic frame of 1,440
//! compute and copy passes over 32 buffers (each pass reading and writing buffers earlier
//! passes wrote), replayed by `framelab replay` through wgpu on this machine's Vulkan driver
//! under GFXReconstruct's capture layer: a stream of about 10,000 `vkCmd*` commands with
//! wgpu's own barriers. The import with the check and without it, side by side: the
//! difference is what the check costs.
//!
//! The stream is made once, in Cargo's target folder (it needs `gfxreconstruct` installed);
//! the same file is what `gfxrecon-replay` replays under the Khronos layer for the README's
//! comparison.

#![allow(clippy::expect_used)]

use std::hint::black_box;
use std::io::Cursor;

use criterion::{Criterion, criterion_group, criterion_main};
use framelab_core::import::{ImportOptions, gfxr};

#[path = "common/sync_stream.rs"]
mod sync_stream;
use sync_stream::stream;

fn bench(c: &mut Criterion) {
    let path = stream();
    let bytes = std::fs::read(&path).expect("stream");
    let len = Some(bytes.len() as u64);
    let import = |skip: bool| {
        gfxr::import(
            Cursor::new(black_box(&bytes)),
            len,
            "sync_bench",
            "sync_bench",
            &ImportOptions {
                skip_sync_check: skip,
                ..ImportOptions::default()
            },
        )
        .expect("imports")
    };
    let checked = import(false);
    eprintln!(
        "{}: {} bytes, {} calls, {} synchronization findings",
        path.display(),
        bytes.len(),
        checked.summary.calls,
        checked.summary.sync_hazards
    );
    let mut group = c.benchmark_group("sync");
    group.sample_size(20);
    group.bench_function("import with the check", |b| b.iter(|| import(false)));
    group.bench_function("import without the check", |b| b.iter(|| import(true)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
