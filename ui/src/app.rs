//! The inspector's frame loop: the docked panels (egui_tiles) drawn over the shared `View`,
//! and the exchange with the replay worker. Everything shown is derived from the inspection
//! model, the timings and the worker's latest image; a frame never waits on the GPU.

use std::sync::Arc;

use crate::model::Inspection;
use crate::panels;
pub use crate::state::{Displayed, HistogramKey, Pane, Selection, View, Zoom};
use crate::worker::{Reply, SaveAs, ViewRequest, Worker, WorkerError};

/// The inspector: the view state the panels share, the worker that replays behind it, and the
/// docked layout. It dereferences to its `View`, so callers select passes and open resources
/// on it as the panels do.
pub struct Inspector {
    pub view: View,
    worker: Option<Worker>,
    /// The second capture's worker (`--against`).
    against_worker: Option<Worker>,
    sent: Option<ViewRequest>,
    /// The pass whose thumbnails were asked for last.
    thumbnails_sent: Option<usize>,
    tree: Option<egui_tiles::Tree<Pane>>,
}

impl std::ops::Deref for Inspector {
    type Target = View;
    fn deref(&self) -> &View {
        &self.view
    }
}

impl std::ops::DerefMut for Inspector {
    fn deref_mut(&mut self) -> &mut View {
        &mut self.view
    }
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
    let history = tiles.insert_pane(Pane::History);
    let diff = tiles.insert_pane(Pane::ImageDiff);
    let bottom = tiles.insert_tab_tile(vec![
        timeline, resources, buffer, dag, memory, history, diff,
    ]);
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
    /// An inspector over `model`; `worker` replays it on a device of its own (absent: the
    /// panels show the model alone). Whatever egui draws with, the inspector only hands it
    /// pixels, so the UI never touches the replay's queue.
    pub fn new(model: Inspection, worker: Option<Worker>) -> Inspector {
        Inspector {
            view: View::new(model, worker.is_some()),
            worker,
            against_worker: None,
            sent: None,
            thumbnails_sent: None,
            tree: Some(default_tree()),
        }
    }

    /// Replays a second capture beside this one for the image diff: `against` pairs its passes
    /// with these, `worker` replays it on a device of its own.
    pub fn with_against(mut self, against: crate::against::Against, worker: Worker) -> Inspector {
        self.view.against = Some(against);
        self.against_worker = Some(worker);
        self
    }

    /// The second capture's replies, its next view, and the FLIP of the two images.
    fn poll_against(&mut self, ctx: &egui::Context) {
        let here = self.view.wanted();
        let Some(worker) = &self.against_worker else {
            return;
        };
        let Some(mut against) = self.view.against.take() else {
            return;
        };
        let a = &mut against;
        while let Ok(reply) = worker.replies.try_recv() {
            match reply {
                Reply::Progress(p) => a.status = p,
                Reply::Failed(e) => a.error = Some(e.to_string()),
                Reply::Shown(s) => {
                    let Some(image) = s.display else { continue };
                    let pixels = Arc::new(image);
                    let old = a.shown.take().map(|s| s.texture);
                    let texture = upload(ctx, old, &pixels, "framelab against");
                    a.shown = Some(crate::against::Shown {
                        request: s.request,
                        texture,
                        pixels,
                    });
                }
                _ => {}
            }
        }
        let there = a.wanted(&self.view.model, &here, self.view.selection.resource);
        if let Some(there) = &there
            && a.sent.as_ref() != Some(there)
            && a.error.is_none()
        {
            worker.request(there.clone());
            a.sent = Some(there.clone());
        }
        // FLIP once both sides show what is asked; on its own thread.
        if let (Some(there), Some(d), Some(s)) = (&there, &self.view.displayed, &a.shown)
            && d.request == here
            && &s.request == there
        {
            let key = (here.clone(), there.clone());
            let done = a.flip.as_ref().is_some_and(|f| f.key == key);
            let running = a.job.as_ref().is_some_and(|(k, _)| *k == key);
            if !done && !running {
                let (tx, rx) = std::sync::mpsc::channel();
                let (reference, test) = (d.pixels.clone(), s.pixels.clone());
                std::thread::spawn(move || {
                    let _ = tx.send(crate::against::flip(&reference, &test));
                });
                a.job = Some((key, rx));
            }
        }
        if let Some((key, rx)) = &a.job
            && let Ok(result) = rx.try_recv()
        {
            let result = result.map(|(mean, p99, map)| crate::against::FlipResult {
                mean,
                p99,
                map: ctx.load_texture("framelab flip", map, egui::TextureOptions::NEAREST),
            });
            a.flip = Some(crate::against::Flip {
                key: key.clone(),
                result,
            });
            a.job = None;
        }
        self.view.against = Some(against);
    }

