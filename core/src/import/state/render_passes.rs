//! A `VkRenderPassCreateInfo` (or its `2` form) as the attachments, subpasses and
//! dependencies the import follows.

use super::*;

/// A render pass's layout, by name only: a number or an unknown name derives no transition.
fn layout_name(a: &Arg<'_>) -> Got<Option<ImageLayout>> {
    Ok(ImageLayout::from_name(&a.name()?))
}

pub(super) fn render_pass(ci: &Arg<'_>) -> Got<RenderPassInfo> {
    let attachments = ci
        .list("pAttachments")?
        .iter()
        .map(|a| {
            Ok(AttachmentDesc {
                format: a.get("format")?.name()?,
                load: a.get("loadOp")?.name()?,
                store: a.get("storeOp")?.name()?,
                stencil_load: a.get("stencilLoadOp")?.name()?,
                stencil_store: a.get("stencilStoreOp")?.name()?,
                initial: layout_name(&a.get("initialLayout")?)?,
                final_layout: layout_name(&a.get("finalLayout")?)?,
            })
        })
        .collect::<Got<Vec<_>>>()?;
    type Ref = (u32, Option<ImageLayout>);
    // The positions of the attachment references that name an attachment (not UNUSED).
    let used_slots = |sp: &Arg<'_>, key: &str| -> Vec<u32> {
        sp.list(key)
            .unwrap_or_default()
            .iter()
            .enumerate()
            .filter(|(_, r)| {
                r.get("attachment")
                    .and_then(|a| a.u32())
                    .is_ok_and(|a| a != u32::MAX)
            })
            .map(|(k, _)| k as u32)
            .collect()
    };
    let refs = |sp: &Arg<'_>, key: &str| -> Got<Vec<Ref>> {
        sp.list(key)?
            .iter()
            .map(|r| Ok((r.get("attachment")?.u32()?, layout_name(&r.get("layout")?)?)))
            .filter(|r: &Got<Ref>| !matches!(r, Ok((u32::MAX, _))))
            .collect()
    };
    let subpasses = ci
        .list("pSubpasses")?
        .iter()
        .map(|sp| {
            Ok(SubpassDesc {
                colors: refs(sp, "pColorAttachments")?,
                color_slots: used_slots(sp, "pColorAttachments"),
                resolve_slots: used_slots(sp, "pResolveAttachments"),
                resolves: refs(sp, "pResolveAttachments")?,
                depth: match sp.opt("pDepthStencilAttachment") {
                    Some(d) => {
                        let a = d.get("attachment")?.u32()?;
                        (a != u32::MAX)
                            .then(|| Ok((a, layout_name(&d.get("layout")?)?)))
                            .transpose()?
                    }
                    None => None,
                },
                inputs: refs(sp, "pInputAttachments")?,
            })
        })
        .collect::<Got<Vec<_>>>()?;
    let dependencies = ci
        .list("pDependencies")?
        .iter()
        .map(|d| {
            Ok(Dependency {
                src_subpass: d.get("srcSubpass")?.u32()?,
                dst_subpass: d.get("dstSubpass")?.u32()?,
                src_stages: d.get("srcStageMask")?.stages()?,
                dst_stages: d.get("dstStageMask")?.stages()?,
                src_access: d.get("srcAccessMask")?.access()?,
                dst_access: d.get("dstAccessMask")?.access()?,
            })
        })
        .collect::<Got<Vec<_>>>()?;
    Ok(RenderPassInfo {
        attachments,
        subpasses,
        dependencies,
    })
}
