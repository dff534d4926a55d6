//! Pixel history: the picked texel of the viewed texture through the frame, every pass and
//! draw that wrote it with the value after each (changes marked); a row selects its pass or
//! draw.

use egui_extras::{Column, TableBuilder};

use crate::state::View;

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let picked = app.picked;
    ui.horizontal(|ui| {
        let enabled = app.replays() && picked.is_some() && !app.history_pending;
        let label = match picked {
            Some((x, y)) => format!("history of texel ({x}, {y})"),
            None => "history (click a texel first)".to_owned(),
        };
        if ui.add_enabled(enabled, egui::Button::new(label)).clicked() {
            app.request_history();
        }
        if app.history_pending {
            ui.spinner();
            ui.label("replaying the passes that wrote it...");
        }
    });
    let h = match &app.history {
        None => return,
        Some(Err(e)) => {
            ui.colored_label(egui::Color32::LIGHT_RED, e.to_string());
            return;
        }
        Some(Ok(h)) => h.clone(),
    };
    let model = app.model.clone();
    let texture = model
        .resources
        .iter()
        .find(|r| {
            r.texture
                .as_ref()
                .is_some_and(|t| t.plan_index == h.request.texture.plan_index)
        })
        .map_or("?", |r| r.name.as_str());
    ui.label(format!(
        "{texture} mip {} layer {} texel ({}, {}): {} write(s) this frame; started as {}",
        h.request.texture.sub.mip,
        h.request.texture.sub.layer,
        h.request.x,
        h.request.y,
        h.rows.iter().filter(|r| r.step.is_none()).count(),
        h.start
    ));
    for n in &h.notes {
        ui.weak(n);
    }
    let mut chosen = None;
    let height = (ui.available_height() - 20.0).max(20.0);
    ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Truncate);
    TableBuilder::new(ui)
        .id_salt("pixel history")
        .striped(true)
        .min_scrolled_height(0.0)
        .max_scroll_height(height)
        .column(Column::auto().at_least(140.0))
        .column(Column::auto().at_least(220.0))
        .column(Column::remainder())
        .header(18.0, |mut row| {
            for t in ["pass", "draw or dispatch", "value after"] {
                row.col(|ui| {
                    ui.strong(t);
                });
            }
        })
        .body(|body| {
            body.rows(18.0, h.rows.len(), |mut row| {
                let r = &h.rows[row.index()];
                let pass = model.passes.get(r.pass);
                row.col(|ui| {
                    let name = pass.map_or("?", |p| p.name.as_str());
                    if ui.link(name).clicked() {
                        chosen = Some((r.pass, r.step));
                    }
                });
                row.col(|ui| {
                    let text = match r.step {
                        Some(k) => pass
                            .and_then(|p| p.work.get(k))
                            .map_or(format!("#{k}"), Clone::clone),
                        None => "(the whole pass)".to_owned(),
                    };
                    if r.step.is_some() {
                        if ui.link(text).clicked() {
                            chosen = Some((r.pass, r.step));
                        }
                    } else {
                        ui.strong(text);
                    }
                });
                row.col(|ui| {
                    let text = egui::RichText::new(&r.value).monospace();
                    if r.changed {
                        ui.label(text.color(egui::Color32::from_rgb(120, 210, 120)));
                    } else {
                        ui.weak(text);
                    }
                });
            });
        });
    if let Some((pass, step)) = chosen {
        // Keep the texture the history is of.
        let follow = app.selection.follow;
        app.selection.follow = false;
        match step {
            Some(k) => app.select_step(pass, k),
            None => app.select_pass(pass),
        }
        app.selection.follow = follow;
    }
}
