//! The timeline: one lane per queue, each pass as wide as its GPU time and placed where its
//! work started, fences as lines from the signalling pass to the waiting one; hover for the
//! figures, click to make a pass current, wheel to zoom about the pointer, drag to pan,
//! double-click to see the whole frame again. With a compared report, bars take the colour of
//! the diff's verdict, explained by a legend.

use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};

use crate::state::View;

const LANE: f32 = 26.0;
const LABEL: f32 = 70.0;
const UNMEASURED_WIDTH: f32 = 6.0;

fn verdict_color(verdict: &str) -> Option<Color32> {
    match verdict {
        "regression" => Some(Color32::from_rgb(210, 70, 60)),
        "improvement" => Some(Color32::from_rgb(70, 170, 90)),
        _ => None,
    }
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let Some(timings) = app.timings.clone() else {
        ui.label(if app.replays() {
            "waiting for the first timed frame..."
        } else {
            "not replayed, so not timed: give --timings a report"
        });
        return;
    };
    let end = timings
        .passes
        .iter()
        .flatten()
        .filter(|t| t.measured)
        .map(|t| t.start_ns + t.gpu_ns)
        .fold(0.0f64, f64::max);
    if end <= 0.0 {
        ui.label("the adapter gave no timestamps");
        return;
    }
    // The visible span: (start, length) in ns, within the frame.
    let (mut t0, mut span) = app.timeline_span.unwrap_or((0.0, end));
    span = span.clamp(end * 1e-4, end);
    t0 = t0.clamp(0.0, end - span);
    ui.horizontal(|ui| {
        ui.weak(format!(
            "frame: {:.3} ms on the GPU (from {})",
            end / 1e6,
            timings.source
        ));
        if span < end {
            ui.weak(format!(
                "showing {:.3}-{:.3} ms (double-click: whole frame)",
                t0 / 1e6,
                (t0 + span) / 1e6
            ));
        }
    });
    compare_legend(ui, &model);
    if let Some(note) = &timings.note {
        ui.weak(format!("grey: not measured ({note})"));
    }
    let counted = (0..model.passes.len()).any(|i| super::work::measure(&timings, i, 0).is_some());
    // Colouring by a measure: bars on a ramp from the frame's least to its most.
    let by = app.timeline_color.filter(|_| counted);
    let most = by.map_or(0.0, |m| {
        (0..model.passes.len())
            .filter_map(|i| super::work::measure(&timings, i, m))
            .fold(0.0f64, f64::max)
    });
    if counted {
        colour_by(app, ui, by, most);
    }
    let height = LANE * model.queues.len() as f32 + 20.0;
    let (rect, response) = ui.allocate_exact_size(
        Vec2::new(ui.available_width(), height),
        Sense::click_and_drag(),
    );
    let painter = ui.painter_at(rect);
    let width = (rect.width() - LABEL - 4.0).max(1.0);
    let x_of = |ns: f64| rect.left() + LABEL + (((ns - t0) / span) as f32) * width;
    zoom(app, ui, &response, (rect, width), (t0, span, end));
    lane_names(ui, &painter, rect, &model.queues);
    let bar = |i: usize| -> Option<Rect> {
        let t = timings.passes.get(i).copied().flatten()?;
        let p = model.passes.get(i)?;
        let y = rect.top() + p.queue as f32 * LANE + 3.0;
        let x0 = x_of(t.start_ns);
        // An unmeasured pass keeps its place, narrow, so it can still be found and clicked.
        let x1 = if t.measured {
            x_of(t.start_ns + t.gpu_ns).max(x0 + 2.0)
        } else {
            x0 + UNMEASURED_WIDTH
        };
        Some(Rect::from_min_max(
            Pos2::new(x0, y),
            Pos2::new(x1, y + LANE - 6.0),
        ))
    };
    // Bars and fences stay right of the lane names however far the view is zoomed.
    let lanes = painter.with_clip_rect(Rect::from_min_max(
        Pos2::new(rect.left() + LABEL, rect.top()),
        rect.max,
    ));
    let mut hovered = None;
    app.timeline_bars.clear();
    for (i, p) in model.passes.iter().enumerate() {
        let Some(r) = bar(i) else { continue };
        app.timeline_bars.push((i, r));
        let compare = model
            .compare
            .as_ref()
            .and_then(|c| c.passes.get(i).cloned().flatten());
        let color = match by {
            Some(m) => super::work::measure(&timings, i, m)
                .map_or(Color32::from_gray(90), |v| super::work::ramp(v, most)),
            None => compare
                .as_ref()
                .and_then(|c| verdict_color(&c.verdict))
                .unwrap_or_else(|| super::queue_color(p.queue)),
        };
        let measured = timings.passes[i].is_some_and(|t| t.measured);
        let color = if !measured {
            Color32::from_gray(110)
        } else if p.culled {
            color.gamma_multiply(0.4)
        } else {
            color
        };
        lanes.rect_filled(r, 2.0, color);
        if i == app.selection.pass {
            lanes.rect_stroke(
                r,
                2.0,
                Stroke::new(2.0, Color32::WHITE),
                egui::StrokeKind::Outside,
            );
        }
        if r.width() > 40.0 {
            lanes.text(
                r.left_center() + Vec2::new(3.0, 0.0),
                egui::Align2::LEFT_CENTER,
                &p.name,
                egui::FontId::proportional(11.0),
                Color32::BLACK,
            );
        }
        if response.hover_pos().is_some_and(|h| r.contains(h)) {
            hovered = Some(i);
        }
    }
    for &(from, to) in &model.fences {
        if let (Some(a), Some(b)) = (bar(from), bar(to)) {
            let (p0, p1) = (a.right_center(), b.left_center());
            lanes.line_segment([p0, p1], Stroke::new(1.5, Color32::YELLOW));
            lanes.circle_filled(p1, 3.0, Color32::YELLOW);
        }
    }
    if let Some(i) = hovered {
        let text = hover_text(&model, &timings, i, by);
        response.clone().on_hover_text(text);
        if response.clicked() {
            app.select_pass(i);
        }
    }
}

