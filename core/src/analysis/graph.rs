//! The pass DAG: a petgraph graph whose nodes are passes and whose edges are read-after-write,
//! write-after-read and write-after-write hazards per subresource unit, submission order within
//! a queue, and fences between queues. Also the topological order that keeps each queue's
//! recorded order, cycle reporting, and culling of passes whose work never reaches an output.
//!
//! Edges are found in recorded order with one pass over the accesses: each unit remembers its
//! last writer and the readers since, so the work is linear in the number of unit accesses.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::EdgeRef;
use serde::Serialize;

use super::model::{FirstAccess, FrameModel, MPass, MResource, OptPass};
use super::units::Units;
use crate::capture::model::Subresources;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeKind {
    /// Read after write: the later pass reads what the earlier wrote.
    Raw,
    /// Write after read: the later pass overwrites what the earlier read.
    War,
    /// Write after write.
    Waw,
    /// Submission order on one queue.
    Queue,
    /// A fence from the signalling pass to the waiting pass.
    Fence,
}

impl EdgeKind {
    pub fn is_data(self) -> bool {
        matches!(self, EdgeKind::Raw | EdgeKind::War | EdgeKind::Waw)
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Edge {
    pub kind: EdgeKind,
    /// The resource, for data edges.
    pub resource: Option<MResource>,
    /// For data edges, the later pass's access (index into its accesses) whose range has the
    /// hazard: edges stay small, and the range is one lookup away (`Edge::range`).
    pub access: Option<u32>,
}

impl Edge {
    /// The subresource range of a data edge: the later pass's access range.
    pub fn range<'m>(&self, model: &'m FrameModel, to: MPass) -> Option<&'m Subresources> {
        let access = self.access?;
        Some(
            &model
                .passes
                .get(to.index())?
                .accesses
                .get(access as usize)?
                .range,
        )
    }
}

/// A read of a `history` resource before the frame writes it: it sees the previous frame.
#[derive(Clone, Debug, Serialize)]
pub struct HistoryRead {
    pub pass: MPass,
    pub resource: MResource,
}

#[derive(Debug)]
pub struct PassGraph {
    pub graph: DiGraph<MPass, Edge>,
    /// Node of each pass (node index == pass index; kept for clarity at call sites).
    pub nodes: Vec<NodeIndex>,
    pub history_reads: Vec<HistoryRead>,
    /// The last writer of each unit at the end of the frame (for culling).
    final_writers: Vec<OptPass>,
}

/// A cycle in the pass graph: the passes on it, and the resources whose hazards close it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the pass graph has a cycle: {}: {}", passes.join(" -> "), steps.join("; "))]
pub struct CycleError {
    /// The passes around the cycle, the first repeated at the end.
    pub passes: Vec<String>,
    pub resources: Vec<String>,
    /// Why each pass must follow the one before it (data hazard, queue order or fence, with
    /// the JSON path of the wait).
    pub steps: Vec<String>,
}

/// The end of a list of readers in the arena (an arena position, not a pass).
const END: u32 = u32::MAX;

