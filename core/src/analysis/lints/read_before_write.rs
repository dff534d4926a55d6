//! Lint rule FL006: a read of contents nothing wrote (no initial contents, not history). A
//! pass's own writes count where it holds several draws, dispatches or copies, whose order
//! within it the pass's accesses do not keep, and so does a clear of a single-subresource
//! attachment at the pass's start, before anything in it reads (a draw reading what its own
//! pass renders: framebuffer fetch). An imported swapchain image is left out: an acquired
//! image's contents are undefined to the program too, and loading them is allowed (the
//! validation layer accepts it; `replay` says nothing of them either).

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::model::MResource;
use crate::capture::format::LoadOp;
use crate::capture::model::{Capture, PassDesc, ResourceId};

/// FL006 `read-before-write`: a read of contents nothing wrote (no initial contents, not history).
pub const READ_BEFORE_WRITE: LintKind = LintKind::new(&LintDef {
    code: "FL006",
    name: "read-before-write",
    severity: LintSeverity::Error,
    description: "a read of contents nothing wrote (no initial contents, not history)",
});

/// Read before anything wrote it, in order.
pub(super) struct ReadBeforeWrite;

impl Rule for ReadBeforeWrite {
    fn kinds(&self) -> &'static [LintKind] {
        &[READ_BEFORE_WRITE]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter {
            model,
            order,
            capture,
            ..
        } = *l;
        // An imported storage binding reads only by assumption (no shader code says).
        let assumed_reads = capture.not_replayable().is_some();
        let mut written: BTreeSet<MResource> = BTreeSet::new();
        let mut reported: BTreeSet<MResource> = BTreeSet::new();
        for &p in order {
            let pass = &model.passes[p.index()];
            // A pass of several draws, dispatches or copies keeps their order, which the
            // pass's accesses do not: what one of them writes another may read after it (a
            // two-pass blur recorded as two dispatches of one pass).
            let c = capture.pass(pass.id);
            let works = c.draws.len()
                + c.dispatches.len()
                + c.copies.len()
                + c.clears.len()
                + c.blits.len();
            let cleared = cleared_at_load(capture, c);
            let own_writes: BTreeSet<MResource> = if works > 1 {
                pass.accesses
                    .iter()
                    .filter(|a| a.writes)
                    .map(|a| a.resource)
                    .collect()
            } else {
                BTreeSet::new()
            };
            for a in &pass.accesses {
                let r = &model.resources[a.resource.index()];
                if a.reads
                    && (!assumed_reads || !a.uav || !a.writes)
                    && !written.contains(&a.resource)
                    && !own_writes.contains(&a.resource)
                    && !cleared.contains(&r.id)
                    && !capture.resource(r.id).swapchain
                    && !r.initialised
                    && r.previous_of.is_none()
                    && reported.insert(a.resource)
                {
                    out.push(lint(READ_BEFORE_WRITE, format!("\"{}\" reads \"{}\" before any pass writes it and it has no initial contents", pass.name, r.name), Some(pass.id), Some(r.id)));
                }
            }
            for a in &pass.accesses {
                if a.writes {
                    written.insert(a.resource);
                }
            }
        }
    }
}

/// The attachments `pass` clears as it begins that are one subresource whole: whatever in
/// the pass reads them reads after the clear. (Of a texture of several mips, layers or slices
/// the read may be of another, which the clear does not write.)
fn cleared_at_load(capture: &Capture, pass: &PassDesc) -> BTreeSet<ResourceId> {
    let whole = |id: ResourceId| {
        let r = capture.resource(id);
        r.mip_levels <= 1 && r.array_layers <= 1 && r.depth <= 1
    };
    let colors = pass
        .color_attachments
        .iter()
        .filter(|a| a.load == LoadOp::Clear)
        .map(|a| a.resource);
    let depth = pass
        .depth_stencil
        .iter()
        .filter(|d| d.depth_load == LoadOp::Clear)
        .map(|d| d.resource);
    colors.chain(depth).filter(|&id| whole(id)).collect()
}
