//! Attachment clears inside a raster pass (`vkCmdClearAttachments`), checked against the
//! rules the specification gives the command: every colour attachment named is one of the
//! pass's, a depth or stencil value needs a depth/stencil attachment with that aspect, the
//! rectangles lie inside the attachments, and the clear sits between the pass's draws. Only
//! imported frames carry them: the replay draws them with the imported passes.

use super::Validator;
use crate::capture::diag::JsonPath;
use crate::capture::format::{AttachmentClear, Pass, PassKind};
use crate::capture::model::{AttachmentClearDesc, ColorAttachmentDesc, DepthStencilDesc};

impl Validator<'_> {
    /// The pass's attachment clears, validated against its attachments (`size`: theirs).
    pub(super) fn pass_attachment_clears(
        &mut self,
        p: &Pass,
        path: &JsonPath,
        colors: &[ColorAttachmentDesc],
        depth: Option<&DepthStencilDesc>,
        size: Option<(u32, u32)>,
    ) -> Vec<AttachmentClearDesc> {
        if p.attachment_clears.is_empty() {
            return Vec::new();
        }
        if p.kind != PassKind::Raster || !self.vulkan() {
            self.diags.error(
                "attachment-clear",
                &path.field("attachment_clears"),
                format!(
                    "pass \"{}\": attachment clears belong to raster passes of imported frames (a `vulkan` source)",
                    p.name
                ),
            );
            return Vec::new();
        }
        let mut out = Vec::new();
        for (i, c) in p.attachment_clears.iter().enumerate() {
            let cpath = path.field("attachment_clears").index(i);
            if let Some(d) = self.check_attachment_clear(p, c, &cpath, colors, depth, size) {
                out.push(d);
            }
        }
        out
    }

    fn check_attachment_clear(
        &mut self,
        p: &Pass,
        c: &AttachmentClear,
        path: &JsonPath,
        colors: &[ColorAttachmentDesc],
        depth: Option<&DepthStencilDesc>,
        size: Option<(u32, u32)>,
    ) -> Option<AttachmentClearDesc> {
        let before = self.diags.error_count();
        if c.before_draw as usize > p.draws.len() {
            self.diags.error(
                "attachment-clear",
                &path.field("before_draw"),
                format!(
                    "comes before draw {} but the pass has {} draws",
                    c.before_draw,
                    p.draws.len()
                ),
            );
        }
        if c.colors.is_empty() && c.depth.is_none() && c.stencil.is_none() {
            self.diags.error(
                "attachment-clear",
                path,
                "clears no colour attachment, depth or stencil",
            );
        }
        for (k, color) in c.colors.iter().enumerate() {
            let cpath = path.field("colors").index(k);
            if color.attachment as usize >= colors.len() {
                self.diags.error(
                    "attachment-clear",
                    &cpath.field("attachment"),
                    format!(
                        "colour attachment {} of a pass with {}",
                        color.attachment,
                        colors.len()
                    ),
                );
            } else if c.colors[..k]
                .iter()
                .any(|o| o.attachment == color.attachment)
            {
                self.diags.error(
                    "attachment-clear",
                    &cpath.field("attachment"),
                    format!("colour attachment {} named twice", color.attachment),
                );
            }
        }
        let format = depth.map(|d| d.format);
        if let Some(v) = c.depth {
            if format.is_none_or(|f| f.depth_bits == 0) {
                self.diags.error(
                    "attachment-clear",
                    &path.field("depth"),
                    "clears depth, but the pass has no depth attachment",
                );
            } else if !(0.0..=1.0).contains(&v) {
                self.diags.error(
                    "attachment-clear",
                    &path.field("depth"),
                    format!("depth {v} is outside 0..1"),
                );
            }
        }
        if c.stencil.is_some() && format.is_none_or(|f| f.stencil_bits == 0) {
            self.diags.error(
                "attachment-clear",
                &path.field("stencil"),
                "clears stencil, but the pass has no stencil attachment",
            );
        }
        if c.rects.is_empty() {
            self.diags
                .error("attachment-clear", &path.field("rects"), "no rectangles");
        }
        for (k, &[x, y, w, h]) in c.rects.iter().enumerate() {
            let inside = size.is_none_or(|(sw, sh)| {
                u64::from(x) + u64::from(w) <= u64::from(sw)
                    && u64::from(y) + u64::from(h) <= u64::from(sh)
            });
            if w == 0 || h == 0 || !inside {
                let (sw, sh) = size.unwrap_or_default();
                self.diags.error(
                    "attachment-clear",
                    &path.field("rects").index(k),
                    format!(
                        "rectangle {w}x{h} at ({x}, {y}) is empty or outside the {sw}x{sh} attachments"
                    ),
                );
            }
        }
        (self.diags.error_count() == before).then(|| AttachmentClearDesc {
            before_draw: c.before_draw as usize,
            colors: c
                .colors
                .iter()
                .map(|k| (k.attachment as usize, k.value))
                .collect(),
            depth: c.depth,
            stencil: c.stencil,
            rects: c.rects.clone(),
        })
    }
}