pub fn build(model: &FrameModel, units: &Units) -> PassGraph {
    let n = model.passes.len();
    let mut last_writer: Vec<OptPass> = vec![OptPass::NONE; units.total];
    // Readers since the last write, per unit, as linked lists in one arena (no allocation per
    // unit): head index per unit, then (pass, next) entries.
    let mut reader_head: Vec<u32> = vec![END; units.total];
    let mut reader_arena: Vec<(MPass, u32)> = Vec::with_capacity(units.use_count());
    let mut history_reads = Vec::new();
    // One resource's hazards in one pass as (from, kind, access index); the edge keeps the
    // range of the first access of the pass that has the hazard.
    let mut found: Vec<(MPass, EdgeKind, FirstAccess)> = Vec::new();
    // Hazard edges are added as found; most uses of a unit add about one.
    let mut graph: DiGraph<MPass, Edge> =
        DiGraph::with_capacity(n, units.use_count() + n + model.fences.len());
    let nodes: Vec<NodeIndex> = MPass::range(n).map(|p| graph.add_node(p)).collect();
    let mut last_on_queue: Vec<Option<MPass>> = vec![None; model.queues.len()];

    for (p, pass) in model.passes.iter().enumerate() {
        let p = MPass::new(p);
        let last = last_on_queue.get_mut(pass.queue.index());
        if let Some(prev) = last.and_then(|l| l.replace(p)) {
            graph.add_edge(
                nodes[prev.index()],
                nodes[p.index()],
                Edge {
                    kind: EdgeKind::Queue,
                    resource: None,
                    access: None,
                },
            );
        }
        for a in &pass.accesses {
            if let Some(of) = model.resources[a.resource.index()].previous_of {
                history_reads.push(HistoryRead {
                    pass: p,
                    resource: of,
                });
            }
        }
        let uses = units.uses(p);
        // Each unit appears once per pass, and the state below is only updated after all of
        // the pass's uses, so a read-modify-write is one use. A resource's units are adjacent,
        // so one hazard found on several of them is deduplicated within that group.
        let mut group = 0;
        while group < uses.len() {
            let resource = uses[group].resource;
            let mut end = group + 1;
            while end < uses.len() && uses[end].resource == resource {
                end += 1;
            }
            found.clear();
            for u in &uses[group..end] {
                let unit = u.unit.index();
                if let Some(w) = last_writer[unit].get() {
                    if u.reads {
                        found.push((w, EdgeKind::Raw, u.first_read));
                    }
                    if u.writes {
                        found.push((w, EdgeKind::Waw, u.first_write));
                    }
                }
                if u.writes {
                    let mut cursor = reader_head[unit];
                    while cursor != END {
                        let (reader, next) = reader_arena[cursor as usize];
                        found.push((reader, EdgeKind::War, u.first_write));
                        cursor = next;
                    }
                }
            }
            if end - group > 1 {
                // Sorting by access index last keeps the earliest access of each hazard.
                found.sort_unstable();
                found.dedup_by_key(|e| (e.0, e.1));
            }
            for &(from, kind, access) in &found {
                graph.add_edge(
                    nodes[from.index()],
                    nodes[p.index()],
                    Edge {
                        kind,
                        resource: Some(resource),
                        access: access.get(),
                    },
                );
            }
            group = end;
        }
        for u in uses {
            let unit = u.unit.index();
            if u.writes {
                last_writer[unit] = OptPass::some(p);
                reader_head[unit] = END;
            } else if u.reads {
                reader_arena.push((p, reader_head[unit]));
                reader_head[unit] = (reader_arena.len() - 1) as u32;
            }
        }
    }

    for &(from, to) in &model.fences {
        graph.add_edge(
            nodes[from.index()],
            nodes[to.index()],
            Edge {
                kind: EdgeKind::Fence,
                resource: None,
                access: None,
            },
        );
    }
    PassGraph {
        graph,
        nodes,
        history_reads,
        final_writers: last_writer,
    }
}

/// A topological order; among ready passes the earliest recorded goes first, so each queue's
/// recorded order is kept (queue edges force it) and the result is deterministic.
pub fn order(model: &FrameModel, g: &PassGraph) -> Result<Vec<MPass>, CycleError> {
    match recorded_order(model) {
        Some(order) => Ok(order),
        None => topological_order(model, g),
    }
}

/// The recorded order, when it is the order `order` picks, which is known without the graph:
/// hazard and queue edges always run from an earlier recorded pass to a later one, so only a
/// declared fence can point backwards. With none doing so every edge points forward, the
/// earliest recorded ready pass is always the next one, and the order is the recorded order.
pub fn recorded_order(model: &FrameModel) -> Option<Vec<MPass>> {
    model
        .fences
        .iter()
        .all(|&(signal, wait)| signal < wait)
        .then(|| MPass::range(model.passes.len()).collect())
}

/// Kahn's algorithm with the earliest recorded ready pass first.
pub fn topological_order(model: &FrameModel, g: &PassGraph) -> Result<Vec<MPass>, CycleError> {
    let n = model.passes.len();
    let mut indegree = vec![0u32; n];
    for e in g.graph.edge_references() {
        indegree[e.target().index()] += 1;
    }
    let mut ready: BinaryHeap<Reverse<MPass>> = MPass::range(n)
        .filter(|&p| indegree[p.index()] == 0)
        .map(Reverse)
        .collect();
    let mut out = Vec::with_capacity(n);
    while let Some(Reverse(p)) = ready.pop() {
        out.push(p);
        for e in g.graph.edges(g.nodes[p.index()]) {
            let t = e.target().index();
            indegree[t] -= 1;
            if indegree[t] == 0 {
                ready.push(Reverse(MPass::new(t)));
            }
        }
    }
    if out.len() == n {
        return Ok(out);
    }
    Err(find_cycle(model, g, &indegree))
}

