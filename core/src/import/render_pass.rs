//! Render pass instances as the GPU runs them: each subpass's attachments resolved to the
//! views the framebuffer (or `vkCmdBeginRendering`) names, load and store ops per first and
//! last use, and the layout transitions and external dependencies the render pass implies at
//! its start and end, as barriers.

use super::commands::{
    AttUse, BarrierCmd, BarrierTarget, DepthUse, RenderInstance, SubpassUse, clear_color,
};
use super::state::{Dependency, Objects};
use super::value::{Arg, Got, Skip};
use crate::capture::vulkan::{AccessFlags as A, ImageLayout, PipelineStages as S};

const EXTERNAL: u32 = u32::MAX;

/// The implicit external dependencies Vulkan adds when a render pass declares none.
fn implicit(begin: bool) -> Dependency {
    let attachment_access = A::COLOR_ATTACHMENT_READ
        | A::COLOR_ATTACHMENT_WRITE
        | A::DEPTH_STENCIL_ATTACHMENT_READ
        | A::DEPTH_STENCIL_ATTACHMENT_WRITE
        | A::INPUT_ATTACHMENT_READ;
    if begin {
        Dependency {
            src_subpass: EXTERNAL,
            dst_subpass: 0,
            src_stages: S::TOP_OF_PIPE,
            dst_stages: S::ALL_COMMANDS,
            src_access: A::EMPTY,
            dst_access: attachment_access,
        }
    } else {
        Dependency {
            src_subpass: 0,
            dst_subpass: EXTERNAL,
            src_stages: S::ALL_COMMANDS,
            dst_stages: S::BOTTOM_OF_PIPE,
            src_access: A::COLOR_ATTACHMENT_WRITE | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
            dst_access: A::EMPTY,
        }
    }
}