    /// Brings `pane` to the front of its tab group.
    /// Colours the timeline's bars by a work measure (an index into `panels::work::MEASURES`).
    pub fn color_timeline_by(&mut self, measure: usize) {
        self.view.timeline_color = Some(measure);
    }

    pub fn show_pane(&mut self, pane: Pane) {
        match &mut self.tree {
            Some(tree) => {
                tree.make_active(|_, tile| matches!(tile, egui_tiles::Tile::Pane(p) if *p == pane));
            }
            // Asked while the tree is being drawn: after it.
            None => self.view.pane_pending = Some(pane),
        }
    }

    /// Saves the texture view as shown (PNG) or its values (EXR) to `save_path`, with the
    /// extension set to match; the outcome arrives in `saved`.
    pub fn save_view(&mut self, how: SaveAs) {
        // A saved image has every texel, whatever the zoom.
        let mut wanted = self.view.wanted();
        if let Some(t) = &mut wanted.texture {
            t.stride = 1;
        }
        let ext = match how {
            SaveAs::Png => "png",
            SaveAs::Exr => "exr",
        };
        let view = &mut self.view;
        let path = std::path::Path::new(view.save_path.trim()).with_extension(ext);
        view.save_path = path.display().to_string();
        view.saved = None;
        let sent = wanted.texture.is_some()
            && !view.save_path.trim().is_empty()
            && self
                .worker
                .as_ref()
                .is_some_and(|w| w.save(wanted, how, path));
        if sent {
            view.saving = true;
        } else {
            view.saved = Some(Err(WorkerError::NothingToSave));
        }
    }

    fn poll(&mut self, ctx: &egui::Context) {
        let Some(worker) = &self.worker else {
            return;
        };
        let mut shown = Vec::new();
        while let Ok(reply) = worker.replies.try_recv() {
            match reply {
                Reply::Progress(p) => self.view.status = p,
                Reply::Ready => self.view.ready = true,
                Reply::Replayed { done, total } => self.view.replayed = Some((done, total)),
                Reply::Timings(t) => {
                    // A report given on the command line stays; the worker's own frames
                    // replace each other.
                    if self
                        .view
                        .timings
                        .as_ref()
                        .is_none_or(|o| o.source == t.source)
                    {
                        self.view.timings = Some(t);
                    }
                }
                Reply::Shown(s) => shown.push(s),
                Reply::History(h) => {
                    self.view.history = Some(h);
                    self.view.history_pending = false;
                }
                Reply::Thumbnail {
                    pass,
                    texture,
                    image,
                } => {
                    if self.thumbnails_sent == Some(pass) {
                        self.view.thumbnails_waiting =
                            self.view.thumbnails_waiting.saturating_sub(1);
                    }
                    let Some(image) = image else { continue };
                    let thumbnails = &mut self.view.thumbnails.0;
                    // Thumbnails of the last few passes visited are kept.
                    if thumbnails.len() > 8 * crate::state::THUMBNAILS {
                        thumbnails.clear();
                    }
                    let handle = ctx.load_texture(
                        format!("framelab thumbnail {pass} {texture}"),
                        image,
                        egui::TextureOptions::LINEAR,
                    );
                    thumbnails.insert((pass, texture), handle);
                }
                Reply::Saved(result) => {
                    self.view.saved = Some(result);
                    self.view.saving = false;
                }
                Reply::Failed(e) => {
                    self.view.error = Some(e.to_string());
                    self.view.idle = true;
                }
            }
        }
        for s in shown {
            let s = *s;
            if Some(&s.request) == self.sent.as_ref() {
                self.view.idle = true;
            }
            if let (Some(bytes), Some(b)) = (s.buffer.clone(), s.request.buffer) {
                self.view.buffer_bytes = Some(((s.request.pass, b), bytes));
            }
            let Some(image) = s.display else {
                self.view.displayed = None;
                continue;
            };
            let pixels = Arc::new(image);
            let old = self.view.displayed.take().map(|d| d.texture);
            let texture = upload(ctx, old, &pixels, "framelab view");
            let range = s.range;
            if self.view.fit_pending
                && self.view.wanted().texture.map(|t| t.plan_index)
                    == s.request.texture.as_ref().map(|t| t.plan_index)
                && let Some((lo, hi)) = range
            {
                self.view.fit_pending = false;
                self.view.selection.controls.black = lo;
                self.view.selection.controls.white = if hi > lo { hi } else { lo + 1.0 };
            }
            self.view.displayed = Some(Displayed {
                request: s.request,
                texture,
                size: s.texels,
                range,
                histogram: None,
                decoded: s.decoded,
                note: s.note,
                written: s.written,
                pixels,
                arrived_at: self.view.replayed,
            });
        }
        let pass = self.view.selection.pass;
        if self.thumbnails_sent != Some(pass) && self.view.error.is_none() {
            let list: Vec<_> = self
                .view
                .thumbnail_requests(pass)
                .into_iter()
                .filter(|t| !self.view.thumbnails.0.contains_key(&(pass, t.plan_index)))
                .collect();
            self.view.thumbnails_waiting = list.len();
            worker.thumbnails(pass, list);
            self.thumbnails_sent = Some(pass);
        }
        let wanted = self.view.wanted();
        if self.sent.as_ref() != Some(&wanted) && self.view.error.is_none() {
            if worker.request(wanted.clone()) {
                self.view.idle = false;
            }
            self.sent = Some(wanted);
        }
        self.poll_against(ctx);
        if !self.view.is_idle() || self.view.replaying() {
            ctx.request_repaint_after(std::time::Duration::from_millis(30));
        }
    }

