//! `vkCmdClearAttachments` inside a render pass instance: the subpass's colour attachments it
//! names become indices into the raster pass's own, the depth and stencil values apply where
//! the attachment has those aspects, and the clear is placed before the pass's next draw.

use super::*;
use crate::capture::format::{AttachmentClear, AttachmentClearColor};
use crate::import::commands::AttachmentClearCmd;

impl Builder {
    /// Records `c`, made in subpass `sub` of `ri`, in `pass`; `Err` says what of it the replay
    /// cannot do.
    pub(super) fn attachment_clear(
        &mut self,
        objects: &Objects,
        (ri, sub, pass): (&RenderInstance, usize, usize),
        c: &AttachmentClearCmd,
    ) -> Result<(), &'static str> {
        let Some(s) = ri.subpasses.get(sub) else {
            return Ok(());
        };
        // The pass has the subpass's colour attachments whose views resolved (`raster`).
        let slots: Vec<(u32, Option<&str>)> = s
            .colors
            .iter()
            .filter(|a| objects.views.contains_key(&a.view))
            .map(|a| {
                (
                    a.slot,
                    objects.view_kinds.get(&a.view).map(|k| k.1.as_str()),
                )
            })
            .collect();
        // A colour attachment the subpass leaves unused is cleared by nothing, as the
        // specification says.
        let colors: Vec<AttachmentClearColor> = c
            .colors
            .iter()
            .filter_map(|&(slot, value)| {
                let i = slots.iter().position(|&(s, _)| s == slot)?;
                // Read through the attachment's view: integers for an integer attachment.
                Some(AttachmentClearColor {
                    attachment: i as u32,
                    value: value.through(slots[i].1),
                })
            })
            .collect();
        let format = s
            .depth
            .as_ref()
            .and_then(|d| objects.views.get(&d.view))
            .and_then(|v| objects.images.get(&v.image))
            .map(|i| i.format.as_str())
            .filter(|_| self.passes[pass].depth_stencil.is_some());
        let depth = c
            .depth
            .filter(|_| format.is_some_and(|f| f.starts_with("VK_FORMAT_D")));
        let stencil = c
            .stencil
            .filter(|_| format.is_some_and(|f| f.contains("S8")));
        let mut rects = Vec::new();
        for &([x, y, w, h], base, layers) in &c.rects {
            if base != 0 || layers != 1 {
                return Err("clears of layers other than the first (layered rendering)");
            }
            let clamp = |v: i64| u32::try_from(v.max(0)).unwrap_or(u32::MAX);
            let (x, y) = (clamp(x), clamp(y));
            let (w, h) = (clamp(w), clamp(h));
            if w > 0 && h > 0 {
                rects.push([x, y, w, h]);
            }
        }
        if rects.is_empty() || colors.is_empty() && depth.is_none() && stencil.is_none() {
            return Ok(());
        }
        let p = &mut self.passes[pass];
        p.attachment_clears.push(AttachmentClear {
            before_draw: p.draws.len() as u32,
            colors,
            depth,
            stencil,
            rects,
        });
        Ok(())
    }
}
