//! The DXGI format table: every `DXGI_FORMAT` value with its element size, block footprint,
//! channels and their numeric types, typeless family, depth/stencil aspects, sRGB flag and the
//! Vulkan `VkFormat` equivalent where one exists.
//!
//! Captures name formats as D3D12 does (`R10G10B10A2_UNORM`), so every later stage (validation,
//! sizes, barriers, lowering to wgpu) asks this table rather than matching on names. Channels are
//! derived from the DXGI name, which is regular for all colour and depth formats; block-compressed,
//! video and palette formats, which the name does not describe, are given explicitly.

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::sync::LazyLock;

use vulkan_only::build_vulkan_only;

mod vulkan_only;

/// How a format's bits are laid out in memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// One element per texel (or per `block` of texels for packed 4:2:2 formats).
    Linear,
    /// 4x4 block compression (BC1-BC7).
    BlockCompressed,
    /// Several planes (luma + chroma) with subsampled chroma; `bits` is the average per texel.
    Planar,
    /// Driver-defined layout with no byte size (sampler feedback, opaque video).
    Opaque,
}

/// The numeric interpretation of one channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Numeric {
    Typeless,
    Unorm,
    Snorm,
    Uint,
    Sint,
    Float,
    /// Unsigned float without sign bit (R11G11B10, BC6H_UF16).
    Ufloat,
    /// Shared-exponent float (R9G9B9E5).
    SharedExp,
    /// Extended-range biased fixed point (R10G10B10_XR_BIAS_A2).
    XrBias,
    /// Palette index or video component: not a number a shader reads directly.
    Other,
}

/// One channel of a format: its letter (R, G, B, A, D, S, X for unused, Y/U/V for video), bits
/// and numeric type.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Channel {
    pub name: char,
    pub bits: u32,
    pub numeric: Numeric,
}

/// Everything framelab knows about one DXGI format.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct FormatInfo {
    /// The name without the `DXGI_FORMAT_` prefix, as captures write it.
    pub name: &'static str,
    /// The numeric value of the `DXGI_FORMAT` enumerator.
    pub value: u32,
    pub layout: Layout,
    /// Bits per element: per texel, per 4x4 block for BC, per 2x1 block for packed 4:2:2, and
    /// the average per texel for planar formats.
    pub bits_per_element: u32,
    /// Texels covered by one element (1x1, 4x4 for BC, 2x1 for packed 4:2:2).
    pub block_width: u32,
    pub block_height: u32,
    pub channels: Vec<Channel>,
    /// The `_TYPELESS` format whose views this format is one of, if any.
    pub typeless_family: Option<&'static str>,
    pub depth_bits: u32,
    pub stencil_bits: u32,
    pub srgb: bool,
    /// The Vulkan format with the same bits and meaning; `None` where Vulkan has none.
    pub vk_format: Option<&'static str>,
}

impl FormatInfo {
    pub fn is_typeless(&self) -> bool {
        self.name.ends_with("_TYPELESS") && self.depth_bits == 0 && self.stencil_bits == 0
            || self.channels.iter().all(|c| c.numeric == Numeric::Typeless)
                && !self.channels.is_empty()
    }
    pub fn is_depth_stencil(&self) -> bool {
        self.depth_bits > 0 || self.stencil_bits > 0
    }
    /// A depth/stencil *storage* format (D16, D24S8, D32, D32S8), as opposed to the typeless
    /// families and the read views (R24_UNORM_X8_TYPELESS, ...) which carry no depth aspect.
    pub fn is_depth_format(&self) -> bool {
        // Vulkan-only entries keep their `VK_FORMAT_` name; X8_D24 pads its depth, S8 has
        // stencil alone.
        let bare = self.name.trim_start_matches("VK_FORMAT_");
        (bare.starts_with('D') || bare.starts_with("X8_D") || bare.starts_with("S8"))
            && self.is_depth_stencil()
    }
    /// A format with depth or stencil bits, or a typeless family holding nothing else
    /// (R24G8, R32G8X24): D3D12 and Vulkan allow these only on 1D and 2D textures (arrays and
    /// cubes included), never on 3D ones.
    pub fn is_depth_only(&self) -> bool {
        self.is_depth_stencil() || matches!(self.name, "R24G8_TYPELESS" | "R32G8X24_TYPELESS")
    }
    pub fn is_block_compressed(&self) -> bool {
        self.layout == Layout::BlockCompressed
    }
    /// Whether a texture of this format can be created at all (video and palette formats are
    /// recorded for completeness but no render pipeline consumes them).
    pub fn is_video_or_palette(&self) -> bool {
        matches!(self.layout, Layout::Planar | Layout::Opaque)
            || self.channels.iter().any(|c| c.numeric == Numeric::Other)
    }
    /// The dominant numeric type: what a shader sees when it reads the first channel.
    pub fn numeric(&self) -> Option<Numeric> {
        self.channels
            .iter()
            .find(|c| c.name != 'X')
            .map(|c| c.numeric)
    }
    pub fn is_integer(&self) -> bool {
        matches!(self.numeric(), Some(Numeric::Uint | Numeric::Sint))
    }
    /// Bytes of one subresource of `width` x `height` texels, rounding up to whole elements.
    pub fn surface_bytes(&self, width: u64, height: u64) -> Option<u64> {
        if self.layout == Layout::Opaque || self.bits_per_element == 0 {
            return None;
        }
        if self.layout == Layout::Planar {
            let texels = width.checked_mul(height)?;
            return texels
                .checked_mul(u64::from(self.bits_per_element))
                .map(|b| b.div_ceil(8));
        }
        let bw = width.div_ceil(u64::from(self.block_width));
        let bh = height.div_ceil(u64::from(self.block_height));
        let bits = bw
            .checked_mul(bh)?
            .checked_mul(u64::from(self.bits_per_element))?;
        Some(bits.div_ceil(8))
    }

