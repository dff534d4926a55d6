//! The replay worker: a thread that owns the replay session, so the UI thread never waits on
//! the GPU. It times a few whole frames first, then, for each view the UI asks for, replays
//! frame 1 up to the current pass after a whole frame 0 (only when the pass changed), so a view
//! never depends on the views before it; it reads the viewed texture back
//! for exact pixel values (only when the pass or texture changed), and draws the display
//! image. Requests that pile up while it works are skipped to the latest.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use framelab_replay::Replaying;
use framelab_replay::decode::{DecodedImage, read_stencil, read_texture, readable_format};

use crate::model::{PassTime, Sampling, Timings};
use crate::visualise::{Controls, Subresource, Visualiser};

/// What the UI wants on screen.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRequest {
    /// The frame as it is right after this pass (plan index).
    pub pass: usize,
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
}

/// How a view is saved: the image as shown (PNG), or the subresource's values (EXR).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SaveAs {
    Png,
    Exr,
}

enum Command {
    View(ViewRequest),
    Save(ViewRequest, SaveAs, std::path::PathBuf),
}

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
}

/// What the worker sends back.
#[derive(Debug)]
pub enum Reply {
    Progress(String),
    /// Per plan pass, from the last timed frame.
    Timings(Timings),
    Shown(Box<Shown>),
    /// A save finished: the file written, or why not.
    Saved(Result<String, WorkerError>),
    Failed(WorkerError),
}

#[derive(Debug)]
pub struct Shown {
    pub request: ViewRequest,
    /// The display image (the request's texture), on the replay device.
    pub display: Option<wgpu::Texture>,
    /// The viewed subresource read back and decoded, for exact pixel values; `None` where the
    /// format has no decoder (its reason in `note`).
    pub decoded: Option<Arc<DecodedImage>>,
    pub note: Option<String>,
    /// The requested buffer's bytes as of the pass (at most [`MAX_BUFFER_READ`]).
    pub buffer: Option<Arc<Vec<u8>>>,
}

/// A buffer's bytes as of a pass, keyed by (pass, plan buffer).
pub type BufferBytes = ((usize, usize), Arc<Vec<u8>>);

/// The buffer viewer reads at most this many bytes of a buffer, so a huge buffer costs a
/// bounded copy; the viewer says when it shows a prefix.
pub const MAX_BUFFER_READ: u64 = 64 << 20;

/// The UI's end of the worker.
#[derive(Debug)]
pub struct Worker {
    requests: Sender<Command>,
    pub replies: Receiver<Reply>,
}

impl Worker {
    /// Starts the worker on a replay, timing `timed_frames` whole frames first. Passes the
    /// adapter's timestamps do not measure get no time.
    pub fn start(replaying: Replaying, timed_frames: u32) -> Worker {
        let (requests, rx) = std::sync::mpsc::channel();
        let (tx, replies) = std::sync::mpsc::channel();
        std::thread::spawn(move || run(replaying, timed_frames, &rx, &tx));
        Worker { requests, replies }
    }

    /// Asks for a view; `false` when the worker has stopped.
    pub fn request(&self, view: ViewRequest) -> bool {
        self.requests.send(Command::View(view)).is_ok()
    }

    /// Asks for `view` to be written to `path`; answered with [`Reply::Saved`].
    pub fn save(&self, view: ViewRequest, how: SaveAs, path: std::path::PathBuf) -> bool {
        self.requests.send(Command::Save(view, how, path)).is_ok()
    }
}

/// A texture read back as of a pass: its decoded subresources, or why there are none.
struct ReadBack {
    /// Pass, plan texture, and whether the stencil aspect was read.
    key: (usize, usize, bool),
    images: Vec<Arc<DecodedImage>>,
    note: Option<String>,
}

struct State {
    replaying: Replaying,
    replayed_pass: Option<usize>,
    read: Option<ReadBack>,
    /// The last buffer read back: (pass, plan buffer) and its bytes.
    buffer: Option<BufferBytes>,
    visualiser: Visualiser,
}