/// What a compared report's bar colours mean, and the comparison's note.
fn compare_legend(ui: &mut egui::Ui, model: &crate::model::Inspection) {
    if model.compare.is_some() {
        ui.horizontal(|ui| {
            for (verdict, text) in [
                ("regression", "slower there"),
                ("improvement", "faster there"),
            ] {
                if let Some(c) = verdict_color(verdict) {
                    let (r, _) = ui.allocate_exact_size(Vec2::splat(10.0), Sense::hover());
                    ui.painter().rect_filled(r, 2.0, c);
                    ui.weak(format!("{verdict}: {text}"));
                }
            }
            ui.weak("queue colour: no significant change, or too few frames to tell");
        });
        if let Some(note) = &model.compare.as_ref().and_then(|c| c.note.clone()) {
            ui.colored_label(Color32::from_rgb(240, 180, 60), note);
        }
    }
}

/// The measure the bars are coloured by, chosen in a combo box, and its ramp's legend.
fn colour_by(app: &mut View, ui: &mut egui::Ui, by: Option<usize>, most: f64) {
    ui.horizontal(|ui| {
        // Named by its label, which screen readers (and the UI tests) find it by.
        egui::ComboBox::new("timeline colour", "colour by")
            .selected_text(by.map_or("queue", |m| super::work::MEASURES[m]))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut app.timeline_color, None, "queue");
                for (m, name) in super::work::MEASURES.iter().enumerate() {
                    ui.selectable_value(&mut app.timeline_color, Some(m), *name);
                }
            });
        if let Some(m) = by {
            let (r, _) = ui.allocate_exact_size(Vec2::new(60.0, 10.0), Sense::hover());
            for k in 0..12 {
                let x = r.left() + r.width() * k as f32 / 12.0;
                let cell = Rect::from_min_max(
                    Pos2::new(x, r.top()),
                    Pos2::new(x + r.width() / 12.0 + 0.5, r.bottom()),
                );
                let v = most * f64::from(k) / 11.0;
                ui.painter()
                    .rect_filled(cell, 0.0, super::work::ramp(v, most));
            }
            ui.weak(format!(
                "0 .. {} {} (grey: not counted)",
                if m == 5 {
                    format!("{most:.2}")
                } else {
                    framelab_core::timing::counters::short(most as u64)
                },
                super::work::MEASURES[m]
            ));
        }
    });
}

