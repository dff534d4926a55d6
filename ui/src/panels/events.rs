//! The event browser: marker groups, passes in execution order with queue and GPU time, each
//! pass's draws, dispatches, copies and clears when expanded (a draw or dispatch selected shows
//! the frame as of it); a filter; culled passes greyed.

use crate::model::Inspection;
use crate::state::View;

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

/// One line of the event list.
enum Line<'a> {
    Group {
        depth: usize,
        name: &'a str,
    },
    Pass(usize),
    Work {
        depth: usize,
        pass: usize,
        index: usize,
        text: &'a str,
    },
}

/// The list as lines: marker groups open where a pass's path leaves the previous one's, the
/// work of each expanded pass below it.
fn lines<'a>(
    model: &'a Inspection,
    visible: &[usize],
    expanded: &std::collections::BTreeSet<usize>,
) -> Vec<Line<'a>> {
    let mut out = Vec::new();
    let mut open: Vec<&str> = Vec::new();
    for &i in visible {
        let p = &model.passes[i];
        let common = open
            .iter()
            .zip(&p.markers)
            .take_while(|(a, b)| **a == b.as_str())
            .count();
        open.truncate(common);
        for (depth, m) in p.markers.iter().enumerate().skip(common) {
            out.push(Line::Group { depth, name: m });
            open.push(m);
        }
        out.push(Line::Pass(i));
        if expanded.contains(&i) {
            for (index, w) in p.work.iter().enumerate() {
                out.push(Line::Work {
                    depth: p.markers.len(),
                    pass: i,
                    index,
                    text: w,
                });
            }
        }
    }
    out
}

const ROW: f32 = 20.0;

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        let label = ui.label("filter");
        ui.add(
            egui::TextEdit::singleline(&mut app.selection.filter)
                .id_salt("event filter")
                .desired_width(f32::INFINITY),
        )
        .labelled_by(label.id);
    });
    let model = app.model.clone();
    let current = app.selection.pass;
    let rows = lines(
        &model,
        &visible(&model, &app.selection.filter),
        &app.selection.expanded,
    );
    let mut clicked = None;
    let mut step_clicked = None;
    let mut toggled = None;
    let mut area = egui::ScrollArea::vertical()
        .id_salt("events")
        .auto_shrink([false, false]);
    // Bring a newly current pass into view (only visible rows are laid out, so it cannot
    // scroll itself there).
    if app.events_scrolled_to != Some(current) {
        app.events_scrolled_to = Some(current);
        if let Some(row) = rows
            .iter()
            .position(|l| matches!(l, Line::Pass(i) if *i == current))
        {
            let view = ui.available_height();
            area = area.vertical_scroll_offset((row as f32 * ROW - view / 2.0).max(0.0));
        }
    }
    area.show_rows(ui, ROW, rows.len(), |ui, range| {
        for line in &rows[range] {
            ui.horizontal(|ui| {
                ui.set_height(ROW - ui.spacing().item_spacing.y);
                match line {
                    Line::Group { depth, name } => {
                        ui.add_space(*depth as f32 * 12.0);
                        ui.label(egui::RichText::new(format!("{name} /")).strong());
                    }
                    Line::Work {
                        depth,
                        pass,
                        index,
                        text,
                    } => {
                        ui.add_space(*depth as f32 * 12.0 + 24.0);
                        let p = &model.passes[*pass];
                        let text = egui::RichText::new(*text).small();
                        if *index < p.steps {
                            // A draw or dispatch: the frame as of it.
                            let on = *pass == current && app.selection.step == Some(*index);
                            if ui.add(egui::Button::selectable(on, text)).clicked() {
                                step_clicked = Some((*pass, *index));
                            }
                        } else {
                            ui.label(text);
                        }
                    }
                    Line::Pass(i) => {
                        let p = &model.passes[*i];
                        let ms = super::pass_ms(app, *i)
                            .map_or("-".to_owned(), |ms| format!("{ms:.3} ms"));
                        // Figures first, from the right, so a long name is cut short instead
                        // of running under them.
                        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                            // In a narrow panel the name matters more than the figures: the
                            // queue's colour bar stays, and the time shows on the timeline.
                            let width = ui.available_width();
                            if width > 180.0 {
                                ui.label(egui::RichText::new(ms).monospace());
                            }
                            if width > 240.0 {
                                ui.label(egui::RichText::new(&model.queues[p.queue]).weak());
                            }
                            ui.with_layout(
                                egui::Layout::left_to_right(egui::Align::Center),
                                |ui| {
                                    ui.add_space(p.markers.len() as f32 * 12.0);
                                    let open = app.selection.expanded.contains(i);
                                    if p.work.is_empty() {
                                        ui.add_space(14.0);
                                    } else if ui
                                        .add(
                                            egui::Button::new(if open { "v" } else { ">" })
                                                .small()
                                                .frame(false),
                                        )
                                        .on_hover_text("show its draws, dispatches and copies")
                                        .clicked()
                                    {
                                        toggled = Some(*i);
                                    }
                                    let (rect, _) = ui.allocate_exact_size(
                                        egui::vec2(4.0, 14.0),
                                        egui::Sense::hover(),
                                    );
                                    ui.painter().rect_filled(
                                        rect,
                                        1.0,
                                        super::queue_color(p.queue),
                                    );
                                    let mut text = egui::RichText::new(&p.name);
                                    if p.culled {
                                        text = text.weak().italics();
                                    }
                                    let r = ui
                                        .add(
                                            egui::Button::selectable(*i == current, text)
                                                .truncate(),
                                        )
                                        .on_hover_text(format!("{} ({} pass)", p.name, p.kind));
                                    if r.clicked() {
                                        clicked = Some(*i);
                                    }
                                },
                            );
                        });
                    }
                }
            });
        }
    });
    if let Some(i) = clicked {
        app.select_pass(i);
    }
    if let Some((pass, step)) = step_clicked {
        app.select_step(pass, step);
    }
    if let Some(i) = toggled
        && !app.selection.expanded.remove(&i)
    {
        app.selection.expanded.insert(i);
    }
}
