//! Vulkan's fixed-function vocabulary at wgpu level: topology, rasterisation, depth and
//! stencil, blending, vertex formats and samplers, each from the enumerant names an imported
//! capture keeps. A name wgpu has no twin for is an error naming it, never a guess.

use wgpu_types as wgpu;

use crate::spirv::IntegerFetch;

use super::VkProblem;
use crate::capture::format::{
    BlendAttachment, DepthStencilVk, GraphicsState, StencilFaceVk, VkSampler,
};
use crate::plan::SamplerSpec;

fn unsupported(what: &str, name: &str) -> VkProblem {
    VkProblem::Unsupported {
        feature: format!("{what} {name}"),
    }
}

fn strip<'a>(name: &'a str, prefix: &str) -> &'a str {
    name.strip_prefix(prefix).unwrap_or(name)
}

pub(super) fn compare(name: &str) -> Result<wgpu::CompareFunction, VkProblem> {
    use wgpu::CompareFunction as C;
    Ok(match strip(name, "VK_COMPARE_OP_") {
        "NEVER" => C::Never,
        "LESS" => C::Less,
        "EQUAL" => C::Equal,
        "LESS_OR_EQUAL" => C::LessEqual,
        "GREATER" => C::Greater,
        "NOT_EQUAL" => C::NotEqual,
        "GREATER_OR_EQUAL" => C::GreaterEqual,
        "ALWAYS" => C::Always,
        _ => return Err(unsupported("compare op", name)),
    })
}

fn stencil_op(name: &str) -> Result<wgpu::StencilOperation, VkProblem> {
    use wgpu::StencilOperation as S;
    Ok(match strip(name, "VK_STENCIL_OP_") {
        "KEEP" => S::Keep,
        "ZERO" => S::Zero,
        "REPLACE" => S::Replace,
        "INVERT" => S::Invert,
        "INCREMENT_AND_CLAMP" => S::IncrementClamp,
        "DECREMENT_AND_CLAMP" => S::DecrementClamp,
        "INCREMENT_AND_WRAP" => S::IncrementWrap,
        "DECREMENT_AND_WRAP" => S::DecrementWrap,
        _ => return Err(unsupported("stencil op", name)),
    })
}

fn stencil_face(f: &StencilFaceVk) -> Result<wgpu::StencilFaceState, VkProblem> {
    Ok(wgpu::StencilFaceState {
        compare: compare(&f.compare_op)?,
        fail_op: stencil_op(&f.fail_op)?,
        depth_fail_op: stencil_op(&f.depth_fail_op)?,
        pass_op: stencil_op(&f.pass_op)?,
    })
}

/// The pipeline's primitive state. wgpu's strip topologies need the index format when
/// primitive restart is on; `strip_index` gives it from the draws.
pub(super) fn primitive(
    g: &GraphicsState,
    strip_index: Option<wgpu::IndexFormat>,
) -> Result<wgpu::PrimitiveState, VkProblem> {
    use wgpu::PrimitiveTopology as T;
    let topology = match strip(&g.topology, "VK_PRIMITIVE_TOPOLOGY_") {
        "POINT_LIST" => T::PointList,
        "LINE_LIST" => T::LineList,
        "LINE_STRIP" => T::LineStrip,
        "TRIANGLE_LIST" => T::TriangleList,
        "TRIANGLE_STRIP" => T::TriangleStrip,
        _ => return Err(unsupported("topology", &g.topology)),
    };
    let polygon_mode = match strip(&g.polygon_mode, "VK_POLYGON_MODE_") {
        "FILL" => wgpu::PolygonMode::Fill,
        "LINE" => wgpu::PolygonMode::Line,
        "POINT" => wgpu::PolygonMode::Point,
        _ => return Err(unsupported("polygon mode", &g.polygon_mode)),
    };
    // Culling applies to polygons: points and lines are never culled.
    let polygons = g.topology.contains("TRIANGLE");
    let cull_mode = match g.cull_mode {
        _ if !polygons => None,
        0 => None,
        1 => Some(wgpu::Face::Front),
        2 => Some(wgpu::Face::Back),
        _ => {
            return Err(VkProblem::Unsupported {
                feature: "cull mode FRONT_AND_BACK".to_owned(),
            });
        }
    };
    let front_face = match strip(&g.front_face, "VK_FRONT_FACE_") {
        "COUNTER_CLOCKWISE" => wgpu::FrontFace::Ccw,
        "CLOCKWISE" => wgpu::FrontFace::Cw,
        _ => return Err(unsupported("front face", &g.front_face)),
    };
    if g.rasterizer_discard {
        return Err(VkProblem::Unsupported {
            feature: "rasterizer discard".to_owned(),
        });
    }
    // The width is read only where lines are rasterized.
    if draws_lines(g) && g.line_width != 1.0 {
        return Err(VkProblem::Unsupported {
            feature: format!("line width {} (wgpu draws 1-pixel lines)", g.line_width),
        });
    }
    // wgpu draws indexed strips only with restart on (`restart_note` says when that is not
    // what Vulkan did).
    let strips = matches!(topology, T::LineStrip | T::TriangleStrip);
    Ok(wgpu::PrimitiveState {
        topology,
        strip_index_format: if strips { strip_index } else { None },
        front_face,
        cull_mode,
        unclipped_depth: g.depth_clamp,
        polygon_mode,
        conservative: false,
    })
}

