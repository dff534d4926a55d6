//! Lint rule FL007: a copy whose result is never read, or that repeats an identical copy.

use std::collections::BTreeMap;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::analysis::graph::EdgeKind;
use crate::analysis::model::MPass;
use crate::capture::model::ResourceId;

/// FL007 `redundant-copy`: a copy whose result is never read, or that repeats an identical copy.
pub const REDUNDANT_COPY: LintKind = LintKind::new(&LintDef {
    code: "FL007",
    name: "redundant-copy",
    severity: LintSeverity::Warning,
    description: "a copy whose result is never read, or that repeats an identical copy",
});

/// Copies whose result nobody reads, and repeated identical copies.
pub(super) struct RedundantCopies;

impl Rule for RedundantCopies {
    fn kinds(&self) -> &'static [LintKind] {
        &[REDUNDANT_COPY]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter {
            capture,
            model,
            graph,
            order,
            ..
        } = *l;
        let mut seen_copies: BTreeMap<(ResourceId, ResourceId, String), MPass> = BTreeMap::new();
        for &p in order {
            let pass = l.capture_pass(p);
            for (i, c) in pass.copies.iter().enumerate() {
                let dst = c.dst.resource;
                let (src_m, dst_m) = (
                    Linter::model_resource(c.src.resource),
                    Linter::model_resource(dst),
                );
                let read_later = graph.graph.edges(graph.nodes[p.index()]).any(|e| {
                    e.weight().kind == EdgeKind::Raw && e.weight().resource == Some(dst_m)
                });
                let dst_res = capture.resource(dst);
                if !read_later && !dst_res.output && !dst_res.history {
                    out.push(lint(
                        REDUNDANT_COPY,
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
                            REDUNDANT_COPY,
                            format!(
                                "\"{}\" repeats the copy \"{}\" made from \"{}\" to \"{}\"",
                                pass.name,
                                l.capture_pass(earlier).name,
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
}
