//! What the panels see and change: the inspection model, the timings, the user's selection, the
//! worker's latest image, and the small requests a panel makes of the inspector (a save, a pane
//! to bring forward). The panels take a `View` and never the inspector itself, so the
//! inspector's frame loop and the worker exchange stay in `app` and nothing points back at it.

use std::sync::Arc;

use egui::Vec2;
use framelab_replay::decode::DecodedImage;

use crate::model::{Inspection, Sampling, Timings};
use crate::visualise::{Controls, Subresource};
use crate::worker::{
    BufferBytes, HistoryRequest, PixelHistory, SaveAs, TextureRequest, ViewRequest, WorkerError,
    Written,
};

/// Thumbnails the worker drew, uploaded to egui: (pass, plan texture) -> image.
#[derive(Default)]
pub struct Thumbnails(pub std::collections::BTreeMap<(usize, usize), egui::TextureHandle>);

impl std::fmt::Debug for Thumbnails {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} thumbnails", self.0.len())
    }
}

/// Thumbnails asked for per pass, at most.
pub const THUMBNAILS: usize = 24;

/// The controls a texture opens with (its stencil aspect, if `stencil`), and whether its black
/// and white points fit the values read back (depth).
pub fn default_controls(t: &crate::model::TextureView, stencil: bool) -> (Controls, bool) {
    let mut c = Controls {
        encode_srgb: t.encode_srgb && !stencil,
        ..Controls::default()
    };
    let mut fit = false;
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
            fit = true;
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
    (c, fit)
}

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
    History,
    ImageDiff,
}

impl Pane {
    /// Every pane, for choosing one by name.
    pub const ALL: [Pane; 10] = [
        Pane::Events,
        Pane::Texture,
        Pane::Buffer,
        Pane::Resources,
        Pane::Details,
        Pane::Timeline,
        Pane::Dag,
        Pane::Memory,
        Pane::History,
        Pane::ImageDiff,
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
            Pane::History => "History",
            Pane::ImageDiff => "Image diff",
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
    /// A draw or dispatch of the current pass (its index among them): the texture viewer shows
    /// the frame right after it instead.
    pub step: Option<usize>,
    /// Passes whose draws and dispatches the event list shows (expanding one never moves the
    /// rows above it, and selecting a pass expands nothing).
    pub expanded: std::collections::BTreeSet<usize>,
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
    /// Selecting a pass opens its first output (on by default, as a frame debugger's texture
    /// viewer follows the current pass); off keeps the open texture.
    pub follow: bool,
    /// The texture picker's search text.
    pub texture_filter: String,
    /// Zoom and pan of every texture viewed before, restored when it opens again.
    pub zooms: std::collections::BTreeMap<usize, (Zoom, Vec2)>,
}

impl std::fmt::Debug for Displayed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Displayed")
            .field("request", &self.request)
            .field("texture", &self.texture.id())
            .field("size", &self.size)
            .field("written", &self.written)
            .finish_non_exhaustive()
    }
}

/// What a histogram was counted for: the shown channels, black and white points.
pub type HistogramKey = ([bool; 4], f32, f32);

