//! The image diff: the viewed texture as of the current pass here, the same texture as of the
//! paired pass in the second capture (`--against`), and FLIP's error map between the two as
//! shown, side by side, with the mean and 99th-percentile error and the colour scale.

use egui::{Color32, Vec2};

use crate::state::View;

/// One image scaled into `width`, under its caption.
fn image(ui: &mut egui::Ui, caption: &str, texture: Option<&egui::TextureHandle>, width: f32) {
    ui.vertical(|ui| {
        ui.set_width(width);
        ui.add(egui::Label::new(egui::RichText::new(caption).small()).truncate());
        match texture {
            Some(t) => {
                let size = t.size_vec2();
                let scale = (width / size.x).min(1e4);
                ui.image(egui::load::SizedTexture::new(t.id(), size * scale));
            }
            None => {
                ui.weak("...");
            }
        }
    });
}

/// FLIP's magma scale from no error (left) to the largest (right).
fn legend(ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.weak("FLIP 0");
        let (rect, _) = ui.allocate_exact_size(Vec2::new(160.0, 10.0), egui::Sense::hover());
        let lut = nv_flip::magma_lut().to_vec();
        let colours: Vec<&[u8]> = lut.chunks_exact(3).collect();
        let steps = 32;
        for i in 0..steps {
            let at = i * (colours.len().max(1) - 1) / (steps - 1);
            let Some(&[cr, cg, cb]) = colours.get(at) else {
                continue;
            };
            let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
            let r = egui::Rect::from_min_max(
                egui::pos2(x0, rect.top()),
                egui::pos2(x0 + rect.width() / steps as f32 + 0.5, rect.bottom()),
            );
            ui.painter()
                .rect_filled(r, 0.0, Color32::from_rgb(*cr, *cg, *cb));
        }
        ui.weak("1");
    });
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let Some(a) = &app.against else {
        ui.label(
            "compare this frame with another, pass by pass: start with --against OTHER.json \
             (another capture, or this one again)",
        );
        return;
    };
    if let Some(e) = &a.error {
        ui.colored_label(Color32::LIGHT_RED, format!("{}: {e}", a.model.capture));
        return;
    }
    let pass = app.selection.pass;
    let here = app.model.passes.get(pass).map_or("?", |p| p.name.as_str());
    let Some((there, renamed)) = a.pass_of.get(pass).copied().flatten() else {
        ui.label(format!("{} has no pass matching {here}", a.model.capture));
        return;
    };
    let there_name = a.model.passes.get(there).map_or("?", |p| p.name.as_str());
    let texture = app
        .selection
        .resource
        .and_then(|r| app.model.resources.get(r))
        .map_or("(no texture)", |r| r.name.as_str());
    ui.horizontal_wrapped(|ui| {
        ui.label(format!(
            "{texture} after {here} here, after {there_name} in {}{}",
            a.model.capture,
            if renamed { " (renamed)" } else { "" }
        ));
        if a.shown.is_none() {
            ui.spinner();
            ui.weak(&a.status);
        }
    });
    match a.flip.as_ref().map(|f| &f.result) {
        Some(Ok(f)) => {
            ui.horizontal(|ui| {
                ui.label(format!(
                    "FLIP mean {:.4}, 99th percentile {:.4}",
                    f.mean, f.p99
                ));
                legend(ui);
            });
        }
        Some(Err(why)) => {
            ui.colored_label(Color32::from_rgb(240, 180, 60), why.to_string());
        }
        None => {}
    }
    let width = ((ui.available_width() - 16.0) / 3.0).max(60.0);
    let flip = a
        .flip
        .as_ref()
        .and_then(|f| f.result.as_ref().ok())
        .map(|f| &f.map);
    egui::ScrollArea::vertical()
        .id_salt("image diff")
        .show(ui, |ui| {
            ui.horizontal_top(|ui| {
                image(
                    ui,
                    &format!("here: {}", app.model.capture),
                    app.displayed.as_ref().map(|d| &d.texture),
                    width,
                );
                image(
                    ui,
                    &format!("there: {}", a.model.capture),
                    a.shown.as_ref().map(|s| &s.texture),
                    width,
                );
                image(ui, "FLIP error", flip, width);
            });
        });
}
