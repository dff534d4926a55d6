//! Meshes: built as float attributes, then encoded into the capture's stream formats
//! (snorm16x4 positions, float16x2 UVs, packed 10:10:10:2 normals, unorm8x4 colours,
//! per-instance float4 rows).

use std::collections::BTreeMap;

use super::{buffer, buildings, f16, fbm, hash};
use crate::capture::format::{ParamValue, StepMode, VertexFormat, VertexStream};
use crate::capture::generators::{Content, Seeded, Shape};

/// A mesh as float attributes.
#[derive(Debug, Default, Clone)]
pub struct MeshData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub colors: Vec<[f32; 4]>,
    pub indices: Vec<u32>,
}

impl MeshData {
    fn vertex(&mut self, p: [f32; 3], n: [f32; 3], uv: [f32; 2], color: [f32; 4]) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        self.colors.push(color);
        (self.positions.len() - 1) as u32
    }
    fn quad(&mut self, corners: [[f32; 3]; 4], n: [f32; 3], color: [f32; 4]) {
        let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let i: Vec<u32> = (0..4)
            .map(|k| self.vertex(corners[k], n, uv[k], color))
            .collect();
        self.indices.extend([i[0], i[1], i[2], i[0], i[2], i[3]]);
    }
    fn cuboid(&mut self, min: [f32; 3], max: [f32; 3], color: [f32; 4]) {
        let [x0, y0, z0] = min;
        let [x1, y1, z1] = max;
        self.quad(
            [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]],
            [0.0, 0.0, 1.0],
            color,
        );
        self.quad(
            [[x1, y0, z0], [x0, y0, z0], [x0, y1, z0], [x1, y1, z0]],
            [0.0, 0.0, -1.0],
            color,
        );
        self.quad(
            [[x1, y0, z1], [x1, y0, z0], [x1, y1, z0], [x1, y1, z1]],
            [1.0, 0.0, 0.0],
            color,
        );
        self.quad(
            [[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]],
            [-1.0, 0.0, 0.0],
            color,
        );
        self.quad(
            [[x0, y1, z1], [x1, y1, z1], [x1, y1, z0], [x0, y1, z0]],
            [0.0, 1.0, 0.0],
            color,
        );
        self.quad(
            [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]],
            [0.0, -1.0, 0.0],
            color,
        );
    }
    fn grid(&mut self, size: f32, divisions: u32, height: impl Fn(f32, f32) -> f32) {
        let n = divisions.max(1);
        let base = self.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let (x, z) = ((u - 0.5) * size, (v - 0.5) * size);
                let e = size / n as f32;
                let (hx, hz) = (
                    height(x + e, z) - height(x - e, z),
                    height(x, z + e) - height(x, z - e),
                );
                let normal = normalize([-hx, 2.0 * e, -hz]);
                self.vertex([x, height(x, z), z], normal, [u, v], [1.0, 1.0, 1.0, 1.0]);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = base + j * (n + 1) + i;
                let b = a + n + 1;
                self.indices.extend([a, b, a + 1, a + 1, b, b + 1]);
            }
        }
    }
    fn sphere(&mut self, center: [f32; 3], radius: f32, segments: u32, rings: u32) {
        let (segments, rings) = (segments.max(3), rings.max(2));
        let base = self.positions.len() as u32;
        for r in 0..=rings {
            let phi = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let theta = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
                let n = [phi.sin() * theta.cos(), phi.cos(), phi.sin() * theta.sin()];
                let p = [
                    center[0] + radius * n[0],
                    center[1] + radius * n[1],
                    center[2] + radius * n[2],
                ];
                self.vertex(
                    p,
                    n,
                    [s as f32 / segments as f32, r as f32 / rings as f32],
                    [1.0, 1.0, 1.0, 1.0],
                );
            }
        }
        for r in 0..rings {
            for s in 0..segments {
                let a = base + r * (segments + 1) + s;
                let b = a + segments + 1;
                self.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
            }
        }
    }
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-12);
    [v[0] / l, v[1] / l, v[2] / l]
}