pub(super) fn begin_render_pass(
    args: &Arg<'_>,
    objects: &Objects,
    origin: String,
) -> Got<RenderInstance> {
    let info = args.get("pRenderPassBegin")?;
    let rp_handle = info.get("renderPass")?.handle()?;
    let fb_handle = info.get("framebuffer")?.handle()?;
    let rp = objects
        .render_passes
        .get(&rp_handle)
        .ok_or_else(|| Skip(format!("render pass {rp_handle} was never created")))?;
    let mut views = objects
        .framebuffers
        .get(&fb_handle)
        .ok_or_else(|| Skip(format!("framebuffer {fb_handle} was never created")))?
        .attachments
        .clone();
    // Imageless framebuffers take their views from VkRenderPassAttachmentBeginInfo.
    let mut next = info.opt("pNext");
    while let Some(n) = next {
        if let Some(list) = n.opt("pAttachments") {
            views = list.items()?.iter().map(Arg::handle).collect::<Got<_>>()?;
        }
        next = n.opt("pNext");
    }
    let clears: Vec<Arg<'_>> = info.list("pClearValues")?;
    let view = |a: u32| -> Got<u64> {
        views
            .get(a as usize)
            .copied()
            .ok_or_else(|| Skip(format!("attachment {a} is not in framebuffer {fb_handle}")))
    };
    let first_use = |a: u32| {
        rp.subpasses.iter().position(|s| {
            s.colors
                .iter()
                .chain(&s.resolves)
                .chain(&s.inputs)
                .any(|(x, _)| *x == a)
                || s.depth.as_ref().is_some_and(|(x, _)| *x == a)
        })
    };
    let last_use = |a: u32| {
        rp.subpasses.iter().rposition(|s| {
            s.colors
                .iter()
                .chain(&s.resolves)
                .chain(&s.inputs)
                .any(|(x, _)| *x == a)
                || s.depth.as_ref().is_some_and(|(x, _)| *x == a)
        })
    };
    let mut subpasses = Vec::new();
    for (si, s) in rp.subpasses.iter().enumerate() {
        let ops = |a: u32| -> (String, String, String, String) {
            let d = &rp.attachments[a as usize];
            let first = first_use(a) == Some(si);
            let last = last_use(a) == Some(si);
            let load = |op: &str| {
                if first {
                    op.to_owned()
                } else {
                    "LOAD".to_owned()
                }
            };
            let store = |op: &str| {
                if last {
                    op.to_owned()
                } else {
                    "STORE".to_owned()
                }
            };
            (
                load(&d.load),
                store(&d.store),
                load(&d.stencil_load),
                store(&d.stencil_store),
            )
        };
        let mut sub = SubpassUse::default();
        for &(a, _) in &s.colors {
            if a as usize >= rp.attachments.len() {
                return Err(Skip(format!(
                    "subpass {si} names attachment {a} the render pass lacks"
                )));
            }
            let (load, store, ..) = ops(a);
            let clear = clears.get(a as usize).map(clear_color).unwrap_or_default();
            sub.colors.push(AttUse {
                view: view(a)?,
                load,
                store,
                clear,
            });
        }
        if let Some((a, layout)) = &s.depth {
            if *a as usize >= rp.attachments.len() {
                return Err(Skip(format!(
                    "subpass {si} names attachment {a} the render pass lacks"
                )));
            }
            let (load, store, stencil_load, stencil_store) = ops(*a);
            let ds = clears.get(*a as usize).and_then(|c| c.opt("depthStencil"));
            sub.depth = Some(DepthUse {
                view: view(*a)?,
                load,
                store,
                stencil_load,
                stencil_store,
                depth_clear: ds
                    .as_ref()
                    .and_then(|d| d.get("depth").ok()?.f64().ok())
                    .unwrap_or(1.0),
                stencil_clear: ds
                    .as_ref()
                    .and_then(|d| d.get("stencil").ok()?.u32().ok())
                    .unwrap_or(0),
                read_only: layout.contains("READ_ONLY"),
            });
        }
        for (k, &(a, _)) in s.resolves.iter().enumerate() {
            if let Some(&(src, _)) = s.colors.get(k) {
                sub.resolves.push((view(src)?, view(a)?));
            }
        }
        subpasses.push(sub);
    }
    let mut begin_barriers = Vec::new();
    let mut end_barriers = Vec::new();
    for (a, d) in rp.attachments.iter().enumerate() {
        let a = a as u32;
        let layout_in = |si: usize| {
            let s = &rp.subpasses[si];
            s.colors
                .iter()
                .chain(&s.resolves)
                .chain(&s.inputs)
                .chain(s.depth.iter())
                .find(|(x, _)| *x == a)
                .map(|(_, l)| l.clone())
        };
        let (Some(first), Some(last)) = (first_use(a), last_use(a)) else {
            continue;
        };
        let Ok(v) = view(a) else { continue };
        let Some(image) = objects.views.get(&v) else {
            continue;
        };
        let target = BarrierTarget::Image {
            image: image.image,
            mips: (image.base_mip, image.mip_count),
            layers: (image.base_layer, image.layer_count),
        };
        // The external dependency orders the attachment against earlier work even where the
        // layout stays; at the end only a layout change or a declared dependency does anything.
        let transition = |from: &str,
                          to: &str,
                          dep: &Dependency,
                          what: &str,
                          always: bool|
         -> Option<BarrierCmd> {
            let (from, to) = (ImageLayout::from_name(from)?, ImageLayout::from_name(to)?);
            (from != to || always).then(|| BarrierCmd {
                origin: format!("{origin}: attachment {a} {what}"),
                target: target.clone(),
                src_stages: dep.src_stages,
                dst_stages: dep.dst_stages,
                src_access: dep.src_access,
                dst_access: dep.dst_access,
                layouts: Some((from, to)),
                families: None,
            })
        };
        // Every declared external dependency into the first subpass using the attachment (and
        // out of the last) applies to it together.
        let fold = |deps: Vec<&Dependency>| {
            deps.into_iter().cloned().reduce(|a, b| Dependency {
                src_stages: a.src_stages | b.src_stages,
                dst_stages: a.dst_stages | b.dst_stages,
                src_access: a.src_access | b.src_access,
                dst_access: a.dst_access | b.dst_access,
                ..a
            })
        };
        let declared_in = fold(
            rp.dependencies
                .iter()
                .filter(|x| x.src_subpass == EXTERNAL && x.dst_subpass as usize == first)
                .collect(),
        );
        let declared_out = fold(
            rp.dependencies
                .iter()
                .filter(|x| x.dst_subpass == EXTERNAL && x.src_subpass as usize == last)
                .collect(),
        );
        let (in_what, out_what) = (
            if declared_in.is_some() {
                "initialLayout, external dependency"
            } else {
                "initialLayout, implicit external dependency"
            },
            if declared_out.is_some() {
                "finalLayout, external dependency"
            } else {
                "finalLayout, implicit external dependency"
            },
        );
        if let Some(l) = layout_in(first)
            && let Some(b) = transition(
                &d.initial,
                &l,
                &declared_in.clone().unwrap_or_else(|| implicit(true)),
                in_what,
                true,
            )
        {
            begin_barriers.push(b);
        }
        if let Some(l) = layout_in(last)
            && let Some(b) = transition(
                &l,
                &d.final_layout,
                &declared_out.clone().unwrap_or_else(|| implicit(false)),
                out_what,
                declared_out.is_some(),
            )
        {
            end_barriers.push(b);
        }
    }
    Ok(RenderInstance {
        subpasses,
        begin_barriers,
        end_barriers,
    })
}

