//! The inspector's model projected from the pipeline's stages by id: passes in execution order
//! with their bindings, attachments, state, work, parameters, derived and recorded barriers and
//! lints; resources with sizes, heaps, aliasing-plan offsets, first and last use and what they
//! alias; queue waits; timings from a report and the diff against a second one. The text of a
//! pass (work, bindings, attachments, state, recorded barriers) is core's `pass_text`, the
//! derived barriers core's `BarrierReport`, the waits core's fence edges: this module joins
//! them by id. The panels receive only this plain data (ids, names and preformatted text),
//! never capture types, and `launch` starts the replay they drive.

mod launch;
mod timings;

use std::collections::BTreeMap;

pub use self::launch::{DEFAULT_BUDGET, LaunchError, LaunchOptions, launch};
use self::timings::{compare_from, timings_from};

use crate::model::{
    Barrier, BarrierSide, BarrierSource, Inspection, Pass, Resource, Sampling, TextureView,
};
pub use framelab_core::buffer_views::buffer_views;
use framelab_replay::wgpu;

use framelab_core::analysis::model::{MPass, MResource};
use framelab_core::analysis::report::pass_text::{self, spelled};
use framelab_core::analysis::report::{self, Analysis, BarrierReport};
use framelab_core::capture::model::{Capture, PassId, ResourceId};
use framelab_core::pipeline::{Analysed, Lowered};
use framelab_core::timing::TimingReport;

fn derived(b: &BarrierReport, side: BarrierSide) -> Barrier {
    Barrier {
        side,
        source: BarrierSource::Derived,
        kind: spelled(&b.kind),
        resource: b.resource.clone(),
        subresource: b.subresource.describe(),
        states: match &b.resource_before {
            Some(before) => format!("{before} -> {}", b.resource),
            None => format!("{} -> {}", b.before, b.after),
        },
        vulkan: b.vulkan.describe(),
    }
}

/// How the viewer reads a plan texture, or why it cannot.
fn texture_view(plan_index: usize, spec: &framelab_core::plan::TextureSpec) -> TextureView {
    use wgpu::TextureFormat as F;
    let f = spec.format;
    let sampling = if f.has_depth_aspect() {
        Sampling::Depth
    } else if f.has_stencil_aspect() {
        Sampling::Stencil
    } else {
        match f.sample_type(None, None) {
            Some(wgpu::TextureSampleType::Uint) => Sampling::Uint,
            Some(wgpu::TextureSampleType::Sint) => Sampling::Sint,
            _ => Sampling::Float,
        }
    };
    let hdr = matches!(
        f,
        F::Rgba16Float | F::Rgba32Float | F::Rg11b10Ufloat | F::Rgb9e5Ufloat
    );
    TextureView {
        plan_index,
        sampling,
        volume: spec.dimension == wgpu::TextureDimension::D3,
        encode_srgb: f.is_srgb() || hdr,
        unviewable: (spec.samples > 1)
            .then(|| "multisampled: view the resolved texture".to_owned()),
        stencil: framelab_replay::decode::has_stencil(spec),
    }
}

fn resources(
    c: &Capture,
    a: &Analysis,
    lowered: Option<&Lowered>,
    pass_index: &BTreeMap<PassId, usize>,
) -> Vec<Resource> {
    let info = framelab_core::info::report(c);
    let buffers = lowered.map(|l| buffer_views(&l.plan)).unwrap_or_default();
    // A history resource's previous-frame copy is a resource of its own in the memory plan;
    // its placement is not the resource's.
    let own = |r: MResource| a.model.resources[r.index()].previous_of.is_none();
    let offset: BTreeMap<ResourceId, u64> = a
        .memory
        .resources
        .iter()
        .filter(|m| own(m.resource))
        .map(|m| (a.resource_id(m.resource), m.offset))
        .collect();
    let mut aliases: BTreeMap<ResourceId, Vec<String>> = BTreeMap::new();
    for x in &a.memory.aliasing_barriers {
        let name = |r: MResource| a.model.resources[r.index()].name.clone();
        for (this, other) in [
            (x.resource_before, x.resource_after),
            (x.resource_after, x.resource_before),
        ] {
            if own(this) {
                aliases
                    .entry(a.resource_id(this))
                    .or_default()
                    .push(name(other));
            }
        }
    }
    // First and last pass using each resource, in execution order.
    let mut uses: BTreeMap<ResourceId, (usize, usize)> = BTreeMap::new();
    for (&id, &i) in pass_index {
        for access in &c.pass(id).accesses {
            let e = uses.entry(access.resource).or_insert((i, i));
            e.0 = e.0.min(i);
            e.1 = e.1.max(i);
        }
    }
    info.resources
        .iter()
        .zip(&c.resources)
        .map(|(ri, r)| {
            let id = r.id;
            let mut al = aliases.remove(&id).unwrap_or_default();
            al.sort();
            al.dedup();
            Resource {
                id,
                name: ri.name.clone(),
                kind: ri.kind.to_owned(),
                format: ri.format.unwrap_or("").to_owned(),
                width: ri.width,
                height: ri.height,
                depth: ri.depth,
                mips: ri.mip_levels,
                layers: ri.array_layers,
                bytes: ri.bytes,
                heap: format!("{} ({})", ri.heap, ri.heap_type),
                offset: offset.get(&id).copied(),
                first_pass: uses.get(&id).map(|u| u.0),
                last_pass: uses.get(&id).map(|u| u.1),
                aliases: al,
                texture: lowered.and_then(|l| {
                    l.texture_of
                        .get(&id)
                        .map(|&t| texture_view(t, &l.plan.textures[t]))
                }),
                buffer: lowered
                    .and_then(|l| l.buffer_of.get(&id))
                    .and_then(|&b| buffers.get(b).cloned()),
            }
        })
        .collect()
}

