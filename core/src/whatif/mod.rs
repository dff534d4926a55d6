//! What if: a variant of a frame made by edits (a lint's fix applied, a pass culled, a recorded
//! barrier dropped, a resource's format changed), and the static verdict on it: the errors the
//! variant has that the frame had not (hazards, reads of what nothing wrote), before anything
//! runs. The command line replays both and measures; this module needs no device.

mod edit;
mod verdict;

pub use edit::{Edit, EditError, apply};
pub use verdict::{StaticVerdict, static_verdict};

#[cfg(test)]
mod tests;
