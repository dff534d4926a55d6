//! The inspector's panels, one module each; they read the inspector's model and selection and
//! change only the selection.

pub mod buffer;
pub mod dag;
pub mod details;
pub mod events;
pub mod history;
pub mod image_diff;
pub mod memory;
pub mod resources;
pub mod texture;
pub mod timeline;
pub mod work;

use crate::state::View;

/// Queue colours shared by the event list, timeline and pass details.
pub fn queue_color(queue: usize) -> egui::Color32 {
    const COLORS: [egui::Color32; 4] = [
        egui::Color32::from_rgb(86, 140, 220),
        egui::Color32::from_rgb(220, 140, 60),
        egui::Color32::from_rgb(90, 180, 110),
        egui::Color32::from_rgb(170, 110, 200),
    ];
    COLORS[queue % COLORS.len()]
}

/// Milliseconds of a pass's GPU time, if timed.
pub fn pass_ms(app: &View, pass: usize) -> Option<f64> {
    app.timings
        .as_ref()
        .and_then(|t| t.passes.get(pass).copied().flatten())
        .filter(|t| t.measured)
        .map(|t| t.gpu_ns / 1e6)
}

pub fn status_bar(app: &View, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        let m = &app.model;
        ui.label(format!("{}  scale {}", m.capture, m.scale));
        ui.separator();
        let timing = app.timings.as_ref().map_or(
            if app.replays() {
                "not timed yet"
            } else {
                "not replayed"
            }
            .to_owned(),
            |t| format!("timings: {}", t.source),
        );
        ui.label(timing);
        ui.separator();
        match &app.error {
            Some(e) => {
                ui.colored_label(egui::Color32::LIGHT_RED, format!("error: {e}"));
            }
            None => {
                // The browsed frame's progress: every pass up to `done` can be viewed.
                if app.replaying() {
                    let (done, total) = app
                        .replayed
                        .map_or((0, app.model.passes.len().max(1)), |(d, t)| (d + 1, t));
                    ui.add(
                        egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                            .desired_width(160.0)
                            .text(format!("{done}/{total} passes")),
                    );
                } else if !app.is_idle() {
                    ui.spinner();
                }
                ui.label(&app.status);
            }
        }
    });
}
