//! Lints: the warnings a frame debugger gives (PIX's "remove ALLOW_UNORDERED_ACCESS", unused
//! results, missing or redundant barriers) with stable codes, a severity, and the pass and
//! resource they are about. Rules read the validated capture for flags, formats and descriptor
//! heaps, and the analysis results for order, culling, barriers and fences.

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

mod fix;
mod recorded;
mod vulkan;

pub use fix::Fix;

use super::barriers::BarrierPlan;
use super::graph::{EdgeKind, PassGraph};
use super::model::{FrameModel, MPass, MResource};
use crate::capture::format::{Access, DescriptorHeapType, LoadOp, ResourceFlag};
use crate::capture::model::{BindingTarget, Capture, PassDesc, PassId, ResourceAccess, ResourceId};
use recorded::compare_recorded;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LintSeverity {
    Error,
    Warning,
    Info,
}

/// Every lint framelab knows, with its stable code, short name, severity and description.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum LintKind {
    /// ALLOW_UNORDERED_ACCESS on a resource never bound as a UAV
    UnusedUavFlag,
    /// ALLOW_RENDER_TARGET on a resource never rendered to
    UnusedRenderTargetFlag,
    /// ALLOW_DEPTH_STENCIL on a resource never bound as depth
    UnusedDepthStencilFlag,
    /// a resource written and never read (and not a frame output)
    WrittenNeverRead,
    /// a pass whose writes never reach a frame output
    PassWithoutEffect,
    /// a read of contents nothing wrote (no initial contents, not history)
    ReadBeforeWrite,
    /// a copy whose result is never read, or that repeats an identical copy
    RedundantCopy,
    /// a TYPELESS resource no pass views with a typed format
    TypelessWithoutTypedView,
    /// depth bound writable by a pass that only tests it: bind it read-only (DEPTH_READ)
    DepthCouldBeReadOnly,
    /// more descriptors needed than a descriptor heap holds, or no heap of a needed type
    DescriptorHeapCapacity,
    /// every write masks off channels: a format with fewer channels would do
    UnusedChannels,
    /// mip levels no pass touches
    UnusedMips,
    /// a resource no pass touches
    UnusedResource,
    /// a cross-queue dependency no fence orders
    MissingFence,
    /// a resource in an UPLOAD heap read by several passes: copy it to a DEFAULT heap
    UploadHeapReadOften,
    /// a texture with one mip sampled through an anisotropic sampler
    AnisotropicWithoutMips,
    /// a transition or UAV barrier the frame needs was not recorded
    BarrierMissing,
    /// a recorded barrier the frame does not need
    BarrierRedundant,
    /// a recorded barrier covers more subresources or states than needed
    BarrierOverBroad,
    /// a recorded barrier could be split (begin after the last use, end before the next)
    BarrierCouldSplit,
    /// a recorded transition names a before-state the resource is not in
    BarrierWrongBeforeState,
    /// a call breaks a valid-usage statement of the specification (its VUID given)
    ValidUsage,
}

impl LintKind {
    /// Every lint, in code order (the catalogue reports list).
    pub const ALL: [LintKind; 22] = [
        LintKind::UnusedUavFlag,
        LintKind::UnusedRenderTargetFlag,
        LintKind::UnusedDepthStencilFlag,
        LintKind::WrittenNeverRead,
        LintKind::PassWithoutEffect,
        LintKind::ReadBeforeWrite,
        LintKind::RedundantCopy,
        LintKind::TypelessWithoutTypedView,
        LintKind::DepthCouldBeReadOnly,
        LintKind::DescriptorHeapCapacity,
        LintKind::UnusedChannels,
        LintKind::UnusedMips,
        LintKind::UnusedResource,
        LintKind::MissingFence,
        LintKind::UploadHeapReadOften,
        LintKind::AnisotropicWithoutMips,
        LintKind::BarrierMissing,
        LintKind::BarrierRedundant,
        LintKind::BarrierOverBroad,
        LintKind::BarrierCouldSplit,
        LintKind::BarrierWrongBeforeState,
        LintKind::ValidUsage,
    ];

