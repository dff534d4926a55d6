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

/// The barrier table of one side of the pass; returns the resource whose name was clicked.
fn barriers(
    ui: &mut egui::Ui,
    model: &crate::model::Inspection,
    p: &Pass,
    side: BarrierSide,
) -> Option<usize> {
    let list: Vec<_> = p.barriers.iter().filter(|b| b.side == side).collect();
    if list.is_empty() {
        ui.weak("none");
        return None;
    }
    let mut open = None;
    // A Vulkan program's frame drops the D3D12 column: its states are only a translation.
    let headers: &[&str] = if model.vulkan_terms {
        &["source", "kind", "resource", "range", "Vulkan"]
    } else {
        &["source", "kind", "resource", "range", "D3D12", "Vulkan"]
    };
    TableBuilder::new(ui)
        .id_salt(("barriers", side == BarrierSide::Before))
        .striped(true)
        .columns(Column::auto(), headers.len() - 1)
        .column(Column::remainder())
        .header(18.0, |mut h| {
            for t in headers {
                h.col(|ui| {
                    ui.strong(*t);
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
                    let states = (!model.vulkan_terms).then_some(b.states.as_str());
                    for (i, text) in [
                        Some(source),
                        Some(&b.kind),
                        Some(&b.resource),
                        Some(&b.subresource),
                        states,
                        Some(&b.vulkan),
                    ]
                    .into_iter()
                    .flatten()
                    .enumerate()
                    {
                        row.col(|ui| match by_name(model, text).filter(|_| i == 2) {
                            Some(r) => {
                                if resource_link(ui, model, r) {
                                    open = Some(r);
                                }
                            }
                            // The Vulkan column is the long one: clipped by a narrow
                            // panel, whole on hover.
                            None if i == headers.len() - 1 => {
                                ui.label(text).on_hover_text(text);
                            }
                            None => {
                                ui.label(text);
                            }
                        });
                    }
                });
            }
        });
    open
}

/// A resource's name as a link that opens it (a texture in the viewer, a buffer in the buffer
/// viewer); `true` when clicked. Resources the replay cannot show are plain text.
pub fn resource_link(ui: &mut egui::Ui, model: &crate::model::Inspection, r: usize) -> bool {
    let Some(res) = model.resources.get(r) else {
        return false;
    };
    let viewable =
        res.texture.as_ref().is_some_and(|t| t.unviewable.is_none()) || res.buffer.is_some();
    if viewable {
        ui.link(&res.name)
            .on_hover_text(format!(
                "{} {} {}x{}: open",
                res.kind, res.format, res.width, res.height
            ))
            .clicked()
    } else {
        ui.weak(&res.name);
        false
    }
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
                match &c.moved {
                    Some(q) => ui.label(format!(
                        "compared: {:.3} ms there, moved to queue {q} (not compared)",
                        c.other_ms
                    )),
                    None => ui.label(format!(
                        "compared: {:.3} ms there{}, {:+.1}%, {}",
                        c.other_ms,
                        c.renamed
                            .as_ref()
                            .map_or(String::new(), |n| format!(" (renamed {n})")),
                        c.change_pct,
                        c.verdict
                    )),
                };
            }
            let section =
                |ui: &mut egui::Ui, title: &str, n: usize, body: &mut dyn FnMut(&mut egui::Ui)| {
                    egui::CollapsingHeader::new(format!("{title} ({n})"))
                        .default_open(n > 0)
                        .show(ui, body);
                };
            super::work::section(ui, app.timings.as_ref(), app.selection.pass);
            let mut open = None;
            for (title, list) in [("Outputs", &p.outputs), ("Inputs", &p.inputs)] {
                section(ui, title, list.len(), &mut |ui| {
                    ui.horizontal_wrapped(|ui| {
                        for &r in list {
                            if thumbnail(ui, app, &model, r) {
                                open = Some(r);
                            }
                        }
                    });
                });
            }
            section(ui, "Bindings", p.bindings.len(), &mut |ui| {
                egui::Grid::new("bindings").striped(true).show(ui, |ui| {
                    for (k, v) in &p.bindings {
                        ui.label(egui::RichText::new(k).monospace());
                        // `resource as view ...`: the resource's name opens it.
                        let (name, rest) = v.split_once(" as ").unwrap_or((v.as_str(), ""));
                        ui.horizontal(|ui| {
                            ui.spacing_mut().item_spacing.x = 4.0;
                            match by_name(&model, name) {
                                Some(r) if resource_link(ui, &model, r) => open = Some(r),
                                Some(_) => {}
                                None => {
                                    ui.label(name);
                                }
                            }
                            if !rest.is_empty() {
                                ui.label(format!("as {rest}"));
                            }
                        });
                        ui.end_row();
                    }
                });
            });
            section(ui, "Attachments", p.attachments.len(), &mut |ui| {
                for a in &p.attachments {
                    ui.horizontal(|ui| {
                        ui.spacing_mut().item_spacing.x = 4.0;
                        ui.label(format!("{}:", a.slot));
                        if resource_link(ui, &model, a.resource) {
                            open = Some(a.resource);
                        }
                        ui.label(&a.text);
                    });
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
                if let Some(r) = barriers(ui, &model, p, BarrierSide::Before) {
                    open = Some(r);
                }
            });
            section(ui, "Barriers after", p.barriers.len() - before, &mut |ui| {
                if let Some(r) = barriers(ui, &model, p, BarrierSide::After) {
                    open = Some(r);
                }
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
            if let Some(r) = open {
                app.open_resource(r);
            }
        });
}

/// Resource `r` as a cell of the thumbnail grid: its image as of the current pass (a texture
/// whose thumbnail has arrived) or its kind, its name below; `true` when clicked.
fn thumbnail(ui: &mut egui::Ui, app: &View, model: &crate::model::Inspection, r: usize) -> bool {
    let pass = app.selection.pass;
    let res = &model.resources[r];
    let image = res
        .texture
        .as_ref()
        .and_then(|t| app.thumbnails.0.get(&(pass, t.plan_index)));
    let side = crate::worker::THUMBNAIL_SIZE as f32;
    ui.allocate_ui(egui::vec2(side, side + 16.0), |ui| {
        ui.vertical(|ui| {
            ui.set_width(side);
            ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Truncate);
            let (rect, response) =
                ui.allocate_exact_size(egui::vec2(side, side), egui::Sense::click());
            ui.painter()
                .rect_filled(rect, 3.0, ui.visuals().extreme_bg_color);
            match image {
                Some(image) => {
                    let size = image.size_vec2();
                    let scale = (side / size.x.max(size.y)).min(1.0);
                    let at = egui::Rect::from_center_size(rect.center(), size * scale);
                    ui.painter().image(
                        image.id(),
                        at,
                        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                        egui::Color32::WHITE,
                    );
                }
                None => {
                    ui.painter().text(
                        rect.center(),
                        egui::Align2::CENTER_CENTER,
                        &res.kind,
                        egui::FontId::proportional(11.0),
                        ui.visuals().weak_text_color(),
                    );
                }
            }
            if response.hovered() {
                ui.painter().rect_stroke(
                    rect,
                    3.0,
                    egui::Stroke::new(1.5, ui.visuals().selection.stroke.color),
                    egui::StrokeKind::Inside,
                );
            }
            let link = resource_link(ui, model, r);
            response
                .on_hover_text(format!("{}: open", res.name))
                .clicked()
                || link
        })
        .inner
    })
    .inner
}

/// The resource named `name` (barrier and binding rows name resources).
fn by_name(model: &crate::model::Inspection, name: &str) -> Option<usize> {
    model.resources.iter().position(|r| r.name == name)
}
