//! The inspector's model projected from the pipeline's stages by id: passes in execution order
//! with their bindings, attachments, state, work, parameters, derived and recorded barriers and
//! lints; resources with sizes, heaps, aliasing-plan offsets, first and last use and what they
//! alias; queue waits; timings from a report and the diff against a second one. The panels
//! receive only this plain data (ids, names and preformatted text), never capture types, and
//! `launch` starts the replay they drive.

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
use serde::Serialize;

use framelab_core::analysis::model::{MPass, MResource};
use framelab_core::analysis::report::{self, Analysis, BarrierReport};
use framelab_core::capture::model::{
    BindingTarget, Capture, PassDesc, PassId, ResourceId, Subresources,
};
use framelab_core::pipeline::{Analysed, Lowered};
use framelab_core::timing::TimingReport;

/// A serde enum's name as the capture spells it.
fn spelled(x: &impl Serialize) -> String {
    match serde_json::to_value(x) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(v) => v.to_string(),
        Err(_) => String::new(),
    }
}

fn range_text(r: &Subresources, texture: bool) -> String {
    if texture {
        format!(
            "mips {}..{} layers {}..{}",
            r.mip_base,
            r.mip_base + r.mip_count,
            r.layer_base,
            r.layer_base + r.layer_count
        )
    } else {
        format!("bytes {}+{}", r.byte_offset, r.byte_size)
    }
}

fn params(
    p: &BTreeMap<String, framelab_core::capture::format::ParamValue>,
) -> Vec<(String, String)> {
    p.iter()
        .map(|(k, v)| (k.clone(), serde_json::to_string(v).unwrap_or_default()))
        .collect()
}

fn work(c: &Capture, p: &PassDesc) -> Vec<String> {
    let name = |r| c.resource(r).name.clone();
    // An imported draw or dispatch names the Vulkan pipeline it runs with.
    let pipeline = |vk: &Option<Box<framelab_core::capture::vk_model::VkWork>>| {
        vk.as_ref()
            .and_then(|w| c.vulkan.as_ref()?.pipelines.get(w.pipeline))
            .map_or(String::new(), |pl| format!(" with {}", pl.name))
    };
    let mut out = Vec::new();
    for (i, d) in p.draws.iter().enumerate() {
        let what = d.label.clone().unwrap_or_else(|| format!("draw {i}"));
        let args = match (&d.indirect, d.mesh) {
            (Some((buf, offset)), _) => format!("indirect from {} @ {offset}", name(*buf)),
            (None, Some(m)) => format!(
                "mesh {} x{} instances",
                c.meshes[m.index()].name,
                d.instances
            ),
            (None, None) => format!(
                "{} vertices x{} instances",
                d.count.unwrap_or(0),
                d.instances
            ),
        };
        out.push(format!("{what}: {args}{}", pipeline(&d.vk)));
    }
    for (i, d) in p.dispatches.iter().enumerate() {
        let what = d.label.clone().unwrap_or_else(|| format!("dispatch {i}"));
        let args = match (&d.indirect, d.groups) {
            (Some((buf, offset)), _) => format!("indirect from {} @ {offset}", name(*buf)),
            (None, Some([x, y, z])) => format!("{x}x{y}x{z} groups"),
            (None, None) => "no groups".to_owned(),
        };
        out.push(format!("{what}: {args}{}", pipeline(&d.vk)));
    }
    for cp in &p.copies {
        out.push(format!(
            "copy {} mip {} -> {} mip {}",
            name(cp.src.resource),
            cp.src.mip,
            name(cp.dst.resource),
            cp.dst.mip
        ));
    }
    for cl in &p.clears {
        out.push(format!("clear {} to {:?}", name(cl.resource), cl.value));
    }
    if let Some((src, dst)) = p.resolve {
        out.push(format!("resolve {} -> {}", name(src), name(dst)));
    }
    if let Some((r, range)) = &p.generate_mips {
        out.push(format!(
            "generate mips of {} ({})",
            name(*r),
            range_text(range, true)
        ));
    }
    if let Some(r) = p.present {
        out.push(format!("present {}", name(r)));
    }
    out
}

