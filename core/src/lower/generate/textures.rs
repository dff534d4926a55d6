//! Texture contents: each generator evaluated per texel (or averaged per 4x4 block and
//! encoded as BC7), then encoded in the texture's wgpu format.

use wgpu_types::TextureFormat;

use super::{f16, fbm, hash, small_float};
use crate::capture::generators::{Content, Seeded};
use crate::lower::ContentsError;

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

/// Encodes one texel of RGBA values in `format`, or says the format cannot be generated.
pub fn encode_texel(format: TextureFormat, c: [f64; 4]) -> Result<Vec<u8>, ContentsError> {
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
        other => return Err(ContentsError::Unwritable { format: other }),
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
) -> Result<Vec<Vec<u8>>, ContentsError> {
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

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

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
}
