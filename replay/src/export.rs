//! Export: every subresource of a texture (each mip, array layer, cube face and 3D slice), read
//! back and decoded by `decode`, written as PNG (8-bit colour; 10- and 16-bit normalised colour
//! as 16-bit PNG; integers normalised to their value range) or EXR (float, HDR and depth, with
//! an 8-bit preview), named `<resource>[_mip<M>][_layer<L>][_z<Z>].png|.exr`, with a manifest
//! entry of what each file holds.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::decode::{self, DecodedImage, ValueKind};
use framelab_core::atomic;
use framelab_core::plan::TextureSpec;

#[derive(Debug, Clone, Serialize)]
pub struct ExportedFile {
    pub file: String,
    pub resource: String,
    pub mip: u32,
    pub layer: u32,
    pub z: Option<u32>,
    pub width: u32,
    pub height: u32,
    /// The texture's format as the capture names it (DXGI), given by the caller.
    pub format: String,
    /// The format the values were read back in (wgpu's name; depth-stencil formats read one
    /// aspect).
    pub read_as: String,
    /// png8, png16, png16-normalised (integer formats: min..max of the data mapped to
    /// 0..65535), png8-stencil (the stencil aspect, exact values), exr
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
    /// PNG colour is written opaque, as a texture viewer shows it (G-buffer alpha is often a
    /// tag or unused and made images look empty). Where the alpha channel varies it is
    /// written as its own grey image, named here; where it is constant, its value is here.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_constant: Option<f64>,
    /// The image the frame presented (the last present pass's, when the whole frame ran).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub presented: bool,
}

/// How the caller names a texture's files and its format.
#[derive(Clone, Copy, Debug)]
pub struct Naming<'a> {
    /// The resource's name (for the manifest).
    pub resource: &'a str,
    /// The file-name stem, from [`unique_stems`].
    pub stem: &'a str,
    /// The format as the capture names it.
    pub format: &'a str,
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

/// A resource name as a file-name stem: characters other than ASCII letters, digits, `_`
/// and `-` become `_` (so a stem never holds a `.`).
fn sanitise(resource: &str) -> String {
    resource.replace(
        |c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'),
        "_",
    )
}

/// The `_mip<M>_layer<L>_z<Z>` part of each subresource's file name.
fn suffixes(spec: &TextureSpec) -> Vec<String> {
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    let layers = if d3 {
        1
    } else {
        spec.size.depth_or_array_layers
    };
    let mut out = Vec::new();
    for mip in 0..spec.mip_levels {
        let slices = if d3 {
            (spec.size.depth_or_array_layers >> mip).max(1)
        } else {
            1
        };
        for layer in 0..layers {
            for z in 0..slices {
                out.push(file_name("", spec, mip, layer, d3.then_some(z), ""));
            }
        }
    }
    out
}

/// A file-name stem per texture, unique by construction: two names that sanitise alike
/// (`a.b`, `a_b`), or a name that equals another texture's subresource file (`x_mip1` beside
/// a mipped `x`), or that differ only in case, get `-2`, `-3` ... on the later one, so no
/// export file overwrites another. The manifest lists each file's resource by its real name.
pub fn unique_stems(specs: &[TextureSpec]) -> Vec<String> {
    let mut claimed = std::collections::BTreeSet::new();
    specs
        .iter()
        .map(|spec| {
            let base = sanitise(&spec.name);
            let suffixes = suffixes(spec);
            let mut stem = base.clone();
            for k in 2.. {
                let names: Vec<String> = suffixes
                    .iter()
                    .map(|s| format!("{stem}{s}").to_ascii_lowercase())
                    .collect();
                if names.iter().all(|n| !claimed.contains(n)) {
                    claimed.extend(names);
                    break;
                }
                stem = format!("{base}-{k}");
            }
            stem
        })
        .collect()
}

/// A file name for a subresource of the texture whose files are named `stem`.
pub fn file_name(
    stem: &str,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
    z: Option<u32>,
    ext: &str,
) -> String {
    let mut name = stem.to_owned();
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
    if ext.is_empty() {
        name
    } else {
        format!("{name}.{ext}")
    }
}

/// Why an image could not be encoded into its file.
#[derive(Debug, thiserror::Error)]
enum EncodeImageError {
    #[error(transparent)]
    Png(#[from] image::ImageError),
    #[error(transparent)]
    Exr(#[from] exr::error::Error),
}

fn atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), EncodeImageError>,
) -> Result<(), ExportError> {
    atomic::write_with(path, write).map_err(|e| ExportError::Write {
        path: e.path,
        message: e.message,
    })
}

