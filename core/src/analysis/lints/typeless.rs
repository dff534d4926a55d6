//! Lint rule FL008: a TYPELESS resource no pass views with a typed format.

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::model::{BindingTarget, ResourceId};

/// FL008 `typeless-without-typed-view`: a TYPELESS resource no pass views with a typed format.
pub const TYPELESS_WITHOUT_TYPED_VIEW: LintKind = LintKind::new(&LintDef {
    code: "FL008",
    name: "typeless-without-typed-view",
    severity: LintSeverity::Warning,
    description: "a TYPELESS resource no pass views with a typed format",
});

/// Typeless resources without a typed view.
pub(super) struct TypelessWithoutView;

impl Rule for TypelessWithoutView {
    fn kinds(&self) -> &'static [LintKind] {
        &[TYPELESS_WITHOUT_TYPED_VIEW]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *l;
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
            let used = l.uses_of(r.id).next().is_some();
            if used && !typed_view {
                out.push(lint(
                TYPELESS_WITHOUT_TYPED_VIEW,
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
}
