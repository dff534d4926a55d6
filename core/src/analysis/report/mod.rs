//! `framelab analyze` and `framelab graph`: runs every analysis on a capture and turns the
//! results into stable, sorted reports (JSON with names instead of ids) and readable tables,
//! and the pass graph into JSON or Graphviz DOT (`graph`); `text` renders the tables, and
//! `pass_text` spells one pass (its work, bindings, state, recorded barriers) for viewers.

mod graph_out;
pub mod pass_text;
mod text;

pub use graph_out::{GraphEdge, GraphPass, GraphReport, HistoryReadReport, dot, graph_report};
pub use text::render_text;

use std::collections::BTreeMap;

use serde::Serialize;

use super::barriers::{self, BarrierKind, BarrierPlan, Placement, VkScope};
use super::graph::{self, CycleError, PassGraph};
use super::lints::{self, Lint, LintInput, LintSeverity};
use super::memory::{self, MemoryPlan, Totals};
use super::model::{self, FrameModel, MPass, MQueue, MResource};
use super::schedule::{self, Schedule};
use crate::capture::model::{Capture, PassId, ResourceId, Subresources};

/// Everything the analyses found. Order, culled passes and lints are capture ids; barriers,
/// fences, the memory plan and the schedule keep the model's dense indices (what their hot loops
/// use), which `pass_id` and `resource_id` turn into capture ids.
#[derive(Debug)]
pub struct Analysis {
    pub model: FrameModel,
    pub graph: PassGraph,
    /// Execution order, as capture passes.
    pub order: Vec<PassId>,
    /// Execution order as indices into `model.passes` (what graph, barriers and memory speak).
    pub model_order: Vec<MPass>,
    /// Capture passes whose work never reaches an output.
    pub culled: Vec<PassId>,
    pub plan: BarrierPlan,
    pub memory: MemoryPlan,
    pub schedule: Schedule,
    pub lints: Vec<Lint>,
}