/// Whether the pipeline rasterizes lines: a line topology, or polygons drawn as lines.
fn draws_lines(g: &GraphicsState) -> bool {
    g.topology.contains("_LINE_") || g.polygon_mode.ends_with("_LINE")
}

/// What the pipeline's line rasterization mode does to its lines: nothing where it draws none
/// or the mode is the default; Bresenham and rectangular lines of one pixel are drawn as
/// wgpu's (the driver's default mode, which the specification lets be either), said in a
/// note since pixels at a line's ends and along its edges may differ; smooth and stippled
/// lines, which wgpu has no way to draw, are refused.
pub(super) fn lines(g: &GraphicsState) -> Result<Option<String>, VkProblem> {
    if !draws_lines(g) {
        return Ok(None);
    }
    if g.line_stipple {
        return Err(VkProblem::Unsupported {
            feature: "stippled lines (wgpu has none)".to_owned(),
        });
    }
    match g.line_rasterization_mode.as_deref() {
        None => Ok(None),
        Some(m) if m.contains("SMOOTH") => Err(VkProblem::Unsupported {
            feature: format!("lines drawn in {m} (antialiased lines: wgpu has none)"),
        }),
        Some(m) => Ok(Some(format!(
            "lines drawn in {m} are drawn in the driver's default mode: pixels at their ends and edges may differ"
        ))),
    }
}

/// Where an indexed strip draws with primitive restart off: wgpu has no such draw, so it
/// draws with restart on, which is the same unless an index is the all-ones value (a 16-bit
/// index of 65535 names a vertex in Vulkan and restarts the strip in wgpu): said as a note.
pub(super) fn restart_note(
    g: &GraphicsState,
    strip_index: Option<wgpu::IndexFormat>,
) -> Option<String> {
    let strips = g.topology.ends_with("_STRIP");
    (strips && strip_index.is_some() && !g.primitive_restart).then(|| {
        format!(
            "indexed {} drawn with primitive restart on (wgpu's only indexed strip): the same unless an index is all ones",
            g.topology.trim_start_matches("VK_PRIMITIVE_TOPOLOGY_").to_lowercase()
        )
    })
}

/// Where wgpu cannot take a draw's depth bias constant factor as Vulkan gave it (wgpu's is a
/// whole number of the format's resolvable steps), what it takes instead, said as a note:
/// the nearest whole number, which moves each biased depth by under one resolvable step.
pub(super) fn bias_rounding(g: &GraphicsState) -> Option<String> {
    let [constant, ..] = g.depth_bias.filter(|_| g.topology.contains("TRIANGLE"))?;
    (constant.is_finite() && constant.fract() != 0.0).then(|| {
        format!(
            "depth bias constant factor {constant} taken as {} (wgpu takes whole numbers of the depth format's resolvable step; each biased depth moves by {:.2} of a step)",
            constant.round(),
            (constant - constant.round()).abs()
        )
    })
}

