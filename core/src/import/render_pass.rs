//! Render pass instances as the GPU runs them: each subpass's attachments resolved to the
//! views the framebuffer (or `vkCmdBeginRendering`) names, load and store ops per first and
//! last use, and the layout transitions and external dependencies the render pass implies at
//! its start and end, as barriers.

use super::commands::{
    AttUse, BarrierCmd, BarrierTarget, DepthUse, Origin, RenderInstance, SubpassUse, clear_color_of,
};
use super::state::{AttachmentDesc, Dependency, Objects, RenderPassInfo, SubpassDesc};
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

/// The views a render pass instance renders to, by attachment index.
struct Views {
    framebuffer: u64,
    views: Vec<u64>,
}

impl Views {
    fn get(&self, a: u32) -> Got<u64> {
        self.views.get(a as usize).copied().ok_or_else(|| {
            Skip(format!(
                "attachment {a} is not in framebuffer {}",
                self.framebuffer
            ))
        })
    }
}

/// Whether subpass `s` uses attachment `a` in any role.
fn uses_attachment(s: &SubpassDesc, a: u32) -> bool {
    s.colors
        .iter()
        .chain(&s.resolves)
        .chain(&s.inputs)
        .any(|(x, _)| *x == a)
        || s.depth.as_ref().is_some_and(|(x, _)| *x == a)
}

fn first_use(rp: &RenderPassInfo, a: u32) -> Option<usize> {
    rp.subpasses.iter().position(|s| uses_attachment(s, a))
}

fn last_use(rp: &RenderPassInfo, a: u32) -> Option<usize> {
    rp.subpasses.iter().rposition(|s| uses_attachment(s, a))
}

pub(super) fn begin_render_pass(
    args: &Arg<'_>,
    objects: &Objects,
    origin: Origin,
) -> Got<RenderInstance> {
    let info = args.get("pRenderPassBegin")?;
    let rp_handle = info.get("renderPass")?.handle()?;
    let fb_handle = info.get("framebuffer")?.handle()?;
    let rp = objects
        .render_passes
        .get(&rp_handle)
        .ok_or_else(|| Skip(format!("render pass {rp_handle} was never created")))?;
    let framebuffer = objects
        .framebuffers
        .get(&fb_handle)
        .ok_or_else(|| Skip(format!("framebuffer {fb_handle} was never created")))?;
    let layers = framebuffer.layers;
    let mut views = framebuffer.attachments.clone();
    // Imageless framebuffers take their views from VkRenderPassAttachmentBeginInfo.
    let mut next = info.opt("pNext");
    while let Some(n) = next {
        if let Some(list) = n.opt("pAttachments") {
            views = list.items()?.iter().map(Arg::handle).collect::<Got<_>>()?;
        }
        next = n.opt("pNext");
    }
    let views = Views {
        framebuffer: fb_handle,
        views,
    };
    let clears: Vec<Arg<'_>> = info.list("pClearValues")?;
    let subpasses = rp
        .subpasses
        .iter()
        .enumerate()
        .map(|(si, s)| subpass_use(rp, si, s, &views, &clears))
        .collect::<Got<Vec<_>>>()?;
    let mut begin_barriers = Vec::new();
    let mut end_barriers = Vec::new();
    let mut layouts = Vec::new();
    for (a, d) in rp.attachments.iter().enumerate() {
        let (begin, end) = attachment_barriers(rp, a as u32, d, &views, objects, &origin);
        begin_barriers.extend(begin);
        end_barriers.extend(end);
        if let (Some(_), Ok(view), Some(initial), Some(last)) = (
            first_use(rp, a as u32),
            views.get(a as u32),
            d.initial,
            d.final_layout,
        ) {
            layouts.push((
                view,
                (initial != ImageLayout::Undefined).then_some(initial),
                last,
            ));
        }
    }
    Ok(RenderInstance {
        subpasses,
        begin_barriers,
        end_barriers,
        layouts,
        layers,
    })
}

