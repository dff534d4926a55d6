//! The event browser: marker groups, passes in execution order with queue and GPU time, the
//! current pass's draws, dispatches, copies and clears; a filter; culled passes greyed.

use crate::app::Inspector;
use crate::model::Inspection;

/// Passes matching the filter (name or marker, case-insensitive), in order.
pub fn visible(model: &Inspection, filter: &str) -> Vec<usize> {
    let f = filter.to_lowercase();
    model
        .passes
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            f.is_empty()
                || p.name.to_lowercase().contains(&f)
                || p.markers.iter().any(|m| m.to_lowercase().contains(&f))
        })
        .map(|(i, _)| i)
        .collect()
}

pub fn ui(app: &mut Inspector, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.label("filter");
        ui.add(
            egui::TextEdit::singleline(&mut app.selection.filter)
                .id_salt("event filter")
                .desired_width(f32::INFINITY),
        );
    });
    let model = app.model.clone();
    let mut clicked = None;
    egui::ScrollArea::vertical()
        .id_salt("events")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            let mut open: Vec<&str> = Vec::new();
            for i in visible(&model, &app.selection.filter) {
                let p = &model.passes[i];
                // Marker groups whose path differs from the previous pass's open here.
                let common = open
                    .iter()
                    .zip(&p.markers)
                    .take_while(|(a, b)| **a == b.as_str())
                    .count();
                open.truncate(common);
                for (depth, m) in p.markers.iter().enumerate().skip(common) {
                    ui.horizontal(|ui| {
                        ui.add_space(depth as f32 * 12.0);
                        ui.label(egui::RichText::new(format!("{m} /")).strong());
                    });
                    open.push(m);
                }
                let selected = app.selection.pass == i;
                let ms = super::pass_ms(app, i).map_or("-".to_owned(), |ms| format!("{ms:.3} ms"));
                let mut text = egui::RichText::new(&p.name);
                if p.culled {
                    text = text.weak().italics();
                }
                ui.horizontal(|ui| {
                    ui.add_space(p.markers.len() as f32 * 12.0);
                    let (rect, _) =
                        ui.allocate_exact_size(egui::vec2(4.0, 14.0), egui::Sense::hover());
                    ui.painter()
                        .rect_filled(rect, 1.0, super::queue_color(p.queue));
                    let r = ui
                        .selectable_label(selected, text)
                        .on_hover_text(format!("{} pass", p.kind));
                    if r.clicked() {
                        clicked = Some(i);
                    }
                    if selected {
                        r.scroll_to_me(None);
                    }
                    ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                        ui.label(egui::RichText::new(ms).monospace());
                        ui.label(egui::RichText::new(&model.queues[p.queue]).weak());
                    });
                });
                if selected {
                    for w in &p.work {
                        ui.horizontal(|ui| {
                            ui.add_space(p.markers.len() as f32 * 12.0 + 24.0);
                            ui.label(egui::RichText::new(w).small());
                        });
                    }
                }
            }
        });
    if let Some(i) = clicked {
        app.select_pass(i);
    }
}