/// Depth and stencil for a pass whose depth target has `format`. A pipeline without depth
/// state in a pass with a depth target neither tests nor writes, which wgpu says as
/// `Always` and no writes.
pub(super) fn depth_stencil(
    g: &GraphicsState,
    format: wgpu::TextureFormat,
) -> Result<wgpu::DepthStencilState, VkProblem> {
    let off = DepthStencilVk::off();
    let d = g.depth_stencil.as_ref().unwrap_or(&off);
    if d.depth_bounds.is_some() {
        return Err(VkProblem::Unsupported {
            feature: "depth bounds test".to_owned(),
        });
    }
    let (depth_compare, depth_write) = if d.depth_test {
        (compare(&d.depth_compare)?, d.depth_write)
    } else {
        // Vulkan writes no depth when the test is off.
        (wgpu::CompareFunction::Always, false)
    };
    let stencil = match (d.stencil_test, &d.front, &d.back) {
        (true, Some(f), Some(b)) => {
            if f.compare_mask != b.compare_mask || f.write_mask != b.write_mask {
                return Err(VkProblem::Unsupported {
                    feature: "different stencil masks per face".to_owned(),
                });
            }
            crate::lower::states::reference_read(wgpu::StencilState {
                front: stencil_face(f)?,
                back: stencil_face(b)?,
                read_mask: f.compare_mask,
                write_mask: f.write_mask,
            })
        }
        _ => wgpu::StencilState::default(),
    };
    // Vulkan biases polygons only: a line or point topology draws unbiased.
    let polygons = g.topology.contains("TRIANGLE");
    let bias = match g.depth_bias.filter(|_| polygons) {
        Some([constant, clamp, slope]) => {
            if !constant.is_finite() || constant.abs() > 1.0e6 {
                return Err(VkProblem::Unsupported {
                    feature: format!("depth bias constant factor {constant}"),
                });
            }
            wgpu::DepthBiasState {
                constant: constant.round() as i32,
                slope_scale: slope,
                // Depths end in [0, 1]: a clamp of 1 or more in size changes no depth, and a
                // clamp needs a device feature wgpu's Vulkan backend does not turn on.
                clamp: if clamp.abs() >= 1.0 { 0.0 } else { clamp },
            }
        }
        None => wgpu::DepthBiasState::default(),
    };
    Ok(wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(depth_write),
        depth_compare: Some(depth_compare),
        stencil,
        bias,
    })
}

fn blend_factor(name: &str) -> Result<wgpu::BlendFactor, VkProblem> {
    use wgpu::BlendFactor as F;
    Ok(match strip(name, "VK_BLEND_FACTOR_") {
        "ZERO" => F::Zero,
        "ONE" => F::One,
        "SRC_COLOR" => F::Src,
        "ONE_MINUS_SRC_COLOR" => F::OneMinusSrc,
        "DST_COLOR" => F::Dst,
        "ONE_MINUS_DST_COLOR" => F::OneMinusDst,
        "SRC_ALPHA" => F::SrcAlpha,
        "ONE_MINUS_SRC_ALPHA" => F::OneMinusSrcAlpha,
        "DST_ALPHA" => F::DstAlpha,
        "ONE_MINUS_DST_ALPHA" => F::OneMinusDstAlpha,
        "CONSTANT_COLOR" | "CONSTANT_ALPHA" => F::Constant,
        "ONE_MINUS_CONSTANT_COLOR" | "ONE_MINUS_CONSTANT_ALPHA" => F::OneMinusConstant,
        "SRC_ALPHA_SATURATE" => F::SrcAlphaSaturated,
        // The fragment shader's second output (`Index` 1 in SPIR-V): wgpu's
        // DUAL_SOURCE_BLENDING, asked for by the pass (`uses_second_source`).
        "SRC1_COLOR" => F::Src1,
        "ONE_MINUS_SRC1_COLOR" => F::OneMinusSrc1,
        "SRC1_ALPHA" => F::Src1Alpha,
        "ONE_MINUS_SRC1_ALPHA" => F::OneMinusSrc1Alpha,
        _ => return Err(unsupported("blend factor", name)),
    })
}

