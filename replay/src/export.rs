//! Export: every subresource of a texture (each mip, array layer, cube face and 3D slice) read
//! back and written as PNG (8-bit colour; 10- and 16-bit normalised colour as 16-bit PNG;
//! integers normalised to their value range) or EXR (float, HDR and depth), named
//! `<resource>[_mip<M>][_layer<L>][_z<Z>].png|.exr`, with a manifest of what each file holds.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::plan::TextureSpec;

#[derive(Debug, Clone, Serialize)]
pub struct ExportedFile {
    pub file: String,
    pub resource: String,
    pub mip: u32,
    pub layer: u32,
    pub z: Option<u32>,
    pub width: u32,
    pub height: u32,
    pub format: String,
    /// png8, png16, png16-normalised (integer formats: min..max of the data mapped to 0..65535), exr
    pub encoding: &'static str,
    /// Smallest and largest channel value found (in the format's own units).
    pub min: f64,
    pub max: f64,
    /// For EXR files: an 8-bit PNG to look at, range-mapped like a texture viewer's range
    /// control (depth: min..max, nearest bright; colour: 0..99.5th percentile, gamma 2.2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preview: Option<String>,
    /// Every texel holds the same value (a cleared or never-written target).
    pub uniform: bool,
}

/// The display range of float data: depth spans min..max; colour spans 0 (or a negative
/// minimum) up to the 99.5th percentile, so a few very bright texels (a sun disk) do not
/// flatten the rest of the image.
fn preview_range(values: &[[f32; 4]], channels: usize, depth: bool) -> (f32, f32) {
    let mut finite: Vec<f32> = values
        .iter()
        .flat_map(|v| v[..channels.min(3)].iter().copied())
        .filter(|x| x.is_finite())
        .collect();
    if finite.is_empty() {
        return (0.0, 1.0);
    }
    let lo = finite.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = if depth {
        finite.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    } else {
        let k = ((finite.len() - 1) as f64 * 0.995) as usize;
        *finite.select_nth_unstable_by(k, f32::total_cmp).1
    };
    let lo = if depth { lo } else { lo.min(0.0) };
    (lo, if hi > lo { hi } else { lo + 1.0 })
}

#[derive(Debug, Clone, Serialize)]
pub struct Skipped {
    pub resource: String,
    pub reason: String,
}

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("writing {path}: {message}")]
    Write { path: String, message: String },
    #[error("reading back \"{resource}\": {message}")]
    Readback { resource: String, message: String },
}

/// How texel bytes decode into channel values.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Decode {
    Unorm8(usize),
    Snorm8(usize),
    Uint(usize, usize),
    Sint(usize, usize),
    Unorm16(usize),
    Snorm16(usize),
    Half(usize),
    Float(usize),
    Rgb10a2,
    Rg11b10,
    Rgb9e5,
    Bgra8,
}

fn decoding(f: wgpu::TextureFormat) -> Option<(Decode, u32)> {
    use wgpu::TextureFormat as F;
    Some(match f {
        F::R8Unorm => (Decode::Unorm8(1), 1),
        F::Rg8Unorm => (Decode::Unorm8(2), 2),
        F::Rgba8Unorm | F::Rgba8UnormSrgb => (Decode::Unorm8(4), 4),
        F::Bgra8Unorm | F::Bgra8UnormSrgb => (Decode::Bgra8, 4),
        F::R8Snorm => (Decode::Snorm8(1), 1),
        F::Rg8Snorm => (Decode::Snorm8(2), 2),
        F::Rgba8Snorm => (Decode::Snorm8(4), 4),
        F::R8Uint => (Decode::Uint(1, 1), 1),
        F::Rg8Uint => (Decode::Uint(2, 1), 2),
        F::Rgba8Uint => (Decode::Uint(4, 1), 4),
        F::R8Sint => (Decode::Sint(1, 1), 1),
        F::Rgba8Sint => (Decode::Sint(4, 1), 4),
        F::R16Uint => (Decode::Uint(1, 2), 2),
        F::Rg16Uint => (Decode::Uint(2, 2), 4),
        F::Rgba16Uint => (Decode::Uint(4, 2), 8),
        F::R16Sint => (Decode::Sint(1, 2), 2),
        F::R32Uint => (Decode::Uint(1, 4), 4),
        F::Rg32Uint => (Decode::Uint(2, 4), 8),
        F::Rgba32Uint => (Decode::Uint(4, 4), 16),
        F::R32Sint => (Decode::Sint(1, 4), 4),
        F::R16Unorm | F::Depth16Unorm => (Decode::Unorm16(1), 2),
        F::Rg16Unorm => (Decode::Unorm16(2), 4),
        F::Rgba16Unorm => (Decode::Unorm16(4), 8),
        F::R16Snorm => (Decode::Snorm16(1), 2),
        F::Rg16Snorm => (Decode::Snorm16(2), 4),
        F::Rgba16Snorm => (Decode::Snorm16(4), 8),
        F::R16Float => (Decode::Half(1), 2),
        F::Rg16Float => (Decode::Half(2), 4),
        F::Rgba16Float => (Decode::Half(4), 8),
        F::R32Float | F::Depth32Float | F::Depth32FloatStencil8 => (Decode::Float(1), 4),
        F::Rg32Float => (Decode::Float(2), 8),
        F::Rgba32Float => (Decode::Float(4), 16),
        F::Rgb10a2Unorm => (Decode::Rgb10a2, 4),
        F::Rg11b10Ufloat => (Decode::Rg11b10, 4),
        F::Rgb9e5Ufloat => (Decode::Rgb9e5, 4),
        _ => return None,
    })
}

