//! The edits a what-if takes, parsed from their command-line spelling, and applied to the serde
//! form of a capture (so the variant is validated and analysed as any capture is). Edits name
//! passes and resources as the capture does; a lint's fixes are taken from the frame's own
//! analysis. Every edit that cannot apply is an error naming it: nothing is applied in part.

use std::collections::BTreeSet;

use crate::analysis::lints::{Fix, Lint, LintKind};
use crate::capture::format::{Extent, RawCapture, RelativeSize, ResourceFlag, ResourceKind};
use crate::capture::model::Capture;

use super::merge::merge;

/// `--fix all`: every finding that has a fix.
const ALL: &str = "ALL";

/// One change to a frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Apply the fixes of every finding of a lint (`FL005`), or of those about one pass or
    /// resource (`FL005:ssao`); `all` applies every fixable finding's.
    Fix { code: String, at: Option<String> },
    /// Drop a pass.
    Cull { pass: String },
    /// Drop a pass's recorded barrier, by its place in the pass's list (from 0).
    DropBarrier { pass: String, index: usize },
    /// Give a resource another format (DXGI's name, as the capture spells formats).
    Format { resource: String, format: String },
    /// Run a pass on another queue (the async compute queue, say).
    Queue { pass: String, queue: String },
    /// Multiply a texture's width and height by a factor.
    ScaleResource { resource: String, factor: f64 },
    /// Make two raster passes one render pass (`A+B`; a pass name may hold `+`, so the split
    /// is the one that names two passes).
    Merge { passes: String },
}

/// Why an edit cannot be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
    #[error("{edit}: {why}")]
    Syntax { edit: String, why: &'static str },
    #[error("--fix {code}: no lint has that code (docs/analysis.md lists them)")]
    UnknownLint { code: String },
    #[error("--fix {code}: {}", nothing_to_fix(.at, *.unfixable))]
    NothingToFix {
        code: String,
        at: Option<String>,
        unfixable: usize,
    },
    #[error("{edit}: the capture has no pass \"{pass}\"")]
    UnknownPass { edit: String, pass: String },
    #[error("{edit}: the capture has no resource \"{resource}\"")]
    UnknownResource { edit: String, resource: String },
    #[error("{edit}: pass \"{pass}\" records {count} barriers (0..{count})")]
    NoSuchBarrier {
        edit: String,
        pass: String,
        count: usize,
    },
    #[error(
        "{edit}: \"{format}\" is not a format framelab knows (DXGI's names, e.g. R11G11B10_FLOAT)"
    )]
    UnknownFormat { edit: String, format: String },
    #[error("{edit}: \"{resource}\" is a buffer: only a texture's format or size can change")]
    NotATexture { edit: String, resource: String },
    #[error("{edit}: the capture has no queue \"{queue}\"")]
    UnknownQueue { edit: String, queue: String },
    #[error("{edit}: {why}")]
    CannotMerge {
        edit: String,
        why: Box<super::merge::Unmergeable>,
    },
}

fn nothing_to_fix(at: &Option<String>, unfixable: usize) -> String {
    let place = at
        .as_ref()
        .map_or(String::new(), |a| format!(" about \"{a}\""));
    if unfixable == 0 {
        format!("the frame has no such finding{place}")
    } else {
        format!("{unfixable} finding(s){place}, none with a change to the frame as its fix")
    }
}

/// `NAME=VALUE` split at the first `=`.
fn pair<'a>(edit: &str, s: &'a str) -> Result<(&'a str, &'a str), EditError> {
    match s.split_once('=') {
        Some((a, b)) if !a.is_empty() && !b.is_empty() => Ok((a, b)),
        _ => Err(EditError::Syntax {
            edit: edit.to_owned(),
            why: "expected NAME=VALUE",
        }),
    }
}

impl Edit {
    /// `--fix CODE[:WHERE]`.
    pub fn fix(s: &str) -> Result<Edit, EditError> {
        let (code, at) = match s.split_once(':') {
            Some((c, a)) => (c, Some(a.to_owned())),
            None => (s, None),
        };
        let code = code.to_ascii_uppercase();
        if code != ALL && !LintKind::all().iter().any(|k| k.code() == code) {
            return Err(EditError::UnknownLint { code });
        }
        Ok(Edit::Fix { code, at })
    }

    /// `--cull PASS`.
    pub fn cull(s: &str) -> Result<Edit, EditError> {
        if s.is_empty() {
            return Err(EditError::Syntax {
                edit: "--cull".into(),
                why: "expected a pass name",
            });
        }
        Ok(Edit::Cull { pass: s.to_owned() })
    }