fn blend_op(name: &str) -> Result<wgpu::BlendOperation, VkProblem> {
    use wgpu::BlendOperation as O;
    Ok(match strip(name, "VK_BLEND_OP_") {
        "ADD" => O::Add,
        "SUBTRACT" => O::Subtract,
        "REVERSE_SUBTRACT" => O::ReverseSubtract,
        "MIN" => O::Min,
        "MAX" => O::Max,
        _ => return Err(unsupported("blend op", name)),
    })
}

/// Whether the blend reads the pipeline's blend constants.
pub(super) fn uses_constant(b: &BlendAttachment) -> bool {
    b.enable
        && [&b.src_color, &b.dst_color, &b.src_alpha, &b.dst_alpha]
            .iter()
            .any(|f| f.contains("CONSTANT"))
}

/// Whether the blend reads the fragment shader's second output (dual-source blending).
pub(super) fn uses_second_source(b: &BlendAttachment) -> bool {
    b.enable
        && [&b.src_color, &b.dst_color, &b.src_alpha, &b.dst_alpha]
            .iter()
            .any(|f| f.contains("SRC1"))
}

/// One colour target's blend and write mask.
pub(super) fn color_target(
    format: wgpu::TextureFormat,
    b: Option<&BlendAttachment>,
) -> Result<wgpu::ColorTargetState, VkProblem> {
    let Some(b) = b else {
        return Ok(wgpu::ColorTargetState {
            format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        });
    };
    let blend = if b.enable {
        Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: blend_factor(&b.src_color)?,
                dst_factor: blend_factor(&b.dst_color)?,
                operation: blend_op(&b.color_op)?,
            },
            alpha: wgpu::BlendComponent {
                src_factor: blend_factor(&b.src_alpha)?,
                dst_factor: blend_factor(&b.dst_alpha)?,
                operation: blend_op(&b.alpha_op)?,
            },
        })
    } else {
        None
    };
    Ok(wgpu::ColorTargetState {
        format,
        blend,
        // VkColorComponentFlags and wgpu's ColorWrites share bits: R 1, G 2, B 4, A 8.
        write_mask: wgpu::ColorWrites::from_bits_truncate(b.write_mask & 0xf),
    })
}

