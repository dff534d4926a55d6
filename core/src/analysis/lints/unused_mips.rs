//! Lint rule FL012: mip levels no pass touches.

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};

/// FL012 `unused-mips`: mip levels no pass touches.
pub const UNUSED_MIPS: LintKind = LintKind::new(&LintDef {
    code: "FL012",
    name: "unused-mips",
    severity: LintSeverity::Info,
    description: "mip levels no pass touches",
});

/// Mips no pass touches.
pub(super) struct UnusedMips;

impl Rule for UnusedMips {
    fn kinds(&self) -> &'static [LintKind] {
        &[UNUSED_MIPS]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *l;
        for r in capture
            .resources
            .iter()
            .filter(|r| r.is_texture() && r.mip_levels > 1)
        {
            let max_mip = l
                .uses_of(r.id)
                .map(|(_, a)| a.range.mip_base + a.range.mip_count)
                .max();
            if let Some(used) = max_mip.filter(|&m| m < r.mip_levels) {
                out.push(lint(
                    UNUSED_MIPS,
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
}
