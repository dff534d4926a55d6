//! What if: a variant of a frame made by edits (a lint's fix applied, a pass culled, a recorded
//! barrier dropped, a resource's format changed, two passes merged), and the static verdict on it: the errors the
//! variant has that the frame had not (hazards, reads of what nothing wrote), before anything
//! runs. The command line replays both and measures; this module needs no device.

mod edit;
mod merge;
mod verdict;

pub use edit::{Edit, EditError, apply};
pub use merge::Unmergeable;
pub use verdict::{StaticVerdict, static_verdict};

use std::collections::{BTreeMap, BTreeSet};

use crate::analysis::report::AnalyzeOptions;
use crate::capture::Options;
use crate::capture::model::Capture;
use crate::pipeline::{Analysed, Loaded, StageError};

/// Why a frame and its variant could not both be made.
#[derive(Debug, thiserror::Error)]
pub enum VariantError {
    /// The frame itself does not read, validate or analyse.
    #[error(transparent)]
    Frame(StageError),
    #[error(transparent)]
    Edit(#[from] EditError),
    /// The edits made a capture that does not validate (or analyse).
    #[error("the edited frame is not a valid capture: {0}")]
    Invalid(StageError),
}

/// A frame and the variant its edits make, both validated and analysed for one scale.
#[derive(Debug)]
pub struct Pair {
    pub frame: Analysed,
    pub variant: Analysed,
    /// Each change made, in words.
    pub changes: Vec<String>,
    /// Both judged by framelab's pass-level rules (`PASS_LEVEL` says why), not by the
    /// import's command-by-command check of the stream.
    pub pass_level: bool,
}

/// Why an edited imported frame is judged pass by pass.
pub const PASS_LEVEL: &str = "judged by framelab's pass-level rules on both frames: the import's command-by-command synchronization check read the stream as captured, which an edit of the model leaves as it was; edit the stream itself with --set to judge command by command";

/// Leaves out the hazards the import found in the stream; whether there were any findings to
/// leave out (the stream was checked).
fn without_stream_check(raw: &mut crate::capture::format::RawCapture) -> bool {
    raw.source
        .as_mut()
        .is_some_and(|s| s.sync_hazards.take().is_some())
}

/// The static verdict on the pair, saying how it was judged.
pub fn verdict(pair: &Pair) -> StaticVerdict {
    let (a, b) = (&pair.frame, &pair.variant);
    let mut v = static_verdict(&a.capture, &a.analysis.lints, &b.capture, &b.analysis.lints);
    if pair.pass_level {
        v.note = Some(PASS_LEVEL.to_owned());
    }
    v
}

fn analysed(loaded: Loaded, options: &Options) -> Result<Analysed, StageError> {
    loaded
        .validate(options)?
        .analyse(AnalyzeOptions { cull: false })
}

/// The frame `loaded` and the variant `edits` make of `start` (the frame itself when `None`;
/// the import of an edited stream otherwise), fixes taken from the frame's own findings.
pub fn variant(
    mut loaded: Loaded,
    start: Option<Loaded>,
    edits: &[Edit],
    options: &Options,
) -> Result<Pair, VariantError> {
    let mut raw = match start {
        Some(s) => s,
        None => Loaded::from_raw(&loaded.path, loaded.raw.clone()),
    };
    // The import's synchronization check judged the commands of the stream it read; an edit
    // of the model (a barrier dropped, passes merged) changes no command it saw, so its
    // findings would stand unchanged in the variant. Both frames are then judged by the same
    // pass-level rules, which read the model; an edited stream (`--set`) alone keeps them.
    let pass_level = !edits.is_empty() && without_stream_check(&mut raw.raw);
    if pass_level {
        without_stream_check(&mut loaded.raw);
    }
    let frame = analysed(loaded, options).map_err(VariantError::Frame)?;
    let (edited, changes) = apply(&raw.raw, &frame.capture, &frame.analysis.lints, edits)?;
    let variant =
        analysed(Loaded::from_raw(&raw.path, edited), options).map_err(VariantError::Invalid)?;
    Ok(Pair {
        frame,
        variant,
        changes,
        pass_level,
    })
}

/// For each pass of the variant that a merge made (`first+second`, named by the edit), the
/// frame's pass it ends as: the last one merged into it, whose name is the longest that follows
/// a `+` (so `a+b+c` ends as `c`). Keyed by the frame's pass name.
pub fn merged_into(frame: &Capture, variant: &Capture) -> BTreeMap<String, String> {
    let here: BTreeSet<&str> = frame.passes.iter().map(|p| p.name.as_str()).collect();
    let mut out = BTreeMap::new();
    for p in variant
        .passes
        .iter()
        .filter(|p| !here.contains(p.name.as_str()))
    {
        let last = p
            .name
            .match_indices('+')
            .map(|(i, _)| &p.name[i + 1..])
            .find(|tail| here.contains(tail));
        if let Some(last) = last {
            out.insert(last.to_owned(), p.name.clone());
        }
    }
    out
}

/// The passes of the frame and its variant that end in the same state, as indices into each
/// one's passes, with whether the pair is a rename: a pass the edits kept, by its name; a
/// merged pass, with the last pass merged into it. Culled passes, and the passes merged into
/// another before its last, have none.
pub fn pass_pairs(frame: &Capture, variant: &Capture) -> Vec<(usize, usize, bool)> {
    let merged = merged_into(frame, variant);
    let there: BTreeMap<&str, usize> = variant
        .passes
        .iter()
        .enumerate()
        .map(|(j, p)| (p.name.as_str(), j))
        .collect();
    frame
        .passes
        .iter()
        .enumerate()
        .filter_map(|(i, p)| match merged.get(&p.name) {
            Some(m) => Some((i, *there.get(m.as_str())?, true)),
            None => Some((i, *there.get(p.name.as_str())?, false)),
        })
        .collect()
}

#[cfg(test)]
mod merge_tests;
#[cfg(test)]
mod tests;