fn small_float(bits: u32, mantissa_bits: u32) -> f32 {
    let exponent = bits >> mantissa_bits;
    let mantissa = bits & ((1 << mantissa_bits) - 1);
    let m = mantissa as f32 / (1u32 << mantissa_bits) as f32;
    match exponent {
        0 => m * 2f32.powi(-14),
        31 => {
            if mantissa == 0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        e => (1.0 + m) * 2f32.powi(e as i32 - 15),
    }
}

/// Channel values of one texel (up to four).
fn decode(d: Decode, t: &[u8]) -> ([f32; 4], usize) {
    let mut out = [0.0f32; 4];
    let n = match d {
        Decode::Unorm8(n) => {
            for i in 0..n {
                out[i] = f32::from(t[i]) / 255.0
            }
            n
        }
        Decode::Bgra8 => {
            out = [
                f32::from(t[2]) / 255.0,
                f32::from(t[1]) / 255.0,
                f32::from(t[0]) / 255.0,
                f32::from(t[3]) / 255.0,
            ];
            4
        }
        Decode::Snorm8(n) => {
            for i in 0..n {
                out[i] = (f32::from(t[i] as i8) / 127.0).max(-1.0)
            }
            n
        }
        Decode::Uint(n, size) | Decode::Sint(n, size) => {
            let signed = matches!(d, Decode::Sint(..));
            for i in 0..n {
                let b = &t[i * size..(i + 1) * size];
                out[i] = match (size, signed) {
                    (1, false) => f32::from(b[0]),
                    (1, true) => f32::from(b[0] as i8),
                    (2, false) => f32::from(u16::from_le_bytes([b[0], b[1]])),
                    (2, true) => f32::from(i16::from_le_bytes([b[0], b[1]])),
                    (_, false) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                    (_, true) => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                };
            }
            n
        }
        Decode::Unorm16(n) => {
            for i in 0..n {
                out[i] = f32::from(u16::from_le_bytes([t[2 * i], t[2 * i + 1]])) / 65535.0
            }
            n
        }
        Decode::Snorm16(n) => {
            for i in 0..n {
                out[i] =
                    (f32::from(i16::from_le_bytes([t[2 * i], t[2 * i + 1]])) / 32767.0).max(-1.0)
            }
            n
        }
        Decode::Half(n) => {
            for i in 0..n {
                out[i] = half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32()
            }
            n
        }
        Decode::Float(n) => {
            for i in 0..n {
                out[i] = f32::from_le_bytes([t[4 * i], t[4 * i + 1], t[4 * i + 2], t[4 * i + 3]])
            }
            n
        }
        Decode::Rgb10a2 => {
            let v = u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
            out = [
                (v & 1023) as f32 / 1023.0,
                ((v >> 10) & 1023) as f32 / 1023.0,
                ((v >> 20) & 1023) as f32 / 1023.0,
                (v >> 30) as f32 / 3.0,
            ];
            4
        }
        Decode::Rg11b10 => {
            let v = u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
            out = [
                small_float(v & 0x7FF, 6),
                small_float((v >> 11) & 0x7FF, 6),
                small_float((v >> 22) & 0x3FF, 5),
                1.0,
            ];
            3
        }
        Decode::Rgb9e5 => {
            let v = u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
            let scale = 2f32.powi((v >> 27) as i32 - 15 - 9);
            out = [
                (v & 511) as f32 * scale,
                ((v >> 9) & 511) as f32 * scale,
                ((v >> 18) & 511) as f32 * scale,
                1.0,
            ];
            3
        }
    };
    (out, n)
}

/// A file name for a subresource.
pub fn file_name(
    resource: &str,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
    z: Option<u32>,
    ext: &str,
) -> String {
    let mut name = resource.replace(
        |c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'),
        "_",
    );
    if spec.mip_levels > 1 {
        name.push_str(&format!("_mip{mip}"));
    }
    let layers = if spec.dimension == wgpu::TextureDimension::D3 {
        1
    } else {
        spec.size.depth_or_array_layers
    };
    if layers > 1 {
        name.push_str(&format!("_layer{layer}"));
    }
    if let Some(z) = z {
        name.push_str(&format!("_z{z}"));
    }
    format!("{name}.{ext}")
}

fn write_err(path: &Path, e: impl std::fmt::Display) -> ExportError {
    ExportError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Writes through a temporary name so no partial file is left behind.
fn atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ExportError> {
    let tmp = path.with_extension(format!(
        "tmp.{}",
        path.extension().and_then(|e| e.to_str()).unwrap_or("bin")
    ));
    match write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string())) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(write_err(path, e))
        }
    }
}

