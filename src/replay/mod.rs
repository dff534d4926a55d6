//! `framelab replay`: validate, order (and optionally cull) a capture, open a GPU device,
//! lower the capture into a replay plan, run N frames, and write the timing report, a Chrome
//! trace and every texture as PNG/EXR. wgpu exposes one queue, so passes from the capture's
//! graphics, compute and copy queues run in DAG order on it; the reports keep each pass's
//! capture queue.

pub mod formats;
pub mod frame;
pub mod generate;
pub mod lower;

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use framelab_replay::wgpu::Features;
use serde::Serialize;
use sha2::Digest;

use crate::analysis::report::{AnalyzeOptions, analyze};
use crate::capture::{self, Capture, Options};

#[derive(Debug, Clone)]
pub struct ReplayOptions {
    pub scale: f64,
    pub frames: u32,
    pub adapter: Option<String>,
    pub cull: bool,
    pub out: Option<PathBuf>,
    /// Export the state right after this pass of the last frame.
    pub after: Option<String>,
    /// Export only this resource.
    pub resource: Option<String>,
    pub timings: Option<PathBuf>,
    pub trace: Option<PathBuf>,
}

/// What happened, for the command to print.
#[derive(Debug)]
pub enum Event<'a> {
    Adapter(&'a str),
    Note(&'a str),
    Frame { index: u32, total: u32 },
    Exported { files: usize },
}

#[derive(Debug, Serialize)]
pub struct TimingReport {
    pub adapter: String,
    pub backend: String,
    pub capture: String,
    pub capture_sha256: String,
    pub scale: f64,
    pub frames: u32,
    pub passes: Vec<PassTiming>,
}

#[derive(Debug, Serialize)]
pub struct PassTiming {
    pub name: String,
    pub queue: String,
    pub marker_path: String,
    /// One per frame; `null` where the adapter could not time the pass.
    pub gpu_ns: Vec<Option<u64>>,
    pub cpu_ns: Vec<u64>,
}

#[derive(Debug, Serialize)]
struct Manifest<'a> {
    capture: &'a str,
    frames: u32,
    after: Option<&'a str>,
    files: &'a [framelab_replay::export::ExportedFile],
    skipped: &'a [framelab_replay::export::Skipped],
}

/// Features requested when the adapter has them.
pub fn wanted_features() -> Features {
    Features::TIMESTAMP_QUERY
        | Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | Features::TIMESTAMP_QUERY_INSIDE_PASSES
        | Features::TEXTURE_COMPRESSION_BC
        | Features::DEPTH32FLOAT_STENCIL8
        | Features::TEXTURE_FORMAT_16BIT_NORM
        | Features::RG11B10UFLOAT_RENDERABLE
        | Features::FLOAT32_FILTERABLE
        | Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
}

pub fn load(path: &Path, scale: f64) -> anyhow::Result<Capture> {
    capture::load_and_validate(
        path,
        &Options {
            scale,
            ..Options::default()
        },
    )
    .map(|v| v.capture)
    .map_err(|e| {
        let details: Vec<String> = e.diagnostics().iter().map(|d| d.to_string()).collect();
        anyhow::anyhow!("{e}\n{}", details.join("\n"))
    })
}

pub fn replay(
    path: &Path,
    options: &ReplayOptions,
    mut on: impl FnMut(Event<'_>),
) -> anyhow::Result<TimingReport> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let capture = load(path, options.scale)?;
    let analysis = analyze(&capture, AnalyzeOptions { cull: options.cull })
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let order: Vec<crate::capture::model::PassId> = analysis
        .order
        .iter()
        .filter_map(|&p| {
            capture
                .pass_by_name(&analysis.model.passes[p as usize].name)
                .map(|d| d.id)
        })
        .collect();
    let ctx = framelab_replay::open_device(options.adapter.as_deref(), wanted_features())?;
    on(Event::Adapter(&ctx.summary.to_string()));
    let available = ctx.device.features();
    let lowered = lower::lower(&capture, &order, available, &ctx.summary.name)?;
    for n in &lowered.notes {
        on(Event::Note(n));
    }
    if !available.contains(Features::TIMESTAMP_QUERY) {
        on(Event::Note(
            "the adapter has no timestamp queries: GPU times are not measured",
        ));
    }
    let stop_after = match &options.after {
        Some(name) => Some(
            lowered
                .plan
                .passes
                .iter()
                .position(|p| &p.name == name)
                .with_context(|| format!("--after: no pass \"{name}\" in the replayed order"))?,
        ),
        None => None,
    };
    let export_texture = match &options.resource {
        Some(name) => Some(
            lowered
                .plan
                .textures
                .iter()
                .position(|t| &t.name == name)
                .with_context(|| format!("--resource: no texture \"{name}\" is replayed"))?,
        ),
        None => None,
    };
    let pass_count = lowered.plan.passes.len();
    let mut session = framelab_replay::Session::new(&ctx, lowered.plan)?;
    let mut times: Vec<Vec<framelab_replay::PassTime>> = Vec::new();
    let frames = options.frames.max(1);
    for f in 0..frames {
        on(Event::Frame {
            index: f,
            total: frames,
        });
        let constants = frame::constants(&capture, f);
        let stop = if f + 1 == frames { stop_after } else { None };
        times.push(session.run_frame(&constants, stop)?);
    }
    let report = TimingReport {
        adapter: ctx.summary.name.clone(),
        backend: ctx.summary.backend.clone(),
        capture: capture.name.clone(),
        capture_sha256: format!("{:x}", sha2::Sha256::digest(&bytes)),
        scale: options.scale,
        frames,
        passes: (0..pass_count)
            .map(|i| {
                let p = capture.pass(lowered.pass_ids[i]);
                PassTiming {
                    name: p.name.clone(),
                    queue: capture.queue(p.queue).name.clone(),
                    marker_path: p.marker_path(),
                    gpu_ns: times
                        .iter()
                        .map(|t| t.get(i).and_then(|x| x.gpu_ns))
                        .collect(),
                    cpu_ns: times
                        .iter()
                        .map(|t| t.get(i).map_or(0, |x| x.cpu_ns))
                        .collect(),
                }
            })
            .collect(),
    };
    if let Some(file) = &options.timings {
        crate::output::write_atomically(
            file,
            (serde_json::to_string_pretty(&report)? + "\n").as_bytes(),
        )?;
    }
    if let Some(file) = &options.trace {
        crate::output::write_atomically(file, trace(&report, &times).as_bytes())?;
    }
    if let Some(out) = &options.out {
        let files = export(
            &session,
            out,
            &capture.name,
            frames,
            options.after.as_deref(),
            export_texture,
        )?;
        on(Event::Exported { files });
    }
    Ok(report)
}

