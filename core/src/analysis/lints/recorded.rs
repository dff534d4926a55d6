//! Lints that compare the barriers a capture recorded with the ones the frame needs, PIX
//! style: missing, redundant, over-broad, could-be-split and wrong-before-state barriers.

use std::collections::BTreeMap;

use super::{Fix, Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::barriers::{Barrier, BarrierKind, BarrierPlan};
use crate::analysis::model::{FrameModel, MPass, MResource, State};
use crate::capture::format::{BarrierType, ResourceState, SplitFlag};
use crate::capture::model::{Capture, RecordedBarrierDesc, ResourceId, Subresources};

/// FL020 `barrier-missing`: a transition or UAV barrier the frame needs was not recorded.
pub const BARRIER_MISSING: LintKind = LintKind::new(&LintDef {
    code: "FL020",
    name: "barrier-missing",
    severity: LintSeverity::Error,
    description: "a transition or UAV barrier the frame needs was not recorded",
});

/// FL021 `barrier-redundant`: a recorded barrier the frame does not need.
pub const BARRIER_REDUNDANT: LintKind = LintKind::new(&LintDef {
    code: "FL021",
    name: "barrier-redundant",
    severity: LintSeverity::Warning,
    description: "a recorded barrier the frame does not need",
});

/// FL022 `barrier-over-broad`: a recorded barrier covers more subresources or states than
/// needed.
pub const BARRIER_OVER_BROAD: LintKind = LintKind::new(&LintDef {
    code: "FL022",
    name: "barrier-over-broad",
    severity: LintSeverity::Warning,
    description: "a recorded barrier covers more subresources or states than needed",
});

/// FL023 `barrier-could-split`: a recorded barrier could be split.
pub const BARRIER_COULD_SPLIT: LintKind = LintKind::new(&LintDef {
    code: "FL023",
    name: "barrier-could-split",
    severity: LintSeverity::Info,
    description: "a recorded barrier could be split (begin after the last use, end before the next)",
});

/// FL024 `barrier-wrong-before-state`: a recorded transition names a before-state the
/// resource is not in.
pub const BARRIER_WRONG_BEFORE_STATE: LintKind = LintKind::new(&LintDef {
    code: "FL024",
    name: "barrier-wrong-before-state",
    severity: LintSeverity::Error,
    description: "a recorded transition names a before-state the resource is not in",
});

/// The D3D12 barriers a capture recorded against the ones its frame needs (the Vulkan ones are
/// `vulkan`'s, which reports with these kinds too).
pub(super) struct RecordedBarriers;

impl Rule for RecordedBarriers {
    fn kinds(&self) -> &'static [LintKind] {
        &[
            BARRIER_MISSING,
            BARRIER_REDUNDANT,
            BARRIER_OVER_BROAD,
            BARRIER_COULD_SPLIT,
            BARRIER_WRONG_BEFORE_STATE,
        ]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        out.extend(compare_recorded(l.capture, l.model, l.plan));
    }
}

fn state_of(s: ResourceState) -> State {
    match s {
        ResourceState::Common => State::COMMON,
        ResourceState::VertexAndConstantBuffer => State::VERTEX_AND_CONSTANT_BUFFER,
        ResourceState::IndexBuffer => State::INDEX_BUFFER,
        ResourceState::RenderTarget => State::RENDER_TARGET,
        ResourceState::UnorderedAccess => State::UNORDERED_ACCESS,
        ResourceState::DepthWrite => State::DEPTH_WRITE,
        ResourceState::DepthRead => State::DEPTH_READ,
        ResourceState::NonPixelShaderResource => State::NON_PIXEL_SHADER_RESOURCE,
        ResourceState::PixelShaderResource => State::PIXEL_SHADER_RESOURCE,
        ResourceState::IndirectArgument => State::INDIRECT_ARGUMENT,
        ResourceState::CopyDest => State::COPY_DEST,
        ResourceState::CopySource => State::COPY_SOURCE,
        ResourceState::ResolveDest => State::RESOLVE_DEST,
        ResourceState::ResolveSource => State::RESOLVE_SOURCE,
        ResourceState::GenericRead => State::VERTEX_AND_CONSTANT_BUFFER
            .union(State::INDEX_BUFFER)
            .union(State::NON_PIXEL_SHADER_RESOURCE)
            .union(State::PIXEL_SHADER_RESOURCE)
            .union(State::INDIRECT_ARGUMENT)
            .union(State::COPY_SOURCE),
        ResourceState::AllShaderResource => {
            State::NON_PIXEL_SHADER_RESOURCE.union(State::PIXEL_SHADER_RESOURCE)
        }
        ResourceState::Present => State::PRESENT,
    }
}

/// Whether a recorded barrier's range (all subresources when absent) covers `inner`.
pub(super) fn covers(outer: Option<&Subresources>, inner: &Subresources) -> bool {
    outer.is_none_or(|o| {
        o.mip_base <= inner.mip_base
            && inner.mip_base + inner.mip_count <= o.mip_base + o.mip_count
            && o.layer_base <= inner.layer_base
            && inner.layer_base + inner.layer_count <= o.layer_base + o.layer_count
    })
}

/// Compares the barriers a capture recorded with the derived ones, PIX style. Runs only when
/// the capture recorded barriers at all.
/// The union of a recorded barrier's states (COMMON when none).
fn states(list: &[ResourceState]) -> State {
    list.iter()
        .fold(State::COMMON, |s, x| s.union(state_of(*x)))
}