/// Each queue's name at the start of its lane, and the line under the lane.
fn lane_names(ui: &egui::Ui, painter: &egui::Painter, rect: Rect, queues: &[String]) {
    for (q, name) in queues.iter().enumerate() {
        let y = rect.top() + q as f32 * LANE;
        painter.text(
            Pos2::new(rect.left() + 2.0, y + LANE / 2.0),
            egui::Align2::LEFT_CENTER,
            name,
            egui::FontId::proportional(12.0),
            ui.visuals().text_color(),
        );
        painter.line_segment(
            [
                Pos2::new(rect.left(), y + LANE),
                Pos2::new(rect.right(), y + LANE),
            ],
            Stroke::new(1.0, Color32::from_gray(60)),
        );
    }
}

/// A pass's figures for the tooltip: its time (or why not measured), the measure the bars
/// are coloured by, and the comparison.
fn hover_text(
    model: &crate::model::Inspection,
    timings: &crate::model::Timings,
    i: usize,
    by: Option<usize>,
) -> String {
    let p = &model.passes[i];
    let t = timings.passes[i];
    let mut text = match t {
        Some(t) if !t.measured => format!(
            "{}\nnot measured: {}\nstarts at {:.3} ms",
            p.name,
            timings
                .note
                .as_deref()
                .unwrap_or("the adapter cannot time it"),
            t.start_ns / 1e6
        ),
        _ => format!(
            "{}\n{:.3} ms, starts at {:.3} ms",
            p.name,
            t.map_or(0.0, |t| t.gpu_ns / 1e6),
            t.map_or(0.0, |t| t.start_ns / 1e6)
        ),
    };
    if let Some(m) = by {
        text.push_str(&match super::work::measure(timings, i, m) {
            Some(v) => format!("\n{}: {v:.2}", super::work::MEASURES[m]),
            None => format!("\n{}: not counted", super::work::MEASURES[m]),
        });
    }
    if let Some(c) = model
        .compare
        .as_ref()
        .and_then(|c| c.passes.get(i).cloned().flatten())
    {
        text.push_str(&match &c.moved {
            Some(q) => format!("\nthere: {:.3} ms on {q} (moved: not compared)", c.other_ms),
            None => format!(
                "\ncompared: {:.3} ms, {:+.1}% ({})",
                c.other_ms, c.change_pct, c.verdict
            ),
        });
    }
    text
}

/// Double-click shows the whole frame; the wheel zooms about the time under the pointer and a
/// drag moves the span with it (`t0` and `span` shown of a frame `end` long).
fn zoom(
    app: &mut View,
    ui: &egui::Ui,
    response: &egui::Response,
    (rect, width): (Rect, f32),
    (t0, span, end): (f64, f64, f64),
) {
    if response.double_clicked() {
        app.timeline_span = None;
    } else if let Some(at) = response.hover_pos() {
        let wheel = ui.input(|i| i.smooth_scroll_delta.y);
        let drag = response.drag_delta().x;
        if wheel != 0.0 || drag != 0.0 {
            // Zoom about the time under the pointer; drag moves the span with the pointer.
            let under = t0 + f64::from((at.x - rect.left() - LABEL) / width) * span;
            let factor = f64::from((-wheel / 200.0).exp());
            let new_span = (span * factor).clamp(end * 1e-4, end);
            let mut new_t0 = under - (under - t0) * new_span / span;
            new_t0 -= f64::from(drag / width) * new_span;
            app.timeline_span = Some((new_t0.clamp(0.0, end - new_span), new_span));
        }
    }
}
