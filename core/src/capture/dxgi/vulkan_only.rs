//! The formats Vulkan has and DXGI does not, kept under their `VK_FORMAT_*` names so that an
//! imported image keeps its real format: a hand-made table of those with depth, stencil and
//! the common packed and compressed families, and every other registry format derived from
//! its name.

use super::{Channel, FormatInfo, Layout, Numeric, TABLE, ch, channel_bits, channels_from_name};

/// VkFormats with no DXGI twin, kept under their Vulkan name so that imported resources keep
/// their real format: (name, bits per element, block width, block height).
const VULKAN_ONLY: &[(&str, u32, u32, u32)] = &[
    ("VK_FORMAT_R4G4_UNORM_PACK8", 8, 1, 1),
    ("VK_FORMAT_R4G4B4A4_UNORM_PACK16", 16, 1, 1),
    ("VK_FORMAT_R5G6B5_UNORM_PACK16", 16, 1, 1),
    ("VK_FORMAT_R5G5B5A1_UNORM_PACK16", 16, 1, 1),
    ("VK_FORMAT_R8G8B8_UNORM", 24, 1, 1),
    ("VK_FORMAT_R8G8B8_SNORM", 24, 1, 1),
    ("VK_FORMAT_R8G8B8_UINT", 24, 1, 1),
    ("VK_FORMAT_R8G8B8_SINT", 24, 1, 1),
    ("VK_FORMAT_R8G8B8_SRGB", 24, 1, 1),
    ("VK_FORMAT_B8G8R8_UNORM", 24, 1, 1),
    ("VK_FORMAT_B8G8R8_SRGB", 24, 1, 1),
    ("VK_FORMAT_R16G16B16_UNORM", 48, 1, 1),
    ("VK_FORMAT_R16G16B16_SNORM", 48, 1, 1),
    ("VK_FORMAT_R16G16B16_UINT", 48, 1, 1),
    ("VK_FORMAT_R16G16B16_SINT", 48, 1, 1),
    ("VK_FORMAT_R16G16B16_SFLOAT", 48, 1, 1),
    ("VK_FORMAT_R64_UINT", 64, 1, 1),
    ("VK_FORMAT_R64_SINT", 64, 1, 1),
    ("VK_FORMAT_R64_SFLOAT", 64, 1, 1),
    ("VK_FORMAT_R64G64_SFLOAT", 128, 1, 1),
    ("VK_FORMAT_R64G64B64A64_SFLOAT", 256, 1, 1),
    ("VK_FORMAT_D16_UNORM_S8_UINT", 32, 1, 1),
    ("VK_FORMAT_X8_D24_UNORM_PACK32", 32, 1, 1),
    ("VK_FORMAT_S8_UINT", 8, 1, 1),
    ("VK_FORMAT_ETC2_R8G8B8_UNORM_BLOCK", 64, 4, 4),
    ("VK_FORMAT_ETC2_R8G8B8_SRGB_BLOCK", 64, 4, 4),
    ("VK_FORMAT_ETC2_R8G8B8A1_UNORM_BLOCK", 64, 4, 4),
    ("VK_FORMAT_ETC2_R8G8B8A8_UNORM_BLOCK", 128, 4, 4),
    ("VK_FORMAT_ETC2_R8G8B8A8_SRGB_BLOCK", 128, 4, 4),
    ("VK_FORMAT_EAC_R11_UNORM_BLOCK", 64, 4, 4),
    ("VK_FORMAT_EAC_R11G11_UNORM_BLOCK", 128, 4, 4),
    ("VK_FORMAT_ASTC_4x4_UNORM_BLOCK", 128, 4, 4),
    ("VK_FORMAT_ASTC_4x4_SRGB_BLOCK", 128, 4, 4),
    ("VK_FORMAT_ASTC_6x6_UNORM_BLOCK", 128, 6, 6),
    ("VK_FORMAT_ASTC_6x6_SRGB_BLOCK", 128, 6, 6),
    ("VK_FORMAT_ASTC_8x8_UNORM_BLOCK", 128, 8, 8),
    ("VK_FORMAT_ASTC_8x8_SRGB_BLOCK", 128, 8, 8),
];

