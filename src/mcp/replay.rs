//! The replay behind `texture`, `read_texels`, `timings` and `what_if`: one worker thread per opened
//! capture, started on the first request, owning a device and a `Replaying` session (its
//! objects live on one thread). The
//! worker holds frame 0 open at the last pass it was asked for, so a request for that pass
//! or a later one continues from there instead of replaying from the start; an earlier pass
//! begins the frame again. A timing run takes a session of its own, so the held frame stays
//! where it was. The worker reports each pass or frame done (for progress notifications) and
//! stops between them when the request is cancelled. A what-if runs on a device of its own,
//! for the frame and its variant side by side.

use std::path::PathBuf;
use std::sync::{Arc, mpsc};
use std::thread::JoinHandle;

use framelab_core::analysis::report::AnalyzeOptions;
use framelab_core::capture::Options;
use framelab_core::pipeline::{Analysed, Loaded};
use framelab_replay::Replaying;
use framelab_replay::decode::{self, DecodedImage};
use tokio_util::sync::CancellationToken;

/// One texture wanted as it stands after a pass of frame 0.
pub struct Request {
    /// The capture texture's plan index is found by the worker from this name.
    pub resource: String,
    /// The pass after which to read it; `None`: after the whole frame.
    pub after: Option<String>,
    pub mip: u32,
    pub layer: u32,
    pub slice: u32,
    /// Called with (passes submitted, passes to submit) as the replay goes.
    pub progress: Box<dyn Fn(usize, usize) + Send>,
    pub cancel: CancellationToken,
    pub reply: tokio::sync::oneshot::Sender<anyhow::Result<Arc<DecodedImage>>>,
}

/// Frames replayed and timed, as `framelab replay --timings` does.
pub struct Timings {
    pub frames: u32,
    /// Count every pass's pipeline statistics too (the report's `counters`).
    pub counters: bool,
    /// Called with (frames done, frames to run).
    pub progress: Box<dyn Fn(usize, usize) + Send>,
    pub cancel: CancellationToken,
    pub reply: tokio::sync::oneshot::Sender<anyhow::Result<framelab_core::timing::TimingReport>>,
}

/// Bytes of a buffer as they stood after a pass of frame 0.
pub struct BufferRequest {
    pub resource: String,
    pub after: Option<String>,
    pub offset: u64,
    pub length: u64,
    pub progress: Box<dyn Fn(usize, usize) + Send>,
    pub cancel: CancellationToken,
    pub reply: tokio::sync::oneshot::Sender<anyhow::Result<BufferBytes>>,
}

/// The bytes read, and the ways the buffer can be read as rows (the inspector's).
pub struct BufferBytes {
    pub bytes: Vec<u8>,
    pub size: u64,
    pub layouts: Vec<framelab_core::buffer_views::LayoutChoice>,
}

/// What the worker is asked to do.
pub enum Job {
    Texture(Request),
    Buffer(BufferRequest),
    Timings(Timings),
}

/// A capture's replay worker.
pub struct Worker {
    jobs: Option<mpsc::Sender<Job>>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    pub fn start(path: PathBuf, scale: f64) -> Worker {
        let (jobs, inbox) = mpsc::channel::<Job>();
        let thread = std::thread::Builder::new()
            .name("mcp-replay".into())
            .spawn(move || serve(&path, scale, &inbox))
            .ok();
        Worker {
            jobs: Some(jobs),
            thread,
        }
    }

    pub fn send(&self, request: Job) -> anyhow::Result<()> {
        self.jobs
            .as_ref()
            .and_then(|j| j.send(request).ok())
            .ok_or_else(|| anyhow::anyhow!("the replay worker has stopped"))
    }
}

impl Drop for Worker {
    /// Closing the queue ends the worker after its current request.
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

type ReadKey = (usize, Option<usize>, u32, u32, u32);

/// The session and where frame 0 is held.
struct Held {
    replaying: Replaying,
    ctx: framelab_replay::GpuContext,
    /// The plan texture of each capture texture.
    texture_of: std::collections::BTreeMap<framelab_core::capture::model::ResourceId, usize>,
    /// The plan buffer of each capture buffer.
    buffer_of: std::collections::BTreeMap<framelab_core::capture::model::ResourceId, usize>,
    /// How each plan buffer can be read as rows.
    buffer_views: Vec<framelab_core::buffer_views::BufferView>,
    /// The last plan pass submitted in the open frame, if one is open.
    at: Option<usize>,
    /// The last subresource read back, by (plan texture, pass held at, mip, layer, slice):
    /// `texture` then `read_texels` of the same view read the GPU once.
    read_back: Option<(ReadKey, Arc<DecodedImage>)>,
}

fn start(path: &std::path::Path, scale: f64) -> anyhow::Result<Held> {
    let options = Options {
        scale,
        ..Options::default()
    };
    let analysed = Analysed::for_replay(path, &options, AnalyzeOptions { cull: false })?;
    let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())?;
    let lowered = analysed.lower(ctx.device.features(), &ctx.summary.name)?;
    let texture_of = lowered.texture_of.clone();
    let buffer_of = lowered.buffer_of.clone();
    let buffer_views = framelab_core::buffer_views::buffer_views(&lowered.plan);
    let replaying = Replaying::start(&ctx, lowered)?;
    Ok(Held {
        replaying,
        ctx,
        texture_of,
        buffer_of,
        buffer_views,
        at: None,
        read_back: None,
    })
}