pub(super) fn begin_rendering(info: &Arg<'_>) -> Got<RenderInstance> {
    let mut sub = SubpassUse::default();
    for c in info.list("pColorAttachments")? {
        let view = c.get("imageView")?.handle()?;
        if view == 0 {
            continue;
        }
        sub.colors.push(AttUse {
            view,
            load: c.get("loadOp")?.name()?,
            store: c.get("storeOp")?.name()?,
            clear: c
                .opt("clearValue")
                .map(|v| clear_color(&v))
                .unwrap_or_default(),
        });
        if let Some(r) = c.opt("resolveImageView") {
            let r = r.handle()?;
            if r != 0 {
                sub.resolves.push((view, r));
            }
        }
    }
    let depth = info
        .opt("pDepthAttachment")
        .filter(|d| d.get("imageView").and_then(|v| v.handle()).unwrap_or(0) != 0);
    let stencil = info
        .opt("pStencilAttachment")
        .filter(|d| d.get("imageView").and_then(|v| v.handle()).unwrap_or(0) != 0);
    if let Some(d) = depth.as_ref().or(stencil.as_ref()) {
        let ops = |a: &Option<Arg<'_>>| -> Got<(String, String)> {
            match a {
                Some(a) => Ok((a.get("loadOp")?.name()?, a.get("storeOp")?.name()?)),
                None => Ok(("DONT_CARE".to_owned(), "DONT_CARE".to_owned())),
            }
        };
        let (load, store) = ops(&depth)?;
        let (stencil_load, stencil_store) = ops(&stencil)?;
        let clear = d.opt("clearValue").and_then(|c| c.opt("depthStencil"));
        sub.depth = Some(DepthUse {
            view: d.get("imageView")?.handle()?,
            load,
            store,
            stencil_load,
            stencil_store,
            depth_clear: clear
                .as_ref()
                .and_then(|c| c.get("depth").ok()?.f64().ok())
                .unwrap_or(1.0),
            stencil_clear: clear
                .as_ref()
                .and_then(|c| c.get("stencil").ok()?.u32().ok())
                .unwrap_or(0),
            read_only: d.get("imageLayout")?.name()?.contains("READ_ONLY"),
        });
    }

    Ok(RenderInstance {
        subpasses: vec![sub],
        begin_barriers: Vec::new(),
        end_barriers: Vec::new(),
    })
}
