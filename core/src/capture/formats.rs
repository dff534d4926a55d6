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
    "VK_FORMAT_BC1_RGB_UNORM_BLOCK",
    "VK_FORMAT_BC1_RGB_SRGB_BLOCK",
    "VK_FORMAT_A8B8G8R8_UNORM_PACK32",
    "VK_FORMAT_A8B8G8R8_SRGB_PACK32",
    "VK_FORMAT_A8B8G8R8_SNORM_PACK32",
    "VK_FORMAT_A8B8G8R8_UINT_PACK32",
    "VK_FORMAT_A8B8G8R8_SINT_PACK32",
    "VK_FORMAT_A2R10G10B10_UNORM_PACK32",
    // 16-bit packed formats, held as RGBA8 (`lower::packed16`); Vulkan's with a DXGI twin
    // go by the DXGI name.
    "B5G6R5_UNORM",
    "B5G5R5A1_UNORM",
    "B4G4R4A4_UNORM",
    "A4B4G4R4_UNORM",
    "VK_FORMAT_B5G6R5_UNORM_PACK16",
    "VK_FORMAT_B4G4R4A4_UNORM_PACK16",
    "VK_FORMAT_A4B4G4R4_UNORM_PACK16",
    "VK_FORMAT_R5G5B5A1_UNORM_PACK16",
    "VK_FORMAT_B5G5R5A1_UNORM_PACK16",
    "VK_FORMAT_A2R10G10B10_UINT_PACK32",
    "VK_FORMAT_B8G8R8A8_SNORM",
    "VK_FORMAT_B8G8R8A8_UINT",
    "VK_FORMAT_B8G8R8A8_SINT",
    "VK_FORMAT_S8_UINT",
    // Three-channel formats, held with a fourth channel of one (`lower::repack::Repack`).
    "R32G32B32_FLOAT",
    "R32G32B32_UINT",
    "R32G32B32_SINT",
    "VK_FORMAT_R8G8B8_UNORM",
    "VK_FORMAT_R8G8B8_SNORM",
    "VK_FORMAT_R8G8B8_UINT",
    "VK_FORMAT_R8G8B8_SINT",
    "VK_FORMAT_R8G8B8_SRGB",
    "VK_FORMAT_B8G8R8_UNORM",
    "VK_FORMAT_B8G8R8_SNORM",
    "VK_FORMAT_B8G8R8_UINT",
    "VK_FORMAT_B8G8R8_SINT",
    "VK_FORMAT_B8G8R8_SRGB",
    "VK_FORMAT_R16G16B16_UNORM",
    "VK_FORMAT_R16G16B16_SNORM",
    "VK_FORMAT_R16G16B16_UINT",
    "VK_FORMAT_R16G16B16_SINT",
    "VK_FORMAT_R16G16B16_SFLOAT",
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

/// Why WebGPU has no texture format for a DXGI or Vulkan format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoWebGpuFormat {
    Rgb96,
    PackedBgr16,
    /// Vulkan's packed 8- and 16-bit formats, in any channel order.
    PackedSmall,
    AlphaOnly,
    OneBit,
    XChannel,
    XrBias,
    Packed422,
    VideoPaletteOrOpaque,
    /// Three channels of 8 or 16 bits (`R8G8B8`, `R16G16B16`).
    Rgb24Or48,
    /// Channels of 64 bits.
    Wide64,
    /// Scaled integers, read as floats (`USCALED`, `SSCALED`).
    Scaled,
    /// Signed 10-bit channels with a 2-bit alpha.
    Signed1010102,
    /// One- and two-channel sRGB.
    NarrowSrgb,
    /// 10- or 12-bit channels padded to 16 (`R10X6`, `R12X4`).
    Padded,
    /// ETC2, EAC and ASTC.
    MobileCompressed,
    Pvrtc,
    DepthWithStencil16,
    /// A Vulkan format with no DXGI twin that no family above covers.
    VulkanOnly,
}

