//! Lints that compare the barriers a Vulkan application recorded (imported captures) with the
//! ones the frame needs, in Vulkan's terms: stage and access masks and image layouts.
//!
//! A derived barrier is satisfied by a recorded one on the same resource (or a global memory
//! barrier) recorded after the previous use on that queue and before the pass, whose source
//! scope reaches the previous use, whose destination scope reaches the pass's use, and which
//! leaves an image in a layout the pass can use. Vulkan needs no barrier where D3D12 changes
//! between read states of a buffer, nor for a buffer's first use in the frame.

use std::collections::BTreeSet;

use super::{Lint, LintKind, lint};
use crate::analysis::barriers::{Barrier, BarrierKind, BarrierPlan, VkScope};
use crate::analysis::model::{FrameModel, State};
use crate::capture::format::BarrierType;
use crate::capture::model::{Capture, ResourceId, Subresources, VulkanBarrierDesc};
use crate::capture::vulkan::{self, ACCESS, STAGES, access, expand_access, expand_stages, stage};

fn mask(table: &[(&str, u64)], names: &[&'static str]) -> u64 {
    let owned: Vec<String> = names.iter().map(|s| (*s).to_owned()).collect();
    vulkan::parse_mask(table, &owned).unwrap_or(0)
}

fn covers(outer: Option<&Subresources>, inner: &Subresources) -> bool {
    outer.is_none_or(|o| {
        o.mip_base <= inner.mip_base
            && inner.mip_base + inner.mip_count <= o.mip_base + o.mip_count
            && o.layer_base <= inner.layer_base
            && inner.layer_base + inner.layer_count <= o.layer_base + o.layer_count
    })
}

/// Layouts that serve a use needing `needed`.
fn layout_serves(recorded: &str, needed: &str) -> bool {
    recorded == needed
        || (recorded == "GENERAL" && needed != "PRESENT_SRC_KHR")
        || (recorded == "ATTACHMENT_OPTIMAL"
            && matches!(needed, "COLOR_ATTACHMENT_OPTIMAL" | "DEPTH_STENCIL_ATTACHMENT_OPTIMAL"))
        || (recorded == "READ_ONLY_OPTIMAL"
            && matches!(needed, "SHADER_READ_ONLY_OPTIMAL" | "DEPTH_STENCIL_READ_ONLY_OPTIMAL"))
        || (needed == "GENERAL" && recorded != "UNDEFINED" && recorded != "PRESENT_SRC_KHR")
}

fn names(table: &[(&str, u64)], m: u64) -> String {
    let n = vulkan::mask_names(table, m);
    if n.is_empty() { "NONE".to_owned() } else { n.join("|") }
}

/// What a derived barrier asks of a recorded one.
struct Need {
    src_stages: u64,
    src_writes: u64,
    dst_stages: u64,
    dst_access: u64,
    old_layout: Option<&'static str>,
    layout: Option<&'static str>,
}

impl Need {
    fn of(d: &Barrier, model: &FrameModel) -> Option<Need> {
        let buffer = model.resources[d.resource as usize].is_buffer;
        if d.kind == BarrierKind::Aliasing {
            return None;
        }
        let from_initial = d.before == State::COMMON;
        let read_to_read = d.before.is_read_only() && d.after.is_read_only();
        if buffer && (from_initial || read_to_read) {
            return None;
        }
        let (src, dst): (VkScope, VkScope) = d.vulkan(model);
        if !buffer && read_to_read && src.layout == dst.layout {
            return None;
        }
        let src_stages = if from_initial { 0 } else { mask(STAGES, &src.stages) };
        let src_writes = if from_initial { 0 } else { mask(ACCESS, &src.access) & access::WRITES };
        let (dst_stages, dst_access) = if d.after == State::PRESENT {
            (0, 0)
        } else {
            (mask(STAGES, &dst.stages), mask(ACCESS, &dst.access))
        };
        Some(Need {
            src_stages,
            src_writes,
            dst_stages,
            dst_access,
            old_layout: if from_initial { None } else { src.layout },
            layout: dst.layout,
        })
    }

    /// What `r` lacks to satisfy this need; empty when it does.
    fn lacks(&self, r: &VulkanBarrierDesc) -> Vec<String> {
        let mut out = Vec::new();
        let (ss, ds) = (expand_stages(r.src_stages), expand_stages(r.dst_stages));
        let (sa, da) = (expand_access(r.src_access), expand_access(r.dst_access));
        if self.src_stages != 0 && ss & self.src_stages == 0 {
            out.push(format!("srcStageMask {} does not reach {}", names(STAGES, r.src_stages), names(STAGES, self.src_stages)));
        }
        if self.src_writes != 0 && sa & self.src_writes == 0 {
            out.push(format!("srcAccessMask {} does not make {} available", names(ACCESS, r.src_access), names(ACCESS, self.src_writes)));
        }
        if self.dst_stages != 0 && ds & self.dst_stages == 0 {
            out.push(format!("dstStageMask {} does not reach {}", names(STAGES, r.dst_stages), names(STAGES, self.dst_stages)));
        }
        if self.dst_access != 0 && da & self.dst_access == 0 {
            out.push(format!("dstAccessMask {} does not make it visible to {}", names(ACCESS, r.dst_access), names(ACCESS, self.dst_access)));
        }
        if let Some(needed) = self.layout {
            match r.new_layout {
                Some(l) if layout_serves(l, needed) => {}
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
            names(STAGES, self.src_stages),
            names(ACCESS, self.src_writes),
            names(STAGES, self.dst_stages),
            names(ACCESS, self.dst_access)
        );
        if let Some(l) = self.layout {
            t += &format!(", layout {} -> {l}", self.old_layout.unwrap_or("UNDEFINED"));
        }
        t
    }
}

/// Compares the Vulkan barriers of an imported capture with the derived ones.
pub(super) fn compare_vulkan(capture: &Capture, model: &FrameModel, plan: &BarrierPlan) -> Vec<Lint> {
    let mut out = Vec::new();
    let recorded: Vec<(u32, usize, ResourceIdOpt, &VulkanBarrierDesc, Option<&Subresources>)> = capture
        .passes
        .iter()
        .flat_map(|p| {
            p.barriers.iter().enumerate().filter_map(move |(i, b)| {
                let v = b.vulkan.as_ref().filter(|_| b.barrier_type == BarrierType::Vulkan)?;
                Some((p.id.0, i, b.resource, v, b.range.as_ref()))
            })
        })
        .collect();
    if recorded.is_empty() {
        return out;
    }
    let mut used: BTreeSet<(u32, usize)> = BTreeSet::new();
    let queue_of = |pass: u32| capture.passes[pass as usize].queue;
    for d in plan.barriers.iter().filter(|b| !b.next_frame) {
        let Some(need) = Need::of(d, model) else { continue };
        let pass = model.passes[d.for_pass as usize].id.0;
        let resource = model.resources[d.resource as usize].id;
        let after = d.split_begin_after.map(|p| model.passes[p as usize].id.0);
        let in_window = |p: u32| queue_of(p) == queue_of(pass) && p <= pass && after.is_none_or(|a| p > a);
        let candidates: Vec<_> = recorded
            .iter()
            .filter(|(p, _, r, _, range)| {
                in_window(*p) && (r.is_none() || (*r == Some(resource) && covers(*range, &d.range)))
            })
            .collect();
        let name = &capture.resource(resource).name;
        let pname = &capture.passes[pass as usize].name;
        match candidates.iter().find(|c| need.lacks(c.3).is_empty()) {
            Some(&&(p, i, _, v, _)) => {
                used.insert((p, i));
                if let (Some(old), Some(current)) = (v.old_layout, need.old_layout)
                    && old != "UNDEFINED"
                    && !layout_serves(old, current)
                {
                    out.push(lint(LintKind::BarrierWrongBeforeState, format!(
                        "\"{pname}\": {} takes \"{name}\" from {old}, but it is in {current}", v.origin
                    ), Some(capture.passes[pass as usize].id), Some(resource)));
                }
                let broad_src = v.src_stages & stage::ALL_COMMANDS != 0 && need.src_stages != 0;
                let broad_dst = v.dst_stages & stage::ALL_COMMANDS != 0 && need.dst_stages != 0;
                let broad_access = (v.src_access | v.dst_access) & (access::MEMORY_READ | access::MEMORY_WRITE) != 0;
                if broad_src || broad_dst || broad_access {
                    out.push(lint(LintKind::BarrierOverBroad, format!(
                        "\"{pname}\": {} on \"{name}\" waits on {}/{} -> {}/{}; {} is enough",
                        v.origin,
                        names(STAGES, v.src_stages), names(ACCESS, v.src_access),
                        names(STAGES, v.dst_stages), names(ACCESS, v.dst_access),
                        need.describe()
                    ), Some(capture.passes[pass as usize].id), Some(resource)));
                }
            }
            None => match candidates.iter().find(|c| c.2 == Some(resource)) {
                Some(&&(p, i, _, v, _)) => {
                    used.insert((p, i));
                    out.push(lint(LintKind::BarrierMissing, format!(
                        "\"{pname}\" needs {} on \"{name}\"; {} records one but its {} (a hazard)",
                        need.describe(), v.origin, need.lacks(v).join("; ")
                    ), Some(capture.passes[pass as usize].id), Some(resource)));
                }
                None => out.push(lint(LintKind::BarrierMissing, format!(
                    "\"{pname}\" needs a barrier on \"{name}\" ({}) that the capture did not record (a hazard)",
                    need.describe()
                ), Some(capture.passes[pass as usize].id), Some(resource))),
            },
        }
    }
    for &(p, i, r, v, _) in &recorded {
        if used.contains(&(p, i)) {
            continue;
        }
        let what = match (v.old_layout, v.new_layout) {
            (Some(a), Some(b)) if a != b => format!("layout transition {a} -> {b}"),
            _ => format!("{}/{} -> {}/{} dependency", names(STAGES, v.src_stages), names(ACCESS, v.src_access), names(STAGES, v.dst_stages), names(ACCESS, v.dst_access)),
        };
        let on = r.map_or_else(|| "all memory".to_owned(), |r| format!("\"{}\"", capture.resource(r).name));
        out.push(lint(LintKind::BarrierRedundant, format!(
            "\"{}\": {} ({what} on {on}) orders nothing the frame needs",
            capture.passes[p as usize].name, v.origin
        ), Some(capture.passes[p as usize].id), r));
    }
    out
}

type ResourceIdOpt = Option<ResourceId>;