    /// Bytes of every mip level, layer and sample of a texture in this format, tightly packed
    /// level after level; `depth` is a 3D texture's (halved with each level), 1 otherwise.
    /// `None` on overflow or for a format without a size.
    pub fn texture_bytes(
        &self,
        (width, height, depth): (u32, u32, u32),
        layers: u32,
        mips: u32,
        samples: u32,
    ) -> Option<u64> {
        let mut sum: u64 = 0;
        for m in 0..mips {
            let (w, h, d) = (
                (width >> m).max(1),
                (height >> m).max(1),
                (depth >> m).max(1),
            );
            let level = self
                .surface_bytes(u64::from(w), u64::from(h))?
                .checked_mul(u64::from(d))?
                .checked_mul(u64::from(layers))?
                .checked_mul(u64::from(samples))?;
            sum = sum.checked_add(level)?;
        }
        Some(sum)
    }
}

impl fmt::Display for FormatInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

/// (value, name, bits per element, block w, block h, VkFormat)
type Row = (u32, &'static str, u32, u32, u32, Option<&'static str>);

macro_rules! rows {
    ($( $value:literal $name:ident $bits:literal $bw:literal $bh:literal $vk:tt ;)*) => {
        &[ $( ($value, stringify!($name), $bits, $bw, $bh, rows!(@vk $vk)) ),* ]
    };
    (@vk -) => { None };
    (@vk $vk:ident) => { Some(concat!("VK_FORMAT_", stringify!($vk))) };
}

