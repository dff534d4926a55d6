//! Valid usage of clear values: a depth clear value outside [0, 1], which Vulkan allows only
//! where the device enabled `VK_EXT_depth_range_unrestricted`
//! (`VUID-VkClearDepthStencilValue-depth-02506`), wherever a `VkClearDepthStencilValue` is
//! consumed: a render pass instance's clear value for each depth/stencil attachment it
//! clears (either aspect: the value is one structure), a dynamic rendering depth or stencil
//! attachment cleared, `vkCmdClearDepthStencilImage`, and `vkCmdClearAttachments` of a depth
//! aspect. Programs break it by leaving the value unset where they clear only the stencil.

use super::state::Objects;
use super::value::{ASPECTS, Arg, Got};
use crate::capture::format::ValidUsageFinding;

const VUID: &str = "VUID-VkClearDepthStencilValue-depth-02506";
const CLEAR: &str = "VK_ATTACHMENT_LOAD_OP_CLEAR";
const DEPTH_ASPECT: u64 = 0x2;

/// Whether `format` (`VK_FORMAT_*`) has a depth or a stencil aspect.
fn depth_or_stencil(format: &str) -> bool {
    format.starts_with("VK_FORMAT_D")
        || format == "VK_FORMAT_S8_UINT"
        || format.ends_with("_S8_UINT")
}

/// The finding for `value` (a `VkClearDepthStencilValue` at `member`) when its depth is out
/// of range; NaN is out of range too.
fn check(command: &str, member: &str, value: Option<Arg<'_>>) -> Option<ValidUsageFinding> {
    let depth = value?.get("depth").ok()?.f64().ok()?;
    if (0.0..=1.0).contains(&depth) {
        return None;
    }
    Some(ValidUsageFinding {
        vuid: VUID.to_owned(),
        command: command.to_owned(),
        detail: format!(
            "{member}.depth is {depth}, outside [0, 1], and the device did not enable VK_EXT_depth_range_unrestricted"
        ),
    })
}

/// The depth clear values command `call` (recorded as `command`) consumes that are out of
/// range.
pub fn clear_values(
    call: &str,
    command: &str,
    args: &Arg<'_>,
    objects: &Objects,
) -> Got<Vec<ValidUsageFinding>> {
    if objects.depth_range_unrestricted {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    match call {
        "vkCmdBeginRenderPass" | "vkCmdBeginRenderPass2" | "vkCmdBeginRenderPass2KHR" => {
            let begin = args.get("pRenderPassBegin")?;
            let Some(pass) = objects
                .render_passes
                .get(&begin.get("renderPass")?.handle()?)
            else {
                return Ok(out);
            };
            let clears = begin.list("pClearValues")?;
            for (i, a) in pass.attachments.iter().enumerate() {
                let cleared = a.load == CLEAR || a.stencil_load == CLEAR;
                if depth_or_stencil(&a.format) && cleared {
                    let value = clears.get(i).and_then(|c| c.opt("depthStencil"));
                    let member = format!("pClearValues[{i}].depthStencil");
                    out.extend(check(command, &member, value));
                }
            }
        }
        "vkCmdBeginRendering" | "vkCmdBeginRenderingKHR" => {
            let info = args.get("pRenderingInfo")?;
            for key in ["pDepthAttachment", "pStencilAttachment"] {
                let Some(a) = info.opt(key) else { continue };
                let view = a.get("imageView").and_then(|v| v.handle()).unwrap_or(0);
                if view != 0 && a.get("loadOp")?.name()? == CLEAR {
                    let value = a.opt("clearValue").and_then(|c| c.opt("depthStencil"));
                    let member = format!("{key}->clearValue.depthStencil");
                    out.extend(check(command, &member, value));
                    // Both name the same value where they are one attachment.
                    break;
                }
            }
        }
        "vkCmdClearDepthStencilImage" => {
            out.extend(check(command, "pDepthStencil", args.opt("pDepthStencil")));
        }
        "vkCmdClearAttachments" => {
            for (i, a) in args.list("pAttachments")?.iter().enumerate() {
                let aspects = a.get("aspectMask")?.flags(ASPECTS)?;
                if aspects & DEPTH_ASPECT != 0 {
                    let value = a.opt("clearValue").and_then(|c| c.opt("depthStencil"));
                    let member = format!("pAttachments[{i}].clearValue.depthStencil");
                    out.extend(check(command, &member, value));
                }
            }
        }
        _ => {}
    }
    Ok(out)
}
