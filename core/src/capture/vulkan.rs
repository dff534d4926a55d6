//! Vulkan's synchronisation vocabulary: pipeline stage and access bits, image layouts, and the
//! VkFormats without a DXGI twin.
//!
//! Imported captures keep their barriers in Vulkan's own terms (names without `VK_` and `_BIT`,
//! values of the `*2` enums, which extend the original ones bit for bit), so that validation can
//! check the names and the analysis can speak the application's language.

/// `VkPipelineStageFlagBits2`.
pub const STAGES: &[(&str, u64)] = &[
    ("TOP_OF_PIPE", 0x1),
    ("DRAW_INDIRECT", 0x2),
    ("VERTEX_INPUT", 0x4),
    ("VERTEX_SHADER", 0x8),
    ("TESSELLATION_CONTROL_SHADER", 0x10),
    ("TESSELLATION_EVALUATION_SHADER", 0x20),
    ("GEOMETRY_SHADER", 0x40),
    ("FRAGMENT_SHADER", 0x80),
    ("EARLY_FRAGMENT_TESTS", 0x100),
    ("LATE_FRAGMENT_TESTS", 0x200),
    ("COLOR_ATTACHMENT_OUTPUT", 0x400),
    ("COMPUTE_SHADER", 0x800),
    ("TRANSFER", 0x1000),
    ("BOTTOM_OF_PIPE", 0x2000),
    ("HOST", 0x4000),
    ("ALL_GRAPHICS", 0x8000),
    ("ALL_COMMANDS", 0x10000),
    ("COPY", 0x1_0000_0000),
    ("RESOLVE", 0x2_0000_0000),
    ("BLIT", 0x4_0000_0000),
    ("CLEAR", 0x8_0000_0000),
    ("INDEX_INPUT", 0x10_0000_0000),
    ("VERTEX_ATTRIBUTE_INPUT", 0x20_0000_0000),
    ("PRE_RASTERIZATION_SHADERS", 0x40_0000_0000),
];

/// `VkAccessFlagBits2`.
pub const ACCESS: &[(&str, u64)] = &[
    ("INDIRECT_COMMAND_READ", 0x1),
    ("INDEX_READ", 0x2),
    ("VERTEX_ATTRIBUTE_READ", 0x4),
    ("UNIFORM_READ", 0x8),
    ("INPUT_ATTACHMENT_READ", 0x10),
    ("SHADER_READ", 0x20),
    ("SHADER_WRITE", 0x40),
    ("COLOR_ATTACHMENT_READ", 0x80),
    ("COLOR_ATTACHMENT_WRITE", 0x100),
    ("DEPTH_STENCIL_ATTACHMENT_READ", 0x200),
    ("DEPTH_STENCIL_ATTACHMENT_WRITE", 0x400),
    ("TRANSFER_READ", 0x800),
    ("TRANSFER_WRITE", 0x1000),
    ("HOST_READ", 0x2000),
    ("HOST_WRITE", 0x4000),
    ("MEMORY_READ", 0x8000),
    ("MEMORY_WRITE", 0x10000),
    ("SHADER_SAMPLED_READ", 0x1_0000_0000),
    ("SHADER_STORAGE_READ", 0x2_0000_0000),
    ("SHADER_STORAGE_WRITE", 0x4_0000_0000),
];

/// `VkImageLayout` values framelab understands.
pub const LAYOUTS: &[(&str, u32)] = &[
    ("UNDEFINED", 0),
    ("GENERAL", 1),
    ("COLOR_ATTACHMENT_OPTIMAL", 2),
    ("DEPTH_STENCIL_ATTACHMENT_OPTIMAL", 3),
    ("DEPTH_STENCIL_READ_ONLY_OPTIMAL", 4),
    ("SHADER_READ_ONLY_OPTIMAL", 5),
    ("TRANSFER_SRC_OPTIMAL", 6),
    ("TRANSFER_DST_OPTIMAL", 7),
    ("PREINITIALIZED", 8),
    ("PRESENT_SRC_KHR", 1_000_001_002),
    ("SHARED_PRESENT_KHR", 1_000_111_000),
    ("DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL", 1_000_117_000),
    ("DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL", 1_000_117_001),
    ("DEPTH_ATTACHMENT_OPTIMAL", 1_000_241_000),
    ("DEPTH_READ_ONLY_OPTIMAL", 1_000_241_001),
    ("STENCIL_ATTACHMENT_OPTIMAL", 1_000_241_002),
    ("STENCIL_READ_ONLY_OPTIMAL", 1_000_241_003),
    ("READ_ONLY_OPTIMAL", 1_000_314_000),
    ("ATTACHMENT_OPTIMAL", 1_000_314_001),
];

