//! Queue schedule: which compute-queue passes may overlap graphics work (neither is ordered
//! before the other by dependencies, queue order or fences), and the critical path through the
//! DAG weighted by GPU time (recorded in the capture, or measured by a replay) against the
//! serial sum, which is what perfect overlap could save.

use petgraph::visit::EdgeRef;
use serde::Serialize;

use super::barriers::FenceNeed;
use super::graph::PassGraph;
use super::model::FrameModel;
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
    /// Graphics-queue passes it is not ordered against, in order.
    pub overlaps: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Schedule {
    pub critical_path: CriticalPath,
    pub async_compute: Vec<Overlap>,
}

/// Ancestor sets (bit per pass) over every edge and fence.
fn ancestors(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[u32],
    fences: &[FenceNeed],
) -> (usize, Vec<u64>) {
    let n = model.passes.len();
    let words = n.div_ceil(64).max(1);
    let mut preds: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in graph.graph.edge_references() {
        preds[e.target().index()].push(e.source().index() as u32);
    }
    for f in fences {
        preds[f.wait_before as usize].push(f.signal_after);
    }
    let mut bits = vec![0u64; n * words];
    for &p in order {
        for &a in &preds[p as usize] {
            let (pa, pp) = (a as usize * words, p as usize * words);
            for w in 0..words {
                bits[pp + w] |= bits[pa + w];
            }
            bits[pp + a as usize / 64] |= 1 << (a % 64);
        }
    }
    (words, bits)
}

pub fn schedule(
    model: &FrameModel,
    graph: &PassGraph,
    order: &[u32],
    fences: &[FenceNeed],
    times: &[Option<u64>],
    timing_source: &str,
) -> Schedule {
    let (words, bits) = ancestors(model, graph, order, fences);
    let before = |a: usize, b: usize| bits[b * words + a / 64] & (1 << (a % 64)) != 0;
    let mut async_compute = Vec::new();
    for &c in order {
        if model.queue_type(c as usize) != QueueType::Compute {
            continue;
        }
        let overlaps: Vec<String> = order
            .iter()
            .filter(|&&g| model.queue_type(g as usize) == QueueType::Graphics)
            .filter(|&&g| !before(c as usize, g as usize) && !before(g as usize, c as usize))
            .map(|&g| model.passes[g as usize].name.clone())
            .collect();
        async_compute.push(Overlap {
            pass: model.passes[c as usize].name.clone(),
            overlaps,
        });
    }
    // Longest path, node-weighted, over all ordering constraints.
    let n = model.passes.len();
    let weight = |p: usize| times.get(p).copied().flatten().unwrap_or(0);
    let mut dist = vec![0u64; n];
    let mut via: Vec<Option<u32>> = vec![None; n];
    let mut preds: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in graph.graph.edge_references() {
        preds[e.target().index()].push(e.source().index() as u32);
    }
    for f in fences {
        preds[f.wait_before as usize].push(f.signal_after);
    }
    for &p in order {
        let best = preds[p as usize]
            .iter()
            .copied()
            .max_by_key(|&a| (dist[a as usize], std::cmp::Reverse(a)));
        // Recorded times come from the capture: saturate rather than overflow.
        dist[p as usize] = weight(p as usize).saturating_add(best.map_or(0, |a| dist[a as usize]));
        via[p as usize] = best;
    }
    let end = (0..n).max_by_key(|&p| (dist[p], std::cmp::Reverse(p)));
    let mut passes = Vec::new();
    let mut cursor = end.map(|p| p as u32);
    while let Some(p) = cursor {
        passes.push(model.passes[p as usize].name.clone());
        cursor = via[p as usize];
    }
    passes.reverse();
    Schedule {
        critical_path: CriticalPath {
            timing_source: timing_source.to_owned(),
            length_ns: end.map_or(0, |p| dist[p]),
            serial_ns: (0..n).map(weight).fold(0, u64::saturating_add),
            passes,
        },
        async_compute,
    }
}
