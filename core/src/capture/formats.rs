//! What WebGPU can do with a DXGI format, decided from the format alone. Validation refuses
//! what the replay could never do (a colour attachment WebGPU cannot render to), and it must
//! know that without asking the lowering; the lowering in turn takes its reasons from here, so
//! both stages say the same thing about the same format.

use super::dxgi::{FormatInfo, Numeric};

/// The DXGI formats WebGPU has a texture format with the same bits and meaning for. The
/// lowering's mapping covers exactly these (a test there keeps the two in step).
const WEBGPU_TWINS: &[&str] = &[
    "R8_UNORM",
    "R8_SNORM",
    "R8_UINT",
    "R8_SINT",
    "R8G8_UNORM",
    "R8G8_SNORM",
    "R8G8_UINT",
    "R8G8_SINT",
    "R16_UNORM",
    "R16_SNORM",
    "R16_UINT",
    "R16_SINT",
    "R16_FLOAT",
    "D16_UNORM",
    "R8G8B8A8_UNORM",
    "R8G8B8A8_UNORM_SRGB",
    "R8G8B8A8_SNORM",
    "R8G8B8A8_UINT",
    "R8G8B8A8_SINT",
    "B8G8R8A8_UNORM",
    "B8G8R8A8_UNORM_SRGB",
    "R10G10B10A2_UNORM",
    "R10G10B10A2_UINT",
    "R11G11B10_FLOAT",
    "R9G9B9E5_SHAREDEXP",
    "R16G16_UNORM",
    "R16G16_SNORM",
    "R16G16_UINT",
    "R16G16_SINT",
    "R16G16_FLOAT",
    "R32_UINT",
    "R32_SINT",
    "R32_FLOAT",
    "D32_FLOAT",
    "D24_UNORM_S8_UINT",
    "D32_FLOAT_S8X24_UINT",
    "VK_FORMAT_X8_D24_UNORM_PACK32",
    "VK_FORMAT_S8_UINT",
    "R16G16B16A16_UNORM",
    "R16G16B16A16_SNORM",
    "R16G16B16A16_UINT",
    "R16G16B16A16_SINT",
    "R16G16B16A16_FLOAT",
    "R32G32_UINT",
    "R32G32_SINT",
    "R32G32_FLOAT",
    "R32G32B32A32_UINT",
    "R32G32B32A32_SINT",
    "R32G32B32A32_FLOAT",
    "BC1_UNORM",
    "BC1_UNORM_SRGB",
    "BC2_UNORM",
    "BC2_UNORM_SRGB",
    "BC3_UNORM",
    "BC3_UNORM_SRGB",
    "BC4_UNORM",
    "BC4_SNORM",
    "BC5_UNORM",
    "BC5_SNORM",
    "BC6H_UF16",
    "BC6H_SF16",
    "BC7_UNORM",
    "BC7_UNORM_SRGB",
];

/// Why WebGPU has no texture format for a DXGI format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NoWebGpuFormat {
    #[error("96-bit RGB textures do not exist in WebGPU")]
    Rgb96,
    #[error("16-bit packed BGR formats do not exist in WebGPU")]
    PackedBgr16,
    #[error("alpha-only A8 does not exist in WebGPU")]
    AlphaOnly,
    #[error("1-bit formats do not exist in WebGPU")]
    OneBit,
    #[error("X-channel formats do not exist in WebGPU (use B8G8R8A8)")]
    XChannel,
    #[error("the XR-bias format does not exist in WebGPU")]
    XrBias,
    #[error("packed 4:2:2 formats are not renderable in WebGPU")]
    Packed422,
    #[error("video, palette and opaque formats are not textures framelab can replay")]
    VideoPaletteOrOpaque,
    /// A VkFormat with no DXGI twin and no WebGPU format of the same bits.
    #[error(
        "this Vulkan format has no WebGPU twin of the same bits (24- and 48-bit RGB, 64-bit channels, D16 with stencil, ETC2, EAC and ASTC are not replayed)"
    )]
    VulkanOnly,
}