pub mod stage {
    pub const TOP_OF_PIPE: u64 = 0x1;
    pub const DRAW_INDIRECT: u64 = 0x2;
    pub const VERTEX_INPUT: u64 = 0x4;
    pub const VERTEX_SHADER: u64 = 0x8;
    pub const FRAGMENT_SHADER: u64 = 0x80;
    pub const EARLY_FRAGMENT_TESTS: u64 = 0x100;
    pub const LATE_FRAGMENT_TESTS: u64 = 0x200;
    pub const COLOR_ATTACHMENT_OUTPUT: u64 = 0x400;
    pub const COMPUTE_SHADER: u64 = 0x800;
    pub const TRANSFER: u64 = 0x1000;
    pub const BOTTOM_OF_PIPE: u64 = 0x2000;
    pub const ALL_GRAPHICS: u64 = 0x8000;
    pub const ALL_COMMANDS: u64 = 0x10000;
    /// COPY, RESOLVE, BLIT and CLEAR: the parts of TRANSFER.
    pub const TRANSFER_PARTS: u64 = 0xF_0000_0000;
    /// INDEX_INPUT and VERTEX_ATTRIBUTE_INPUT: the parts of VERTEX_INPUT.
    pub const VERTEX_INPUT_PARTS: u64 = 0x30_0000_0000;
    pub const PRE_RASTERIZATION_SHADERS: u64 = 0x40_0000_0000;
    /// Vertex, tessellation and geometry shaders.
    pub const PRE_RASTERIZATION_PARTS: u64 = 0x78;
    /// Every stage ALL_GRAPHICS stands for.
    pub const GRAPHICS: u64 = 0x7FF & !COMPUTE_SHADER
        | VERTEX_INPUT_PARTS
        | PRE_RASTERIZATION_SHADERS
        | TOP_OF_PIPE
        | BOTTOM_OF_PIPE;
}

pub mod access {
    pub const INDIRECT_COMMAND_READ: u64 = 0x1;
    pub const INDEX_READ: u64 = 0x2;
    pub const VERTEX_ATTRIBUTE_READ: u64 = 0x4;
    pub const UNIFORM_READ: u64 = 0x8;
    pub const SHADER_READ: u64 = 0x20;
    pub const SHADER_WRITE: u64 = 0x40;
    pub const COLOR_ATTACHMENT_READ: u64 = 0x80;
    pub const COLOR_ATTACHMENT_WRITE: u64 = 0x100;
    pub const DEPTH_STENCIL_ATTACHMENT_READ: u64 = 0x200;
    pub const DEPTH_STENCIL_ATTACHMENT_WRITE: u64 = 0x400;
    pub const TRANSFER_READ: u64 = 0x800;
    pub const TRANSFER_WRITE: u64 = 0x1000;
    pub const MEMORY_READ: u64 = 0x8000;
    pub const MEMORY_WRITE: u64 = 0x10000;
    pub const SHADER_SAMPLED_READ: u64 = 0x1_0000_0000;
    pub const SHADER_STORAGE_READ: u64 = 0x2_0000_0000;
    pub const SHADER_STORAGE_WRITE: u64 = 0x4_0000_0000;
    /// Every write bit.
    pub const WRITES: u64 = SHADER_WRITE
        | COLOR_ATTACHMENT_WRITE
        | DEPTH_STENCIL_ATTACHMENT_WRITE
        | TRANSFER_WRITE
        | 0x4000
        | MEMORY_WRITE
        | SHADER_STORAGE_WRITE;
}

/// Stages a mask stands for, with ALL_COMMANDS, ALL_GRAPHICS and the stages the original
/// enum grouped (TRANSFER, VERTEX_INPUT, PRE_RASTERIZATION_SHADERS) spelt out both ways.
pub fn expand_stages(mask: u64) -> u64 {
    use stage::*;
    let mut m = mask;
    if m & ALL_COMMANDS != 0 {
        return u64::MAX;
    }
    if m & ALL_GRAPHICS != 0 {
        m |= GRAPHICS;
    }
    if m & TRANSFER != 0 {
        m |= TRANSFER_PARTS;
    }
    if m & VERTEX_INPUT != 0 {
        m |= VERTEX_INPUT_PARTS;
    }
    if m & PRE_RASTERIZATION_SHADERS != 0 {
        m |= PRE_RASTERIZATION_PARTS;
    }
    m
}