/// Decodes one subresource's rows (tightly packed, `row_bytes` each) and writes it to `dir`.
#[allow(clippy::too_many_arguments)]
pub fn write_image(
    dir: &Path,
    resource: &str,
    spec: &TextureSpec,
    format: wgpu::TextureFormat,
    mip: u32,
    layer: u32,
    z: Option<u32>,
    width: u32,
    height: u32,
    data: &[u8],
) -> Result<Option<ExportedFile>, ExportError> {
    let Some((decoder, texel_bytes)) = decoding(format) else {
        return Ok(None);
    };
    let pixels = (width * height) as usize;
    let mut values: Vec<[f32; 4]> = Vec::with_capacity(pixels);
    let mut channels = 1;
    for p in 0..pixels {
        let o = p * texel_bytes as usize;
        let Some(t) = data.get(o..o + texel_bytes as usize) else {
            break;
        };
        let (v, n) = decode(decoder, t);
        channels = n;
        values.push(v);
    }
    let finite = values
        .iter()
        .flat_map(|v| v[..channels].iter().copied())
        .filter(|x| x.is_finite());
    let (min, max) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (min, max) = if min > max { (0.0, 0.0) } else { (min, max) };
    let uniform = values
        .first()
        .is_none_or(|first| values.iter().all(|v| v[..channels] == first[..channels]));
    let integer = matches!(decoder, Decode::Uint(..) | Decode::Sint(..));
    let float = matches!(
        decoder,
        Decode::Half(_)
            | Decode::Float(_)
            | Decode::Rg11b10
            | Decode::Rgb9e5
            | Decode::Snorm8(_)
            | Decode::Snorm16(_)
    ) || format.has_depth_aspect();
    let eight_bit = matches!(decoder, Decode::Unorm8(_) | Decode::Bgra8);
    let to_rgba = |v: &[f32; 4]| -> [f32; 4] {
        match channels {
            1 => [v[0], v[0], v[0], 1.0],
            2 => [v[0], v[1], 0.0, 1.0],
            3 => [v[0], v[1], v[2], 1.0],
            _ => *v,
        }
    };
    let (ext, encoding) = if float {
        ("exr", "exr")
    } else if integer {
        ("png", "png16-normalised")
    } else if eight_bit {
        ("png", "png8")
    } else {
        ("png", "png16")
    };
    let name = file_name(resource, spec, mip, layer, z, ext);
    let path = dir.join(&name);
    let mut preview = None;
    if encoding == "exr" {
        atomically(&path, |tmp| {
            exr::prelude::write_rgba_file(tmp, width as usize, height as usize, |x, y| {
                let v = to_rgba(&values[y * width as usize + x]);
                (v[0], v[1], v[2], v[3])
            })
            .map_err(|e| e.to_string())
        })?;
        let depth = format.has_depth_aspect();
        let (lo, hi) = preview_range(&values, channels, depth);
        let preview_name = file_name(resource, spec, mip, layer, z, "preview.png");
        atomically(&dir.join(&preview_name), |tmp| {
            let mut img = image::RgbaImage::new(width, height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = to_rgba(&values[i]);
                let map = |c: f32| {
                    let t = ((c - lo) / (hi - lo)).clamp(0.0, 1.0);
                    // Depth reads better with near bright; colour gets a display gamma.
                    let t = if depth { 1.0 - t } else { t.powf(1.0 / 2.2) };
                    (t * 255.0).round() as u8
                };
                *p = image::Rgba([map(v[0]), map(v[1]), map(v[2]), 255]);
            }
            img.save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| e.to_string())
        })?;
        preview = Some(preview_name);
    }
    match encoding {
        "exr" => {}
        "png8" => atomically(&path, |tmp| {
            let mut img = image::RgbaImage::new(width, height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = to_rgba(&values[i]);
                *p = image::Rgba(v.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
            }
            img.save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| e.to_string())
        })?,
        _ => atomically(&path, |tmp| {
            let (lo, span) = if integer {
                (min, (max - min).max(1.0))
            } else {
                (0.0, 1.0)
            };
            let mut img: image::ImageBuffer<image::Rgba<u16>, Vec<u16>> =
                image::ImageBuffer::new(width, height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = to_rgba(&values[i]);
                let n = |c: f32| (((c - lo) / span).clamp(0.0, 1.0) * 65535.0).round() as u16;
                let alpha = if channels == 4 && !integer {
                    n(v[3])
                } else {
                    65535
                };
                *p = image::Rgba([n(v[0]), n(v[1]), n(v[2]), alpha]);
            }
            img.save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| e.to_string())
        })?,
    }
    Ok(Some(ExportedFile {
        file: name,
        resource: resource.to_owned(),
        mip,
        layer,
        z,
        width,
        height,
        format: format!("{format:?}"),
        encoding,
        min: f64::from(min),
        max: f64::from(max),
        preview,
        uniform,
    }))
}

