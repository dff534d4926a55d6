//! Export throughput: encoding and writing one decoded 1024x1024 subresource as the export
//! does (8-bit PNG, 16-bit PNG, EXR with its preview), in MB/s of decoded texels, on one
//! thread; `replay --out` runs these on every core while the GPU thread reads back the next
//! texture (README, Performance).
// A benchmark that cannot write its files has nothing to measure: stop loudly.
#![allow(clippy::expect_used)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use framelab_core::plan::TextureSpec;
use framelab_replay::decode::{DecodedImage, ValueKind};
use framelab_replay::export::{Naming, write_image};
use framelab_replay::wgpu;

const SIDE: u32 = 1024;

fn image(format: wgpu::TextureFormat, kind: ValueKind) -> (TextureSpec, DecodedImage) {
    let spec = TextureSpec {
        name: "bench".into(),
        format,
        dimension: wgpu::TextureDimension::D2,
        size: wgpu::Extent3d {
            width: SIDE,
            height: SIDE,
            depth_or_array_layers: 1,
        },
        mip_levels: 1,
        samples: 1,
        usage: wgpu::TextureUsages::empty(),
        view_formats: Vec::new(),
        initial: None,
        history: false,
        cube: false,
    };
    // A smooth gradient with texel noise: compresses like a rendered target, not like a
    // constant or like random bytes.
    let values = (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = (
                (i % SIDE) as f32 / SIDE as f32,
                (i / SIDE) as f32 / SIDE as f32,
            );
            let n = ((i.wrapping_mul(2_654_435_761) >> 24) as f32) / 2550.0;
            [x + n, y, 1.0 - x * y, 1.0]
        })
        .collect();
    let decoded = DecodedImage {
        mip: 0,
        layer: 0,
        z: None,
        width: SIDE,
        height: SIDE,
        format,
        channels: 4,
        kind,
        values,
    };
    (spec, decoded)
}

fn export(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("framelab-export-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let mut group = c.benchmark_group("export_1024x1024");
    group.sample_size(10);
    group.throughput(Throughput::Bytes(u64::from(SIDE * SIDE) * 16));
    for (name, format, kind) in [
        ("png8", wgpu::TextureFormat::Rgba8Unorm, ValueKind::Unorm8),
        (
            "png16",
            wgpu::TextureFormat::Rgb10a2Unorm,
            ValueKind::UnormWide,
        ),
        (
            "exr+preview",
            wgpu::TextureFormat::Rgba16Float,
            ValueKind::Float,
        ),
    ] {
        let (spec, decoded) = image(format, kind);
        let naming = Naming {
            resource: name,
            stem: name,
            format: name,
        };
        group.bench_function(name, |b| {
            b.iter(|| write_image(&dir, naming, &spec, &decoded).expect("written"));
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(dir);
}

criterion_group!(benches, export);
criterion_main!(benches);
