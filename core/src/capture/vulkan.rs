//! Vulkan's synchronisation vocabulary as types: pipeline stages and access flags as bit sets
//! over the `*2` enums' values, image layouts as an enum.
//!
//! Imported captures keep their barriers in Vulkan's own terms, so that validation can check
//! them and the analysis can speak the application's language. Names (without `VK_` and
//! `_BIT`) are parsed once, when a capture is validated or imported, and spelled only when
//! text or JSON is written; everything in between compares values.

/// The most push-constant bytes any device takes (`maxPushConstantsSize` is at least 128;
/// none framelab replays on offers more than 256): imports and validation hold to it.
pub const MAX_PUSH_CONSTANT_BYTES: u32 = 256;

use std::borrow::Cow;
use std::fmt;
use std::ops::{BitAnd, BitOr, BitOrAssign, Not};

/// A bit set over one of Vulkan's `*FlagBits2` enums, with the named bits in the enum's order
/// (which is the order names are written in).
macro_rules! vk_flags {
    ($(#[$doc:meta])* $ty:ident { $($bit:ident = $value:expr,)* }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct $ty(u64);

        #[allow(dead_code)]
        impl $ty {
            $(pub const $bit: Self = Self($value);)*
            pub const EMPTY: Self = Self(0);
            /// Every named bit with its name, in the enum's order.
            pub const NAMES: &'static [(&'static str, u64)] = &[$((stringify!($bit), $value),)*];

            pub const fn from_bits(bits: u64) -> Self {
                Self(bits)
            }

            pub const fn bits(self) -> u64 {
                self.0
            }

            pub const fn is_empty(self) -> bool {
                self.0 == 0
            }

            /// Whether any bit of `other` is set here.
            pub const fn intersects(self, other: Self) -> bool {
                self.0 & other.0 != 0
            }

            /// The names of the bits set (in the enum's order), borrowed from the table; bits
            /// without a name as hex.
            pub fn names(self) -> Vec<Cow<'static, str>> {
                mask_names(Self::NAMES, self.0)
            }

            /// The set the names stand for (with or without `VK_..._` and `_BIT`, or `0x` hex);
            /// the first unknown name as the error.
            pub fn parse<'a, S: AsRef<str> + 'a>(
                names: impl IntoIterator<Item = &'a S>,
            ) -> Result<Self, UnknownName<'a>> {
                parse_mask(Self::NAMES, names).map(Self)
            }
        }

        /// `NONE` for the empty set, else the names joined by `|`.
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                if self.is_empty() {
                    f.write_str("NONE")
                } else {
                    f.write_str(&self.names().join("|"))
                }
            }
        }

        impl BitOr for $ty {
            type Output = Self;
            fn bitor(self, rhs: Self) -> Self {
                Self(self.0 | rhs.0)
            }
        }

        impl BitOrAssign for $ty {
            fn bitor_assign(&mut self, rhs: Self) {
                self.0 |= rhs.0;
            }
        }

        impl BitAnd for $ty {
            type Output = Self;
            fn bitand(self, rhs: Self) -> Self {
                Self(self.0 & rhs.0)
            }
        }

        impl Not for $ty {
            type Output = Self;
            fn not(self) -> Self {
                Self(!self.0)
            }
        }
    };
}

vk_flags! {
    /// `VkPipelineStageFlagBits2`.
    PipelineStages {
        TOP_OF_PIPE = 0x1,
        DRAW_INDIRECT = 0x2,
        VERTEX_INPUT = 0x4,
        VERTEX_SHADER = 0x8,
        TESSELLATION_CONTROL_SHADER = 0x10,
        TESSELLATION_EVALUATION_SHADER = 0x20,
        GEOMETRY_SHADER = 0x40,
        FRAGMENT_SHADER = 0x80,
        EARLY_FRAGMENT_TESTS = 0x100,
        LATE_FRAGMENT_TESTS = 0x200,
        COLOR_ATTACHMENT_OUTPUT = 0x400,
        COMPUTE_SHADER = 0x800,
        TRANSFER = 0x1000,
        BOTTOM_OF_PIPE = 0x2000,
        HOST = 0x4000,
        ALL_GRAPHICS = 0x8000,
        ALL_COMMANDS = 0x10000,
        COPY = 0x1_0000_0000,
        RESOLVE = 0x2_0000_0000,
        BLIT = 0x4_0000_0000,
        CLEAR = 0x8_0000_0000,
        INDEX_INPUT = 0x10_0000_0000,
        VERTEX_ATTRIBUTE_INPUT = 0x20_0000_0000,
        PRE_RASTERIZATION_SHADERS = 0x40_0000_0000,
    }
}

