//! Reading a texture back into memory: every subresource (mip, array layer, 3D slice) copied
//! to a buffer, mapped, and decoded from its wgpu format into `[f32; 4]` texels with the
//! statistics a viewer needs (channel count, finite min and max, whether every texel is the
//! same). Export writes these images to files; an inspector can show them without any file.

use framelab_core::plan::TextureSpec;

/// One subresource decoded into channel values.
#[derive(Debug, Clone)]
pub struct DecodedImage {
    pub mip: u32,
    pub layer: u32,
    /// The slice of a 3D texture.
    pub z: Option<u32>,
    pub width: u32,
    pub height: u32,
    /// The format the bytes were read in (depth-stencil formats read their depth aspect).
    pub format: wgpu::TextureFormat,
    /// Meaningful channels per texel (1-4); the rest of each `[f32; 4]` is padding.
    pub channels: usize,
    pub kind: ValueKind,
    /// Row-major texels, `width * height` of them.
    pub values: Vec<[f32; 4]>,
}

/// What the decoded values are, which decides how they are best stored and shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueKind {
    /// 8-bit normalised colour.
    Unorm8,
    /// Normalised colour with more than 8 bits.
    UnormWide,
    /// Integers, in their own units.
    Integer,
    /// Float, signed normalised, packed float and depth values.
    Float,
}

impl DecodedImage {
    /// The exact value of a texel as the format stores it: `R v  G v ...` (10- and 16-bit
    /// normalised channels with their integer code), or the stencil value in decimal and binary.
    pub fn texel_values(&self, x: u32, y: u32) -> Option<String> {
        let d = self;
        if x >= d.width || y >= d.height {
            return None;
        }
        let v = d.values[(y * d.width + x) as usize];
        if d.format == wgpu::TextureFormat::Stencil8 {
            let s = v[0] as u32;
            return Some(format!("S {s} (0b{s:08b})"));
        }
        let names = ["R", "G", "B", "A"];
        let parts: Vec<String> = (0..d.channels)
            .map(|c| match d.kind {
                ValueKind::Integer => format!("{} {}", names[c], v[c] as i64),
                ValueKind::Unorm8 => format!(
                    "{} {:.4} ({})",
                    names[c],
                    v[c],
                    (v[c] * 255.0).round() as u32
                ),
                ValueKind::UnormWide => match unorm_bits(d.format, c) {
                    Some(bits) => format!(
                        "{} {:.5} ({})",
                        names[c],
                        v[c],
                        (f64::from(v[c]) * f64::from((1u32 << bits) - 1)).round() as u32
                    ),
                    None => format!("{} {}", names[c], v[c]),
                },
                _ => format!("{} {}", names[c], v[c]),
            })
            .collect();
        Some(parts.join("  "))
    }

    /// Smallest and largest finite channel value, (0, 0) when there is none.
    pub fn range(&self) -> (f32, f32) {
        let (min, max) = self
            .values
            .iter()
            .flat_map(|v| v[..self.channels].iter().copied())
            .filter(|x| x.is_finite())
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        if min > max { (0.0, 0.0) } else { (min, max) }
    }

    /// Every texel holds the same value (a cleared or never-written target).
    pub fn uniform(&self) -> bool {
        let n = self.channels;
        self.values
            .first()
            .is_none_or(|first| self.values.iter().all(|v| v[..n] == first[..n]))
    }

    /// A texel as RGBA: one channel as grey, two as RG, alpha 1 where the format has none.
    pub fn rgba(&self, index: usize) -> [f32; 4] {
        let v = &self.values[index];
        match self.channels {
            1 => [v[0], v[0], v[0], 1.0],
            2 => [v[0], v[1], 0.0, 1.0],
            3 => [v[0], v[1], v[2], 1.0],
            _ => *v,
        }
    }
}

/// Why a texture cannot be read back into images.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unreadable(pub &'static str);

#[derive(Debug, thiserror::Error)]
#[error("reading back \"{resource}\": {message}")]
pub struct ReadError {
    pub resource: String,
    pub message: String,
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
        F::R8Uint | F::Stencil8 => (Decode::Uint(1, 1), 1),
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

/// Decodes tightly packed texels of `format`; `None` when there is no decoder for it.
pub fn decode_image(
    format: wgpu::TextureFormat,
    (mip, layer, z): (u32, u32, Option<u32>),
    width: u32,
    height: u32,
    data: &[u8],
) -> Option<DecodedImage> {
    let (decoder, texel_bytes) = decoding(format)?;
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
    let kind = if matches!(
        decoder,
        Decode::Half(_)
            | Decode::Float(_)
            | Decode::Rg11b10
            | Decode::Rgb9e5
            | Decode::Snorm8(_)
            | Decode::Snorm16(_)
    ) || format.has_depth_aspect()
    {
        ValueKind::Float
    } else if matches!(decoder, Decode::Uint(..) | Decode::Sint(..)) {
        ValueKind::Integer
    } else if matches!(decoder, Decode::Unorm8(_) | Decode::Bgra8) {
        ValueKind::Unorm8
    } else {
        ValueKind::UnormWide
    };
    Some(DecodedImage {
        mip,
        layer,
        z,
        width,
        height,
        format,
        channels,
        kind,
        values,
    })
}

/// The format a texture is read back in, or why it cannot be.
pub fn readable_format(spec: &TextureSpec) -> Result<wgpu::TextureFormat, Unreadable> {
    if spec.samples > 1 {
        return Err(Unreadable("multisampled: resolve it to export"));
    }
    if spec.format.is_compressed() {
        // Read through the GPU's decoder into an uncompressed copy (see `decompress`).
        return match crate::decompress::decompressed_format(spec.format) {
            Some(_) if !spec.usage.contains(wgpu::TextureUsages::TEXTURE_BINDING) => Err(
                Unreadable("block-compressed and never sampled: the GPU cannot decode it"),
            ),
            Some(f) => Ok(f),
            None => Err(Unreadable(
                "block-compressed in a format framelab cannot decode",
            )),
        };
    }
    let format = match spec.format {
        wgpu::TextureFormat::Depth32FloatStencil8 => wgpu::TextureFormat::Depth32Float,
        wgpu::TextureFormat::Depth24Plus | wgpu::TextureFormat::Depth24PlusStencil8 => {
            return Err(Unreadable("Depth24Plus cannot be copied to a buffer"));
        }
        f => f,
    };
    if decoding(format).is_none() {
        return Err(Unreadable("no decoder for this format"));
    }
    Ok(format)
}

/// Reads back every subresource of `texture` and decodes it, mip by mip, layer by layer,
/// slice by slice. The caller checks `readable_format` first.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    format: wgpu::TextureFormat,
) -> Result<Vec<DecodedImage>, ReadError> {
    read_texture_part(device, queue, texture, spec, format, None)
}