/// Walks backwards from a pass left with unmet dependencies until a pass repeats.
fn find_cycle(model: &FrameModel, g: &PassGraph, indegree: &[u32]) -> CycleError {
    let start = indegree.iter().position(|&d| d > 0).unwrap_or(0);
    // Walk incoming edges backwards from a pass left with dependencies until a pass repeats.
    let mut path: Vec<usize> = vec![start];
    let mut via: Vec<(EdgeKind, Option<MResource>)> = Vec::new();
    let mut seen = vec![usize::MAX; model.passes.len()];
    seen[start] = 0;
    let mut current = start;
    loop {
        let incoming = g
            .graph
            .edges_directed(g.nodes[current], petgraph::Direction::Incoming)
            .filter(|e| indegree[e.source().index()] > 0)
            .min_by_key(|e| (e.source().index(), e.weight().kind, e.weight().resource));
        let Some(e) = incoming else { break };
        let prev = e.source().index();
        via.push((e.weight().kind, e.weight().resource));
        if seen[prev] != usize::MAX {
            let from = seen[prev];
            // Forward order: prev (= path[from]) -> path[last] -> ... -> path[from]; the edge
            // into path[k] from path[k+1] is via[k], the edge into path[last] is the last one.
            let mut nodes = vec![MPass::new(prev)];
            let mut edges = Vec::new();
            for k in (from..path.len()).rev() {
                nodes.push(MPass::new(path[k]));
                edges.push(via[k]);
            }
            return describe_cycle(model, &nodes, &edges);
        }
        seen[prev] = path.len();
        path.push(prev);
        current = prev;
    }
    CycleError {
        passes: vec![model.passes[start].name.clone()],
        resources: Vec::new(),
        steps: Vec::new(),
    }
}

/// A cycle `nodes[0] -> nodes[1] -> ... -> nodes[0]` with the edge into each `nodes[i + 1]`.
fn describe_cycle(
    model: &FrameModel,
    nodes: &[MPass],
    edges: &[(EdgeKind, Option<MResource>)],
) -> CycleError {
    let name = |p: MPass| model.passes[p.index()].name.as_str();
    let resource =
        |r: Option<MResource>| r.map_or("?", |r| model.resources[r.index()].name.as_str());
    let steps = nodes
        .windows(2)
        .zip(edges)
        .map(|(w, &(kind, r))| {
            let (a, b) = (w[0], w[1]);
            match kind {
                EdgeKind::Raw => format!(
                    "{} reads {}, which {} writes",
                    name(b),
                    resource(r),
                    name(a)
                ),
                EdgeKind::War => format!(
                    "{} writes {}, which {} reads",
                    name(b),
                    resource(r),
                    name(a)
                ),
                EdgeKind::Waw => format!("{} writes {} after {}", name(b), resource(r), name(a)),
                EdgeKind::Queue => format!(
                    "{} follows {} on queue {}",
                    name(b),
                    name(a),
                    model
                        .queues
                        .get(model.passes[b.index()].queue.index())
                        .map_or("?", |q| q.name.as_str())
                ),
                EdgeKind::Fence => format!(
                    "{} waits on a fence {} signals ($.passes[{}].wait)",
                    name(b),
                    name(a),
                    model.passes[b.index()].id.index()
                ),
            }
        })
        .collect();
    let mut resources: Vec<String> = edges
        .iter()
        .filter_map(|&(_, r)| r.map(|r| model.resources[r.index()].name.clone()))
        .collect();
    resources.sort();
    resources.dedup();
    CycleError {
        passes: nodes.iter().map(|&p| name(p).to_owned()).collect(),
        resources,
        steps,
    }
}