/// The image the worker last drew, uploaded to egui.
pub struct Displayed {
    pub request: ViewRequest,
    pub texture: egui::TextureHandle,
    /// The subresource's size in texels (the image is smaller by the request's stride).
    pub size: [u32; 2],
    pub decoded: Option<Arc<DecodedImage>>,
    /// The decoded values' finite range (for auto-fit), found once.
    pub range: Option<(f32, f32)>,
    /// The histogram and the (channels, black, white) it was counted for.
    pub histogram: Option<(HistogramKey, Vec<u32>)>,
    pub note: Option<String>,
    /// When the texture was last written, as of the view's pass.
    pub written: Option<Written>,
    /// The pixels as shown (for the image diff).
    pub pixels: Arc<egui::ColorImage>,
    /// How far the first replay had got when this image arrived (passes done, total).
    pub arrived_at: Option<(usize, usize)>,
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
    /// The timeline's visible span (start, length in ns); `None`: the whole frame.
    pub timeline_span: Option<(f64, f64)>,
    /// The measure the timeline colours bars by (`panels::work::MEASURES`); `None`: queues.
    pub timeline_color: Option<usize>,
    /// A second capture replayed beside this one for the image diff (`--against`).
    pub against: Option<crate::against::Against>,
    /// The last pixel history answered, or why not.
    pub history: Option<Result<Arc<PixelHistory>, crate::worker::WorkerError>>,
    /// A pixel history was asked for and not yet answered.
    pub history_pending: bool,
    /// A history a panel asked for, sent by the inspector after the frame's panels.
    pub(crate) history_request: Option<HistoryRequest>,
    /// Thumbnails the worker drew: (pass, plan texture) -> image.
    pub thumbnails: Thumbnails,
    /// Thumbnails asked for the current pass and not yet answered.
    pub thumbnails_waiting: usize,
    /// The worker has done everything it does on its own at start (the browsed frame, the
    /// timed frames).
    pub ready: bool,
    /// Where the timeline drew each pass last frame (for clicks, and for tests to aim at).
    pub timeline_bars: Vec<(usize, egui::Rect)>,
    /// Fit black and white points to the next image's range (set when a depth texture opens).
    pub fit_pending: bool,
    /// The texture panel's image area last frame, for the display's stride.
    pub texture_area: egui::Vec2,
    /// Where each pane shown was drawn last frame (for tests of the layout).
    pub pane_rects: Vec<(Pane, egui::Rect)>,
    /// Where the DAG drew each pass last frame.
    pub dag_nodes: Vec<(usize, egui::Rect)>,
    /// The DAG's pan and zoom.
    pub dag_view: (Vec2, f32),
    /// The pass the DAG last centred on.
    pub dag_centred: Option<usize>,
    /// The pass the event list last scrolled to.
    pub events_scrolled_to: Option<usize>,
    /// The viewed buffer's bytes as of a pass: (pass, plan buffer) and the bytes.
    pub buffer_bytes: Option<BufferBytes>,
    pub error: Option<String>,
    /// Passes of the browsed frame the worker has replayed (the last one) and their count;
    /// `None` before the first.
    pub replayed: Option<(usize, usize)>,
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
                step: None,
                expanded: Default::default(),
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
                follow: true,
                texture_filter: String::new(),
                zooms: Default::default(),
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
            timeline_span: None,
            timeline_color: None,
            thumbnails: Default::default(),
            thumbnails_waiting: 0,
            ready: false,
            history: None,
            against: None,
            history_pending: false,
            history_request: None,
            events_scrolled_to: None,
            buffer_bytes: None,
            save_path: String::new(),
            saved: None,
            fit_pending: false,
            dag_nodes: Vec::new(),
            pane_rects: Vec::new(),
            texture_area: egui::Vec2::ZERO,
            dag_view: (Vec2::ZERO, 1.0),
            dag_centred: None,
            error: None,
            replayed: None,
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

    /// Whether the worker is still replaying the browsed frame.
    pub fn replaying(&self) -> bool {
        self.replays
            && self.error.is_none()
            && self.replayed.is_none_or(|(done, total)| done + 1 < total)
    }

    /// Whether pass `pass` can be viewed now (its copies are made).
    pub fn pass_ready(&self, pass: usize) -> bool {
        !self.replays || self.replayed.is_some_and(|(done, _)| pass <= done)
    }

    /// Whether the window shows all it will without further input: the worker is idle and done
    /// with its start, and every thumbnail of the current pass has arrived.
    pub fn is_settled(&self) -> bool {
        self.is_idle()
            && (!self.replays || self.ready || self.error.is_some())
            && self.thumbnails_waiting == 0
    }

    /// Whether the worker has answered everything asked of it.
    pub fn is_idle(&self) -> bool {
        self.idle && !self.saving && !self.history_pending && self.against_settled()
    }

    /// Whether the image diff shows what the selection asks for (or cannot).
    fn against_settled(&self) -> bool {
        let Some(a) = &self.against else {
            return true;
        };
        if a.error.is_some() {
            return true;
        }
        let view = self.wanted();
        let Some(there) = a.wanted(&self.model, &view, self.selection.resource) else {
            return true;
        };
        let shown = a.shown.as_ref().is_some_and(|s| s.request == there);
        let here = self.displayed.as_ref().is_some_and(|d| d.request == view);
        shown && here && a.flip.as_ref().is_some_and(|f| f.key == (view, there))
    }