/// Reads back one mip and array layer of `texture` (of a 3D texture, every slice of the mip)
/// and decodes it: a viewer showing one subresource of a shadow-map array reads a quarter of
/// it. The caller checks `readable_format` first.
pub fn read_subresource(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    format: wgpu::TextureFormat,
    mip: u32,
    layer: u32,
) -> Result<Vec<DecodedImage>, ReadError> {
    read_texture_part(device, queue, texture, spec, format, Some((mip, layer)))
}

/// The stencil aspect of one mip and array layer (see [`read_subresource`]).
pub fn read_stencil_subresource(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
) -> Result<Vec<DecodedImage>, ReadError> {
    stencil(device, queue, texture, spec, Some((mip, layer)))
}

fn read_texture_part(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    format: wgpu::TextureFormat,
    only: Option<(u32, u32)>,
) -> Result<Vec<DecodedImage>, ReadError> {
    if spec.format.is_compressed() {
        let (decoded, decoded_spec) =
            crate::decompress::decompress(device, queue, texture, spec, format).map_err(|e| {
                ReadError {
                    resource: spec.name.clone(),
                    message: e.to_string(),
                }
            })?;
        return read_aspect(
            device,
            queue,
            &decoded,
            &decoded_spec,
            format,
            wgpu::TextureAspect::All,
            only,
        );
    }
    let aspect = if spec.format.has_depth_aspect() {
        wgpu::TextureAspect::DepthOnly
    } else {
        wgpu::TextureAspect::All
    };
    read_aspect(device, queue, texture, spec, format, aspect, only)
}

/// Whether a texture has a stencil aspect besides its depth that [`read_stencil`] can read.
/// A stencil-only texture's stencil is its one aspect, which `read_texture` reads (reading it
/// twice wrote the same file from two threads at once).
pub fn has_stencil(spec: &TextureSpec) -> bool {
    spec.samples == 1 && spec.format.has_stencil_aspect() && spec.format.has_depth_aspect()
}

/// Reads back the stencil aspect of a depth-stencil (or stencil) texture as `Stencil8`
/// integer images; the caller checks [`has_stencil`] first.
pub fn read_stencil(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
) -> Result<Vec<DecodedImage>, ReadError> {
    stencil(device, queue, texture, spec, None)
}

fn stencil(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    only: Option<(u32, u32)>,
) -> Result<Vec<DecodedImage>, ReadError> {
    read_aspect(
        device,
        queue,
        texture,
        spec,
        wgpu::TextureFormat::Stencil8,
        wgpu::TextureAspect::StencilOnly,
        only,
    )
}

/// Reads `aspect` of every subresource, or of the one mip and layer in `only`.
fn read_aspect(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    format: wgpu::TextureFormat,
    aspect: wgpu::TextureAspect,
    only: Option<(u32, u32)>,
) -> Result<Vec<DecodedImage>, ReadError> {
    let texel = format.block_copy_size(Some(aspect)).unwrap_or(4);
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    let layers = if d3 {
        1
    } else {
        spec.size.depth_or_array_layers
    };
    let mut images = Vec::new();
    for mip in 0..spec.mip_levels {
        let w = (spec.size.width >> mip).max(1);
        let h = (spec.size.height >> mip).max(1);
        let depth = if d3 {
            (spec.size.depth_or_array_layers >> mip).max(1)
        } else {
            1
        };
        for layer in 0..layers {
            if only.is_some_and(|(m, l)| m != mip || (!d3 && l != layer)) {
                continue;
            }
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
                .map_err(|e| ReadError {
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
                images.extend(decode_image(format, (mip, layer, z), w, h, &tight));
            }
        }
    }
    Ok(images)
}

/// Bits of channel `c` of a normalised format wider than 8 bits, for its integer code.
fn unorm_bits(f: wgpu::TextureFormat, c: usize) -> Option<u32> {
    use wgpu::TextureFormat as F;
    match f {
        F::Rgb10a2Unorm => Some(if c == 3 { 2 } else { 10 }),
        F::R16Unorm | F::Rg16Unorm | F::Rgba16Unorm => Some(16),
        _ => None,
    }
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