/// Every enumerator of `DXGI_FORMAT` in dxgiformat.h, in numeric order.
#[rustfmt::skip]
const ROWS: &[Row] = rows! {
    0 UNKNOWN 0 1 1 -;
    1 R32G32B32A32_TYPELESS 128 1 1 -;
    2 R32G32B32A32_FLOAT 128 1 1 R32G32B32A32_SFLOAT;
    3 R32G32B32A32_UINT 128 1 1 R32G32B32A32_UINT;
    4 R32G32B32A32_SINT 128 1 1 R32G32B32A32_SINT;
    5 R32G32B32_TYPELESS 96 1 1 -;
    6 R32G32B32_FLOAT 96 1 1 R32G32B32_SFLOAT;
    7 R32G32B32_UINT 96 1 1 R32G32B32_UINT;
    8 R32G32B32_SINT 96 1 1 R32G32B32_SINT;
    9 R16G16B16A16_TYPELESS 64 1 1 -;
    10 R16G16B16A16_FLOAT 64 1 1 R16G16B16A16_SFLOAT;
    11 R16G16B16A16_UNORM 64 1 1 R16G16B16A16_UNORM;
    12 R16G16B16A16_UINT 64 1 1 R16G16B16A16_UINT;
    13 R16G16B16A16_SNORM 64 1 1 R16G16B16A16_SNORM;
    14 R16G16B16A16_SINT 64 1 1 R16G16B16A16_SINT;
    15 R32G32_TYPELESS 64 1 1 -;
    16 R32G32_FLOAT 64 1 1 R32G32_SFLOAT;
    17 R32G32_UINT 64 1 1 R32G32_UINT;
    18 R32G32_SINT 64 1 1 R32G32_SINT;
    19 R32G8X24_TYPELESS 64 1 1 -;
    20 D32_FLOAT_S8X24_UINT 64 1 1 D32_SFLOAT_S8_UINT;
    21 R32_FLOAT_X8X24_TYPELESS 64 1 1 -;
    22 X32_TYPELESS_G8X24_UINT 64 1 1 -;
    23 R10G10B10A2_TYPELESS 32 1 1 -;
    24 R10G10B10A2_UNORM 32 1 1 A2B10G10R10_UNORM_PACK32;
    25 R10G10B10A2_UINT 32 1 1 A2B10G10R10_UINT_PACK32;
    26 R11G11B10_FLOAT 32 1 1 B10G11R11_UFLOAT_PACK32;
    27 R8G8B8A8_TYPELESS 32 1 1 -;
    28 R8G8B8A8_UNORM 32 1 1 R8G8B8A8_UNORM;
    29 R8G8B8A8_UNORM_SRGB 32 1 1 R8G8B8A8_SRGB;
    30 R8G8B8A8_UINT 32 1 1 R8G8B8A8_UINT;
    31 R8G8B8A8_SNORM 32 1 1 R8G8B8A8_SNORM;
    32 R8G8B8A8_SINT 32 1 1 R8G8B8A8_SINT;
    33 R16G16_TYPELESS 32 1 1 -;
    34 R16G16_FLOAT 32 1 1 R16G16_SFLOAT;
    35 R16G16_UNORM 32 1 1 R16G16_UNORM;
    36 R16G16_UINT 32 1 1 R16G16_UINT;
    37 R16G16_SNORM 32 1 1 R16G16_SNORM;
    38 R16G16_SINT 32 1 1 R16G16_SINT;
    39 R32_TYPELESS 32 1 1 -;
    40 D32_FLOAT 32 1 1 D32_SFLOAT;
    41 R32_FLOAT 32 1 1 R32_SFLOAT;
    42 R32_UINT 32 1 1 R32_UINT;
    43 R32_SINT 32 1 1 R32_SINT;
    44 R24G8_TYPELESS 32 1 1 -;
    45 D24_UNORM_S8_UINT 32 1 1 D24_UNORM_S8_UINT;
    46 R24_UNORM_X8_TYPELESS 32 1 1 -;
    47 X24_TYPELESS_G8_UINT 32 1 1 -;
    48 R8G8_TYPELESS 16 1 1 -;
    49 R8G8_UNORM 16 1 1 R8G8_UNORM;
    50 R8G8_UINT 16 1 1 R8G8_UINT;
    51 R8G8_SNORM 16 1 1 R8G8_SNORM;
    52 R8G8_SINT 16 1 1 R8G8_SINT;
    53 R16_TYPELESS 16 1 1 -;
    54 R16_FLOAT 16 1 1 R16_SFLOAT;
    55 D16_UNORM 16 1 1 D16_UNORM;
    56 R16_UNORM 16 1 1 R16_UNORM;
    57 R16_UINT 16 1 1 R16_UINT;
    58 R16_SNORM 16 1 1 R16_SNORM;
    59 R16_SINT 16 1 1 R16_SINT;
    60 R8_TYPELESS 8 1 1 -;
    61 R8_UNORM 8 1 1 R8_UNORM;
    62 R8_UINT 8 1 1 R8_UINT;
    63 R8_SNORM 8 1 1 R8_SNORM;
    64 R8_SINT 8 1 1 R8_SINT;
    65 A8_UNORM 8 1 1 A8_UNORM_KHR;
    66 R1_UNORM 1 1 1 -;
    67 R9G9B9E5_SHAREDEXP 32 1 1 E5B9G9R9_UFLOAT_PACK32;
    68 R8G8_B8G8_UNORM 32 2 1 B8G8R8G8_422_UNORM;
    69 G8R8_G8B8_UNORM 32 2 1 G8B8G8R8_422_UNORM;
    70 BC1_TYPELESS 64 4 4 -;
    71 BC1_UNORM 64 4 4 BC1_RGBA_UNORM_BLOCK;
    72 BC1_UNORM_SRGB 64 4 4 BC1_RGBA_SRGB_BLOCK;
    73 BC2_TYPELESS 128 4 4 -;
    74 BC2_UNORM 128 4 4 BC2_UNORM_BLOCK;
    75 BC2_UNORM_SRGB 128 4 4 BC2_SRGB_BLOCK;
    76 BC3_TYPELESS 128 4 4 -;
    77 BC3_UNORM 128 4 4 BC3_UNORM_BLOCK;
    78 BC3_UNORM_SRGB 128 4 4 BC3_SRGB_BLOCK;
    79 BC4_TYPELESS 64 4 4 -;
    80 BC4_UNORM 64 4 4 BC4_UNORM_BLOCK;
    81 BC4_SNORM 64 4 4 BC4_SNORM_BLOCK;
    82 BC5_TYPELESS 128 4 4 -;
    83 BC5_UNORM 128 4 4 BC5_UNORM_BLOCK;
    84 BC5_SNORM 128 4 4 BC5_SNORM_BLOCK;
    85 B5G6R5_UNORM 16 1 1 R5G6B5_UNORM_PACK16;
    86 B5G5R5A1_UNORM 16 1 1 A1R5G5B5_UNORM_PACK16;
    87 B8G8R8A8_UNORM 32 1 1 B8G8R8A8_UNORM;
    88 B8G8R8X8_UNORM 32 1 1 -;
    89 R10G10B10_XR_BIAS_A2_UNORM 32 1 1 -;
    90 B8G8R8A8_TYPELESS 32 1 1 -;
    91 B8G8R8A8_UNORM_SRGB 32 1 1 B8G8R8A8_SRGB;
    92 B8G8R8X8_TYPELESS 32 1 1 -;
    93 B8G8R8X8_UNORM_SRGB 32 1 1 -;
    94 BC6H_TYPELESS 128 4 4 -;
    95 BC6H_UF16 128 4 4 BC6H_UFLOAT_BLOCK;
    96 BC6H_SF16 128 4 4 BC6H_SFLOAT_BLOCK;
    97 BC7_TYPELESS 128 4 4 -;
    98 BC7_UNORM 128 4 4 BC7_UNORM_BLOCK;
    99 BC7_UNORM_SRGB 128 4 4 BC7_SRGB_BLOCK;
    100 AYUV 32 1 1 -;
    101 Y410 32 1 1 -;
    102 Y416 64 1 1 -;
    103 NV12 12 1 1 G8_B8R8_2PLANE_420_UNORM;
    104 P010 24 1 1 G10X6_B10X6R10X6_2PLANE_420_UNORM_3PACK16;
    105 P016 24 1 1 G16_B16R16_2PLANE_420_UNORM;
    106 OPAQUE_420 12 1 1 -;
    107 YUY2 32 2 1 G8B8G8R8_422_UNORM;
    108 Y210 64 2 1 G10X6B10X6G10X6R10X6_422_UNORM_4PACK16;
    109 Y216 64 2 1 G16B16G16R16_422_UNORM;
    110 NV11 12 1 1 -;
    111 AI44 8 1 1 -;
    112 IA44 8 1 1 -;
    113 P8 8 1 1 -;
    114 A8P8 16 1 1 -;
    115 B4G4R4A4_UNORM 16 1 1 A4R4G4B4_UNORM_PACK16;
    130 P208 16 1 1 G8_B8R8_2PLANE_422_UNORM;
    131 V208 16 1 1 -;
    132 V408 24 1 1 G8_B8R8_2PLANE_444_UNORM;
    189 SAMPLER_FEEDBACK_MIN_MIP_OPAQUE 0 1 1 -;
    190 SAMPLER_FEEDBACK_MIP_REGION_USED_OPAQUE 0 1 1 -;
    191 A4B4G4R4_UNORM 16 1 1 R4G4B4A4_UNORM_PACK16;
};