/// The wgpu vertex format of a `VK_FORMAT_*` vertex attribute.
pub(super) fn vertex_format(name: &str) -> Result<wgpu::VertexFormat, VkProblem> {
    use wgpu::VertexFormat as V;
    Ok(match strip(name, "VK_FORMAT_") {
        "R8_UINT" => V::Uint8,
        "R8G8_UINT" => V::Uint8x2,
        "R8G8B8A8_UINT" => V::Uint8x4,
        "R8_SINT" => V::Sint8,
        "R8G8_SINT" => V::Sint8x2,
        "R8G8B8A8_SINT" => V::Sint8x4,
        "R8_UNORM" => V::Unorm8,
        "R8G8_UNORM" => V::Unorm8x2,
        "R8G8B8A8_UNORM" => V::Unorm8x4,
        "B8G8R8A8_UNORM" => V::Unorm8x4Bgra,
        "R8_SNORM" => V::Snorm8,
        "R8G8_SNORM" => V::Snorm8x2,
        "R8G8B8A8_SNORM" => V::Snorm8x4,
        "R16_UINT" => V::Uint16,
        "R16G16_UINT" => V::Uint16x2,
        "R16G16B16A16_UINT" => V::Uint16x4,
        "R16_SINT" => V::Sint16,
        "R16G16_SINT" => V::Sint16x2,
        "R16G16B16A16_SINT" => V::Sint16x4,
        "R16_UNORM" => V::Unorm16,
        "R16G16_UNORM" => V::Unorm16x2,
        "R16G16B16A16_UNORM" => V::Unorm16x4,
        "R16_SNORM" => V::Snorm16,
        "R16G16_SNORM" => V::Snorm16x2,
        "R16G16B16A16_SNORM" => V::Snorm16x4,
        "R16_SFLOAT" => V::Float16,
        "R16G16_SFLOAT" => V::Float16x2,
        "R16G16B16A16_SFLOAT" => V::Float16x4,
        "R32_SFLOAT" => V::Float32,
        "R32G32_SFLOAT" => V::Float32x2,
        "R32G32B32_SFLOAT" => V::Float32x3,
        "R32G32B32A32_SFLOAT" => V::Float32x4,
        "R32_UINT" => V::Uint32,
        "R32G32_UINT" => V::Uint32x2,
        "R32G32B32_UINT" => V::Uint32x3,
        "R32G32B32A32_UINT" => V::Uint32x4,
        "R32_SINT" => V::Sint32,
        "R32G32_SINT" => V::Sint32x2,
        "R32G32B32_SINT" => V::Sint32x3,
        "R32G32B32A32_SINT" => V::Sint32x4,
        "A2B10G10R10_UNORM_PACK32" => V::Unorm10_10_10_2,
        // Scaled formats (integers read as floats) fetched as the integers they hold; the
        // vertex shader converts them (`spirv::scaled`, `integer_fetch`).
        "R8_USCALED" => V::Uint8,
        "R8G8_USCALED" => V::Uint8x2,
        "R8G8B8A8_USCALED" => V::Uint8x4,
        "R8_SSCALED" => V::Sint8,
        "R8G8_SSCALED" => V::Sint8x2,
        "R8G8B8A8_SSCALED" => V::Sint8x4,
        "R16_USCALED" => V::Uint16,
        "R16G16_USCALED" => V::Uint16x2,
        "R16G16B16A16_USCALED" => V::Uint16x4,
        "R16_SSCALED" => V::Sint16,
        "R16G16_SSCALED" => V::Sint16x2,
        "R16G16B16A16_SSCALED" => V::Sint16x4,
        // Packed 2-10-10-10 formats wgpu lacks, fetched as their word and taken apart in
        // the vertex shader (`spirv::scaled`, `integer_fetch`).
        "A2B10G10R10_SNORM_PACK32"
        | "A2B10G10R10_USCALED_PACK32"
        | "A2B10G10R10_SSCALED_PACK32"
        | "A2R10G10B10_UNORM_PACK32"
        | "A2R10G10B10_SNORM_PACK32"
        | "A2R10G10B10_USCALED_PACK32"
        | "A2R10G10B10_SSCALED_PACK32" => V::Uint32,
        _ => return Err(unsupported("vertex format", name)),
    })
}

/// How the vertex format `name` is fetched where wgpu has no format for it (`vertex_format`):
/// a scaled format as its integers, a packed 2-10-10-10 one as its word; `None` for any other.
pub(super) fn integer_fetch(name: &str) -> Option<IntegerFetch> {
    let bare = strip(name, "VK_FORMAT_");
    vertex_format(name).ok()?;
    if let Some(packing) = bare.strip_suffix("_PACK32") {
        let red_low = packing.starts_with("A2B10G10R10");
        let kind = packing.rsplit('_').next()?;
        if bare == "A2B10G10R10_UNORM_PACK32" {
            return None;
        }
        return Some(IntegerFetch::Packed {
            red_low,
            signed: kind.starts_with('S'),
            normalized: kind.ends_with("NORM"),
        });
    }
    let signed = bare.ends_with("_SSCALED");
    (signed || bare.ends_with("_USCALED")).then_some(IntegerFetch::Scaled { signed })
}

/// Whether sampler `s`'s LOD bias changes nothing read through a view of `levels` mip
/// levels: with one level reachable the bias moves no level, and with the same filter up
/// and down it picks no other filter. wgpu has no LOD bias, so elsewhere it is refused.
pub(super) fn bias_is_moot(s: &VkSampler, levels: u32) -> bool {
    let one_level = levels <= 1 || s.max_lod <= s.min_lod;
    s.mip_lod_bias == 0.0 || (one_level && s.mag_filter == s.min_filter)
}