    fn row(self) -> (&'static str, &'static str, LintSeverity, &'static str) {
        match self {
            LintKind::UnusedUavFlag => (
                "FL001",
                "unused-uav-flag",
                LintSeverity::Warning,
                "ALLOW_UNORDERED_ACCESS on a resource never bound as a UAV",
            ),
            LintKind::UnusedRenderTargetFlag => (
                "FL002",
                "unused-render-target-flag",
                LintSeverity::Warning,
                "ALLOW_RENDER_TARGET on a resource never rendered to",
            ),
            LintKind::UnusedDepthStencilFlag => (
                "FL003",
                "unused-depth-stencil-flag",
                LintSeverity::Warning,
                "ALLOW_DEPTH_STENCIL on a resource never bound as depth",
            ),
            LintKind::WrittenNeverRead => (
                "FL004",
                "written-never-read",
                LintSeverity::Warning,
                "a resource written and never read (and not a frame output)",
            ),
            LintKind::PassWithoutEffect => (
                "FL005",
                "pass-without-effect",
                LintSeverity::Warning,
                "a pass whose writes never reach a frame output",
            ),
            LintKind::ReadBeforeWrite => (
                "FL006",
                "read-before-write",
                LintSeverity::Error,
                "a read of contents nothing wrote (no initial contents, not history)",
            ),
            LintKind::RedundantCopy => (
                "FL007",
                "redundant-copy",
                LintSeverity::Warning,
                "a copy whose result is never read, or that repeats an identical copy",
            ),
            LintKind::TypelessWithoutTypedView => (
                "FL008",
                "typeless-without-typed-view",
                LintSeverity::Warning,
                "a TYPELESS resource no pass views with a typed format",
            ),
            LintKind::DepthCouldBeReadOnly => (
                "FL009",
                "depth-could-be-read-only",
                LintSeverity::Info,
                "depth bound writable by a pass that only tests it: bind it read-only (DEPTH_READ)",
            ),
            LintKind::DescriptorHeapCapacity => (
                "FL010",
                "descriptor-heap-capacity",
                LintSeverity::Error,
                "more descriptors needed than a descriptor heap holds, or no heap of a needed type",
            ),
            LintKind::UnusedChannels => (
                "FL011",
                "unused-channels",
                LintSeverity::Info,
                "every write masks off channels: a format with fewer channels would do",
            ),
            LintKind::UnusedMips => (
                "FL012",
                "unused-mips",
                LintSeverity::Info,
                "mip levels no pass touches",
            ),
            LintKind::UnusedResource => (
                "FL013",
                "unused-resource",
                LintSeverity::Warning,
                "a resource no pass touches",
            ),
            LintKind::MissingFence => (
                "FL014",
                "missing-fence",
                LintSeverity::Error,
                "a cross-queue dependency no fence orders",
            ),
            LintKind::UploadHeapReadOften => (
                "FL015",
                "upload-heap-read-often",
                LintSeverity::Info,
                "a resource in an UPLOAD heap read by several passes: copy it to a DEFAULT heap",
            ),
            LintKind::AnisotropicWithoutMips => (
                "FL016",
                "anisotropic-without-mips",
                LintSeverity::Warning,
                "a texture with one mip sampled through an anisotropic sampler",
            ),
            LintKind::BarrierMissing => (
                "FL020",
                "barrier-missing",
                LintSeverity::Error,
                "a transition or UAV barrier the frame needs was not recorded",
            ),
            LintKind::BarrierRedundant => (
                "FL021",
                "barrier-redundant",
                LintSeverity::Warning,
                "a recorded barrier the frame does not need",
            ),
            LintKind::BarrierOverBroad => (
                "FL022",
                "barrier-over-broad",
                LintSeverity::Warning,
                "a recorded barrier covers more subresources or states than needed",
            ),
            LintKind::BarrierCouldSplit => (
                "FL023",
                "barrier-could-split",
                LintSeverity::Info,
                "a recorded barrier could be split (begin after the last use, end before the next)",
            ),
            LintKind::BarrierWrongBeforeState => (
                "FL024",
                "barrier-wrong-before-state",
                LintSeverity::Error,
                "a recorded transition names a before-state the resource is not in",
            ),
            LintKind::ValidUsage => (
                "FL025",
                "valid-usage",
                LintSeverity::Error,
                "a call breaks a valid-usage statement of the specification (its VUID given)",
            ),
        }
    }
    /// Stable code, e.g. `FL001`.
    pub fn code(self) -> &'static str {
        self.row().0
    }
    /// Short name, e.g. `unused-uav-flag`.
    pub fn name(self) -> &'static str {
        self.row().1
    }
    pub fn severity(self) -> LintSeverity {
        self.row().2
    }
    /// What the lint finds.
    pub fn description(self) -> &'static str {
        self.row().3
    }
}

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

    /// Flags never used.
    fn unused_flags(&self, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *self;
        for r in &capture.resources {
            let uses: Vec<Access> = self.uses_of(r.id).map(|(_, a)| a.access).collect();
            if uses.is_empty() {
                if r.swapchain {
                    continue;
                }
                out.push(lint(
                    LintKind::UnusedResource,
                    format!("\"{}\" is declared but no pass uses it", r.name),
                    None,
                    Some(r.id),
                ));
                continue;
            }
            let checks = [
                (
                    ResourceFlag::AllowUnorderedAccess,
                    LintKind::UnusedUavFlag,
                    uses.iter().any(|a| a.is_unordered(r.is_texture())),
                    "bound as an unordered-access view",
                ),
                (
                    ResourceFlag::AllowRenderTarget,
                    LintKind::UnusedRenderTargetFlag,
                    uses.contains(&Access::ColorAttachment),
                    "rendered to",
                ),
                (
                    ResourceFlag::AllowDepthStencil,
                    LintKind::UnusedDepthStencilFlag,
                    uses.iter()
                        .any(|a| matches!(a, Access::DepthRead | Access::DepthWrite)),
                    "bound as depth-stencil",
                ),
            ];
            for (flag, code, used, how) in checks {
                if r.has_flag(flag) && !used {
                    let message = if self.vulkan_terms() {
                        let (usage, how) = match flag {
                            ResourceFlag::AllowRenderTarget => ("COLOR_ATTACHMENT", how),
                            ResourceFlag::AllowDepthStencil => ("DEPTH_STENCIL_ATTACHMENT", how),
                            _ if r.is_texture() => ("STORAGE", "bound as a storage image"),
                            _ => ("STORAGE", "bound as a storage buffer"),
                        };
                        let why = if r.is_texture() {
                            "fewer usage flags let the driver pick a better layout"
                        } else {
                            "the usage flag can go"
                        };
                        format!(
                            "\"{}\" was created with {usage} usage but is never {how}; {why}",
                            r.name
                        )
                    } else {
                        format!(
                            "\"{}\" has {} but is never {how}; removing the flag can enable compression",
                            r.name,
                            flag.name()
                        )
                    };
                    let mut l = lint(code, message, None, Some(r.id));
                    l.fix = Some(Fix::RemoveFlag {
                        resource: r.id,
                        flag,
                    });
                    out.push(l);
                }
            }
        }
    }

    /// Written, never read.
    fn written_never_read(&self, out: &mut Vec<Lint>) {
        let Linter { capture, model, .. } = *self;
        let read_by: BTreeSet<MResource> = model
            .passes
            .iter()
            .flat_map(|p| p.accesses.iter())
            .filter(|a| a.reads)
            .map(|a| {
                model.resources[a.resource.index()]
                    .previous_of
                    .unwrap_or(a.resource)
            })
            .collect();
        for r in &capture.resources {
            let written = self.uses_of(r.id).any(|(_, a)| a.writes);
            if written && !read_by.contains(&Self::model_resource(r.id)) && !r.output && !r.history
            {
                out.push(lint(
                    LintKind::WrittenNeverRead,
                    format!("\"{}\" is written but nothing reads it", r.name),
                    None,
                    Some(r.id),
                ));
            }
        }
    }

    /// Dead passes.
    fn dead_passes(&self, out: &mut Vec<Lint>) {
        let Linter { model, culled, .. } = *self;
        for &p in culled {
            let pass = &model.passes[p.index()];
            let message = if pass.accesses.iter().any(|a| a.writes) {
                format!(
                    "the results of \"{}\" never reach a frame output (use --cull to drop it)",
                    pass.name
                )
            } else {
                format!("\"{}\" writes nothing", pass.name)
            };
            let mut l = lint(LintKind::PassWithoutEffect, message, Some(pass.id), None);
            l.fix = Some(Fix::CullPass { pass: pass.id });
            out.push(l);
        }
    }

    /// Read before anything wrote it, in order.
    fn read_before_write(&self, out: &mut Vec<Lint>) {
        let Linter {
            model,
            order,
            capture,
            ..
        } = *self;
        // An imported storage binding reads only by assumption (no shader code says).
        let assumed_reads = capture.not_replayable().is_some();
        let mut written: BTreeSet<MResource> = BTreeSet::new();
        let mut reported: BTreeSet<MResource> = BTreeSet::new();
        for &p in order {
            let pass = &model.passes[p.index()];
            for a in &pass.accesses {
                let r = &model.resources[a.resource.index()];
                if a.reads
                    && (!assumed_reads || !a.uav || !a.writes)
                    && !written.contains(&a.resource)
                    && !r.initialised
                    && r.previous_of.is_none()
                    && reported.insert(a.resource)
                {
                    out.push(lint(LintKind::ReadBeforeWrite, format!("\"{}\" reads \"{}\" before any pass writes it and it has no initial contents", pass.name, r.name), Some(pass.id), Some(r.id)));
                }
            }
            for a in &pass.accesses {
                if a.writes {
                    written.insert(a.resource);
                }
            }
        }
    }

    /// Copies whose result nobody reads, and repeated identical copies.
    fn redundant_copies(&self, out: &mut Vec<Lint>) {
        let Linter {
            capture,
            model,
            graph,
            order,
            ..
        } = *self;
        let mut seen_copies: BTreeMap<(ResourceId, ResourceId, String), MPass> = BTreeMap::new();
        for &p in order {
            let pass = self.capture_pass(p);
            for (i, c) in pass.copies.iter().enumerate() {
                let dst = c.dst.resource;
                let (src_m, dst_m) = (
                    Self::model_resource(c.src.resource),
                    Self::model_resource(dst),
                );
                let read_later = graph.graph.edges(graph.nodes[p.index()]).any(|e| {
                    e.weight().kind == EdgeKind::Raw && e.weight().resource == Some(dst_m)
                });
                let dst_res = capture.resource(dst);
                if !read_later && !dst_res.output && !dst_res.history {
                    out.push(lint(
                        LintKind::RedundantCopy,
                        format!(
                            "copy {i} of \"{}\" into \"{}\" is never read",
                            pass.name, dst_res.name
                        ),
                        Some(pass.id),
                        Some(dst),
                    ));
                }
                let key = (
                    c.src.resource,
                    dst,
                    format!("{:?}{:?}{:?}", c.src.origin, c.dst.origin, c.extent),
                );
                if let Some(&earlier) = seen_copies.get(&key) {
                    let touched_between = order
                        .iter()
                        .skip_while(|&&q| q != earlier)
                        .skip(1)
                        .take_while(|&&q| q != p)
                        .any(|&q| {
                            model.passes[q.index()]
                                .accesses
                                .iter()
                                .any(|a| a.writes && (a.resource == src_m || a.resource == dst_m))
                        });
                    if !touched_between {
                        out.push(lint(
                            LintKind::RedundantCopy,
                            format!(
                                "\"{}\" repeats the copy \"{}\" made from \"{}\" to \"{}\"",
                                pass.name,
                                self.capture_pass(earlier).name,
                                capture.resource(c.src.resource).name,
                                dst_res.name
                            ),
                            Some(pass.id),
                            Some(dst),
                        ));
                    }
                }
                seen_copies.insert(key, p);
            }
        }
    }

    /// Typeless resources without a typed view.
    fn typeless_without_view(&self, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *self;
        // Resources some pass views with a type: a typed binding view or an attachment.
        let mut typed_views: BTreeSet<ResourceId> = BTreeSet::new();
        for p in &capture.passes {
            for b in &p.bindings {
                if let BindingTarget::Resource {
                    resource,
                    view_format: Some(vf),
                    ..
                } = b.target
                    && !vf.is_typeless()
                {
                    typed_views.insert(resource);
                }
            }
            typed_views.extend(p.color_attachments.iter().map(|c| c.resource));
            typed_views.extend(p.depth_stencil.as_ref().map(|d| d.resource));
        }
        for r in &capture.resources {
            let Some(f) = r.format.filter(|f| f.is_typeless()) else {
                continue;
            };
            let typed_view = typed_views.contains(&r.id);
            let used = self.uses_of(r.id).next().is_some();
            if used && !typed_view {
                out.push(lint(
                    LintKind::TypelessWithoutTypedView,
                    format!(
                        "\"{}\" is {} and no pass views it with a typed format; give it a typed format",
                        r.name, f.name
                    ),
                    None,
                    Some(r.id),
                ));
            }
        }
    }

    /// Depth bound writable but only tested.
    fn depth_could_be_read_only(&self, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *self;
        for &p in order {
            let pass = self.capture_pass(p);
            if let Some(d) = &pass.depth_stencil {
                let access = pass.accesses.iter().find(|a| {
                    a.resource == d.resource
                        && matches!(a.access, Access::DepthRead | Access::DepthWrite)
                });
                // A Vulkan attachment in a writable layout is written by its store operation,
                // so what tells is whether any draw writes depth or stencil.
                let only_tested = if self.vulkan_terms() {
                    d.depth_load != LoadOp::Clear
                        && d.stencil_load != LoadOp::Clear
                        && !pass.draws.iter().any(|w| self.vk_draw_may_write_depth(w))
                } else {
                    access.is_some_and(|a| a.access == Access::DepthRead)
                };
                if !d.read_only && only_tested {
                    let name = &capture.resource(d.resource).name;
                    let message = if self.vulkan_terms() {
                        format!(
                            "\"{}\" attaches \"{name}\" in a writable layout but no draw writes it: a read-only depth layout (DEPTH_STENCIL_READ_ONLY_OPTIMAL) lets other passes sample it meanwhile",
                            pass.name
                        )
                    } else {
                        format!(
                            "\"{}\" binds \"{name}\" writable but never writes it: bind it read_only so it stays in DEPTH_READ",
                            pass.name
                        )
                    };
                    out.push(lint(
                        LintKind::DepthCouldBeReadOnly,
                        message,
                        Some(pass.id),
                        Some(d.resource),
                    ));
                }
            }
        }
    }

    /// Whether an imported draw's pipeline may write depth or stencil: depth writes with the
    /// depth test on, stencil writes with the stencil test on, or either left to dynamic
    /// state (whose values the capture does not keep). A draw with no pipeline known may.
    fn vk_draw_may_write_depth(&self, draw: &crate::capture::model::DrawDesc) -> bool {
        let pipeline = draw.vk.as_ref().and_then(|w| {
            self.capture
                .vulkan
                .as_ref()
                .and_then(|m| m.pipelines.get(w.pipeline))
        });
        let Some(g) = pipeline.and_then(|p| p.graphics.as_deref()) else {
            return true;
        };
        let dynamic = g.dynamic_states.iter().any(|s| {
            s.contains("DEPTH_WRITE_ENABLE")
                || s.contains("DEPTH_TEST_ENABLE")
                || s.contains("STENCIL_OP")
                || s.contains("STENCIL_TEST_ENABLE")
                || s.contains("STENCIL_WRITE_MASK")
        });
        let Some(ds) = &g.depth_stencil else {
            return dynamic;
        };
        let stencil_writes = ds.stencil_test
            && [&ds.front, &ds.back].into_iter().flatten().any(|f| {
                f.write_mask != 0
                    && [&f.fail_op, &f.pass_op, &f.depth_fail_op]
                        .iter()
                        .any(|op| !op.ends_with("KEEP"))
            });
        dynamic || (ds.depth_test && ds.depth_write) || stencil_writes
    }

    /// Descriptor heaps.
    fn descriptor_heaps(&self, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *self;
        let mut needed: BTreeMap<DescriptorHeapType, u64> = BTreeMap::new();
        for &p in order {
            let pass = self.capture_pass(p);
            for b in &pass.bindings {
                let ty = match b.target {
                    BindingTarget::Sampler(_) => DescriptorHeapType::Sampler,
                    BindingTarget::Resource { .. } => DescriptorHeapType::CbvSrvUav,
                };
                *needed.entry(ty).or_default() += 1;
            }
            if pass.shader.is_some() {
                // The frame-constants and per-pass parameter buffers.
                *needed.entry(DescriptorHeapType::CbvSrvUav).or_default() += 2;
            }
            *needed.entry(DescriptorHeapType::Rtv).or_default() +=
                pass.color_attachments.len() as u64;
            *needed.entry(DescriptorHeapType::Dsv).or_default() +=
                u64::from(pass.depth_stencil.is_some());
        }
        for (ty, count) in needed.into_iter().filter(|(_, c)| *c > 0) {
            let name = match ty {
                DescriptorHeapType::CbvSrvUav => "CBV_SRV_UAV",
                DescriptorHeapType::Sampler => "SAMPLER",
                DescriptorHeapType::Rtv => "RTV",
                DescriptorHeapType::Dsv => "DSV",
            };
            let capacity: u64 = capture
                .descriptor_heaps
                .iter()
                .filter(|h| h.heap_type == ty)
                .map(|h| u64::from(h.capacity))
                .sum();
            if capture.descriptor_heaps.is_empty() {
                continue; // A capture without descriptor heaps does not model them.
            }
            if capacity == 0 {
                out.push(lint(
                    LintKind::DescriptorHeapCapacity,
                    format!(
                        "the frame needs {count} {name} descriptors but declares no {name} heap"
                    ),
                    None,
                    None,
                ));
            } else if count > capacity {
                out.push(lint(LintKind::DescriptorHeapCapacity, format!("the frame needs {count} {name} descriptors but its {name} heaps hold {capacity}"), None, None));
            }
        }
    }

    /// Channels masked off in every write.
    fn unused_channels(&self, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *self;
        // Every colour attachment's write mask, by resource.
        let mut all_masks: BTreeMap<ResourceId, Vec<Option<&String>>> = BTreeMap::new();
        for c in capture
            .passes
            .iter()
            .flat_map(|p| p.color_attachments.iter())
        {
            all_masks
                .entry(c.resource)
                .or_default()
                .push(c.write_mask.as_ref());
        }
        for r in &capture.resources {
            let Some(f) = r.format else { continue };
            let channels = f.channels.iter().filter(|c| c.name != 'X').count();
            let masks: &[Option<&String>] = all_masks.get(&r.id).map_or(&[], Vec::as_slice);
            if masks.is_empty()
                || masks.iter().any(Option::is_none)
                || self
                    .uses_of(r.id)
                    .any(|(_, a)| a.writes && a.access != Access::ColorAttachment)
            {
                continue;
            }
            let union: BTreeSet<char> = masks.iter().flatten().flat_map(|m| m.chars()).collect();
            if union.len() < channels {
                let used: String = union.iter().collect();
                out.push(lint(LintKind::UnusedChannels, format!("\"{}\" ({}) is only ever written in channels \"{used}\"; a {}-channel format would do", r.name, f.name, union.len()), None, Some(r.id)));
            }
        }
    }

    /// Mips no pass touches.
    fn unused_mips(&self, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *self;
        for r in capture
            .resources
            .iter()
            .filter(|r| r.is_texture() && r.mip_levels > 1)
        {
            let max_mip = self
                .uses_of(r.id)
                .map(|(_, a)| a.range.mip_base + a.range.mip_count)
                .max();
            if let Some(used) = max_mip.filter(|&m| m < r.mip_levels) {
                out.push(lint(
                    LintKind::UnusedMips,
                    format!(
                        "\"{}\" has {} mips but passes use only the first {used}",
                        r.name, r.mip_levels
                    ),
                    None,
                    Some(r.id),
                ));
            }
        }
    }

    /// Fences the frame lacks.
    fn missing_fences(&self, out: &mut Vec<Lint>) {
        let Linter { model, plan, .. } = *self;
        for f in plan.fences.iter().filter(|f| !f.declared) {
            let (a, b) = (
                &model.passes[f.signal_after.index()],
                &model.passes[f.wait_before.index()],
            );
            out.push(lint(
                LintKind::MissingFence,
                format!(
                    "\"{}\" (queue {}) must wait for \"{}\" (queue {}), but no fence orders them",
                    b.name,
                    model.queues[b.queue.index()].name,
                    a.name,
                    model.queues[a.queue.index()].name
                ),
                Some(b.id),
                None,
            ));
        }
    }

    /// Upload-heap resources read by several passes.
    fn upload_heap_reads(&self, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *self;
        for r in &capture.resources {
            if r.heap_type(&capture.heaps) == crate::capture::format::HeapType::Upload {
                let readers: BTreeSet<u32> = self
                    .uses_of(r.id)
                    .filter(|(_, a)| a.reads)
                    .map(|(p, _)| p.id.0)
                    .collect();
                if readers.len() >= 2 {
                    let (from, to) = if self.vulkan_terms() {
                        ("host-visible memory", "DEVICE_LOCAL memory")
                    } else {
                        ("an UPLOAD heap", "a DEFAULT heap")
                    };
                    out.push(lint(
                        LintKind::UploadHeapReadOften,
                        format!(
                            "\"{}\" lives in {from} and {} passes read it across the bus; copy it to {to} once",
                            r.name,
                            readers.len()
                        ),
                        None,
                        Some(r.id),
                    ));
                }
            }
        }
    }
}

