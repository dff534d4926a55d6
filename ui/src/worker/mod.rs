//! The replay worker: a thread that owns the replay session, on a device and queue of its own,
//! so the UI thread never submits to or waits on them. It creates the session's pipelines,
//! times a whole frame 0, then replays frame 1 a pass at a time, keeping a copy of what each
//! pass writes (`snapshots`); every pass it has finished can be browsed at once. A view is then
//! served from those copies: the texture as of the pass, read back for exact values (the last
//! few read-backs are kept), drawn into a display image and read back as pixels the UI uploads
//! to its own renderer. Only a copy the memory budget evicted costs a replay up to its pass.
//! Views asked for while it works are skipped to the latest; saves are carried out in order.

mod history;
mod snapshots;
mod steps;

use std::collections::{BTreeSet, VecDeque};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use framelab_core::pipeline::Lowered;
use framelab_replay::decode::{
    DecodedImage, read_stencil_subresource, read_subresource, readable_format,
};
use framelab_replay::{GpuContext, Replaying};

pub use self::history::{HistoryRequest, HistoryRow, PixelHistory};
pub use self::snapshots::{Found, PassWrites, Snapshots, texture_bytes};
use crate::model::{PassTime, Sampling, Timings};
use crate::visualise::{Controls, Subresource, Visualiser};

/// What the UI wants on screen.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRequest {
    /// The frame as it is right after this pass (plan index).
    pub pass: usize,
    /// Or right after this draw or dispatch of the pass (its index among them).
    pub step: Option<usize>,
    pub texture: Option<TextureRequest>,
    /// A buffer to read back (plan index).
    pub buffer: Option<usize>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TextureRequest {
    pub plan_index: usize,
    pub sampling: Sampling,
    pub volume: bool,
    pub sub: Subresource,
    pub controls: Controls,
    /// Texels per display pixel along each axis: a 4096x4096 shadow map fitted into a panel a
    /// quarter as wide is drawn at 1024x1024; zoomed in, at every texel. The values read out
    /// are always every texel's.
    pub stride: u32,
}

/// How a view is saved: the image as shown (PNG), or the subresource's values (EXR).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SaveAs {
    Png,
    Exr,
}

enum Command {
    View(ViewRequest),
    Save(ViewRequest, SaveAs, PathBuf),
    /// Small images of these textures as of a pass, drawn when nothing else waits.
    Thumbnails(usize, Vec<TextureRequest>),
    History(HistoryRequest),
}

/// The longer side of a thumbnail, in pixels.
pub const THUMBNAIL_SIZE: u32 = 96;

