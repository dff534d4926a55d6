//! Lint rule FL015: a resource in an UPLOAD heap read by several passes: copy it to a DEFAULT
//! heap.

use std::collections::BTreeSet;

use super::{Lint, LintDef, LintKind, LintSeverity, Linter, Rule, lint};

/// FL015 `upload-heap-read-often`: a resource in an UPLOAD heap read by several passes: copy it to
/// a DEFAULT heap.
pub const UPLOAD_HEAP_READ_OFTEN: LintKind = LintKind::new(&LintDef {
    code: "FL015",
    name: "upload-heap-read-often",
    severity: LintSeverity::Info,
    description: "a resource in an UPLOAD heap read by several passes: copy it to a DEFAULT heap",
});

/// Upload-heap resources read by several passes.
pub(super) struct UploadHeapReads;

impl Rule for UploadHeapReads {
    fn kinds(&self) -> &'static [LintKind] {
        &[UPLOAD_HEAP_READ_OFTEN]
    }

    fn check(&self, l: &Linter<'_>, out: &mut Vec<Lint>) {
        let Linter { capture, .. } = *l;
        for r in &capture.resources {
            if r.heap_type(&capture.heaps) == crate::capture::format::HeapType::Upload {
                let readers: BTreeSet<u32> = l
                    .uses_of(r.id)
                    .filter(|(_, a)| a.reads)
                    .map(|(p, _)| p.id.0)
                    .collect();
                if readers.len() >= 2 {
                    let (from, to) = if l.vulkan_terms() {
                        ("host-visible memory", "DEVICE_LOCAL memory")
                    } else {
                        ("an UPLOAD heap", "a DEFAULT heap")
                    };
                    out.push(lint(
                    UPLOAD_HEAP_READ_OFTEN,
                    format!(
                        "\"{}\" lives in {from} and {} passes read it across the bus; copy it to {to} once",
                        r.name,
                        readers.len()
                    ),
                    None,
                    Some(r.id),
                ));
                }
            }
        }
    }
}
