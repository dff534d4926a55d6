//! Blit passes: scaled, filtered copies between 2D subresources (Vulkan's `vkCmdBlitImage`),
//! checked against the rules the specification gives the command: both sides single-sampled
//! textures, corners inside their mips, no overlap within one subresource, integer formats
//! only with integer formats of the same signedness and only with nearest filtering.

use super::Validator;
use crate::capture::diag::JsonPath;
use crate::capture::dxgi::Numeric;
use crate::capture::format::{Access, Blit, BlitFilter, BlitRegion, PassKind, ResourceKind};
use crate::capture::model::{
    AccessSource, BlitDesc, BlitSide, ResourceAccess, ResourceDesc, Subresources,
};

impl Validator<'_> {
    /// The pass's blits, each with its source read and destination write.
    pub(super) fn pass_blits(
        &mut self,
        p: &crate::capture::format::Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Vec<BlitDesc> {
        if p.kind == PassKind::Blit && p.blits.is_empty() {
            self.diags.error(
                "blit",
                path,
                format!("blit pass \"{}\" has no blits", p.name),
            );
        }
        let mut out = Vec::new();
        for (i, b) in p.blits.iter().enumerate() {
            let bpath = path.field("blits").index(i);
            if let Some(d) = self.check_blit(b, &bpath, resources, accesses, i) {
                out.push(d);
            }
        }
        out
    }

    fn check_blit(
        &mut self,
        b: &Blit,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        index: usize,
    ) -> Option<BlitDesc> {
        let before = self.diags.error_count();
        let src = self.blit_side(&b.src, &path.field("src"), resources);
        let dst = self.blit_side(&b.dst, &path.field("dst"), resources);
        let ((src, sr), (dst, dr)) = (src?, dst?);
        let (sf, df) = (sr.format?, dr.format?);
        let kind = |n: Option<Numeric>| match n {
            Some(Numeric::Uint) => "unsigned integer",
            Some(Numeric::Sint) => "signed integer",
            _ => "floating-point or normalised",
        };
        let (sk, dk) = (kind(sf.numeric()), kind(df.numeric()));
        if sk != dk {
            self.diags.error(
                "blit",
                path,
                format!(
                    "cannot blit {} ({sk}) into {} ({dk}): a blit converts only between formats of one kind",
                    sf.name, df.name
                ),
            );
        }
        if (sf.is_depth_stencil() || df.is_depth_stencil()) && sf.name != df.name {
            self.diags.error(
                "blit",
                path,
                format!(
                    "a depth or stencil blit needs one format on both sides, not {} and {}",
                    sf.name, df.name
                ),
            );
        }
        if b.filter == BlitFilter::Linear && (sf.is_integer() || sf.is_depth_stencil()) {
            self.diags.error(
                "blit",
                &path.field("filter"),
                format!("{} cannot be filtered linearly; use nearest", sf.name),
            );
        }
        if src.resource == dst.resource && src.mip == dst.mip && src.layer == dst.layer {
            let span = |c: [[u32; 2]; 2], k: usize| (c[0][k].min(c[1][k]), c[0][k].max(c[1][k]));
            let overlaps = (0..2).all(|k| {
                let (a0, a1) = span(src.corners, k);
                let (b0, b1) = span(dst.corners, k);
                a0 < b1 && b0 < a1
            });
            if overlaps {
                self.diags.error(
                    "blit",
                    path,
                    format!(
                        "the source and destination regions overlap in mip {} layer {} of \"{}\"",
                        src.mip, src.layer, sr.name
                    ),
                );
            }
        }
        if self.diags.error_count() > before {
            return None;
        }
        for (side, access, reads, writes) in [
            (&src, Access::CopySrc, true, false),
            (&dst, Access::CopyDst, false, true),
        ] {
            let r = resources?.get(side.resource.0 as usize)?;
            let mut range = Subresources::whole(r);
            range.mip_base = side.mip;
            range.mip_count = 1;
            range.layer_base = side.layer;
            range.layer_count = 1;
            accesses.push(ResourceAccess {
                resource: side.resource,
                access,
                range,
                reads,
                writes,
                source: AccessSource::Blit(index),
            });
        }
        Some(BlitDesc {
            src,
            dst,
            linear: b.filter == BlitFilter::Linear,
        })
    }

    /// One side: a single-sampled 1D or 2D texture, its subresource, corners inside the mip.
    fn blit_side<'r>(
        &mut self,
        side: &BlitRegion,
        path: &JsonPath,
        resources: Option<&'r [ResourceDesc]>,
    ) -> Option<(BlitSide, &'r ResourceDesc)> {
        let id = self.lookup("resource", &side.resource, &path.field("resource"));
        let r = resources?.get(id? as usize)?;
        if !r.is_texture() || r.kind == ResourceKind::Texture3D {
            self.diags.error(
                "blit",
                &path.field("resource"),
                format!(
                    "\"{}\" is not a 1D or 2D texture; blits read and write those",
                    r.name
                ),
            );
            return None;
        }
        if r.samples > 1 {
            self.diags.error(
                "blit",
                &path.field("resource"),
                format!(
                    "\"{}\" is multisampled ({} samples); blits take single-sampled textures (resolve it first)",
                    r.name, r.samples
                ),
            );
            return None;
        }
        // Reports a mip or layer that does not exist.
        self.single_subresource(r, side.mip, side.layer, path);
        let (w, h, _) = r.mip_extent(side.mip.min(r.mip_levels.saturating_sub(1)));
        for (k, corner) in side.corners.iter().enumerate() {
            if corner[0] > w || corner[1] > h {
                self.diags.error(
                    "blit",
                    &path.field("corners").index(k),
                    format!(
                        "corner {corner:?} is outside mip {} of \"{}\" ({w}x{h})",
                        side.mip, r.name
                    ),
                );
            }
        }
        Some((
            BlitSide {
                resource: r.id,
                mip: side.mip,
                layer: side.layer,
                corners: side.corners,
            },
            r,
        ))
    }
}
