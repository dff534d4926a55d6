//! The last stage of the journey `framelab_core::pipeline` starts: a lowered capture running
//! in a session on a device, with every frame's per-pass samples kept so the timing report can
//! be built at the end. `replay` drives one, `diff` two on one device frame by frame in turn,
//! and the inspector's worker one on its own thread.

use std::collections::BTreeMap;

use framelab_core::capture::model::{Capture, PassId, ResourceId};
use framelab_core::pipeline::{Analysed, Lowered};
use framelab_core::plan::Params;
use framelab_core::timing::{self, PassTiming, Sample, TimingReport};

use crate::device::GpuContext;
use crate::run::{ReplayError, Session};

/// A frame being replayed a pass at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Open {
    /// The frame's index: which frame constants it runs with (camera, time, jitter).
    pub frame: u32,
    /// How many of the plan's passes were submitted whole.
    pub done: usize,
    /// A pass submitted only up to one of its draws or dispatches (`Replaying::step`): what
    /// it writes is part way, so nothing can run on from here until the caller puts it back
    /// (`Replaying::restored`).
    pub partial: Option<usize>,
}

/// A capture running on the device, with the samples of every frame so far.
#[derive(Debug)]
pub struct Replaying {
    pub analysed: Analysed,
    /// The capture pass of each plan pass.
    pub pass_ids: Vec<PassId>,
    pub session: Session,
    /// Per frame run, per plan pass.
    pub times: Vec<Vec<Sample>>,
    /// Per frame run, per plan pass: pipeline statistics when the frame was counted.
    pub counts: Vec<Vec<Option<framelab_core::timing::counters::Counts>>>,
    adapter: String,
    device_type: wgpu::DeviceType,
    backend: String,
    /// The plan texture of each capture texture, and the plan buffer of each capture buffer.
    pub(crate) texture_of: BTreeMap<ResourceId, usize>,
    pub(crate) buffer_of: BTreeMap<ResourceId, usize>,
    /// The frame held open a pass at a time (`cursor`), and the last frame run whole.
    pub(crate) open: Option<Open>,
    pub(crate) last_whole: Option<u32>,
}

impl Replaying {
    /// Creates the plan's resources and pipelines on `ctx`.
    pub fn start(ctx: &GpuContext, lowered: Lowered) -> Result<Replaying, ReplayError> {
        Ok(Replaying {
            session: Session::new(ctx, lowered.plan)?,
            analysed: lowered.analysed,
            pass_ids: lowered.pass_ids,
            times: Vec::new(),
            counts: Vec::new(),
            adapter: ctx.summary.name.clone(),
            device_type: ctx.summary.device_type,
            backend: ctx.summary.backend.clone(),
            texture_of: lowered.texture_of,
            buffer_of: lowered.buffer_of,
            open: None,
            last_whole: None,
        })
    }

    pub fn capture(&self) -> &Capture {
        &self.analysed.capture
    }

    /// The frame constants of frame `f` (camera, time, jitter).
    pub fn constants(&self, f: u32) -> Params {
        framelab_core::lower::frame::constants(self.capture(), f)
    }

    /// Why this adapter's timestamps do not measure each plan pass, if they do not.
    pub fn untrusted(&self) -> Vec<Option<String>> {
        self.pass_ids
            .iter()
            .map(|&id| {
                timing::untrusted_timestamps(
                    &self.adapter,
                    self.device_type,
                    self.capture().pass(id).kind,
                )
            })
            .collect()
    }

    /// Runs frame `f` (stopping after plan pass `stop`, if given) and keeps its samples; the
    /// open frame, if any, is ended first.
    pub fn frame(&mut self, f: u32, stop: Option<usize>) -> Result<(), ReplayError> {
        self.release();
        let constants = self.constants(f);
        self.last_whole = None;
        let measured = self.session.run_frame(&constants, stop)?;
        if stop.is_none() {
            self.last_whole = Some(f);
        }
        self.times.push(
            measured
                .iter()
                .map(|t| Sample {
                    gpu_start_ns: t.gpu_start_ns,
                    gpu_ns: t.gpu_ns,
                    cpu_ns: t.cpu_ns,
                })
                .collect(),
        );
        self.counts
            .push(measured.iter().map(|t| t.counters).collect());
        Ok(())
    }

    /// The timing report of the frames run, the first `warmup` of them marked as warm-up.
    pub fn report(&self, warmup: u32) -> TimingReport {
        let capture = self.capture();
        let times = &self.times;
        let untrusted = self.untrusted();
        TimingReport {
            format_version: timing::FORMAT_VERSION,
            adapter: self.adapter.clone(),
            backend: self.backend.clone(),
            capture: capture.name.clone(),
            capture_sha256: self.analysed.sha256.clone().unwrap_or_default(),
            scale: capture.scale,
            frames: times.len() as u32,
            warmup,
            timestamp_period_ns: self.session.timestamp_period(),
            timestamps: if self.session.timestamp_pairs() {
                timing::StampLayout::Pairs
            } else {
                timing::StampLayout::Chained
            },
            passes: self
                .pass_ids
                .iter()
                .zip(untrusted)
                .enumerate()
                .map(|(i, (&id, gpu_untrusted))| {
                    let p = capture.pass(id);
                    let mut writes: Vec<String> = p
                        .accesses
                        .iter()
                        .filter(|a| a.writes)
                        .map(|a| capture.resource(a.resource).name.clone())
                        .collect();
                    writes.sort();
                    writes.dedup();
                    let traffic = framelab_core::analysis::traffic::pass_traffic(capture, id);
                    PassTiming {
                        name: p.name.clone(),
                        queue: capture.queue(p.queue).name.clone(),
                        marker_path: p.marker_path(),
                        kind: p.kind.as_str().to_owned(),
                        writes,
                        bytes_read: traffic.read,
                        bytes_written: traffic.written,
                        gpu_ns: times
                            .iter()
                            .map(|t| t.get(i).and_then(|x| x.gpu_ns))
                            .collect(),
                        cpu_ns: times
                            .iter()
                            .map(|t| t.get(i).map_or(0, |x| x.cpu_ns))
                            .collect(),
                        gpu_untrusted,
                        counters: timing::counters::Counters::from_frames(
                            &self
                                .counts
                                .iter()
                                .map(|f| f.get(i).copied().flatten())
                                .collect::<Vec<_>>(),
                        ),
                        work: Some(self.session.work(i)),
                    }
                })
                .collect(),
        }
    }
}

/// Runs frames `frames` of two replays on one device in turn, A B, B A, A B, ...: whatever
/// running second costs or saves (caches warm, clocks ramped) falls on both alike.
pub fn interleaved(
    a: &mut Replaying,
    b: &mut Replaying,
    frames: std::ops::Range<u32>,
) -> Result<(), ReplayError> {
    for f in frames {
        if f % 2 == 0 {
            a.frame(f, None)?;
            b.frame(f, None)?;
        } else {
            b.frame(f, None)?;
            a.frame(f, None)?;
        }
    }
    Ok(())
}
