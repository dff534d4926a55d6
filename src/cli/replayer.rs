//! One capture being replayed: validated, ordered, lowered for the device and running in a
//! session, with every frame's per-pass samples kept so the timing report can be built at the
//! end. `replay` drives one; `diff` drives two on one device, frame by frame in turn.

use std::path::Path;

use anyhow::Context;
use framelab::analysis::report::{AnalyzeOptions, analyze};
use framelab::capture::model::PassId;
use framelab::capture::{self, Capture, Options};
use framelab::lower::{self, Lowered};
use framelab::timing::{self, PassTiming, Sample, TimingReport};
use framelab_replay::GpuContext;
use sha2::Digest;

/// Reads the capture file once: its bytes are hashed for the report and parsed from memory.
pub fn load(path: &Path, scale: f64) -> anyhow::Result<(Capture, String)> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let hash = format!("{:x}", sha2::Sha256::digest(&bytes));
    let options = Options {
        scale,
        ..Options::default()
    };
    let validated = capture::load::parse(path, &bytes)
        .and_then(|raw| capture::validate::validate(&raw, path, &options))
        .map_err(|e| {
            let details: Vec<String> = e.diagnostics().iter().map(|d| d.to_string()).collect();
            anyhow::anyhow!("{e}\n{}", details.join("\n"))
        })?;
    Ok((validated.capture, hash))
}

/// A capture loaded, validated and ordered (nothing on the GPU yet).
pub struct Loaded {
    pub capture: Capture,
    pub sha256: String,
    pub order: Vec<PassId>,
    pub scale: f64,
}

impl Loaded {
    pub fn new(path: &Path, scale: f64, cull: bool) -> anyhow::Result<Loaded> {
        let (capture, sha256) = load(path, scale)?;
        let analysis = analyze(&capture, AnalyzeOptions { cull })
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        Ok(Loaded {
            order: analysis.order,
            capture,
            sha256,
            scale,
        })
    }

    /// Loads a capture to replay: one that cannot be (an import) is refused before any
    /// device opens.
    pub fn for_replay(path: &Path, scale: f64, cull: bool) -> anyhow::Result<Loaded> {
        let loaded = Self::new(path, scale, cull)?;
        if let Some(why) = loaded.capture.not_replayable() {
            anyhow::bail!(why);
        }
        Ok(loaded)
    }

    /// The capture's plan for this device.
    pub fn lower(&self, ctx: &GpuContext) -> anyhow::Result<Lowered> {
        Ok(lower::lower(
            &self.capture,
            &self.order,
            ctx.device.features(),
            &ctx.summary.name,
        )?)
    }
}

/// A capture running on the device, with the samples of every frame so far.
pub struct Replayer {
    pub loaded: Loaded,
    pub pass_ids: Vec<PassId>,
    pub session: framelab_replay::Session,
    pub times: Vec<Vec<Sample>>,
}

impl Replayer {
    pub fn new(ctx: &GpuContext, loaded: Loaded, lowered: Lowered) -> anyhow::Result<Replayer> {
        Ok(Replayer {
            pass_ids: lowered.pass_ids,
            session: framelab_replay::Session::new(ctx, lowered.plan)?,
            loaded,
            times: Vec::new(),
        })
    }

    /// Runs frame `f` (stopping after plan pass `stop`, if given) and keeps its samples.
    pub fn frame(&mut self, f: u32, stop: Option<usize>) -> anyhow::Result<()> {
        let constants = lower::frame::constants(&self.loaded.capture, f);
        let measured = self.session.run_frame(&constants, stop)?;
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
        Ok(())
    }

    /// The timing report of the frames run, the first `warmup` of them marked as warm-up.
    pub fn report(&self, ctx: &GpuContext, warmup: u32) -> TimingReport {
        let capture = &self.loaded.capture;
        let times = &self.times;
        TimingReport {
            format_version: timing::FORMAT_VERSION,
            adapter: ctx.summary.name.clone(),
            backend: ctx.summary.backend.clone(),
            capture: capture.name.clone(),
            capture_sha256: self.loaded.sha256.clone(),
            scale: self.loaded.scale,
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
                .enumerate()
                .map(|(i, &id)| {
                    let p = capture.pass(id);
                    let mut writes: Vec<String> = p
                        .accesses
                        .iter()
                        .filter(|a| a.writes)
                        .map(|a| capture.resource(a.resource).name.clone())
                        .collect();
                    writes.sort();
                    writes.dedup();
                    let traffic = framelab::analysis::traffic::pass_traffic(capture, id);
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
                        gpu_untrusted: framelab::timing::untrusted_timestamps(
                            &ctx.summary.name,
                            &ctx.summary.device_type,
                            p.kind.as_str(),
                        ),
                    }
                })
                .collect(),
        }
    }
}