/// Formats whose name does not spell their typeless family by channel layout alone.
const FAMILY_EXCEPTIONS: &[(&str, &str)] = &[
    ("D32_FLOAT_S8X24_UINT", "R32G8X24_TYPELESS"),
    ("R32_FLOAT_X8X24_TYPELESS", "R32G8X24_TYPELESS"),
    ("X32_TYPELESS_G8X24_UINT", "R32G8X24_TYPELESS"),
    ("D32_FLOAT", "R32_TYPELESS"),
    ("D24_UNORM_S8_UINT", "R24G8_TYPELESS"),
    ("R24_UNORM_X8_TYPELESS", "R24G8_TYPELESS"),
    ("X24_TYPELESS_G8_UINT", "R24G8_TYPELESS"),
    ("D16_UNORM", "R16_TYPELESS"),
    ("R10G10B10_XR_BIAS_A2_UNORM", "R10G10B10A2_TYPELESS"),
];

fn numeric_of(token: &str) -> Option<Numeric> {
    Some(match token {
        "TYPELESS" => Numeric::Typeless,
        "UNORM" => Numeric::Unorm,
        "SNORM" => Numeric::Snorm,
        "UINT" => Numeric::Uint,
        "SINT" => Numeric::Sint,
        "FLOAT" | "SF16" => Numeric::Float,
        "UF16" => Numeric::Ufloat,
        "SHAREDEXP" => Numeric::SharedExp,
        _ => return None,
    })
}