impl Analysis {
    /// The capture pass of a model pass index (what barriers, fences and the schedule hold).
    pub fn pass_id(&self, model_pass: MPass) -> PassId {
        self.model.passes[model_pass.index()].id
    }
    /// The capture resource of a model resource index (a previous-frame copy maps to the
    /// resource it copies).
    pub fn resource_id(&self, model_resource: MResource) -> ResourceId {
        self.model.resources[model_resource.index()].id
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct AnalyzeOptions {
    /// Drop culled passes before ordering, barriers and memory.
    pub cull: bool,
}

pub fn analyze(capture: &Capture, options: AnalyzeOptions) -> Result<Analysis, CycleError> {
    // The whole frame is analysed once; lints describe it (model indices are capture pass ids).
    let full = model::from_capture(capture);
    // Without --cull the memory plan is for this frame: derive it beside the rest.
    let super::Derived {
        units: full_units,
        graph: full_graph,
        order: full_order,
        plan: full_plan,
        memory: full_memory,
    } = super::derive_frame(&full, !options.cull)?;
    let culled = graph::culled(&full, &full_units, &full_graph);
    let full_ids: Vec<PassId> = full.passes.iter().map(|p| p.id).collect();
    let lints = lints::lints(&LintInput {
        capture,
        model: &full,
        graph: &full_graph,
        order: &full_order,
        culled: &culled,
        plan: &full_plan,
    });
    // With --cull, order, barriers and memory are derived again for the frame without them.
    let (model, graph, order, plan, memory) = match (full_memory, culled.is_empty()) {
        (Some(memory), _) => (full, full_graph, full_order, full_plan, memory),
        (None, true) => {
            let memory = memory::plan(&full, &full_order);
            (full, full_graph, full_order, full_plan, memory)
        }
        (None, false) => {
            let model = graph::without_passes(&full, &culled);
            let derived = super::derive_frame(&model, true)?;
            let memory = derived
                .memory
                .unwrap_or_else(|| memory::plan(&model, &derived.order));
            (model, derived.graph, derived.order, derived.plan, memory)
        }
    };
    let times: Vec<Option<u64>> = model.passes.iter().map(|p| p.gpu_ns).collect();
    let source = if times.iter().any(Option::is_some) {
        "recorded"
    } else {
        "none"
    };
    let schedule = schedule::schedule(&model, &graph, &order, &plan.fences, &times, source);
    Ok(Analysis {
        order: order.iter().map(|&p| model.passes[p.index()].id).collect(),
        culled: culled.iter().map(|&p| full_ids[p.index()]).collect(),
        model,
        graph,
        model_order: order,
        plan,
        memory,
        schedule,
        lints,
    })
}

// ---------------------------------------------------------------------------------------------
// JSON report

/// A lint as reports show it: codes and names instead of ids, sorted by them.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct LintReport {
    pub code: &'static str,
    pub name: &'static str,
    pub severity: LintSeverity,
    pub message: String,
    pub pass: Option<String>,
    pub resource: Option<String>,
    /// The specification's valid-usage ID, where the finding breaks one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vuid: Option<String>,
    /// The change to the frame that fixes it (`what-if --fix CODE` applies it), where the
    /// advice is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fix: Option<String>,
}

/// The lints of `a` with names from `capture`, sorted and without repeats.
pub fn lint_reports(capture: &Capture, lints: &[Lint]) -> Vec<LintReport> {
    let mut out: Vec<LintReport> = lints.iter().map(|l| lint_report(capture, l)).collect();
    out.sort();
    out.dedup();
    out
}

#[derive(Debug, Serialize)]
pub struct Report {
    pub capture: String,
    pub order: Vec<String>,
    pub culled: Vec<String>,
    pub barriers: Vec<Boundary>,
    pub fences: Vec<FenceReport>,
    pub queue_transfers: Vec<TransferReport>,
    pub memory: MemoryReport,
    pub lints: Vec<LintReport>,
    pub critical_path: schedule::CriticalPath,
    pub async_compute: Vec<schedule::Overlap>,
    /// The frame came from a Vulkan program: the text speaks layouts, stages and accesses
    /// (the JSON gives both vocabularies on every barrier).
    #[serde(skip)]
    pub vulkan_terms: bool,
}

#[derive(Debug, Serialize)]
pub struct Boundary {
    /// Position in the order of the pass this boundary precedes.
    pub position: usize,
    pub pass: String,
    pub queue: String,
    pub barriers: Vec<BarrierReport>,
}

#[derive(Debug, Serialize)]
pub struct BarrierReport {
    pub kind: BarrierKind,
    pub resource: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resource_before: Option<String>,
    pub subresource: SubresourceReport,
    pub before: String,
    pub after: String,
    /// Executes before the boundary's pass, or as a release after an earlier pass.
    pub placement: String,
    pub queue: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split_begin_after: Option<String>,
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub next_frame: bool,
    pub vulkan: VulkanReport,
}

#[derive(Debug, Serialize)]
pub struct VulkanReport {
    pub old_layout: Option<&'static str>,
    pub new_layout: Option<&'static str>,
    pub src_stages: Vec<&'static str>,
    pub src_access: Vec<&'static str>,
    pub dst_stages: Vec<&'static str>,
    pub dst_access: Vec<&'static str>,
}

impl VulkanReport {
    /// The barrier as a Vulkan user reads it: `old -> new` layouts (images), then each side's
    /// stages / accesses; an empty access mask is `NONE`, as Vulkan spells it.
    pub fn describe(&self) -> String {
        let join = |v: &[&str]| {
            if v.is_empty() {
                "NONE".to_owned()
            } else {
                v.join("|")
            }
        };
        let layouts = match (self.old_layout, self.new_layout) {
            (Some(o), Some(n)) => format!("{o} -> {n}; "),
            _ => String::new(),
        };
        format!(
            "{layouts}{} / {} -> {} / {}",
            join(&self.src_stages),
            join(&self.src_access),
            join(&self.dst_stages),
            join(&self.dst_access)
        )
    }
}

#[derive(Debug, Clone, Serialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(untagged)]
pub enum SubresourceReport {
    All(&'static str),
    Texture { mips: [u32; 2], layers: [u32; 2] },
    Bytes { bytes: [u64; 2] },
}

impl SubresourceReport {
    /// `all`, `mips 0+1 layers 0+6` or `bytes 0+256`, as tables show it.
    pub fn describe(&self) -> String {
        match self {
            SubresourceReport::All(_) => "all".to_owned(),
            SubresourceReport::Texture { mips, layers } => format!(
                "mips {}+{} layers {}+{}",
                mips[0], mips[1], layers[0], layers[1]
            ),
            SubresourceReport::Bytes { bytes } => format!("bytes {}+{}", bytes[0], bytes[1]),
        }
    }
}

#[derive(Debug, Serialize)]
pub struct FenceReport {
    pub signal_after: String,
    pub wait_before: String,
    pub declared: bool,
}

#[derive(Debug, Serialize)]
pub struct TransferReport {
    pub resource: String,
    pub subresource: SubresourceReport,
    pub release_after: String,
    pub acquire_before: String,
    pub from_queue: String,
    pub to_queue: String,
}

#[derive(Debug, Serialize)]
pub struct MemoryReport {
    pub heap_types: BTreeMap<String, Totals>,
    pub total: Totals,
    /// Aliased bytes over the lower bound (1.0 is optimal).
    pub aliased_over_lower_bound: f64,
    pub resources: Vec<ResourceMemory>,
    pub aliasing_barriers: Vec<AliasingReport>,
}

#[derive(Debug, Serialize)]
pub struct ResourceMemory {
    pub name: String,
    pub pool: String,
    pub bytes: u64,
    pub offset: u64,
    pub first_use: Option<String>,
    pub last_use: Option<String>,
    pub persistent: bool,
}

#[derive(Debug, Serialize)]
pub struct AliasingReport {
    pub before_pass: String,
    pub resource_before: String,
    pub resource_after: String,
}

fn subresource(model: &FrameModel, resource: MResource, r: &Subresources) -> SubresourceReport {
    let res = &model.resources[resource.index()];
    if *r == res.whole() {
        SubresourceReport::All("all")
    } else if res.is_buffer {
        SubresourceReport::Bytes {
            bytes: [r.byte_offset, r.byte_size],
        }
    } else {
        SubresourceReport::Texture {
            mips: [r.mip_base, r.mip_count],
            layers: [r.layer_base, r.layer_count],
        }
    }
}

/// The derived barriers (transitions, UAV barriers, aliasing barriers) at the boundary before
/// each pass, indexed by model pass (`MPass::index`), in the order reports list them. `report` names them; the
/// inspector projects them onto its passes by id.
pub fn barriers_by_pass(a: &Analysis) -> Vec<Vec<BarrierReport>> {
    let m = &a.model;
    let pass = |p: MPass| m.passes[p.index()].name.clone();
    let queue = |q: MQueue| m.queues[q.index()].name.clone();
    let resource = |r: MResource| m.resources[r.index()].name.clone();
    let vk = |src: &VkScope, dst: &VkScope| VulkanReport {
        old_layout: src.layout,
        new_layout: dst.layout,
        src_stages: src.stages.clone(),
        src_access: src.access.clone(),
        dst_stages: dst.stages.clone(),
        dst_access: dst.access.clone(),
    };
    let mut by_pass: Vec<Vec<BarrierReport>> = (0..m.passes.len()).map(|_| Vec::new()).collect();
    let mut sorted: Vec<&barriers::Barrier> = a.plan.barriers.iter().collect();
    sorted.sort_by_key(|b| (b.for_pass, b.kind, b.resource, b.range, b.placement));
    for b in sorted {
        let (vk_src, vk_dst) = b.vulkan(m);
        by_pass[b.for_pass.index()].push(BarrierReport {
            kind: b.kind,
            resource: resource(b.resource),
            resource_before: None,
            subresource: subresource(m, b.resource, &b.range),
            before: b.before.name(),
            after: b.after.name(),
            placement: match b.placement {
                Placement::Before(p) => format!("before {}", pass(p)),
                Placement::After(p) => format!("after {}", pass(p)),
            },
            queue: queue(b.queue),
            split_begin_after: b.split_begin_after.map(pass),
            next_frame: b.next_frame,
            vulkan: vk(&vk_src, &vk_dst),
        });
    }
    for ab in &a.memory.aliasing_barriers {
        let q = m.passes[ab.before_pass.index()].queue;
        by_pass[ab.before_pass.index()].push(BarrierReport {
            kind: BarrierKind::Aliasing,
            resource: resource(ab.resource_after),
            resource_before: Some(resource(ab.resource_before)),
            subresource: SubresourceReport::All("all"),
            before: "-".into(),
            after: "-".into(),
            placement: format!("before {}", pass(ab.before_pass)),
            queue: queue(q),
            split_begin_after: None,
            next_frame: false,
            vulkan: VulkanReport {
                old_layout: Some("UNDEFINED"),
                new_layout: None,
                src_stages: vec!["ALL_COMMANDS"],
                src_access: vec!["MEMORY_WRITE"],
                dst_stages: vec!["ALL_COMMANDS"],
                dst_access: vec!["MEMORY_READ", "MEMORY_WRITE"],
            },
        });
    }
    for barriers in &mut by_pass {
        barriers.sort_by(|x, y| {
            (x.kind, &x.resource, &x.placement).cmp(&(y.kind, &y.resource, &y.placement))
        });
    }
    by_pass
}

/// A lint as reports show it.
pub fn lint_report(capture: &Capture, l: &Lint) -> LintReport {
    LintReport {
        code: l.kind.code(),
        name: l.kind.name(),
        severity: l.kind.severity(),
        message: l.message.clone(),
        pass: l.pass.map(|p| capture.pass(p).name.clone()),
        resource: l.resource.map(|r| capture.resource(r).name.clone()),
        vuid: l.vuid.clone(),
        fix: l.fix.map(|f| f.describe(capture)),
    }
}

pub fn report(capture: &Capture, a: &Analysis) -> Report {
    let m = &a.model;
    let pass = |p: MPass| m.passes[p.index()].name.clone();
    let queue = |q: MQueue| m.queues[q.index()].name.clone();
    let resource = |r: MResource| m.resources[r.index()].name.clone();
    let mut by_pass = barriers_by_pass(a);
    let boundaries: Vec<Boundary> = a
        .model_order
        .iter()
        .enumerate()
        .map(|(position, &p)| Boundary {
            position,
            pass: pass(p),
            queue: queue(m.passes[p.index()].queue),
            barriers: std::mem::take(&mut by_pass[p.index()]),
        })
        .collect();
    let fences = a
        .plan
        .fences
        .iter()
        .map(|f| FenceReport {
            signal_after: pass(f.signal_after),
            wait_before: pass(f.wait_before),
            declared: f.declared,
        })
        .collect();
    let queue_transfers = a
        .plan
        .transfers
        .iter()
        .map(|t| TransferReport {
            resource: resource(t.resource),
            subresource: subresource(m, t.resource, &t.range),
            release_after: pass(t.release_after),
            acquire_before: pass(t.acquire_before),
            from_queue: queue(t.from_queue),
            to_queue: queue(t.to_queue),
        })
        .collect();
    let mem = &a.memory;
    let memory = MemoryReport {
        heap_types: mem.per_heap_type.clone(),
        total: mem.total.clone(),
        aliased_over_lower_bound: ratio(&mem.total),
        resources: mem
            .resources
            .iter()
            .map(|r| ResourceMemory {
                name: resource(r.resource),
                pool: mem.pools[r.pool as usize].clone(),
                bytes: r.bytes,
                offset: r.offset,
                first_use: r.lifetime.map(|l| pass(a.model_order[l.first as usize])),
                last_use: r.lifetime.map(|l| pass(a.model_order[l.last as usize])),
                persistent: r.persistent,
            })
            .collect(),
        aliasing_barriers: mem
            .aliasing_barriers
            .iter()
            .map(|b| AliasingReport {
                before_pass: pass(b.before_pass),
                resource_before: resource(b.resource_before),
                resource_after: resource(b.resource_after),
            })
            .collect(),
    };
    Report {
        capture: capture.name.clone(),
        order: a.model_order.iter().map(|&p| pass(p)).collect(),
        culled: a
            .culled
            .iter()
            .map(|&p| capture.pass(p).name.clone())
            .collect(),
        barriers: boundaries,
        fences,
        queue_transfers,
        memory,
        lints: lint_reports(capture, &a.lints),
        critical_path: a.schedule.critical_path.clone(),
        async_compute: a.schedule.async_compute.clone(),
        vulkan_terms: capture.from_vulkan_program(),
    }
}

pub fn ratio(t: &Totals) -> f64 {
    if t.lower_bound_bytes == 0 {
        1.0
    } else {
        (t.aliased_bytes as f64 / t.lower_bound_bytes as f64 * 1000.0).round() / 1000.0
    }
}
