//! Hazards inside one pass: a subresource rendered to and bound (a feedback loop), or read
//! through one binding and written through another. Both compare the ranges the pass's
//! accesses cover, so they share the overlap test and the history exception.

use super::Validator;
use crate::capture::diag::JsonPath;
use crate::capture::format::Pass;
use crate::capture::model::{
    AccessSource, BindingDesc, ResourceAccess, ResourceDesc, Subresources,
};

/// Whether two mip and layer ranges share a subresource.
fn overlaps(a: &Subresources, b: &Subresources) -> bool {
    a.mip_base < b.mip_base + b.mip_count
        && b.mip_base < a.mip_base + a.mip_count
        && a.layer_base < b.layer_base + b.layer_count.max(1)
        && b.layer_base < a.layer_base + a.layer_count.max(1)
}

/// Whether `variable` binds a history resource's previous-frame copy: another texture than the
/// one this frame writes, so no hazard with it.
fn previous_frame(bindings: &[BindingDesc], variable: &str) -> bool {
    bindings
        .iter()
        .any(|b| b.variable == variable && b.previous_frame)
}

impl Validator<'_> {
    /// A raster pass may not read or write through a binding a subresource it renders to
    /// (colour, or depth-stencil it writes): GPUs give undefined results and WebGPU refuses it.
    /// A binding of a history resource's previous-frame copy (TAA's history) reads another
    /// texture than the one rendered to, so it is no loop.
    pub(super) fn check_feedback(
        &mut self,
        p: &Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &[ResourceAccess],
        bindings: &[BindingDesc],
    ) {
        for target in accesses.iter().filter(|a| {
            matches!(a.source, AccessSource::ColorAttachment(_))
                || (a.source == AccessSource::DepthStencil && a.writes)
        }) {
            for bound in accesses
                .iter()
                .filter(|a| a.resource == target.resource && overlaps(&a.range, &target.range))
            {
                let AccessSource::Binding(variable) = &bound.source else {
                    continue;
                };
                if previous_frame(bindings, variable) {
                    continue;
                }
                let name = resources
                    .and_then(|r| r.get(target.resource.index()))
                    .map_or("?", |r| r.name.as_str());
                let what = match target.source {
                    AccessSource::ColorAttachment(i) => format!("colour attachment {i}"),
                    _ => "the depth-stencil attachment it writes".to_owned(),
                };
                let message = format!(
                    "pass \"{}\" binds \"{name}\" as `{variable}` while it is {what}: a subresource cannot be read and rendered to in one pass (use a read-only depth attachment, or another mip or layer)",
                    p.name
                );
                // Vulkan lets a subpass read its own attachments (input attachments, feedback
                // loop layouts): an imported frame that does is kept, and the replay refuses it
                // by name.
                if self.vulkan() {
                    self.diags.warning(
                        "feedback-loop",
                        &path.field("bindings").field(variable),
                        message,
                    );
                } else {
                    self.diags.error(
                        "feedback-loop",
                        &path.field("bindings").field(variable),
                        message,
                    );
                }
            }
        }
    }

    /// A subresource may not be read through one binding and written through another in one
    /// pass (a shader resource and an unordered-access view of the same mip and layer, or of
    /// overlapping bytes of a buffer): D3D12 forbids it without a barrier between the work,
    /// and within one dispatch or draw it is undefined. Every pass kind, every overlapping
    /// range. An imported frame
    /// binds what the application bound without the shader code that would say which
    /// bindings it really uses, so there it is a warning.
    pub(super) fn check_view_hazards(
        &mut self,
        p: &Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &[ResourceAccess],
        bindings: &[BindingDesc],
    ) {
        let bound: Vec<(&str, &ResourceAccess)> = accesses
            .iter()
            .filter_map(|a| match &a.source {
                AccessSource::Binding(v) if !previous_frame(bindings, v) => Some((v.as_str(), a)),
                _ => None,
            })
            .collect();
        // A buffer binding's bytes: its range, or the whole buffer.
        let bytes = |variable: &str| {
            p.bindings
                .get(variable)
                .and_then(|b| b.bytes.as_ref())
                .map_or((0, u64::MAX), |r| {
                    (r.offset, r.offset.saturating_add(r.size))
                })
        };
        let imported = self.raw.source.is_some();
        let mut reported = std::collections::BTreeSet::new();
        for (i, (wv, w)) in bound.iter().enumerate() {
            if !w.writes {
                continue;
            }
            let Some(r) = resources.and_then(|r| r.get(w.resource.index())) else {
                continue;
            };
            let texture = r.is_texture();
            for (j, (rv, other)) in bound.iter().enumerate() {
                if i == j || other.resource != w.resource || other.writes {
                    continue;
                }
                let shared = if texture {
                    overlaps(&w.range, &other.range)
                } else {
                    let (a, b) = (bytes(wv), bytes(rv));
                    a.0 < b.1 && b.0 < a.1
                };
                if !shared {
                    continue;
                }
                if !reported.insert((*rv, *wv)) {
                    continue;
                }
                let what = if texture {
                    format!(
                        "the same subresource (mip {}, layer {})",
                        w.range.mip_base.max(other.range.mip_base),
                        w.range.layer_base.max(other.range.layer_base)
                    )
                } else {
                    "overlapping bytes".to_owned()
                };
                let message = format!(
                    "pass \"{}\" reads \"{}\" through `{rv}` ({}) and writes {what} through `{wv}` ({}): one subresource cannot be read and written through different views in one pass; bind one read-write view, or split the pass with a barrier between",
                    p.name,
                    r.name,
                    other.access.as_str(),
                    w.access.as_str()
                );
                let at = path.field("bindings").field(rv);
                if imported {
                    self.diags.warning("view-hazard", &at, message);
                } else {
                    self.diags.error("view-hazard", &at, message);
                }
            }
        }
    }
}