/// Builds a generator mesh.
pub fn mesh(shape: &Seeded<Shape>) -> MeshData {
    // Meshes are built in f32: every parameter is rounded to it first.
    let f = |v: f64| v as f32;
    let seed = shape.seed;
    let mut m = MeshData::default();
    match shape.generator {
        Shape::Grid { size, divisions } => {
            m.grid(f(size), f(divisions) as u32, |_, _| 0.0);
        }
        Shape::WaterPlate {
            size,
            divisions,
            height,
        } => {
            let h = f(height);
            m.grid(f(size), f(divisions) as u32, |_, _| h);
        }
        Shape::Terrain {
            size,
            resolution,
            height,
            octaves,
        } => {
            let (size, height, octaves) = (f(size), f(height), f(octaves) as u32);
            m.grid(size, f(resolution) as u32, |x, z| {
                height
                    * (fbm(
                        seed,
                        f64::from(x / size) + 0.5,
                        f64::from(z / size) + 0.5,
                        0.0,
                        3.0,
                        octaves,
                    ) as f32
                        - 0.5)
            });
        }
        Shape::Box { size } => {
            let s = f(size) * 0.5;
            m.cuboid([-s, -s, -s], [s, s, s], [1.0, 1.0, 1.0, 1.0]);
        }
        Shape::CityBlocks(city) => {
            for b in buildings(seed, city.rounded_to_f32()) {
                // Window tint in the colour stream; shaders turn it into emissive windows.
                let tint = b.tint.map(|c| c as f32);
                m.cuboid(
                    b.min.map(|c| c as f32),
                    b.max.map(|c| c as f32),
                    [tint[0], tint[1], tint[2], 1.0],
                );
            }
        }
        Shape::FoliageCards {
            count,
            area,
            height,
            width,
        } => {
            let (count, area, height, width) = (f(count) as i64, f(area), f(height), f(width));
            for i in 0..count {
                let r = |c: i64| hash(seed, i, c, 7) as f32;
                let (x, z, h) = (
                    (r(0) - 0.5) * area,
                    (r(1) - 0.5) * area,
                    height * (0.6 + 0.8 * r(2)),
                );
                let w = width * 0.5;
                let green = [0.2 + 0.2 * r(3), 0.5 + 0.3 * r(4), 0.15, 1.0];
                m.quad(
                    [
                        [x - w, 0.0, z],
                        [x + w, 0.0, z],
                        [x + w, h, z],
                        [x - w, h, z],
                    ],
                    [0.0, 0.0, 1.0],
                    green,
                );
                m.quad(
                    [
                        [x, 0.0, z - w],
                        [x, 0.0, z + w],
                        [x, h, z + w],
                        [x, h, z - w],
                    ],
                    [1.0, 0.0, 0.0],
                    green,
                );
            }
        }
        Shape::Sphere {
            radius,
            segments,
            rings,
        } => m.sphere([0.0; 3], f(radius), f(segments) as u32, f(rings) as u32),
        Shape::Capsule {
            radius,
            height,
            segments,
        } => {
            let (radius, height, segments) = (f(radius), f(height), f(segments) as u32);
            let half = (height * 0.5 - radius).max(0.0);
            // Two end spheres (their inner halves hide inside the cylinder) and the cylinder.
            m.sphere([0.0, half, 0.0], radius, segments, segments / 2);
            m.sphere([0.0, -half, 0.0], radius, segments, segments / 2);
            // The cylinder between the two caps.
            let base = m.positions.len() as u32;
            for s in 0..=segments {
                let t = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
                let n = [t.cos(), 0.0, t.sin()];
                m.vertex(
                    [radius * n[0], -half, radius * n[2]],
                    n,
                    [s as f32 / segments as f32, 0.0],
                    [1.0; 4],
                );
                m.vertex(
                    [radius * n[0], half, radius * n[2]],
                    n,
                    [s as f32 / segments as f32, 1.0],
                    [1.0; 4],
                );
            }
            for s in 0..segments {
                let a = base + 2 * s;
                m.indices.extend([a, a + 1, a + 2, a + 1, a + 3, a + 2]);
            }
        }
    }
    m
}