fn bindings(c: &Capture, p: &PassDesc) -> Vec<(String, String)> {
    p.bindings
        .iter()
        .map(|b| {
            let target = match &b.target {
                BindingTarget::Resource {
                    resource,
                    view_format,
                    view_kind,
                } => {
                    let r = c.resource(*resource);
                    let mut s = format!(
                        "{}{} as {}",
                        r.name,
                        if b.previous_frame {
                            " (previous frame)"
                        } else {
                            ""
                        },
                        view_kind.as_str()
                    );
                    if let Some(f) = view_format {
                        s.push_str(&format!(" {}", f.name));
                    }
                    if let Some(a) = b.access {
                        s.push_str(&format!(", {}", a.as_str()));
                    }
                    if let Some(range) = &b.range {
                        s.push_str(&format!(", {}", range_text(range, r.is_texture())));
                    }
                    s
                }
                BindingTarget::Sampler(s) => format!("sampler {}", c.samplers[s.index()].name),
            };
            (b.variable.clone(), target)
        })
        .collect()
}

/// Each attachment: its slot, its resource (model index) and the rest of its line.
fn attachments(p: &PassDesc) -> Vec<crate::model::Attachment> {
    let mut out: Vec<crate::model::Attachment> = p
        .color_attachments
        .iter()
        .enumerate()
        .map(|(i, a)| crate::model::Attachment {
            slot: format!("color {i}"),
            resource: a.resource.index(),
            text: format!(
                "mip {} layer {} ({}), load {}{}, store {}",
                a.mip,
                a.layer,
                a.format.name,
                spelled(&a.load),
                if spelled(&a.load) == "clear" {
                    format!(" {:?}", a.clear)
                } else {
                    String::new()
                },
                spelled(&a.store)
            ),
        })
        .collect();
    if let Some(d) = &p.depth_stencil {
        out.push(crate::model::Attachment {
            slot: "depth".into(),
            resource: d.resource.index(),
            text: format!(
                "mip {} ({}), depth load {} ({}) store {}, stencil load {} ({}) store {}{}",
                d.mip,
                d.format.name,
                spelled(&d.depth_load),
                d.depth_clear,
                spelled(&d.depth_store),
                spelled(&d.stencil_load),
                d.stencil_clear,
                spelled(&d.stencil_store),
                if d.read_only { ", read-only" } else { "" }
            ),
        });
    }
    out
}

fn state(c: &Capture, p: &PassDesc) -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Some(s) = &p.shader {
        out.push(("shader".to_owned(), c.shader(s.id).file.clone()));
        for (stage, entry) in [
            ("vertex", &s.vertex),
            ("fragment", &s.fragment),
            ("compute", &s.compute),
        ] {
            if let Some(e) = entry {
                out.push((stage.to_owned(), e.clone()));
            }
        }
    }
    // An imported pass's state is its draws' and dispatches' pipelines; a pass-level render
    // state would be made up.
    if let Some(vk) = &c.vulkan {
        let mut used: Vec<usize> = p
            .draws
            .iter()
            .filter_map(|d| d.vk.as_ref())
            .chain(p.dispatches.iter().filter_map(|d| d.vk.as_ref()))
            .map(|w| w.pipeline)
            .collect();
        used.sort_unstable();
        used.dedup();
        for pl in used.iter().filter_map(|&i| vk.pipelines.get(i)) {
            let stages: Vec<String> = pl
                .stages
                .iter()
                .filter_map(|s| {
                    let m = vk.modules.get(s.module)?;
                    Some(format!(
                        "{} {}",
                        s.stage
                            .trim_start_matches("VK_SHADER_STAGE_")
                            .trim_end_matches("_BIT")
                            .to_lowercase(),
                        m.name
                    ))
                })
                .collect();
            out.push((pl.name.clone(), stages.join(", ")));
            if let Some(g) = &pl.graphics {
                let short = |n: &str, prefix: &str| n.trim_start_matches(prefix).to_lowercase();
                let mut line = format!(
                    "{}, cull {}, front {}",
                    short(&g.topology, "VK_PRIMITIVE_TOPOLOGY_"),
                    ["none", "front", "back", "both"][(g.cull_mode & 3) as usize],
                    short(&g.front_face, "VK_FRONT_FACE_")
                );
                if let Some(d) = g.depth_stencil.as_ref().filter(|d| d.depth_test) {
                    line += &format!(
                        ", depth {}{}",
                        short(&d.depth_compare, "VK_COMPARE_OP_"),
                        if d.depth_write { " write" } else { "" }
                    );
                }
                if g.blend.iter().any(|b| b.enable) {
                    line += ", blend";
                }
                out.push((String::new(), line));
            }
        }
        return out;
    }
    // An import without code records no pipeline state: the defaults would be made up.
    if p.kind.as_str() == "raster"
        && c.not_replayable().is_none()
        && let Ok(serde_json::Value::Object(m)) = serde_json::to_value(&p.state)
    {
        for (k, v) in m {
            let text = match v {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            };
            out.push((k, text));
        }
    }
    out
}

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