/// Chrome trace-event JSON: one track per capture queue, frames laid end to end.
fn trace(report: &TimingReport, times: &[Vec<framelab_replay::PassTime>]) -> String {
    let mut queues: Vec<&str> = report.passes.iter().map(|p| p.queue.as_str()).collect();
    queues.sort_unstable();
    queues.dedup();
    let mut events = Vec::new();
    for (i, q) in queues.iter().enumerate() {
        events.push(serde_json::json!({"name": "thread_name", "ph": "M", "pid": 1, "tid": i + 1, "args": {"name": q}}));
    }
    let mut frame_start_us = 0.0f64;
    for (f, frame) in times.iter().enumerate() {
        let mut cursor = 0.0f64;
        let mut frame_end = 0.0f64;
        for (i, t) in frame.iter().enumerate() {
            let p = &report.passes[i];
            let tid = queues.iter().position(|q| *q == p.queue).unwrap_or(0) + 1;
            let (start, dur) = match (t.gpu_start_ns, t.gpu_ns) {
                (Some(s), Some(d)) => (s as f64 / 1000.0, d as f64 / 1000.0),
                _ => (cursor, t.cpu_ns as f64 / 1000.0),
            };
            cursor = start + dur;
            frame_end = frame_end.max(start + dur);
            events.push(serde_json::json!({
                "name": p.name, "cat": p.marker_path, "ph": "X", "pid": 1, "tid": tid,
                "ts": frame_start_us + start, "dur": dur.max(0.001),
                "args": {"frame": f, "queue": p.queue, "gpu_ns": t.gpu_ns, "cpu_ns": t.cpu_ns}
            }));
        }
        frame_start_us += frame_end + 1.0;
    }
    serde_json::to_string_pretty(
        &serde_json::json!({"traceEvents": events, "displayTimeUnit": "ns"}),
    )
    .unwrap_or_default()
        + "\n"
}

/// Writes every texture (or one) into a staging folder, then replaces `out` with it.
fn export(
    session: &framelab_replay::Session,
    out: &Path,
    capture: &str,
    frames: u32,
    after: Option<&str>,
    only: Option<usize>,
) -> anyhow::Result<usize> {
    use framelab_replay::export;
    if out.exists()
        && !(out.join("manifest.json").is_file()
            || out
                .read_dir()
                .map(|mut d| d.next().is_none())
                .unwrap_or(false))
    {
        bail!(
            "{} exists and is not an earlier framelab export (no manifest.json); choose another --out",
            out.display()
        );
    }
    let staging = export::staging_dir(out);
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging).with_context(|| format!("creating {}", staging.display()))?;
    let result = (|| -> anyhow::Result<usize> {
        let mut files = Vec::new();
        let mut skipped = Vec::new();
        for (i, spec) in session.plan.textures.iter().enumerate() {
            if only.is_some_and(|o| o != i) {
                continue;
            }
            let (f, s) = export::export_texture(
                &session.device,
                &session.queue,
                session.texture(i),
                spec,
                &staging,
            )?;
            files.extend(f);
            skipped.extend(s);
        }
        let manifest = Manifest {
            capture,
            frames,
            after,
            files: &files,
            skipped: &skipped,
        };
        std::fs::write(
            staging.join("manifest.json"),
            serde_json::to_string_pretty(&manifest)? + "\n",
        )?;
        Ok(files.len())
    })();
    match result {
        Ok(n) => {
            if out.exists() {
                std::fs::remove_dir_all(out)
                    .with_context(|| format!("replacing {}", out.display()))?;
            }
            std::fs::rename(&staging, out)
                .with_context(|| format!("moving the export into {}", out.display()))?;
            Ok(n)
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&staging);
            Err(e)
        }
    }
}
