//! Pass details: queue, kind and markers; bindings (WGSL variable -> resource view);
//! attachments with load/store/clear; render state; draws and dispatches with their
//! arguments; parameters; the barriers before and after the pass, derived and recorded side
//! by side with their Vulkan equivalents; the lints that concern it.

use egui_extras::{Column, TableBuilder};

use crate::model::{BarrierSide, BarrierSource, Pass};
use crate::state::View;

fn pairs(ui: &mut egui::Ui, id: &str, rows: &[(String, String)]) {
    egui::Grid::new(id).striped(true).show(ui, |ui| {
        for (k, v) in rows {
            ui.label(egui::RichText::new(k).monospace());
            ui.label(v);
            ui.end_row();
        }
    });
}

fn barriers(ui: &mut egui::Ui, p: &Pass, side: BarrierSide) {
    let list: Vec<_> = p.barriers.iter().filter(|b| b.side == side).collect();
    if list.is_empty() {
        ui.weak("none");
        return;
    }
    TableBuilder::new(ui)
        .id_salt(("barriers", side == BarrierSide::Before))
        .striped(true)
        .columns(Column::auto(), 5)
        .column(Column::remainder())
        .header(18.0, |mut h| {
            for t in ["source", "kind", "resource", "range", "D3D12", "Vulkan"] {
                h.col(|ui| {
                    ui.strong(t);
                });
            }
        })
        .body(|mut body| {
            for b in list {
                body.row(18.0, |mut row| {
                    let source = match b.source {
                        BarrierSource::Derived => "derived",
                        BarrierSource::Recorded => "recorded",
                    };
                    for text in [
                        source,
                        &b.kind,
                        &b.resource,
                        &b.subresource,
                        &b.states,
                        &b.vulkan,
                    ] {
                        row.col(|ui| {
                            ui.label(text);
                        });
                    }
                });
            }
        });
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let Some(p) = model.passes.get(app.selection.pass) else {
        return;
    };
    egui::ScrollArea::both()
        .id_salt("details")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            // Long state names and Vulkan masks read on one line; the area scrolls sideways.
            ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Extend);
            ui.label(egui::RichText::new(&p.name).strong().size(16.0));
            let ms = super::pass_ms(app, app.selection.pass)
                .map_or("not timed".to_owned(), |ms| format!("{ms:.3} ms"));
            ui.label(format!(
                "{} on {}, {}{}",
                p.kind,
                model.queues[p.queue],
                ms,
                if p.culled {
                    " (culled: reaches no output)"
                } else {
                    ""
                }
            ));
            if !p.markers.is_empty() {
                ui.weak(p.markers.join(" / "));
            }
            if let Some(c) = model
                .compare
                .as_ref()
                .and_then(|c| c.passes.get(app.selection.pass).cloned().flatten())
            {
                ui.label(format!(
                    "compared: {:.3} ms there, {:+.1}%, {}",
                    c.other_ms, c.change_pct, c.verdict
                ));
            }
            let section =
                |ui: &mut egui::Ui, title: &str, n: usize, body: &mut dyn FnMut(&mut egui::Ui)| {
                    egui::CollapsingHeader::new(format!("{title} ({n})"))
                        .default_open(n > 0)
                        .show(ui, body);
                };
            section(ui, "Bindings", p.bindings.len(), &mut |ui| {
                pairs(ui, "bindings", &p.bindings)
            });
            section(ui, "Attachments", p.attachments.len(), &mut |ui| {
                for a in &p.attachments {
                    ui.label(a);
                }
            });
            section(ui, "State", p.state.len(), &mut |ui| {
                pairs(ui, "state", &p.state)
            });
            section(ui, "Work", p.work.len(), &mut |ui| {
                for w in &p.work {
                    ui.label(w);
                }
            });
            section(ui, "Parameters", p.params.len(), &mut |ui| {
                pairs(ui, "params", &p.params)
            });
            let before = p
                .barriers
                .iter()
                .filter(|b| b.side == BarrierSide::Before)
                .count();
            section(ui, "Barriers before", before, &mut |ui| {
                barriers(ui, p, BarrierSide::Before)
            });
            section(ui, "Barriers after", p.barriers.len() - before, &mut |ui| {
                barriers(ui, p, BarrierSide::After)
            });
            section(ui, "Lints", p.lints.len(), &mut |ui| {
                for l in &p.lints {
                    // A synchronization finding is a long sentence naming two commands: wrapped,
                    // so all of it can be read in the panel.
                    let text = egui::RichText::new(l).color(egui::Color32::from_rgb(230, 170, 60));
                    // The panel scrolls sideways for the barrier tables: wrap at what is seen.
                    let visible = (ui.clip_rect().max.x - ui.cursor().min.x).max(120.0);
                    ui.allocate_ui(egui::vec2(visible, 0.0), |ui| {
                        ui.add(egui::Label::new(text).wrap());
                    });
                }
            });
        });
}
