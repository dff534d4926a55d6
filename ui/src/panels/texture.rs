//! The texture viewer: the viewed texture as of the current pass, drawn on the GPU by the
//! display pass; channel toggles, black and white points (auto-fit from the read-back values,
//! reset), exposure, sRGB encoding, inversion, the NaN/Inf/negative overlay, mip and layer
//! (or 3D slice), zoom (fit, 1:1, wheel) and pan, the exact value of the texel under the
//! cursor in the texture's own format, and a histogram of the shown channels.

use egui::{Color32, Pos2, Rect, Sense, Vec2};
use framelab_replay::decode::DecodedImage;

use crate::model::Sampling;
use crate::state::{View, Zoom};
use crate::visualise::Controls;
use crate::worker::{SaveAs, Written};

/// The exact value of a texel as the format stores it, after its position.
pub fn texel_text(d: &DecodedImage, x: u32, y: u32) -> Option<String> {
    Some(format!("({x}, {y}) {}", d.texel_values(x, y)?))
}

fn controls(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let textures: Vec<usize> = model
        .resources
        .iter()
        .enumerate()
        .filter(|(_, r)| r.texture.is_some())
        .map(|(i, _)| i)
        .collect();
    let current = app.selection.resource;
    ui.horizontal_wrapped(|ui| {
        let name = current.map_or("(none)", |r| model.resources[r].name.as_str());
        let mut pick = None;
        egui::ComboBox::from_label("texture")
            .selected_text(name)
            .width(200.0)
            .height(400.0)
            .show_ui(ui, |ui| {
                ui.add(
                    egui::TextEdit::singleline(&mut app.selection.texture_filter)
                        .hint_text("search")
                        .desired_width(180.0),
                )
                .request_focus();
                let needle = app.selection.texture_filter.to_lowercase();
                for &i in &textures {
                    let n = &model.resources[i].name;
                    if !needle.is_empty() && !n.to_lowercase().contains(&needle) {
                        continue;
                    }
                    if ui.selectable_label(current == Some(i), n).clicked() {
                        pick = Some(i);
                    }
                }
            });
        ui.checkbox(&mut app.selection.follow, "follow pass")
            .on_hover_text("selecting a pass opens its first output");
        if let Some(i) = pick {
            app.open_resource(i);
        }
        let Some(r) = app.selection.resource.map(|r| &model.resources[r]) else {
            return;
        };
        ui.label(format!("{} {}x{}", r.format, r.width, r.height));
        let volume = r.texture.as_ref().is_some_and(|t| t.volume);
        let sub = &mut app.selection.sub;
        if r.mips > 1 {
            ui.add(
                egui::DragValue::new(&mut sub.mip)
                    .range(0..=r.mips - 1)
                    .prefix("mip "),
            );
        }
        let layers = if volume {
            (r.depth >> sub.mip).max(1)
        } else {
            r.layers
        };
        if layers > 1 {
            let what = if volume { "slice " } else { "layer " };
            ui.add(
                egui::DragValue::new(&mut sub.layer)
                    .range(0..=layers - 1)
                    .prefix(what),
            );
        }
        sub.layer = sub.layer.min(layers.saturating_sub(1));
    });
    let stencil_aspect = app
        .selection
        .resource
        .and_then(|r| model.resources[r].texture.as_ref())
        .filter(|t| t.stencil && t.sampling == Sampling::Depth)
        .is_some();
    if stencil_aspect {
        ui.horizontal(|ui| {
            let mut stencil = app.selection.stencil;
            ui.selectable_value(&mut stencil, false, "depth");
            ui.selectable_value(&mut stencil, true, "stencil");
            if stencil != app.selection.stencil {
                app.show_aspect(stencil);
            }
        });
    }
    let showing_stencil = app.selection.stencil
        || app
            .selection
            .resource
            .and_then(|r| model.resources[r].texture.as_ref())
            .is_some_and(|t| t.sampling == Sampling::Stencil);
    let c = &mut app.selection.controls;
    ui.horizontal_wrapped(|ui| {
        if showing_stencil {
            stencil_bits(ui, c);
        } else {
            for (k, name) in ["R", "G", "B", "A"].iter().enumerate() {
                ui.toggle_value(&mut c.channels[k], *name);
            }
        }
        ui.separator();
        ui.add(
            egui::DragValue::new(&mut c.black)
                .speed(0.01)
                .prefix("black "),
        );
        ui.add(
            egui::DragValue::new(&mut c.white)
                .speed(0.01)
                .prefix("white "),
        );
        let range = app.displayed.as_ref().and_then(|d| d.range);
        if ui
            .add_enabled(range.is_some(), egui::Button::new("auto-fit"))
            .clicked()
            && let Some((lo, hi)) = range
        {
            c.black = lo;
            c.white = if hi > lo { hi } else { lo + 1.0 };
        }
        if ui.button("reset").clicked() {
            c.black = 0.0;
            c.white = 1.0;
            c.exposure = 0.0;
        }
        ui.add(egui::Slider::new(&mut c.exposure, -10.0..=10.0).text("EV"));
        ui.checkbox(&mut c.encode_srgb, "sRGB");
        ui.checkbox(&mut c.invert, "invert");
        ui.checkbox(&mut c.overlay, "NaN/Inf/neg");
        ui.separator();
        if ui
            .selectable_label(app.selection.zoom == Zoom::Fit, "fit")
            .clicked()
        {
            app.selection.zoom = Zoom::Fit;
            app.selection.pan = Vec2::ZERO;
        }
        if ui
            .selectable_label(app.selection.zoom == Zoom::Scale(1.0), "1:1")
            .clicked()
        {
            app.selection.zoom = Zoom::Scale(1.0);
        }
    });
}

