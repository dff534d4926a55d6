//! Lint rule FL004: a resource written and never read (and not a frame output).

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::model::MResource;

/// FL004 `written-never-read`: a resource written and never read (and not a frame output).
pub const WRITTEN_NEVER_READ: LintKind = LintKind::new(&LintDef {
    code: "FL004",
    name: "written-never-read",
    severity: LintSeverity::Warning,
    description: "a resource written and never read (and not a frame output)",
});

/// Written, never read.
pub(super) struct WrittenNeverRead;

impl Rule for WrittenNeverRead {
    fn kinds(&self) -> &'static [LintKind] {
        &[WRITTEN_NEVER_READ]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, model, .. } = *l;
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
            let written = l.uses_of(r.id).any(|(_, a)| a.writes);
            if written
                && !read_by.contains(&Linter::model_resource(r.id))
                && !r.output
                && !r.history
            {
                out.push(lint(
                    WRITTEN_NEVER_READ,
                    format!("\"{}\" is written but nothing reads it", r.name),
                    None,
                    Some(r.id),
                ));
            }
        }
    }
}
