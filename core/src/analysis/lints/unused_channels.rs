//! Lint rule FL011: every write masks off channels: a format with fewer channels would do.

use std::collections::{BTreeMap, BTreeSet};

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};
use crate::capture::format::Access;
use crate::capture::model::ResourceId;

/// FL011 `unused-channels`: every write masks off channels: a format with fewer channels would do.
pub const UNUSED_CHANNELS: LintKind = LintKind::new(&LintDef {
    code: "FL011",
    name: "unused-channels",
    severity: LintSeverity::Info,
    description: "every write masks off channels: a format with fewer channels would do",
});

/// Channels masked off in every write.
pub(super) struct UnusedChannels;

impl Rule for UnusedChannels {
    fn kinds(&self) -> &'static [LintKind] {
        &[UNUSED_CHANNELS]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *l;
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
                || l.uses_of(r.id)
                    .any(|(_, a)| a.writes && a.access != Access::ColorAttachment)
            {
                continue;
            }
            let union: BTreeSet<char> = masks.iter().flatten().flat_map(|m| m.chars()).collect();
            if union.len() < channels {
                let used: String = union.iter().collect();
                out.push(lint(UNUSED_CHANNELS, format!("\"{}\" ({}) is only ever written in channels \"{used}\"; a {}-channel format would do", r.name, f.name, union.len()), None, Some(r.id)));
            }
        }
    }
}
