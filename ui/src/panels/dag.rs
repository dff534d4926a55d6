//! The pass DAG drawn with egui's painter: passes in layers (a pass one layer right of the
//! latest pass it depends on), coloured by queue, culled passes grey; data hazards as solid
//! (read after write), dashed (write after read) and dotted (write after write) lines, queue
//! order thin grey, fences yellow; drag to pan, wheel to zoom, click a pass to make it current;
//! the current pass is centred when it changes.

use egui::{Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};

use crate::model::{EdgeKind, Inspection};
use crate::state::View;

const NODE: Vec2 = Vec2::new(150.0, 22.0);
const GAP: Vec2 = Vec2::new(40.0, 10.0);

/// Each pass's (layer, row): the layer one past the deepest pass it depends on (edges go
/// from earlier to later passes), rows in execution order within a layer.
pub fn layout(model: &Inspection) -> Vec<(usize, usize)> {
    let n = model.passes.len();
    let mut layer = vec![0usize; n];
    for e in &model.edges {
        if e.from < e.to && e.to < n {
            layer[e.to] = layer[e.to].max(layer[e.from] + 1);
        }
    }
    // Edges are sorted by source; a second sweep in target order settles chains.
    let mut by_target: Vec<&crate::model::Edge> = model.edges.iter().collect();
    by_target.sort_by_key(|e| e.to);
    for e in by_target {
        if e.from < e.to && e.to < n {
            layer[e.to] = layer[e.to].max(layer[e.from] + 1);
        }
    }
    let mut rows = vec![0usize; layer.iter().max().map_or(0, |m| m + 1)];
    layer
        .iter()
        .map(|&l| {
            let r = rows[l];
            rows[l] += 1;
            (l, r)
        })
        .collect()
}

fn dashed(points: [Pos2; 2], stroke: Stroke, dash: f32, gap: f32) -> Vec<Shape> {
    Shape::dashed_line(&points, stroke, dash, gap)
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let cells = layout(&model);
    let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
    if response.dragged() {
        app.dag_view.0 += response.drag_delta();
    }
    if response.hovered() {
        let wheel = ui.input(|i| i.smooth_scroll_delta.y);
        if wheel != 0.0 {
            app.dag_view.1 = (app.dag_view.1 * (1.0 + wheel / 300.0)).clamp(0.2, 3.0);
        }
    }
    // A newly selected pass is brought to the centre; dragging moves away from it freely.
    if app.dag_centred != Some(app.selection.pass)
        && let Some(&(l, r)) = cells.get(app.selection.pass)
    {
        let zoom = app.dag_view.1;
        let node = Vec2::new(l as f32 * (NODE.x + GAP.x), r as f32 * (NODE.y + GAP.y)) * zoom
            + NODE * zoom / 2.0;
        app.dag_view.0 = rect.center() - (rect.min + Vec2::splat(8.0) + node);
        app.dag_centred = Some(app.selection.pass);
    }
    let (pan, zoom) = app.dag_view;
    let origin = rect.min + Vec2::splat(8.0) + pan;
    let node_rect = |(l, r): (usize, usize)| {
        let min =
            origin + Vec2::new(l as f32 * (NODE.x + GAP.x), r as f32 * (NODE.y + GAP.y)) * zoom;
        Rect::from_min_size(min, NODE * zoom)
    };
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(20));
    for e in &model.edges {
        let (Some(&a), Some(&b)) = (cells.get(e.from), cells.get(e.to)) else {
            continue;
        };
        let points = [node_rect(a).right_center(), node_rect(b).left_center()];
        let data = Color32::from_gray(200);
        match e.kind {
            EdgeKind::Raw => {
                painter.line_segment(points, Stroke::new(1.5, data));
            }
            EdgeKind::War => {
                painter.extend(dashed(points, Stroke::new(1.2, data), 6.0, 4.0));
            }
            EdgeKind::Waw => {
                painter.extend(dashed(points, Stroke::new(1.2, data), 2.0, 3.0));
            }
            EdgeKind::Queue => {
                painter.line_segment(points, Stroke::new(0.8, Color32::from_gray(90)));
            }
            EdgeKind::Fence => {
                painter.line_segment(points, Stroke::new(1.5, Color32::YELLOW));
            }
        }
    }
    app.dag_nodes.clear();
    let mut clicked = None;
    for (i, p) in model.passes.iter().enumerate() {
        let r = node_rect(cells[i]);
        app.dag_nodes.push((i, r));
        let fill = if p.culled {
            Color32::from_gray(70)
        } else {
            super::queue_color(p.queue)
        };
        painter.rect_filled(r, 3.0, fill);
        if i == app.selection.pass {
            painter.rect_stroke(
                r,
                3.0,
                Stroke::new(2.0, Color32::WHITE),
                egui::StrokeKind::Outside,
            );
        }
        painter.text(
            r.left_center() + Vec2::new(4.0, 0.0),
            egui::Align2::LEFT_CENTER,
            &p.name,
            egui::FontId::proportional(11.0 * zoom),
            Color32::BLACK,
        );
        if response.clicked()
            && response
                .interact_pointer_pos()
                .is_some_and(|at| r.contains(at))
        {
            clicked = Some(i);
        }
    }
    if let Some(i) = clicked {
        app.select_pass(i);
    }
}