/// Why the worker could not answer a view or a save; shown in the status bar or beside the
/// save button.
#[derive(Debug, thiserror::Error)]
pub enum WorkerError {
    #[error(transparent)]
    Replay(#[from] framelab_replay::ReplayError),
    #[error(transparent)]
    Read(#[from] framelab_replay::decode::ReadError),
    #[error(transparent)]
    Readback(#[from] framelab_replay::ReadbackError),
    #[error(transparent)]
    Export(#[from] framelab_replay::export::ExportError),
    #[error("no texture is shown")]
    NothingShown,
    /// The viewed subresource has no values to save; why (its format has no decoder ...).
    #[error("{0}")]
    NotRead(String),
    #[error("the display image read back empty")]
    EmptyDisplay,
    #[error("no buffer {0} in the replay plan")]
    NoBuffer(usize),
    #[error("nothing to save: open a texture and name a file")]
    NothingToSave,
    /// Asked of a pass the frame has not reached, or of an evicted copy while the frame
    /// replays: served once it can be.
    #[error("not replayed yet")]
    Later,
}

/// When the shown resource was last written in the browsed frame, as of the view's pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Written {
    /// By this plan pass.
    After(usize),
    /// Not yet this frame: its contents are those the frame started with (the previous
    /// frame's, or the capture's initial contents).
    NotYet,
    /// No pass of the frame writes it.
    Never,
    /// By this pass, up to and including draw or dispatch `step`.
    Step { pass: usize, step: usize },
}

/// What the worker sends back.
#[derive(Debug)]
pub enum Reply {
    Progress(String),
    /// Everything the worker does on its own at start is done: the browsed frame and the
    /// timed frames.
    Ready,
    /// Passes `0..=done` of the browsed frame (of `total`) can be viewed.
    Replayed {
        done: usize,
        total: usize,
    },
    /// Per plan pass, from the last timed frame.
    Timings(Timings),
    Shown(Box<Shown>),
    /// A save finished: the file written, or why not.
    Saved(Result<String, WorkerError>),
    /// A texel's history through the frame, or why there is none.
    History(Result<Arc<PixelHistory>, WorkerError>),
    /// A thumbnail of plan texture `texture` as of `pass` (`None`: its copy was evicted, and a
    /// thumbnail never costs a replay).
    Thumbnail {
        pass: usize,
        texture: usize,
        image: Option<egui::ColorImage>,
    },
    Failed(WorkerError),
}

#[derive(Debug)]
pub struct Shown {
    pub request: ViewRequest,
    /// The display image of the request's texture, as pixels for the UI's own renderer.
    pub display: Option<egui::ColorImage>,
    /// The viewed subresource read back and decoded, for exact pixel values; `None` where the
    /// format has no decoder (its reason in `note`).
    pub decoded: Option<Arc<DecodedImage>>,
    pub note: Option<String>,
    /// When the texture was last written, as of the pass.
    pub written: Option<Written>,
    /// The subresource's size in texels (the display image is smaller by the stride).
    pub texels: [u32; 2],
    /// The decoded values' finite range (for auto-fit).
    pub range: Option<(f32, f32)>,
    /// The requested buffer's bytes as of the pass (at most [`MAX_BUFFER_READ`]).
    pub buffer: Option<Arc<Vec<u8>>>,
}

/// A buffer's bytes as of a pass, keyed by (pass, plan buffer).
pub type BufferBytes = ((usize, usize), Arc<Vec<u8>>);

/// The buffer viewer reads at most this many bytes of a buffer, so a huge buffer costs a
/// bounded copy; the viewer says when it shows a prefix.
pub const MAX_BUFFER_READ: u64 = 64 << 20;

/// Read-backs kept, most recent first: re-opening one of these textures costs only the
/// display draw.
const READS_KEPT: usize = 8;

/// What the worker needs to start: the device it replays on (its own, not the UI's), the
/// lowered capture, what each plan pass writes, the whole frames to time and the bytes of pass
/// copies it may keep.
#[derive(Debug)]
pub struct Launch {
    pub ctx: GpuContext,
    pub lowered: Lowered,
    pub writes: Vec<PassWrites>,
    pub timed_frames: u32,
    pub budget: u64,
}

/// The UI's end of the worker. Dropping it stops the worker at its next pass or frame and
/// waits for it, so no replay is still using the device when the process exits.
#[derive(Debug)]
pub struct Worker {
    requests: framelab_replay::Worker<Command>,
    pub replies: Receiver<Reply>,
}

impl Worker {
    /// Starts the worker: it sets the replay up on its own thread and reports as it goes.
    pub fn start(launch: Launch) -> Worker {
        let (tx, replies) = std::sync::mpsc::channel();
        let requests = framelab_replay::Worker::start("inspector-replay", move |rx| {
            if let Err(Stop::Failed(e)) = run(launch, &rx, &tx) {
                let _ = tx.send(Reply::Failed(e));
            }
        });
        Worker { requests, replies }
    }

    fn send(&self, command: Command) -> bool {
        self.requests.send(command)
    }

    /// Asks for a view; `false` when the worker has stopped.
    pub fn request(&self, view: ViewRequest) -> bool {
        self.send(Command::View(view))
    }

    /// Asks for thumbnails of `textures` as of `pass`, answered one [`Reply::Thumbnail`] each;
    /// a later call replaces what is left of an earlier one.
    pub fn thumbnails(&self, pass: usize, textures: Vec<TextureRequest>) -> bool {
        self.send(Command::Thumbnails(pass, textures))
    }

    /// Asks for the history of a texel; answered with [`Reply::History`].
    pub fn history(&self, request: HistoryRequest) -> bool {
        self.send(Command::History(request))
    }

    /// Asks for `view` to be written to `path`; answered with [`Reply::Saved`].
    pub fn save(&self, view: ViewRequest, how: SaveAs, path: PathBuf) -> bool {
        self.send(Command::Save(view, how, path))
    }
}

/// Why the worker stopped.
enum Stop {
    /// The UI went away.
    Closed,
    Failed(WorkerError),
}

impl<E: Into<WorkerError>> From<E> for Stop {
    fn from(e: E) -> Stop {
        Stop::Failed(e.into())
    }
}

/// Where a texture's or buffer's contents as of a pass were found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Origin {
    /// The copy made after this pass (`None`: at the frame's start).
    After(Option<usize>),
    /// The resource itself: nothing in the frame writes it.
    Live,
    /// The pass replayed up to one of its draws or dispatches.
    Step(usize, usize),
}

impl Origin {
    fn written(self) -> Written {
        match self {
            Origin::After(Some(p)) => Written::After(p),
            Origin::After(None) => Written::NotYet,
            Origin::Live => Written::Never,
            Origin::Step(pass, step) => Written::Step { pass, step },
        }
    }
}

/// One subresource of a texture read back (of a 3D texture, every slice of a mip), decoded,
/// or why it could not be.
struct ReadBack {
    /// Plan texture, where it came from, whether the stencil aspect was read, and the mip and
    /// layer.
    key: (usize, Origin, bool, (u32, u32)),
    /// Each decoded image with its finite range (found once, at the read).
    images: Vec<(Arc<DecodedImage>, (f32, f32))>,
    note: Option<String>,
}

/// A buffer read back: (plan buffer, where it came from) and its bytes.
type ReadBuffer = ((usize, Origin), Arc<Vec<u8>>);

struct State {
    replaying: Replaying,
    /// What each plan pass submits (the plan does not change, so worked out once).
    work: Vec<Option<framelab_core::timing::counters::Work>>,
    writes: Vec<PassWrites>,
    snaps: Snapshots,
    /// The browsed frame is being replayed: nothing may replay over it.
    browsing: bool,
    reads: VecDeque<ReadBack>,
    /// The last buffer read back: (plan buffer, origin) and its bytes.
    buffer: Option<ReadBuffer>,
    visualiser: Visualiser,
    /// What the pass wrote up to one of its draws: (pass, step) and copies of its textures.
    step: Option<(
        (usize, usize),
        std::collections::BTreeMap<usize, wgpu::Texture>,
    )>,
    /// Frame 1 held open at a pass whose draws are shown (see `steps`).
    open: Option<steps::Open>,
}

/// Commands not yet carried out: the latest view, and saves in order.
#[derive(Default)]
struct Pending {
    view: Option<ViewRequest>,
    saves: VecDeque<(ViewRequest, SaveAs, PathBuf)>,
    thumbnails: Option<(usize, VecDeque<TextureRequest>)>,
    history: Option<HistoryRequest>,
}

impl Pending {
    fn push(&mut self, command: Command) {
        match command {
            Command::View(v) => self.view = Some(v),
            Command::Save(v, how, path) => self.saves.push_back((v, how, path)),
            Command::Thumbnails(pass, list) => self.thumbnails = Some((pass, list.into())),
            Command::History(h) => self.history = Some(h),
        }
    }

    /// Takes every command sent so far without waiting.
    fn drain(&mut self, rx: &Receiver<Command>) -> Result<(), Stop> {
        loop {
            match rx.try_recv() {
                Ok(c) => self.push(c),
                Err(TryRecvError::Empty) => return Ok(()),
                Err(TryRecvError::Disconnected) => return Err(Stop::Closed),
            }
        }
    }

    /// Waits for a command, then takes the rest.
    fn wait(&mut self, rx: &Receiver<Command>) -> Result<(), Stop> {
        let c = rx.recv().map_err(|_| Stop::Closed)?;
        self.push(c);
        self.drain(rx)
    }
}

fn run(launch: Launch, rx: &Receiver<Command>, tx: &Sender<Reply>) -> Result<(), Stop> {
    let Launch {
        ctx,
        lowered,
        writes,
        timed_frames,
        budget,
    } = launch;
    let send = |r: Reply| tx.send(r).map_err(|_| Stop::Closed);
    send(Reply::Progress(format!(
        "creating {} passes' pipelines and resources",
        lowered.plan.passes.len()
    )))?;
    let mut replaying = Replaying::start(&ctx, lowered)?;
    // Timed frames count each pass's work too (the timeline can be coloured by it); where the
    // adapter cannot count, passes show no counters.
    replaying.session.set_counting(true);
    let plan = &replaying.session.plan;
    let snaps = Snapshots::new(plan.textures.len(), plan.buffers.len(), budget);
    let work = (0..replaying.session.plan.passes.len())
        .map(|i| Some(replaying.session.work(i)))
        .collect();
    let mut s = State {
        replaying,
        work,
        writes,
        snaps,
        browsing: false,
        reads: VecDeque::new(),
        buffer: None,
        visualiser: Visualiser::default(),
        step: None,
        open: None,
    };
    let mut pending = Pending::default();
    send(Reply::Progress("timing frame 0".into()))?;
    send(Reply::Timings(time_frame(&mut s, 0)?))?;
    browse_frame(&mut s, rx, tx, &mut pending)?;
    for f in 2..=timed_frames {
        pending.drain(rx)?;
        serve(&mut s, &mut pending, rx, tx)?;
        send(Reply::Progress(format!("timing frame {f}")))?;
        send(Reply::Timings(time_frame(&mut s, f)?))?;
    }
    send(Reply::Progress(ready(&s)))?;
    send(Reply::Ready)?;
    loop {
        serve(&mut s, &mut pending, rx, tx)?;
        pending.wait(rx)?;
    }
}

fn ready(s: &State) -> String {
    format!(
        "ready: {} MiB of pass copies kept{}",
        s.snaps.used() >> 20,
        if s.snaps.evicted > 0 {
            format!(", {} evicted by the memory budget", s.snaps.evicted)
        } else {
            String::new()
        }
    )
}

/// Runs frame `f` whole and returns its per-pass GPU times.
fn time_frame(s: &mut State, f: u32) -> Result<Timings, Stop> {
    steps::close(s);
    let untrusted = s.replaying.untrusted();
    let times = s.replaying.run_whole(f)?;
    let trusted = |i: usize| untrusted.get(i).is_none_or(Option::is_none);
    Ok(Timings {
        source: "replay".into(),
        passes: times
            .iter()
            .enumerate()
            .map(|(i, t)| {
                Some(PassTime {
                    start_ns: t.gpu_start_ns? as f64,
                    gpu_ns: t.gpu_ns? as f64,
                    measured: trusted(i),
                    counters: t.counters,
                })
            })
            .collect(),
        note: untrusted.iter().flatten().next().cloned(),
        work: s.work.clone(),
    })
}

/// Replays frame 1 a pass at a time, copying what each pass writes (and, first, what the
/// frame will write, as it starts), and serves views of the passes done between passes.
fn browse_frame(
    s: &mut State,
    rx: &Receiver<Command>,
    tx: &Sender<Reply>,
    pending: &mut Pending,
) -> Result<(), Stop> {
    s.browsing = true;
    // Frame 1 begun after frame 0, which `time_frame` ran whole.
    s.replaying
        .hold(1, 0, |_| Ok::<(), framelab_replay::ReplayError>(()))?;
    let textures: BTreeSet<usize> = s.writes.iter().flat_map(|w| w.textures.clone()).collect();
    let buffers: BTreeSet<usize> = s.writes.iter().flat_map(|w| w.buffers.clone()).collect();
    keep(s, None, &textures, &buffers);
    let total = s.replaying.session.plan.passes.len();
    for i in 0..total {
        let name = s.replaying.session.plan.passes[i].name.clone();
        tx.send(Reply::Progress(format!(
            "replaying frame 1: pass {} of {total}, {name}",
            i + 1
        )))
        .map_err(|_| Stop::Closed)?;
        s.replaying
            .hold(1, i + 1, |_| Ok::<(), framelab_replay::ReplayError>(()))?;
        let w = s.writes.get(i).cloned().unwrap_or_default();
        keep(
            s,
            Some(i),
            &w.textures.into_iter().collect(),
            &w.buffers.into_iter().collect(),
        );
        s.snaps.mark_done(i);
        tx.send(Reply::Replayed { done: i, total })
            .map_err(|_| Stop::Closed)?;
        pending.drain(rx)?;
        serve(s, pending, rx, tx)?;
    }
    s.replaying.release();
    s.browsing = false;
    Ok(())
}

/// Copies the frame's current `textures` and `buffers` as they are after `after`.
fn keep(
    s: &mut State,
    after: Option<usize>,
    textures: &BTreeSet<usize>,
    buffers: &BTreeSet<usize>,
) {
    copies(s, |snaps, session, e| {
        for &t in textures {
            snaps.keep_texture(&session.device, e, t, after, session.texture_in_frame(t));
        }
        for &b in buffers {
            snaps.keep_buffer(&session.device, e, b, after, session.buffer_in_frame(b));
        }
    });
}

/// Carries out the pending commands the replay can answer now: saves in order, then the
/// latest view, then thumbnails one at a time, looking for newer commands between them.
fn serve(
    s: &mut State,
    pending: &mut Pending,
    rx: &Receiver<Command>,
    tx: &Sender<Reply>,
) -> Result<(), Stop> {
    let last = s.replaying.session.plan.passes.len().saturating_sub(1);
    let send = |r: Reply| tx.send(r).map_err(|_| Stop::Closed);
    loop {
        while let Some((view, _, _)) = pending.saves.front() {
            if !s.snaps.ready(view.pass.min(last)) {
                break;
            }
            let Some((view, how, path)) = pending.saves.pop_front() else {
                break;
            };
            match save(s, &view, how, &path) {
                Err(WorkerError::Later) => {
                    pending.saves.push_front((view, how, path));
                    break;
                }
                done => send(Reply::Saved(done))?,
            }
        }
        if let Some(view) = pending.view.take() {
            if !s.snaps.ready(view.pass.min(last)) {
                pending.view = Some(view);
            } else {
                match show(s, &view) {
                    Ok(shown) => send(Reply::Shown(Box::new(shown)))?,
                    Err(WorkerError::Later) => pending.view = Some(view),
                    Err(e) => send(Reply::Failed(e))?,
                }
            }
        }
        if let Some(h) = pending.history.take() {
            match history::history(s, &h) {
                Err(WorkerError::Later) => pending.history = Some(h),
                done => {
                    send(Reply::History(done.map(Arc::new)))?;
                    pending.drain(rx)?;
                    continue;
                }
            }
        }
        let Some((pass, list)) = &mut pending.thumbnails else {
            return Ok(());
        };
        let pass = (*pass).min(last);
        if !s.snaps.ready(pass) {
            return Ok(());
        }
        let Some(t) = list.pop_front() else {
            pending.thumbnails = None;
            return Ok(());
        };
        // A thumbnail never costs a replay: one whose copy is gone is left out.
        send(Reply::Thumbnail {
            pass,
            texture: t.plan_index,
            image: thumbnail(s, pass, &t),
        })?;
        pending.drain(rx)?;
    }
}

/// A small image of `t` as of `pass`, from the pass copies (depth fitted to its range).
fn thumbnail(s: &mut State, pass: usize, t: &TextureRequest) -> Option<egui::ColorImage> {
    let (texture, origin) = match s.snaps.texture(t.plan_index, pass) {
        Found::Copy { copy, after } => (copy, Origin::After(after)),
        Found::Live => (
            s.replaying.session.texture(t.plan_index).clone(),
            Origin::Live,
        ),
        Found::Evicted { .. } | Found::NotYet => return None,
    };
    let mut controls = t.controls;
    if t.sampling == Sampling::Depth {
        // Fitted to the subresource's range, from the read-back the viewer keeps (the view of
        // this pass has usually just read it).
        read_cached(s, &texture, origin, t);
        let (_, (lo, hi)) = subresource(&s.reads.front()?.images, t)?;
        let (lo, hi) = (*lo, *hi);
        controls.black = lo;
        controls.white = if hi > lo { hi } else { lo + 1.0 };
    }
    // Every stride-th texel, to about twice the thumbnail's size, then box-filtered down.
    let side = (texture.width() >> t.sub.mip).max(texture.height() >> t.sub.mip);
    let stride = side.div_ceil(2 * THUMBNAIL_SIZE).max(1);
    let session = &s.replaying.session;
    let display = s.visualiser.draw(
        &session.device,
        &session.queue,
        &texture,
        (t.sampling, t.volume),
        t.sub,
        &controls,
        stride,
    );
    let full = crate::visualise::read_display(&session.device, &session.queue, &display).ok()?;
    Some(shrink(&full, THUMBNAIL_SIZE))
}

/// `image` scaled down (box filter) so its longer side is at most `side` pixels.
fn shrink(image: &egui::ColorImage, side: u32) -> egui::ColorImage {
    let [w, h] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    let Some(rgba) = image::RgbaImage::from_raw(w as u32, h as u32, bytes) else {
        return image.clone();
    };
    let scale = f64::from(side) / w.max(h).max(1) as f64;
    if scale >= 1.0 {
        return image.clone();
    }
    let (tw, th) = (
        ((w as f64 * scale).round() as u32).max(1),
        ((h as f64 * scale).round() as u32).max(1),
    );
    let small = image::imageops::thumbnail(&rgba, tw, th);
    egui::ColorImage::from_rgba_premultiplied([tw as usize, th as usize], small.as_raw())
}

/// Writes the view `request` asks for: the display image as shown (PNG), or the viewed
/// subresource's decoded values (EXR).
fn save(
    s: &mut State,
    request: &ViewRequest,
    how: SaveAs,
    path: &std::path::Path,
) -> Result<String, WorkerError> {
    // The same view as on screen: copies and read-backs are kept, only the small display draw
    // runs again.
    let shown = show(s, request)?;
    let written = match how {
        SaveAs::Png => {
            let display = shown.display.ok_or(WorkerError::NothingShown)?;
            let [w, h] = display.size;
            let bytes: Vec<u8> = display.pixels.iter().flat_map(|c| c.to_array()).collect();
            let image = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
                .ok_or(WorkerError::EmptyDisplay)?;
            framelab_replay::export::save_rgba8(path, &image)
        }
        SaveAs::Exr => {
            let decoded = shown.decoded.ok_or_else(|| {
                WorkerError::NotRead(shown.note.unwrap_or_else(|| "nothing read back".into()))
            })?;
            framelab_replay::export::save_exr(path, &decoded)
        }
    };
    written?;
    Ok(path.display().to_string())
}

/// Holds frame 1 open right after `pass`, after a whole frame 0 (what `replay --frames 2
/// --after PASS` exports), to make again a copy the budget evicted; a later pass asked for next
/// runs on from there.
fn replay_to(s: &mut State, pass: usize) -> Result<(), WorkerError> {
    if s.browsing {
        return Err(WorkerError::Later);
    }
    steps::close(s);
    s.replaying
        .hold(1, pass + 1, |_| Ok::<(), framelab_replay::ReplayError>(()))?;
    Ok(())
}

/// Encodes copies with `record` and submits them.
fn copies(
    s: &mut State,
    record: impl FnOnce(&mut Snapshots, &framelab_replay::Session, &mut wgpu::CommandEncoder),
) {
    let session = &s.replaying.session;
    let mut encoder = session
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("framelab pass copies"),
        });
    record(&mut s.snaps, session, &mut encoder);
    session.queue.submit([encoder.finish()]);
}

