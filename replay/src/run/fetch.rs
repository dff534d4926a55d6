//! An imported render pass whose draws read an attachment it renders to (framebuffer fetch
//! through an input attachment, or a feedback loop; `VkFetch` in the plan): replayed as
//! several wgpu render passes, the attachment copied between them for the draws that read it.
//! The first pass loads or clears as the application's did, the last stores as it did, and
//! every pass between loads and stores everything; the pass's timestamps go on the first
//! pass's start and the last's end, and its statistics are one query per pass, summed.

use framelab_core::plan::{ColorTarget, DepthTarget, VkRasterOp};

use super::Session;
use super::clear_rects::Restore;
use super::stamps::Stamps;
use super::vulkan::{Segment, WorkGroups};

/// The attachments of segment `first`/`last`: later ones load what the one before stored,
/// earlier ones store what the next loads.
fn targets(r: &VkRasterOp, first: bool, last: bool) -> (Vec<ColorTarget>, Option<DepthTarget>) {
    let mut color = r.color.clone();
    let mut depth = r.depth.clone();
    for c in &mut color {
        if !first {
            c.load = None;
            c.discard_load = false;
        }
        if !last {
            c.store = true;
        }
    }
    if let Some(d) = &mut depth {
        if !first {
            d.depth_clear = None;
            d.stencil_clear = None;
        }
        if !last {
            d.depth_store = true;
            d.stencil_store = true;
        }
    }
    (color, depth)
}

impl Session {
    /// Records an imported render pass, split where its draws read what it renders.
    pub(super) fn encode_vk_render_passes(
        &self,
        (i, name): (usize, &str),
        r: &VkRasterOp,
        groups: &WorkGroups,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        (stamps, stat): (Stamps<'_>, Option<super::counters::PassQueries<'_>>),
    ) {
        let segments = r.segments();
        let last = segments.len() - 1;
        let mut carried = Restore::default();
        for (s, draws) in segments.into_iter().enumerate() {
            if s > 0 {
                self.copy_fetched(r, draws.start, parity, encoder);
            }
            let segment = Segment {
                draws,
                first: s == 0,
                last: s == last,
            };
            let (color, depth) = if last == 0 {
                (r.color.clone(), r.depth.clone())
            } else {
                targets(r, segment.first, segment.last)
            };
            let timestamps = stamps.and_then(|(set, start, end)| {
                let start = start.filter(|_| segment.first);
                let end = segment.last.then_some(end);
                (start.is_some() || end.is_some()).then_some(wgpu::RenderPassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: start,
                    end_of_pass_write_index: end,
                })
            });
            let rp = self.begin_render(name, (&color, depth.as_ref()), parity, encoder, timestamps);
            let query = stat.and_then(|q| q.get(s as u32));
            self.encode_vk_raster((i, name), r, groups, rp, query, (&segment, &mut carried));
        }
    }

    /// The copies taken before draw `before`: each attachment's subresource, as drawn so far,
    /// into the texture the draws after it read.
    fn copy_fetched(
        &self,
        r: &VkRasterOp,
        before: usize,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        for f in r.fetches.iter().filter(|f| f.before == before) {
            let c = &r.color[f.color];
            let size = self.plan.textures[f.copy].size;
            encoder.copy_texture_to_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.textures[c.texture][parity],
                    mip_level: c.mip,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: c.layer,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyTextureInfo {
                    texture: &self.textures[f.copy][0],
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                size,
            );
        }
    }
}
