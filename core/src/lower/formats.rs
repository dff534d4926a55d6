//! DXGI to wgpu format lowering. The only place framelab maps formats to wgpu.
//!
//! Rules, in order:
//! - **Direct**: formats with a wgpu twin map to it (R8G8B8A8_UNORM -> Rgba8Unorm, R11G11B10_FLOAT
//!   -> Rg11b10Ufloat, BC7_UNORM_SRGB -> Bc7RgbaUnormSrgb, ...).
//! - **By usage**: typeless families become their depth format when the resource is a depth
//!   target (R16_TYPELESS -> Depth16Unorm, R32_TYPELESS -> Depth32Float, R24G8_TYPELESS ->
//!   Depth24PlusStencil8, R32G8X24_TYPELESS -> Depth32FloatStencil8, falling back to
//!   Depth24PlusStencil8 without that feature), otherwise the format of their first typed view.
//!   Views of a depth format read its depth aspect (R16_UNORM on a D16 target samples the depth).
//! - **Held otherwise** (`Repack`): channels in an order wgpu lacks, exchanged in the contents;
//!   16-bit packed formats as RGBA8, unpacked (`packed16`); three-channel formats as their
//!   four-channel twin with alpha one.
//! - **Unsupported**, with the reason `capture::formats` gives (validation gives the same): A8, R1, shared-
//!   exponent and XR-bias variants wgpu lacks, video and palette formats.

use wgpu_types::{Features, TextureFormat};

pub use super::repack::Repack;
use crate::capture::dxgi::FormatInfo;
use crate::capture::formats::NoWebGpuFormat;

/// What a DXGI format becomes on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lowered {
    pub format: TextureFormat,
    /// Optional device features the format needs.
    pub features: Features,
    /// A stated approximation (e.g. the depth fallback), for the replay log.
    pub note: Option<&'static str>,
    /// How the texture's bytes are rearranged from the capture's, where they are.
    pub repack: Option<Repack>,
}