/// A resource as of a pass, from what the copies store found: the copy, the resource itself
/// (`live`), or, for an evicted copy, the resource after a replay up to the pass, whose copy
/// `keep` makes again.
fn resolve<T: Clone>(
    s: &mut State,
    found: Found<T>,
    pass: usize,
    live: impl Fn(&framelab_replay::Session) -> T,
    keep: impl FnOnce(&mut Snapshots, &wgpu::Device, &mut wgpu::CommandEncoder, Option<usize>, &T),
) -> Result<(T, Origin), WorkerError> {
    match found {
        Found::Copy { copy, after } => Ok((copy, Origin::After(after))),
        Found::Live => Ok((live(&s.replaying.session), Origin::Live)),
        Found::NotYet => Err(WorkerError::Later),
        Found::Evicted { after } => {
            replay_to(s, pass)?;
            let resource = live(&s.replaying.session);
            copies(s, |snaps, session, e| {
                keep(snaps, &session.device, e, after, &resource);
            });
            Ok((resource, Origin::After(after)))
        }
    }
}

/// Plan texture `t` as of right after `pass`, and where it was found.
fn texture_at(
    s: &mut State,
    t: usize,
    pass: usize,
) -> Result<(wgpu::Texture, Origin), WorkerError> {
    let found = s.snaps.texture(t, pass);
    resolve(
        s,
        found,
        pass,
        |session| session.texture(t).clone(),
        |snaps, device, e, after, live| snaps.keep_texture(device, e, t, after, live),
    )
}