/// Load and store ops of attachment `a` in subpass `si`: its own at its first and last use,
/// LOAD and STORE in between (the contents carry over between subpasses).
fn ops(rp: &RenderPassInfo, si: usize, a: u32) -> (String, String, String, String) {
    let d = &rp.attachments[a as usize];
    let first = first_use(rp, a) == Some(si);
    let last = last_use(rp, a) == Some(si);
    let load = |op: &str| if first { op } else { "LOAD" }.to_owned();
    let store = |op: &str| if last { op } else { "STORE" }.to_owned();
    (
        load(&d.load),
        store(&d.store),
        load(&d.stencil_load),
        store(&d.stencil_store),
    )
}

/// The attachments subpass `si` renders to.
fn subpass_use(
    rp: &RenderPassInfo,
    si: usize,
    s: &SubpassDesc,
    views: &Views,
    clears: &[Arg<'_>],
) -> Got<SubpassUse> {
    let lacks = |a: u32| {
        Skip(format!(
            "subpass {si} names attachment {a} the render pass lacks"
        ))
    };
    let mut sub = SubpassUse::default();
    for (k, &(a, _)) in s.colors.iter().enumerate() {
        if a as usize >= rp.attachments.len() {
            return Err(lacks(a));
        }
        let (load, store, ..) = ops(rp, si, a);
        let format = rp.attachments.get(a as usize).map(|d| d.format.as_str());
        let clear = clears
            .get(a as usize)
            .map(|c| clear_color_of(c, format))
            .unwrap_or_default();
        sub.colors.push(AttUse {
            view: views.get(a)?,
            slot: s.color_slots.get(k).copied().unwrap_or(k as u32),
            load,
            store,
            clear,
        });
    }
    if let Some((a, layout)) = &s.depth {
        if *a as usize >= rp.attachments.len() {
            return Err(lacks(*a));
        }
        let (load, store, stencil_load, stencil_store) = ops(rp, si, *a);
        let ds = clears.get(*a as usize).and_then(|c| c.opt("depthStencil"));
        sub.depth = Some(DepthUse {
            view: views.get(*a)?,
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
            read_only: layout.is_some_and(ImageLayout::depth_read_only),
            stencil_read_only: layout.is_some_and(ImageLayout::stencil_read_only),
        });
    }
    // A resolve attachment resolves the colour attachment at its own position in the lists.
    for (k, &(a, _)) in s.resolves.iter().enumerate() {
        let slot = s.resolve_slots.get(k).copied().unwrap_or(k as u32);
        let color = s.color_slots.iter().position(|&c| c == slot);
        if let Some(&(src, _)) = color.and_then(|c| s.colors.get(c)) {
            sub.resolves.push((views.get(src)?, views.get(a)?));
        }
    }
    Ok(sub)
}

/// Every declared external dependency into (or out of) a subpass applies to an attachment
/// together.
fn fold(deps: impl Iterator<Item = Dependency>) -> Option<Dependency> {
    deps.reduce(|a, b| Dependency {
        src_stages: a.src_stages | b.src_stages,
        dst_stages: a.dst_stages | b.dst_stages,
        src_access: a.src_access | b.src_access,
        dst_access: a.dst_access | b.dst_access,
        ..a
    })
}

/// The barriers attachment `a` gets at the start and the end of the render pass: its
/// transition from initialLayout and to finalLayout, each with the external dependency that
/// orders it.
fn attachment_barriers(
    rp: &RenderPassInfo,
    a: u32,
    d: &AttachmentDesc,
    views: &Views,
    objects: &Objects,
    origin: &Origin,
) -> (Option<BarrierCmd>, Option<BarrierCmd>) {
    let (Some(first), Some(last)) = (first_use(rp, a), last_use(rp, a)) else {
        return (None, None);
    };
    let Ok(v) = views.get(a) else {
        return (None, None);
    };
    let Some(image) = objects.views.get(&v) else {
        return (None, None);
    };
    let layout_in = |si: usize| {
        let s = &rp.subpasses[si];
        s.colors
            .iter()
            .chain(&s.resolves)
            .chain(&s.inputs)
            .chain(s.depth.iter())
            .find(|(x, _)| *x == a)
            .map(|(_, l)| *l)
    };
    let target = BarrierTarget::Image {
        image: image.image,
        mips: (image.base_mip, image.mip_count),
        layers: (image.base_layer, image.layer_count),
    };
    // A declared external dependency orders the attachment against earlier (or later) work
    // even where the layout stays; the implicit one exists only where the layout changes
    // (Vulkan's render pass chapter: "only exists if there exists an automatic layout
    // transition away from initialLayout", and likewise into finalLayout).
    let transition = |from: Option<ImageLayout>,
                      to: Option<ImageLayout>,
                      dep: &Dependency,
                      what: &'static str,
                      always: bool|
     -> Option<BarrierCmd> {
        let (from, to) = (from?, to?);
        (from != to || always).then(|| BarrierCmd {
            origin: Origin {
                attachment: Some((a, what)),
                ..origin.clone()
            },
            target: target.clone(),
            src_stages: dep.src_stages,
            dst_stages: dep.dst_stages,
            src_access: dep.src_access,
            dst_access: dep.dst_access,
            layouts: Some((from, to)),
            families: None,
        })
    };
    let deps = rp.dependencies.iter().cloned();
    let declared_in = fold(
        deps.clone()
            .filter(|x| x.src_subpass == EXTERNAL && x.dst_subpass as usize == first),
    );
    let declared_out =
        fold(deps.filter(|x| x.dst_subpass == EXTERNAL && x.src_subpass as usize == last));
    let in_what = if declared_in.is_some() {
        "initialLayout, external dependency"
    } else {
        "initialLayout, implicit external dependency"
    };
    let out_what = if declared_out.is_some() {
        "finalLayout, external dependency"
    } else {
        "finalLayout, implicit external dependency"
    };
    let begin = layout_in(first).and_then(|l| {
        let dep = declared_in.clone().unwrap_or_else(|| implicit(true));
        transition(d.initial, l, &dep, in_what, declared_in.is_some())
    });
    let end = layout_in(last).and_then(|l| {
        let dep = declared_out.clone().unwrap_or_else(|| implicit(false));
        transition(l, d.final_layout, &dep, out_what, declared_out.is_some())
    });
    (begin, end)
}

pub(super) fn begin_rendering(info: &Arg<'_>, objects: &Objects) -> Got<RenderInstance> {
    let mut sub = SubpassUse::default();
    // Dynamic rendering neither transitions nor expects anything but each view's own layout.
    let mut layouts = Vec::new();
    let mut expect = |view: u64, a: &Arg<'_>| {
        if let Some(l) = a
            .get("imageLayout")
            .ok()
            .and_then(|l| ImageLayout::from_name(&l.symbol().ok()?))
        {
            layouts.push((view, Some(l), l));
        }
    };
    for (slot, c) in info.list("pColorAttachments")?.iter().enumerate() {
        let view = c.get("imageView")?.handle()?;
        if view == 0 {
            continue;
        }
        expect(view, c);
        sub.colors.push(AttUse {
            view,
            slot: slot as u32,
            load: c.get("loadOp")?.name()?,
            store: c.get("storeOp")?.name()?,
            clear: c
                .opt("clearValue")
                .map(|v| clear_color_of(&v, objects.view_kinds.get(&view).map(|k| k.1.as_str())))
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
        let view = d.get("imageView")?.handle()?;
        expect(view, d);
        sub.depth = Some(DepthUse {
            view,
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
            read_only: ImageLayout::from_name(&d.get("imageLayout")?.symbol()?)
                .is_some_and(ImageLayout::depth_read_only),
            stencil_read_only: ImageLayout::from_name(&d.get("imageLayout")?.symbol()?)
                .is_some_and(ImageLayout::stencil_read_only),
        });
    }

    Ok(RenderInstance {
        subpasses: vec![sub],
        begin_barriers: Vec::new(),
        end_barriers: Vec::new(),
        layouts,
        layers: info
            .opt("layerCount")
            .and_then(|l| l.u32().ok())
            .unwrap_or(1),
    })
}
