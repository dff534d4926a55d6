//! Procedural contents named by captures: textures (noise, blue noise, checker, constant,
//! gradient, atlas, coastline), buffers (lights, instances, constant, noise) and meshes (grid,
//! box, city blocks, terrain, water plate, foliage cards, sphere, capsule), all from a seed and
//! deterministic, so a capture stays small and a replay is the same everywhere.
//!
//! This module holds what they share (the seeded hash, value noise, half and small-float
//! encoding, the city's building layout); `textures`, `buffers` and `meshes` make each kind.

mod buffers;
mod meshes;
mod textures;

pub use buffers::buffer;
pub use meshes::{MeshData, encode_streams, mesh};
pub use textures::{encode_texel, texture};

use crate::capture::generators::City;

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

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::capture::format::ParamValue;
    use crate::capture::generators::{Content, Seeded, Shape};

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

    /// `Shape::counts`, which validation checks draws against, is what the generator builds,
    /// for every shape and for parameters at and past their edges.
    #[test]
    fn shape_counts_are_what_the_generators_build() {
        let cases: &[(&str, &[(&str, f64)])] = &[
            ("grid", &[("divisions", 0.0)]),
            ("grid", &[("divisions", 7.0)]),
            ("grid", &[("divisions", 2.5)]),
            ("water_plate", &[("divisions", 5.0)]),
            ("terrain", &[("resolution", 9.0), ("octaves", 1.0)]),
            ("box", &[]),
            ("city_blocks", &[("blocks_x", 2.0), ("blocks_z", 3.0)]),
            (
                "city_blocks",
                &[
                    ("blocks_x", 1.0),
                    ("blocks_z", 2.0),
                    ("buildings_per_block", 0.0),
                ],
            ),
            ("foliage_cards", &[("count", 5.0)]),
            ("foliage_cards", &[("count", 0.0)]),
            ("sphere", &[("segments", 8.0), ("rings", 4.0)]),
            ("sphere", &[("segments", 1.0), ("rings", 1.0)]),
            ("capsule", &[("segments", 6.0)]),
            ("capsule", &[("segments", 3.0)]),
        ];
        for (name, params) in cases {
            let params: BTreeMap<String, ParamValue> = params
                .iter()
                .map(|(k, v)| ((*k).to_owned(), ParamValue::Scalar(*v)))
                .collect();
            let shape = Shape::new(name, &params).unwrap();
            let built = mesh(&Seeded {
                generator: shape.clone(),
                seed: 3,
            });
            assert_eq!(
                shape.counts(),
                (built.positions.len() as u64, built.indices.len() as u64),
                "{name} {params:?}"
            );
        }
    }
}