    /// Asks for the history of the picked texel of the viewed subresource: every pass and
    /// draw that wrote it this frame, with the value after each.
    pub fn request_history(&mut self) {
        let (Some(texture), Some((x, y))) = (self.wanted().texture, self.picked) else {
            return;
        };
        self.history_request = Some(HistoryRequest { texture, x, y });
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

    /// Makes `pass` the current pass and, when following, opens its first output a viewer can
    /// show (colour attachment, depth, then anything else it writes).
    pub fn select_pass(&mut self, pass: usize) {
        if pass >= self.model.passes.len() {
            return;
        }
        self.selection.pass = pass;
        self.selection.step = None;
        if !self.selection.follow {
            return;
        }
        let viewable = |r: &usize| {
            self.model.resources.get(*r).is_some_and(|res| {
                res.texture.as_ref().is_some_and(|t| t.unviewable.is_none()) || res.buffer.is_some()
            })
        };
        let first = self.model.passes[pass]
            .outputs
            .iter()
            .copied()
            .find(viewable);
        if let Some(r) = first
            && Some(r) != self.selection.resource
            && Some(r) != self.selection.buffer
        {
            self.open_resource(r);
        }
    }

    /// Shows the draws and dispatches of `pass` in the event list.
    pub fn expanded_pass(&mut self, pass: usize) {
        self.selection.expanded.insert(pass);
    }

    /// Makes draw or dispatch `step` of `pass` current: the texture viewer shows the frame
    /// right after it (the pass's first output, when following).
    pub fn select_step(&mut self, pass: usize, step: usize) {
        let Some(p) = self.model.passes.get(pass) else {
            return;
        };
        if step >= p.steps {
            return;
        }
        if pass != self.selection.pass {
            self.select_pass(pass);
        }
        self.selection.step = Some(step);
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
        // Each texture keeps its own zoom and pan; one never seen before opens fitted.
        if let Some(old) = self.selection.resource {
            let kept = (self.selection.zoom, self.selection.pan);
            self.selection.zooms.insert(old, kept);
        }
        let (zoom, pan) = self
            .selection
            .zooms
            .get(&r)
            .copied()
            .unwrap_or((Zoom::Fit, Vec2::ZERO));
        self.selection.zoom = zoom;
        self.selection.pan = pan;
        self.selection.resource = Some(r);
        self.selection.sub = Subresource::default();
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
        let (c, fit) = default_controls(t, stencil);
        self.fit_pending = fit;
        self.selection.controls = c;
    }

    /// Thumbnails of the textures pass `pass` reads and writes (at most [`THUMBNAILS`]), with
    /// the controls each opens with.
    pub(crate) fn thumbnail_requests(&self, pass: usize) -> Vec<TextureRequest> {
        let Some(p) = self.model.passes.get(pass) else {
            return Vec::new();
        };
        p.outputs
            .iter()
            .chain(&p.inputs)
            .filter_map(|&r| {
                let t = self.model.resources.get(r)?.texture.as_ref()?;
                if t.unviewable.is_some() {
                    return None;
                }
                let (controls, _) = default_controls(t, false);
                Some(TextureRequest {
                    plan_index: t.plan_index,
                    sampling: t.sampling,
                    volume: t.volume,
                    sub: Subresource::default(),
                    controls,
                    stride: 1,
                })
            })
            .take(THUMBNAILS)
            .collect()
    }

    /// Texels per display pixel for resource `r` at the current zoom: as many as fit in one
    /// pixel of the panel (at least 1), so a large texture is drawn at the size it is seen.
    fn stride(&self, r: usize) -> u32 {
        let res = &self.model.resources[r];
        let mip = self.selection.sub.mip;
        let (w, h) = ((res.width >> mip).max(1), (res.height >> mip).max(1));
        let per_pixel = match self.selection.zoom {
            Zoom::Fit => {
                let area = self.texture_area;
                if area.x < 1.0 || area.y < 1.0 {
                    return 1;
                }
                (w as f32 / area.x).max(h as f32 / area.y)
            }
            Zoom::Scale(s) => 1.0 / s.max(1e-3),
        };
        // Powers of two, so small zoom changes do not ask for a new image each time.
        let stride = per_pixel.max(1.0).log2().floor().exp2() as u32;
        stride.clamp(1, 64)
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
                stride: self.stride(r),
            })
        });
        let buffer = self
            .selection
            .buffer
            .and_then(|r| self.model.resources[r].buffer.as_ref())
            .map(|b| b.plan_index);
        ViewRequest {
            pass: self.selection.pass,
            step: self.selection.step,
            texture,
            buffer,
        }
    }
}