fn edges(a: &Analysis, pass_index: &BTreeMap<PassId, usize>) -> Vec<crate::model::Edge> {
    use petgraph::visit::EdgeRef;
    let mut out: Vec<crate::model::Edge> = a
        .graph
        .graph
        .edge_references()
        .filter_map(|e| {
            let from = *pass_index.get(&a.pass_id(a.graph.graph[e.source()]))?;
            let to = *pass_index.get(&a.pass_id(a.graph.graph[e.target()]))?;
            Some(crate::model::Edge {
                from,
                to,
                kind: e.weight().kind,
                resource: e
                    .weight()
                    .resource
                    .map(|r| a.model.resources[r.index()].name.clone()),
            })
        })
        .collect();
    out.sort_by_key(|e| (e.from, e.to));
    out
}

/// The aliasing plan's blocks, by resource id, with their lifetimes as positions among the
/// passes shown (persistent resources live the whole frame).
fn memory(a: &Analysis, pass_index: &BTreeMap<PassId, usize>) -> Vec<crate::model::MemoryBlock> {
    let last = pass_index.len().saturating_sub(1);
    let at = |order_position: u32| {
        let model_pass = *a.model_order.get(order_position as usize)?;
        pass_index.get(&a.pass_id(model_pass)).copied()
    };
    a.memory
        .resources
        .iter()
        // A previous-frame copy's block is not the resource's own.
        .filter(|m| a.model.resources[m.resource.index()].previous_of.is_none())
        .filter_map(|m| {
            let (first, last) = match (m.persistent, m.lifetime) {
                (true, _) => (0, last),
                (false, Some(l)) => (at(l.first)?, at(l.last)?),
                (false, None) => return None,
            };
            Some(crate::model::MemoryBlock {
                resource: a.resource_id(m.resource),
                pool: a.memory.pools[m.pool as usize].clone(),
                offset: m.offset,
                bytes: m.bytes,
                first,
                last,
            })
        })
        .collect()
}

