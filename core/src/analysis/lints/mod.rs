//! Lints: the warnings a frame debugger gives (PIX's "remove ALLOW_UNORDERED_ACCESS", unused
//! results, missing or redundant barriers) with stable codes, a severity, and the pass and
//! resource they are about. Rules read the validated capture for flags, formats and descriptor
//! heaps, and the analysis results for order, culling, barriers and fences. Each rule is a file
//! of this folder holding its kinds (code, name, severity, description) and its check; `RULES`
//! lists them.

use std::collections::BTreeSet;

use serde::Serialize;

mod anisotropic;
mod dead_passes;
mod depth_read_only;
mod descriptor_heaps;
mod fix;
mod missing_fences;
mod passes_could_merge;
mod read_before_write;
mod recorded;
mod redundant_copies;
mod typeless;
mod unused_channels;
mod unused_flags;
mod unused_mips;
mod upload_heap;
mod vulkan;
mod written_never_read;

pub use fix::Fix;
pub use passes_could_merge::{Unordered, conflict, unordered_inside};

use super::barriers::BarrierPlan;
use super::graph::PassGraph;
use super::model::{FrameModel, MPass, MResource};
use crate::capture::model::{Capture, PassDesc, PassId, ResourceAccess, ResourceId};

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LintSeverity {
    Error,
    Warning,
    Info,
}

/// A kind of finding: its stable code, short name, severity and description. Each rule's file
/// defines its kinds.
#[derive(Debug)]
pub struct LintDef {
    pub code: &'static str,
    pub name: &'static str,
    pub severity: LintSeverity,
    pub description: &'static str,
}

/// A kind of finding, compared and ordered by its code.
#[derive(Clone, Copy, Debug)]
pub struct LintKind(&'static LintDef);

impl LintKind {
    pub const fn new(def: &'static LintDef) -> Self {
        LintKind(def)
    }
    /// Every lint, in code order (the catalogue reports list).
    pub fn all() -> Vec<LintKind> {
        let mut all: Vec<LintKind> = RULES.iter().flat_map(|r| r.kinds()).copied().collect();
        all.sort();
        all
    }
    /// Stable code, e.g. `FL001`.
    pub fn code(self) -> &'static str {
        self.0.code
    }
    /// Short name, e.g. `unused-uav-flag`.
    pub fn name(self) -> &'static str {
        self.0.name
    }
    pub fn severity(self) -> LintSeverity {
        self.0.severity
    }
    /// What the lint finds.
    pub fn description(self) -> &'static str {
        self.0.description
    }
}

impl PartialEq for LintKind {
    fn eq(&self, other: &Self) -> bool {
        self.0.code == other.0.code
    }
}

impl Eq for LintKind {}

impl PartialOrd for LintKind {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for LintKind {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.code.cmp(other.0.code)
    }
}

impl std::hash::Hash for LintKind {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.code.hash(state);
    }
}

/// One lint rule: the kinds of finding it makes and its check, in a file of its own. A new
/// lint is that file and a line in `RULES`.
trait Rule: Sync {
    fn kinds(&self) -> &'static [LintKind];
    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>);
}

/// Every rule, in the order they run (their findings are sorted afterwards).
const RULES: &[&dyn Rule] = &[
    &unused_flags::UnusedFlags,
    &written_never_read::WrittenNeverRead,
    &dead_passes::DeadPasses,
    &read_before_write::ReadBeforeWrite,
    &redundant_copies::RedundantCopies,
    &typeless::TypelessWithoutView,
    &depth_read_only::DepthCouldBeReadOnly,
    &descriptor_heaps::DescriptorHeaps,
    &unused_channels::UnusedChannels,
    &unused_mips::UnusedMips,
    &missing_fences::MissingFences,
    &upload_heap::UploadHeapReads,
    &anisotropic::AnisotropicWithoutMips,
    &passes_could_merge::PassesCouldMerge,
    &recorded::RecordedBarriers,
    &vulkan::VulkanBarriers,
];

/// One finding, about a capture pass and/or resource (ids; reports name them).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Lint {
    pub kind: LintKind,
    pub message: String,
    pub pass: Option<PassId>,
    pub resource: Option<ResourceId>,
    /// The specification's valid-usage ID the finding breaks, where it has one.
    pub vuid: Option<String>,
    /// The change to the frame the advice amounts to, where it is one.
    pub fix: Option<Fix>,
}

fn lint(
    kind: LintKind,
    message: String,
    pass: Option<PassId>,
    resource: Option<ResourceId>,
) -> Lint {
    Lint {
        kind,
        message,
        pass,
        resource,
        vuid: None,
        fix: None,
    }
}

#[derive(Debug)]
pub struct LintInput<'a> {
    pub capture: &'a Capture,
    pub model: &'a FrameModel,
    pub graph: &'a PassGraph,
    pub order: &'a [MPass],
    pub culled: &'a [MPass],
    pub plan: &'a BarrierPlan,
}

/// The inputs every rule reads.
#[derive(Clone, Copy)]
struct Linter<'a> {
    capture: &'a Capture,
    model: &'a FrameModel,
    graph: &'a PassGraph,
    order: &'a [MPass],
    culled: &'a [MPass],
    plan: &'a BarrierPlan,
    in_order: &'a BTreeSet<PassId>,
    /// Per resource (by index), every pass's accesses of it with the pass, in capture order:
    /// built once so that per-resource rules cost the accesses' number, not resources x
    /// passes.
    uses: &'a [Vec<(&'a PassDesc, &'a ResourceAccess)>],
}
impl<'a> Linter<'a> {
    /// The frame came from a Vulkan program: advice names usage flags, layouts and memory
    /// properties, not D3D12's flags, states and heaps.
    fn vulkan_terms(&self) -> bool {
        self.capture.from_vulkan_program()
    }

    /// The capture pass a model pass is.
    fn capture_pass(&self, p: MPass) -> &'a PassDesc {
        self.capture.pass(self.model.passes[p.index()].id)
    }

    /// The model resource a capture resource is: lints read the whole frame's model, where
    /// every capture resource keeps its index (previous-frame copies come after them).
    fn model_resource(id: ResourceId) -> MResource {
        MResource::new(id.index())
    }

    /// The accesses of resource `r` by the passes that run, with their pass.
    fn uses_of(
        &self,
        r: ResourceId,
    ) -> impl Iterator<Item = (&'a PassDesc, &'a ResourceAccess)> + 'a {
        let in_order = self.in_order;
        self.uses
            .get(r.index())
            .into_iter()
            .flatten()
            .copied()
            .filter(move |(p, _)| in_order.contains(&p.id))
    }
}

pub fn lints(input: &LintInput<'_>) -> Vec<Lint> {
    let in_order: BTreeSet<PassId> = input
        .order
        .iter()
        .map(|p| input.model.passes[p.index()].id)
        .collect();
    let mut uses: Vec<Vec<(&PassDesc, &ResourceAccess)>> =
        vec![Vec::new(); input.capture.resources.len()];
    for p in &input.capture.passes {
        for a in &p.accesses {
            if let Some(list) = uses.get_mut(a.resource.index()) {
                list.push((p, a));
            }
        }
    }
    let linter = Linter {
        capture: input.capture,
        model: input.model,
        graph: input.graph,
        order: input.order,
        culled: input.culled,
        plan: input.plan,
        in_order: &in_order,
        uses: &uses,
    };
    let mut out = Vec::new();
    for rule in RULES {
        rule.check(&linter, &mut out);
    }
    out.sort();
    out.dedup();
    out
}