/// Plan buffer `b` as of right after `pass`, and where it was found.
fn buffer_at(s: &mut State, b: usize, pass: usize) -> Result<(wgpu::Buffer, Origin), WorkerError> {
    let found = s.snaps.buffer(b, pass);
    resolve(
        s,
        found,
        pass,
        |session| session.buffer(b).clone(),
        |snaps, device, e, after, live| snaps.keep_buffer(device, e, b, after, live),
    )
}

fn show(s: &mut State, request: &ViewRequest) -> Result<Shown, WorkerError> {
    let passes = s.replaying.session.plan.passes.len();
    let pass = request.pass.min(passes.saturating_sub(1));
    let buffer = match request.buffer {
        Some(b) => Some(read_buffer(s, pass, b)?),
        None => None,
    };
    let Some(t) = &request.texture else {
        return Ok(Shown {
            request: request.clone(),
            display: None,
            decoded: None,
            note: None,
            written: None,
            texels: [0, 0],
            range: None,
            buffer,
        });
    };
    let step_copy = match request.step {
        Some(step) => {
            steps::replay_step(s, pass, step)?;
            s.step
                .as_ref()
                .and_then(|(_, copies)| copies.get(&t.plan_index).cloned())
                .map(|c| (c, Origin::Step(pass, step)))
        }
        None => None,
    };
    // A texture the pass does not write is as it was before the pass, draws or not.
    let (texture, origin) = match step_copy {
        Some(found) => found,
        None => texture_at(s, t.plan_index, pass)?,
    };
    read_cached(s, &texture, origin, t);
    let (decoded, range, note) = match s.reads.front() {
        Some(r) => {
            let image = subresource(&r.images, t).cloned();
            (
                image.as_ref().map(|i| i.0.clone()),
                image.map(|i| i.1),
                r.note.clone(),
            )
        }
        None => (None, None, None),
    };
    let session = &s.replaying.session;
    let display = s.visualiser.draw(
        &session.device,
        &session.queue,
        &texture,
        (t.sampling, t.volume),
        t.sub,
        &t.controls,
        t.stride,
    );
    let pixels = crate::visualise::read_display(&session.device, &session.queue, &display)?;
    session.check_faults("drawing the texture view")?;
    let mip = t.sub.mip.min(texture.mip_level_count().saturating_sub(1));
    Ok(Shown {
        request: request.clone(),
        display: Some(pixels),
        range,
        decoded,
        note,
        written: Some(origin.written()),
        texels: [
            (texture.width() >> mip).max(1),
            (texture.height() >> mip).max(1),
        ],
        buffer,
    })
}