/// Encodes one attribute value in a vertex format. Positions in snorm formats are stored
/// divided by `scale` (the mesh's largest coordinate, so they fit in [-1, 1]).
fn encode_attribute(format: VertexFormat, v: [f32; 4]) -> Vec<u8> {
    let sn16 = |x: f32| ((x.clamp(-1.0, 1.0) * 32767.0).round() as i16).to_le_bytes();
    let un16 = |x: f32| ((x.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes();
    let un8 = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let sn8 = |x: f32| (x.clamp(-1.0, 1.0) * 127.0).round() as i8 as u8;
    match format {
        VertexFormat::Snorm16x4 => [sn16(v[0]), sn16(v[1]), sn16(v[2]), sn16(v[3])].concat(),
        VertexFormat::Snorm16x2 => [sn16(v[0]), sn16(v[1])].concat(),
        VertexFormat::Unorm16x2 => [un16(v[0]), un16(v[1])].concat(),
        VertexFormat::Float16x2 => [f16(v[0]), f16(v[1])].concat(),
        VertexFormat::Float16x4 => [f16(v[0]), f16(v[1]), f16(v[2]), f16(v[3])].concat(),
        VertexFormat::PackedSnorm10x3 => {
            // Biased into unsigned 10-bit fields (fetched as Unorm10_10_10_2).
            let q = |x: f32| ((x.clamp(-1.0, 1.0) * 0.5 + 0.5) * 1023.0).round() as u32;
            (q(v[0]) | (q(v[1]) << 10) | (q(v[2]) << 20))
                .to_le_bytes()
                .to_vec()
        }
        VertexFormat::Unorm8x4 => vec![un8(v[0]), un8(v[1]), un8(v[2]), un8(v[3])],
        VertexFormat::Snorm8x4 => vec![sn8(v[0]), sn8(v[1]), sn8(v[2]), sn8(v[3])],
        VertexFormat::Uint8x4 => v.map(|x| x as u8).to_vec(),
        VertexFormat::Float32 => v[0].to_le_bytes().to_vec(),
        VertexFormat::Float32x2 => [v[0].to_le_bytes(), v[1].to_le_bytes()].concat(),
        VertexFormat::Float32x3 => {
            [v[0].to_le_bytes(), v[1].to_le_bytes(), v[2].to_le_bytes()].concat()
        }
        VertexFormat::Float32x4 => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        VertexFormat::Uint32 => (v[0] as u32).to_le_bytes().to_vec(),
        VertexFormat::Uint32x2 => {
            [(v[0] as u32).to_le_bytes(), (v[1] as u32).to_le_bytes()].concat()
        }
    }
}

/// Encodes the streams of a capture mesh: per-vertex attributes by semantic, per-instance rows
/// from the `instances` generator with the mesh's seed.
pub fn encode_streams(
    data: &MeshData,
    streams: &[VertexStream],
    instance_count: u32,
    seed: u64,
    instances: Option<&Seeded<Content>>,
) -> Vec<Vec<u8>> {
    // Snorm positions are stored as xyz / s with w = s / 4096, s the power of two bounding the
    // mesh (exact in snorm16 to 1e-4), so a shader decodes xyz * exp2(round(log2(w * 4096))).
    let scale = data
        .positions
        .iter()
        .flat_map(|p| p.iter().map(|c| c.abs()))
        .fold(0.0f32, f32::max)
        .max(1.0)
        .log2()
        .ceil()
        .exp2();
    // Without an instance generator, the mesh's seed scatters `instances` rows.
    let count = BTreeMap::from([(
        "count".to_owned(),
        ParamValue::Scalar(f64::from(instance_count)),
    )]);
    let default_rows =
        Content::new("instances", &count).map(|generator| Seeded { generator, seed });
    let size = u64::from(instance_count) * 48;
    let rows = match instances.or(default_rows.as_ref()) {
        Some(contents) => buffer(contents, size),
        None => vec![0; size as usize],
    };
    let row = |i: usize, r: usize| -> [f32; 4] {
        let o = i * 48 + r * 16;
        let f = |k: usize| {
            f32::from_le_bytes(
                rows[o + 4 * k..o + 4 * k + 4]
                    .try_into()
                    .unwrap_or_default(),
            )
        };
        [f(0), f(1), f(2), f(3)]
    };
    streams
        .iter()
        .map(|s| {
            let count = match s.step {
                StepMode::Vertex => data.positions.len(),
                StepMode::Instance => instance_count as usize,
            };
            let mut out = Vec::new();
            for i in 0..count {
                for a in &s.attributes {
                    let sem = a.semantic.to_ascii_uppercase();
                    let snorm = matches!(
                        a.format,
                        VertexFormat::Snorm16x4 | VertexFormat::Snorm16x2 | VertexFormat::Snorm8x4
                    );
                    let v: [f32; 4] = if sem.starts_with("INSTANCE") {
                        let r =
                            sem.chars().last().and_then(|c| c.to_digit(10)).unwrap_or(0) as usize;
                        row(i, r.min(2))
                    } else if sem.starts_with("POSITION") {
                        let p = data.positions[i];
                        if snorm {
                            [p[0] / scale, p[1] / scale, p[2] / scale, scale / 4096.0]
                        } else {
                            [p[0], p[1], p[2], 1.0]
                        }
                    } else if sem.starts_with("NORMAL") {
                        let n = data.normals[i];
                        [n[0], n[1], n[2], 0.0]
                    } else if sem.starts_with("TANGENT") {
                        let n = data.normals[i];
                        let t = normalize(if n[1].abs() < 0.99 {
                            [n[2], 0.0, -n[0]]
                        } else {
                            [1.0, 0.0, 0.0]
                        });
                        [t[0], t[1], t[2], 1.0]
                    } else if sem.starts_with("COLOR") {
                        data.colors[i]
                    } else if sem.starts_with("TEXCOORD") {
                        let uv = data.uvs[i];
                        [uv[0], uv[1], 0.0, 0.0]
                    } else {
                        [0.0; 4]
                    };
                    out.extend(encode_attribute(a.format, v));
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::small_float;
    use super::*;

    #[test]
    fn meshes_have_consistent_indices() {
        for name in [
            "grid",
            "box",
            "city_blocks",
            "terrain",
            "water_plate",
            "foliage_cards",
            "sphere",
            "capsule",
        ] {
            let m = mesh(&Seeded {
                generator: Shape::new(name, &BTreeMap::new()).unwrap(),
                seed: 3,
            });
            assert!(!m.indices.is_empty(), "{name}");
            assert_eq!(m.indices.len() % 3, 0, "{name}");
            assert!(
                m.indices.iter().all(|&i| (i as usize) < m.positions.len()),
                "{name}"
            );
            assert!(
                m.normals
                    .iter()
                    .all(|n| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-3),
                "{name}"
            );
        }
    }

    #[test]
    fn packed_formats_encode() {
        assert_eq!(
            encode_attribute(VertexFormat::Snorm16x4, [1.0, -1.0, 0.0, 0.5]).len(),
            8
        );
        let n = u32::from_le_bytes(
            encode_attribute(VertexFormat::PackedSnorm10x3, [1.0, 0.0, -1.0, 0.0])
                .try_into()
                .unwrap(),
        );
        assert_eq!(n & 0x3FF, 1023);
        assert_eq!((n >> 10) & 0x3FF, 512);
        assert_eq!((n >> 20) & 0x3FF, 0);
        let one = small_float(1.0, 6);
        assert_eq!(one, 15 << 6);
    }
}
