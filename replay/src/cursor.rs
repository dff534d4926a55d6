//! The frame cursor: a replayed frame held open right after one of its passes (or part way
//! through one, up to a draw), so that what the passes so far wrote can be read back, and the
//! capture's names of passes, textures and buffers resolved to the plan's. The MCP server's
//! reads, the inspector's worker (its browsed frame, its draw steps, its copies made again) and
//! `replay --after`'s pass name all reach "frame F as of pass P" through here.

use crate::replaying::{Open, Replaying};
use crate::run::ReplayError;

/// A name the replay does not know, or knows as something else.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    #[error("no pass \"{0}\"")]
    NoPass(String),
    #[error("pass \"{0}\" is not replayed (culled, or outside the replayed order)")]
    PassNotReplayed(String),
    #[error("no resource \"{0}\"")]
    NoResource(String),
    #[error("\"{name}\" is not a {kind} the replay creates")]
    NotReplayed { name: String, kind: &'static str },
}

impl Replaying {
    /// Where the open frame stands, if one is open.
    pub fn open(&self) -> Option<Open> {
        self.open
    }

    /// Holds frame `frame` open with its first `done` plan passes submitted. Runs on from the
    /// open frame when it is that frame, not past `done` and not part way through a pass;
    /// otherwise ends it and starts the frame again: at once when the last whole frame run
    /// was the one before it (or it is frame 0 of a session that has run nothing), else after
    /// frames `0..frame` run whole. `before_pass` is called with each pass's index before it
    /// is submitted (to report progress or stop: its error stops the replay there, the frame
    /// left open at the passes done).
    pub fn hold<E: From<ReplayError>>(
        &mut self,
        frame: u32,
        done: usize,
        mut before_pass: impl FnMut(usize) -> Result<(), E>,
    ) -> Result<(), E> {
        let done = done.min(self.session.plan.passes.len());
        let from = match self.open {
            Some(o) if o.frame == frame && o.done <= done && o.partial.is_none() => o.done,
            _ => {
                self.release();
                // Frame 0 follows whatever ran before it; frames 0..0 are none to run.
                let follows = frame == 0 || self.last_whole == Some(frame - 1);
                if !follows {
                    for f in 0..frame {
                        self.run_whole(f)?;
                    }
                }
                let constants = self.constants(frame);
                self.session.begin_frame(&constants)?;
                self.open = Some(Open {
                    frame,
                    done: 0,
                    partial: None,
                });
                0
            }
        };
        for i in from..done {
            before_pass(i)?;
            self.session.submit_pass(i)?;
            if let Some(o) = &mut self.open {
                o.done = i + 1;
            }
        }
        Ok(())
    }

    /// Holds frame `frame` open with pass `pass` submitted up to its draw or dispatch `step`
    /// (the passes before it whole): a frame debugger's view of one draw.
    pub fn step(&mut self, frame: u32, pass: usize, step: usize) -> Result<(), ReplayError> {
        self.hold(frame, pass, |_| Ok::<(), ReplayError>(()))?;
        let ran = self.session.submit_pass_until(pass, step);
        if ran.is_err() {
            self.release();
            return ran;
        }
        if let Some(o) = &mut self.open {
            o.partial = Some(pass);
        }
        Ok(())
    }

    /// The caller put back what the partly run pass wrote, as it was before the pass: the
    /// open frame can run on from it.
    pub fn restored(&mut self) {
        if let Some(o) = &mut self.open {
            o.partial = None;
        }
    }

    /// Ends the open frame, if one is open, so that whole frames can run. A frame ended with
    /// every pass done whole counts as run whole: the next frame can follow it.
    pub fn release(&mut self) {
        if let Some(o) = self.open.take() {
            self.session.end_frame();
            let whole = o.done == self.session.plan.passes.len() && o.partial.is_none();
            self.last_whole = whole.then_some(o.frame);
        }
    }

    /// Runs frame `f` whole (the open frame ended first) and returns its per-pass times,
    /// without keeping them ([`Replaying::frame`] keeps them for the report).
    pub fn run_whole(&mut self, f: u32) -> Result<Vec<crate::PassTime>, ReplayError> {
        self.release();
        let constants = self.constants(f);
        let times = self.session.run_frame(&constants, None);
        self.last_whole = times.as_ref().ok().map(|_| f);
        times
    }

    /// The plan pass the capture's pass `name` became.
    pub fn plan_pass(&self, name: &str) -> Result<usize, NameError> {
        let id = self
            .capture()
            .passes
            .iter()
            .find(|p| p.name == name)
            .ok_or_else(|| NameError::NoPass(name.to_owned()))?
            .id;
        self.pass_ids
            .iter()
            .position(|&p| p == id)
            .ok_or_else(|| NameError::PassNotReplayed(name.to_owned()))
    }

    /// The plan texture the capture's resource `name` became.
    pub fn plan_texture(&self, name: &str) -> Result<usize, NameError> {
        self.plan_index(name, &self.texture_of, "texture")
    }

    /// The plan buffer the capture's resource `name` became.
    pub fn plan_buffer(&self, name: &str) -> Result<usize, NameError> {
        self.plan_index(name, &self.buffer_of, "buffer")
    }

    /// Where the capture's resource `name` is in `of` (the plan's textures or buffers, `kind`).
    fn plan_index(
        &self,
        name: &str,
        of: &std::collections::BTreeMap<framelab_core::capture::model::ResourceId, usize>,
        kind: &'static str,
    ) -> Result<usize, NameError> {
        let id = self.resource_named(name)?;
        of.get(&id).copied().ok_or_else(|| NameError::NotReplayed {
            name: name.to_owned(),
            kind,
        })
    }

    fn resource_named(
        &self,
        name: &str,
    ) -> Result<framelab_core::capture::model::ResourceId, NameError> {
        self.capture()
            .resources
            .iter()
            .find(|r| r.name == name)
            .map(|r| r.id)
            .ok_or_else(|| NameError::NoResource(name.to_owned()))
    }
}
