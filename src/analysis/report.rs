//! `framelab analyze` and `framelab graph`: runs every analysis on a capture and turns the
//! results into stable, sorted reports (JSON with names instead of ids) and readable tables,
//! and the pass graph into JSON or Graphviz DOT.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use petgraph::visit::EdgeRef;
use serde::Serialize;

use super::barriers::{self, BarrierKind, BarrierPlan, Placement, VkScope};
use super::graph::{self, CycleError, EdgeKind, PassGraph};
use super::lints::{self, Lint, LintInput, LintSeverity};
use super::memory::{self, MemoryPlan, Totals};
use super::model::{self, FrameModel};
use super::schedule::{self, Schedule};
use crate::capture::model::{Capture, PassId, Subresources};
use crate::text::human_bytes;
use crate::text::table;

/// Everything the analyses found, with ids into `model`.
#[derive(Debug)]
pub struct Analysis {
    pub model: FrameModel,
    pub graph: PassGraph,
    /// Execution order, as capture passes.
    pub order: Vec<PassId>,
    /// Execution order as indices into `model.passes` (what graph, barriers and memory speak).
    pub model_order: Vec<u32>,
    /// Capture passes whose work never reaches an output.
    pub culled: Vec<PassId>,
    pub plan: BarrierPlan,
    pub memory: MemoryPlan,
    pub schedule: Schedule,
    pub lints: Vec<Lint>,
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
        order: order.iter().map(|&p| model.passes[p as usize].id).collect(),
        culled: culled.iter().map(|&p| full_ids[p as usize]).collect(),
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
}

