//! Lint rule FL009: depth bound writable by a pass that only tests it: bind it read-only
//! (DEPTH_READ).

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::format::{Access, LoadOp};

/// FL009 `depth-could-be-read-only`: depth bound writable by a pass that only tests it: bind it
/// read-only (DEPTH_READ).
pub const DEPTH_COULD_BE_READ_ONLY: LintKind = LintKind::new(&LintDef {
    code: "FL009",
    name: "depth-could-be-read-only",
    severity: LintSeverity::Info,
    description: "depth bound writable by a pass that only tests it: bind it read-only (DEPTH_READ)",
});

/// Depth bound writable but only tested.
pub(super) struct DepthCouldBeReadOnly;

impl Rule for DepthCouldBeReadOnly {
    fn kinds(&self) -> &'static [LintKind] {
        &[DEPTH_COULD_BE_READ_ONLY]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, order, .. } = *l;
        for &p in order {
            let pass = l.capture_pass(p);
            if let Some(d) = &pass.depth_stencil {
                let access = pass.accesses.iter().find(|a| {
                    a.resource == d.resource
                        && matches!(a.access, Access::DepthRead | Access::DepthWrite)
                });
                // A Vulkan attachment in a writable layout is written by its store operation,
                // so what tells is whether any draw writes depth or stencil.
                let only_tested = if l.vulkan_terms() {
                    d.depth_load != LoadOp::Clear
                        && d.stencil_load != LoadOp::Clear
                        && !pass.draws.iter().any(|w| vk_draw_may_write_depth(l, w))
                } else {
                    access.is_some_and(|a| a.access == Access::DepthRead)
                };
                if !d.read_only && only_tested {
                    let name = &capture.resource(d.resource).name;
                    let message = if l.vulkan_terms() {
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
                        DEPTH_COULD_BE_READ_ONLY,
                        message,
                        Some(pass.id),
                        Some(d.resource),
                    ));
                }
            }
        }
    }
}

/// Whether an imported draw's pipeline may write depth or stencil: depth writes with the
/// depth test on, stencil writes with the stencil test on, or either left to dynamic
/// state (whose values the capture does not keep). A draw with no pipeline known may.
fn vk_draw_may_write_depth(l: &Linter<'_>, draw: &crate::capture::model::DrawDesc) -> bool {
    let pipeline = draw.vk.as_ref().and_then(|w| {
        l.capture
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
