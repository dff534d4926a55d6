//! Feedback loops: a texture a draw binds that the same pass renders to. Vulkan lets a
//! subpass read its own attachment (an input attachment, "framebuffer fetch", as Skia reads
//! the destination for its blend modes; a feedback-loop layout); wgpu does not read and render
//! one subresource in a pass. A draw that samples or fetches exactly the colour subresource it
//! renders reads a copy taken before it (`VkFetch`); any other such binding is refused by name.

use super::{VkProblem, vk_error};
use crate::capture::model::PassDesc;
use crate::lower::{LowerError, Lowering};
use crate::plan::*;

/// Entry `entry` of a draw's group `set`, which reads colour attachment `color`, to be
/// pointed at the attachment's copy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Fetched {
    set: usize,
    entry: usize,
    color: usize,
}

/// A binding of an attachment the pass renders that a copy cannot stand in for.
#[derive(Debug, thiserror::Error)]
#[error(
    "{attachment} read through set {set} (wgpu binding {binding}) in the pass that renders to it ({why}: wgpu cannot read and render one subresource in a pass)"
)]
struct Unfetchable {
    attachment: String,
    set: usize,
    binding: u32,
    why: &'static str,
}

/// Why a colour attachment's binding cannot read a copy of it, if it cannot.
fn uncopyable(
    spec: &TextureSpec,
    layout: Option<&wgpu_types::BindGroupLayoutEntry>,
    (base_mip, mips, base_layer, layers): (u32, Option<u32>, u32, Option<u32>),
) -> Option<&'static str> {
    let count = |n: Option<u32>, base: u32, all: u32| n.unwrap_or(all.saturating_sub(base));
    let sampled = layout.is_some_and(|l| matches!(l.ty, wgpu_types::BindingType::Texture { .. }));
    if !sampled {
        Some("a storage image of the attachment, whose writes a copy would not keep")
    } else if spec.samples > 1 {
        Some("a multisampled attachment, which the replay does not copy")
    } else if spec.dimension != wgpu_types::TextureDimension::D2 {
        Some("a slice of a 3D attachment, which the replay does not copy")
    } else if count(mips, base_mip, spec.mip_levels) != 1
        || count(layers, base_layer, spec.size.depth_or_array_layers) != 1
    {
        Some("a view of more than the subresource rendered to, which a copy of it would not hold")
    } else {
        None
    }
}

/// The entries of one draw's groups that read an attachment of its pass, or why one cannot
/// be replayed.
fn feedback(
    groups: &[Option<VkGroup>],
    (color, depth): (&[ColorTarget], Option<&DepthTarget>),
    textures: &[TextureSpec],
    layouts: &[Vec<wgpu_types::BindGroupLayoutEntry>],
) -> Result<Vec<Fetched>, Unfetchable> {
    let within =
        |x: u32, base: u32, count: Option<u32>| x >= base && count.is_none_or(|n| x - base < n);
    let mut out = Vec::new();
    for (set, g) in groups.iter().enumerate() {
        let Some(g) = g else { continue };
        for (entry, (binding, r)) in g.entries.iter().enumerate() {
            let VkResource::Texture {
                texture,
                base_mip,
                mips,
                base_layer,
                layers,
                ..
            } = *r
            else {
                continue;
            };
            let seen = |t: usize, mip: u32, layer: u32| {
                t == texture && within(mip, base_mip, mips) && within(layer, base_layer, layers)
            };
            let refuse = |attachment: String, why| Unfetchable {
                attachment,
                set,
                binding: *binding,
                why,
            };
            if let Some(k) = color.iter().position(|c| seen(c.texture, c.mip, c.layer)) {
                let layout = layouts
                    .get(g.layout)
                    .and_then(|l| l.iter().find(|e| e.binding == *binding));
                let range = (base_mip, mips, base_layer, layers);
                if let Some(why) = uncopyable(&textures[texture], layout, range) {
                    return Err(refuse(format!("colour attachment {k}"), why));
                }
                out.push(Fetched {
                    set,
                    entry,
                    color: k,
                });
            } else if depth
                .filter(|d| !(d.read_only && d.stencil_read_only))
                .is_some_and(|d| seen(d.texture, d.mip, d.layer))
            {
                return Err(refuse(
                    "the depth/stencil attachment".to_owned(),
                    "a feedback loop on a writable depth/stencil attachment",
                ));
            }
        }
    }
    Ok(out)
}

