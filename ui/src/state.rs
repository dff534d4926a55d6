//! What the panels see and change: the inspection model, the timings, the user's selection, the
//! worker's latest image, and the small requests a panel makes of the inspector (a save, a pane
//! to bring forward). The panels take a `View` and never the inspector itself, so the
//! inspector's frame loop and the worker exchange stay in `app` and nothing points back at it.

use std::sync::Arc;

use egui::Vec2;
use framelab_replay::decode::DecodedImage;

use crate::model::{Inspection, Sampling, Timings};
use crate::visualise::{Controls, Subresource};
use crate::worker::{BufferBytes, SaveAs, TextureRequest, ViewRequest, WorkerError};

/// The docked panels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pane {
    Events,
    Texture,
    Resources,
    Details,
    Timeline,
    Dag,
    Memory,
    Buffer,
}

impl Pane {
    /// Every pane, for choosing one by name.
    pub const ALL: [Pane; 8] = [
        Pane::Events,
        Pane::Texture,
        Pane::Buffer,
        Pane::Resources,
        Pane::Details,
        Pane::Timeline,
        Pane::Dag,
        Pane::Memory,
    ];

    pub fn title(self) -> &'static str {
        match self {
            Pane::Events => "Events",
            Pane::Texture => "Texture",
            Pane::Resources => "Resources",
            Pane::Details => "Pass",
            Pane::Timeline => "Timeline",
            Pane::Dag => "DAG",
            Pane::Memory => "Memory",
            Pane::Buffer => "Buffer",
        }
    }
}

/// How the texture is scaled in its panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Zoom {
    Fit,
    /// Screen points per texel.
    Scale(f32),
}

/// What the user has chosen.
#[derive(Clone, Debug)]
pub struct Selection {
    /// The current pass: every panel shows the frame as it is right after it.
    pub pass: usize,
    pub resource: Option<usize>,
    /// The viewed texture's stencil aspect is shown instead of its depth.
    pub stencil: bool,
    /// The buffer in the buffer viewer (a resource index) and how its rows are read: a layout
    /// index into its `layouts`, or `None` for raw bytes.
    pub buffer: Option<usize>,
    pub buffer_layout: Option<usize>,
    pub sub: Subresource,
    pub controls: Controls,
    pub filter: String,
    pub resource_filter: String,
    /// Resource table sort: column and ascending.
    pub sort: (usize, bool),
    pub zoom: Zoom,
    pub pan: Vec2,
}

/// What a histogram was counted for: the shown channels, black and white points.
pub type HistogramKey = ([bool; 4], f32, f32);

/// The image the worker last drew, registered with egui.
#[derive(Debug)]
pub struct Displayed {
    pub request: ViewRequest,
    pub texture_id: egui::TextureId,
    pub size: [u32; 2],
    pub decoded: Option<Arc<DecodedImage>>,
    /// The decoded values' finite range (for auto-fit), found once.
    pub range: Option<(f32, f32)>,
    /// The histogram and the (channels, black, white) it was counted for.
    pub histogram: Option<(HistogramKey, Vec<u32>)>,
    pub note: Option<String>,
    /// Kept alive while egui samples it.
    pub(crate) _texture: wgpu::Texture,
}

#[derive(Debug)]
pub struct View {
    pub model: Arc<Inspection>,
    pub timings: Option<Timings>,
    pub selection: Selection,
    pub displayed: Option<Displayed>,
    /// The pixel under the cursor: texel coordinates in the viewed subresource.
    pub hovered: Option<(u32, u32)>,
    /// The texel clicked last (or given on the command line), read out when none is hovered.
    pub picked: Option<(u32, u32)>,
    pub status: String,
    /// Where the timeline drew each pass last frame (for clicks, and for tests to aim at).
    pub timeline_bars: Vec<(usize, egui::Rect)>,
    /// Fit black and white points to the next image's range (set when a depth texture opens).
    pub fit_pending: bool,
    /// Where the DAG drew each pass last frame.
    pub dag_nodes: Vec<(usize, egui::Rect)>,
    /// The DAG's pan and zoom.
    pub dag_view: (Vec2, f32),
    /// The pass the event list last scrolled to.
    pub events_scrolled_to: Option<usize>,
    /// The viewed buffer's bytes as of a pass: (pass, plan buffer) and the bytes.
    pub buffer_bytes: Option<BufferBytes>,
    pub error: Option<String>,
    /// Where the texture viewer saves (edited in its panel).
    pub save_path: String,
    /// The last save's outcome: the file written, or why not.
    pub saved: Option<Result<String, WorkerError>>,
    /// A replay runs behind the views (an imported capture has none).
    pub(crate) replays: bool,
    /// The worker answered the last request (and finished timing).
    pub(crate) idle: bool,
    /// A save was asked for and not yet answered.
    pub(crate) saving: bool,
    /// A save a panel asked for, carried out by the inspector after the frame's panels.
    pub(crate) save_request: Option<SaveAs>,
    /// A pane to bring to the front once the docked layout is drawn.
    pub(crate) pane_pending: Option<Pane>,
}