impl NoWebGpuFormat {
    /// The reason WebGPU lacks the format `name`, judged by its family; for a name the
    /// families below do not cover, the catch-all for video, palette and opaque formats.
    pub fn of(name: &str) -> NoWebGpuFormat {
        match name {
            n if n.starts_with("R32G32B32_") => NoWebGpuFormat::Rgb96,
            "B5G6R5_UNORM" | "B5G5R5A1_UNORM" | "B4G4R4A4_UNORM" | "A4B4G4R4_UNORM" => {
                NoWebGpuFormat::PackedBgr16
            }
            "A8_UNORM" => NoWebGpuFormat::AlphaOnly,
            "R1_UNORM" => NoWebGpuFormat::OneBit,
            "B8G8R8X8_UNORM" | "B8G8R8X8_UNORM_SRGB" | "B8G8R8X8_TYPELESS" => {
                NoWebGpuFormat::XChannel
            }
            "R10G10B10_XR_BIAS_A2_UNORM" => NoWebGpuFormat::XrBias,
            n if n.starts_with("VK_FORMAT_") => NoWebGpuFormat::VulkanOnly,
            "R8G8_B8G8_UNORM" | "G8R8_G8B8_UNORM" => NoWebGpuFormat::Packed422,
            _ => NoWebGpuFormat::VideoPaletteOrOpaque,
        }
    }
}

/// Why WebGPU has no texture format for the DXGI format `name`, if it has none.
pub fn webgpu_gap(name: &str) -> Option<NoWebGpuFormat> {
    (!WEBGPU_TWINS.contains(&name)).then(|| NoWebGpuFormat::of(name))
}

/// Why a colour format cannot be rendered to on any GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NotRenderable {
    #[error(transparent)]
    NoWebGpuFormat(#[from] NoWebGpuFormat),
    #[error("shared-exponent formats cannot be rendered to")]
    SharedExponent,
}

/// Why a colour format cannot be rendered to on any GPU, if it cannot: WebGPU has no such
/// format, or it is shared-exponent (never a render target). Formats whose render support
/// varies by adapter (16-bit normalised) pass here and are checked against the device at
/// replay, which validation cannot see.
pub fn not_renderable(info: &FormatInfo) -> Option<NotRenderable> {
    if let Some(gap) = webgpu_gap(info.name) {
        return Some(NotRenderable::NoWebGpuFormat(gap));
    }
    (info.numeric() == Some(Numeric::SharedExp)).then_some(NotRenderable::SharedExponent)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::dxgi::{all, lookup};

    #[test]
    fn vulkan_only_formats_say_so() {
        assert_eq!(
            webgpu_gap("VK_FORMAT_D16_UNORM_S8_UINT"),
            Some(NoWebGpuFormat::VulkanOnly)
        );
        assert_eq!(webgpu_gap("VK_FORMAT_X8_D24_UNORM_PACK32"), None);
    }

    #[test]
    fn every_twin_is_a_dxgi_format() {
        for name in WEBGPU_TWINS {
            assert!(lookup(name).is_some(), "{name}");
        }
    }

    #[test]
    fn renderability_follows_the_format() {
        let not = |name| lookup(name).and_then(not_renderable);
        assert_eq!(not("R8G8B8A8_UNORM"), None);
        assert_eq!(not("R16G16B16A16_UNORM"), None);
        assert_eq!(
            not("R9G9B9E5_SHAREDEXP"),
            Some(NotRenderable::SharedExponent)
        );
        assert_eq!(
            not("R32G32B32_FLOAT").map(|n| n.to_string()),
            Some("96-bit RGB textures do not exist in WebGPU".to_owned())
        );
        let shared: Vec<_> = all()
            .iter()
            .filter(|f| f.numeric() == Some(Numeric::SharedExp))
            .map(|f| f.name)
            .collect();
        assert_eq!(shared, ["R9G9B9E5_SHAREDEXP"]);
    }
}