impl NoWebGpuFormat {
    /// The reason, as said wherever a format is refused (and in the coverage table).
    pub fn text(self) -> &'static str {
        match self {
            NoWebGpuFormat::Rgb96 => "96-bit RGB textures do not exist in WebGPU",
            NoWebGpuFormat::PackedBgr16 => "16-bit packed BGR formats do not exist in WebGPU",
            NoWebGpuFormat::PackedSmall => "packed 8- and 16-bit formats do not exist in WebGPU",
            NoWebGpuFormat::AlphaOnly => "alpha-only A8 does not exist in WebGPU",
            NoWebGpuFormat::OneBit => "1-bit formats do not exist in WebGPU",
            NoWebGpuFormat::XChannel => "X-channel formats do not exist in WebGPU (use B8G8R8A8)",
            NoWebGpuFormat::XrBias => "the XR-bias format does not exist in WebGPU",
            NoWebGpuFormat::Packed422 => "packed 4:2:2 formats are not renderable in WebGPU",
            NoWebGpuFormat::VideoPaletteOrOpaque => {
                "video, palette and opaque formats are not textures framelab can replay"
            }
            NoWebGpuFormat::Rgb24Or48 => {
                "three-channel 8- and 16-bit formats do not exist in WebGPU"
            }
            NoWebGpuFormat::Wide64 => "64-bit channels do not exist in WebGPU textures",
            NoWebGpuFormat::Scaled => {
                "scaled integer formats (integers read as floats) do not exist in WebGPU"
            }
            NoWebGpuFormat::Signed1010102 => {
                "signed 10-bit formats with 2-bit alpha do not exist in WebGPU"
            }
            NoWebGpuFormat::NarrowSrgb => {
                "one- and two-channel sRGB formats do not exist in WebGPU"
            }
            NoWebGpuFormat::Padded => {
                "formats padded to 16 bits a channel (10X6, 12X4) do not exist in WebGPU"
            }
            NoWebGpuFormat::MobileCompressed => {
                "ETC2, EAC and ASTC textures are not replayed (wgpu has them only as adapter features)"
            }
            NoWebGpuFormat::Pvrtc => "PVRTC compression does not exist in WebGPU",
            NoWebGpuFormat::DepthWithStencil16 => "D16 with stencil does not exist in WebGPU",
            NoWebGpuFormat::VulkanOnly => "this Vulkan format has no WebGPU twin of the same bits",
        }
    }

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
            n if n.starts_with("VK_FORMAT_") => Self::of_vulkan(&n["VK_FORMAT_".len()..]),
            "R8G8_B8G8_UNORM" | "G8R8_G8B8_UNORM" => NoWebGpuFormat::Packed422,
            _ => NoWebGpuFormat::VideoPaletteOrOpaque,
        }
    }

    /// The family of a Vulkan-only format, by its name without `VK_FORMAT_`.
    fn of_vulkan(bare: &str) -> NoWebGpuFormat {
        use NoWebGpuFormat as N;
        let head = bare.split('_').next().unwrap_or_default();
        match bare {
            b if b.contains("PLANE") || b.contains("_422") => N::VideoPaletteOrOpaque,
            b if b.starts_with("PVRTC") => N::Pvrtc,
            b if b.starts_with("ETC2") || b.starts_with("EAC") || b.starts_with("ASTC") => {
                N::MobileCompressed
            }
            b if b.contains("SCALED") => N::Scaled,
            b if b.contains('X')
                && (b.contains("X6") || b.contains("X4"))
                && !b.starts_with("X8") =>
            {
                N::Padded
            }
            "D16_UNORM_S8_UINT" => N::DepthWithStencil16,
            b if b.contains("64") => N::Wide64,
            b if b.starts_with("A2") => N::Signed1010102,
            "R8_SRGB" | "R8G8_SRGB" => N::NarrowSrgb,
            b if b.ends_with("_PACK16") || b.ends_with("_PACK8") => N::PackedSmall,
            _ if matches!(head, "R8G8B8" | "B8G8R8" | "R16G16B16") => N::Rgb24Or48,
            _ => N::VulkanOnly,
        }
    }
}

impl std::fmt::Display for NoWebGpuFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.text())
    }
}

impl std::error::Error for NoWebGpuFormat {}

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
    #[error(
        "16-bit packed BGR formats do not exist in WebGPU: the replay holds them as RGBA8 to read, and would not render at their 4 to 6 bits a channel"
    )]
    Packed16,
    #[error(
        "three-channel formats do not exist in WebGPU: the replay holds them with a fourth channel of one to read, which rendering would write"
    )]
    ThreeChannel,
}

/// Why a colour format cannot be rendered to on any GPU, if it cannot: WebGPU has no such
/// format, or it is shared-exponent (never a render target). Formats whose render support
/// varies by adapter (16-bit normalised) pass here and are checked against the device at
/// replay, which validation cannot see.
pub fn not_renderable(info: &FormatInfo) -> Option<NotRenderable> {
    if let Some(gap) = webgpu_gap(info.name) {
        return Some(NotRenderable::NoWebGpuFormat(gap));
    }
    if crate::lower::packed16::layout(info.name).is_some() {
        return Some(NotRenderable::Packed16);
    }
    if matches!(
        crate::lower::repack::Repack::of(info.name),
        Some(crate::lower::repack::Repack::Widen3 { .. })
    ) {
        return Some(NotRenderable::ThreeChannel);
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
            Some(NoWebGpuFormat::DepthWithStencil16)
        );
        assert_eq!(
            webgpu_gap("VK_FORMAT_A2B10G10R10_SNORM_PACK32"),
            Some(NoWebGpuFormat::Signed1010102)
        );
        assert_eq!(
            webgpu_gap("VK_FORMAT_R16G16B16A16_USCALED"),
            Some(NoWebGpuFormat::Scaled)
        );
        assert_eq!(webgpu_gap("VK_FORMAT_R8G8B8_UNORM"), None);
        assert_eq!(
            webgpu_gap("VK_FORMAT_R8G8B8_USCALED"),
            Some(NoWebGpuFormat::Scaled)
        );
        assert_eq!(webgpu_gap("VK_FORMAT_A2R10G10B10_UNORM_PACK32"), None);
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
        assert_eq!(not("R32G32B32_FLOAT"), Some(NotRenderable::ThreeChannel));
        assert_eq!(
            not("R32G32B32_TYPELESS").map(|n| n.to_string()),
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