    /// `--drop-barrier PASS:N`.
    pub fn drop_barrier(s: &str) -> Result<Edit, EditError> {
        let edit = format!("--drop-barrier {s}");
        let (pass, index) = s
            .rsplit_once(':')
            .and_then(|(p, n)| Some((p, n.parse::<usize>().ok()?)))
            .filter(|(p, _)| !p.is_empty())
            .ok_or(EditError::Syntax {
                edit,
                why: "expected PASS:N, N the barrier's place in the pass's list from 0",
            })?;
        Ok(Edit::DropBarrier {
            pass: pass.to_owned(),
            index,
        })
    }

    /// `--format RESOURCE=FORMAT`.
    pub fn format(s: &str) -> Result<Edit, EditError> {
        let (resource, format) = pair(&format!("--format {s}"), s)?;
        Ok(Edit::Format {
            resource: resource.to_owned(),
            format: format.to_ascii_uppercase(),
        })
    }

    /// `--queue PASS=QUEUE`.
    pub fn queue(s: &str) -> Result<Edit, EditError> {
        let (pass, queue) = pair(&format!("--queue {s}"), s)?;
        Ok(Edit::Queue {
            pass: pass.to_owned(),
            queue: queue.to_owned(),
        })
    }

    /// `--scale-resource RESOURCE=F`, F in (0, 16].
    pub fn scale_resource(s: &str) -> Result<Edit, EditError> {
        let edit = format!("--scale-resource {s}");
        let (resource, factor) = pair(&edit, s)?;
        let factor = factor
            .parse::<f64>()
            .ok()
            .filter(|f| f.is_finite() && *f > 0.0 && *f <= 16.0)
            .ok_or(EditError::Syntax {
                edit,
                why: "the factor is a number above 0 and at most 16",
            })?;
        Ok(Edit::ScaleResource {
            resource: resource.to_owned(),
            factor,
        })
    }

    /// `--merge A+B`.
    pub fn merge(s: &str) -> Result<Edit, EditError> {
        let edit = format!("--merge {s}");
        let two = s
            .match_indices('+')
            .any(|(i, _)| i > 0 && i + 1 < s.len() && s[..i] != s[i + 1..]);
        if !two {
            return Err(EditError::Syntax {
                edit,
                why: "expected FIRST+SECOND, two different passes",
            });
        }
        Ok(Edit::Merge {
            passes: s.to_owned(),
        })
    }

    /// The edit as the command line spells it.
    pub fn spelling(&self) -> String {
        match self {
            Edit::Fix { code, at: None } => format!("--fix {code}"),
            Edit::Fix { code, at: Some(a) } => format!("--fix {code}:{a}"),
            Edit::Cull { pass } => format!("--cull {pass}"),
            Edit::DropBarrier { pass, index } => format!("--drop-barrier {pass}:{index}"),
            Edit::Format { resource, format } => format!("--format {resource}={format}"),
            Edit::Queue { pass, queue } => format!("--queue {pass}={queue}"),
            Edit::ScaleResource { resource, factor } => {
                format!("--scale-resource {resource}={factor}")
            }
            Edit::Merge { passes } => format!("--merge {passes}"),
        }
    }
}

/// A change by names, once the edits and fixes are resolved.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Change {
    RemoveFlag {
        resource: String,
        flag: ResourceFlag,
    },
    Cull {
        pass: String,
    },
    DropBarrier {
        pass: String,
        index: usize,
    },
    Format {
        resource: String,
        format: String,
    },
    Queue {
        pass: String,
        queue: String,
    },
    /// The factor as its bits (a float has no order of its own).
    Scale {
        resource: String,
        factor_bits: u64,
    },
    /// Merges are made in the order given (`seq`), one merge's pass open to the next.
    Merge {
        seq: usize,
        passes: String,
    },
}