fn serve(path: &std::path::Path, scale: f64, inbox: &mpsc::Receiver<Job>) {
    let mut held: Option<anyhow::Result<Held>> = None;
    while let Ok(job) = inbox.recv() {
        let after = match &job {
            Job::Timings(_) => None,
            Job::Texture(r) => Some(&r.after),
            Job::Buffer(r) => Some(&r.after),
        };
        // A pass before the one the frame is held at needs the frame's starting contents,
        // which the passes since have overwritten: the session starts again.
        if let (Some(after), Some(Ok(h))) = (after, &held)
            && let (Some(at), Some(stop)) = (h.at, stop_of(h, after).ok().flatten())
            && stop < at
        {
            held = None;
        }
        match job {
            Job::Timings(t) => {
                let report = timings(path, scale, &t);
                let _ = t.reply.send(report);
            }
            Job::Texture(r) => {
                let answer = match held.get_or_insert_with(|| start(path, scale)) {
                    Ok(h) => read(h, &r),
                    Err(e) => Err(anyhow::anyhow!("the capture cannot be replayed here: {e}")),
                };
                let _ = r.reply.send(answer);
            }
            Job::Buffer(r) => {
                let answer = match held.get_or_insert_with(|| start(path, scale)) {
                    Ok(h) => read_buffer(h, &r),
                    Err(e) => Err(anyhow::anyhow!("the capture cannot be replayed here: {e}")),
                };
                let _ = r.reply.send(answer);
            }
        }
    }
}

/// `t.frames` frames on a session of their own, and their timing report.
fn timings(
    path: &std::path::Path,
    scale: f64,
    t: &Timings,
) -> anyhow::Result<framelab_core::timing::TimingReport> {
    let mut h = start(path, scale)
        .map_err(|e| anyhow::anyhow!("the capture cannot be replayed here: {e}"))?;
    let frames = t.frames as usize;
    if !h.replaying.session.set_counting(t.counters) {
        return Err(anyhow::anyhow!(
            "{} has no pipeline statistics queries: work counters cannot be measured on it",
            h.ctx.summary.name
        ));
    }
    for f in 0..t.frames {
        if t.cancel.is_cancelled() {
            eprintln!(
                "framelab mcp: {}: timing cancelled before frame {} of {frames}",
                h.replaying.capture().name,
                f + 1
            );
            anyhow::bail!("cancelled");
        }
        h.replaying.frame(f, None)?;
        (t.progress)(f as usize + 1, frames);
    }
    Ok(h.replaying.report(0))
}

/// The plan pass after which a request reads (the last one when it names none).
fn stop_of(h: &Held, after: &Option<String>) -> anyhow::Result<Option<usize>> {
    match after {
        None => Ok(h.replaying.session.plan.passes.len().checked_sub(1)),
        Some(name) => {
            let id = h
                .replaying
                .capture()
                .passes
                .iter()
                .find(|p| &p.name == name)
                .ok_or_else(|| anyhow::anyhow!("no pass \"{name}\""))?
                .id;
            h.replaying
                .pass_ids
                .iter()
                .position(|&p| p == id)
                .map(Some)
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "pass \"{name}\" is not replayed (culled, or outside the replayed order)"
                    )
                })
        }
    }
}

/// The plan texture or buffer (`of`, named `kind`) the capture resource `name` became.
fn plan_index(
    h: &Held,
    of: &std::collections::BTreeMap<framelab_core::capture::model::ResourceId, usize>,
    name: &str,
    kind: &str,
) -> anyhow::Result<usize> {
    let resource = h
        .replaying
        .capture()
        .resources
        .iter()
        .find(|x| x.name == name)
        .ok_or_else(|| anyhow::anyhow!("no resource \"{name}\""))?
        .id;
    of.get(&resource)
        .copied()
        .ok_or_else(|| anyhow::anyhow!("\"{name}\" is not a {kind} the replay creates"))
}