fn save_png<P: image::Pixel<Subpixel = S> + image::PixelWithColorType, S: image::Primitive>(
    img: &image::ImageBuffer<P, Vec<S>>,
    tmp: &Path,
) -> Result<(), EncodeImageError>
where
    [S]: image::EncodableLayout,
{
    Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
}

/// Writes `image`'s values as a float RGBA EXR at `path` (replacing it only once complete).
pub fn save_exr(path: &Path, image: &DecodedImage) -> Result<(), ExportError> {
    let width = image.width as usize;
    atomically(path, |tmp| {
        exr::prelude::write_rgba_file(tmp, width, image.height as usize, |x, y| {
            let v = image.rgba(y * width + x);
            (v[0], v[1], v[2], v[3])
        })
        .map_err(EncodeImageError::from)
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
    save_exr(path, image)?;
    atomically(&dir.join(&preview_name), |tmp| {
        save_png(&float_preview(image), tmp)
    })?;
    Ok(preview_name)
}

/// The 8-bit preview of a float image: its finite range stretched, colour with a display
/// gamma, depth inverted so that near is bright.
fn float_preview(image: &DecodedImage) -> image::RgbaImage {
    let depth = image.format.has_depth_aspect();
    let (lo, hi) = preview_range(&image.values, image.channels, depth);
    let mut img = image::RgbaImage::new(image.width, image.height);
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
    img
}

/// 8-bit values with opaque alpha, as the export's `png8` files hold them.
fn unorm8_image(image: &DecodedImage) -> image::RgbaImage {
    let mut img = image::RgbaImage::new(image.width, image.height);
    for (i, p) in img.pixels_mut().enumerate() {
        let v = image.rgba(i);
        let mut rgba = v.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        rgba[3] = 255;
        *p = image::Rgba(rgba);
    }
    img
}

/// The 8-bit image an export shows for `image`: the `png8` file itself for 8-bit formats,
/// the preview for float ones, the 16-bit file's values to 8 bits for integer and wide ones.
pub fn display_rgba8(image: &DecodedImage) -> image::RgbaImage {
    match image.kind {
        _ if image.format == wgpu::TextureFormat::Stencil8 => {
            image::RgbaImage::from_fn(image.width, image.height, |x, y| {
                let s = image.values[(y * image.width + x) as usize][0] as u8;
                image::Rgba([s, s, s, 255])
            })
        }
        ValueKind::Float => float_preview(image),
        ValueKind::Unorm8 => unorm8_image(image),
        ValueKind::Integer | ValueKind::UnormWide => {
            let (min, max) = image.range();
            let (lo, span) = if image.kind == ValueKind::Integer {
                (min, (max - min).max(1.0))
            } else {
                (0.0, 1.0)
            };
            let mut img = image::RgbaImage::new(image.width, image.height);
            for (i, p) in img.pixels_mut().enumerate() {
                let v = image.rgba(i);
                let n = |c: f32| (((c - lo) / span).clamp(0.0, 1.0) * 255.0).round() as u8;
                *p = image::Rgba([n(v[0]), n(v[1]), n(v[2]), 255]);
            }
            img
        }
    }
}

/// Writes a decoded subresource into `dir` and describes the file.
pub fn write_image(
    dir: &Path,
    naming: Naming<'_>,
    spec: &TextureSpec,
    image: &DecodedImage,
) -> Result<ExportedFile, ExportError> {
    let (width, height, channels) = (image.width, image.height, image.channels);
    let (min, max) = image.range();
    let integer = image.kind == ValueKind::Integer;
    let stencil = image.format == wgpu::TextureFormat::Stencil8;
    let (ext, encoding) = match image.kind {
        _ if stencil => ("stencil.png", "png8-stencil"),
        ValueKind::Float => ("exr", "exr"),
        ValueKind::Integer => ("png", "png16-normalised"),
        ValueKind::Unorm8 => ("png", "png8"),
        ValueKind::UnormWide => ("png", "png16"),
    };
    let (mip, layer, z) = (image.mip, image.layer, image.z);
    let name = file_name(naming.stem, spec, mip, layer, z, ext);
    let path = dir.join(&name);
    let mut preview = None;
    // Colour formats with a data-carrying alpha: a constant is recorded, a varying one gets
    // its own image.
    let has_alpha = channels == 4 && matches!(image.kind, ValueKind::Unorm8 | ValueKind::UnormWide);
    let alpha_range = has_alpha.then(|| {
        image
            .values
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v[3]), hi.max(v[3]))
            })
    });
    let alpha_constant = alpha_range
        .filter(|(lo, hi)| lo == hi)
        .map(|(lo, _)| f64::from(lo));
    let mut alpha = None;
    match image.kind {
        _ if stencil => atomically(&path, |tmp| {
            let img = image::GrayImage::from_fn(width, height, |x, y| {
                image::Luma([image.values[(y * width + x) as usize][0] as u8])
            });
            save_png(&img, tmp)
        })?,
        ValueKind::Float => {
            let preview_name = file_name(naming.stem, spec, mip, layer, z, "preview.png");
            preview = Some(write_exr(dir, &path, image, preview_name)?);
        }
        ValueKind::Unorm8 => atomically(&path, |tmp| save_png(&unorm8_image(image), tmp))?,
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
                *p = image::Rgba([n(v[0]), n(v[1]), n(v[2]), 65535]);
            }
            save_png(&img, tmp)
        })?,
    }
    if alpha_range.is_some() && alpha_constant.is_none() {
        let alpha_name = file_name(naming.stem, spec, mip, layer, z, "alpha.png");
        let wide = image.kind == ValueKind::UnormWide;
        atomically(&dir.join(&alpha_name), |tmp| {
            let a = |x: u32, y: u32| image.values[(y * width + x) as usize][3].clamp(0.0, 1.0);
            if wide {
                let img: image::ImageBuffer<image::Luma<u16>, Vec<u16>> =
                    image::ImageBuffer::from_fn(width, height, |x, y| {
                        image::Luma([(a(x, y) * 65535.0).round() as u16])
                    });
                save_png(&img, tmp)
            } else {
                let img = image::GrayImage::from_fn(width, height, |x, y| {
                    image::Luma([(a(x, y) * 255.0).round() as u8])
                });
                save_png(&img, tmp)
            }
        })?;
        alpha = Some(alpha_name);
    }
    Ok(ExportedFile {
        file: name,
        resource: naming.resource.to_owned(),
        mip,
        layer,
        z,
        width,
        height,
        format: naming.format.to_owned(),
        read_as: format!("{:?}", image.format),
        encoding,
        min: f64::from(min),
        max: f64::from(max),
        preview,
        uniform: image.uniform(),
        alpha,
        alpha_constant,
        presented: false,
    })
}