impl Lowering<'_> {
    /// Points every draw's reads of a colour attachment its pass renders at a copy taken
    /// before the draw, and gives the copies to take; a read no copy can stand in for refuses
    /// the draw by name.
    pub(super) fn vk_fetches(
        &mut self,
        p: &PassDesc,
        draws: &mut [VkDrawOp],
        (color, depth): (&[ColorTarget], Option<&DepthTarget>),
        cleared_read_only: bool,
    ) -> Result<Vec<VkFetch>, LowerError> {
        let mut fetches = Vec::new();
        for (i, op) in draws.iter_mut().enumerate() {
            let layouts = &self.plan.vk.group_layouts;
            let fetched = feedback(&op.groups, (color, depth), &self.plan.textures, layouts)
                .map_err(|e| {
                    let feature = if cleared_read_only {
                        format!(
                            "vkCmdClearAttachments of a depth/stencil attachment in a read-only layout that the pass's draws also sample ({e})"
                        )
                    } else {
                        e.to_string()
                    };
                    vk_error(p, format!("draw {i}"), VkProblem::Unsupported { feature })
                })?;
            let mut read: Vec<usize> = fetched.iter().map(|f| f.color).collect();
            read.sort_unstable();
            read.dedup();
            for k in read {
                let copy = self.vk_attachment_copy(&color[k]);
                for f in fetched.iter().filter(|f| f.color == k) {
                    if let Some(g) = op.groups.get_mut(f.set).and_then(Option::as_mut)
                        && let VkResource::Texture {
                            texture,
                            base_mip,
                            mips,
                            base_layer,
                            layers,
                            ..
                        } = &mut g.entries[f.entry].1
                    {
                        (*texture, *base_mip, *mips, *base_layer, *layers) =
                            (copy, 0, Some(1), 0, Some(1));
                    }
                }
                fetches.push(VkFetch {
                    before: i,
                    color: k,
                    copy,
                });
            }
        }
        if !fetches.is_empty() {
            let mut draws_reading: Vec<usize> = fetches.iter().map(|f| f.before).collect();
            draws_reading.dedup();
            self.notes.push(format!(
                "pass \"{}\": {} draw(s) read a colour attachment the pass renders to (framebuffer fetch, or a feedback loop); the replay ends the render pass before each, copies the attachment and lets the draw read the copy",
                p.name,
                draws_reading.len()
            ));
        }
        Ok(fetches)
    }

    /// The copy of colour target `c`'s subresource that draws reading it bind, made on first
    /// use: one level and one layer of the attachment's format, shared by every pass that
    /// renders to and reads the same subresource (the copies are taken in queue order).
    fn vk_attachment_copy(&mut self, c: &ColorTarget) -> usize {
        let key = (c.texture, c.mip, c.layer);
        if let Some(&t) = self.vk.attachment_copies.get(&key) {
            return t;
        }
        let source = &self.plan.textures[c.texture];
        let mut name = format!("{} as drawn so far", source.name);
        if c.mip > 0 || c.layer > 0 {
            name.push_str(&format!(" (level {}, layer {})", c.mip, c.layer));
        }
        let copy = TextureSpec {
            name,
            format: source.format,
            dimension: wgpu_types::TextureDimension::D2,
            size: wgpu_types::Extent3d {
                width: (source.size.width >> c.mip).max(1),
                height: (source.size.height >> c.mip).max(1),
                depth_or_array_layers: 1,
            },
            mip_levels: 1,
            samples: 1,
            usage: wgpu_types::TextureUsages::TEXTURE_BINDING | wgpu_types::TextureUsages::COPY_DST,
            view_formats: source.view_formats.clone(),
            initial: None,
            history: false,
            cube: false,
        };
        self.plan.textures[c.texture].usage |= wgpu_types::TextureUsages::COPY_SRC;
        self.plan.textures.push(copy);
        let index = self.plan.textures.len() - 1;
        self.vk.attachment_copies.insert(key, index);
        index
    }
}