/// The timing reports the inspector was given.
#[derive(Debug, Default)]
pub struct Reports<'a> {
    pub timings: Option<(&'a TimingReport, String)>,
    pub compare: Option<(&'a TimingReport, String)>,
}

/// The inspector's model of a capture that is not replayed (an import): passes, barriers,
/// resources, the DAG and memory, with no texture or buffer contents to view.
pub fn model_without_replay(
    analysed: &Analysed,
    reports: &Reports<'_>,
) -> Result<Inspection, framelab_core::timing::diff::DiffError> {
    let (c, a) = (&analysed.capture, &analysed.analysis);
    model(c, a, &a.order, None, reports)
}

/// `order`: the passes shown, in execution order (the replayed ones when `lowered` is given).
/// Everything is joined by id: the analysis's barriers, lints and memory plan land on the pass
/// and resource they name, without going through names.
fn model(
    c: &Capture,
    a: &Analysis,
    order: &[PassId],
    lowered: Option<&Lowered>,
    reports: &Reports<'_>,
) -> Result<Inspection, framelab_core::timing::diff::DiffError> {
    let pass_index: BTreeMap<PassId, usize> =
        order.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let mut boundary: BTreeMap<PassId, Vec<BarrierReport>> = report::barriers_by_pass(a)
        .into_iter()
        .enumerate()
        .map(|(p, barriers)| (a.pass_id(MPass::new(p)), barriers))
        .collect();
    let derived_at = |id: Option<&PassId>, side| -> Vec<Barrier> {
        id.and_then(|id| boundary.get(id))
            .map(|list| list.iter().map(|x| derived(x, side)).collect())
            .unwrap_or_default()
    };
    let mut lints: BTreeMap<PassId, Vec<report::LintReport>> = BTreeMap::new();
    for l in &a.lints {
        if let Some(p) = l.pass {
            lints.entry(p).or_default().push(report::lint_report(c, l));
        }
    }
    let passes: Vec<Pass> = order
        .iter()
        .enumerate()
        .map(|(i, &id)| {
            let p = c.pass(id);
            let mut barriers = derived_at(Some(&id), BarrierSide::Before);
            barriers.extend(
                pass_text::recorded_barriers(c, p)
                    .into_iter()
                    .map(|b| Barrier {
                        side: BarrierSide::Before,
                        source: BarrierSource::Recorded,
                        kind: b.kind,
                        resource: b.resource,
                        subresource: b.subresource,
                        states: b.states,
                        vulkan: b.vulkan,
                    }),
            );
            barriers.extend(derived_at(order.get(i + 1), BarrierSide::After));
            let mut pass_lints = lints.remove(&id).unwrap_or_default();
            pass_lints.sort();
            pass_lints.dedup();
            Pass {
                id,
                name: p.name.clone(),
                queue: p.queue.index(),
                kind: p.kind.as_str().to_owned(),
                markers: p.markers.clone(),
                culled: a.culled.contains(&id),
                work: pass_text::work(c, p),
                steps: p.draws.len() + p.dispatches.len(),
                bindings: pass_text::bindings(c, p),
                attachments: pass_text::attachments(p)
                    .into_iter()
                    .map(|a| crate::model::Attachment {
                        slot: a.slot,
                        resource: a.resource.index(),
                        text: a.text,
                    })
                    .collect(),
                state: pass_text::state(c, p),
                params: pass_text::params(&p.params),
                barriers,
                lints: pass_lints
                    .iter()
                    .map(|l| format!("{} {}: {}", l.code, spelled(&l.severity), l.message))
                    .collect(),
                inputs: touched(p, false),
                outputs: touched(p, true),
            }
        })
        .collect();
    boundary.clear();
    let mut m = Inspection {
        capture: c.name.clone(),
        scale: c.scale,
        queues: c.queues.iter().map(|q| q.name.clone()).collect(),
        passes,
        resources: resources(c, a, lowered, &pass_index),
        fences: {
            // Cross-queue waits between the passes shown, as positions in `order`.
            let mut f: Vec<(usize, usize)> = c
                .fence_edges()
                .into_iter()
                .filter_map(|(s, w)| Some((*pass_index.get(&s)?, *pass_index.get(&w)?)))
                .collect();
            f.sort_unstable();
            f
        },
        edges: edges(a, &pass_index),
        memory: memory(a, &pass_index),
        timings: None,
        compare: None,
        presented: None,
        vulkan_terms: c.from_vulkan_program(),
    };
    m.presented = order
        .iter()
        .rev()
        .find_map(|&id| c.pass(id).present)
        .and_then(|r| m.resources.iter().position(|x| x.id == r));
    if let Some((t, source)) = &reports.timings {
        m.timings = Some(timings_from(&m, t, source));
        if let Some((b, other)) = &reports.compare {
            m.compare = Some(compare_from(&m, t, b, other)?);
        }
    }
    Ok(m)
}

/// The resources (model indices: capture order) pass `p` writes (`writes`) or only reads, each
/// once; outputs list colour attachments first, then depth, so a pass opens on what it draws.
fn touched(p: &framelab_core::capture::model::PassDesc, writes: bool) -> Vec<usize> {
    use framelab_core::capture::format::Access;
    let rank = |a: Access| match a {
        Access::ColorAttachment => 0,
        Access::DepthWrite | Access::DepthRead => 1,
        _ => 2,
    };
    let mut list: Vec<(u8, usize, usize)> = p
        .accesses
        .iter()
        .enumerate()
        .filter(|(_, a)| if writes { a.writes } else { !a.writes })
        .map(|(i, a)| (rank(a.access), i, a.resource.index()))
        .collect();
    list.sort_unstable();
    let mut seen = std::collections::BTreeSet::new();
    let mut out: Vec<usize> = list
        .into_iter()
        .filter(|&(_, _, r)| seen.insert(r))
        .map(|(_, _, r)| r)
        .collect();
    if !writes {
        // A resource read and written is an output.
        let written: std::collections::BTreeSet<usize> = p
            .accesses
            .iter()
            .filter(|a| a.writes)
            .map(|a| a.resource.index())
            .collect();
        out.retain(|r| !written.contains(r));
    }
    out
}
