//! Valid usage checked statically from the calls: statements of the specification that real
//! programs break and that need no execution to see, each finding with its VUID. A finding
//! is not a refusal: drivers run such frames, and so does the replay.
//!
//! Checked here: a render pass that loads an attachment whose initial layout is `UNDEFINED`
//! (its contents are undefined at the load; garbage on some GPUs), for the colour or depth
//! aspect (`loadOp`) and the stencil aspect (`stencilLoadOp`). Layouts at use (a barrier's old
//! layout, a render pass's initial layout, a descriptor's layout) are checked with the
//! synchronization rules, which track the layouts (`sync`).

use super::value::{Arg, Got};
use crate::capture::format::ValidUsageFinding;

const UNDEFINED: &str = "VK_IMAGE_LAYOUT_UNDEFINED";
const LOAD: &str = "VK_ATTACHMENT_LOAD_OP_LOAD";

/// `vkCreateRenderPass` (`v2`: `vkCreateRenderPass2`) call `command`: every attachment it
/// loads from `initialLayout` UNDEFINED.
pub fn render_pass(command: &str, v2: bool, args: &Arg<'_>) -> Got<Vec<ValidUsageFinding>> {
    let ci = args.get("pCreateInfo")?;
    let structure = if v2 {
        "VkAttachmentDescription2"
    } else {
        "VkAttachmentDescription"
    };
    let mut out = Vec::new();
    for (i, a) in ci.list("pAttachments")?.iter().enumerate() {
        if a.get("initialLayout")?.name()? != UNDEFINED {
            continue;
        }
        let format = a.get("format")?.name()?;
        let stencil = format == "VK_FORMAT_S8_UINT" || format.ends_with("_S8_UINT");
        let color_or_depth = format != "VK_FORMAT_S8_UINT";
        // Vulkan 1.2's description may give the stencil aspect a layout of its own; without
        // one the stencil starts in `initialLayout` too.
        let separate_stencil = v2 && a.opt("pNext").is_some();
        let stencil_vuid = if v2 { "format-06703" } else { "format-06700" };
        let checks = [
            (color_or_depth, "loadOp", "format-06699"),
            (stencil && !separate_stencil, "stencilLoadOp", stencil_vuid),
        ];
        for (applies, member, number) in checks {
            if applies && a.get(member)?.name()? == LOAD {
                out.push(ValidUsageFinding {
                    vuid: format!("VUID-{structure}-{number}"),
                    command: command.to_owned(),
                    detail: format!(
                        "pAttachments[{i}] ({format}): {member} {LOAD} with initialLayout {UNDEFINED}"
                    ),
                });
            }
        }
    }
    Ok(out)
}
