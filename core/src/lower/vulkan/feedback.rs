//! Feedback loops: a texture a draw binds that the same pass renders to. Vulkan lets a
//! subpass read its own attachment (an input attachment, "framebuffer fetch", as Skia reads
//! the destination for its blend modes; a feedback-loop layout); wgpu does not read and render
//! one subresource in a pass. A draw that reads exactly the colour subresource it renders
//! reads a copy taken before it (`VkFetch`); any other such read is refused by name.

use crate::plan::*;

/// A binding of draw's group `set` at wgpu binding `binding` that reads colour attachment
/// `color`, to be pointed at the attachment's copy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Fetched {
    pub set: usize,
    pub binding: u32,
    pub color: usize,
}

/// A read of an attachment the pass renders that a copy cannot stand in for.
#[derive(Debug, thiserror::Error)]
#[error(
    "{attachment} read through set {set} (wgpu binding {binding}) in the pass that renders to it ({why}: wgpu cannot read and render one subresource in a pass)"
)]
pub(super) struct Unfetchable {
    attachment: String,
    set: usize,
    binding: u32,
    why: &'static str,
}

/// The bindings of one draw that read an attachment of its pass, or why one cannot be
/// replayed.
pub(super) fn feedback(
    groups: &[Option<VkGroup>],
    color: &[ColorTarget],
    depth: Option<&DepthTarget>,
    textures: &[TextureSpec],
) -> Result<Vec<Fetched>, Unfetchable> {
    let within =
        |x: u32, base: u32, count: Option<u32>| x >= base && count.is_none_or(|n| x - base < n);
    let mut out = Vec::new();
    for (set, g) in groups.iter().enumerate() {
        let Some(g) = g else { continue };
        for (binding, r) in &g.entries {
            let VkResource::Texture {
                texture,
                base_mip,
                mips,
                base_layer,
                layers,
                ..
            } = r
            else {
                continue;
            };
            let seen = |t: usize, mip: u32, layer: u32| {
                t == *texture
                    && within(mip, *base_mip, *mips)
                    && within(layer, *base_layer, *layers)
            };
            let unfetchable = |attachment: String, why: &'static str| Unfetchable {
                attachment,
                set,
                binding: *binding,
                why,
            };
            if let Some(k) = color.iter().position(|c| seen(c.texture, c.mip, c.layer)) {
                let spec = &textures[color[k].texture];
                let count =
                    |n: Option<u32>, base: u32, all: u32| n.unwrap_or(all.saturating_sub(base));
                let one_subresource = count(*mips, *base_mip, spec.mip_levels) == 1
                    && count(*layers, *base_layer, spec.size.depth_or_array_layers) == 1;
                let why = if spec.samples > 1 {
                    Some("a multisampled attachment, which the replay does not copy")
                } else if spec.dimension != wgpu_types::TextureDimension::D2 {
                    Some("a slice of a 3D attachment, which the replay does not copy")
                } else if !one_subresource {
                    Some(
                        "a view of more than the subresource rendered to, which a copy of it would not hold",
                    )
                } else {
                    None
                };
                match why {
                    Some(why) => return Err(unfetchable(format!("colour attachment {k}"), why)),
                    None => out.push(Fetched {
                        set,
                        binding: *binding,
                        color: k,
                    }),
                }
                continue;
            }
            if depth
                .filter(|d| !(d.read_only && d.stencil_read_only))
                .is_some_and(|d| seen(d.texture, d.mip, d.layer))
            {
                return Err(unfetchable(
                    "the depth/stencil attachment".to_owned(),
                    "a feedback loop on a writable depth/stencil attachment",
                ));
            }
        }
    }
    Ok(out)
}

/// Points the fetched bindings at the copies (`copies[k]`: colour attachment `k`'s copy,
/// one level and one layer).
pub(super) fn redirect(groups: &mut [Option<VkGroup>], fetched: &[Fetched], copies: &[usize]) {
    for f in fetched {
        let Some(g) = groups.get_mut(f.set).and_then(Option::as_mut) else {
            continue;
        };
        for (binding, r) in &mut g.entries {
            if *binding != f.binding {
                continue;
            }
            if let VkResource::Texture {
                texture,
                base_mip,
                mips,
                base_layer,
                layers,
                ..
            } = r
            {
                *texture = copies[f.color];
                *base_mip = 0;
                *mips = Some(1);
                *base_layer = 0;
                *layers = Some(1);
            }
        }
    }
}

impl crate::lower::Lowering<'_> {
    /// The copy of colour target `c`'s subresource that draws reading it bind, made on first
    /// use: one level and one layer of the attachment's format, shared by every pass that
    /// renders to and reads the same subresource (the copies are taken in queue order).
    pub(super) fn vk_attachment_copy(&mut self, c: &ColorTarget) -> usize {
        let source = &self.plan.textures[c.texture];
        let mut name = format!("{} as drawn so far", source.name);
        if c.mip > 0 || c.layer > 0 {
            name.push_str(&format!(" (level {}, layer {})", c.mip, c.layer));
        }
        if let Some(t) = self.plan.textures.iter().position(|t| t.name == name) {
            return t;
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
        self.plan.textures.len() - 1
    }
}