impl View {
    /// The state of a fresh inspector over `model` (`replays`: a worker drives it).
    pub(crate) fn new(model: Inspection, replays: bool) -> View {
        let timings = model.timings.clone();
        let mut view = View {
            model: Arc::new(model),
            timings,
            selection: Selection {
                pass: 0,
                resource: None,
                stencil: false,
                buffer: None,
                buffer_layout: None,
                sub: Subresource::default(),
                controls: Controls::default(),
                filter: String::new(),
                resource_filter: String::new(),
                sort: (0, true),
                zoom: Zoom::Fit,
                pan: Vec2::ZERO,
            },
            displayed: None,
            hovered: None,
            picked: None,
            status: if replays {
                "starting".into()
            } else {
                "imported capture: no replay, no texture contents".into()
            },
            timeline_bars: Vec::new(),
            events_scrolled_to: None,
            buffer_bytes: None,
            save_path: String::new(),
            saved: None,
            fit_pending: false,
            dag_nodes: Vec::new(),
            dag_view: (Vec2::ZERO, 1.0),
            error: None,
            replays,
            idle: !replays,
            saving: false,
            save_request: None,
            pane_pending: None,
        };
        view.selection.pass = view.model.passes.len().saturating_sub(1);
        // The presented image first: what the frame is for.
        let viewable = |r: usize| {
            view.model.resources[r]
                .texture
                .as_ref()
                .is_some_and(|t| t.unviewable.is_none())
        };
        let first_texture = view
            .model
            .presented
            .filter(|&r| viewable(r))
            .or_else(|| (0..view.model.resources.len()).find(|&r| viewable(r)));
        if let Some(r) = first_texture {
            view.open_resource(r);
        }
        view
    }

    /// Whether a replay runs behind the views (an imported capture has none).
    pub fn replays(&self) -> bool {
        self.replays
    }

    /// Whether the worker has answered everything asked of it.
    pub fn is_idle(&self) -> bool {
        self.idle && !self.saving
    }

    /// Picks texel (x, y) of the viewed subresource for the pixel readout.
    pub fn pick(&mut self, x: u32, y: u32) {
        self.picked = Some((x, y));
    }

    /// Brings `pane` to the front of its tab group once the docked layout is drawn.
    pub fn show_pane(&mut self, pane: Pane) {
        self.pane_pending = Some(pane);
    }

    /// Asks for the texture view to be saved as shown (PNG) or as values (EXR) to `save_path`.
    pub fn request_save(&mut self, how: SaveAs) {
        self.save_request = Some(how);
    }

    /// Makes `pass` the current pass.
    pub fn select_pass(&mut self, pass: usize) {
        if pass < self.model.passes.len() {
            self.selection.pass = pass;
        }
    }

    /// Opens resource `r` in the texture viewer, with controls suited to its format.
    pub fn open_resource(&mut self, r: usize) {
        let Some(res) = self.model.resources.get(r) else {
            return;
        };
        if let Some(b) = &res.buffer {
            self.selection.buffer = Some(r);
            self.selection.buffer_layout = (!b.layouts.is_empty()).then_some(0);
            self.show_pane(Pane::Buffer);
            return;
        }
        self.selection.resource = Some(r);
        self.selection.sub = Subresource::default();
        self.selection.pan = Vec2::ZERO;
        self.picked = None;
        self.fit_pending = false;
        if let Some(t) = &res.texture {
            let stencil = t.sampling == Sampling::Stencil;
            self.show_aspect(stencil);
        }
    }

    /// Shows the stencil aspect (or the texture's own: colour or depth) of the viewed texture,
    /// with controls suited to it.
    pub fn show_aspect(&mut self, stencil: bool) {
        let Some(t) = self
            .selection
            .resource
            .and_then(|r| self.model.resources[r].texture.as_ref())
        else {
            return;
        };
        let stencil = stencil && (t.stencil || t.sampling == Sampling::Stencil);
        self.selection.stencil = stencil;
        self.fit_pending = false;
        let mut c = Controls {
            encode_srgb: t.encode_srgb && !stencil,
            ..Controls::default()
        };
        match if stencil {
            Sampling::Stencil
        } else {
            t.sampling
        } {
            // Depth: near is 0 in a forward depth buffer; invert so near is bright.
            // Perspective depth crowds near one value: fit black and white to the range
            // read back once it arrives, and invert so near is bright.
            Sampling::Depth => {
                c.channels = [true, false, false, false];
                c.invert = true;
                self.fit_pending = true;
            }
            Sampling::Stencil => {
                c.channels = [true, false, false, false];
                c.white = 255.0;
            }
            Sampling::Uint | Sampling::Sint => {
                c.white = 255.0;
            }
            Sampling::Float => {}
        }
        self.selection.controls = c;
    }

    /// The view the panels want now.
    pub(crate) fn wanted(&self) -> ViewRequest {
        let texture = self.selection.resource.and_then(|r| {
            let t = self.model.resources[r].texture.as_ref()?;
            if t.unviewable.is_some() {
                return None;
            }
            Some(TextureRequest {
                plan_index: t.plan_index,
                sampling: if self.selection.stencil {
                    Sampling::Stencil
                } else {
                    t.sampling
                },
                volume: t.volume,
                sub: self.selection.sub,
                controls: self.selection.controls,
            })
        });
        let buffer = self
            .selection
            .buffer
            .and_then(|r| self.model.resources[r].buffer.as_ref())
            .map(|b| b.plan_index);
        ViewRequest {
            pass: self.selection.pass,
            texture,
            buffer,
        }
    }
}