/// Reads back every subresource of `texture` and writes it into `dir`.
pub fn export_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    dir: &Path,
) -> Result<(Vec<ExportedFile>, Option<Skipped>), ExportError> {
    let skip = |reason: &str| {
        Ok((
            Vec::new(),
            Some(Skipped {
                resource: spec.name.clone(),
                reason: reason.to_owned(),
            }),
        ))
    };
    if spec.samples > 1 {
        return skip("multisampled: resolve it to export");
    }
    if spec.format.is_compressed() {
        return skip("block-compressed: exported images are decoded formats only");
    }
    let format = match spec.format {
        wgpu::TextureFormat::Depth32FloatStencil8 => wgpu::TextureFormat::Depth32Float,
        wgpu::TextureFormat::Depth24Plus | wgpu::TextureFormat::Depth24PlusStencil8 => {
            return skip("Depth24Plus cannot be copied to a buffer");
        }
        f => f,
    };
    if decoding(format).is_none() {
        return skip("no decoder for this format");
    }
    let aspect = if spec.format.has_depth_aspect() {
        wgpu::TextureAspect::DepthOnly
    } else {
        wgpu::TextureAspect::All
    };
    let texel = format.block_copy_size(Some(aspect)).unwrap_or(4);
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    let layers = if d3 {
        1
    } else {
        spec.size.depth_or_array_layers
    };
    let mut files = Vec::new();
    for mip in 0..spec.mip_levels {
        let w = (spec.size.width >> mip).max(1);
        let h = (spec.size.height >> mip).max(1);
        let depth = if d3 {
            (spec.size.depth_or_array_layers >> mip).max(1)
        } else {
            1
        };
        for layer in 0..layers {
            let row = w * texel;
            let padded = row.div_ceil(256) * 256;
            let size = u64::from(padded) * u64::from(h) * u64::from(depth);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("export"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: mip,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: if d3 { 0 } else { layer },
                    },
                    aspect,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: depth,
                },
            );
            queue.submit([encoder.finish()]);
            let bytes = crate::readback::read_buffer(device, queue, &buffer, size, &spec.name)
                .map_err(|e| ExportError::Readback {
                    resource: spec.name.clone(),
                    message: e.to_string(),
                })?;
            for zi in 0..depth {
                let mut tight = Vec::with_capacity((row * h) as usize);
                for y in 0..h {
                    let o = (zi * h + y) as usize * padded as usize;
                    tight.extend_from_slice(&bytes[o..o + row as usize]);
                }
                let z = d3.then_some(zi);
                if let Some(f) =
                    write_image(dir, &spec.name, spec, format, mip, layer, z, w, h, &tight)?
                {
                    files.push(f);
                }
            }
        }
    }
    Ok((files, None))
}

/// The folder for an export: results go to a temporary sibling that is renamed at the end.
pub fn staging_dir(out: &Path) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    out.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_floats_decode() {
        // R11G11B10: 1.0 is exponent 15, mantissa 0 in each channel.
        let one11 = 15u32 << 6;
        let one10 = 15u32 << 5;
        let v = one11 | (one11 << 11) | (one10 << 22);
        let (c, n) = decode(Decode::Rg11b10, &v.to_le_bytes());
        assert_eq!((n, c[0], c[1], c[2]), (3, 1.0, 1.0, 1.0));
        let v: u32 = (1023 | (512 << 10)) | (3 << 30);
        let (c, _) = decode(Decode::Rgb10a2, &v.to_le_bytes());
        assert!((c[0] - 1.0).abs() < 1e-6 && (c[1] - 0.5).abs() < 1e-3 && c[3] == 1.0);
    }
}