/// Splits a channel token like `R10G10B10A2` into (letter, bits) pairs.
fn channel_bits(token: &str) -> Option<Vec<(char, u32)>> {
    let mut out = Vec::new();
    let mut chars = token.chars().peekable();
    while let Some(letter) = chars.next() {
        if !letter.is_ascii_uppercase() {
            return None;
        }
        let mut digits = String::new();
        while let Some(d) = chars.peek().filter(|c| c.is_ascii_digit()) {
            digits.push(*d);
            chars.next();
        }
        out.push((letter, digits.parse().ok()?));
    }
    (!out.is_empty()).then_some(out)
}

/// Channels as DXGI's naming spells them: groups of channel tokens followed by a type token,
/// e.g. `D32_FLOAT_S8X24_UINT` is D32 float, S8 uint, X24 uint.
fn channels_from_name(name: &str) -> Option<Vec<Channel>> {
    let mut channels = Vec::new();
    let mut pending: Vec<(char, u32)> = Vec::new();
    for token in name.split('_') {
        if token == "SRGB" {
            continue;
        }
        if let Some(numeric) = numeric_of(token) {
            if pending.is_empty() {
                return None;
            }
            channels.extend(pending.drain(..).map(|(name, bits)| Channel {
                name,
                bits,
                numeric,
            }));
        } else {
            pending.extend(channel_bits(token)?);
        }
    }
    pending
        .is_empty()
        .then_some(channels)
        .filter(|c: &Vec<Channel>| !c.is_empty())
}

fn ch(name: char, bits: u32, numeric: Numeric) -> Channel {
    Channel {
        name,
        bits,
        numeric,
    }
}

/// Channels of the formats whose names are not channel lists.
fn channels_special(name: &str) -> Vec<Channel> {
    use Numeric::*;
    let bc = |channels: &str, numeric: Numeric| -> Vec<Channel> {
        channels.chars().map(|c| ch(c, 0, numeric)).collect()
    };
    let numeric = if name.ends_with("_TYPELESS") {
        Typeless
    } else if name.ends_with("_SNORM") {
        Snorm
    } else {
        Unorm
    };
    match name {
        "UNKNOWN"
        | "SAMPLER_FEEDBACK_MIN_MIP_OPAQUE"
        | "SAMPLER_FEEDBACK_MIP_REGION_USED_OPAQUE"
        | "OPAQUE_420" => Vec::new(),
        "R10G10B10_XR_BIAS_A2_UNORM" => {
            vec![
                ch('R', 10, XrBias),
                ch('G', 10, XrBias),
                ch('B', 10, XrBias),
                ch('A', 2, Unorm),
            ]
        }
        "R8G8_B8G8_UNORM" => vec![ch('R', 8, Unorm), ch('G', 8, Unorm), ch('B', 8, Unorm)],
        "G8R8_G8B8_UNORM" => vec![ch('G', 8, Unorm), ch('R', 8, Unorm), ch('B', 8, Unorm)],
        "BC6H_UF16" => bc("RGB", Ufloat),
        "BC6H_SF16" => bc("RGB", Float),
        "BC6H_TYPELESS" => bc("RGB", Typeless),
        _ if name.starts_with("BC1") || name.starts_with("BC2") || name.starts_with("BC3") => {
            bc("RGBA", numeric)
        }
        _ if name.starts_with("BC4") => bc("R", numeric),
        _ if name.starts_with("BC5") => bc("RG", numeric),
        _ if name.starts_with("BC7") => bc("RGBA", numeric),
        "AYUV" => vec![
            ch('V', 8, Other),
            ch('U', 8, Other),
            ch('Y', 8, Other),
            ch('A', 8, Unorm),
        ],
        "Y410" => vec![
            ch('U', 10, Other),
            ch('Y', 10, Other),
            ch('V', 10, Other),
            ch('A', 2, Unorm),
        ],
        "Y416" => vec![
            ch('U', 16, Other),
            ch('Y', 16, Other),
            ch('V', 16, Other),
            ch('A', 16, Unorm),
        ],
        "YUY2" | "NV12" | "NV11" | "P208" | "V208" | "V408" => {
            vec![ch('Y', 8, Other), ch('U', 8, Other), ch('V', 8, Other)]
        }
        "P010" | "Y210" => vec![ch('Y', 10, Other), ch('U', 10, Other), ch('V', 10, Other)],
        "P016" | "Y216" => vec![ch('Y', 16, Other), ch('U', 16, Other), ch('V', 16, Other)],
        "AI44" => vec![ch('A', 4, Unorm), ch('I', 4, Other)],
        "IA44" => vec![ch('I', 4, Other), ch('A', 4, Unorm)],
        "P8" => vec![ch('P', 8, Other)],
        "A8P8" => vec![ch('A', 8, Unorm), ch('P', 8, Other)],
        _ => Vec::new(),
    }
}

