//! Extended dynamic state 3 and vertex input baked into a draw's pipeline variant: the
//! values `vkCmdSetVertexInputEXT`, `vkCmdSetPolygonModeEXT`, `vkCmdSetColorBlendEnableEXT`
//! and the like set before the draw replace the pipeline's, and what wgpu has no twin for
//! is refused by name where the draw switches it on.

use super::VkProblem;
use crate::capture::format::{
    BlendAttachment, GraphicsState, VertexBinding, VkExtendedDynamicValues,
};

/// The dynamic states (without `VK_DYNAMIC_STATE_`) whose values are in
/// `VkExtendedDynamicValues`.
pub(super) const EXTENDED: &[&str] = &[
    "VERTEX_INPUT_EXT",
    "POLYGON_MODE_EXT",
    "DEPTH_CLAMP_ENABLE_EXT",
    "DEPTH_CLIP_ENABLE_EXT",
    "DEPTH_CLIP_NEGATIVE_ONE_TO_ONE_EXT",
    "ALPHA_TO_COVERAGE_ENABLE_EXT",
    "ALPHA_TO_ONE_ENABLE_EXT",
    "RASTERIZATION_SAMPLES_EXT",
    "SAMPLE_MASK_EXT",
    "COLOR_BLEND_ENABLE_EXT",
    "COLOR_BLEND_EQUATION_EXT",
    "COLOR_WRITE_MASK_EXT",
    "LOGIC_OP_ENABLE_EXT",
    "PROVOKING_VERTEX_MODE_EXT",
    "LINE_RASTERIZATION_MODE_EXT",
    "LINE_STIPPLE_ENABLE_EXT",
];

fn refuse(feature: String) -> Result<(), VkProblem> {
    Err(VkProblem::Unsupported { feature })
}

/// A colour attachment's blend state, made where the pipeline has none for it (its blend
/// state is all dynamic): blending off, every channel written.
fn attachment(e: &mut GraphicsState, i: usize) -> &mut BlendAttachment {
    while e.blend.len() <= i {
        e.blend.push(BlendAttachment {
            enable: false,
            src_color: "VK_BLEND_FACTOR_ONE".to_owned(),
            dst_color: "VK_BLEND_FACTOR_ZERO".to_owned(),
            color_op: "VK_BLEND_OP_ADD".to_owned(),
            src_alpha: "VK_BLEND_FACTOR_ONE".to_owned(),
            dst_alpha: "VK_BLEND_FACTOR_ZERO".to_owned(),
            alpha_op: "VK_BLEND_OP_ADD".to_owned(),
            write_mask: 0xf,
        });
    }
    &mut e.blend[i]
}