fn recorded(c: &Capture, p: &PassDesc) -> Vec<Barrier> {
    p.barriers
        .iter()
        .map(|b| {
            let resource = b.resource.map(|r| c.resource(r));
            let states = |s: &[framelab_core::capture::format::ResourceState]| {
                s.iter().map(spelled).collect::<Vec<_>>().join("|")
            };
            Barrier {
                side: BarrierSide::Before,
                source: BarrierSource::Recorded,
                kind: spelled(&b.barrier_type),
                resource: resource.map_or("(all)".to_owned(), |r| r.name.clone()),
                subresource: match (&b.range, resource) {
                    (Some(range), Some(r)) => range_text(range, r.is_texture()),
                    _ => "all".to_owned(),
                },
                states: match b.resource_before {
                    Some(before) => format!("{} -> ...", c.resource(before).name),
                    None if b.before.is_empty() && b.after.is_empty() => String::new(),
                    None => format!("{} -> {}", states(&b.before), states(&b.after)),
                },
                vulkan: b.vulkan.as_ref().map(vulkan_text).unwrap_or_default(),
            }
        })
        .collect()
}

/// A recorded Vulkan barrier as the details pane lists it: layouts, then scopes, then origin.
fn vulkan_text(v: &framelab_core::capture::model::VulkanBarrierDesc) -> String {
    let layouts = match (v.old_layout, v.new_layout) {
        (Some(a), Some(b)) => format!("{a} -> {b}; "),
        _ => String::new(),
    };
    format!(
        "{layouts}{}/{} -> {}/{} ({})",
        v.src_stages, v.src_access, v.dst_stages, v.dst_access, v.origin
    )
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
            barriers.extend(recorded(c, p));
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
                work: work(c, p),
                steps: p.draws.len() + p.dispatches.len(),
                bindings: bindings(c, p),
                attachments: attachments(p),
                state: state(c, p),
                params: params(&p.params),
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
        fences: fences(c, order),
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

/// Cross-queue waits between the passes shown (positions in `order`): each fence's
/// signalling passes found once, then every pass that waits on it.
fn fences(c: &Capture, order: &[PassId]) -> Vec<(usize, usize)> {
    let mut signalled_by: BTreeMap<_, Vec<usize>> = BTreeMap::new();
    for (j, &id) in order.iter().enumerate() {
        for &f in &c.pass(id).signal {
            signalled_by.entry(f).or_default().push(j);
        }
    }
    let mut out = Vec::new();
    for (i, &id) in order.iter().enumerate() {
        for f in &c.pass(id).wait {
            for &j in signalled_by.get(f).map(Vec::as_slice).unwrap_or_default() {
                out.push((j, i));
            }
        }
    }
    out.sort_unstable();
    out
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
