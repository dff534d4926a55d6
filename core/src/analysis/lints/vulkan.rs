//! Lints that compare the barriers a Vulkan application recorded (imported captures) with the
//! ones the frame needs, in Vulkan's terms: stage and access masks and image layouts.
//!
//! The needs are Vulkan's own, derived from each resource's uses in submission order (not from
//! D3D12's state transitions): a write before any later use, a read before a later write, and
//! a change of image layout each need a barrier; reads after reads in one layout need none,
//! and nothing is known of what came before the capture, so a first use needs only its layout.
//! A need is met by a recorded barrier on the resource (or a global memory barrier) recorded
//! on the pass's queue after the previous use and before the pass, whose source scope reaches
//! the previous use, whose destination scope reaches this one, and which leaves an image in a
//! layout this use can take.

use std::collections::{BTreeMap, BTreeSet};

use super::recorded::covers;
use super::recorded::{
    BARRIER_MISSING, BARRIER_OVER_BROAD, BARRIER_REDUNDANT, BARRIER_WRONG_BEFORE_STATE,
};
use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::model::FrameModel;
use crate::capture::format::{Access, BarrierType, HazardKind, PassKind};
use crate::capture::model::{
    Capture, PassDesc, PassId, QueueId, ResourceAccess, ResourceId, Subresources, VulkanBarrierDesc,
};
use crate::capture::vulkan::{AccessFlags as A, ImageLayout as L, PipelineStages as S};

/// FL025 `valid-usage`: a call breaks a valid-usage statement of the specification.
pub const VALID_USAGE: LintKind = LintKind::new(&LintDef {
    code: "FL025",
    name: "valid-usage",
    severity: LintSeverity::Error,
    description: "a call breaks a valid-usage statement of the specification (its VUID given)",
});

/// FL026 `rendering-layout`: a dynamic rendering attachment is not in the layout its
/// `VkRenderingAttachmentInfo` says. What it is used in is the image's layout as the
/// specification has it, but no valid-usage statement says so and the Khronos validation layer
/// (1.3.239) does not check it, so it is a warning rather than `barrier-missing`'s error: a
/// load from it reads undefined contents on drivers that lay the layouts out differently.
pub const RENDERING_LAYOUT: LintKind = LintKind::new(&LintDef {
    code: "FL026",
    name: "rendering-layout",
    severity: LintSeverity::Warning,
    description: "a dynamic rendering attachment is not in the layout its rendering info names",
});

/// A Vulkan frame's recorded barriers against what its passes need, and what the import found
/// in its stream (hazards command by command, valid-usage statements broken).
pub(super) struct VulkanBarriers;

impl Rule for VulkanBarriers {
    fn kinds(&self) -> &'static [LintKind] {
        &[VALID_USAGE, RENDERING_LAYOUT]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        out.extend(compare_vulkan(l.capture, l.model, l.uses));
    }
}

/// Vulkan's scope of one access: stages, access bits and the image layout that serves it.
fn scope(a: Access, raster: bool) -> (S, A, Option<L>) {
    let shader = if raster {
        S::VERTEX_SHADER | S::FRAGMENT_SHADER
    } else {
        S::COMPUTE_SHADER
    };
    let tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    match a {
        Access::Sampled => (shader, A::SHADER_READ, Some(L::ShaderReadOnlyOptimal)),
        Access::StorageRead => (shader, A::SHADER_READ, Some(L::General)),
        Access::StorageWrite | Access::StorageReadWrite => {
            (shader, A::SHADER_READ | A::SHADER_WRITE, Some(L::General))
        }
        Access::Uniform => (shader, A::UNIFORM_READ, None),
        Access::IndirectArgs => (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ, None),
        Access::VertexBuffer => (S::VERTEX_INPUT, A::VERTEX_ATTRIBUTE_READ, None),
        Access::IndexBuffer => (S::VERTEX_INPUT, A::INDEX_READ, None),
        Access::CopySrc | Access::ResolveSrc => {
            (S::TRANSFER, A::TRANSFER_READ, Some(L::TransferSrcOptimal))
        }
        Access::CopyDst | Access::ResolveDst => {
            (S::TRANSFER, A::TRANSFER_WRITE, Some(L::TransferDstOptimal))
        }
        Access::ColorAttachment => (
            S::COLOR_ATTACHMENT_OUTPUT,
            A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
            Some(L::ColorAttachmentOptimal),
        ),
        Access::DepthRead => (
            tests,
            A::DEPTH_STENCIL_ATTACHMENT_READ,
            Some(L::DepthStencilReadOnlyOptimal),
        ),
        Access::DepthWrite => (
            tests,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
            Some(L::DepthStencilAttachmentOptimal),
        ),
        Access::Present => (S::EMPTY, A::EMPTY, Some(L::PresentSrc)),
    }
}