/// The axes on which sampler `s` mirrors once and clamps (bit 0 `u`, 1 `v`, 2 `w`), which
/// the shader's rewrite mirrors (`spirv::mirror_once`) before the sampler clamps to the edge.
pub(super) fn mirror_once_axes(s: &VkSampler) -> u8 {
    [&s.address_mode_u, &s.address_mode_v, &s.address_mode_w]
        .iter()
        .enumerate()
        .filter(|(_, m)| strip(m, "VK_SAMPLER_ADDRESS_MODE_") == "MIRROR_CLAMP_TO_EDGE")
        .fold(0, |axes, (i, _)| axes | (1 << i))
}

/// A Vulkan sampler at wgpu level (its LOD bias is checked where it meets a view:
/// `bias_is_moot`).
pub(super) fn sampler(s: &VkSampler) -> Result<SamplerSpec, VkProblem> {
    let filter = |n: &str| match strip(n, "VK_FILTER_") {
        "NEAREST" => Ok(wgpu::FilterMode::Nearest),
        "LINEAR" => Ok(wgpu::FilterMode::Linear),
        _ => Err(unsupported("filter", n)),
    };
    let address = |n: &str| match strip(n, "VK_SAMPLER_ADDRESS_MODE_") {
        "REPEAT" => Ok(wgpu::AddressMode::Repeat),
        "MIRRORED_REPEAT" => Ok(wgpu::AddressMode::MirrorRepeat),
        "CLAMP_TO_EDGE" => Ok(wgpu::AddressMode::ClampToEdge),
        "CLAMP_TO_BORDER" => Ok(wgpu::AddressMode::ClampToBorder),
        // Mirrored once in the shader (`spirv::mirror_once`, `mirror_once_axes`), then
        // clamped here.
        "MIRROR_CLAMP_TO_EDGE" => Ok(wgpu::AddressMode::ClampToEdge),
        _ => Err(unsupported(
            &format!("sampler {} with address mode", s.name),
            n,
        )),
    };
    // Unnormalized coordinates are divided by the image's size in the shader
    // (`spirv::unnormalized`): the sampler itself takes normalized ones.
    let mip = match strip(&s.mipmap_mode, "VK_SAMPLER_MIPMAP_MODE_") {
        "NEAREST" => wgpu::MipmapFilterMode::Nearest,
        "LINEAR" => wgpu::MipmapFilterMode::Linear,
        _ => return Err(unsupported("mipmap mode", &s.mipmap_mode)),
    };
    let address = [
        address(&s.address_mode_u)?,
        address(&s.address_mode_v)?,
        address(&s.address_mode_w)?,
    ];
    // The border colour is read only where an address clamps to it.
    let border = if address.contains(&wgpu::AddressMode::ClampToBorder) {
        Some(border_color(s)?)
    } else {
        None
    };
    Ok(SamplerSpec {
        name: s.name.clone(),
        address,
        border,
        mag: filter(&s.mag_filter)?,
        min: filter(&s.min_filter)?,
        mip,
        lod: lod_clamp(s.min_lod, s.max_lod),
        compare: s.compare_op.as_deref().map(compare).transpose()?,
        anisotropy: s.max_anisotropy.map_or(1, |a| a.clamp(1.0, 16.0) as u16),
    })
    .map(|mut spec| {
        // Vulkan leaves the anisotropic filtering scheme to the implementation ("should
        // consider" the filters); wgpu filters anisotropically only with every filter linear,
        // which is what lavapipe does with nearest filters too (`anisotropic_nearest`).
        if spec.anisotropy > 1 {
            spec.mag = wgpu::FilterMode::Linear;
            spec.min = wgpu::FilterMode::Linear;
            spec.mip = wgpu::MipmapFilterMode::Linear;
        }
        spec
    })
}

