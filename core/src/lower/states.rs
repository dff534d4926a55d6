//! Fixed-function state at wgpu level: compare functions, stencil, blending, primitive
//! assembly, depth-stencil state, colour write masks and samplers.

use crate::plan::*;
use wgpu_types as wgpu;

use crate::capture::format::{self as cf, RenderState};

pub(super) fn compare(c: cf::CompareFunction) -> wgpu::CompareFunction {
    use cf::CompareFunction as C;
    match c {
        C::Never => wgpu::CompareFunction::Never,
        C::Less => wgpu::CompareFunction::Less,
        C::Equal => wgpu::CompareFunction::Equal,
        C::LessEqual => wgpu::CompareFunction::LessEqual,
        C::Greater => wgpu::CompareFunction::Greater,
        C::NotEqual => wgpu::CompareFunction::NotEqual,
        C::GreaterEqual => wgpu::CompareFunction::GreaterEqual,
        C::Always => wgpu::CompareFunction::Always,
    }
}

pub(super) fn stencil_op(o: cf::StencilOp) -> wgpu::StencilOperation {
    use cf::StencilOp as S;
    match o {
        S::Keep => wgpu::StencilOperation::Keep,
        S::Zero => wgpu::StencilOperation::Zero,
        S::Replace => wgpu::StencilOperation::Replace,
        S::Invert => wgpu::StencilOperation::Invert,
        S::IncrementClamp => wgpu::StencilOperation::IncrementClamp,
        S::DecrementClamp => wgpu::StencilOperation::DecrementClamp,
        S::IncrementWrap => wgpu::StencilOperation::IncrementWrap,
        S::DecrementWrap => wgpu::StencilOperation::DecrementWrap,
    }
}

pub(super) fn blend(b: &cf::Blend) -> Option<wgpu::BlendState> {
    use cf::{BlendFactor as F, BlendOp as O, BlendPreset as P};
    let factor = |f: F| match f {
        F::Zero => wgpu::BlendFactor::Zero,
        F::One => wgpu::BlendFactor::One,
        F::Src => wgpu::BlendFactor::Src,
        F::OneMinusSrc => wgpu::BlendFactor::OneMinusSrc,
        F::SrcAlpha => wgpu::BlendFactor::SrcAlpha,
        F::OneMinusSrcAlpha => wgpu::BlendFactor::OneMinusSrcAlpha,
        F::Dst => wgpu::BlendFactor::Dst,
        F::OneMinusDst => wgpu::BlendFactor::OneMinusDst,
        F::DstAlpha => wgpu::BlendFactor::DstAlpha,
        F::OneMinusDstAlpha => wgpu::BlendFactor::OneMinusDstAlpha,
        F::Constant => wgpu::BlendFactor::Constant,
    };
    let op = |o: O| match o {
        O::Add => wgpu::BlendOperation::Add,
        O::Subtract => wgpu::BlendOperation::Subtract,
        O::ReverseSubtract => wgpu::BlendOperation::ReverseSubtract,
        O::Min => wgpu::BlendOperation::Min,
        O::Max => wgpu::BlendOperation::Max,
    };
    match b {
        cf::Blend::Preset(P::Opaque) => None,
        cf::Blend::Preset(P::Alpha) => Some(wgpu::BlendState::ALPHA_BLENDING),
        cf::Blend::Preset(P::PremultipliedAlpha) => {
            Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)
        }
        cf::Blend::Preset(P::Additive) => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::OVER,
        }),
        cf::Blend::Preset(P::Multiply) => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Dst,
                dst_factor: wgpu::BlendFactor::Zero,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::OVER,
        }),
        cf::Blend::Custom { color, alpha } => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: factor(color.src),
                dst_factor: factor(color.dst),
                operation: op(color.op),
            },
            alpha: wgpu::BlendComponent {
                src_factor: factor(alpha.src),
                dst_factor: factor(alpha.dst),
                operation: op(alpha.op),
            },
        }),
    }
}

