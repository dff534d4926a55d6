//! `framelab diff --structure`: what changed between two captures without replaying either.
//! Passes are paired by marker path, name and occurrence (so a pass that moved to another
//! queue is still the same pass), leftovers by kind, queue and written resources (a rename);
//! resources and fences by name. Field changes are found by comparing the `info` records of
//! both sides, so every field `info` reports is diffed and none is forgotten; memory totals
//! before and after aliasing come from the analysis.

pub mod render;

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;
use serde_json::Value;

use crate::analysis::report::Analysis;
use crate::capture::model::Capture;
use crate::info::{self, InfoReport, PassInfo};
use crate::matching::match_items;

/// The version of the structural diff's JSON shape.
pub const STRUCTURE_FORMAT_VERSION: u32 = 1;

/// One field that differs, with its value on each side.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Change {
    pub field: String,
    pub a: Value,
    pub b: Value,
}

/// An item (pass, resource, fence) present on both sides whose fields differ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Changed {
    pub name: String,
    pub changes: Vec<Change>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Renamed {
    pub from: String,
    pub to: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Moved {
    /// The pass's marker path.
    pub pass: String,
    pub from: String,
    pub to: String,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PassChanges {
    /// Queue/marker path of passes only in B, and only in A.
    pub added: Vec<String>,
    pub removed: Vec<String>,
    pub renamed: Vec<Renamed>,
    pub moved: Vec<Moved>,
    /// Draw, dispatch and copy counts, kinds, and resources read and written.
    pub changed: Vec<Changed>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct NamedChanges {
    pub added: Vec<String>,
    pub removed: Vec<String>,
    pub changed: Vec<Changed>,
}

/// Bytes of one heap type (or of all of them), in A and in B.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MemoryRow {
    pub heap_type: String,
    /// Every resource in its own memory.
    pub unaliased_bytes: [u64; 2],
    /// After placing resources with disjoint lifetimes in the same memory.
    pub aliased_bytes: [u64; 2],
    /// The most bytes live at once: no placement does better.
    pub lower_bound_bytes: [u64; 2],
}

/// Frame-wide counts, in A and in B.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Counts {
    pub passes: [usize; 2],
    pub resources: [usize; 2],
    pub draws: [usize; 2],
    pub dispatches: [usize; 2],
    pub copies: [usize; 2],
    pub fences: [usize; 2],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Side {
    pub capture: String,
    pub source: String,
    /// The scale its sizes were resolved at: `--scale`, or 1 for an imported frame.
    pub scale: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StructureDiff {
    pub format_version: u32,
    pub a: Side,
    pub b: Side,
    pub scale: f64,
    pub counts: Counts,
    pub queues: NamedChanges,
    pub passes: PassChanges,
    pub resources: NamedChanges,
    pub fences: NamedChanges,
    /// Per heap type, then `total`.
    pub memory: Vec<MemoryRow>,
}

impl StructureDiff {
    /// Whether the two frames have the same structure (memory and counts follow from it).
    pub fn is_empty(&self) -> bool {
        let named =
            |n: &NamedChanges| n.added.is_empty() && n.removed.is_empty() && n.changed.is_empty();
        let p = &self.passes;
        named(&self.queues)
            && named(&self.resources)
            && named(&self.fences)
            && p.added.is_empty()
            && p.removed.is_empty()
            && p.renamed.is_empty()
            && p.moved.is_empty()
            && p.changed.is_empty()
    }
}

/// One validated, analysed capture.
#[derive(Clone, Copy, Debug)]
pub struct Frame<'a> {
    pub capture: &'a Capture,
    pub analysis: &'a Analysis,
}

/// A record's fields by name (records are `info`'s, serialised).
fn fields(record: &impl Serialize) -> serde_json::Map<String, Value> {
    match serde_json::to_value(record) {
        Ok(Value::Object(m)) => m,
        _ => serde_json::Map::new(),
    }
}

/// Fields of two records that differ, `skip` left out.
fn field_changes(a: &impl Serialize, b: &impl Serialize, skip: &[&str]) -> Vec<Change> {
    let (ma, mb) = (fields(a), fields(b));
    let names: BTreeSet<&String> = ma.keys().chain(mb.keys()).collect();
    names
        .into_iter()
        .filter(|f| !skip.contains(&f.as_str()))
        .filter_map(|f| {
            let (va, vb) = (
                ma.get(f).cloned().unwrap_or(Value::Null),
                mb.get(f).cloned().unwrap_or(Value::Null),
            );
            (va != vb).then(|| Change {
                field: f.clone(),
                a: va,
                b: vb,
            })
        })
        .collect()
}

/// Items paired by name: added, removed and changed.
fn by_name<T: Serialize>(a: &[T], b: &[T], name: impl Fn(&T) -> &str) -> NamedChanges {
    let ia: BTreeMap<&str, &T> = a.iter().map(|x| (name(x), x)).collect();
    let ib: BTreeMap<&str, &T> = b.iter().map(|x| (name(x), x)).collect();
    let mut out = NamedChanges::default();
    for (n, x) in &ia {
        match ib.get(n) {
            None => out.removed.push((*n).to_owned()),
            Some(y) => {
                let changes = field_changes(x, y, &["name"]);
                if !changes.is_empty() {
                    out.changed.push(Changed {
                        name: (*n).to_owned(),
                        changes,
                    });
                }
            }
        }
    }
    out.added = ib
        .keys()
        .filter(|n| !ia.contains_key(*n))
        .map(|n| (*n).to_owned())
        .collect();
    // Names with numbers (an import's `buffer_7`, `buffer_71`, `buffer_9`) in natural order.
    out.added
        .sort_by(|x, y| alphanumeric_sort::compare_str(x, y));
    out.removed
        .sort_by(|x, y| alphanumeric_sort::compare_str(x, y));
    out.changed
        .sort_by(|x, y| alphanumeric_sort::compare_str(&x.name, &y.name));
    out
}

fn pass_label(p: &PassInfo) -> String {
    format!("{}/{}", p.queue, p.marker_path)
}

/// Passes paired by marker path, name and occurrence, leftovers by kind, queue and written
/// resources (a rename).
fn pass_matching(a: &[PassInfo], b: &[PassInfo]) -> crate::matching::Matching {
    match_items(
        a,
        b,
        |p| (p.marker_path.clone(), p.name.clone()),
        |p| (!p.writes.is_empty()).then(|| (p.kind, p.queue.clone(), p.writes.clone())),
    )
}

/// The passes the structural diff takes for the same pass in captures `a` and `b`: indices
/// into each capture's passes, and whether the pair is a rename. The inspector compares a
/// pass's images across two captures with these.
pub fn pass_pairs(a: &Capture, b: &Capture) -> Vec<(usize, usize, bool)> {
    let (ia, ib) = (info::report(a), info::report(b));
    let m = pass_matching(&ia.passes, &ib.passes);
    m.pairs
        .iter()
        .map(|&(i, j)| (i, j, m.renamed.contains(&(i, j))))
        .collect()
}

fn passes(a: &[PassInfo], b: &[PassInfo]) -> PassChanges {
    let m = pass_matching(a, b);
    let mut out = PassChanges {
        added: m.added.iter().map(|&j| pass_label(&b[j])).collect(),
        removed: m.removed.iter().map(|&i| pass_label(&a[i])).collect(),
        ..PassChanges::default()
    };
    for &(i, j) in &m.pairs {
        let (pa, pb) = (&a[i], &b[j]);
        if m.renamed.contains(&(i, j)) {
            out.renamed.push(Renamed {
                from: pass_label(pa),
                to: pass_label(pb),
            });
        }
        if pa.queue != pb.queue {
            out.moved.push(Moved {
                pass: pb.marker_path.clone(),
                from: pa.queue.clone(),
                to: pb.queue.clone(),
            });
        }
        // Name and queue changes are the renames and moves above.
        let skip = ["name", "marker_path", "queue", "queue_type"];
        let changes = field_changes(pa, pb, &skip);
        if !changes.is_empty() {
            out.changed.push(Changed {
                name: pass_label(pb),
                changes,
            });
        }
    }
    out
}

/// Per fence: the passes that signal it and those that wait on it.
#[derive(Serialize)]
struct FenceRecord {
    name: String,
    signalled_by: Vec<String>,
    waited_by: Vec<String>,
}

fn fences(capture: &Capture) -> Vec<FenceRecord> {
    let mut out: Vec<FenceRecord> = capture
        .fences
        .iter()
        .map(|f| FenceRecord {
            name: f.clone(),
            signalled_by: Vec::new(),
            waited_by: Vec::new(),
        })
        .collect();
    for p in &capture.passes {
        for f in &p.signal {
            out[f.index()].signalled_by.push(p.marker_path());
        }
        for f in &p.wait {
            out[f.index()].waited_by.push(p.marker_path());
        }
    }
    out
}

fn memory(a: &Analysis, b: &Analysis) -> Vec<MemoryRow> {
    let (ma, mb) = (&a.memory, &b.memory);
    let types: BTreeSet<&String> = ma
        .per_heap_type
        .keys()
        .chain(mb.per_heap_type.keys())
        .collect();
    let row = |name: &str, ta: Option<&crate::analysis::memory::Totals>, tb: Option<&_>| {
        let get = |t: Option<&crate::analysis::memory::Totals>| t.cloned().unwrap_or_default();
        let (ta, tb) = (get(ta), get(tb));
        MemoryRow {
            heap_type: name.to_owned(),
            unaliased_bytes: [ta.unaliased_bytes, tb.unaliased_bytes],
            aliased_bytes: [ta.aliased_bytes, tb.aliased_bytes],
            lower_bound_bytes: [ta.lower_bound_bytes, tb.lower_bound_bytes],
        }
    };
    let mut rows: Vec<MemoryRow> = types
        .into_iter()
        .map(|t| row(t, ma.per_heap_type.get(t), mb.per_heap_type.get(t)))
        .collect();
    rows.push(row("total", Some(&ma.total), Some(&mb.total)));
    rows
}

fn counts(a: &InfoReport, b: &InfoReport, ca: &Capture, cb: &Capture) -> Counts {
    let sum = |r: &InfoReport, f: fn(&PassInfo) -> usize| r.passes.iter().map(f).sum();
    Counts {
        passes: [a.passes.len(), b.passes.len()],
        resources: [a.resources.len(), b.resources.len()],
        draws: [sum(a, |p| p.draws), sum(b, |p| p.draws)],
        dispatches: [sum(a, |p| p.dispatches), sum(b, |p| p.dispatches)],
        copies: [sum(a, |p| p.copies), sum(b, |p| p.copies)],
        fences: [ca.fences.len(), cb.fences.len()],
    }
}

/// The structural diff of B against A (each resolved at the scale given, an imported frame at
/// its own sizes).
pub fn diff(a: Frame<'_>, b: Frame<'_>) -> StructureDiff {
    let (ia, ib) = (info::report(a.capture), info::report(b.capture));
    let side = |f: Frame<'_>| Side {
        capture: f.capture.name.clone(),
        source: f.capture.source.display().to_string(),
        scale: f.capture.scale,
    };
    StructureDiff {
        format_version: STRUCTURE_FORMAT_VERSION,
        a: side(a),
        b: side(b),
        scale: a.capture.scale,
        counts: counts(&ia, &ib, a.capture, b.capture),
        queues: by_name(&ia.queues, &ib.queues, |q| &q.name),
        passes: passes(&ia.passes, &ib.passes),
        resources: by_name(&ia.resources, &ib.resources, |r| &r.name),
        fences: by_name(&fences(a.capture), &fences(b.capture), |f| &f.name),
        memory: memory(a.analysis, b.analysis),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pass(name: &str, queue: &str, draws: usize, writes: &[&str]) -> PassInfo {
        PassInfo {
            name: name.into(),
            queue: queue.into(),
            queue_type: "graphics",
            kind: "raster",
            marker_path: format!("Frame/{name}"),
            draws,
            dispatches: 0,
            copies: 0,
            reads: vec!["depth".into()],
            writes: writes.iter().map(|w| (*w).to_owned()).collect(),
        }
    }

    #[test]
    fn named_items_are_listed_in_natural_order() {
        #[derive(Serialize)]
        struct Item {
            name: &'static str,
            size: u32,
        }
        let item = |name, size| Item { name, size };
        let a = [
            item("buffer_9", 1),
            item("buffer_71", 1),
            item("buffer_7", 1),
        ];
        let b = [item("image_10", 1), item("image_2", 1), item("buffer_9", 2)];
        let d = by_name(&a, &b, |i| i.name);
        assert_eq!(d.removed, ["buffer_7", "buffer_71"]);
        assert_eq!(d.added, ["image_2", "image_10"]);
        let a = [item("image_10", 1), item("image_2", 1)];
        let b = [item("image_10", 2), item("image_2", 2)];
        let changed: Vec<String> = by_name(&a, &b, |i| i.name)
            .changed
            .into_iter()
            .map(|c| c.name)
            .collect();
        assert_eq!(changed, ["image_2", "image_10"]);
    }

    #[test]
    fn passes_are_added_removed_renamed_moved_and_changed() {
        let a = [
            pass("gbuffer", "gfx", 10, &["albedo"]),
            pass("ssao", "gfx", 1, &["ao"]),
            pass("lights", "gfx", 1, &["hdr"]),
            pass("gone", "gfx", 1, &["debug"]),
        ];
        let b = [
            pass("gbuffer", "gfx", 12, &["albedo"]),
            pass("ssao", "async", 1, &["ao"]),
            pass("lighting", "gfx", 1, &["hdr"]),
            pass("fresh", "gfx", 1, &["ui"]),
        ];
        let d = passes(&a, &b);
        assert_eq!(d.added, ["gfx/Frame/fresh"]);
        assert_eq!(d.removed, ["gfx/Frame/gone"]);
        assert_eq!(
            d.renamed,
            [Renamed {
                from: "gfx/Frame/lights".into(),
                to: "gfx/Frame/lighting".into()
            }]
        );
        assert_eq!(
            d.moved,
            [Moved {
                pass: "Frame/ssao".into(),
                from: "gfx".into(),
                to: "async".into()
            }]
        );
        assert_eq!(
            d.changed,
            [Changed {
                name: "gfx/Frame/gbuffer".into(),
                changes: vec![Change {
                    field: "draws".into(),
                    a: 10.into(),
                    b: 12.into()
                }]
            }]
        );
    }

    #[test]
    fn identical_passes_have_no_changes() {
        let a = [pass("gbuffer", "gfx", 10, &["albedo"])];
        assert_eq!(passes(&a, &a), PassChanges::default());
    }
}
