//! Lint rule FL005: a pass whose writes never reach a frame output.

use super::{Fix, Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};

/// FL005 `pass-without-effect`: a pass whose writes never reach a frame output.
pub const PASS_WITHOUT_EFFECT: LintKind = LintKind::new(&LintDef {
    code: "FL005",
    name: "pass-without-effect",
    severity: LintSeverity::Warning,
    description: "a pass whose writes never reach a frame output",
});

/// Dead passes.
pub(super) struct DeadPasses;

impl Rule for DeadPasses {
    fn kinds(&self) -> &'static [LintKind] {
        &[PASS_WITHOUT_EFFECT]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { model, culled, .. } = *l;
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
            let mut l = lint(PASS_WITHOUT_EFFECT, message, Some(pass.id), None);
            l.fix = Some(Fix::CullPass { pass: pass.id });
            out.push(l);
        }
    }
}