/// How one pass uses one resource, all its accesses together.
#[derive(Clone, Copy)]
struct Use {
    pass: u32,
    stages: S,
    access: A,
    writes: bool,
    /// Sees the previous contents (a load, a read-modify-write).
    reads: bool,
    /// Every write is a storage binding's assumed one.
    assumed: bool,
    layout: Option<L>,
}

/// `assumed`: storage bindings read and write by assumption (an import without shader code).
fn use_of(
    accesses: &[&ResourceAccess],
    pass: u32,
    raster: bool,
    image: bool,
    assumed: bool,
) -> Use {
    let mut u = Use {
        pass,
        stages: S::EMPTY,
        access: A::EMPTY,
        writes: false,
        reads: false,
        assumed: true,
        layout: None,
    };
    for a in accesses {
        let (st, ac, layout) = scope(a.access, raster);
        u.stages |= st;
        u.access |= ac;
        u.writes |= a.writes;
        u.reads |= a.reads;
        if a.writes && !(assumed && a.access == Access::StorageReadWrite) {
            u.assumed = false;
        }
        if image {
            u.layout = match (u.layout, layout) {
                (None, l) => l,
                (Some(prev), Some(l)) if prev != l => {
                    // Reading depth as an attachment and sampling it: the read-only layout.
                    let depth_ro = L::DepthStencilReadOnlyOptimal;
                    if (prev == depth_ro && l == L::ShaderReadOnlyOptimal)
                        || (l == depth_ro && prev == L::ShaderReadOnlyOptimal)
                    {
                        Some(depth_ro)
                    } else {
                        Some(L::General)
                    }
                }
                (prev, _) => prev,
            };
        }
    }
    if !u.writes {
        u.access = u.access & !A::WRITES;
    }
    u
}

/// What the frame asks of the barriers between two uses of a resource.
#[derive(PartialEq, Eq)]
struct Need {
    /// A first use: what came before the capture is unknown, so a matching barrier is used
    /// but none is required.
    optional: bool,
    /// The use sees the previous contents.
    reads: bool,
    src_stages: S,
    src_writes: A,
    dst_stages: S,
    dst_access: A,
    old_layout: Option<L>,
    layout: Option<L>,
}

impl Need {
    /// The barrier `next` needs after `prev` (`None`: the first use in the capture); `None`
    /// when no barrier is needed (reads after reads in one layout, a buffer's first use).
    fn between(prev: Option<&Use>, next: &Use, image: bool) -> Option<Need> {
        let layout = next.layout.filter(|_| image);
        let Some(prev) = prev else {
            // What came before the capture is unknown: only a layout transition is certain.
            return layout.map(|l| Need {
                optional: true,
                reads: next.reads,
                src_stages: S::EMPTY,
                src_writes: A::EMPTY,
                dst_stages: S::EMPTY,
                dst_access: A::EMPTY,
                old_layout: None,
                layout: Some(l),
            });
        };
        let relayout = image && prev.layout != layout;
        if !prev.writes && !next.writes && !relayout {
            return None;
        }
        // A hazard that rests on an assumed storage write is unproven; a layout change is not.
        let unproven = !relayout
            && ((prev.writes && prev.assumed) || (!prev.writes && next.writes && next.assumed));
        Some(Need {
            optional: unproven,
            reads: next.reads,
            src_stages: prev.stages,
            src_writes: prev.access & A::WRITES,
            dst_stages: next.stages,
            // After reads only an execution dependency is needed (unless the layout changes).
            dst_access: if prev.writes || relayout {
                next.access
            } else {
                A::EMPTY
            },
            old_layout: prev.layout.filter(|_| image),
            layout,
        })
    }

