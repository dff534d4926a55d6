//! Queue schedule: which compute-queue passes may overlap graphics work (neither is ordered
//! before the other by dependencies, queue order or fences), and the critical path through the
//! DAG weighted by GPU time (recorded in the capture, or measured by a replay) against the
//! serial sum, which is what perfect overlap could save.

use std::collections::BTreeMap;

use petgraph::visit::EdgeRef;
use serde::Serialize;

use super::barriers::FenceNeed;
use super::clocks::Clocks;
use super::graph::PassGraph;
use super::model::{FrameModel, MPass, MQueue};
use crate::capture::format::QueueType;

#[derive(Clone, Debug, Serialize)]
pub struct CriticalPath {
    /// Where the times came from: `recorded`, `measured`, or `none` (every pass weighs 0).
    pub timing_source: String,
    pub length_ns: u64,
    pub serial_ns: u64,
    pub passes: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Overlap {
    /// A pass on a compute queue.
    pub pass: String,
    /// Graphics-queue passes it is not ordered against, in order (the first
    /// `MAX_LISTED_OVERLAPS`).
    pub overlaps: Vec<String>,
    /// How many more graphics passes it is not ordered against.
    #[serde(skip_serializing_if = "is_zero")]
    pub more: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

#[derive(Clone, Debug, Serialize)]
pub struct Schedule {
    pub critical_path: CriticalPath,
    pub async_compute: Vec<Overlap>,
}

/// Graphics passes listed per compute pass at most; the rest are counted.
pub const MAX_LISTED_OVERLAPS: usize = 64;

/// Happens-before over every edge (queue order included) and fence.
fn ancestors(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[MPass],
    fences: &[FenceNeed],
) -> Clocks {
    let preds = predecessors(model, graph, fences);
    let queue_of = model.passes.iter().map(|p| p.queue).collect();
    Clocks::new(model.queues.len(), queue_of, order, |p| {
        preds[p.index()].clone()
    })
}

/// Every pass's direct predecessors: edge sources (queue order included), then fence
/// signallers.
fn predecessors(model: &FrameModel, graph: &PassGraph, fences: &[FenceNeed]) -> Vec<Vec<MPass>> {
    let mut preds: Vec<Vec<MPass>> = vec![Vec::new(); model.passes.len()];
    for e in graph.graph.edge_references() {
        preds[e.target().index()].push(MPass::new(e.source().index()));
    }
    for f in fences {
        preds[f.wait_before.index()].push(f.signal_after);
    }
    preds
}

pub fn schedule(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[MPass],
    fences: &[FenceNeed],
    times: &[Option<u64>],
    timing_source: &str,
) -> Schedule {
    let clocks = ancestors(model, graph, order, fences);
    // Each graphics queue's passes in order, with their place in `order`. On one queue, the
    // passes before a compute pass are a prefix and the passes after it a suffix (a pass after
    // one that follows it follows it too), so the passes it may overlap are one range per
    // queue, found by binary search.
    let place: Vec<usize> = {
        let mut place = vec![usize::MAX; model.passes.len()];
        for (i, &p) in order.iter().enumerate() {
            place[p.index()] = i;
        }
        place
    };
    let mut graphics: BTreeMap<MQueue, Vec<MPass>> = BTreeMap::new();
    for &g in order {
        if model.queue_type(g) == QueueType::Graphics {
            graphics
                .entry(model.passes[g.index()].queue)
                .or_default()
                .push(g);
        }
    }
    let mut async_compute = Vec::new();
    for &c in order {
        if model.queue_type(c) != QueueType::Compute {
            continue;
        }
        let mut ranges: Vec<&[MPass]> = Vec::new();
        for passes in graphics.values() {
            let lo = passes.partition_point(|&g| clocks.before(g, c));
            let hi = passes.partition_point(|&g| !clocks.before(c, g));
            if hi > lo {
                ranges.push(&passes[lo..hi]);
            }
        }
        let total: usize = ranges.iter().map(|r| r.len()).sum();
        let mut listed: Vec<MPass> = Vec::new();
        for r in &ranges {
            listed.extend(r.iter().take(MAX_LISTED_OVERLAPS));
        }
        listed.sort_unstable_by_key(|&g| place[g.index()]);
        listed.truncate(MAX_LISTED_OVERLAPS);
        async_compute.push(Overlap {
            pass: model.passes[c.index()].name.clone(),
            more: total - listed.len(),
            overlaps: listed
                .iter()
                .map(|&g| model.passes[g.index()].name.clone())
                .collect(),
        });
    }
    // Longest path, node-weighted, over all ordering constraints. With no pass timed at all
    // (or every time zero), every pass weighs one, so the path is the longest chain of
    // dependent passes rather than whichever pass comes last among equals; its length in
    // time stays zero.
    let n = model.passes.len();
    let untimed = times.iter().all(|t| t.unwrap_or(0) == 0);
    let weight = |p: usize| times.get(p).copied().flatten().unwrap_or(0);
    let rank = |p: usize| if untimed { 1 } else { weight(p) };
    let mut dist = vec![0u64; n];
    let mut via: Vec<Option<MPass>> = vec![None; n];
    let preds = predecessors(model, graph, fences);
    for &p in order {
        let best = preds[p.index()]
            .iter()
            .copied()
            .max_by_key(|&a| (dist[a.index()], std::cmp::Reverse(a)));
        // Recorded times come from the capture: saturate rather than overflow.
        dist[p.index()] = rank(p.index()).saturating_add(best.map_or(0, |a| dist[a.index()]));
        via[p.index()] = best;
    }
    let end = (0..n).max_by_key(|&p| (dist[p], std::cmp::Reverse(p)));
    let mut passes = Vec::new();
    let mut cursor = end.map(MPass::new);
    while let Some(p) = cursor {
        passes.push(model.passes[p.index()].name.clone());
        cursor = via[p.index()];
    }
    passes.reverse();
    Schedule {
        critical_path: CriticalPath {
            timing_source: timing_source.to_owned(),
            length_ns: if untimed {
                0
            } else {
                end.map_or(0, |p| dist[p])
            },
            serial_ns: (0..n).map(weight).fold(0, u64::saturating_add),
            passes,
        },
        async_compute,
    }
}
