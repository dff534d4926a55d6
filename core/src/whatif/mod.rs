//! What if: a variant of a frame made by edits (a lint's fix applied, a pass culled, a recorded
//! barrier dropped, a resource's format changed), and the static verdict on it: the errors the
//! variant has that the frame had not (hazards, reads of what nothing wrote), before anything
//! runs. The command line replays both and measures; this module needs no device.

mod edit;
mod verdict;

pub use edit::{Edit, EditError, apply};
pub use verdict::{StaticVerdict, static_verdict};

use crate::analysis::report::AnalyzeOptions;
use crate::capture::Options;
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
}

fn analysed(loaded: Loaded, options: &Options) -> Result<Analysed, StageError> {
    loaded
        .validate(options)?
        .analyse(AnalyzeOptions { cull: false })
}

/// The frame `loaded` and the variant `edits` make of `start` (the frame itself when `None`;
/// the import of an edited stream otherwise), fixes taken from the frame's own findings.
pub fn variant(
    loaded: Loaded,
    start: Option<Loaded>,
    edits: &[Edit],
    options: &Options,
) -> Result<Pair, VariantError> {
    let raw = match start {
        Some(s) => s,
        None => Loaded::from_raw(&loaded.path, loaded.raw.clone()),
    };
    let frame = analysed(loaded, options).map_err(VariantError::Frame)?;
    let (edited, changes) = apply(&raw.raw, &frame.capture, &frame.analysis.lints, edits)?;
    let variant =
        analysed(Loaded::from_raw(&raw.path, edited), options).map_err(VariantError::Invalid)?;
    Ok(Pair {
        frame,
        variant,
        changes,
    })
}

#[cfg(test)]
mod tests;