    /// What `r` lacks to satisfy this need; empty when it does.
    fn lacks(&self, r: &VulkanBarrierDesc) -> Vec<String> {
        let mut out = Vec::new();
        // Both sides spelt out, so that SHADER_WRITE meets SHADER_STORAGE_WRITE and TRANSFER
        // meets COPY.
        let reaches = |have: S, need: S| have.expand().intersects(need.expand());
        let covers = |have: A, need: A| have.expand().intersects(need.expand());
        if !self.src_stages.is_empty() && !reaches(r.src_stages, self.src_stages) {
            out.push(format!(
                "srcStageMask {} does not reach {}",
                r.src_stages, self.src_stages
            ));
        }
        if !self.src_writes.is_empty() && !covers(r.src_access, self.src_writes) {
            out.push(format!(
                "srcAccessMask {} does not make {} available",
                r.src_access, self.src_writes
            ));
        }
        if !self.dst_stages.is_empty() && !reaches(r.dst_stages, self.dst_stages) {
            out.push(format!(
                "dstStageMask {} does not reach {}",
                r.dst_stages, self.dst_stages
            ));
        }
        if !self.dst_access.is_empty() && !covers(r.dst_access, self.dst_access) {
            out.push(format!(
                "dstAccessMask {} does not make it visible to {}",
                r.dst_access, self.dst_access
            ));
        }
        if let Some(needed) = self.layout {
            match r.new_layout {
                Some(l) if l.serves(needed) => {}
                Some(l) => out.push(format!("newLayout {l} where the pass needs {needed}")),
                None if self.old_layout.is_some_and(|o| o != needed) => {
                    out.push(format!("no layout transition to {needed}"));
                }
                None => {}
            }
        }
        out
    }

    fn describe(&self) -> String {
        let mut t = format!(
            "{}/{} -> {}/{}",
            self.src_stages, self.src_writes, self.dst_stages, self.dst_access
        );
        if let Some(l) = self.layout {
            t += &format!(
                ", layout {} -> {l}",
                self.old_layout.unwrap_or(L::Undefined)
            );
        }
        t
    }
}

/// Compares the Vulkan barriers of an imported capture with the ones its accesses need.
/// `uses` holds, per resource index, every pass's accesses of it in capture order.
fn compare_vulkan(
    capture: &Capture,
    model: &FrameModel,
    uses: &[Vec<(&PassDesc, &ResourceAccess)>],
) -> Vec<Lint> {
    let mut out = pass_level(capture, model, uses);
    // Where the import checked the command stream by Vulkan's synchronization rules, its
    // findings are the missing barriers: they name the command, the subresource and both
    // accesses, which the pass-level comparison cannot.
    if let Some(hazards) = capture
        .origin
        .as_ref()
        .and_then(|o| o.sync_hazards.as_ref())
    {
        out.retain(|l| l.kind != BARRIER_MISSING && l.kind != BARRIER_WRONG_BEFORE_STATE);
        // Looked up by name once: a frame may hold thousands of findings and of passes.
        let resources: std::collections::HashMap<&str, _> = capture
            .resources
            .iter()
            .map(|r| (r.name.as_str(), r.id))
            .collect();
        let passes: std::collections::HashMap<&str, _> = capture
            .passes
            .iter()
            .map(|p| (p.name.as_str(), p.id))
            .collect();
        for h in hazards {
            let resource = resources.get(h.resource.as_str()).copied();
            let sub = match (h.mip, h.layer) {
                (Some(m), Some(l)) => format!(" mip {m} layer {l}"),
                _ => String::new(),
            };
            let (kind, message) = if h.kind == HazardKind::LayoutMismatch {
                // A barrier from the wrong old layout names a wrong before-state; anything
                // else used in the wrong layout lacks the transition that would put it there.
                let kind = if h.access.starts_with("old layout") {
                    BARRIER_WRONG_BEFORE_STATE
                } else if h.access.starts_with("attachment in")
                    && (h.access.contains(" at vkCmdBeginRendering")
                        || h.command.starts_with("vkCmdBeginRendering"))
                {
                    RENDERING_LAYOUT
                } else {
                    BARRIER_MISSING
                };
                let message = format!(
                    "{}: \"{}\"{sub}: {}, but it is in {} (since {})",
                    h.command, h.resource, h.access, h.prior, h.prior_command
                );
                (kind, message)
            } else {
                let message = format!(
                    "{}: {} hazard on \"{}\"{sub}: {} after the {} of {}, with no execution and memory dependency between them",
                    h.command,
                    h.kind.as_str(),
                    h.resource,
                    h.access,
                    h.prior,
                    h.prior_command
                );
                (BARRIER_MISSING, message)
            };
            let pass = h
                .pass
                .as_ref()
                .and_then(|name| passes.get(name.as_str()).copied());
            let mut l = lint(kind, message, pass, resource);
            if h.kind == HazardKind::LayoutMismatch {
                l.vuid = layout_vuid(&h.command, &h.access);
                if let Some(v) = &l.vuid {
                    l.message = format!("{v}: {}", l.message);
                }
            }
            out.push(l);
        }
    }
    // The valid-usage statements the stream's calls break, found at import.
    if let Some(found) = capture.origin.as_ref().and_then(|o| o.valid_usage.as_ref()) {
        for f in found {
            let mut l = lint(
                VALID_USAGE,
                format!("{}: {}: {}", f.command, f.vuid, f.detail),
                None,
                None,
            );
            l.vuid = Some(f.vuid.clone());
            out.push(l);
        }
    }
    out
}

