//! Attachment clears of an imported render pass (`vkCmdClearAttachments`) at wgpu level: a
//! value per colour target, the depth and stencil values, rectangles clipped to the targets.
//! Integer colour targets take the value as the import read it through their format
//! (integers); what a draw cannot write is refused: read-only or absent depth and stencil.

use super::VkProblem;
use crate::capture::model::AttachmentClearDesc;
use crate::plan::{ColorTarget, DepthTarget, VkClearOp};

/// `c` for a pass with targets `color` and `depth`, `extent` in pixels.
pub(super) fn clear_op(
    c: &AttachmentClearDesc,
    color: &[ColorTarget],
    depth: Option<&DepthTarget>,
    extent: (u32, u32),
) -> Result<VkClearOp, VkProblem> {
    let mut colors = vec![None; color.len()];
    for &(i, value) in &c.colors {
        if i >= color.len() {
            return Err(VkProblem::Missing(format!(
                "colour attachment {i} of a pass with {}",
                color.len()
            )));
        }
        colors[i] = Some(value);
    }
    if c.depth.is_some() && depth.is_none_or(|d| d.read_only)
        || c.stencil.is_some() && depth.is_none_or(|d| d.stencil_read_only)
    {
        return Err(VkProblem::Unsupported {
            feature: "vkCmdClearAttachments of a read-only or absent depth/stencil attachment"
                .to_owned(),
        });
    }
    let (w, h) = extent;
    let rects = c
        .rects
        .iter()
        .filter_map(|&[x, y, rw, rh]| {
            let (x, y) = (x.min(w), y.min(h));
            let (rw, rh) = (rw.min(w - x), rh.min(h - y));
            (rw > 0 && rh > 0).then_some([x, y, rw, rh])
        })
        .collect();
    Ok(VkClearOp {
        before: c.before_draw,
        colors,
        depth: c.depth,
        stencil: c.stencil,
        rects,
    })
}