fn read(h: &mut Held, r: &Request) -> anyhow::Result<Arc<DecodedImage>> {
    let texture = plan_index(h, &h.texture_of, &r.resource, "texture")?;
    advance(h, &r.after, &r.cancel, &r.progress)?;
    let key = (texture, h.at, r.mip, r.layer, r.slice);
    if let Some((k, image)) = &h.read_back
        && *k == key
    {
        return Ok(image.clone());
    }
    let spec = &h.replaying.session.plan.textures[texture];
    let format = decode::readable_format(spec).map_err(|e| anyhow::anyhow!(e.0))?;
    let images = decode::read_subresource(
        &h.ctx.device,
        &h.ctx.queue,
        h.replaying.session.texture_in_frame(texture),
        spec,
        format,
        r.mip,
        r.layer,
    )?;
    let image = Arc::new(
        images
            .into_iter()
            .find(|i| i.z.unwrap_or(0) == r.slice)
            .ok_or_else(|| {
                anyhow::anyhow!("no slice {} of mip {} layer {}", r.slice, r.mip, r.layer)
            })?,
    );
    h.read_back = Some((key, image.clone()));
    Ok(image)
}

/// Holds frame 0 open right after the pass `after` names: continues from the pass it is held
/// at, or begins the frame (a fresh session, see `serve`).
fn advance(
    h: &mut Held,
    after: &Option<String>,
    cancel: &CancellationToken,
    progress: &(dyn Fn(usize, usize) + Send),
) -> anyhow::Result<()> {
    let stop = stop_of(h, after)?;
    let from = match (h.at, stop) {
        (Some(at), Some(stop)) if at <= stop => at + 1,
        // A fresh session (`serve` starts one again for an earlier pass): begin the frame.
        _ => {
            let constants = h.replaying.constants(0);
            h.replaying.session.begin_frame(&constants)?;
            h.at = None;
            0
        }
    };
    if let Some(stop) = stop {
        for i in from..=stop {
            if cancel.is_cancelled() {
                // The client hears nothing more of a cancelled request; the log says where
                // the replay stopped.
                eprintln!(
                    "framelab mcp: {}: replay cancelled before pass {} of {}",
                    h.replaying.capture().name,
                    i + 1,
                    stop + 1
                );
                anyhow::bail!("cancelled");
            }
            h.replaying.session.submit_pass(i)?;
            h.at = Some(i);
            progress(i + 1, stop + 1);
        }
    }
    Ok(())
}

fn read_buffer(h: &mut Held, r: &BufferRequest) -> anyhow::Result<BufferBytes> {
    let buffer = plan_index(h, &h.buffer_of, &r.resource, "buffer")?;
    advance(h, &r.after, &r.cancel, &r.progress)?;
    let source = h.replaying.session.buffer_in_frame(buffer);
    let size = source.size();
    if r.offset >= size {
        return Err(anyhow::anyhow!(
            "offset {} is past the end of \"{}\" ({size} bytes)",
            r.offset,
            r.resource
        ));
    }
    let length = r.length.min(size - r.offset);
    let bytes = framelab_replay::read_buffer_range(
        &h.ctx.device,
        &h.ctx.queue,
        source,
        r.offset,
        length,
        &r.resource,
    )?;
    let layouts = h
        .buffer_views
        .iter()
        .find(|v| v.plan_index == buffer)
        .map(|v| v.layouts.clone())
        .unwrap_or_default();
    Ok(BufferBytes {
        bytes,
        size,
        layouts,
    })
}

/// A what-if on a capture file, on a device of its own: the frame and its variant made,
/// judged, and measured where safe (`framelab_replay::what_if`, as `framelab what-if`).
pub fn what_if(
    path: &std::path::Path,
    scale: f64,
    edits: &[framelab_core::whatif::Edit],
    options: &framelab_replay::what_if::Options,
) -> anyhow::Result<framelab_replay::what_if::WhatIf> {
    use framelab_replay::what_if::{judge, measure};
    let loaded = Loaded::read_hashed(path)?;
    let capture_options = Options {
        scale,
        ..Options::default()
    };
    let pair = framelab_core::whatif::variant(loaded, None, edits, &capture_options)?;
    let given = edits.iter().map(|e| e.spelling()).collect();
    let mut report = judge(&pair, path.display().to_string(), given, options.tolerance);
    if report.safe {
        let ctx = framelab_replay::open_device(None, framelab_core::lower::wanted_features())?;
        measure(&mut report, &ctx, pair, options)?;
    }
    Ok(report)
}