fn direct(name: &str) -> Option<TextureFormat> {
    use TextureFormat as F;
    Some(match name {
        "R8_UNORM" => F::R8Unorm,
        "R8_SNORM" => F::R8Snorm,
        "R8_UINT" => F::R8Uint,
        "R8_SINT" => F::R8Sint,
        "R8G8_UNORM" => F::Rg8Unorm,
        "R8G8_SNORM" => F::Rg8Snorm,
        "R8G8_UINT" => F::Rg8Uint,
        "R8G8_SINT" => F::Rg8Sint,
        "R16_UNORM" => F::R16Unorm,
        "R16_SNORM" => F::R16Snorm,
        "R16_UINT" => F::R16Uint,
        "R16_SINT" => F::R16Sint,
        "R16_FLOAT" => F::R16Float,
        "D16_UNORM" => F::Depth16Unorm,
        "R8G8B8A8_UNORM" => F::Rgba8Unorm,
        "R8G8B8A8_UNORM_SRGB" => F::Rgba8UnormSrgb,
        "R8G8B8A8_SNORM" => F::Rgba8Snorm,
        "R8G8B8A8_UINT" => F::Rgba8Uint,
        "R8G8B8A8_SINT" => F::Rgba8Sint,
        "B8G8R8A8_UNORM" => F::Bgra8Unorm,
        "B8G8R8A8_UNORM_SRGB" => F::Bgra8UnormSrgb,
        "R10G10B10A2_UNORM" => F::Rgb10a2Unorm,
        "R10G10B10A2_UINT" => F::Rgb10a2Uint,
        "R11G11B10_FLOAT" => F::Rg11b10Ufloat,
        "R9G9B9E5_SHAREDEXP" => F::Rgb9e5Ufloat,
        "R16G16_UNORM" => F::Rg16Unorm,
        "R16G16_SNORM" => F::Rg16Snorm,
        "R16G16_UINT" => F::Rg16Uint,
        "R16G16_SINT" => F::Rg16Sint,
        "R16G16_FLOAT" => F::Rg16Float,
        "R32_UINT" => F::R32Uint,
        "R32_SINT" => F::R32Sint,
        "R32_FLOAT" => F::R32Float,
        "D32_FLOAT" => F::Depth32Float,
        "D24_UNORM_S8_UINT" => F::Depth24PlusStencil8,
        "D32_FLOAT_S8X24_UINT" => F::Depth32FloatStencil8,
        // Packed 32-bit words with A in the high byte: the same bytes as RGBA8, in order.
        "VK_FORMAT_A8B8G8R8_UNORM_PACK32" => F::Rgba8Unorm,
        "VK_FORMAT_A8B8G8R8_SRGB_PACK32" => F::Rgba8UnormSrgb,
        "VK_FORMAT_A8B8G8R8_SNORM_PACK32" => F::Rgba8Snorm,
        "VK_FORMAT_A8B8G8R8_UINT_PACK32" => F::Rgba8Uint,
        "VK_FORMAT_A8B8G8R8_SINT_PACK32" => F::Rgba8Sint,
        // 16-bit packed formats held as RGBA8 (`repack`, `packed16`).
        "B5G6R5_UNORM"
        | "B5G5R5A1_UNORM"
        | "B4G4R4A4_UNORM"
        | "A4B4G4R4_UNORM"
        | "VK_FORMAT_R5G6B5_UNORM_PACK16"
        | "VK_FORMAT_B5G6R5_UNORM_PACK16"
        | "VK_FORMAT_R4G4B4A4_UNORM_PACK16"
        | "VK_FORMAT_B4G4R4A4_UNORM_PACK16"
        | "VK_FORMAT_A4R4G4B4_UNORM_PACK16"
        | "VK_FORMAT_A4B4G4R4_UNORM_PACK16"
        | "VK_FORMAT_R5G5B5A1_UNORM_PACK16"
        | "VK_FORMAT_B5G5R5A1_UNORM_PACK16"
        | "VK_FORMAT_A1R5G5B5_UNORM_PACK16"
        | "VK_FORMAT_A1B5G5R5_UNORM_PACK16"
        | "VK_FORMAT_A1B5G5R5_UNORM_PACK16_KHR" => F::Rgba8Unorm,
        // Formats held with red and blue exchanged (`repack`).
        "VK_FORMAT_A2R10G10B10_UNORM_PACK32" => F::Rgb10a2Unorm,
        "VK_FORMAT_A2R10G10B10_UINT_PACK32" => F::Rgb10a2Uint,
        "VK_FORMAT_B8G8R8A8_SNORM" => F::Rgba8Snorm,
        "VK_FORMAT_B8G8R8A8_UINT" => F::Rgba8Uint,
        "VK_FORMAT_B8G8R8A8_SINT" => F::Rgba8Sint,
        // Depth24Plus is WebGPU's "24 bits of depth or more, no stencil".
        "VK_FORMAT_X8_D24_UNORM_PACK32" => F::Depth24Plus,
        "VK_FORMAT_S8_UINT" => F::Stencil8,
        "R16G16B16A16_UNORM" => F::Rgba16Unorm,
        "R16G16B16A16_SNORM" => F::Rgba16Snorm,
        "R16G16B16A16_UINT" => F::Rgba16Uint,
        "R16G16B16A16_SINT" => F::Rgba16Sint,
        "R16G16B16A16_FLOAT" => F::Rgba16Float,
        "R32G32_UINT" => F::Rg32Uint,
        "R32G32_SINT" => F::Rg32Sint,
        "R32G32_FLOAT" => F::Rg32Float,
        "R32G32B32A32_UINT" => F::Rgba32Uint,
        "R32G32B32A32_SINT" => F::Rgba32Sint,
        "R32G32B32A32_FLOAT" => F::Rgba32Float,
        // Three-channel formats held with a fourth channel of one (`Repack::Widen3`).
        "R32G32B32_FLOAT" => F::Rgba32Float,
        "R32G32B32_UINT" => F::Rgba32Uint,
        "R32G32B32_SINT" => F::Rgba32Sint,
        "VK_FORMAT_R8G8B8_UNORM" | "VK_FORMAT_B8G8R8_UNORM" => F::Rgba8Unorm,
        "VK_FORMAT_R8G8B8_SRGB" | "VK_FORMAT_B8G8R8_SRGB" => F::Rgba8UnormSrgb,
        "VK_FORMAT_R8G8B8_SNORM" | "VK_FORMAT_B8G8R8_SNORM" => F::Rgba8Snorm,
        "VK_FORMAT_R8G8B8_UINT" | "VK_FORMAT_B8G8R8_UINT" => F::Rgba8Uint,
        "VK_FORMAT_R8G8B8_SINT" | "VK_FORMAT_B8G8R8_SINT" => F::Rgba8Sint,
        "VK_FORMAT_R16G16B16_UNORM" => F::Rgba16Unorm,
        "VK_FORMAT_R16G16B16_SNORM" => F::Rgba16Snorm,
        "VK_FORMAT_R16G16B16_UINT" => F::Rgba16Uint,
        "VK_FORMAT_R16G16B16_SINT" => F::Rgba16Sint,
        "VK_FORMAT_R16G16B16_SFLOAT" => F::Rgba16Float,
        "BC1_UNORM" => F::Bc1RgbaUnorm,
        "BC1_UNORM_SRGB" => F::Bc1RgbaUnormSrgb,
        // The same blocks as BC1 with alpha: its three-colour blocks' fourth entry decodes to
        // black with alpha 0 there and 1 here, so a sampled view of it reads alpha as one
        // (`lower::vulkan::bindings`, `opaque_bc1`).
        "VK_FORMAT_BC1_RGB_UNORM_BLOCK" => F::Bc1RgbaUnorm,
        "VK_FORMAT_BC1_RGB_SRGB_BLOCK" => F::Bc1RgbaUnormSrgb,
        "BC2_UNORM" => F::Bc2RgbaUnorm,
        "BC2_UNORM_SRGB" => F::Bc2RgbaUnormSrgb,
        "BC3_UNORM" => F::Bc3RgbaUnorm,
        "BC3_UNORM_SRGB" => F::Bc3RgbaUnormSrgb,
        "BC4_UNORM" => F::Bc4RUnorm,
        "BC4_SNORM" => F::Bc4RSnorm,
        "BC5_UNORM" => F::Bc5RgUnorm,
        "BC5_SNORM" => F::Bc5RgSnorm,
        "BC6H_UF16" => F::Bc6hRgbUfloat,
        "BC6H_SF16" => F::Bc6hRgbFloat,
        "BC7_UNORM" => F::Bc7RgbaUnorm,
        "BC7_UNORM_SRGB" => F::Bc7RgbaUnormSrgb,
        _ => return None,
    })
}