/// (bits per element, block width, block height, layout) of a registry `VK_FORMAT_*` name
/// the tables above do not list, read from the name as the specification spells formats:
/// compressed blocks by family, multi-planar and 4:2:2 video formats as planar, `_PACKn` and
/// `_kPACKn` at their packed size, the rest as the sum of their channels' bits.
fn derived_size(bare: &str) -> (u32, u32, u32, Layout) {
    let digits = |s: &str| s.parse::<u32>().unwrap_or(0);
    if bare.contains("PLANE") {
        // The average bits per texel over the planes: 4:2:0 has half a texel of chroma.
        let depth = if bare.starts_with("G8") { 8 } else { 16 };
        let per = if bare.contains("_420") {
            3
        } else if bare.contains("_422") {
            4
        } else {
            6
        };
        return (depth * per / 2, 1, 1, Layout::Planar);
    }
    if bare.contains("_422_") {
        let depth = if bare.contains('8') && !bare.contains("16") && !bare.contains('X') {
            8
        } else {
            16
        };
        return (depth * 4, 2, 1, Layout::Linear);
    }
    if let Some(rest) = bare.strip_prefix("ASTC_") {
        let (w, h) = rest
            .split('_')
            .next()
            .and_then(|d| d.split_once('x'))
            .map_or((4, 4), |(w, h)| (digits(w), digits(h)));
        return (128, w, h, Layout::BlockCompressed);
    }
    if bare.starts_with("PVRTC") {
        let w = if bare.contains("2BPP") { 8 } else { 4 };
        return (64, w, 4, Layout::BlockCompressed);
    }
    if bare.ends_with("_BLOCK") {
        let half = bare.starts_with("BC1")
            || bare.starts_with("BC4")
            || bare.starts_with("EAC_R11_")
            || bare.starts_with("ETC2_R8G8B8_")
            || bare.starts_with("ETC2_R8G8B8A1");
        return (if half { 64 } else { 128 }, 4, 4, Layout::BlockCompressed);
    }
    for (suffix, bits) in [
        ("_4PACK16", 64),
        ("_3PACK16", 48),
        ("_2PACK16", 32),
        ("_PACK32", 32),
        ("_PACK16", 16),
        ("_PACK8", 8),
    ] {
        if bare.ends_with(suffix) {
            return (bits, 1, 1, Layout::Linear);
        }
    }
    let channels: u32 = bare
        .split('_')
        .next()
        .and_then(channel_bits)
        .map_or(0, |c| c.iter().map(|(_, b)| b).sum());
    (channels, 1, 1, Layout::Linear)
}

/// Every registry `VK_FORMAT_*` with neither a DXGI twin nor a row in `VULKAN_ONLY`, derived
/// from its name (`derived_size`), so that an image of any format is imported with it.
fn registry_rest() -> Vec<(&'static str, u32, u32, u32)> {
    let twins: std::collections::HashSet<&str> = TABLE.iter().filter_map(|f| f.vk_format).collect();
    crate::import::gfxr::tables::ENUMS
        .iter()
        .find(|e| e.name == "VkFormat")
        .map(|e| e.values)
        .unwrap_or_default()
        .iter()
        .map(|(_, n)| *n)
        .filter(|n| {
            *n != "VK_FORMAT_UNDEFINED"
                && !twins.contains(n)
                && !VULKAN_ONLY.iter().any(|(v, ..)| v == n)
        })
        .map(|n| {
            let (bits, bw, bh, _) = derived_size(n.trim_start_matches("VK_FORMAT_"));
            (n, bits, bw, bh)
        })
        .collect()
}

pub(super) fn build_vulkan_only() -> Vec<FormatInfo> {
    VULKAN_ONLY
        .iter()
        .copied()
        .chain(registry_rest())
        .map(|(name, bits, bw, bh)| {
            let bare = name.trim_start_matches("VK_FORMAT_");
            let (_, _, _, layout) = derived_size(bare);
            let compressed = layout == Layout::BlockCompressed;
            let numeric = if bare.contains("SCALED")
                || bare.contains("_422")
                || layout == Layout::Planar
                || bare.contains("S10_5")
            {
                // Scaled integers read as floats, video and fixed-point formats: no number a
                // replayed shader reads as framelab represents channels.
                Numeric::Other
            } else if bare.contains("SNORM") {
                Numeric::Snorm
            } else if bare.contains("SINT") {
                Numeric::Sint
            } else if bare.contains("UINT") {
                Numeric::Uint
            } else if bare.contains("SFLOAT") {
                Numeric::Float
            } else {
                Numeric::Unorm
            };
            let channels: Vec<Channel> = if compressed {
                let letters = if bare.starts_with("EAC_R11G11") {
                    "RG"
                } else if bare.starts_with("EAC") {
                    "R"
                } else if bare.contains("R8G8B8_") {
                    "RGB"
                } else {
                    "RGBA"
                };
                letters.chars().map(|c| ch(c, 0, numeric)).collect()
            } else {
                let mut spelled = bare
                    .replace("SFLOAT", "FLOAT")
                    .replace("USCALED", "UINT")
                    .replace("SSCALED", "SINT");
                for pack in [
                    "_4PACK16", "_3PACK16", "_2PACK16", "_PACK8", "_PACK16", "_PACK32",
                ] {
                    spelled = spelled.replace(pack, "");
                }
                if let Some(head) = spelled.strip_suffix("_SRGB") {
                    spelled = format!("{head}_UNORM");
                }
                let mut channels = channels_from_name(&spelled).unwrap_or_default();
                if numeric == Numeric::Other {
                    channels.iter_mut().for_each(|c| c.numeric = Numeric::Other);
                    if channels.is_empty() {
                        channels.push(ch('X', 0, Numeric::Other));
                    }
                }
                channels
            };
            let bits_of = |c: char| {
                channels
                    .iter()
                    .filter(|x| x.name == c)
                    .map(|x| x.bits)
                    .sum()
            };
            FormatInfo {
                name,
                value: 0,
                layout,
                bits_per_element: bits,
                block_width: bw,
                block_height: bh,
                depth_bits: bits_of('D'),
                stencil_bits: bits_of('S'),
                channels,
                typeless_family: None,
                srgb: bare.contains("SRGB"),
                vk_format: Some(name),
            }
        })
        .collect()
}