vk_flags! {
    /// `VkAccessFlagBits2`.
    AccessFlags {
        INDIRECT_COMMAND_READ = 0x1,
        INDEX_READ = 0x2,
        VERTEX_ATTRIBUTE_READ = 0x4,
        UNIFORM_READ = 0x8,
        INPUT_ATTACHMENT_READ = 0x10,
        SHADER_READ = 0x20,
        SHADER_WRITE = 0x40,
        COLOR_ATTACHMENT_READ = 0x80,
        COLOR_ATTACHMENT_WRITE = 0x100,
        DEPTH_STENCIL_ATTACHMENT_READ = 0x200,
        DEPTH_STENCIL_ATTACHMENT_WRITE = 0x400,
        TRANSFER_READ = 0x800,
        TRANSFER_WRITE = 0x1000,
        HOST_READ = 0x2000,
        HOST_WRITE = 0x4000,
        MEMORY_READ = 0x8000,
        MEMORY_WRITE = 0x10000,
        SHADER_SAMPLED_READ = 0x1_0000_0000,
        SHADER_STORAGE_READ = 0x2_0000_0000,
        SHADER_STORAGE_WRITE = 0x4_0000_0000,
    }
}

impl PipelineStages {
    /// COPY, RESOLVE, BLIT and CLEAR: the parts of TRANSFER.
    pub const TRANSFER_PARTS: Self = Self(0xF_0000_0000);
    /// INDEX_INPUT and VERTEX_ATTRIBUTE_INPUT: the parts of VERTEX_INPUT.
    pub const VERTEX_INPUT_PARTS: Self = Self(0x30_0000_0000);
    /// Vertex, tessellation and geometry shaders.
    pub const PRE_RASTERIZATION_PARTS: Self = Self(0x78);
    /// Every stage ALL_GRAPHICS stands for.
    pub const GRAPHICS: Self = Self(
        0x7FF & !Self::COMPUTE_SHADER.0
            | Self::VERTEX_INPUT_PARTS.0
            | Self::PRE_RASTERIZATION_SHADERS.0
            | Self::TOP_OF_PIPE.0
            | Self::BOTTOM_OF_PIPE.0,
    );

    /// The stages this set stands for, with ALL_COMMANDS, ALL_GRAPHICS and the stages the
    /// original enum grouped (TRANSFER, VERTEX_INPUT, PRE_RASTERIZATION_SHADERS) spelt out both
    /// ways, so that sets written in either enum's terms compare.
    pub fn expand(self) -> Self {
        if self.intersects(Self::ALL_COMMANDS) {
            return Self(u64::MAX);
        }
        let mut m = self;
        for (group, parts) in [
            (Self::ALL_GRAPHICS, Self::GRAPHICS),
            (Self::TRANSFER, Self::TRANSFER_PARTS),
            (Self::VERTEX_INPUT, Self::VERTEX_INPUT_PARTS),
            (
                Self::PRE_RASTERIZATION_SHADERS,
                Self::PRE_RASTERIZATION_PARTS,
            ),
        ] {
            if m.intersects(group) {
                m |= parts;
            }
        }
        m
    }
}

impl AccessFlags {
    /// Every write bit.
    pub const WRITES: Self = Self(
        Self::SHADER_WRITE.0
            | Self::COLOR_ATTACHMENT_WRITE.0
            | Self::DEPTH_STENCIL_ATTACHMENT_WRITE.0
            | Self::TRANSFER_WRITE.0
            | Self::HOST_WRITE.0
            | Self::MEMORY_WRITE.0
            | Self::SHADER_STORAGE_WRITE.0,
    );

    /// The accesses this set stands for: MEMORY_READ/WRITE cover every read/write,
    /// SHADER_READ/WRITE the sampled and storage accesses of the `*2` enum.
    pub fn expand(self) -> Self {
        let mut m = self;
        if m.intersects(Self::MEMORY_READ) {
            m |= !Self::WRITES;
        }
        if m.intersects(Self::MEMORY_WRITE) {
            m |= Self::WRITES;
        }
        if m.intersects(Self::SHADER_READ) {
            m |= Self::SHADER_SAMPLED_READ | Self::SHADER_STORAGE_READ;
        }
        if m.intersects(Self::SHADER_WRITE) {
            m |= Self::SHADER_STORAGE_WRITE;
        }
        m
    }
}

/// `VkImageLayout`s framelab understands, each with its value and its name.
macro_rules! vk_layouts {
    ($($variant:ident = $name:literal $value:literal,)*) => {
        /// `VkImageLayout`.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum ImageLayout {
            $($variant,)*
        }

        impl ImageLayout {
            pub const ALL: &'static [ImageLayout] = &[$(ImageLayout::$variant,)*];

            /// The name without `VK_IMAGE_LAYOUT_`, as captures and reports spell it.
            pub const fn name(self) -> &'static str {
                match self {
                    $(ImageLayout::$variant => $name,)*
                }
            }

            /// The `VkImageLayout` value.
            pub const fn value(self) -> u32 {
                match self {
                    $(ImageLayout::$variant => $value,)*
                }
            }
        }
    };
}

