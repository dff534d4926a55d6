//! Dynamic state baked into pipeline variants: wgpu fixes in the pipeline what Vulkan lets a
//! command buffer set between draws (cull mode, depth test, depth bias, stencil masks,
//! topology, strides, ...). The values a draw ran with are written into a copy of its
//! pipeline's state, which keys the variant, so each distinct value makes one pipeline and
//! draws that agree share it. What the coverage table refuses is refused here by name.

use std::borrow::Cow;

use super::VkProblem;
use super::extended::{EXTENDED, extended};
use crate::capture::format::{DepthStencilVk, GraphicsState, StencilFaceVk, VkDynamicValues};
use crate::capture::vk_model::VkPipeline;
use crate::coverage::{self, Verdict};

/// A draw's graphics state with its dynamic values in, and the key of its variant (`None`
/// where the pipeline bakes nothing, so every draw of it shares the one pipeline).
pub(super) struct Baked<'g> {
    pub state: Cow<'g, GraphicsState>,
    pub key: Option<String>,
}

/// Set per draw on the render pass, not baked.
fn per_draw(short: &str) -> bool {
    matches!(
        short,
        "VIEWPORT"
            | "SCISSOR"
            | "VIEWPORT_WITH_COUNT"
            | "SCISSOR_WITH_COUNT"
            | "BLEND_CONSTANTS"
            | "STENCIL_REFERENCE"
    )
}

pub(super) fn bake<'g>(
    pipe: &VkPipeline,
    g: &'g GraphicsState,
    values: Option<&VkDynamicValues>,
    clamp_moot: bool,
) -> Result<Baked<'g>, VkProblem> {
    let mut declared = Vec::new();
    for s in &g.dynamic_states {
        match coverage::dynamic_state(s) {
            Some(Verdict::Refused(why)) => {
                return Err(VkProblem::Unsupported {
                    feature: format!("dynamic state {s} of pipeline {} ({why})", pipe.name),
                });
            }
            None => {
                return Err(VkProblem::Unsupported {
                    feature: format!(
                        "dynamic state {s} of pipeline {} (not in the coverage table)",
                        pipe.name
                    ),
                });
            }
            Some(_) => {}
        }
        let short = s.strip_prefix("VK_DYNAMIC_STATE_").unwrap_or(s);
        if !per_draw(short) {
            declared.push(short);
        }
    }
    if declared.is_empty() {
        return Ok(Baked {
            state: Cow::Borrowed(g),
            key: None,
        });
    }
    let none = VkDynamicValues::default();
    let v = values.unwrap_or(&none);
    let has = |s: &str| declared.contains(&s);
    let mut e = g.clone();
    let missing = |what: &str| {
        VkProblem::Missing(format!(
            "pipeline {} has a dynamic {what} the draw never set",
            pipe.name
        ))
    };
    if has("CULL_MODE") {
        e.cull_mode = v.cull_mode.ok_or_else(|| missing("cull mode"))?;
    }
    if has("FRONT_FACE") {
        e.front_face = v.front_face.clone().ok_or_else(|| missing("front face"))?;
    }
    if has("PRIMITIVE_TOPOLOGY") {
        e.topology = v.topology.clone().ok_or_else(|| missing("topology"))?;
    }
    if has("PRIMITIVE_RESTART_ENABLE") {
        e.primitive_restart = v.primitive_restart_enable.unwrap_or(g.primitive_restart);
    }
    if has("RASTERIZER_DISCARD_ENABLE") {
        e.rasterizer_discard = v
            .rasterizer_discard_enable
            .ok_or_else(|| missing("rasterizer discard"))?;
    }
    if has("LINE_WIDTH") {
        // Read only where lines are drawn; `states::primitive` refuses wide ones there.
        e.line_width = v.line_width.unwrap_or(1.0);
    }
    let bias_on = if has("DEPTH_BIAS_ENABLE") {
        v.depth_bias_enable
            .ok_or_else(|| missing("depth bias enable"))?
    } else {
        g.depth_bias.is_some()
    };
    e.depth_bias = if !bias_on {
        None
    } else if has("DEPTH_BIAS") {
        Some(v.depth_bias.ok_or_else(|| missing("depth bias"))?)
    } else {
        g.depth_bias
    };
    if let Some(x) = v.extended.as_deref() {
        extended(&declared, &mut e, x, &missing, clamp_moot)?;
    } else if let Some(s) = declared.iter().find(|s| EXTENDED.contains(s)) {
        return Err(missing(&format!("state VK_DYNAMIC_STATE_{s}")));
    }
    if has("VERTEX_INPUT_BINDING_STRIDE") {
        for b in &mut e.vertex_bindings {
            let stride = v
                .vertex_strides
                .iter()
                .find(|s| s[0] == u64::from(b.binding))
                .ok_or_else(|| missing(&format!("stride of vertex binding {}", b.binding)))?[1];
            b.stride = u32::try_from(stride).map_err(|_| VkProblem::Unsupported {
                feature: format!("a vertex stride of {stride} bytes"),
            })?;
        }
    }
    if let Some(enables) = v
        .color_write_enable
        .as_ref()
        .filter(|_| has("COLOR_WRITE_ENABLE_EXT"))
    {
        for (b, on) in e.blend.iter_mut().zip(enables) {
            if !on {
                b.write_mask = 0;
            }
        }
    }
    if has("LOGIC_OP_EXT") && e.logic_op.is_some() {
        e.logic_op = v.logic_op.clone();
    }
    depth_stencil(&declared, &mut e, v, &missing)?;
    let key = serde_json::to_string(&e).map_err(|err| VkProblem::Missing(err.to_string()))?;
    Ok(Baked {
        state: Cow::Owned(e),
        key: Some(key),
    })
}