/// The file field and the save buttons: PNG writes the view as shown, EXR the values.
fn save_row(app: &mut View, ui: &mut egui::Ui) {
    let Some(r) = app.selection.resource else {
        return;
    };
    // Named after what is shown unless the user typed a name.
    let default = format!(
        "{}_after_{}_mip{}",
        app.model.resources[r].name,
        app.model
            .passes
            .get(app.selection.pass)
            .map_or("frame", |p| p.name.as_str()),
        app.selection.sub.mip
    );
    ui.horizontal(|ui| {
        ui.label("save");
        ui.add(
            egui::TextEdit::singleline(&mut app.save_path)
                .id_salt("save path")
                .hint_text(&default)
                .desired_width(260.0),
        );
        for (how, label, hint) in [
            (SaveAs::Png, "PNG", "the image as shown"),
            (SaveAs::Exr, "EXR", "the subresource's values as float RGBA"),
        ] {
            if ui.button(label).on_hover_text(hint).clicked() {
                if app.save_path.trim().is_empty() {
                    app.save_path.clone_from(&default);
                }
                app.request_save(how);
            }
        }
        match &app.saved {
            Some(Ok(path)) => {
                ui.weak(format!("wrote {path}"));
            }
            Some(Err(e)) => {
                ui.colored_label(Color32::LIGHT_RED, e.to_string());
            }
            None => {}
        }
    });
}

/// Stencil: all eight bits as a grey level, or one bit white where it is set.
fn stencil_bits(ui: &mut egui::Ui, c: &mut Controls) {
    let label = |bits: u32| {
        if bits == 0xff {
            "all bits".to_owned()
        } else {
            format!("bit {}", bits.trailing_zeros())
        }
    };
    let mut bits = c.stencil_bits;
    egui::ComboBox::from_id_salt("stencil bits")
        .selected_text(label(bits))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut bits, 0xff, label(0xff));
            for b in 0..8 {
                ui.selectable_value(&mut bits, 1 << b, label(1 << b));
            }
        });
    if bits != c.stencil_bits {
        c.stencil_bits = bits;
        c.black = 0.0;
        c.white = if bits == 0xff { 255.0 } else { bits as f32 };
    }
}

/// Bins of the shown channels' values between the black and white points.
fn histogram(d: &DecodedImage, channels: [bool; 4], black: f32, white: f32) -> Vec<u32> {
    const BINS: usize = 64;
    // At most about a million texels are counted (evenly spaced), so a 4096x4096 target
    // costs the UI a frame no longer than a 1024x1024 one; the bars' shape is the same.
    const SAMPLES: usize = 1 << 20;
    let mut bins = vec![0u32; BINS];
    let span = (white - black).max(1e-20);
    let step = d.values.len().div_ceil(SAMPLES).max(1);
    for v in d.values.iter().step_by(step) {
        for c in 0..d.channels.min(4) {
            if channels[c] && v[c].is_finite() {
                let t = ((v[c] - black) / span).clamp(0.0, 1.0);
                bins[((t * (BINS - 1) as f32).round()) as usize] += 1;
            }
        }
    }
    bins
}