    /// Steps the current pass with the arrow keys (outside text fields).
    fn keys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let visible = panels::events::visible(&self.view.model, &self.view.selection.filter);
        let here = visible.iter().position(|&p| p == self.view.selection.pass);
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
            self.view.select_pass(p);
        }
    }

    /// The whole window.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.poll(&ctx);
        self.keys(&ctx);
        egui::Panel::bottom("status").show(ui, |ui| {
            panels::status_bar(&self.view, ui);
        });
        egui::CentralPanel::default().show(ui, |ui| {
            self.view.pane_rects.clear();
            if let Some(mut tree) = self.tree.take() {
                tree.ui(
                    &mut Behavior {
                        view: &mut self.view,
                    },
                    ui,
                );
                self.tree = Some(tree);
            }
            if let Some(pane) = self.view.pane_pending.take() {
                self.show_pane(pane);
                ui.ctx().request_repaint();
            }
            if let Some(how) = self.view.save_request.take() {
                self.save_view(how);
            }
            if let Some(h) = self.view.history_request.take()
                && let Some(worker) = &self.worker
                && worker.history(h)
            {
                self.view.history_pending = true;
                self.view.history = None;
                self.show_pane(Pane::History);
            }
        });
    }
}

/// Uploads `pixels` into `old` (kept, so egui reuses the texture) or a new texture; egui
/// shares the pixels with the caller rather than copying them.
fn upload(
    ctx: &egui::Context,
    old: Option<egui::TextureHandle>,
    pixels: &Arc<egui::ColorImage>,
    name: &str,
) -> egui::TextureHandle {
    match old {
        Some(mut t) => {
            t.set(pixels.clone(), egui::TextureOptions::NEAREST);
            t
        }
        None => ctx.load_texture(name, pixels.clone(), egui::TextureOptions::NEAREST),
    }
}

struct Behavior<'a> {
    view: &'a mut View,
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
        self.view.pane_rects.push((*pane, ui.max_rect()));
        egui::Frame::new()
            .inner_margin(4.0)
            .show(ui, |ui| match pane {
                Pane::Events => panels::events::ui(self.view, ui),
                Pane::Texture => panels::texture::ui(self.view, ui),
                Pane::Resources => panels::resources::ui(self.view, ui),
                Pane::Details => panels::details::ui(self.view, ui),
                Pane::Timeline => panels::timeline::ui(self.view, ui),
                Pane::Dag => panels::dag::ui(self.view, ui),
                Pane::Memory => panels::memory::ui(self.view, ui),
                Pane::Buffer => panels::buffer::ui(self.view, ui),
                Pane::History => panels::history::ui(self.view, ui),
                Pane::ImageDiff => panels::image_diff::ui(self.view, ui),
            });
        egui_tiles::UiResponse::None
    }

    /// No panel shrinks below a size its controls fit in, however small the window.
    fn min_size(&self) -> f32 {
        120.0
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