vk_layouts! {
    Undefined = "UNDEFINED" 0,
    General = "GENERAL" 1,
    ColorAttachmentOptimal = "COLOR_ATTACHMENT_OPTIMAL" 2,
    DepthStencilAttachmentOptimal = "DEPTH_STENCIL_ATTACHMENT_OPTIMAL" 3,
    DepthStencilReadOnlyOptimal = "DEPTH_STENCIL_READ_ONLY_OPTIMAL" 4,
    ShaderReadOnlyOptimal = "SHADER_READ_ONLY_OPTIMAL" 5,
    TransferSrcOptimal = "TRANSFER_SRC_OPTIMAL" 6,
    TransferDstOptimal = "TRANSFER_DST_OPTIMAL" 7,
    Preinitialized = "PREINITIALIZED" 8,
    PresentSrc = "PRESENT_SRC_KHR" 1_000_001_002,
    SharedPresent = "SHARED_PRESENT_KHR" 1_000_111_000,
    DepthReadOnlyStencilAttachmentOptimal = "DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL" 1_000_117_000,
    DepthAttachmentStencilReadOnlyOptimal = "DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL" 1_000_117_001,
    DepthAttachmentOptimal = "DEPTH_ATTACHMENT_OPTIMAL" 1_000_241_000,
    DepthReadOnlyOptimal = "DEPTH_READ_ONLY_OPTIMAL" 1_000_241_001,
    StencilAttachmentOptimal = "STENCIL_ATTACHMENT_OPTIMAL" 1_000_241_002,
    StencilReadOnlyOptimal = "STENCIL_READ_ONLY_OPTIMAL" 1_000_241_003,
    ReadOnlyOptimal = "READ_ONLY_OPTIMAL" 1_000_314_000,
    AttachmentOptimal = "ATTACHMENT_OPTIMAL" 1_000_314_001,
}

impl ImageLayout {
    /// The layout a name (with or without `VK_IMAGE_LAYOUT_`) stands for.
    pub fn from_name(name: &str) -> Option<Self> {
        let bare = bare_name(name);
        Self::ALL.iter().copied().find(|l| l.name() == bare)
    }

    /// The layout with this numeric value.
    pub fn from_value(value: u64) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|l| u64::from(l.value()) == value)
    }

    /// A layout only reads may use (an attachment in it is read-only).
    pub fn is_read_only(self) -> bool {
        self.name().contains("READ_ONLY")
    }

    /// Whether a depth/stencil attachment in this layout may not write its stencil aspect:
    /// read-only for it (`DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL`, the read-only layouts)
    /// where `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL` leaves the stencil writable.
    pub fn stencil_read_only(self) -> bool {
        let n = self.name();
        n.contains("READ_ONLY") && !n.contains("STENCIL_ATTACHMENT")
    }

    /// Whether a depth/stencil attachment in this layout may not write its depth aspect.
    pub fn depth_read_only(self) -> bool {
        let n = self.name();
        n.contains("READ_ONLY") && !n.starts_with("DEPTH_ATTACHMENT")
    }

    /// Whether an image in this layout serves a use that needs `needed`: the same layout,
    /// GENERAL (for anything but presenting), or one of the `*2` catch-all layouts.
    pub fn serves(self, needed: Self) -> bool {
        use ImageLayout as L;
        self == needed
            || (self == L::General && needed != L::PresentSrc)
            || (self == L::AttachmentOptimal
                && matches!(
                    needed,
                    L::ColorAttachmentOptimal | L::DepthStencilAttachmentOptimal
                ))
            || (self == L::ReadOnlyOptimal
                && matches!(
                    needed,
                    L::ShaderReadOnlyOptimal | L::DepthStencilReadOnlyOptimal
                ))
            || (needed == L::General && self != L::Undefined && self != L::PresentSrc)
    }
}