/// The fixes of a lint's findings (about `at`, when given), by names.
fn fixes(
    capture: &Capture,
    lints: &[Lint],
    (code, at): (&str, Option<&str>),
    seq: usize,
) -> Result<Vec<Change>, EditError> {
    let about = |l: &Lint| {
        at.is_none_or(|a| {
            l.pass.is_some_and(|p| capture.pass(p).name == a)
                || l.resource.is_some_and(|r| capture.resource(r).name == a)
        })
    };
    let found: Vec<&Lint> = lints
        .iter()
        .filter(|l| (l.kind.code() == code || (code == ALL && l.fix.is_some())) && about(l))
        .collect();
    let changes: Vec<Change> = found
        .iter()
        .filter_map(|l| l.fix)
        .map(|f| match f {
            Fix::RemoveFlag { resource, flag } => Change::RemoveFlag {
                resource: capture.resource(resource).name.clone(),
                flag,
            },
            Fix::CullPass { pass } => Change::Cull {
                pass: capture.pass(pass).name.clone(),
            },
            Fix::DropBarrier { pass, index } => Change::DropBarrier {
                pass: capture.pass(pass).name.clone(),
                index,
            },
            Fix::MergePasses { first, second } => Change::Merge {
                seq,
                passes: format!("{}+{}", capture.pass(first).name, capture.pass(second).name),
            },
        })
        .collect();
    if changes.is_empty() {
        return Err(EditError::NothingToFix {
            code: code.to_owned(),
            at: at.map(str::to_owned),
            unfixable: found.len(),
        });
    }
    Ok(changes)
}

/// The variant of `raw` the edits make, and each change made, in words. `capture` and `lints`
/// are the frame's own validation and analysis, where fixes come from.
pub fn apply(
    raw: &RawCapture,
    capture: &Capture,
    lints: &[Lint],
    edits: &[Edit],
) -> Result<(RawCapture, Vec<String>), EditError> {
    let mut changes = BTreeSet::new();
    for (seq, e) in edits.iter().enumerate() {
        match e {
            Edit::Fix { code, at } => {
                changes.extend(fixes(capture, lints, (code, at.as_deref()), seq)?)
            }
            Edit::Cull { pass } => {
                changes.insert(Change::Cull { pass: pass.clone() });
            }
            Edit::DropBarrier { pass, index } => {
                changes.insert(Change::DropBarrier {
                    pass: pass.clone(),
                    index: *index,
                });
            }
            Edit::Format { resource, format } => {
                changes.insert(Change::Format {
                    resource: resource.clone(),
                    format: format.clone(),
                });
            }
            Edit::Queue { pass, queue } => {
                changes.insert(Change::Queue {
                    pass: pass.clone(),
                    queue: queue.clone(),
                });
            }
            Edit::ScaleResource { resource, factor } => {
                changes.insert(Change::Scale {
                    resource: resource.clone(),
                    factor_bits: factor.to_bits(),
                });
            }
            Edit::Merge { passes } => {
                changes.insert(Change::Merge {
                    seq,
                    passes: passes.clone(),
                });
            }
        }
    }
    let mut out = raw.clone();
    let mut said = Vec::new();
    // Barriers first, from the highest place down, so each index means what it meant in the
    // frame as captured; merges after the changes to single passes, so the merged pass takes
    // them; culls last, so a barrier of a culled pass is still found.
    let mut ordered: Vec<&Change> = changes.iter().collect();
    ordered.sort_by_key(|c| match c {
        Change::DropBarrier { index, .. } => (0, usize::MAX - index),
        Change::RemoveFlag { .. }
        | Change::Format { .. }
        | Change::Queue { .. }
        | Change::Scale { .. } => (1, 0),
        Change::Merge { seq, .. } => (2, *seq),
        Change::Cull { .. } => (3, 0),
    });
    for c in ordered {
        said.push(change(&mut out, capture, c, edits)?);
    }
    Ok((out, said))
}

/// The spelling of the edit a change came from, for its error.
fn origin(edits: &[Edit], c: &Change) -> String {
    let direct = edits.iter().find(|e| match (e, c) {
        (Edit::Cull { pass }, Change::Cull { pass: p }) => pass == p,
        (Edit::DropBarrier { pass, index }, Change::DropBarrier { pass: p, index: i }) => {
            pass == p && index == i
        }
        (Edit::Format { resource, .. }, Change::Format { resource: r, .. })
        | (Edit::ScaleResource { resource, .. }, Change::Scale { resource: r, .. }) => {
            resource == r
        }
        (Edit::Queue { pass, .. }, Change::Queue { pass: p, .. }) => pass == p,
        (Edit::Merge { passes }, Change::Merge { passes: p, .. }) => passes == p,
        _ => false,
    });
    direct.map_or_else(|| "--fix".to_owned(), Edit::spelling)
}