/// Accesses a mask stands for: MEMORY_READ/WRITE cover every read/write, SHADER_READ/WRITE the
/// sampled and storage accesses of the `*2` enum.
pub fn expand_access(mask: u64) -> u64 {
    use access::*;
    let mut m = mask;
    if m & MEMORY_READ != 0 {
        m |= !WRITES;
    }
    if m & MEMORY_WRITE != 0 {
        m |= WRITES;
    }
    if m & SHADER_READ != 0 {
        m |= SHADER_SAMPLED_READ | SHADER_STORAGE_READ;
    }
    if m & SHADER_WRITE != 0 {
        m |= SHADER_STORAGE_WRITE;
    }
    m
}

/// The names of the bits set in `mask` (in table order); bits the table lacks as hex.
pub fn mask_names(table: &[(&str, u64)], mask: u64) -> Vec<String> {
    let mut rest = mask;
    let mut out: Vec<String> = table
        .iter()
        .filter(|(_, v)| mask & v != 0)
        .map(|(n, v)| {
            rest &= !v;
            (*n).to_owned()
        })
        .collect();
    if rest != 0 {
        out.push(format!("{rest:#x}"));
    }
    out
}

/// The mask the names stand for; the first unknown name as the error.
pub fn parse_mask<'a>(
    table: &[(&str, u64)],
    names: impl IntoIterator<Item = &'a String>,
) -> Result<u64, &'a str> {
    let mut mask = 0;
    for n in names {
        if let Some(hex) = n.strip_prefix("0x") {
            mask |= u64::from_str_radix(hex, 16).map_err(|_| n.as_str())?;
            continue;
        }
        let bare = bare_name(n);
        let (_, v) = table.iter().find(|(t, _)| *t == bare).ok_or(n.as_str())?;
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

/// The layout a name (with or without `VK_IMAGE_LAYOUT_`) stands for.
pub fn layout(name: &str) -> Option<&'static str> {
    let bare = bare_name(name);
    LAYOUTS.iter().find(|(n, _)| *n == bare).map(|(n, _)| *n)
}

/// The layout with this numeric value.
pub fn layout_by_value(value: u64) -> Option<&'static str> {
    LAYOUTS
        .iter()
        .find(|(_, v)| u64::from(*v) == value)
        .map(|(n, _)| *n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_round_trip_through_names() {
        let m = 0x400 | 0x1_0000_0000;
        let names = mask_names(STAGES, m);
        assert_eq!(names, ["COLOR_ATTACHMENT_OUTPUT", "COPY"]);
        assert_eq!(parse_mask(STAGES, &names), Ok(m));
        let full = vec!["VK_PIPELINE_STAGE_2_TRANSFER_BIT".to_owned()];
        assert_eq!(parse_mask(STAGES, &full), Ok(0x1000));
        let bad = vec!["SHADING".to_owned()];
        assert_eq!(parse_mask(STAGES, &bad), Err("SHADING"));
        assert_eq!(mask_names(ACCESS, 0x8_0000_0000_0000), ["0x8000000000000"]);
    }

    #[test]
    fn groups_expand_to_their_parts() {
        assert!(expand_stages(stage::ALL_GRAPHICS) & stage::FRAGMENT_SHADER != 0);
        assert!(expand_stages(stage::ALL_GRAPHICS) & stage::COMPUTE_SHADER == 0);
        assert!(expand_stages(stage::TRANSFER) & 0x1_0000_0000 != 0);
        assert!(expand_access(access::MEMORY_READ) & access::TRANSFER_READ != 0);
        assert!(expand_access(access::MEMORY_READ) & access::TRANSFER_WRITE == 0);
        assert_eq!(
            layout("VK_IMAGE_LAYOUT_PRESENT_SRC_KHR"),
            Some("PRESENT_SRC_KHR")
        );
        assert_eq!(layout_by_value(7), Some("TRANSFER_DST_OPTIMAL"));
    }
}