/// Whether `VK_FORMAT_*` `name` is BC1 without alpha, held as BC1 with alpha: every texel
/// it decodes has alpha one, which a sampled view of it reads whatever the blocks say.
pub fn opaque_bc1(name: &str) -> bool {
    matches!(
        name,
        "VK_FORMAT_BC1_RGB_UNORM_BLOCK" | "VK_FORMAT_BC1_RGB_SRGB_BLOCK"
    )
}

/// Why a resource's format cannot be lowered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FormatError {
    #[error("a typeless resource needs a typed view or a depth binding to choose its format")]
    NoTypedView { format: &'static str },
    #[error("{reason}")]
    NoWebGpuFormat {
        format: &'static str,
        reason: NoWebGpuFormat,
    },
}

/// The wgpu twin of the DXGI format `name`, or why WebGPU has none.
pub fn twin(name: &'static str) -> Result<TextureFormat, FormatError> {
    direct(name).ok_or_else(|| FormatError::NoWebGpuFormat {
        format: name,
        reason: NoWebGpuFormat::of(name),
    })
}

/// The features a wgpu format needs beyond WebGPU's baseline.
pub fn features_of(format: TextureFormat) -> Features {
    use TextureFormat as F;
    match format {
        F::R16Unorm
        | F::R16Snorm
        | F::Rg16Unorm
        | F::Rg16Snorm
        | F::Rgba16Unorm
        | F::Rgba16Snorm => Features::TEXTURE_FORMAT_16BIT_NORM,
        F::Depth32FloatStencil8 => Features::DEPTH32FLOAT_STENCIL8,
        f if f.is_compressed() => Features::TEXTURE_COMPRESSION_BC,
        _ => Features::empty(),
    }
}

/// Lowers a resource's format. `depth_target`: the resource is bound as depth-stencil.
/// `first_view`: the first typed view format a pass uses, for typeless colour resources.
/// `available`: the adapter's features, for stated fallbacks.
pub fn lower(
    info: &FormatInfo,
    depth_target: bool,
    first_view: Option<&FormatInfo>,
    available: Features,
) -> Result<Lowered, FormatError> {
    let name = match (info.name, depth_target) {
        ("R16_TYPELESS", true) => "D16_UNORM",
        ("R32_TYPELESS", true) => "D32_FLOAT",
        ("R24G8_TYPELESS", true) => "D24_UNORM_S8_UINT",
        ("R32G8X24_TYPELESS", true) => "D32_FLOAT_S8X24_UINT",
        (n, _) if n.ends_with("_TYPELESS") => match first_view {
            Some(v) => v.name,
            None => return Err(FormatError::NoTypedView { format: info.name }),
        },
        (n, _) => n,
    };
    let format = twin(name)?;
    if format == TextureFormat::Depth32FloatStencil8
        && !available.contains(Features::DEPTH32FLOAT_STENCIL8)
    {
        return Ok(Lowered {
            format: TextureFormat::Depth24PlusStencil8,
            features: Features::empty(),
            note: Some(
                "Depth32FloatStencil8 unavailable: using Depth24PlusStencil8 (less depth precision)",
            ),
            repack: None,
        });
    }
    Ok(Lowered {
        format,
        features: features_of(format),
        note: None,
        repack: Repack::of(name),
    })
}