/// The depth and stencil states the draws set.
fn depth_stencil(
    declared: &[&str],
    e: &mut GraphicsState,
    v: &VkDynamicValues,
    missing: &dyn Fn(&str) -> VkProblem,
) -> Result<(), VkProblem> {
    let has = |s: &str| declared.contains(&s);
    let touches = [
        "DEPTH_TEST_ENABLE",
        "DEPTH_WRITE_ENABLE",
        "DEPTH_COMPARE_OP",
        "DEPTH_BOUNDS_TEST_ENABLE",
        "STENCIL_TEST_ENABLE",
        "STENCIL_OP",
        "STENCIL_COMPARE_MASK",
        "STENCIL_WRITE_MASK",
    ];
    if !touches.iter().any(|s| has(s)) {
        return Ok(());
    }
    let ds = e.depth_stencil.get_or_insert_with(DepthStencilVk::off);
    if has("DEPTH_TEST_ENABLE") {
        ds.depth_test = v
            .depth_test_enable
            .ok_or_else(|| missing("depth test enable"))?;
    }
    if has("DEPTH_WRITE_ENABLE") {
        ds.depth_write = v
            .depth_write_enable
            .ok_or_else(|| missing("depth write enable"))?;
    }
    if has("DEPTH_COMPARE_OP") && ds.depth_test {
        ds.depth_compare = v
            .depth_compare_op
            .clone()
            .ok_or_else(|| missing("depth compare op"))?;
    }
    if has("DEPTH_BOUNDS_TEST_ENABLE") {
        let on = v
            .depth_bounds_test_enable
            .ok_or_else(|| missing("depth bounds test enable"))?;
        // On, it is refused by `states::depth_stencil` whatever the bounds.
        ds.depth_bounds = on.then(|| v.depth_bounds.or(ds.depth_bounds).unwrap_or([0.0, 1.0]));
    }
    if has("STENCIL_TEST_ENABLE") {
        ds.stencil_test = v
            .stencil_test_enable
            .ok_or_else(|| missing("stencil test enable"))?;
    }
    if !ds.stencil_test {
        return Ok(());
    }
    let blank = StencilFaceVk {
        fail_op: "VK_STENCIL_OP_KEEP".to_owned(),
        pass_op: "VK_STENCIL_OP_KEEP".to_owned(),
        depth_fail_op: "VK_STENCIL_OP_KEEP".to_owned(),
        compare_op: "VK_COMPARE_OP_ALWAYS".to_owned(),
        compare_mask: 0xff,
        write_mask: 0xff,
        reference: 0,
    };
    for (i, face) in [&mut ds.front, &mut ds.back].into_iter().enumerate() {
        let f = face.get_or_insert_with(|| blank.clone());
        if has("STENCIL_OP") {
            let ops = &v.stencil_op.as_ref().ok_or_else(|| missing("stencil op"))?[i];
            f.fail_op.clone_from(&ops.fail_op);
            f.pass_op.clone_from(&ops.pass_op);
            f.depth_fail_op.clone_from(&ops.depth_fail_op);
            f.compare_op.clone_from(&ops.compare_op);
        }
        if has("STENCIL_COMPARE_MASK") {
            f.compare_mask = v
                .stencil_compare_mask
                .ok_or_else(|| missing("stencil compare mask"))?[i];
        }
        if has("STENCIL_WRITE_MASK") {
            f.write_mask = v
                .stencil_write_mask
                .ok_or_else(|| missing("stencil write mask"))?[i];
        }
    }
    Ok(())
}