/// Makes the read-back of the subresource `t` asks for of `texture` (found at `origin`) the
/// first of the kept ones, reading it only if it is not kept.
fn read_cached(s: &mut State, texture: &wgpu::Texture, origin: Origin, t: &TextureRequest) {
    let stencil = t.sampling == Sampling::Stencil;
    // A 3D texture's slices are read together.
    let layer = if t.volume { 0 } else { t.sub.layer };
    let key = (t.plan_index, origin, stencil, (t.sub.mip, layer));
    match s.reads.iter().position(|r| r.key == key) {
        Some(i) => {
            if let Some(r) = s.reads.remove(i) {
                s.reads.push_front(r);
            }
        }
        None => {
            let (images, note) = read_sub(s, texture, t);
            let images = images
                .into_iter()
                .map(|d| {
                    let range = d.range();
                    (d, range)
                })
                .collect();
            s.reads.push_front(ReadBack { key, images, note });
            s.reads.truncate(READS_KEPT);
        }
    }
}

/// The image of the subresource (of a 3D texture, the slice) `t` asks for among `images`.
fn subresource<'a, I: std::ops::Deref<Target = DecodedImage>, X>(
    images: &'a [(I, X)],
    t: &TextureRequest,
) -> Option<&'a (I, X)> {
    images.iter().find(|(d, _)| {
        d.mip == t.sub.mip
            && if t.volume {
                d.z == Some(t.sub.layer)
            } else {
                d.layer == t.sub.layer
            }
    })
}

