//! Starting the inspector's replay: the capture lowered for the device (every texture
//! viewable and copyable), the model projected from it, what each plan pass writes, and the
//! worker started on the replay's own device.

use framelab_core::pipeline::{Analysed, Lowered};
use framelab_replay::wgpu;

use super::{Reports, model};
use crate::model::Inspection;

/// Every plan texture the viewer can show gets bound as a texture by the display pass.
fn make_viewable(lowered: &mut Lowered) {
    for t in &mut lowered.plan.textures {
        if t.samples == 1 {
            t.usage |= wgpu::TextureUsages::TEXTURE_BINDING;
        }
        // The worker copies what each pass writes.
        t.usage |= wgpu::TextureUsages::COPY_SRC;
    }
}

/// Why the inspector could not start.
#[derive(Debug, thiserror::Error)]
pub enum LaunchError {
    #[error(transparent)]
    Lower(#[from] framelab_core::pipeline::StageError),
    #[error(transparent)]
    Replay(#[from] framelab_replay::ReplayError),
    #[error("comparing the timing reports: {0}")]
    Compare(#[from] framelab_core::timing::diff::DiffError),
}

/// How the inspector's replay runs: whole frames timed (the first before the browsed frame, the
/// rest after it) and the bytes of pass copies it keeps.
#[derive(Clone, Copy, Debug)]
pub struct LaunchOptions {
    pub frames: u32,
    pub budget: u64,
}

impl Default for LaunchOptions {
    fn default() -> Self {
        LaunchOptions {
            frames: 2,
            budget: DEFAULT_BUDGET,
        }
    }
}

/// The default memory budget for pass copies.
pub const DEFAULT_BUDGET: u64 = 2048 << 20;

/// The inspector's model and its replay worker on `ctx` (the replay's own device): the capture
/// lowered for the device (every texture viewable, copyable) and the worker started, which
/// creates the session on its own thread so the window can open at once.
pub fn launch(
    analysed: Analysed,
    ctx: framelab_replay::GpuContext,
    reports: &Reports<'_>,
    options: LaunchOptions,
) -> Result<(Inspection, crate::worker::Worker), LaunchError> {
    let mut lowered = analysed.lower(ctx.device.features(), &ctx.summary.name)?;
    make_viewable(&mut lowered);
    let a = &lowered.analysed;
    let inspection = model(
        &a.capture,
        &a.analysis,
        &lowered.pass_ids,
        Some(&lowered),
        reports,
    )?;
    let writes = pass_writes(&lowered);
    let worker = crate::worker::Worker::start(crate::worker::Launch {
        ctx,
        lowered,
        writes,
        timed_frames: options.frames.max(1),
        budget: options.budget,
    });
    Ok((inspection, worker))
}

/// The plan textures and buffers each plan pass writes.
fn pass_writes(lowered: &Lowered) -> Vec<crate::worker::PassWrites> {
    let c = lowered.capture();
    lowered
        .pass_ids
        .iter()
        .map(|&id| {
            let p = c.pass(id);
            let mut w = crate::worker::PassWrites {
                steps: p.draws.len() + p.dispatches.len(),
                ..Default::default()
            };
            for a in p.accesses.iter().filter(|a| a.writes) {
                if let Some(&t) = lowered.texture_of.get(&a.resource) {
                    w.textures.push(t);
                }
                if let Some(&b) = lowered.buffer_of.get(&a.resource) {
                    w.buffers.push(b);
                }
            }
            w.textures.sort_unstable();
            w.textures.dedup();
            w.buffers.sort_unstable();
            w.buffers.dedup();
            w
        })
        .collect()
}