/// The valid-usage ID a use in the wrong layout breaks: a barrier's old layout, a render
/// pass's initial layout, a descriptor's layout (the sync check's `access` says which). Found
/// at a submission (the command buffer expects a layout the image is not in when it is
/// submitted), it takes the id the Khronos validation layer gives that check whatever the use,
/// as the layer is the reference these findings are compared with.
fn layout_vuid(command: &str, access: &str) -> Option<String> {
    let call = command.split(" #").next().unwrap_or(command);
    let submitted = call.starts_with("vkQueueSubmit");
    let vuid = if submitted
        && (access.starts_with("old layout")
            || access.starts_with("descriptor in")
            || (access.starts_with("attachment in") && access.contains("vkCmdBeginRenderPass")))
    {
        "UNASSIGNED-CoreValidation-DrawState-InvalidImageLayout"
    } else if access.starts_with("old layout") {
        if call.ends_with('2') || call.ends_with("2KHR") {
            "VUID-VkImageMemoryBarrier2-oldLayout-01197"
        } else {
            "VUID-VkImageMemoryBarrier-oldLayout-01197"
        }
    } else if access.starts_with("attachment in") && call.starts_with("vkCmdBeginRenderPass") {
        "VUID-vkCmdBeginRenderPass-initialLayout-00900"
    } else if access.starts_with("descriptor in") {
        "VUID-VkDescriptorImageInfo-imageLayout-00344"
    } else {
        return None;
    };
    Some(vuid.to_owned())
}

/// The pass-level comparison of the barriers each resource's uses need with those recorded.
/// Every Vulkan barrier the capture recorded, pass by pass in recording order.
fn vulkan_recorded(capture: &Capture) -> Vec<Recorded<'_>> {
    capture
        .passes
        .iter()
        .flat_map(|p| {
            p.barriers.iter().enumerate().filter_map(move |(i, b)| {
                let v = b
                    .vulkan
                    .as_ref()
                    .filter(|_| b.barrier_type == BarrierType::Vulkan)?;
                Some((p.id.0, i, b.resource, v, b.range.as_ref()))
            })
        })
        .collect()
}