/// A stencil test that reads no reference (each face always or never passes, nothing
/// replaced: Skia's stencil-then-cover paths invert with ALWAYS) compared through a read mask
/// of zero instead: EQUAL then always passes and NOT_EQUAL never does, as ALWAYS and NEVER did.
/// wgpu makes the stencil reference a dynamic state of every pipeline but sets it only where
/// the pipeline reads it, and Vulkan asks it set whenever the test is on
/// (`VUID-vkCmdDraw-None-07839`); reading it makes wgpu set it.
pub(super) fn reference_read(mut s: wgpu::StencilState) -> wgpu::StencilState {
    use wgpu::CompareFunction as C;
    if !s.is_enabled() || s.needs_ref_value() {
        return s;
    }
    for face in [&mut s.front, &mut s.back] {
        face.compare = match face.compare {
            C::Never => C::NotEqual,
            _ => C::Equal,
        };
    }
    s.read_mask = 0;
    s
}

/// The depth-stencil state of a raster pass with depth target `d`.
pub(super) fn depth_stencil(st: &RenderState, d: &DepthTarget) -> wgpu::DepthStencilState {
    let face = |f: &cf::StencilFace| wgpu::StencilFaceState {
        compare: compare(f.compare),
        fail_op: stencil_op(f.fail),
        depth_fail_op: stencil_op(f.depth_fail),
        pass_op: stencil_op(f.pass),
    };
    let stencil = st
        .stencil
        .as_ref()
        .map_or(wgpu::StencilState::default(), |s| {
            reference_read(wgpu::StencilState {
                front: face(&s.front),
                back: face(&s.back),
                read_mask: s.read_mask,
                write_mask: s.write_mask,
            })
        });
    wgpu::DepthStencilState {
        format: d.format,
        depth_write_enabled: Some(st.depth_write && !d.read_only),
        depth_compare: Some(
            st.depth_compare
                .map_or(wgpu::CompareFunction::Always, compare),
        ),
        stencil,
        bias: wgpu::DepthBiasState {
            constant: st.depth_bias,
            slope_scale: st.depth_bias_slope,
            clamp: 0.0,
        },
    }
}

pub(super) fn primitive(st: &RenderState) -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        topology: match st.topology {
            cf::Topology::PointList => wgpu::PrimitiveTopology::PointList,
            cf::Topology::LineList => wgpu::PrimitiveTopology::LineList,
            cf::Topology::LineStrip => wgpu::PrimitiveTopology::LineStrip,
            cf::Topology::TriangleList => wgpu::PrimitiveTopology::TriangleList,
            cf::Topology::TriangleStrip => wgpu::PrimitiveTopology::TriangleStrip,
        },
        front_face: if st.front_face == cf::FrontFace::Ccw {
            wgpu::FrontFace::Ccw
        } else {
            wgpu::FrontFace::Cw
        },
        cull_mode: match st.cull {
            cf::CullMode::None => None,
            cf::CullMode::Front => Some(wgpu::Face::Front),
            cf::CullMode::Back => Some(wgpu::Face::Back),
        },
        ..Default::default()
    }
}

/// A write mask spelled as channel letters ("rgb"); all channels when absent.
pub(super) fn write_mask(mask: Option<&String>) -> wgpu::ColorWrites {
    mask.map_or(wgpu::ColorWrites::ALL, |m| {
        let mut w = wgpu::ColorWrites::empty();
        for (ch, bit) in [
            ('r', wgpu::ColorWrites::RED),
            ('g', wgpu::ColorWrites::GREEN),
            ('b', wgpu::ColorWrites::BLUE),
            ('a', wgpu::ColorWrites::ALPHA),
        ] {
            if m.contains(ch) {
                w |= bit;
            }
        }
        w
    })
}

pub(super) fn sampler(s: &cf::Sampler) -> SamplerSpec {
    let address = |a: cf::AddressMode| match a {
        cf::AddressMode::Wrap => wgpu::AddressMode::Repeat,
        cf::AddressMode::Clamp => wgpu::AddressMode::ClampToEdge,
        cf::AddressMode::Mirror => wgpu::AddressMode::MirrorRepeat,
        cf::AddressMode::Border => wgpu::AddressMode::ClampToBorder,
    };
    let filter = |f: cf::Filter| {
        if f == cf::Filter::Linear {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        }
    };
    SamplerSpec {
        name: s.name.clone(),
        address: [
            address(s.address_u),
            address(s.address_v),
            address(s.address_w),
        ],
        mag: filter(s.mag_filter),
        min: filter(s.min_filter),
        mip: if s.mip_filter == cf::Filter::Linear {
            wgpu::MipmapFilterMode::Linear
        } else {
            wgpu::MipmapFilterMode::Nearest
        },
        lod: (s.lod_min, s.lod_max),
        compare: s.compare.map(compare),
        anisotropy: s.max_anisotropy,
        border: None,
    }
}
