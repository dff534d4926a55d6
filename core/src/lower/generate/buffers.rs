//! Buffer contents: light records, instance transform rows, the city's building lots,
//! constants, or seeded noise.

use super::{buildings, hash};
use crate::capture::generators::{Content, Seeded};

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