fn layout_of(name: &str, bw: u32) -> Layout {
    match name {
        "UNKNOWN"
        | "SAMPLER_FEEDBACK_MIN_MIP_OPAQUE"
        | "SAMPLER_FEEDBACK_MIP_REGION_USED_OPAQUE" => Layout::Opaque,
        "NV12" | "P010" | "P016" | "OPAQUE_420" | "NV11" | "P208" | "V208" | "V408" => {
            Layout::Planar
        }
        _ if bw == 4 => Layout::BlockCompressed,
        _ => Layout::Linear,
    }
}

/// The layout signature used to find a format's typeless family: channel letters and bits,
/// with X channels ignored and B/R order kept.
fn family_key(channels: &[Channel]) -> String {
    channels
        .iter()
        .map(|c| format!("{}{}", c.name, c.bits))
        .collect()
}

fn build_table() -> Vec<FormatInfo> {
    let mut infos: Vec<FormatInfo> = ROWS
        .iter()
        .map(|&(value, name, bits, bw, bh, vk)| {
            let parsed = if bw == 1 && bh == 1 && !name.starts_with("BC") {
                channels_from_name(name)
            } else {
                None
            };
            let channels = parsed.unwrap_or_else(|| channels_special(name));
            let depth_bits = channels
                .iter()
                .filter(|c| c.name == 'D')
                .map(|c| c.bits)
                .sum();
            let stencil_bits = channels
                .iter()
                .filter(|c| c.name == 'S')
                .map(|c| c.bits)
                .sum();
            FormatInfo {
                name,
                value,
                layout: layout_of(name, bw),
                bits_per_element: bits,
                block_width: bw,
                block_height: bh,
                channels,
                typeless_family: None,
                depth_bits,
                stencil_bits,
                srgb: name.ends_with("_SRGB"),
                vk_format: vk,
            }
        })
        .collect();

    let mut families: BTreeMap<String, &'static str> = BTreeMap::new();
    for info in &infos {
        if info.name.ends_with("_TYPELESS")
            && info.channels.iter().all(|c| c.numeric == Numeric::Typeless)
        {
            let key = if info.is_block_compressed() {
                info.name.trim_end_matches("_TYPELESS").to_owned()
            } else {
                family_key(&info.channels)
            };
            families.insert(key, info.name);
        }
    }
    for info in &mut infos {
        let exception = FAMILY_EXCEPTIONS
            .iter()
            .find(|(n, _)| *n == info.name)
            .map(|(_, f)| *f);
        let key = if info.is_block_compressed() {
            info.name.split('_').next().unwrap_or_default().to_owned()
        } else {
            family_key(&info.channels)
        };
        let family = exception.or_else(|| families.get(&key).copied());
        info.typeless_family = family.filter(|f| *f != info.name);
    }
    infos
}

static TABLE: LazyLock<Vec<FormatInfo>> = LazyLock::new(build_table);

/// Every format, in numeric order of `DXGI_FORMAT`.
pub fn all() -> &'static [FormatInfo] {
    &TABLE
}

static VULKAN_TABLE: LazyLock<Vec<FormatInfo>> = LazyLock::new(build_vulkan_only);

/// Every format by its upper-case `VK_FORMAT_*` name, for `lookup_vk`: an import looks a
/// format up at every use of an image, too often for a scan of the tables.
static BY_VK_NAME: LazyLock<HashMap<String, &'static FormatInfo>> = LazyLock::new(|| {
    let mut by_name = HashMap::new();
    // The first DXGI twin in numeric order, then the Vulkan-only entries.
    for f in TABLE.iter() {
        if let Some(v) = f.vk_format {
            by_name.entry(v.to_ascii_uppercase()).or_insert(f);
        }
    }
    for f in VULKAN_TABLE.iter() {
        by_name.entry(f.name.to_ascii_uppercase()).or_insert(f);
    }
    by_name
});

/// The format a `VK_FORMAT_*` name (any case) stands for: its DXGI twin where one exists,
/// else the Vulkan-only entry of that name.
pub fn lookup_vk(name: &str) -> Option<&'static FormatInfo> {
    let name = name.trim();
    BY_VK_NAME
        .get(name)
        .or_else(|| BY_VK_NAME.get(&name.to_ascii_uppercase()))
        .copied()
}