/// Writes the values of the extended states `declared` dynamic into `e`.
pub(super) fn extended(
    declared: &[&str],
    e: &mut GraphicsState,
    x: &VkExtendedDynamicValues,
    missing: &dyn Fn(&str) -> VkProblem,
    clamp_moot: bool,
) -> Result<(), VkProblem> {
    let has = |s: &str| declared.contains(&s);
    if has("VERTEX_INPUT_EXT") {
        vertex_input(e, x, missing)?;
    }
    if has("POLYGON_MODE_EXT") {
        e.polygon_mode = x
            .polygon_mode
            .clone()
            .ok_or_else(|| missing("polygon mode"))?;
    }
    if has("DEPTH_CLAMP_ENABLE_EXT") {
        e.depth_clamp = x
            .depth_clamp_enable
            .ok_or_else(|| missing("depth clamp enable"))?;
    }
    // Vulkan clips depth unless it clamps (`depthClipEnable` may say otherwise); wgpu ties
    // the two: its unclipped depth is clamped depth. Clipped and clamped is clipped: what
    // survives the clip is already in range. Neither clipped nor clamped is wgpu's unclipped
    // depth where the clamp changes nothing (`clamp_moot`: no depth attachment, or a
    // fixed-point one, whose test clamps to [0, 1] anyway, with the viewport's depth range
    // [0, 1]); a floating-point attachment would keep depths outside it.
    if has("DEPTH_CLIP_ENABLE_EXT")
        && let Some(clip) = x.depth_clip_enable
        && clip == e.depth_clamp
    {
        if clip {
            e.depth_clamp = false;
        } else if clamp_moot {
            e.depth_clamp = true;
        } else {
            refuse(
                "depth clipping off with depth clamping off into a floating-point depth attachment or a depth range other than [0, 1] (wgpu clamps the depth it does not clip)"
                    .to_owned(),
            )?;
        }
    }
    if has("DEPTH_CLIP_NEGATIVE_ONE_TO_ONE_EXT") {
        e.depth_negative_one_to_one = x
            .depth_clip_negative_one_to_one
            .ok_or_else(|| missing("depth clip range"))?;
    }
    if has("ALPHA_TO_COVERAGE_ENABLE_EXT") {
        e.alpha_to_coverage = x
            .alpha_to_coverage_enable
            .ok_or_else(|| missing("alpha to coverage enable"))?;
    }
    if has("ALPHA_TO_ONE_ENABLE_EXT") {
        e.alpha_to_one = x
            .alpha_to_one_enable
            .ok_or_else(|| missing("alpha to one enable"))?;
    }
    if has("RASTERIZATION_SAMPLES_EXT") {
        e.samples = x
            .rasterization_samples
            .clone()
            .ok_or_else(|| missing("rasterization samples"))?;
    }
    if has("SAMPLE_MASK_EXT") {
        let mask = x
            .sample_mask
            .as_ref()
            .ok_or_else(|| missing("sample mask"))?;
        // Devices have at most 32 samples here: the first word is the whole mask.
        e.sample_mask = Some(mask.first().copied().unwrap_or(0));
    }
    blend_attachments(&has, e, x);
    if has("LOGIC_OP_ENABLE_EXT") {
        let enable = x
            .logic_op_enable
            .ok_or_else(|| missing("logic op enable"))?;
        e.logic_op = if enable {
            Some(
                e.logic_op
                    .clone()
                    .unwrap_or_else(|| "VK_LOGIC_OP_COPY".to_owned()),
            )
        } else {
            None
        };
    }
    if has("PROVOKING_VERTEX_MODE_EXT") {
        e.provoking_vertex_last = x
            .provoking_vertex_mode
            .as_ref()
            .is_some_and(|m| m.contains("LAST_VERTEX"));
    }
    // What lines these give is `states::lines`' to judge, with the pipeline's own.
    if has("LINE_RASTERIZATION_MODE_EXT") {
        e.line_rasterization_mode = x
            .line_rasterization_mode
            .clone()
            .filter(|m| !m.ends_with("DEFAULT_EXT"));
    }
    if has("LINE_STIPPLE_ENABLE_EXT") {
        e.line_stipple = x.line_stipple_enable == Some(true);
    }
    Ok(())
}

/// `vkCmdSetVertexInputEXT`'s bindings and attributes in place of the pipeline's.
fn vertex_input(
    e: &mut GraphicsState,
    x: &VkExtendedDynamicValues,
    missing: &dyn Fn(&str) -> VkProblem,
) -> Result<(), VkProblem> {
    let vi = x
        .vertex_input
        .as_ref()
        .ok_or_else(|| missing("vertex input"))?;
    if let Some(b) = vi
        .bindings
        .iter()
        .find(|b| b.divisor != 1 && b.input_rate.ends_with("INSTANCE"))
    {
        refuse(format!(
            "an instance divisor of {} on vertex binding {} (wgpu steps every instance)",
            b.divisor, b.binding
        ))?;
    }
    e.vertex_bindings = vi
        .bindings
        .iter()
        .map(|b| VertexBinding {
            binding: b.binding,
            stride: b.stride,
            input_rate: b.input_rate.clone(),
        })
        .collect();
    e.vertex_attributes.clone_from(&vi.attributes);
    Ok(())
}

/// The per-attachment blend enables, equations and write masks set dynamically.
fn blend_attachments(
    has: &dyn Fn(&str) -> bool,
    e: &mut GraphicsState,
    x: &VkExtendedDynamicValues,
) {
    if has("COLOR_BLEND_ENABLE_EXT") {
        for (i, v) in x.color_blend_enable.iter().enumerate() {
            if let Some(v) = v {
                attachment(e, i).enable = *v;
            }
        }
    }
    if has("COLOR_BLEND_EQUATION_EXT") {
        for (i, q) in x.color_blend_equation.iter().enumerate() {
            if let Some(q) = q {
                let a = attachment(e, i);
                a.src_color.clone_from(&q.src_color);
                a.dst_color.clone_from(&q.dst_color);
                a.color_op.clone_from(&q.color_op);
                a.src_alpha.clone_from(&q.src_alpha);
                a.dst_alpha.clone_from(&q.dst_alpha);
                a.alpha_op.clone_from(&q.alpha_op);
            }
        }
    }
    if has("COLOR_WRITE_MASK_EXT") {
        for (i, m) in x.color_write_mask.iter().enumerate() {
            if let Some(m) = m {
                attachment(e, i).write_mask = *m;
            }
        }
    }
}