/// Passes whose writes never reach a frame output: not a sink (present), not the final writer
/// of an output or history resource, and not read (transitively) by a pass that is.
pub fn culled(model: &FrameModel, units: &Units, g: &PassGraph) -> Vec<MPass> {
    let n = model.passes.len();
    let mut live = vec![false; n];
    let mut stack: Vec<MPass> = Vec::new();
    for (p, pass) in model.passes.iter().enumerate() {
        if pass.sink {
            live[p] = true;
            stack.push(MPass::new(p));
        }
    }
    for (r, res) in model.resources.iter().enumerate() {
        if res.output || res.history {
            for u in units.span(MResource::new(r)) {
                if let Some(w) = g.final_writers[u].get()
                    && !live[w.index()]
                {
                    live[w.index()] = true;
                    stack.push(w);
                }
            }
        }
    }
    while let Some(p) = stack.pop() {
        for e in g
            .graph
            .edges_directed(g.nodes[p.index()], petgraph::Direction::Incoming)
        {
            let s = e.source().index();
            if e.weight().kind == EdgeKind::Raw && !live[s] {
                live[s] = true;
                stack.push(MPass::new(s));
            }
        }
    }
    MPass::range(n).filter(|&p| !live[p.index()]).collect()
}

/// The model without the given passes (for `--cull`); fences touching them are dropped.
pub fn without_passes(model: &FrameModel, drop: &[MPass]) -> FrameModel {
    let mut keep_index = vec![None; model.passes.len()];
    let mut passes = Vec::new();
    for (i, p) in model.passes.iter().enumerate() {
        if !drop.contains(&MPass::new(i)) {
            keep_index[i] = Some(MPass::new(passes.len()));
            passes.push(p.clone());
        }
    }
    let fences = model
        .fences
        .iter()
        .filter_map(|&(a, b)| Some((keep_index[a.index()]?, keep_index[b.index()]?)))
        .collect();
    FrameModel {
        queues: model.queues.clone(),
        resources: model.resources.clone(),
        passes,
        fences,
        heap_tier: model.heap_tier,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::model::*;
    use crate::capture::format::{HeapType, QueueType};
    use crate::capture::model::ResourceCategory;

    pub(crate) fn texture(name: &str, mips: u32) -> ModelResource {
        ModelResource {
            id: crate::capture::model::ResourceId(0),
            name: name.into(),
            is_buffer: false,
            mips,
            layers: 1,
            buffer_bytes: 0,
            aligned_bytes: 65536,
            alignment: 65536,
            heap_type: HeapType::Default,
            category: ResourceCategory::RtDsTexture,
            history: false,
            output: false,
            swapchain: false,
            initialised: false,
            initial_state: State::COMMON,
            previous_of: None,
        }
    }

    fn access(resource: u32, mip: u32, state: State, reads: bool, writes: bool) -> ModelAccess {
        ModelAccess {
            resource: MResource(resource),
            range: Subresources {
                mip_base: mip,
                mip_count: 1,
                layer_base: 0,
                layer_count: 1,
                byte_offset: 0,
                byte_size: 0,
            },
            state,
            reads,
            writes,
            uav: state == State::UNORDERED_ACCESS,
        }
    }

    fn pass(name: &str, queue: u32, accesses: Vec<ModelAccess>) -> ModelPass {
        ModelPass {
            id: crate::capture::model::PassId(0),
            name: name.into(),
            queue: MQueue(queue),
            accesses,
            raster: queue == 0,
            sink: false,
            gpu_ns: None,
            markers: vec![],
        }
    }

    fn model(resources: Vec<ModelResource>, passes: Vec<ModelPass>) -> FrameModel {
        FrameModel {
            queues: vec![
                QueueInfo {
                    name: "gfx".into(),
                    queue_type: QueueType::Graphics,
                },
                QueueInfo {
                    name: "async".into(),
                    queue_type: QueueType::Compute,
                },
            ],
            resources,
            passes,
            fences: vec![],
            heap_tier: 2,
        }
    }

    fn data_edges(g: &PassGraph) -> Vec<(usize, usize, EdgeKind)> {
        let mut v: Vec<_> = g
            .graph
            .edge_references()
            .filter(|e| e.weight().kind.is_data())
            .map(|e| (e.source().index(), e.target().index(), e.weight().kind))
            .collect();
        v.sort();
        v
    }

    #[test]
    fn hazards_per_subresource() {
        // a writes mip 0, b writes mip 1, c reads mip 0, d writes mip 0.
        let m = model(
            vec![texture("t", 2)],
            vec![
                pass(
                    "a",
                    0,
                    vec![access(0, 0, State::RENDER_TARGET, false, true)],
                ),
                pass(
                    "b",
                    1,
                    vec![access(0, 1, State::UNORDERED_ACCESS, false, true)],
                ),
                pass(
                    "c",
                    1,
                    vec![access(0, 0, State::NON_PIXEL_SHADER_RESOURCE, true, false)],
                ),
                pass(
                    "d",
                    0,
                    vec![access(0, 0, State::RENDER_TARGET, false, true)],
                ),
            ],
        );
        let units = Units::new(&m);
        let g = build(&m, &units);
        assert_eq!(
            data_edges(&g),
            vec![
                (0, 2, EdgeKind::Raw),
                (0, 3, EdgeKind::Waw),
                (2, 3, EdgeKind::War)
            ],
            "b touches only mip 1 and has no data edge"
        );
        assert_eq!(order(&m, &g).unwrap(), MPass::range(4).collect::<Vec<_>>());
    }

    #[test]
    fn history_reads_add_no_edge() {
        let mut t = texture("taa", 1);
        t.history = true;
        let mut m = model(
            vec![t],
            vec![
                pass(
                    "taa",
                    0,
                    vec![access(0, 0, State::PIXEL_SHADER_RESOURCE, true, false)],
                ),
                pass(
                    "resolve",
                    0,
                    vec![access(0, 0, State::RENDER_TARGET, false, true)],
                ),
                pass(
                    "blur",
                    1,
                    vec![access(0, 0, State::NON_PIXEL_SHADER_RESOURCE, true, false)],
                ),
            ],
        );
        m.split_history();
        assert_eq!(m.resources[1].name, "taa (previous frame)");
        let units = Units::new(&m);
        let g = build(&m, &units);
        assert_eq!(g.history_reads.len(), 1);
        assert_eq!(data_edges(&g), vec![(1, 2, EdgeKind::Raw)]);
    }

    #[test]
    fn cycles_name_passes_and_resources() {
        let mut m = model(
            vec![texture("shared", 1)],
            vec![
                pass(
                    "producer",
                    1,
                    vec![access(0, 0, State::UNORDERED_ACCESS, false, true)],
                ),
                pass(
                    "consumer",
                    0,
                    vec![access(0, 0, State::PIXEL_SHADER_RESOURCE, true, false)],
                ),
            ],
        );
        m.fences.push((MPass(1), MPass(0))); // producer waits on the consumer: impossible.
        let units = Units::new(&m);
        let g = build(&m, &units);
        let err = order(&m, &g).unwrap_err();
        assert!(
            err.passes.contains(&"producer".to_owned())
                && err.passes.contains(&"consumer".to_owned()),
            "{err}"
        );
        assert_eq!(err.resources, vec!["shared".to_owned()]);
    }

    #[test]
    fn a_fence_pointing_back_reorders() {
        let mut m = model(
            vec![texture("a", 1), texture("b", 1)],
            vec![
                pass(
                    "late",
                    0,
                    vec![access(0, 0, State::RENDER_TARGET, false, true)],
                ),
                pass(
                    "early",
                    1,
                    vec![access(1, 0, State::UNORDERED_ACCESS, false, true)],
                ),
            ],
        );
        m.fences.push((MPass(1), MPass(0)));
        assert_eq!(recorded_order(&m), None);
        let units = Units::new(&m);
        let g = build(&m, &units);
        assert_eq!(order(&m, &g).unwrap(), vec![MPass(1), MPass(0)]);
    }

    #[test]
    fn culling_keeps_what_reaches_outputs() {
        let mut out = texture("out", 1);
        out.output = true;
        let m = model(
            vec![texture("a", 1), texture("dead", 1), out],
            vec![
                pass(
                    "make_a",
                    0,
                    vec![access(0, 0, State::RENDER_TARGET, false, true)],
                ),
                pass(
                    "dead_pass",
                    0,
                    vec![access(1, 0, State::RENDER_TARGET, false, true)],
                ),
                pass(
                    "final",
                    0,
                    vec![
                        access(0, 0, State::PIXEL_SHADER_RESOURCE, true, false),
                        access(2, 0, State::RENDER_TARGET, false, true),
                    ],
                ),
            ],
        );
        let units = Units::new(&m);
        let g = build(&m, &units);
        assert_eq!(culled(&m, &units, &g), vec![MPass(1)]);
    }
}
