//! The inspector's state and frame loop: the current pass and viewed texture, the docked
//! panels (egui_tiles), and the exchange with the replay worker. Everything shown is derived
//! from the inspection model, the timings and the worker's latest image; a frame never waits
//! on the GPU.

use std::sync::Arc;

use eframe::egui_wgpu;
use egui::Vec2;
use framelab_replay::decode::DecodedImage;

use crate::model::{Inspection, Sampling, Timings};
use crate::panels;
use crate::visualise::{Controls, Subresource};
use crate::worker::{BufferBytes, Reply, SaveAs, TextureRequest, ViewRequest, Worker};

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
    _texture: wgpu::Texture,
}

pub struct Inspector {
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
    pub saved: Option<Result<String, String>>,
    worker: Option<Worker>,
    render_state: Option<egui_wgpu::RenderState>,
    sent: Option<ViewRequest>,
    /// The worker answered the last request (and finished timing).
    idle: bool,
    /// A save was asked for and not yet answered.
    saving: bool,
    tree: Option<egui_tiles::Tree<Pane>>,
    pane_pending: Option<Pane>,
}

impl std::fmt::Debug for Inspector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Inspector")
            .field("capture", &self.model.capture)
            .field("pass", &self.selection.pass)
            .finish()
    }
}

fn default_tree() -> egui_tiles::Tree<Pane> {
    let mut tiles = egui_tiles::Tiles::default();
    let events = tiles.insert_pane(Pane::Events);
    let texture = tiles.insert_pane(Pane::Texture);
    let timeline = tiles.insert_pane(Pane::Timeline);
    let resources = tiles.insert_pane(Pane::Resources);
    let buffer = tiles.insert_pane(Pane::Buffer);
    let details = tiles.insert_pane(Pane::Details);
    let dag = tiles.insert_pane(Pane::Dag);
    let memory = tiles.insert_pane(Pane::Memory);
    let bottom = tiles.insert_tab_tile(vec![timeline, resources, buffer, dag, memory]);
    let middle = tiles.insert_vertical_tile(vec![texture, bottom]);
    let root = tiles.insert_horizontal_tile(vec![events, middle, details]);
    if let Some(egui_tiles::Tile::Container(egui_tiles::Container::Linear(linear))) =
        tiles.get_mut(root)
    {
        linear.shares.set_share(events, 0.8);
        linear.shares.set_share(middle, 2.2);
        linear.shares.set_share(details, 1.0);
    }
    if let Some(egui_tiles::Tile::Container(egui_tiles::Container::Linear(linear))) =
        tiles.get_mut(middle)
    {
        linear.shares.set_share(texture, 2.0);
        linear.shares.set_share(bottom, 1.0);
    }
    egui_tiles::Tree::new(egui::Id::unique("framelab-inspector"), root, tiles)
}

impl Inspector {
    /// An inspector over `model`; `worker` replays it on the device `render_state` draws
    /// with (both absent: the panels show the model alone).
    /// Whether a replay runs behind the views (an imported capture has none).
    pub fn replays(&self) -> bool {
        self.worker.is_some()
    }