fn draw_histogram(ui: &mut egui::Ui, bins: &[u32]) {
    let (rect, _) = ui.allocate_exact_size(Vec2::new(ui.available_width(), 40.0), Sense::hover());
    ui.painter().rect_filled(rect, 0.0, Color32::from_gray(24));
    let max = bins.iter().copied().max().unwrap_or(1).max(1) as f32;
    let w = rect.width() / bins.len() as f32;
    for (i, &n) in bins.iter().enumerate() {
        // Square root so that rare values still show beside a dominant one.
        let h = (n as f32 / max).sqrt() * rect.height();
        let x = rect.left() + i as f32 * w;
        ui.painter().rect_filled(
            Rect::from_min_max(
                Pos2::new(x, rect.bottom() - h),
                Pos2::new(x + w, rect.bottom()),
            ),
            0.0,
            Color32::from_gray(180),
        );
    }
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    controls(app, ui);
    save_row(app, ui);
    let model = app.model.clone();
    let Some(r) = app.selection.resource.map(|r| &model.resources[r]) else {
        ui.label("no texture selected");
        return;
    };
    if let Some(why) = r.texture.as_ref().and_then(|t| t.unviewable.as_ref()) {
        ui.label(format!("{} cannot be shown: {why}", r.name));
        return;
    }
    let pixel = app
        .hovered
        .or(app.picked)
        .zip(app.displayed.as_ref().and_then(|d| d.decoded.as_ref()))
        .and_then(|((x, y), d)| texel_text(d, x, y));
    let note = app.displayed.as_ref().and_then(|d| d.note.clone());
    ui.horizontal(|ui| {
        ui.label(if app.hovered.is_some() {
            "pixel"
        } else {
            "picked"
        });
        ui.label(egui::RichText::new(pixel.unwrap_or_else(|| "-".into())).monospace())
            .on_hover_text("read back from the texture, in its own format");
        if let Some(n) = note {
            ui.weak(format!("(values: {n})"));
        }
        if app.picked.is_some()
            && app.replays()
            && ui
                .small_button("history")
                .on_hover_text("every pass and draw that wrote the picked texel this frame")
                .clicked()
        {
            app.request_history();
        }
    });
    let c = app.selection.controls;
    if let Some(shown) = app.displayed.as_mut()
        && let Some(d) = &shown.decoded
    {
        // Counted again only when what it shows changes: a frame must not walk every texel.
        let key = (c.channels, c.black, c.white);
        if shown.histogram.as_ref().map(|h| h.0) != Some(key) {
            shown.histogram = Some((key, histogram(d, c.channels, c.black, c.white)));
        }
        if let Some((_, bins)) = &shown.histogram {
            draw_histogram(ui, bins);
        }
    }
    let Some(shown) = &app.displayed else {
        ui.label(if app.pass_ready(app.selection.pass) {
            "reading back..."
        } else {
            "waiting for the replay to reach this pass..."
        });
        return;
    };
    written_badge(app, ui);
    let (size, id) = (shown.size, shown.texture.id());
    let avail = ui.available_size();
    let (rect, response) = ui.allocate_exact_size(avail, Sense::click_and_drag());
    app.texture_area = rect.size();
    let texels = Vec2::new(size[0] as f32, size[1] as f32);
    let scale = match app.selection.zoom {
        Zoom::Fit => (rect.width() / texels.x)
            .min(rect.height() / texels.y)
            .max(1e-3),
        Zoom::Scale(s) => s,
    };
    if response.hovered() {
        let wheel = ui.input(|i| i.smooth_scroll_delta.y);
        if wheel != 0.0 {
            app.selection.zoom = Zoom::Scale((scale * (1.0 + wheel / 200.0)).clamp(0.05, 64.0));
        }
    }
    if response.dragged() {
        app.selection.pan += response.drag_delta();
    }
    let image_rect = Rect::from_center_size(rect.center() + app.selection.pan, texels * scale);
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(16));
    painter.image(
        id,
        image_rect,
        Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
        Color32::WHITE,
    );
    let texel = |p: Pos2| {
        let t = (p - image_rect.min) / scale;
        (t.x >= 0.0 && t.y >= 0.0 && t.x < texels.x && t.y < texels.y)
            .then_some((t.x as u32, t.y as u32))
    };
    app.hovered = response.hover_pos().and_then(texel);
    if response.clicked() {
        app.picked = response.interact_pointer_pos().and_then(texel);
    }
    // The picked texel, marked.
    if let Some((x, y)) = app.picked {
        let at = image_rect.min + Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * scale;
        painter.circle_stroke(
            at,
            5.0,
            egui::Stroke::new(1.5, Color32::from_rgb(255, 60, 200)),
        );
    }
}

/// Says whether the shown texture was written this frame as of the current pass, and by which
/// pass: a texture not yet written shows the contents the frame started with.
fn written_badge(app: &View, ui: &mut egui::Ui) {
    let Some(written) = app.displayed.as_ref().and_then(|d| d.written) else {
        return;
    };
    let name = |p: usize| app.model.passes.get(p).map_or("?", |p| p.name.as_str());
    match written {
        Written::After(p) if p == app.selection.pass => {
            ui.label(format!("written by this pass ({})", name(p)));
        }
        Written::After(p) => {
            ui.label(format!("last written by {}", name(p)));
        }
        Written::NotYet => {
            ui.colored_label(
                Color32::from_rgb(240, 180, 60),
                "not yet written this frame: the contents it started the frame with",
            );
        }
        Written::Never => {
            ui.label("not written by any pass of the frame");
        }
        Written::Step { pass, step } => {
            let line = app
                .model
                .passes
                .get(pass)
                .and_then(|p| p.work.get(step))
                .map_or("?", String::as_str);
            ui.label(format!("as of {} {line}", name(pass)));
        }
    }
}
