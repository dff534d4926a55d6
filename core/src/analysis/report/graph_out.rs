//! The pass graph as reports show it: JSON (passes, data edges with the subresource range of
//! each hazard, history reads) and Graphviz DOT with queues as colours and markers as clusters.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use petgraph::visit::EdgeRef;
use serde::Serialize;

use super::{Analysis, SubresourceReport, subresource};
use crate::analysis::graph::EdgeKind;
use crate::analysis::model::{FrameModel, MPass};
use crate::capture::model::PassId;

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
            queue: m.queues[p.queue.index()].name.clone(),
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
                .map(|r| m.resources[r.index()].name.clone()),
            subresource: e.weight().resource.and_then(|r| {
                let range = e.weight().range(m, MPass::new(e.target().index()))?;
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
            pass: m.passes[h.pass.index()].name.clone(),
            resource: m.resources[h.resource.index()].name.clone(),
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
        passes: Vec<MPass>,
        children: BTreeMap<String, Cluster>,
    }
    let mut root = Cluster::default();
    for &p in &a.model_order {
        let mut c = &mut root;
        for marker in &m.passes[p.index()].markers {
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
            let pass = &m.passes[p.index()];
            let colour = QUEUE_COLOURS[pass.queue.index() % QUEUE_COLOURS.len()];
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
