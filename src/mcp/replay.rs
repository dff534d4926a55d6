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

/// A capture's replay worker: its jobs served in turn on a thread of its own.
pub struct Worker(framelab_replay::Worker<Job>);

impl Worker {
    pub fn start(path: PathBuf, scale: f64) -> Worker {
        Worker(framelab_replay::Worker::start("mcp-replay", move |inbox| {
            serve(&path, scale, &inbox)
        }))
    }

    pub fn send(&self, request: Job) -> anyhow::Result<()> {
        if self.0.send(request) {
            Ok(())
        } else {
            Err(anyhow::anyhow!("the replay worker has stopped"))
        }
    }
}

/// (plan texture, passes done in the held frame, mip, layer, slice).
type ReadKey = (usize, usize, u32, u32, u32);

/// The session, its device, and the last subresource read back.
struct Held {
    replaying: Replaying,
    ctx: framelab_replay::GpuContext,
    /// How each plan buffer can be read as rows.
    buffer_views: Vec<framelab_core::buffer_views::BufferView>,
    /// The last subresource read back: `texture` then `read_texels` of the same view read the
    /// GPU once.
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
    let buffer_views = framelab_core::buffer_views::buffer_views(&lowered.plan);
    let replaying = Replaying::start(&ctx, lowered)?;
    Ok(Held {
        replaying,
        ctx,
        buffer_views,
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
            && let (Some(open), Ok(done)) = (h.replaying.open(), done_after(h, after))
            && done < open.done
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

/// How many plan passes a request reads after: through the pass it names, or all of them.
fn done_after(h: &Held, after: &Option<String>) -> anyhow::Result<usize> {
    match after {
        None => Ok(h.replaying.session.plan.passes.len()),
        Some(name) => Ok(h.replaying.plan_pass(name)? + 1),
    }
}

fn read(h: &mut Held, r: &Request) -> anyhow::Result<Arc<DecodedImage>> {
    let texture = h.replaying.plan_texture(&r.resource)?;
    let done = advance(h, &r.after, &r.cancel, &r.progress)?;
    let key = (texture, done, r.mip, r.layer, r.slice);
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

/// Holds frame 0 open right after the pass `after` names (the frame cursor runs on from where
/// it is held, or begins the frame: `serve` starts a fresh session for an earlier pass), and
/// returns how many passes are done.
fn advance(
    h: &mut Held,
    after: &Option<String>,
    cancel: &CancellationToken,
    progress: &(dyn Fn(usize, usize) + Send),
) -> anyhow::Result<usize> {
    let done = done_after(h, after)?;
    let name = h.replaying.capture().name.clone();
    let mut replayed = false;
    h.replaying.hold(0, done, |i| {
        if cancel.is_cancelled() {
            // The client hears nothing more of a cancelled request; the log says where the
            // replay stopped.
            eprintln!(
                "framelab mcp: {name}: replay cancelled before pass {} of {done}",
                i + 1
            );
            anyhow::bail!("cancelled");
        }
        progress(i, done);
        replayed = true;
        Ok(())
    })?;
    // A frame held where it was asked for replays nothing and reports nothing.
    if replayed {
        progress(done, done);
    }
    Ok(done)
}

fn read_buffer(h: &mut Held, r: &BufferRequest) -> anyhow::Result<BufferBytes> {
    let buffer = h.replaying.plan_buffer(&r.resource)?;
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
