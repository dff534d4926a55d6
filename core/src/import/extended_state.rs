//! The setters of extended dynamic state 3 and of vertex input (`vkCmdSetVertexInputEXT`,
//! `vkCmdSetPolygonModeEXT`, `vkCmdSetColorBlendEnableEXT`, ...), read into the values the
//! draws after them run with. Mesa's zink (OpenGL on Vulkan) declares them on every pipeline.

use super::calls::SetState;
use super::value::{Arg, Got, Skip};
use crate::capture::format::{
    VertexAttributeVk, VkBlendEquation, VkExtendedDynamicValues, VkVertexBindingDivisor,
    VkVertexInput,
};

/// Most colour attachments a per-attachment setter may name (Vulkan devices offer 8 or so).
const MAX_ATTACHMENTS: u32 = 64;

/// Records one setter's values in `d`.
pub(super) fn set(d: &mut VkExtendedDynamicValues, set: SetState, args: &Arg<'_>) -> Got<()> {
    let flag = |key: &str| super::pipelines::boolean(args, key);
    match set {
        SetState::VertexInput => d.vertex_input = Some(vertex_input(args)?),
        SetState::PolygonMode => d.polygon_mode = Some(args.get("polygonMode")?.name()?),
        SetState::DepthClampEnable => d.depth_clamp_enable = Some(flag("depthClampEnable")?),
        SetState::DepthClipEnable => d.depth_clip_enable = Some(flag("depthClipEnable")?),
        SetState::DepthClipNegativeOneToOne => {
            d.depth_clip_negative_one_to_one = Some(flag("negativeOneToOne")?);
        }
        SetState::AlphaToCoverageEnable => {
            d.alpha_to_coverage_enable = Some(flag("alphaToCoverageEnable")?);
        }
        SetState::AlphaToOneEnable => d.alpha_to_one_enable = Some(flag("alphaToOneEnable")?),
        SetState::RasterizationSamples => {
            d.rasterization_samples = Some(args.get("rasterizationSamples")?.name()?);
        }
        SetState::SampleMask => {
            d.sample_mask = Some(
                args.list("pSampleMask")?
                    .iter()
                    .map(Arg::u32)
                    .collect::<Got<_>>()?,
            );
        }
        SetState::ColorBlendEnable => {
            let values = args.list("pColorBlendEnables")?;
            let values: Vec<bool> = values
                .iter()
                .map(|v| v.u64().map(|v| v != 0))
                .collect::<Got<_>>()?;
            per_attachment(&mut d.color_blend_enable, args, values)?;
        }
        SetState::ColorBlendEquation => {
            let values = args
                .list("pColorBlendEquations")?
                .iter()
                .map(|e| {
                    Ok(VkBlendEquation {
                        src_color: e.get("srcColorBlendFactor")?.name()?,
                        dst_color: e.get("dstColorBlendFactor")?.name()?,
                        color_op: e.get("colorBlendOp")?.name()?,
                        src_alpha: e.get("srcAlphaBlendFactor")?.name()?,
                        dst_alpha: e.get("dstAlphaBlendFactor")?.name()?,
                        alpha_op: e.get("alphaBlendOp")?.name()?,
                    })
                })
                .collect::<Got<Vec<_>>>()?;
            per_attachment(&mut d.color_blend_equation, args, values)?;
        }
        SetState::ColorWriteMask => {
            let values = args
                .list("pColorWriteMasks")?
                .iter()
                .map(Arg::u32)
                .collect::<Got<Vec<_>>>()?;
            per_attachment(&mut d.color_write_mask, args, values)?;
        }
        SetState::LogicOpEnable => d.logic_op_enable = Some(flag("logicOpEnable")?),
        SetState::ProvokingVertexMode => {
            d.provoking_vertex_mode = Some(args.get("provokingVertexMode")?.name()?);
        }
        SetState::LineRasterizationMode => {
            d.line_rasterization_mode = Some(args.get("lineRasterizationMode")?.name()?);
        }
        SetState::LineStippleEnable => d.line_stipple_enable = Some(flag("stippledLineEnable")?),
        SetState::PatchControlPoints => {
            d.patch_control_points = Some(args.get("patchControlPoints")?.u32()?);
        }
        // The setters of the first two extended-dynamic-state sets are `record`'s own.
        _ => {}
    }
    Ok(())
}

/// Sets `values` at `firstAttachment` onwards, growing the list with unset entries.
fn per_attachment<T: Clone>(list: &mut Vec<Option<T>>, args: &Arg<'_>, values: Vec<T>) -> Got<()> {
    let first = args.get("firstAttachment")?.u32()?;
    let end = first.saturating_add(u32::try_from(values.len()).unwrap_or(u32::MAX));
    if end > MAX_ATTACHMENTS {
        return Err(Skip(format!(
            "colour attachments {first}..{end}: more than {MAX_ATTACHMENTS}"
        )));
    }
    if list.len() < end as usize {
        list.resize(end as usize, None);
    }
    for (k, v) in values.into_iter().enumerate() {
        list[first as usize + k] = Some(v);
    }
    Ok(())
}

fn vertex_input(args: &Arg<'_>) -> Got<VkVertexInput> {
    let bindings = args
        .list("pVertexBindingDescriptions")?
        .iter()
        .map(|b| {
            Ok(VkVertexBindingDivisor {
                binding: b.get("binding")?.u32()?,
                stride: b.get("stride")?.u32()?,
                input_rate: b.get("inputRate")?.name()?,
                divisor: b.opt("divisor").map_or(Ok(1), |d| d.u32())?,
            })
        })
        .collect::<Got<_>>()?;
    let attributes = args
        .list("pVertexAttributeDescriptions")?
        .iter()
        .map(|a| {
            Ok(VertexAttributeVk {
                location: a.get("location")?.u32()?,
                binding: a.get("binding")?.u32()?,
                format: a.get("format")?.name()?,
                offset: a.get("offset")?.u32()?,
            })
        })
        .collect::<Got<_>>()?;
    Ok(VkVertexInput {
        bindings,
        attributes,
    })
}