/// The subresource `t` asks for of `texture` (a replay texture or a copy of it), decoded; or
/// why it cannot be read.
fn read_sub(
    s: &State,
    texture: &wgpu::Texture,
    t: &TextureRequest,
) -> (Vec<Arc<DecodedImage>>, Option<String>) {
    let spec = &s.replaying.session.plan.textures[t.plan_index];
    let (device, queue) = (&s.replaying.session.device, &s.replaying.session.queue);
    let layer = if t.volume { 0 } else { t.sub.layer };
    let read = if t.sampling == Sampling::Stencil {
        Ok(read_stencil_subresource(
            device, queue, texture, spec, t.sub.mip, layer,
        ))
    } else {
        readable_format(spec)
            .map(|f| read_subresource(device, queue, texture, spec, f, t.sub.mip, layer))
    };
    match read {
        Ok(Ok(images)) => (images.into_iter().map(Arc::new).collect(), None),
        Ok(Err(e)) => (Vec::new(), Some(e.to_string())),
        Err(why) => (Vec::new(), Some(why.0.to_owned())),
    }
}

/// Plan buffer `index` as of `pass` (the last one read is kept).
fn read_buffer(s: &mut State, pass: usize, index: usize) -> Result<Arc<Vec<u8>>, WorkerError> {
    let spec = s
        .replaying
        .session
        .plan
        .buffers
        .get(index)
        .ok_or(WorkerError::NoBuffer(index))?;
    // Copies need a multiple of 4 bytes; plan buffers are sized so.
    let size = spec.size.min(MAX_BUFFER_READ) & !3;
    let name = spec.name.clone();
    let (source, origin) = buffer_at(s, index, pass)?;
    if let Some((key, bytes)) = &s.buffer
        && *key == (index, origin)
    {
        return Ok(bytes.clone());
    }
    let bytes = framelab_replay::read_buffer(
        &s.replaying.session.device,
        &s.replaying.session.queue,
        &source,
        size,
        &name,
    )?;
    let bytes = Arc::new(bytes);
    s.buffer = Some(((index, origin), bytes.clone()));
    Ok(bytes)
}