/// Sampler `s`'s border colour as wgpu has it. A custom colour wgpu has as one of its own is
/// that one: transparent black of either type (all bits zero), opaque black or white as
/// floats.
fn border_color(s: &VkSampler) -> Result<wgpu::SamplerBorderColor, VkProblem> {
    use wgpu::SamplerBorderColor as B;
    let kind = strip(&s.border_color, "VK_BORDER_COLOR_");
    Ok(match (kind, s.custom_border_color) {
        ("FLOAT_TRANSPARENT_BLACK" | "INT_TRANSPARENT_BLACK", _) => B::TransparentBlack,
        ("FLOAT_OPAQUE_BLACK", _) => B::OpaqueBlack,
        ("FLOAT_OPAQUE_WHITE", _) => B::OpaqueWhite,
        ("FLOAT_CUSTOM_EXT" | "INT_CUSTOM_EXT", Some([0.0, 0.0, 0.0, 0.0])) => B::TransparentBlack,
        ("FLOAT_CUSTOM_EXT", Some([0.0, 0.0, 0.0, 1.0])) => B::OpaqueBlack,
        ("FLOAT_CUSTOM_EXT", Some([1.0, 1.0, 1.0, 1.0])) => B::OpaqueWhite,
        (_, Some(c)) => {
            return Err(unsupported(
                &format!(
                    "sampler {} with a custom border colour ({}, {}, {}, {}; wgpu has transparent black, opaque black and opaque white) of type",
                    s.name, c[0], c[1], c[2], c[3]
                ),
                &s.border_color,
            ));
        }
        _ => {
            return Err(unsupported(
                &format!("sampler {} with border colour", s.name),
                &s.border_color,
            ));
        }
    })
}

/// Where sampler `s` filters anisotropically with a nearest filter, what the replay does,
/// said as a note: the specification leaves the scheme to the implementation.
pub(super) fn anisotropic_nearest(s: &VkSampler) -> Option<String> {
    let nearest = [&s.mag_filter, &s.min_filter, &s.mipmap_mode]
        .iter()
        .any(|f| f.ends_with("NEAREST"));
    (s.max_anisotropy.is_some_and(|a| a > 1.0) && nearest).then(|| {
        format!(
            "sampler {}: anisotropic filtering with a nearest filter is left to the implementation; replayed with every filter linear (as lavapipe filters it)",
            s.name
        )
    })
}

/// Vulkan's `minLod`/`maxLod` as wgpu's clamps, which must be at least 0 and in order. A
/// negative bound (ImGui's samplers say -1000) changes nothing: Vulkan clamps the computed
/// LOD into [minLod, maxLod], magnifies at LOD 0 or less and reads level 0 there, exactly
/// as with the bound at 0.
fn lod_clamp(min: f32, max: f32) -> (f32, f32) {
    let finite = |x: f32, or: f32| if x.is_nan() { or } else { x };
    let min = finite(min, 0.0).max(0.0);
    (min, finite(max, 1000.0).max(min))
}

/// The wgpu storage format of a SPIR-V storage image's declared format, among those WebGPU
/// can bind as storage.
pub(super) fn storage_format(f: rspirv::spirv::ImageFormat) -> Option<wgpu::TextureFormat> {
    use rspirv::spirv::ImageFormat as I;
    use wgpu::TextureFormat as T;
    Some(match f {
        I::Rgba8 => T::Rgba8Unorm,
        I::Rgba8Snorm => T::Rgba8Snorm,
        I::Rgba8ui => T::Rgba8Uint,
        I::Rgba8i => T::Rgba8Sint,
        I::Rgba16f => T::Rgba16Float,
        I::Rgba16ui => T::Rgba16Uint,
        I::Rgba16i => T::Rgba16Sint,
        I::Rgba32f => T::Rgba32Float,
        I::Rgba32ui => T::Rgba32Uint,
        I::Rgba32i => T::Rgba32Sint,
        I::Rg32f => T::Rg32Float,
        I::Rg32ui => T::Rg32Uint,
        I::Rg32i => T::Rg32Sint,
        I::R32f => T::R32Float,
        I::R32ui => T::R32Uint,
        I::R32i => T::R32Sint,
        _ => return None,
    })
}

/// How a storage image variable is accessed, from its decorations.
pub(super) fn storage_access(var: &crate::spirv::ResourceVar) -> wgpu::StorageTextureAccess {
    if var.non_writable {
        wgpu::StorageTextureAccess::ReadOnly
    } else if var.non_readable {
        wgpu::StorageTextureAccess::WriteOnly
    } else {
        wgpu::StorageTextureAccess::ReadWrite
    }
}
