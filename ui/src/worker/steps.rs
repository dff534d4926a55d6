//! The frame as of one draw or dispatch of a pass. The frame cursor holds frame 1 (after a
//! whole frame 0) open up to the pass: copies of what the pass writes, as it was before the pass
//! ran, let the pass be replayed up to any of its draws again without a replay from the frame's
//! start, and a later pass is reached by going on from there (the pass put back, then run whole
//! with the passes between). Anything else that replays closes the open frame first.

use std::collections::BTreeMap;

use super::{State, WorkerError, snapshots};

/// Frame 1 replayed up to a pass and held open.
pub(super) struct Open {
    /// The pass whose draws are shown, and what it writes as it was before it ran.
    pass: usize,
    before: Vec<(usize, wgpu::Texture)>,
}

/// Ends the open frame, if there is one, so a whole frame can be replayed.
pub(super) fn close(s: &mut State) {
    if s.open.take().is_some() {
        s.replaying.release();
    }
}

/// Encodes copies of the current frame's `textures` and submits them.
fn copy_out(s: &State, textures: &[usize]) -> Vec<(usize, wgpu::Texture)> {
    let session = &s.replaying.session;
    let mut encoder = session
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("framelab step copies"),
        });
    let out = textures
        .iter()
        .map(|&t| {
            let copy =
                snapshots::copy_texture(&session.device, &mut encoder, session.texture_in_frame(t));
            (t, copy)
        })
        .collect();
    session.queue.submit([encoder.finish()]);
    out
}

/// Puts `before` back into the open frame's textures.
fn restore(s: &State, before: &[(usize, wgpu::Texture)]) {
    let session = &s.replaying.session;
    let mut encoder = session
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("framelab step restore"),
        });
    for (t, copy) in before {
        snapshots::copy_into(&mut encoder, copy, session.texture_in_frame(*t));
    }
    session.queue.submit([encoder.finish()]);
}

/// Brings the open frame to just before `pass`: the pass held open put back as it was before
/// it ran, then the frame cursor runs on from there when `pass` is that one or a later one, and
/// starts frame 1 again otherwise.
fn open_at(s: &mut State, pass: usize) -> Result<(), WorkerError> {
    if s.browsing {
        return Err(WorkerError::Later);
    }
    if let Some(o) = s.open.take() {
        restore(s, &o.before);
        s.replaying.restored();
        if o.pass == pass {
            s.open = Some(o);
            return Ok(());
        }
    }
    s.replaying
        .hold(1, pass, |_| Ok::<(), framelab_replay::ReplayError>(()))?;
    let outputs = s
        .writes
        .get(pass)
        .map(|w| w.textures.clone())
        .unwrap_or_default();
    let before = copy_out(s, &outputs);
    s.open = Some(Open { pass, before });
    Ok(())
}

/// Runs `pass` of the open frame up to draw or dispatch `step`, from its starting contents.
pub(super) fn run_until(s: &mut State, pass: usize, step: usize) -> Result<(), WorkerError> {
    open_at(s, pass)?;
    let ran = s.replaying.step(1, pass, step);
    if ran.is_err() {
        // The cursor ended the frame.
        s.open = None;
    }
    Ok(ran?)
}

/// Copies of what `pass` wrote up to draw or dispatch `step`; the last asked for is kept.
pub(super) fn replay_step(s: &mut State, pass: usize, step: usize) -> Result<(), WorkerError> {
    if s.step.as_ref().is_some_and(|(k, _)| *k == (pass, step)) {
        return Ok(());
    }
    run_until(s, pass, step)?;
    let outputs = s
        .writes
        .get(pass)
        .map(|w| w.textures.clone())
        .unwrap_or_default();
    let copies: BTreeMap<usize, wgpu::Texture> = copy_out(s, &outputs).into_iter().collect();
    s.step = Some(((pass, step), copies));
    Ok(())
}