/// Decoded bytes (16 per texel) allowed to wait for the encoders before the reading thread
/// pauses: bounds memory when readback outruns PNG/EXR encoding.
pub const MAX_IN_FLIGHT_BYTES: u64 = 512 << 20;

/// One texture to export.
#[derive(Debug)]
pub struct ExportItem<'a> {
    pub texture: &'a wgpu::Texture,
    pub spec: &'a TextureSpec,
    pub naming: Naming<'a>,
}

/// Exports every item into `dir`: this thread reads textures back from the GPU one after
/// another while rayon's pool encodes and writes the images already read (PNG and EXR
/// encoding dominate an export), with at most [`MAX_IN_FLIGHT_BYTES`] waiting. Files and
/// skipped textures come back in item order, so the manifest is deterministic.
pub fn export_all(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    items: &[ExportItem<'_>],
    dir: &Path,
) -> Result<(Vec<ExportedFile>, Vec<Skipped>), ExportError> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicU64, Ordering};
    let in_flight = AtomicU64::new(0);
    type Written = (usize, usize, Result<ExportedFile, ExportError>);
    let written: Mutex<Vec<Written>> = Mutex::new(Vec::new());
    let mut skipped = Vec::new();
    let read_result = rayon::in_place_scope(|scope| -> Result<(), ExportError> {
        for (i, item) in items.iter().enumerate() {
            let images = match read_for_export(device, queue, item)? {
                Ok(images) => images,
                Err(s) => {
                    skipped.push(s);
                    continue;
                }
            };
            for (j, image) in images.into_iter().enumerate() {
                let bytes = image.values.len() as u64 * 16;
                while in_flight.load(Ordering::Acquire) > MAX_IN_FLIGHT_BYTES {
                    std::thread::sleep(std::time::Duration::from_millis(1));
                }
                in_flight.fetch_add(bytes, Ordering::AcqRel);
                let (in_flight, written) = (&in_flight, &written);
                scope.spawn(move |_| {
                    let result = write_image(dir, item.naming, item.spec, &image);
                    drop(image);
                    in_flight.fetch_sub(bytes, Ordering::AcqRel);
                    if let Ok(mut w) = written.lock() {
                        w.push((i, j, result));
                    }
                });
            }
        }
        Ok(())
    });
    read_result?;
    let mut written = written.into_inner().unwrap_or_default();
    written.sort_by_key(|(i, j, _)| (*i, *j));
    let files = written
        .into_iter()
        .map(|(_, _, r)| r)
        .collect::<Result<Vec<_>, _>>()?;
    Ok((files, skipped))
}