/// A format by its DXGI name (with or without `DXGI_FORMAT_`) or by its `VK_FORMAT_*` name.
pub fn lookup(name: &str) -> Option<&'static FormatInfo> {
    if name.trim().to_ascii_uppercase().starts_with("VK_FORMAT_") {
        return lookup_vk(name);
    }
    let upper = name.trim().to_ascii_uppercase();
    let bare = upper.strip_prefix("DXGI_FORMAT_").unwrap_or(&upper);
    let bare = if bare == "420_OPAQUE" {
        "OPAQUE_420"
    } else {
        bare
    };
    TABLE.iter().find(|f| f.name == bare)
}

pub fn by_value(value: u32) -> Option<&'static FormatInfo> {
    TABLE.iter().find(|f| f.value == value)
}

/// Format names, for did-you-mean suggestions.
pub fn names() -> impl Iterator<Item = &'static str> {
    TABLE.iter().map(|f| f.name)
}

/// Whether a view of `view` may reinterpret a resource created as `resource`: same format, or
/// both in the same typeless family (D3D12's casting rule for typeless resources).
pub fn view_compatible(resource: &FormatInfo, view: &FormatInfo) -> bool {
    if resource.name == view.name {
        return true;
    }
    let family = |f: &FormatInfo| f.typeless_family.unwrap_or(f.name);
    resource.is_typeless() && family(view) == resource.name
        || family(resource) == family(view) && resource.is_typeless()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_covers_every_enumerator_once_in_order() {
        let values: Vec<u32> = all().iter().map(|f| f.value).collect();
        let mut sorted = values.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(values, sorted);
        // 0..=115, 130..=132 and 189..=191 in dxgiformat.h
        assert_eq!(values.len(), 116 + 3 + 3);
        assert_eq!(by_value(41).map(|f| f.name), Some("R32_FLOAT"));
    }

    /// Every VkFormat with a depth or stencil aspect (vk.xml's formats with a `D` or `S`
    /// component), with its depth and stencil bits.
    #[test]
    fn every_vulkan_depth_stencil_format_is_one() {
        for (name, depth, stencil) in [
            ("VK_FORMAT_D16_UNORM", 16, 0),
            ("VK_FORMAT_X8_D24_UNORM_PACK32", 24, 0),
            ("VK_FORMAT_D32_SFLOAT", 32, 0),
            ("VK_FORMAT_S8_UINT", 0, 8),
            ("VK_FORMAT_D16_UNORM_S8_UINT", 16, 8),
            ("VK_FORMAT_D24_UNORM_S8_UINT", 24, 8),
            ("VK_FORMAT_D32_SFLOAT_S8_UINT", 32, 8),
        ] {
            let f = lookup_vk(name).unwrap_or_else(|| panic!("{name}"));
            assert!(f.is_depth_format(), "{name}");
            assert_eq!((f.depth_bits, f.stencil_bits), (depth, stencil), "{name}");
        }
        assert!(!lookup_vk("VK_FORMAT_R32_SFLOAT").unwrap().is_depth_format());
    }

    #[test]
    fn vulkan_names_find_the_first_dxgi_twin_then_vulkan_only_formats() {
        for f in all() {
            let Some(vk) = f.vk_format else { continue };
            let first = all().iter().find(|g| g.vk_format == Some(vk));
            assert_eq!(lookup_vk(vk).map(|g| g.name), first.map(|g| g.name), "{vk}");
            let lower = format!(" {} ", vk.to_ascii_lowercase());
            assert_eq!(lookup_vk(&lower).map(|g| g.name), first.map(|g| g.name));
        }
        assert_eq!(
            lookup_vk("VK_FORMAT_R8G8B8A8_UNORM").map(|f| f.name),
            Some("R8G8B8A8_UNORM")
        );
        let only = lookup_vk("vk_format_r4g4_unorm_pack8").map(|f| f.name);
        assert_eq!(only, Some("VK_FORMAT_R4G4_UNORM_PACK8"));
        assert!(lookup_vk("VK_FORMAT_NOT_A_FORMAT").is_none());
    }

    /// Every `VK_FORMAT_*` of the registry is represented: an image of any format is imported
    /// with it, and the lowering says whether and how it replays.
    #[test]
    fn every_registry_format_is_represented() {
        let names = crate::import::gfxr::tables::ENUMS
            .iter()
            .find(|e| e.name == "VkFormat")
            .expect("VkFormat in the registry")
            .values
            .iter()
            .map(|(_, n)| *n)
            .filter(|n| *n != "VK_FORMAT_UNDEFINED");
        let missing: Vec<&str> = names.filter(|n| lookup_vk(n).is_none()).collect();
        assert!(missing.is_empty(), "{} missing: {missing:?}", missing.len());
    }

    #[test]
    fn channels_are_derived_from_names() {
        let d = lookup("D32_FLOAT_S8X24_UINT").unwrap();
        assert_eq!(d.depth_bits, 32);
        assert_eq!(d.stencil_bits, 8);
        assert_eq!(d.channels.iter().map(|c| c.bits).sum::<u32>(), 64);
        let r = lookup("R10G10B10A2_UNORM").unwrap();
        assert_eq!(r.channels.len(), 4);
        assert!(r.channels.iter().all(|c| c.numeric == Numeric::Unorm));
        let f = lookup("R11G11B10_FLOAT").unwrap();
        assert_eq!(
            f.channels.iter().map(|c| c.bits).collect::<Vec<_>>(),
            vec![11, 11, 10]
        );
        // Every linear format's channel bits add up to its element size.
        for info in all()
            .iter()
            .filter(|f| f.layout == Layout::Linear && f.block_width == 1)
        {
            if info.channels.iter().all(|c| c.bits > 0) && !info.channels.is_empty() {
                let sum: u32 = info.channels.iter().map(|c| c.bits).sum();
                assert_eq!(sum, info.bits_per_element, "{}", info.name);
            }
        }
    }

    #[test]
    fn vulkan_names_find_their_dxgi_twin_or_their_own_entry() {
        assert_eq!(
            lookup("VK_FORMAT_B8G8R8A8_SRGB").map(|f| f.name),
            Some("B8G8R8A8_UNORM_SRGB")
        );
        let rgb = lookup("vk_format_r8g8b8_unorm").unwrap();
        assert_eq!(
            (rgb.name, rgb.bits_per_element, rgb.channels.len()),
            ("VK_FORMAT_R8G8B8_UNORM", 24, 3)
        );
        assert_eq!(rgb.surface_bytes(3, 2), Some(18));
        let ds = lookup("VK_FORMAT_D16_UNORM_S8_UINT").unwrap();
        assert_eq!((ds.depth_bits, ds.stencil_bits), (16, 8));
        let astc = lookup("VK_FORMAT_ASTC_6x6_SRGB_BLOCK").unwrap();
        assert!(astc.is_block_compressed() && astc.srgb);
        assert_eq!(astc.surface_bytes(12, 7), Some(2 * 2 * 16));
        assert!(lookup("VK_FORMAT_NOT_A_FORMAT").is_none());
    }

    #[test]
    fn typeless_families() {
        let family = |n: &str| lookup(n).unwrap().typeless_family;
        assert_eq!(family("R8G8B8A8_UNORM_SRGB"), Some("R8G8B8A8_TYPELESS"));
        assert_eq!(family("D32_FLOAT_S8X24_UINT"), Some("R32G8X24_TYPELESS"));
        assert_eq!(family("D16_UNORM"), Some("R16_TYPELESS"));
        assert_eq!(family("R16_UINT"), Some("R16_TYPELESS"));
        assert_eq!(family("B8G8R8A8_UNORM"), Some("B8G8R8A8_TYPELESS"));
        assert_eq!(family("BC7_UNORM_SRGB"), Some("BC7_TYPELESS"));
        assert_eq!(family("R11G11B10_FLOAT"), None);
        assert_eq!(family("R16_TYPELESS"), None);
    }

    #[test]
    fn lookup_accepts_prefix_and_case() {
        assert_eq!(
            lookup("dxgi_format_bc7_unorm_srgb").map(|f| f.value),
            Some(99)
        );
        assert_eq!(lookup("420_OPAQUE").map(|f| f.value), Some(106));
        assert!(lookup("R8G8B8A8_UNROM").is_none());
    }

    #[test]
    fn view_casting_rule() {
        let f = |n| lookup(n).unwrap();
        assert!(view_compatible(f("R16_TYPELESS"), f("D16_UNORM")));
        assert!(view_compatible(f("R16_TYPELESS"), f("R16_UNORM")));
        assert!(view_compatible(
            f("R32G8X24_TYPELESS"),
            f("R32_FLOAT_X8X24_TYPELESS")
        ));
        assert!(!view_compatible(
            f("R8G8B8A8_UNORM"),
            f("R8G8B8A8_UNORM_SRGB")
        ));
        assert!(!view_compatible(f("R16_TYPELESS"), f("R8G8_UNORM")));
    }

    #[test]
    fn surface_bytes_round_up_blocks() {
        let bc7 = lookup("BC7_UNORM").unwrap();
        assert_eq!(bc7.surface_bytes(1024, 1024), Some(1024 * 1024));
        assert_eq!(bc7.surface_bytes(1, 1), Some(16));
        let nv12 = lookup("NV12").unwrap();
        assert_eq!(nv12.surface_bytes(1920, 1080), Some(1920 * 1080 * 3 / 2));
    }
}
