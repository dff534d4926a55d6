//! Export: every subresource of a texture (each mip, array layer, cube face and 3D slice), read
//! back and decoded by `decode`, written as PNG (8-bit colour; 10- and 16-bit normalised colour
//! as 16-bit PNG; integers normalised to their value range) or EXR (float, HDR and depth, with
//! an 8-bit preview), named `<resource>[_mip<M>][_layer<L>][_z<Z>].png|.exr`, with a manifest
//! entry of what each file holds.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::atomic;
use crate::decode::{self, DecodedImage, ValueKind};
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

fn atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ExportError> {
    atomic::write_with(path, write).map_err(|e| ExportError::Write {
        path: e.path,
        message: e.message,
    })
}

fn save_png<P: image::Pixel<Subpixel = S> + image::PixelWithColorType, S: image::Primitive>(
    img: &image::ImageBuffer<P, Vec<S>>,
    tmp: &Path,
) -> Result<(), String>
where
    [S]: image::EncodableLayout,
{
    img.save_with_format(tmp, image::ImageFormat::Png)
        .map_err(|e| e.to_string())
}

/// Writes `image`'s values as a float RGBA EXR at `path` (replacing it only once complete).
pub fn save_exr(path: &Path, image: &DecodedImage) -> Result<(), ExportError> {
    let width = image.width as usize;
    atomically(path, |tmp| {
        exr::prelude::write_rgba_file(tmp, width, image.height as usize, |x, y| {
            let v = image.rgba(y * width + x);
            (v[0], v[1], v[2], v[3])
        })
        .map_err(|e| e.to_string())
    })
}

/// Writes an 8-bit RGBA image as PNG at `path` (replacing it only once complete).
pub fn save_rgba8(path: &Path, image: &image::RgbaImage) -> Result<(), ExportError> {
    atomically(path, |tmp| save_png(image, tmp))
}

/// Writes a float image as EXR and an 8-bit preview PNG; returns the preview's name.
fn write_exr(
    dir: &Path,
    path: &Path,
    image: &DecodedImage,
    preview_name: String,
) -> Result<String, ExportError> {
    let (width, height) = (image.width, image.height);
    save_exr(path, image)?;
    let depth = image.format.has_depth_aspect();
    let (lo, hi) = preview_range(&image.values, image.channels, depth);
    atomically(&dir.join(&preview_name), |tmp| {
        let mut img = image::RgbaImage::new(width, height);
        for (i, p) in img.pixels_mut().enumerate() {
            let v = image.rgba(i);
            let map = |c: f32| {
                let t = ((c - lo) / (hi - lo)).clamp(0.0, 1.0);
                // Depth reads better with near bright; colour gets a display gamma.
                let t = if depth { 1.0 - t } else { t.powf(1.0 / 2.2) };
                (t * 255.0).round() as u8
            };
            *p = image::Rgba([map(v[0]), map(v[1]), map(v[2]), 255]);
        }
        save_png(&img, tmp)
    })?;
    Ok(preview_name)
}

/// Writes a decoded subresource into `dir` and describes the file.
pub fn write_image(
    dir: &Path,
    resource: &str,
    spec: &TextureSpec,
    image: &DecodedImage,
) -> Result<ExportedFile, ExportError> {
    let (width, height, channels) = (image.width, image.height, image.channels);
    let (min, max) = image.range();
    let integer = image.kind == ValueKind::Integer;
    let (ext, encoding) = match image.kind {
        ValueKind::Float => ("exr", "exr"),
        ValueKind::Integer => ("png", "png16-normalised"),
        ValueKind::Unorm8 => ("png", "png8"),
        ValueKind::UnormWide => ("png", "png16"),
    };
    let (mip, layer, z) = (image.mip, image.layer, image.z);
    let name = file_name(resource, spec, mip, layer, z, ext);
    let path = dir.join(&name);
    let mut preview = None;
    match image.kind {
        ValueKind::Float => {
            let preview_name = file_name(resource, spec, mip, layer, z, "preview.png");
            preview = Some(write_exr(dir, &path, image, preview_name)?);
        }
        ValueKind::Unorm8 => atomically(&path, |tmp| {
            let mut img = image::RgbaImage::new(width, height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = image.rgba(i);
                *p = image::Rgba(v.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
            }
            save_png(&img, tmp)
        })?,
        ValueKind::Integer | ValueKind::UnormWide => atomically(&path, |tmp| {
            let (lo, span) = if integer {
                (min, (max - min).max(1.0))
            } else {
                (0.0, 1.0)
            };
            let mut img: image::ImageBuffer<image::Rgba<u16>, Vec<u16>> =
                image::ImageBuffer::new(width, height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = image.rgba(i);
                let n = |c: f32| (((c - lo) / span).clamp(0.0, 1.0) * 65535.0).round() as u16;
                let alpha = if channels == 4 && !integer {
                    n(v[3])
                } else {
                    65535
                };
                *p = image::Rgba([n(v[0]), n(v[1]), n(v[2]), alpha]);
            }
            save_png(&img, tmp)
        })?,
    }
    Ok(ExportedFile {
        file: name,
        resource: resource.to_owned(),
        mip,
        layer,
        z,
        width,
        height,
        format: format!("{:?}", image.format),
        encoding,
        min: f64::from(min),
        max: f64::from(max),
        preview,
        uniform: image.uniform(),
    })
}

/// Reads back every subresource of `texture` and writes it into `dir`.
pub fn export_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    dir: &Path,
) -> Result<(Vec<ExportedFile>, Option<Skipped>), ExportError> {
    let format = match decode::readable_format(spec) {
        Ok(f) => f,
        Err(decode::Unreadable(reason)) => {
            return Ok((
                Vec::new(),
                Some(Skipped {
                    resource: spec.name.clone(),
                    reason: reason.to_owned(),
                }),
            ));
        }
    };
    let images = decode::read_texture(device, queue, texture, spec, format).map_err(|e| {
        ExportError::Readback {
            resource: e.resource,
            message: e.message,
        }
    })?;
    let files = images
        .iter()
        .map(|image| write_image(dir, &spec.name, spec, image))
        .collect::<Result<Vec<_>, _>>()?;
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