impl Linter<'_> {
    /// Anisotropic filtering picks among mips along the footprint's long axis; a texture with
    /// one mip leaves it only taps of the full-size level, as many as the footprint is long.
    /// Small or thin primitives then cost seconds per draw on software rasterizers (llvmpipe
    /// spent minutes on one frame of the example this way), and the result still aliases.
    fn anisotropic_without_mips(&self, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *self;
        for &p in order {
            let pass = self.capture_pass(p);
            let Some(shader) = &pass.shader else { continue };
            let interface = &capture.shader(shader.id).interface;
            let entries = [&shader.vertex, &shader.fragment, &shader.compute]
                .into_iter()
                .flatten()
                .chain(pass.draws.iter().filter_map(|d| d.vertex.as_ref()))
                .chain(pass.draws.iter().filter_map(|d| d.fragment.as_ref()))
                .chain(pass.dispatches.iter().filter_map(|d| d.entry.as_ref()));
            let pairs: BTreeSet<&(String, String)> = entries
                .filter_map(|e| interface.entry_points.get(e))
                .flat_map(|e| e.sampling.iter())
                .collect();
            let bound = |variable: &str| pass.bindings.iter().find(|b| b.variable == variable);
            for (texture, sampler) in pairs {
                let (Some(t), Some(s)) = (bound(texture), bound(sampler)) else {
                    continue;
                };
                let (BindingTarget::Resource { resource, .. }, BindingTarget::Sampler(s)) =
                    (&t.target, &s.target)
                else {
                    continue;
                };
                let r = capture.resource(*resource);
                let mips = t.range.map_or(r.mip_levels, |range| range.mip_count);
                let s = &capture.samplers[s.index()];
                if s.max_anisotropy > 1 && mips <= 1 {
                    out.push(lint(
                        LintKind::AnisotropicWithoutMips,
                        format!(
                            "\"{}\" samples \"{}\" (one mip) through \"{}\" with {}x anisotropic filtering: give the texture a mip chain or sample it without anisotropy",
                            pass.name, r.name, s.name, s.max_anisotropy
                        ),
                        Some(pass.id),
                        Some(r.id),
                    ));
                }
            }
        }
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
    linter.unused_flags(&mut out);
    linter.written_never_read(&mut out);
    linter.dead_passes(&mut out);
    linter.read_before_write(&mut out);
    linter.redundant_copies(&mut out);
    linter.typeless_without_view(&mut out);
    linter.depth_could_be_read_only(&mut out);
    linter.descriptor_heaps(&mut out);
    linter.unused_channels(&mut out);
    linter.unused_mips(&mut out);
    linter.missing_fences(&mut out);
    linter.upload_heap_reads(&mut out);
    linter.anisotropic_without_mips(&mut out);
    out.extend(compare_recorded(input.capture, input.model, input.plan));
    out.extend(vulkan::compare_vulkan(input.capture, input.model, &uses));
    out.sort();
    out.dedup();
    out
}
