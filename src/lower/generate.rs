//! Procedural contents named by captures: textures (noise, blue noise, checker, constant,
//! gradient, atlas, coastline), buffers (lights, instances, constant, noise) and meshes (grid,
//! box, city blocks, terrain, water plate, foliage cards, sphere, capsule), all from a seed and
//! deterministic, so a capture stays small and a replay is the same everywhere.
//!
//! Meshes are built as float attributes and then encoded into the capture's stream formats
//! (snorm16x4 positions, float16x2 UVs, packed 10:10:10:2 normals, unorm8x4 colours,
//! per-instance float4 rows).

use std::collections::BTreeMap;

use framelab_replay::wgpu::TextureFormat;

use crate::capture::format::{ParamValue, StepMode, VertexFormat, VertexStream};
use crate::capture::generators::{City, Content, Seeded, Shape};

/// A seeded integer hash to [0, 1).
fn hash(seed: u64, x: i64, y: i64, z: i64) -> f64 {
    let mut h = seed
        ^ (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (z as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 33;
    h = h.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    h ^= h >> 33;
    h = h.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    h ^= h >> 33;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth value noise in [0, 1), periodic with period `period` (so textures tile).
fn value_noise(seed: u64, x: f64, y: f64, z: f64, period: i64) -> f64 {
    let (xi, yi, zi) = (x.floor(), y.floor(), z.floor());
    let (fx, fy, fz) = (x - xi, y - yi, z - zi);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (u, v, w) = (s(fx), s(fy), s(fz));
    let wrap = |a: f64| (a as i64).rem_euclid(period.max(1));
    let corner =
        |dx: f64, dy: f64, dz: f64| hash(seed, wrap(xi + dx), wrap(yi + dy), zi as i64 + dz as i64);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = lerp(corner(0.0, 0.0, 0.0), corner(1.0, 0.0, 0.0), u);
    let x10 = lerp(corner(0.0, 1.0, 0.0), corner(1.0, 1.0, 0.0), u);
    let x01 = lerp(corner(0.0, 0.0, 1.0), corner(1.0, 0.0, 1.0), u);
    let x11 = lerp(corner(0.0, 1.0, 1.0), corner(1.0, 1.0, 1.0), u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// Fractal (fBm) value noise in [0, 1].
pub fn fbm(seed: u64, x: f64, y: f64, z: f64, frequency: f64, octaves: u32) -> f64 {
    let (mut sum, mut amp, mut norm, mut f) = (0.0, 0.5, 0.0, frequency.max(1.0));
    for o in 0..octaves.max(1) {
        sum += amp
            * value_noise(
                seed.wrapping_add(u64::from(o) * 131),
                x * f,
                y * f,
                z * f,
                f as i64,
            );
        norm += amp;
        amp *= 0.5;
        f *= 2.0;
    }
    sum / norm
}

/// The value of a texture generator at normalised coordinates (u, v, w) for `layer`.
fn texel(generator: &Content, seed: u64, u: f64, v: f64, w: f64, layer: u32) -> [f64; 4] {
    let s = seed.wrapping_add(u64::from(layer) * 7919);
    match *generator {
        Content::Noise {
            frequency: f,
            octaves,
            amplitude: a,
        } => {
            let o = octaves as u32;
            [0.0, 1.0, 2.0, 3.0].map(|c| a * fbm(s.wrapping_add(c as u64 * 1013), u, v, w, f, o))
        }
        Content::BlueNoise => {
            // R2 low-discrepancy sequence over a hashed index: well spread, high-frequency
            // values like blue noise, per channel decorrelated.
            let (x, y) = ((u * 4096.0) as u64, (v * 4096.0) as u64);
            [0.0, 1.0, 2.0, 3.0].map(|c| {
                let n = (x + y * 4099) as f64
                    + hash(s.wrapping_add(c as u64), x as i64, y as i64, 0) * 0.5;
                (0.5 + n * 0.754_877_666_246_692_7 + (y as f64) * 0.569_840_290_998_053_3).fract()
            })
        }
        Content::Checker { cells } => {
            let cells = cells.max(1.0);
            let c = (((u * cells).floor() + (v * cells).floor()) as i64).rem_euclid(2) as f64;
            [c, c, c, 1.0]
        }
        Content::Constant { value: c } => [c, c, c, c],
        Content::Gradient => [u, v, w, 1.0],
        Content::Atlas { cells } => {
            // Glyph-like panels: a grid of cells, each with a seeded bar pattern and frame.
            let cells = cells.max(1.0);
            let (cu, cv) = ((u * cells).floor(), (v * cells).floor());
            let (fu, fv) = ((u * cells).fract(), (v * cells).fract());
            let frame = !(0.06..=0.94).contains(&fu) || !(0.06..=0.94).contains(&fv);
            let bars =
                (hash(s, cu as i64, cv as i64, (fv * 8.0) as i64) > 0.45) && fu > 0.15 && fu < 0.85;
            let hue = hash(s, cu as i64, cv as i64, 99);
            let on = if frame || bars { 1.0 } else { 0.08 };
            [on * (0.4 + 0.6 * hue), on * (1.0 - hue), on, 1.0]
        }
        Content::Coastline { shore, frequency } => {
            let land = fbm(s, u, v, 0.0, frequency, 5) + (v - 0.5) * 0.6;
            let m = if land > shore { 0.0 } else { 1.0 };
            [m, m, m, 1.0]
        }
        _ => [0.0, 0.0, 0.0, 1.0],
    }
}

fn f16(x: f32) -> [u8; 2] {
    half::f16::from_f32(x).to_le_bytes()
}

/// Unsigned small float with 5-bit exponent (R11G11B10).
fn small_float(x: f32, mantissa_bits: u32) -> u32 {
    let x = x.max(0.0);
    if x == 0.0 {
        return 0;
    }
    let max = (2.0 - 2f32.powi(-(mantissa_bits as i32))) * 2f32.powi(15);
    let x = x.min(max);
    let e = x.log2().floor().max(-14.0);
    let m = if e <= -14.0 && x < 2f32.powi(-14) {
        x / 2f32.powi(-14)
    } else {
        x / 2f32.powf(e) - 1.0
    };
    let exponent = if x < 2f32.powi(-14) {
        0
    } else {
        (e as i32 + 15) as u32
    };
    (exponent << mantissa_bits)
        | ((m * (1u32 << mantissa_bits) as f32).round() as u32).min((1 << mantissa_bits) - 1)
}

/// Encodes one texel of RGBA values in `format`, or says the format cannot be generated.
pub fn encode_texel(format: TextureFormat, c: [f64; 4]) -> Result<Vec<u8>, String> {
    use TextureFormat as F;
    let un8 = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let sn8 = |x: f64| (x.clamp(-1.0, 1.0) * 127.0).round() as i8 as u8;
    let un16 = |x: f64| ((x.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes();
    let f32b = |x: f64| (x as f32).to_le_bytes();
    let h = |x: f64| f16(x as f32);
    Ok(match format {
        F::R8Unorm => vec![un8(c[0])],
        F::Rg8Unorm => vec![un8(c[0]), un8(c[1])],
        F::Rgba8Unorm | F::Rgba8UnormSrgb => vec![un8(c[0]), un8(c[1]), un8(c[2]), un8(c[3])],
        F::Bgra8Unorm | F::Bgra8UnormSrgb => vec![un8(c[2]), un8(c[1]), un8(c[0]), un8(c[3])],
        F::R8Snorm => vec![sn8(c[0])],
        F::Rgba8Snorm => vec![sn8(c[0]), sn8(c[1]), sn8(c[2]), sn8(c[3])],
        F::R8Uint => vec![(c[0].clamp(0.0, 1.0) * 255.0) as u8],
        F::R16Unorm => un16(c[0]).to_vec(),
        F::Rg16Unorm => [un16(c[0]), un16(c[1])].concat(),
        F::Rgba16Unorm => [un16(c[0]), un16(c[1]), un16(c[2]), un16(c[3])].concat(),
        F::R16Float => h(c[0]).to_vec(),
        F::Rg16Float => [h(c[0]), h(c[1])].concat(),
        F::Rgba16Float => [h(c[0]), h(c[1]), h(c[2]), h(c[3])].concat(),
        F::R32Float => f32b(c[0]).to_vec(),
        F::Rg32Float => [f32b(c[0]), f32b(c[1])].concat(),
        F::Rgba32Float => [f32b(c[0]), f32b(c[1]), f32b(c[2]), f32b(c[3])].concat(),
        F::R16Uint => ((c[0].clamp(0.0, 1.0) * 65535.0) as u16)
            .to_le_bytes()
            .to_vec(),
        F::R32Uint => ((c[0].clamp(0.0, 1.0) * f64::from(u32::MAX)) as u32)
            .to_le_bytes()
            .to_vec(),
        F::Rgb10a2Unorm => {
            let q = |x: f64, m: f64| (x.clamp(0.0, 1.0) * m).round() as u32;
            (q(c[0], 1023.0)
                | (q(c[1], 1023.0) << 10)
                | (q(c[2], 1023.0) << 20)
                | (q(c[3], 3.0) << 30))
                .to_le_bytes()
                .to_vec()
        }
        F::Rg11b10Ufloat => (small_float(c[0] as f32, 6)
            | (small_float(c[1] as f32, 6) << 11)
            | (small_float(c[2] as f32, 5) << 22))
            .to_le_bytes()
            .to_vec(),
        other => {
            return Err(format!(
                "a generator cannot write {other:?} (block-compressed or depth): give the texture a side file"
            ));
        }
    })
}

/// One BC7 block (mode 6, both endpoints equal) holding a single RGBA8 colour: a real BC7
/// encoding at 4x4-texel resolution, enough for masks and generated detail without an encoder.
fn bc7_solid_block(c: [u8; 4]) -> [u8; 16] {
    // The shared p-bit is the channels' majority low bit; the others are off by one.
    let p = u32::from(c.iter().filter(|&&x| x & 1 == 1).count() >= 2);
    let mut bits: u128 = 1 << 6;
    let mut at = 7;
    for ch in c {
        let e = u128::from(ch >> 1);
        bits |= e << at;
        bits |= e << (at + 7);
        at += 14;
    }
    bits |= u128::from(p) << at;
    bits |= u128::from(p) << (at + 1);
    bits.to_le_bytes()
}

fn bc7_mip(generator: &Content, seed: u64, (w, h): (u32, u32), layers: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    for layer in 0..layers {
        for by in 0..h.div_ceil(4) {
            for bx in 0..w.div_ceil(4) {
                let mut sum = [0.0f64; 4];
                for (dx, dy) in (0..4).flat_map(|dy| (0..4).map(move |dx| (dx, dy))) {
                    let u = (f64::from((bx * 4 + dx).min(w - 1)) + 0.5) / f64::from(w);
                    let v = (f64::from((by * 4 + dy).min(h - 1)) + 0.5) / f64::from(h);
                    let t = texel(generator, seed, u, v, 0.0, layer);
                    for k in 0..4 {
                        sum[k] += t[k] / 16.0;
                    }
                }
                let q = sum.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
                bytes.extend(bc7_solid_block(q));
            }
        }
    }
    bytes
}

/// Contents of every mip (all layers / slices of a mip together), for a texture generator.
#[allow(clippy::too_many_arguments)]
pub fn texture(
    contents: &Seeded<Content>,
    format: TextureFormat,
    width: u32,
    height: u32,
    depth_or_layers: u32,
    volume: bool,
    mips: u32,
) -> Result<Vec<Vec<u8>>, String> {
    let mut out = Vec::new();
    for mip in 0..mips {
        let (w, h) = ((width >> mip).max(1), (height >> mip).max(1));
        if matches!(
            format,
            TextureFormat::Bc7RgbaUnorm | TextureFormat::Bc7RgbaUnormSrgb
        ) && !volume
        {
            out.push(bc7_mip(
                &contents.generator,
                contents.seed,
                (w, h),
                depth_or_layers,
            ));
            continue;
        }
        let d = if volume {
            (depth_or_layers >> mip).max(1)
        } else {
            depth_or_layers
        };
        let mut bytes = Vec::new();
        for z in 0..d {
            for y in 0..h {
                for x in 0..w {
                    let (u, v) = (
                        (f64::from(x) + 0.5) / f64::from(w),
                        (f64::from(y) + 0.5) / f64::from(h),
                    );
                    let (wz, layer) = if volume {
                        ((f64::from(z) + 0.5) / f64::from(d), 0)
                    } else {
                        (0.0, z)
                    };
                    bytes.extend(encode_texel(
                        format,
                        texel(&contents.generator, contents.seed, u, v, wz, layer),
                    )?);
                }
            }
        }
        out.push(bytes);
    }
    Ok(out)
}

/// Contents of a buffer generator.
pub fn buffer(contents: &Seeded<Content>, size: u64) -> Vec<u8> {
    let seed = contents.seed;
    let mut out: Vec<u8> = Vec::with_capacity(size as usize);
    match contents.generator {
        Content::Lights {
            count,
            area,
            min_radius,
            max_radius,
            intensity,
        } => {
            // 64-byte records: position.xyz, radius, colour.rgb, intensity, direction.xyz,
            // spot cosine (-1: point light), then 16 bytes of zero padding.
            let count = (count as u64).min(size / 64);
            for i in 0..count {
                let r = |k: u64| hash(seed, i as i64, k as i64, 0);
                let hue = r(4);
                let colour = [
                    0.5 + 0.5 * (std::f64::consts::TAU * hue).cos(),
                    0.5 + 0.5 * (std::f64::consts::TAU * (hue + 0.33)).cos(),
                    0.5 + 0.5 * (std::f64::consts::TAU * (hue + 0.67)).cos(),
                ];
                let radius = min_radius + (max_radius - min_radius) * r(3);
                let record = [
                    (r(0) - 0.5) * area,
                    1.0 + 12.0 * r(1),
                    (r(2) - 0.5) * area,
                    radius,
                    colour[0],
                    colour[1],
                    colour[2],
                    intensity * (0.5 + r(5)),
                    0.0,
                    -1.0,
                    0.0,
                    -1.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                ];
                for v in record {
                    out.extend((v as f32).to_le_bytes());
                }
            }
        }
        Content::Instances { count, area } => {
            // Three float4 rows of an affine transform per instance (seed's VB7 layout).
            let count = (count as u64).min(size / 48);
            for i in 0..count {
                let r = |k: u64| hash(seed, i as i64, k as i64, 1);
                let (angle, scale) = (std::f64::consts::TAU * r(3), 0.6 + 0.8 * r(4));
                let (s, c) = (angle.sin() * scale, angle.cos() * scale);
                let (x, z) = ((r(0) - 0.5) * area, (r(1) - 0.5) * area);
                for v in [c, 0.0, s, x, 0.0, scale, 0.0, 0.0, -s, 0.0, c, z] {
                    out.extend((v as f32).to_le_bytes());
                }
            }
        }
        Content::CityLots(city) => {
            // The buildings of `city_blocks` with the same seed and parameters: a unit box
            // (centred, size 1) scaled to each building and moved onto its lot.
            for b in buildings(seed, city).take((size / 48) as usize) {
                let size3 = [0, 1, 2].map(|c| b.max[c] - b.min[c]);
                let centre = [0, 1, 2].map(|c| (b.max[c] + b.min[c]) / 2.0);
                #[rustfmt::skip]
                let rows = [
                    size3[0], 0.0, 0.0, centre[0],
                    0.0, size3[1], 0.0, centre[1],
                    0.0, 0.0, size3[2], centre[2],
                ];
                for v in rows {
                    out.extend((v as f32).to_le_bytes());
                }
            }
        }
        Content::Constant { value } => {
            let v = value as u32;
            while (out.len() as u64) + 4 <= size {
                out.extend(v.to_le_bytes());
            }
        }
        _ => {
            for i in 0..size / 4 {
                out.extend((hash(seed, i as i64, 0, 0) as f32).to_le_bytes());
            }
        }
    }
    out.resize(size as usize, 0);
    out
}

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

/// One building of a street grid: its box and a seeded tint.
struct Building {
    min: [f64; 3],
    max: [f64; 3],
    tint: [f64; 3],
}

/// The buildings of a street grid of `blocks_x` x `blocks_z` blocks, `buildings_per_block` lots
/// each, with seeded heights and insets: one layout for the `city_blocks` mesh and the
/// `city_lots` instance rows, so the two agree building for building.
fn buildings(seed: u64, city: City) -> impl Iterator<Item = Building> {
    let (bx, bz, block, street) = (
        city.blocks_x as i64,
        city.blocks_z as i64,
        city.block_size,
        city.street_width,
    );
    let per = city.buildings_per_block.max(1.0) as i64;
    let pitch = block + street;
    let side = (per as f64).sqrt().ceil() as i64;
    let lot = block / side as f64;
    (0..bx).flat_map(move |i| {
        (0..bz).flat_map(move |j| {
            let (ox, oz) = (
                (i as f64 - bx as f64 / 2.0) * pitch,
                (j as f64 - bz as f64 / 2.0) * pitch,
            );
            (0..per).map(move |k| {
                let r = |c: i64| hash(seed, i * 1000 + j, k, c);
                let height = city.min_height + (city.max_height - city.min_height) * r(0).powi(2);
                let (lx, lz) = (ox + (k % side) as f64 * lot, oz + (k / side) as f64 * lot);
                let inset = lot * (0.05 + 0.1 * r(1));
                Building {
                    min: [lx + inset, 0.0, lz + inset],
                    max: [lx + lot - inset, height, lz + lot - inset],
                    tint: [r(2), r(3), r(4)],
                }
            })
        })
    })
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
    use super::*;

    #[test]
    fn generators_are_deterministic_and_vary() {
        let noise = |seed| {
            let noise = Seeded {
                generator: Content::new("noise", &BTreeMap::new()).unwrap(),
                seed,
            };
            texture(&noise, TextureFormat::Rgba8Unorm, 16, 16, 1, false, 1).unwrap()
        };
        let a = noise(7);
        assert_eq!(a, noise(7));
        assert_ne!(a, noise(8));
        let distinct: std::collections::BTreeSet<u8> = a[0].iter().copied().collect();
        assert!(distinct.len() > 20);
    }

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
    fn city_lots_place_the_buildings_of_city_blocks() {
        let params = BTreeMap::from([
            ("blocks_x".to_owned(), ParamValue::Scalar(2.0)),
            ("blocks_z".to_owned(), ParamValue::Scalar(3.0)),
        ]);
        let city = mesh(&Seeded {
            generator: Shape::new("city_blocks", &params).unwrap(),
            seed: 9,
        });
        let count = 2 * 3 * 4;
        let lots = Seeded {
            generator: Content::new("city_lots", &params).unwrap(),
            seed: 9,
        };
        let rows = buffer(&lots, count * 48);
        let f = |o: usize| f32::from_le_bytes(rows[o..o + 4].try_into().unwrap());
        for b in 0..count as usize {
            // city_blocks writes 24 vertices per building; the box spans +-0.5 of the lot row.
            let verts = &city.positions[b * 24..(b + 1) * 24];
            let min = |c: usize| verts.iter().map(|p| p[c]).fold(f32::INFINITY, f32::min);
            let max = |c: usize| verts.iter().map(|p| p[c]).fold(f32::NEG_INFINITY, f32::max);
            let o = b * 48;
            let (sx, tx, sy, ty, sz, tz) =
                (f(o), f(o + 12), f(o + 20), f(o + 28), f(o + 40), f(o + 44));
            for (lo, hi, s, t) in [
                (min(0), max(0), sx, tx),
                (min(1), max(1), sy, ty),
                (min(2), max(2), sz, tz),
            ] {
                assert!(
                    (t - s / 2.0 - lo).abs() < 1e-3 && (t + s / 2.0 - hi).abs() < 1e-3,
                    "building {b}"
                );
            }
        }
    }

    #[test]
    fn bc7_solid_blocks_decode_to_their_colour() {
        // Mode 6 with equal endpoints and zero indices decodes to (e << 1 | p) per channel.
        let block = u128::from_le_bytes(bc7_solid_block([200, 100, 51, 255]));
        assert_eq!(block & 0x7F, 1 << 6);
        let field = |at: u32| ((block >> at) & 0x7F) as u8;
        let p = ((block >> 63) & 1) as u8;
        assert_eq!(p, ((block >> 64) & 1) as u8);
        let decoded: Vec<u8> = (0..4).map(|c| (field(7 + 14 * c) << 1) | p).collect();
        for (d, want) in decoded.iter().zip([200u8, 100, 51, 255]) {
            assert!(d.abs_diff(want) <= 1, "{decoded:?}");
        }
        assert_eq!(block >> 65, 0, "indices must be zero");
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