/// The decoded images of one export item (the stencil aspect too), or why it is skipped.
fn read_for_export(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    item: &ExportItem<'_>,
) -> Result<Result<Vec<DecodedImage>, Skipped>, ExportError> {
    let spec = item.spec;
    let format = match decode::readable_format(spec) {
        Ok(f) => f,
        Err(decode::Unreadable(reason)) => {
            return Ok(Err(Skipped {
                resource: item.naming.resource.to_owned(),
                reason: reason.to_owned(),
            }));
        }
    };
    let readback = |e: decode::ReadError| ExportError::Readback {
        resource: e.resource,
        message: e.message,
    };
    let mut images =
        decode::read_texture(device, queue, item.texture, spec, format).map_err(readback)?;
    if decode::has_stencil(spec) {
        images.extend(decode::read_stencil(device, queue, item.texture, spec).map_err(readback)?);
    }
    Ok(Ok(images))
}

/// Reads back every subresource of `texture` (and the stencil aspect of a depth-stencil
/// texture) and writes it into `dir`, on this thread.
pub fn export_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    spec: &TextureSpec,
    dir: &Path,
    naming: Naming<'_>,
) -> Result<(Vec<ExportedFile>, Option<Skipped>), ExportError> {
    let item = ExportItem {
        texture,
        spec,
        naming,
    };
    match read_for_export(device, queue, &item)? {
        Err(skipped) => Ok((Vec::new(), Some(skipped))),
        Ok(images) => {
            let files = images
                .iter()
                .map(|image| write_image(dir, naming, spec, image))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((files, None))
        }
    }
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

    fn spec(name: &str, mips: u32, layers: u32) -> TextureSpec {
        TextureSpec {
            name: name.to_owned(),
            format: wgpu::TextureFormat::Rgba8Unorm,
            dimension: wgpu::TextureDimension::D2,
            size: wgpu::Extent3d {
                width: 2,
                height: 1,
                depth_or_array_layers: layers,
            },
            mip_levels: mips,
            samples: 1,
            usage: wgpu::TextureUsages::empty(),
            view_formats: Vec::new(),
            initial: None,
            history: false,
            cube: false,
        }
    }

    #[test]
    fn stems_are_unique_by_construction() {
        let specs = [
            spec("a.b", 1, 1),
            spec("a_b", 1, 1),
            spec("x", 2, 1),
            spec("x_mip1", 1, 1),
            spec("X_MIP0", 1, 1),
            spec("a-b-2", 1, 1),
            spec("a_b", 1, 1),
        ];
        let stems = unique_stems(&specs);
        assert_eq!(
            stems,
            [
                "a_b", "a_b-2", "x", "x_mip1-2", "X_MIP0-2", "a-b-2", "a_b-3"
            ]
        );
        let mut files: Vec<String> = specs
            .iter()
            .zip(&stems)
            .flat_map(|(s, stem)| suffixes(s).into_iter().map(move |x| format!("{stem}{x}")))
            .map(|f| f.to_ascii_lowercase())
            .collect();
        let n = files.len();
        files.sort();
        files.dedup();
        assert_eq!(files.len(), n, "two subresources share a file name");
    }

    fn image(alpha: [f32; 2]) -> DecodedImage {
        DecodedImage {
            mip: 0,
            layer: 0,
            z: None,
            width: 2,
            height: 1,
            format: wgpu::TextureFormat::Rgba8Unorm,
            channels: 4,
            kind: ValueKind::Unorm8,
            values: vec![[1.0, 0.5, 0.0, alpha[0]], [0.0, 0.5, 1.0, alpha[1]]],
        }
    }

    #[test]
    fn colour_is_opaque_and_a_varying_alpha_gets_its_own_image() {
        let dir = std::env::temp_dir().join(format!("framelab-alpha-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let s = spec("t", 1, 1);
        let naming = Naming {
            resource: "t",
            stem: "t",
            format: "R8G8B8A8_UNORM",
        };
        // A tag alpha of 0 (a G-buffer's): the PNG is opaque, the constant recorded.
        let f = write_image(&dir, naming, &s, &image([0.0, 0.0])).unwrap();
        assert_eq!((f.alpha.as_deref(), f.alpha_constant), (None, Some(0.0)));
        assert_eq!(f.format, "R8G8B8A8_UNORM");
        let png = image::open(dir.join("t.png")).unwrap().to_rgba8();
        assert_eq!(png.get_pixel(0, 0).0, [255, 128, 0, 255]);
        // A varying alpha: written beside it as grey.
        let f = write_image(&dir, naming, &s, &image([0.25, 1.0])).unwrap();
        assert_eq!(f.alpha.as_deref(), Some("t.alpha.png"));
        let a = image::open(dir.join("t.alpha.png")).unwrap().to_luma8();
        assert_eq!((a.get_pixel(0, 0).0, a.get_pixel(1, 0).0), ([64], [255]));
        std::fs::remove_dir_all(dir).unwrap();
    }
}
