//! The replay worker: a thread that owns the replay session, so the UI thread never waits on
//! the GPU. It times a few whole frames first, then, for each view the UI asks for, replays
//! frame 1 up to the current pass after a whole frame 0 (only when the pass changed), so a view
//! never depends on the views before it; it reads the viewed texture back
//! for exact pixel values (only when the pass or texture changed), and draws the display
//! image. Requests that pile up while it works are skipped to the latest.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use framelab_replay::Session;
use framelab_replay::decode::{DecodedImage, read_texture, readable_format};
use framelab_replay::plan::Params;

use crate::model::{PassTime, Sampling};
use crate::visualise::{Controls, Subresource, Visualiser};

/// What the UI wants on screen.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRequest {
    /// The frame as it is right after this pass (plan index).
    pub pass: usize,
    pub texture: Option<TextureRequest>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TextureRequest {
    pub plan_index: usize,
    pub sampling: Sampling,
    pub volume: bool,
    pub sub: Subresource,
    pub controls: Controls,
}

/// What the worker sends back.
#[derive(Debug)]
pub enum Reply {
    Progress(String),
    /// Per plan pass, from the timed frames.
    Timings(Vec<Option<PassTime>>),
    Shown(Box<Shown>),
    Failed(String),
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
}

/// The per-frame constants of frame `f`.
pub type Constants = Box<dyn Fn(u32) -> Params + Send>;

/// The UI's end of the worker.
#[derive(Debug)]
pub struct Worker {
    requests: Sender<ViewRequest>,
    pub replies: Receiver<Reply>,
}

impl Worker {
    /// Starts the worker on `session`, timing `timed_frames` whole frames first.
    pub fn start(session: Session, constants: Constants, timed_frames: u32) -> Worker {
        let (requests, rx) = std::sync::mpsc::channel();
        let (tx, replies) = std::sync::mpsc::channel();
        std::thread::spawn(move || run(session, constants, timed_frames, &rx, &tx));
        Worker { requests, replies }
    }

    /// Asks for a view; `false` when the worker has stopped.
    pub fn request(&self, view: ViewRequest) -> bool {
        self.requests.send(view).is_ok()
    }
}

/// A texture read back as of a pass: its decoded subresources, or why there are none.
struct ReadBack {
    key: (usize, usize),
    images: Vec<Arc<DecodedImage>>,
    note: Option<String>,
}

struct State {
    session: Session,
    constants: Constants,
    replayed_pass: Option<usize>,
    read: Option<ReadBack>,
    visualiser: Visualiser,
}

fn run(
    session: Session,
    constants: Constants,
    timed_frames: u32,
    rx: &Receiver<ViewRequest>,
    tx: &Sender<Reply>,
) {
    let mut s = State {
        session,
        constants,
        replayed_pass: None,
        read: None,
        visualiser: Visualiser::default(),
    };
    let mut last = Vec::new();
    for f in 0..timed_frames.max(1) {
        let _ = tx.send(Reply::Progress(format!(
            "timing frame {} of {}",
            f + 1,
            timed_frames.max(1)
        )));
        match s.session.run_frame(&(s.constants)(f), None) {
            Ok(times) => last = times,
            Err(e) => {
                let _ = tx.send(Reply::Failed(e.to_string()));
                return;
            }
        }
    }
    let _ = tx.send(Reply::Timings(
        last.iter()
            .map(|t| {
                Some(PassTime {
                    start_ns: t.gpu_start_ns? as f64,
                    gpu_ns: t.gpu_ns? as f64,
                })
            })
            .collect(),
    ));
    let _ = tx.send(Reply::Progress("ready".into()));
    while let Ok(mut request) = rx.recv() {
        // Only the latest view matters.
        loop {
            match rx.try_recv() {
                Ok(newer) => request = newer,
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        let reply = match show(&mut s, &request, tx) {
            Ok(shown) => Reply::Shown(Box::new(shown)),
            Err(e) => Reply::Failed(e),
        };
        if tx.send(reply).is_err() {
            return;
        }
    }
}

fn show(s: &mut State, request: &ViewRequest, tx: &Sender<Reply>) -> Result<Shown, String> {
    let passes = s.session.plan.passes.len();
    let pass = request.pass.min(passes.saturating_sub(1));
    if s.replayed_pass != Some(pass) {
        let name = s
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
            s.session
                .run_frame(&(s.constants)(frame), stop)
                .map_err(|e| e.to_string())?;
        }
        s.replayed_pass = Some(pass);
        s.read = None;
    }
    let Some(t) = &request.texture else {
        return Ok(Shown {
            request: request.clone(),
            display: None,
            decoded: None,
            note: None,
        });
    };
    let texture = s.session.texture(t.plan_index).clone();
    if s.read.as_ref().map(|r| r.key) != Some((pass, t.plan_index)) {
        let spec = &s.session.plan.textures[t.plan_index];
        let (images, note) = match readable_format(spec) {
            Ok(format) => {
                match read_texture(&s.session.device, &s.session.queue, &texture, spec, format) {
                    Ok(images) => (images.into_iter().map(Arc::new).collect(), None),
                    Err(e) => (Vec::new(), Some(e.to_string())),
                }
            }
            Err(why) => (Vec::new(), Some(why.0.to_owned())),
        };
        s.read = Some(ReadBack {
            key: (pass, t.plan_index),
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
        &s.session.device,
        &s.session.queue,
        &texture,
        t.sampling,
        t.volume,
        t.sub,
        &t.controls,
    );
    s.session
        .check_faults("drawing the texture view")
        .map_err(|e| e.to_string())?;
    Ok(Shown {
        request: request.clone(),
        display: Some(display),
        decoded,
        note,
    })
}
