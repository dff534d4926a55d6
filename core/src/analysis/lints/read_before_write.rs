//! Lint rule FL006: a read of contents nothing wrote (no initial contents, not history). A
//! pass's own writes count where it holds several draws, dispatches or copies, whose order
//! within it the pass's accesses do not keep.

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::model::MResource;

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
            let works = {
                let c = capture.pass(pass.id);
                c.draws.len() + c.dispatches.len() + c.copies.len() + c.clears.len() + c.blits.len()
            };
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
