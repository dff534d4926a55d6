//! The static verdict on a variant: its findings against the frame's own, compared by what
//! they say (code, pass, resource, message; not by ids, which the edits renumber). An error the
//! variant has and the frame had not (a missing barrier, a hazard, a read of what nothing wrote)
//! makes the change unsafe before anything runs.

use std::collections::BTreeSet;

use serde::Serialize;

use crate::analysis::lints::{Lint, LintSeverity};
use crate::analysis::report::{LintReport, lint_reports};
use crate::capture::model::Capture;

/// What the edits did to the frame's findings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StaticVerdict {
    /// Findings of the variant the frame did not have.
    pub introduced: Vec<LintReport>,
    /// Findings of the frame the variant no longer has.
    pub resolved: Vec<LintReport>,
    /// How the findings were judged, where not as `analyze` judges the frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl StaticVerdict {
    /// No error was introduced.
    pub fn safe(&self) -> bool {
        self.errors().next().is_none()
    }

    /// The errors introduced.
    pub fn errors(&self) -> impl Iterator<Item = &LintReport> {
        self.introduced
            .iter()
            .filter(|l| l.severity == LintSeverity::Error)
    }
}

type Key<'a> = (&'static str, Option<&'a str>, Option<&'a str>, &'a str);

fn key(l: &LintReport) -> Key<'_> {
    (
        l.code,
        l.pass.as_deref(),
        l.resource.as_deref(),
        l.message.as_str(),
    )
}

/// Compares the variant's findings with the frame's.
pub fn static_verdict(
    frame: &Capture,
    frame_lints: &[Lint],
    variant: &Capture,
    variant_lints: &[Lint],
) -> StaticVerdict {
    let (a, b) = (
        lint_reports(frame, frame_lints),
        lint_reports(variant, variant_lints),
    );
    let ka: BTreeSet<Key<'_>> = a.iter().map(key).collect();
    let kb: BTreeSet<Key<'_>> = b.iter().map(key).collect();
    StaticVerdict {
        introduced: b
            .iter()
            .filter(|l| !ka.contains(&key(l)))
            .cloned()
            .collect(),
        resolved: a
            .iter()
            .filter(|l| !kb.contains(&key(l)))
            .cloned()
            .collect(),
        note: None,
    }
}