    pub fn new(
        model: Inspection,
        worker: Option<Worker>,
        render_state: Option<egui_wgpu::RenderState>,
    ) -> Inspector {
        let resource = model
            .resources
            .iter()
            .position(|r| r.texture.as_ref().is_some_and(|t| t.unviewable.is_none()));
        let timings = model.timings.clone();
        let mut inspector = Inspector {
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
            status: if worker.is_some() {
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
            idle: worker.is_none(),
            saving: false,
            worker,
            render_state,
            sent: None,
            tree: Some(default_tree()),
            pane_pending: None,
        };
        inspector.selection.pass = inspector.model.passes.len().saturating_sub(1);
        if let Some(r) = resource {
            inspector.open_resource(r);
        }
        inspector
    }

    /// Whether the worker has answered everything asked of it.
    pub fn is_idle(&self) -> bool {
        self.idle && !self.saving
    }

    /// Picks texel (x, y) of the viewed subresource for the pixel readout.
    pub fn pick(&mut self, x: u32, y: u32) {
        self.picked = Some((x, y));
    }

    /// Brings `pane` to the front of its tab group.
    pub fn show_pane(&mut self, pane: Pane) {
        match &mut self.tree {
            Some(tree) => {
                tree.make_active(|_, tile| matches!(tile, egui_tiles::Tile::Pane(p) if *p == pane));
            }
            // Asked from inside a panel, while the tree is being drawn: after it.
            None => self.pane_pending = Some(pane),
        }
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

    /// Saves the texture view as shown (PNG) or its values (EXR) to `save_path`, with the
    /// extension set to match; the outcome arrives in `saved`.
    pub fn save_view(&mut self, how: SaveAs) {
        let wanted = self.wanted();
        let ext = match how {
            SaveAs::Png => "png",
            SaveAs::Exr => "exr",
        };
        let path = std::path::Path::new(self.save_path.trim()).with_extension(ext);
        self.save_path = path.display().to_string();
        self.saved = None;
        let sent = wanted.texture.is_some()
            && !self.save_path.trim().is_empty()
            && self
                .worker
                .as_ref()
                .is_some_and(|w| w.save(wanted, how, path));
        if sent {
            self.saving = true;
        } else {
            self.saved = Some(Err("nothing to save: open a texture and name a file".into()));
        }
    }

    /// The view the panels want now.
    fn wanted(&self) -> ViewRequest {
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

    fn poll(&mut self, ctx: &egui::Context) {
        let Some(worker) = &self.worker else {
            return;
        };
        let mut shown = Vec::new();
        while let Ok(reply) = worker.replies.try_recv() {
            match reply {
                Reply::Progress(p) => self.status = p,
                Reply::Timings(t) => {
                    if self.timings.is_none() {
                        self.timings = Some(t);
                    }
                }
                Reply::Shown(s) => shown.push(s),
                Reply::Saved(result) => {
                    self.saved = Some(result);
                    self.saving = false;
                }
                Reply::Failed(e) => {
                    self.error = Some(e);
                    self.idle = true;
                }
            }
        }
        for s in shown {
            if Some(&s.request) == self.sent.as_ref() {
                self.idle = true;
                self.status = "ready".into();
            }
            if let (Some(bytes), Some(b)) = (s.buffer.clone(), s.request.buffer) {
                self.buffer_bytes = Some(((s.request.pass, b), bytes));
            }
            let Some(texture) = s.display else {
                self.displayed = None;
                continue;
            };
            let Some(rs) = &self.render_state else {
                continue;
            };
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let mut renderer = rs.renderer.write();
            let texture_id = match &self.displayed {
                Some(d) => {
                    renderer.update_egui_texture_from_wgpu_texture(
                        &rs.device,
                        &view,
                        wgpu::FilterMode::Nearest,
                        d.texture_id,
                    );
                    d.texture_id
                }
                None => {
                    renderer.register_native_texture(&rs.device, &view, wgpu::FilterMode::Nearest)
                }
            };
            let range = s.decoded.as_ref().map(|d| d.range());
            if self.fit_pending
                && self.wanted().texture.map(|t| t.plan_index)
                    == s.request.texture.as_ref().map(|t| t.plan_index)
                && let Some((lo, hi)) = range
            {
                self.fit_pending = false;
                self.selection.controls.black = lo;
                self.selection.controls.white = if hi > lo { hi } else { lo + 1.0 };
            }
            self.displayed = Some(Displayed {
                request: s.request.clone(),
                texture_id,
                size: [texture.width(), texture.height()],
                range,
                histogram: None,
                decoded: s.decoded,
                note: s.note,
                _texture: texture,
            });
        }
        let wanted = self.wanted();
        if self.sent.as_ref() != Some(&wanted) && self.error.is_none() {
            if worker.request(wanted.clone()) {
                self.idle = false;
            }
            self.sent = Some(wanted);
        }
        if !self.is_idle() {
            ctx.request_repaint_after(std::time::Duration::from_millis(30));
        }
    }

    /// Steps the current pass with the arrow keys (outside text fields).
    fn keys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let visible = panels::events::visible(&self.model, &self.selection.filter);
        let here = visible.iter().position(|&p| p == self.selection.pass);
        let (up, down) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::ArrowUp),
                i.key_pressed(egui::Key::ArrowDown),
            )
        });
        let next = match (here, up, down) {
            (Some(i), true, false) => i.checked_sub(1).map(|j| visible[j]),
            (Some(i), false, true) => visible.get(i + 1).copied(),
            (None, _, true) | (None, true, _) => visible.first().copied(),
            _ => None,
        };
        if let Some(p) = next {
            self.select_pass(p);
        }
    }

    /// The whole window.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.poll(&ctx);
        self.keys(&ctx);
        egui::Panel::bottom("status").show(ui, |ui| {
            panels::status_bar(self, ui);
        });
        egui::CentralPanel::default().show(ui, |ui| {
            if let Some(mut tree) = self.tree.take() {
                tree.ui(&mut Behavior { app: self }, ui);
                self.tree = Some(tree);
            }
            if let Some(pane) = self.pane_pending.take() {
                self.show_pane(pane);
                ui.ctx().request_repaint();
            }
        });
    }
}

struct Behavior<'a> {
    app: &'a mut Inspector,
}

impl egui_tiles::Behavior<Pane> for Behavior<'_> {
    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    fn pane_ui(
        &mut self,
        ui: &mut egui::Ui,
        _tile_id: egui_tiles::TileId,
        pane: &mut Pane,
    ) -> egui_tiles::UiResponse {
        egui::Frame::new()
            .inner_margin(4.0)
            .show(ui, |ui| match pane {
                Pane::Events => panels::events::ui(self.app, ui),
                Pane::Texture => panels::texture::ui(self.app, ui),
                Pane::Resources => panels::resources::ui(self.app, ui),
                Pane::Details => panels::details::ui(self.app, ui),
                Pane::Timeline => panels::timeline::ui(self.app, ui),
                Pane::Dag => panels::dag::ui(self.app, ui),
                Pane::Memory => panels::memory::ui(self.app, ui),
                Pane::Buffer => panels::buffer::ui(self.app, ui),
            });
        egui_tiles::UiResponse::None
    }

    fn simplification_options(&self) -> egui_tiles::SimplificationOptions {
        egui_tiles::SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..Default::default()
        }
    }
}

impl eframe::App for Inspector {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        Inspector::ui(self, ui);
    }
}