/// Makes one change; what it did, in words.
fn change(
    raw: &mut RawCapture,
    frame: &Capture,
    c: &Change,
    edits: &[Edit],
) -> Result<String, EditError> {
    let edit = || origin(edits, c);
    let pass_index = |raw: &RawCapture, pass: &str| {
        raw.passes
            .iter()
            .position(|p| p.name == pass)
            .ok_or_else(|| EditError::UnknownPass {
                edit: edit(),
                pass: pass.to_owned(),
            })
    };
    let resource_index = |raw: &RawCapture, resource: &str| {
        raw.resources
            .iter()
            .position(|r| r.name == resource)
            .ok_or_else(|| EditError::UnknownResource {
                edit: edit(),
                resource: resource.to_owned(),
            })
    };
    match c {
        Change::Merge { passes, .. } => {
            let split = passes
                .match_indices('+')
                .map(|(i, _)| (&passes[..i], &passes[i + 1..]))
                .find(|(a, b)| {
                    a != b
                        && [a, b]
                            .iter()
                            .all(|n| raw.passes.iter().any(|p| p.name == **n))
                });
            match split {
                Some(pair) => merge(raw, frame, pair, &edit()),
                None => {
                    let (a, b) = passes.split_once('+').unwrap_or((passes, ""));
                    let missing = if raw.passes.iter().any(|p| p.name == a) {
                        b
                    } else {
                        a
                    };
                    Err(EditError::UnknownPass {
                        edit: edit(),
                        pass: missing.to_owned(),
                    })
                }
            }
        }
        Change::Cull { pass } => {
            let i = pass_index(raw, pass)?;
            raw.passes.remove(i);
            Ok(format!("culled pass \"{pass}\""))
        }
        Change::DropBarrier { pass, index } => {
            let i = pass_index(raw, pass)?;
            let barriers = &mut raw.passes[i].barriers;
            if *index >= barriers.len() {
                return Err(EditError::NoSuchBarrier {
                    edit: edit(),
                    pass: pass.clone(),
                    count: barriers.len(),
                });
            }
            barriers.remove(*index);
            Ok(format!("dropped barrier {index} of pass \"{pass}\""))
        }
        Change::RemoveFlag { resource, flag } => {
            let i = resource_index(raw, resource)?;
            raw.resources[i].flags.retain(|f| f != flag);
            Ok(format!("removed {} from \"{resource}\"", flag.name()))
        }
        Change::Format { resource, format } => {
            let i = resource_index(raw, resource)?;
            if crate::capture::dxgi::lookup(format).is_none() {
                return Err(EditError::UnknownFormat {
                    edit: edit(),
                    format: format.clone(),
                });
            }
            let r = &mut raw.resources[i];
            if matches!(r.kind, ResourceKind::Buffer) {
                return Err(EditError::NotATexture {
                    edit: edit(),
                    resource: resource.clone(),
                });
            }
            let before = r.format.replace(format.clone()).unwrap_or_default();
            Ok(format!("\"{resource}\" {before} -> {format}"))
        }
        Change::Queue { pass, queue } => {
            let i = pass_index(raw, pass)?;
            if !raw.queues.iter().any(|q| &q.name == queue) {
                return Err(EditError::UnknownQueue {
                    edit: edit(),
                    queue: queue.clone(),
                });
            }
            let before = std::mem::replace(&mut raw.passes[i].queue, queue.clone());
            Ok(format!(
                "pass \"{pass}\" moved from queue {before} to {queue}"
            ))
        }
        Change::Scale {
            resource,
            factor_bits,
        } => {
            let i = resource_index(raw, resource)?;
            let factor = f64::from_bits(*factor_bits);
            let r = &mut raw.resources[i];
            if matches!(r.kind, ResourceKind::Buffer) {
                return Err(EditError::NotATexture {
                    edit: edit(),
                    resource: resource.clone(),
                });
            }
            for e in [&mut r.width, &mut r.height].into_iter().flatten() {
                *e = scaled(e, factor);
            }
            Ok(format!(
                "\"{resource}\" width and height scaled by {factor}"
            ))
        }
    }
}

/// An extent multiplied by `factor`: texels rounded (at least one), a relative size kept
/// relative.
fn scaled(e: &Extent, factor: f64) -> Extent {
    let relative = |scale: f64, multiple_of| Extent::Scaled {
        scale: scale * factor,
        multiple_of,
    };
    match *e {
        Extent::Texels(n) => Extent::Texels(((n as f64 * factor).round() as u64).max(1)),
        Extent::Named(RelativeSize::Full) => relative(1.0, None),
        Extent::Named(RelativeSize::Half) => relative(0.5, None),
        Extent::Named(RelativeSize::Quarter) => relative(0.25, None),
        Extent::Scaled { scale, multiple_of } => relative(scale, multiple_of),
    }
}