/// The format a view uses: depth formats are viewed through their depth aspect, whatever
/// typed name the capture gave the view (R16_UNORM on D16 reads the depth).
pub fn view_format(
    resource: TextureFormat,
    view: Option<&FormatInfo>,
) -> Result<TextureFormat, FormatError> {
    if resource.has_depth_aspect() {
        return Ok(resource);
    }
    match view {
        None => Ok(resource),
        Some(v) => {
            let f = twin(v.name)?;
            // wgpu reinterprets only between sRGB and linear twins; anything else would need a
            // copy, so the resource's own format is used when the bits agree.
            if f == resource || f.remove_srgb_suffix() == resource.remove_srgb_suffix() {
                Ok(f)
            } else {
                Ok(resource)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::dxgi::lookup;

    #[test]
    fn usage_decides_typeless_formats() {
        let all = Features::all();
        let r16 = lookup("R16_TYPELESS").unwrap();
        assert_eq!(
            lower(r16, true, None, all).unwrap().format,
            TextureFormat::Depth16Unorm
        );
        assert_eq!(
            lower(r16, false, lookup("R16_UNORM"), all).unwrap().format,
            TextureFormat::R16Unorm
        );
        let d32s8 = lookup("R32G8X24_TYPELESS").unwrap();
        assert_eq!(
            lower(d32s8, true, None, all).unwrap().format,
            TextureFormat::Depth32FloatStencil8
        );
        let fallback = lower(d32s8, true, None, Features::empty()).unwrap();
        assert_eq!(fallback.format, TextureFormat::Depth24PlusStencil8);
        assert!(fallback.note.is_some());
    }

    #[test]
    fn every_dxgi_format_lowers_or_says_why() {
        for f in crate::capture::dxgi::all()
            .iter()
            .filter(|f| f.name != "UNKNOWN")
        {
            match lower(f, f.is_depth_format(), None, Features::all()) {
                Ok(l) => assert!(
                    l.format.block_copy_size(None).is_some() || l.format.has_depth_aspect(),
                    "{}",
                    f.name
                ),
                Err(reason) => assert!(!reason.to_string().is_empty()),
            }
        }
        assert_eq!(
            lower(
                lookup("R11G11B10_FLOAT").unwrap(),
                false,
                None,
                Features::all()
            )
            .unwrap()
            .format,
            TextureFormat::Rg11b10Ufloat
        );
        let rgb96 = lower(
            lookup("R32G32B32_FLOAT").unwrap(),
            false,
            None,
            Features::all(),
        )
        .unwrap();
        assert_eq!(rgb96.format, TextureFormat::Rgba32Float);
        assert!(
            lower(
                lookup("VK_FORMAT_R64_SFLOAT").unwrap(),
                false,
                None,
                Features::all()
            )
            .is_err()
        );
    }

    #[test]
    fn three_channel_texels_gain_an_alpha_of_one_in_their_numbers() {
        let widen = |name: &str, bytes: &[u8]| {
            let mut v = bytes.to_vec();
            Repack::of(name).unwrap().apply(&mut v);
            v
        };
        assert_eq!(
            widen("VK_FORMAT_R8G8B8_UNORM", &[1, 2, 3, 4, 5, 6]),
            [1, 2, 3, 255, 4, 5, 6, 255]
        );
        assert_eq!(widen("VK_FORMAT_B8G8R8_SNORM", &[1, 2, 3]), [3, 2, 1, 0x7f]);
        assert_eq!(widen("VK_FORMAT_R8G8B8_UINT", &[1, 2, 3]), [1, 2, 3, 1]);
        assert_eq!(
            widen("VK_FORMAT_R16G16B16_SFLOAT", &[0, 1, 2, 3, 4, 5]),
            [0, 1, 2, 3, 4, 5, 0x00, 0x3c]
        );
        let one = 1.0f32.to_le_bytes();
        let rgb = widen("R32G32B32_FLOAT", &[0u8; 12]);
        assert_eq!((&rgb[..12], &rgb[12..]), (&[0u8; 12][..], &one[..]));
        // Every three-channel format the lowering takes is held so.
        for f in crate::capture::dxgi::all() {
            let three = f.channels.len() == 3 && f.bits_per_element % 3 == 0;
            if three && direct(f.name).is_some() {
                assert!(
                    matches!(Repack::of(f.name), Some(Repack::Widen3 { .. })),
                    "{}",
                    f.name
                );
            }
        }
    }

    #[test]
    fn the_capture_side_knows_which_formats_have_a_twin() {
        for f in crate::capture::dxgi::all() {
            assert_eq!(
                direct(f.name).is_some(),
                crate::capture::formats::webgpu_gap(f.name).is_none(),
                "{}",
                f.name
            );
        }
    }
}