fn pass_level(
    capture: &Capture,
    model: &FrameModel,
    uses: &[Vec<(&PassDesc, &ResourceAccess)>],
) -> Vec<Lint> {
    let mut out = Vec::new();
    let recorded = vulkan_recorded(capture);
    if recorded.is_empty() {
        return out;
    }
    let raster: Vec<bool> = model.passes.iter().map(|p| p.raster).collect();
    let mut used: BTreeSet<(u32, usize)> = BTreeSet::new();
    let queue_of = |pass: u32| capture.passes[pass as usize].queue;
    let assumed = capture.not_replayable().is_some();
    // The recorded barriers by queue and resource (`None`: global) in recording order, so
    // the work stays proportional to the capture's size rather than needs x barriers.
    let mut by_key: BTreeMap<(QueueId, Option<ResourceId>), Vec<usize>> = BTreeMap::new();
    for (k, &(bp, _, res, _, _)) in recorded.iter().enumerate() {
        by_key.entry((queue_of(bp), res)).or_default().push(k);
    }
    // The recorded barriers under `key` after pass `after` (exclusive) up to `pass`.
    let window = |key: (QueueId, Option<ResourceId>), after: Option<u32>, pass: u32| -> &[usize] {
        let Some(list) = by_key.get(&key) else {
            return &[];
        };
        let lo = after.map_or(0, |a| list.partition_point(|&k| recorded[k].0 <= a));
        let hi = list.partition_point(|&k| recorded[k].0 <= pass);
        &list[lo..hi.max(lo)]
    };
    for r in &capture.resources {
        let Some(resource_uses) = uses.get(r.id.index()) else {
            continue;
        };
        // Images are followed per subresource (mip chains render mip n from mip n-1), buffers
        // as a whole.
        let image = r.is_texture();
        let (mips, layers) = if image {
            (r.mip_levels.max(1), r.array_layers.max(1))
        } else {
            (1, 1)
        };
        let units = (mips as usize).saturating_mul(layers as usize);
        let mut prev: Vec<Option<Use>> = vec![None; units];
        // The resource's uses grouped by pass, in submission order.
        for group in resource_uses.chunk_by(|a, b| a.0.id == b.0.id) {
            let p = group[0].0;
            // The CPU's writes during the frame: the next submission makes them visible
            // without a barrier, and they wait for the GPU on fences, not barriers.
            if p.kind == PassKind::Copy && !p.copies.is_empty() && p.copies.iter().all(|c| c.host) {
                continue;
            }
            let accesses: Vec<&ResourceAccess> = group.iter().map(|&(_, a)| a).collect();
            let pass = p.id.0;
            let raster = raster
                .get(pass as usize)
                .copied()
                .unwrap_or(p.kind == PassKind::Raster);
            let mut per_unit: BTreeMap<usize, Vec<&ResourceAccess>> = BTreeMap::new();
            for a in &accesses {
                if !image {
                    per_unit.entry(0).or_default().push(a);
                    continue;
                }
                let mip_end = (a.range.mip_base + a.range.mip_count).min(mips);
                let layer_end = (a.range.layer_base + a.range.layer_count).min(layers);
                for l in a.range.layer_base..layer_end {
                    for m in a.range.mip_base..mip_end {
                        per_unit
                            .entry(l as usize * mips as usize + m as usize)
                            .or_default()
                            .push(a);
                    }
                }
            }
            // Units with the same need are judged together, over the range they span.
            let mut groups: Vec<(Need, Option<u32>, Vec<usize>)> = Vec::new();
            for (unit, accs) in per_unit {
                let next = use_of(&accs, pass, raster, image, assumed);
                let before = prev[unit];
                let need = Need::between(before.as_ref(), &next, image);
                // A run of reads keeps the writer's scope and gathers the readers' stages.
                prev[unit] = Some(match before {
                    Some(pr) if !pr.writes && !next.writes && pr.layout == next.layout => Use {
                        stages: pr.stages | next.stages,
                        access: pr.access | next.access,
                        ..next
                    },
                    _ => next,
                });
                let Some(need) = need else { continue };
                let after = before.map(|u| u.pass);
                match groups
                    .iter_mut()
                    .find(|(n, a, _)| *n == need && *a == after)
                {
                    Some(g) => g.2.push(unit),
                    None => groups.push((need, after, vec![unit])),
                }
            }
            for (need, after, group) in groups {
                let range = span(&group, mips, r);
                let queue = queue_of(pass);
                let mut found: Vec<usize> = window((queue, Some(r.id)), after, pass)
                    .iter()
                    .copied()
                    .filter(|&k| covers(recorded[k].4, &range))
                    .chain(window((queue, None), after, pass).iter().copied())
                    .collect();
                found.sort_unstable();
                let candidates: Vec<&Recorded<'_>> = found.iter().map(|&k| &recorded[k]).collect();
                judge(capture, &mut out, &mut used, &need, &candidates, p.id, r.id);
            }
        }
    }
    for &(p, i, r, v, _) in &recorded {
        // Render pass dependencies are not the application's to drop, and a barrier that
        // changes an image's layout does something whatever it orders.
        let transition = matches!((v.old_layout, v.new_layout), (Some(a), Some(b)) if a != b);
        if used.contains(&(p, i))
            || r.is_none()
            || transition
            || v.origin.starts_with("vkCmdBeginRenderPass")
        {
            continue;
        }
        let what = match (v.old_layout, v.new_layout) {
            (Some(a), Some(b)) if a != b => format!("layout transition {a} -> {b}"),
            _ => format!(
                "{}/{} -> {}/{} dependency",
                v.src_stages, v.src_access, v.dst_stages, v.dst_access
            ),
        };
        let on = r.map_or_else(
            || "all memory".to_owned(),
            |r| format!("\"{}\"", capture.resource(r).name),
        );
        out.push(lint(
            BARRIER_REDUNDANT,
            format!(
                "\"{}\": {} ({what} on {on}) orders nothing the frame needs",
                capture.passes[p as usize].name, v.origin
            ),
            Some(capture.passes[p as usize].id),
            r,
        ));
    }
    out
}