impl fmt::Display for ImageLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The names of the bits set in `mask` (in table order); bits the table lacks as hex.
fn mask_names(table: &[(&'static str, u64)], mask: u64) -> Vec<Cow<'static, str>> {
    let mut rest = mask;
    let mut out: Vec<Cow<'static, str>> = table
        .iter()
        .filter(|(_, v)| mask & v != 0)
        .map(|(n, v)| {
            rest &= !v;
            Cow::Borrowed(*n)
        })
        .collect();
    if rest != 0 {
        out.push(Cow::Owned(format!("{rest:#x}")));
    }
    out
}

/// The mask the names stand for; the first unknown name as the error.
/// A stage or access name that is not Vulkan's (validation names it with a suggestion).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown Vulkan name \"{0}\"")]
pub struct UnknownName<'a>(pub &'a str);

fn parse_mask<'a, S: AsRef<str> + 'a>(
    table: &[(&str, u64)],
    names: impl IntoIterator<Item = &'a S>,
) -> Result<u64, UnknownName<'a>> {
    let mut mask = 0;
    for n in names {
        let n = n.as_ref();
        if let Some(hex) = n.strip_prefix("0x") {
            mask |= u64::from_str_radix(hex, 16).map_err(|_| UnknownName(n))?;
            continue;
        }
        let bare = bare_name(n);
        let (_, v) = table
            .iter()
            .find(|(t, _)| *t == bare)
            .ok_or(UnknownName(n))?;
        mask |= v;
    }
    Ok(mask)
}

/// A Vulkan enumerant without its `VK_..._` prefix and `_BIT` suffix.
pub fn bare_name(name: &str) -> &str {
    let mut s = name.trim();
    for prefix in [
        "VK_PIPELINE_STAGE_2_",
        "VK_PIPELINE_STAGE_",
        "VK_ACCESS_2_",
        "VK_ACCESS_",
        "VK_IMAGE_LAYOUT_",
    ] {
        if let Some(rest) = s.strip_prefix(prefix) {
            s = rest;
            break;
        }
    }
    for suffix in ["_BIT_KHR", "_BIT"] {
        if let Some(rest) = s.strip_suffix(suffix) {
            return rest;
        }
    }
    s.strip_suffix("_KHR")
        .filter(|_| !s.ends_with("PRESENT_SRC_KHR") && !s.ends_with("SHARED_PRESENT_KHR"))
        .unwrap_or(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layouts that keep one aspect of a depth/stencil attachment writable.
    #[test]
    fn depth_and_stencil_are_read_only_apart() {
        use ImageLayout as L;
        let aspects = |l: L| (l.depth_read_only(), l.stencil_read_only());
        assert_eq!(aspects(L::DepthStencilAttachmentOptimal), (false, false));
        assert_eq!(aspects(L::DepthStencilReadOnlyOptimal), (true, true));
        assert_eq!(
            aspects(L::DepthReadOnlyStencilAttachmentOptimal),
            (true, false)
        );
        assert_eq!(
            aspects(L::DepthAttachmentStencilReadOnlyOptimal),
            (false, true)
        );
        assert_eq!(aspects(L::General), (false, false));
    }

    #[test]
    fn masks_round_trip_through_names() {
        let m = PipelineStages::COLOR_ATTACHMENT_OUTPUT | PipelineStages::COPY;
        let names = m.names();
        assert_eq!(names, ["COLOR_ATTACHMENT_OUTPUT", "COPY"]);
        assert_eq!(PipelineStages::parse(&names), Ok(m));
        let full = vec!["VK_PIPELINE_STAGE_2_TRANSFER_BIT".to_owned()];
        assert_eq!(PipelineStages::parse(&full), Ok(PipelineStages::TRANSFER));
        let bad = vec!["SHADING".to_owned()];
        assert_eq!(PipelineStages::parse(&bad), Err(UnknownName("SHADING")));
        assert_eq!(
            AccessFlags::from_bits(0x8_0000_0000_0000).names(),
            ["0x8000000000000"]
        );
        assert_eq!(AccessFlags::EMPTY.to_string(), "NONE");
    }

    #[test]
    fn groups_expand_to_their_parts() {
        type S = PipelineStages;
        type A = AccessFlags;
        assert!(S::ALL_GRAPHICS.expand().intersects(S::FRAGMENT_SHADER));
        assert!(!S::ALL_GRAPHICS.expand().intersects(S::COMPUTE_SHADER));
        assert!(S::TRANSFER.expand().intersects(S::COPY));
        assert!(A::MEMORY_READ.expand().intersects(A::TRANSFER_READ));
        assert!(!A::MEMORY_READ.expand().intersects(A::TRANSFER_WRITE));
        assert_eq!(
            ImageLayout::from_name("VK_IMAGE_LAYOUT_PRESENT_SRC_KHR"),
            Some(ImageLayout::PresentSrc)
        );
        assert_eq!(
            ImageLayout::from_value(7),
            Some(ImageLayout::TransferDstOptimal)
        );
        assert_eq!(ImageLayout::PresentSrc.to_string(), "PRESENT_SRC_KHR");
    }

    #[test]
    fn general_serves_all_but_presenting() {
        use ImageLayout as L;
        assert!(L::General.serves(L::ShaderReadOnlyOptimal));
        assert!(!L::General.serves(L::PresentSrc));
        assert!(L::ReadOnlyOptimal.serves(L::DepthStencilReadOnlyOptimal));
        assert!(!L::Undefined.serves(L::General));
    }
}