/// The recorded barrier (and its place among `recorded`) that does what the derived barrier
/// `d` on `resource` needs: a transition into at least its after-state over its range, or a
/// UAV barrier on it or on every resource.
fn matching<'r>(
    recorded: &[&'r RecordedBarrierDesc],
    d: &Barrier,
    resource: ResourceId,
) -> Option<(usize, &'r RecordedBarrierDesc)> {
    let direct = recorded.iter().enumerate().find(|(_, r)| {
        r.resource == Some(resource)
            && match d.kind {
                BarrierKind::Transition => {
                    r.barrier_type == BarrierType::Transition
                        && covers(r.range.as_ref(), &d.range)
                        && states(&r.after).contains(d.after)
                }
                BarrierKind::Uav => r.barrier_type == BarrierType::Uav,
                BarrierKind::Aliasing => false,
            }
    });
    // A global UAV barrier (no resource) covers every UAV barrier.
    let global = || {
        recorded.iter().enumerate().find(|(_, r)| {
            d.kind == BarrierKind::Uav && r.barrier_type == BarrierType::Uav && r.resource.is_none()
        })
    };
    direct.or_else(global).map(|(i, r)| (i, *r))
}

fn compare_recorded(capture: &Capture, model: &FrameModel, plan: &BarrierPlan) -> Vec<Lint> {
    let mut out = Vec::new();
    let d3d12 = |b: &&RecordedBarrierDesc| b.barrier_type != BarrierType::Vulkan;
    if capture
        .passes
        .iter()
        .all(|p| !p.barriers.iter().any(|b| d3d12(&b)))
    {
        return out;
    }
    let mut by_pass: BTreeMap<MPass, Vec<&Barrier>> = BTreeMap::new();
    for b in plan.barriers.iter().filter(|b| !b.next_frame) {
        by_pass.entry(b.for_pass).or_default().push(b);
    }
    let name = |r: MResource| model.resources[r.index()].name.clone();
    for pass in &capture.passes {
        // The whole frame's model: its passes are the capture's, in the same places.
        let derived = by_pass
            .get(&MPass::new(pass.id.index()))
            .cloned()
            .unwrap_or_default();
        let recorded: Vec<_> = pass
            .barriers
            .iter()
            .filter(|b| b.split != SplitFlag::BeginOnly && d3d12(b))
            .collect();
        let mut used = vec![false; recorded.len()];
        for d in &derived {
            let resource = model.resources[d.resource.index()]
                .previous_of
                .unwrap_or(d.resource);
            let resource_id = model.resources[resource.index()].id;
            let found = matching(&recorded, d, resource_id);
            let Some((i, r)) = found else {
                let what = match d.kind {
                    BarrierKind::Uav => "UAV barrier".to_owned(),
                    _ => format!("transition {} -> {}", d.before.name(), d.after.name()),
                };
                out.push(lint(BARRIER_MISSING, format!("\"{}\" needs a {what} on \"{}\" that the capture did not record (a hazard)", pass.name, name(resource)), Some(pass.id), Some(resource_id)));
                continue;
            };
            used[i] = true;
            if d.kind != BarrierKind::Transition {
                continue;
            }
            let (before, after) = (states(&r.before), states(&r.after));
            if before != d.before {
                out.push(lint(
                    BARRIER_WRONG_BEFORE_STATE,
                    format!(
                        "\"{}\" records \"{}\" going from {} but it is in {}",
                        pass.name,
                        name(resource),
                        before.name(),
                        d.before.name()
                    ),
                    Some(pass.id),
                    Some(resource_id),
                ));
            }
            let whole = model.resources[resource.index()].whole();
            let wider_range = r
                .range
                .as_ref()
                .map_or(d.range != whole, |rr| *rr != d.range);
            if after != d.after || wider_range {
                out.push(lint(
                    BARRIER_OVER_BROAD,
                    format!(
                        "\"{}\" transitions \"{}\" to {} over {}; {} over {} is enough",
                        pass.name,
                        name(resource),
                        after.name(),
                        describe(r.range.as_ref()),
                        d.after.name(),
                        describe(Some(&d.range))
                    ),
                    Some(pass.id),
                    Some(resource_id),
                ));
            }
            if let (Some(q), SplitFlag::None) = (d.split_begin_after, r.split) {
                out.push(lint(BARRIER_COULD_SPLIT, format!("the transition of \"{}\" before \"{}\" could begin after \"{}\" (split barrier)", name(resource), pass.name, model.passes[q.index()].name), Some(pass.id), Some(resource_id)));
            }
        }
        for (i, r) in recorded.iter().enumerate() {
            if !used[i] && r.barrier_type != BarrierType::Aliasing {
                let res = r.resource.map(|x| capture.resource(x).name.clone());
                let mut l = lint(
                    BARRIER_REDUNDANT,
                    format!(
                        "\"{}\" records a {:?} barrier on {} that the frame does not need",
                        pass.name,
                        r.barrier_type,
                        res.as_deref().unwrap_or("all resources")
                    )
                    .replace("Transition", "transition")
                    .replace("Uav", "UAV"),
                    Some(pass.id),
                    r.resource,
                );
                // Its place in the pass's own list, which the fix names.
                l.fix = pass
                    .barriers
                    .iter()
                    .position(|b| std::ptr::eq(b, *r))
                    .map(|index| Fix::DropBarrier {
                        pass: pass.id,
                        index,
                    });
                out.push(l);
            }
        }
    }
    out
}

fn describe(r: Option<&Subresources>) -> String {
    match r {
        None => "all subresources".to_owned(),
        Some(r) if r.byte_size > 0 => {
            format!("bytes {}..{}", r.byte_offset, r.byte_offset + r.byte_size)
        }
        Some(r) => format!(
            "mips {}..{} layers {}..{}",
            r.mip_base,
            r.mip_base + r.mip_count,
            r.layer_base,
            r.layer_base + r.layer_count
        ),
    }
}