type Recorded<'a> = (
    u32,
    usize,
    Option<ResourceId>,
    &'a VulkanBarrierDesc,
    Option<&'a Subresources>,
);

/// The mips and layers a group of (layer * mips + mip) units spans.
fn span(units: &[usize], mips: u32, r: &crate::capture::model::ResourceDesc) -> Subresources {
    let mut s = Subresources::whole(r);
    if !r.is_texture() {
        return s;
    }
    let m = mips.max(1) as usize;
    let (mut m0, mut m1, mut l0, mut l1) = (usize::MAX, 0, usize::MAX, 0);
    for &u in units {
        let (l, mip) = (u / m, u % m);
        m0 = m0.min(mip);
        m1 = m1.max(mip + 1);
        l0 = l0.min(l);
        l1 = l1.max(l + 1);
    }
    s.mip_base = m0 as u32;
    s.mip_count = (m1 - m0) as u32;
    s.layer_base = l0 as u32;
    s.layer_count = (l1 - l0) as u32;
    s
}

/// The verdict on one need: satisfied (maybe over-broadly or from a wrong layout), partly
/// covered, or missing.
fn judge(
    capture: &Capture,
    out: &mut Vec<Lint>,
    used: &mut BTreeSet<(u32, usize)>,
    need: &Need,
    candidates: &[&Recorded<'_>],
    pass: PassId,
    resource: ResourceId,
) {
    let name = &capture.resource(resource).name;
    let pname = &capture.pass(pass).name;
    match candidates.iter().find(|c| need.lacks(c.3).is_empty()) {
        Some(&&(p, i, _, v, _)) => {
            used.insert((p, i));
            if let (Some(old), Some(current)) = (v.old_layout, need.old_layout)
                && old != L::Undefined
                && !old.serves(current)
            {
                out.push(lint(BARRIER_WRONG_BEFORE_STATE, format!(
                    "\"{pname}\": {} takes \"{name}\" from {old}, but it is in {current}", v.origin
                ), Some(pass), Some(resource)));
            }
            if v.old_layout == Some(L::Undefined) && need.old_layout.is_some() && !need.src_writes.is_empty() && need.reads {
                out.push(lint(BARRIER_WRONG_BEFORE_STATE, format!(
                    "\"{pname}\": {} takes \"{name}\" from UNDEFINED, discarding what an earlier pass wrote", v.origin
                ), Some(pass), Some(resource)));
            }
            let every = A::MEMORY_READ | A::MEMORY_WRITE;
            let broad_src = v.src_stages.intersects(S::ALL_COMMANDS) && !need.src_stages.is_empty();
            let broad_dst = v.dst_stages.intersects(S::ALL_COMMANDS) && !need.dst_stages.is_empty();
            let broad_access = (v.src_access.intersects(A::MEMORY_WRITE) && !need.src_writes.is_empty())
                || (v.dst_access.intersects(every) && !need.dst_access.is_empty());
            if (broad_src || broad_dst || broad_access) && !v.origin.contains("implicit") {
                out.push(lint(BARRIER_OVER_BROAD, format!(
                    "\"{pname}\": {} on \"{name}\" waits on {}/{} -> {}/{}; {} is enough",
                    v.origin,
                    v.src_stages, v.src_access, v.dst_stages, v.dst_access,
                    need.describe()
                ), Some(pass), Some(resource)));
            }
        }
        None if need.optional => {}
        None => match candidates.iter().find(|c| c.2 == Some(resource)) {
            Some(&&(p, i, _, v, _)) => {
                used.insert((p, i));
                out.push(lint(BARRIER_MISSING, format!(
                    "\"{pname}\" needs {} on \"{name}\"; {} records one but its {} (a hazard)",
                    need.describe(), v.origin, need.lacks(v).join("; ")
                ), Some(pass), Some(resource)));
            }
            None => out.push(lint(BARRIER_MISSING, format!(
                "\"{pname}\" needs a barrier on \"{name}\" ({}) that the capture did not record (a hazard)",
                need.describe()
            ), Some(pass), Some(resource))),
        },
    }
}