fn run(replaying: Replaying, timed_frames: u32, rx: &Receiver<Command>, tx: &Sender<Reply>) {
    let untrusted = replaying.untrusted();
    let mut s = State {
        replaying,
        replayed_pass: None,
        read: None,
        buffer: None,
        visualiser: Visualiser::default(),
    };
    let mut last = Vec::new();
    for f in 0..timed_frames.max(1) {
        let _ = tx.send(Reply::Progress(format!(
            "timing frame {} of {}",
            f + 1,
            timed_frames.max(1)
        )));
        match s
            .replaying
            .session
            .run_frame(&s.replaying.constants(f), None)
        {
            Ok(times) => last = times,
            Err(e) => {
                let _ = tx.send(Reply::Failed(e.into()));
                return;
            }
        }
    }
    let trusted = |i: usize| untrusted.get(i).is_none_or(Option::is_none);
    let _ = tx.send(Reply::Timings(Timings {
        source: "replay".into(),
        passes: last
            .iter()
            .enumerate()
            .map(|(i, t)| {
                Some(PassTime {
                    start_ns: t.gpu_start_ns? as f64,
                    gpu_ns: t.gpu_ns? as f64,
                    measured: trusted(i),
                })
            })
            .collect(),
        note: untrusted.iter().flatten().next().cloned(),
    }));
    let _ = tx.send(Reply::Progress("ready".into()));
    let mut pending = None;
    loop {
        let Some(mut command) = pending.take().or_else(|| rx.recv().ok()) else {
            return;
        };
        // Only the latest view matters; a save is always carried out, in order.
        while let Command::View(_) = command {
            match rx.try_recv() {
                Ok(newer @ Command::View(_)) => command = newer,
                Ok(save) => {
                    pending = Some(save);
                    break;
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        let reply = match command {
            Command::View(request) => match show(&mut s, &request, tx) {
                Ok(shown) => Reply::Shown(Box::new(shown)),
                Err(e) => Reply::Failed(e),
            },
            Command::Save(request, how, path) => {
                Reply::Saved(save(&mut s, &request, how, &path, tx))
            }
        };
        if tx.send(reply).is_err() {
            return;
        }
    }
}

/// Writes the view `request` asks for: the display image as shown (PNG), or the viewed
/// subresource's decoded values (EXR).
fn save(
    s: &mut State,
    request: &ViewRequest,
    how: SaveAs,
    path: &std::path::Path,
    tx: &Sender<Reply>,
) -> Result<String, WorkerError> {
    // The same view as on screen: replay and read-back are cached, only the small display
    // draw runs again.
    let shown = show(s, request, tx)?;
    let written = match how {
        SaveAs::Png => {
            let display = shown.display.ok_or(WorkerError::NothingShown)?;
            let image = display_pixels(s, &display)?;
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

/// The display image's pixels, read back.
fn display_pixels(s: &State, display: &wgpu::Texture) -> Result<image::RgbaImage, WorkerError> {
    let spec = framelab_core::plan::TextureSpec {
        name: "display".into(),
        format: display.format(),
        dimension: wgpu::TextureDimension::D2,
        size: display.size(),
        mip_levels: 1,
        samples: 1,
        usage: display.usage(),
        initial: None,
        history: false,
        cube: false,
    };
    let decoded = read_texture(
        &s.replaying.session.device,
        &s.replaying.session.queue,
        display,
        &spec,
        display.format(),
    )?;
    let d = decoded.first().ok_or(WorkerError::EmptyDisplay)?;
    Ok(image::RgbaImage::from_fn(d.width, d.height, |x, y| {
        let v = d.rgba((y * d.width + x) as usize);
        image::Rgba(v.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
    }))
}

fn show(s: &mut State, request: &ViewRequest, tx: &Sender<Reply>) -> Result<Shown, WorkerError> {
    let passes = s.replaying.session.plan.passes.len();
    let pass = request.pass.min(passes.saturating_sub(1));
    if s.replayed_pass != Some(pass) {
        let name = s
            .replaying
            .session
            .plan
            .passes
            .get(pass)
            .map_or("?", |p| p.name.as_str())
            .to_owned();
        let _ = tx.send(Reply::Progress(format!("replaying up to {name}")));
        // Always the same frame: frame 1 up to the pass, after a whole frame 0 (what
        // `replay --frames 2 --after PASS` exports), so a view does not depend on the views
        // before it, and history resources hold a whole previous frame.
        for (frame, stop) in [(0, None), (1, Some(pass))] {
            s.replaying
                .session
                .run_frame(&s.replaying.constants(frame), stop)?;
        }
        s.replayed_pass = Some(pass);
        s.read = None;
        s.buffer = None;
    }
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
            buffer,
        });
    };
    let texture = s.replaying.session.texture(t.plan_index).clone();
    let stencil = t.sampling == Sampling::Stencil;
    if s.read.as_ref().map(|r| r.key) != Some((pass, t.plan_index, stencil)) {
        let spec = &s.replaying.session.plan.textures[t.plan_index];
        let (device, queue) = (&s.replaying.session.device, &s.replaying.session.queue);
        let read = if stencil {
            Ok(read_stencil(device, queue, &texture, spec))
        } else {
            readable_format(spec).map(|f| read_texture(device, queue, &texture, spec, f))
        };
        let (images, note) = match read {
            Ok(Ok(images)) => (images.into_iter().map(Arc::new).collect(), None),
            Ok(Err(e)) => (Vec::new(), Some(e.to_string())),
            Err(why) => (Vec::new(), Some(why.0.to_owned())),
        };
        s.read = Some(ReadBack {
            key: (pass, t.plan_index, stencil),
            images,
            note,
        });
    }
    let (decoded, note) = match &s.read {
        Some(ReadBack { images, note, .. }) => (
            images
                .iter()
                .find(|d| {
                    d.mip == t.sub.mip
                        && if t.volume {
                            d.z == Some(t.sub.layer)
                        } else {
                            d.layer == t.sub.layer
                        }
                })
                .cloned(),
            note.clone(),
        ),
        None => (None, None),
    };
    let display = s.visualiser.draw(
        &s.replaying.session.device,
        &s.replaying.session.queue,
        &texture,
        t.sampling,
        t.volume,
        t.sub,
        &t.controls,
    );
    s.replaying
        .session
        .check_faults("drawing the texture view")?;
    Ok(Shown {
        request: request.clone(),
        display: Some(display),
        decoded,
        note,
        buffer,
    })
}

/// Plan buffer `index` as of `pass` (cached until either changes).
fn read_buffer(s: &mut State, pass: usize, index: usize) -> Result<Arc<Vec<u8>>, WorkerError> {
    if let Some((key, bytes)) = &s.buffer
        && *key == (pass, index)
    {
        return Ok(bytes.clone());
    }
    let spec = s
        .replaying
        .session
        .plan
        .buffers
        .get(index)
        .ok_or(WorkerError::NoBuffer(index))?;
    // Copies need a multiple of 4 bytes; plan buffers are sized so.
    let size = spec.size.min(MAX_BUFFER_READ) & !3;
    let bytes = framelab_replay::read_buffer(
        &s.replaying.session.device,
        &s.replaying.session.queue,
        s.replaying.session.buffer(index),
        size,
        &spec.name,
    )?;
    let bytes = Arc::new(bytes);
    s.buffer = Some(((pass, index), bytes.clone()));
    Ok(bytes)
}
