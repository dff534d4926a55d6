//! What the lowering settles across passes once each is lowered. First, the formats each
//! texture is viewed in besides its own. wgpu makes a view in another format
//! only where the texture was created listing it, and lists only the sRGB twin of its format
//! (Vulkan's `VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT` images with a `VkImageFormatListCreateInfo`
//! of UNORM and SRGB, D3D12's typeless resources viewed both ways): every view the plan makes
//! is gathered after the passes are lowered, so no pass has to know what the others view.
//! Likewise what a resolve pass reads is kept by the render pass before it.

use wgpu_types::TextureFormat;

use crate::plan::{BindTarget, PassOp, Plan, VkGroup, VkResource};

/// Adds to each texture of `plan` the other formats its views take.
pub(super) fn gather(plan: &mut Plan) {
    let mut views: Vec<(usize, TextureFormat)> = Vec::new();
    let groups = |gs: &[Option<VkGroup>], out: &mut Vec<(usize, TextureFormat)>| {
        for g in gs.iter().flatten() {
            for (_, r) in &g.entries {
                if let VkResource::Texture {
                    texture,
                    format: Some(f),
                    ..
                } = r
                {
                    out.push((*texture, *f));
                }
            }
        }
    };
    for pass in &plan.passes {
        match &pass.op {
            PassOp::Raster(r) => {
                views.extend(r.color.iter().map(|c| (c.texture, c.format)));
                views.extend(r.depth.iter().map(|d| (d.texture, d.format)));
                views.extend(r.bindings.iter().filter_map(|b| match b.target {
                    BindTarget::Texture {
                        texture, format, ..
                    } => Some((texture, format)),
                    _ => None,
                }));
            }
            PassOp::Compute(c) => {
                views.extend(c.bindings.iter().filter_map(|b| match b.target {
                    BindTarget::Texture {
                        texture, format, ..
                    } => Some((texture, format)),
                    _ => None,
                }));
            }
            PassOp::VkRaster(r) => {
                views.extend(r.color.iter().map(|c| (c.texture, c.format)));
                views.extend(r.depth.iter().map(|d| (d.texture, d.format)));
                for d in &r.draws {
                    groups(&d.groups, &mut views);
                }
            }
            PassOp::VkCompute(c) => {
                for d in &c.dispatches {
                    groups(&d.groups, &mut views);
                }
            }
            _ => {}
        }
    }
    for (t, f) in views {
        let Some(spec) = plan.textures.get_mut(t) else {
            continue;
        };
        if f != spec.format
            && f.remove_srgb_suffix() == spec.format.remove_srgb_suffix()
            && !spec.view_formats.contains(&f)
        {
            spec.view_formats.push(f);
        }
    }
}

/// Marks each depth target its own pass also reads through a binding (`DepthTarget::sampled`).
pub(super) fn mark_sampled_depth(plan: &mut Plan) {
    let in_groups = |gs: &[Option<VkGroup>], t: usize| {
        gs.iter().flatten().any(|g| {
            g.entries
                .iter()
                .any(|(_, r)| matches!(r, VkResource::Texture { texture, .. } if *texture == t))
        })
    };
    for pass in &mut plan.passes {
        match &mut pass.op {
            PassOp::Raster(r) => {
                if let Some(d) = r.depth.as_mut() {
                    d.sampled = r.bindings.iter().any(|b| {
                        matches!(b.target, BindTarget::Texture { texture, .. } if texture == d.texture)
                    });
                }
            }
            PassOp::VkRaster(r) => {
                if let Some(d) = r.depth.as_mut() {
                    d.sampled = r.draws.iter().any(|dr| in_groups(&dr.groups, d.texture));
                }
            }
            _ => {}
        }
    }
}

/// Keeps the multisampled contents a resolve pass reads. A Vulkan subpass resolves its
/// attachments as it ends and may discard the multisampled ones (`storeOp` DONT_CARE, the
/// usual way); the import makes that resolve a pass of its own after the render pass, so the
/// render pass before it must store what the resolve reads.
pub(super) fn keep_resolved(plan: &mut Plan) {
    for i in 0..plan.passes.len() {
        let PassOp::Resolve { src, .. } = plan.passes[i].op else {
            continue;
        };
        for pass in plan.passes[..i].iter_mut().rev() {
            let targets = match &mut pass.op {
                PassOp::VkRaster(r) => &mut r.color,
                PassOp::Raster(r) => &mut r.color,
                _ => continue,
            };
            if let Some(t) = targets.iter_mut().find(|t| t.texture == src) {
                t.store = true;
                break;
            }
        }
    }
}