/// The lints of `a` with names from `capture`, sorted and without repeats.
pub fn lint_reports(capture: &Capture, lints: &[Lint]) -> Vec<LintReport> {
    let mut out: Vec<LintReport> = lints
        .iter()
        .map(|l| LintReport {
            code: l.kind.code(),
            name: l.kind.name(),
            severity: l.kind.severity(),
            message: l.message.clone(),
            pass: l.pass.map(|p| capture.pass(p).name.clone()),
            resource: l.resource.map(|r| capture.resource(r).name.clone()),
        })
        .collect();
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

#[derive(Debug, Clone, Serialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(untagged)]
pub enum SubresourceReport {
    All(&'static str),
    Texture { mips: [u32; 2], layers: [u32; 2] },
    Bytes { bytes: [u64; 2] },
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

fn subresource(model: &FrameModel, resource: u32, r: &Subresources) -> SubresourceReport {
    let res = &model.resources[resource as usize];
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

pub fn report(capture: &Capture, a: &Analysis) -> Report {
    let m = &a.model;
    let pass = |p: u32| m.passes[p as usize].name.clone();
    let queue = |q: u32| m.queues[q as usize].name.clone();
    let resource = |r: u32| m.resources[r as usize].name.clone();
    let vk = |src: &VkScope, dst: &VkScope| VulkanReport {
        old_layout: src.layout,
        new_layout: dst.layout,
        src_stages: src.stages.clone(),
        src_access: src.access.clone(),
        dst_stages: dst.stages.clone(),
        dst_access: dst.access.clone(),
    };
    let mut boundaries: Vec<Boundary> = a
        .model_order
        .iter()
        .enumerate()
        .map(|(position, &p)| Boundary {
            position,
            pass: pass(p),
            queue: queue(m.passes[p as usize].queue),
            barriers: Vec::new(),
        })
        .collect();
    let mut position = vec![0usize; m.passes.len()];
    for (i, &p) in a.model_order.iter().enumerate() {
        position[p as usize] = i;
    }
    let mut sorted: Vec<&barriers::Barrier> = a.plan.barriers.iter().collect();
    sorted.sort_by_key(|b| (b.for_pass, b.kind, b.resource, b.range, b.placement));
    for b in sorted {
        let (vk_src, vk_dst) = b.vulkan(m);
        boundaries[position[b.for_pass as usize]]
            .barriers
            .push(BarrierReport {
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
        let q = m.passes[ab.before_pass as usize].queue;
        boundaries[position[ab.before_pass as usize]]
            .barriers
            .push(BarrierReport {
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
    for b in &mut boundaries {
        b.barriers.sort_by(|x, y| {
            (x.kind, &x.resource, &x.placement).cmp(&(y.kind, &y.resource, &y.placement))
        });
    }
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
    }
}

pub fn ratio(t: &Totals) -> f64 {
    if t.lower_bound_bytes == 0 {
        1.0
    } else {
        (t.aliased_bytes as f64 / t.lower_bound_bytes as f64 * 1000.0).round() / 1000.0
    }
}

pub fn render_text(r: &Report) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "capture {}: {} passes in order, {} culled\n",
        r.capture,
        r.order.len(),
        r.culled.len()
    );
    let order: Vec<Vec<String>> = r
        .barriers
        .iter()
        .map(|b| {
            vec![
                b.position.to_string(),
                b.pass.clone(),
                b.queue.clone(),
                b.barriers.len().to_string(),
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Order\n{}",
        table(&["#", "pass", "queue", "barriers"], &order)
    );
    if !r.culled.is_empty() {
        let _ = writeln!(
            out,
            "Culled (results never reach an output): {}\n",
            r.culled.join(", ")
        );
    }
    let mut rows = Vec::new();
    for b in &r.barriers {
        for x in &b.barriers {
            let sub = match &x.subresource {
                SubresourceReport::All(_) => "all".to_owned(),
                SubresourceReport::Texture { mips, layers } => format!(
                    "mips {}+{} layers {}+{}",
                    mips[0], mips[1], layers[0], layers[1]
                ),
                SubresourceReport::Bytes { bytes } => format!("bytes {}+{}", bytes[0], bytes[1]),
            };
            let kind = match x.kind {
                BarrierKind::Transition => "transition",
                BarrierKind::Uav => "uav",
                BarrierKind::Aliasing => "aliasing",
            };
            let states = match x.kind {
                BarrierKind::Aliasing => format!(
                    "{} -> {}",
                    x.resource_before.as_deref().unwrap_or("?"),
                    x.resource
                ),
                _ => format!("{} -> {}", x.before, x.after),
            };
            let mut note = x.placement.clone();
            if let Some(s) = &x.split_begin_after {
                let _ = write!(note, "; split from {s}");
            }
            if x.next_frame {
                note.push_str("; for next frame");
            }
            rows.push(vec![
                b.pass.clone(),
                kind.to_owned(),
                x.resource.clone(),
                sub,
                states,
                x.queue.clone(),
                note,
            ]);
        }
    }
    let _ = writeln!(
        out,
        "Barriers ({})\n{}",
        rows.len(),
        table(
            &[
                "boundary",
                "kind",
                "resource",
                "subresource",
                "states",
                "queue",
                "placement"
            ],
            &rows
        )
    );
    if !r.fences.is_empty() {
        let f: Vec<Vec<String>> = r
            .fences
            .iter()
            .map(|f| {
                vec![
                    f.signal_after.clone(),
                    f.wait_before.clone(),
                    if f.declared { "declared" } else { "NEEDED" }.to_owned(),
                ]
            })
            .collect();
        let _ = writeln!(
            out,
            "Fences\n{}",
            table(&["signal after", "wait before", "source"], &f)
        );
    }
    let mut mem: Vec<Vec<String>> = r
        .memory
        .heap_types
        .iter()
        .map(|(k, t)| {
            vec![
                k.clone(),
                human_bytes(t.unaliased_bytes),
                human_bytes(t.aliased_bytes),
                human_bytes(t.lower_bound_bytes),
                format!("{:.3}", ratio(t)),
            ]
        })
        .collect();
    let t = &r.memory.total;
    mem.push(vec![
        "total".into(),
        human_bytes(t.unaliased_bytes),
        human_bytes(t.aliased_bytes),
        human_bytes(t.lower_bound_bytes),
        format!("{:.3}", ratio(t)),
    ]);
    let _ = writeln!(
        out,
        "Memory\n{}",
        table(
            &[
                "heap type",
                "unaliased",
                "aliased plan",
                "lower bound",
                "plan / bound"
            ],
            &mem
        )
    );
    let lints: Vec<Vec<String>> = r
        .lints
        .iter()
        .map(|l| {
            let sev = match l.severity {
                lints::LintSeverity::Error => "error",
                lints::LintSeverity::Warning => "warning",
                lints::LintSeverity::Info => "info",
            };
            vec![
                l.code.to_owned(),
                sev.to_owned(),
                l.name.to_owned(),
                l.message.clone(),
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Lints ({})\n{}",
        lints.len(),
        table(&["code", "severity", "lint", "message"], &lints)
    );
    let cp = &r.critical_path;
    let _ = writeln!(
        out,
        "Critical path ({} timings): {:.3} ms of {:.3} ms serial\n  {}",
        cp.timing_source,
        cp.length_ns as f64 / 1e6,
        cp.serial_ns as f64 / 1e6,
        cp.passes.join(" -> ")
    );
    for o in &r.async_compute {
        let _ = writeln!(
            out,
            "  async compute: {} can overlap {}",
            o.pass,
            if o.overlaps.is_empty() {
                "nothing".to_owned()
            } else {
                o.overlaps.join(", ")
            }
        );
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Graph output

#[derive(Debug, Serialize)]
pub struct GraphReport {
    pub passes: Vec<GraphPass>,
    pub edges: Vec<GraphEdge>,
    pub history_reads: Vec<HistoryReadReport>,
}

#[derive(Debug, Serialize)]
pub struct GraphPass {
    pub name: String,
    pub queue: String,
    pub markers: Vec<String>,
    pub culled: bool,
}

#[derive(Debug, Serialize, PartialEq, Eq, PartialOrd, Ord)]
pub struct GraphEdge {
    pub from: String,
    pub to: String,
    pub kind: EdgeKind,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resource: Option<String>,
    /// Data edges: the later pass's range of the resource that has the hazard.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subresource: Option<SubresourceReport>,
}

#[derive(Debug, Serialize)]
pub struct HistoryReadReport {
    pub pass: String,
    pub resource: String,
}

pub fn graph_report(a: &Analysis) -> GraphReport {
    let m = &a.model;
    let passes = m
        .passes
        .iter()
        .map(|p| GraphPass {
            name: p.name.clone(),
            queue: m.queues[p.queue as usize].name.clone(),
            markers: p.markers.clone(),
            culled: a.culled.contains(&p.id),
        })
        .collect();
    let mut edges: Vec<GraphEdge> = a
        .graph
        .graph
        .edge_references()
        .map(|e| GraphEdge {
            from: m.passes[e.source().index()].name.clone(),
            to: m.passes[e.target().index()].name.clone(),
            kind: e.weight().kind,
            resource: e
                .weight()
                .resource
                .map(|r| m.resources[r as usize].name.clone()),
            subresource: e.weight().resource.and_then(|r| {
                let range = e.weight().range(m, e.target().index())?;
                Some(subresource(m, r, range))
            }),
        })
        .collect();
    edges.sort();
    let history_reads = a
        .graph
        .history_reads
        .iter()
        .map(|h| HistoryReadReport {
            pass: m.passes[h.pass as usize].name.clone(),
            resource: m.resources[h.resource as usize].name.clone(),
        })
        .collect();
    GraphReport {
        passes,
        edges,
        history_reads,
    }
}

const QUEUE_COLOURS: [&str; 6] = [
    "#4e79a7", "#f28e2b", "#59a14f", "#b07aa1", "#e15759", "#76b7b2",
];

fn dot_id(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Graphviz DOT: one colour per queue, marker groups as nested clusters, edge style per kind.
pub fn dot(a: &Analysis) -> String {
    let m = &a.model;
    let mut out = String::from(
        "digraph frame {\n  rankdir=LR;\n  node [shape=box, style=\"rounded,filled\", fontname=\"Helvetica\", fontcolor=white];\n  edge [fontname=\"Helvetica\", fontsize=9];\n",
    );
    // Legend: one node per queue.
    out.push_str("  subgraph cluster_legend {\n    label=\"queues\";\n");
    for (i, q) in m.queues.iter().enumerate() {
        let _ = writeln!(
            out,
            "    {} [fillcolor=\"{}\", shape=plaintext, style=filled];",
            dot_id(&format!("queue: {}", q.name)),
            QUEUE_COLOURS[i % QUEUE_COLOURS.len()]
        );
    }
    out.push_str("  }\n");
    // Nested clusters by marker path.
    #[derive(Default)]
    struct Cluster {
        passes: Vec<u32>,
        children: BTreeMap<String, Cluster>,
    }
    let mut root = Cluster::default();
    for &p in &a.model_order {
        let mut c = &mut root;
        for marker in &m.passes[p as usize].markers {
            c = c.children.entry(marker.clone()).or_default();
        }
        c.passes.push(p);
    }
    fn emit(
        out: &mut String,
        c: &Cluster,
        m: &FrameModel,
        culled: &[PassId],
        depth: usize,
        counter: &mut usize,
    ) {
        let indent = "  ".repeat(depth + 1);
        for &p in &c.passes {
            let pass = &m.passes[p as usize];
            let colour = QUEUE_COLOURS[pass.queue as usize % QUEUE_COLOURS.len()];
            let dead = if culled.contains(&pass.id) {
                ", style=\"rounded,filled,dashed\", fillcolor=\"#bbbbbb\""
            } else {
                ""
            };
            let _ = writeln!(
                out,
                "{indent}{} [fillcolor=\"{colour}\"{dead}];",
                dot_id(&pass.name)
            );
        }
        for (name, child) in &c.children {
            *counter += 1;
            let _ = writeln!(
                out,
                "{indent}subgraph cluster_{} {{\n{indent}  label={};\n{indent}  style=rounded; color=\"#999999\";",
                counter,
                dot_id(name)
            );
            emit(out, child, m, culled, depth + 1, counter);
            let _ = writeln!(out, "{indent}}}");
        }
    }
    let mut counter = 0;
    emit(&mut out, &root, m, &a.culled, 0, &mut counter);
    let report = graph_report(a);
    for e in &report.edges {
        let style = match e.kind {
            EdgeKind::Raw => "color=\"#333333\"",
            EdgeKind::War => "color=\"#999999\", style=dashed",
            EdgeKind::Waw => "color=\"#999999\", style=dotted",
            EdgeKind::Queue => "color=\"#cccccc\", arrowhead=none",
            EdgeKind::Fence => "color=\"#e15759\", penwidth=2",
        };
        let label = e
            .resource
            .as_ref()
            .map(|r| format!(", label={}", dot_id(r)))
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "  {} -> {} [{style}{label}];",
            dot_id(&e.from),
            dot_id(&e.to)
        );
    }
    out.push_str("}\n");
    out
}
