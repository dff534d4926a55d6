//! Feedback loops: a texture a draw binds that the same pass renders to, which wgpu does not
//! allow and the replay refuses by name.

use crate::plan::*;

/// A texture a draw binds that is also an attachment the pass writes: Vulkan lets a subpass
/// read its own attachment (an input attachment, "framebuffer fetch"; a feedback-loop
/// layout), wgpu does not read and render one subresource in a pass.
pub(super) fn feedback(
    groups: &[Option<VkGroup>],
    color: &[ColorTarget],
    depth: Option<&DepthTarget>,
) -> Option<String> {
    let within =
        |x: u32, base: u32, count: Option<u32>| x >= base && count.is_none_or(|n| x - base < n);
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
            let attachment = color
                .iter()
                .position(|c| seen(c.texture, c.mip, c.layer))
                .map(|k| format!("colour attachment {k}"))
                .or_else(|| {
                    depth
                        .filter(|d| !(d.read_only && d.stencil_read_only))
                        .filter(|d| seen(d.texture, d.mip, d.layer))
                        .map(|_| "the depth/stencil attachment".to_owned())
                });
            if let Some(a) = attachment {
                return Some(format!(
                    "{a} read through set {set} (wgpu binding {binding}) in the pass that renders to it (framebuffer fetch or a feedback loop: wgpu cannot read and render one subresource in a pass)"
                ));
            }
        }
    }
    None
}
