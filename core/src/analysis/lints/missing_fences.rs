//! Lint rule FL014: a cross-queue dependency no fence orders.

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};

/// FL014 `missing-fence`: a cross-queue dependency no fence orders.
pub const MISSING_FENCE: LintKind = LintKind::new(&LintDef {
    code: "FL014",
    name: "missing-fence",
    severity: LintSeverity::Error,
    description: "a cross-queue dependency no fence orders",
});

/// Fences the frame lacks.
pub(super) struct MissingFences;

impl Rule for MissingFences {
    fn kinds(&self) -> &'static [LintKind] {
        &[MISSING_FENCE]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { model, plan, .. } = *l;
        for f in plan.fences.iter().filter(|f| !f.declared) {
            let (a, b) = (
                &model.passes[f.signal_after.index()],
                &model.passes[f.wait_before.index()],
            );
            out.push(lint(
                MISSING_FENCE,
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
}
