//! The memory view: per pool of the aliasing plan, each resource as a block spanning its
//! lifetime (passes, x) at its offset (y, height its size), so resources sharing memory at
//! different times stack in the same rows; the pool's extent and the lower bound (the most
//! bytes live at once) beside it; hover for names and bytes, the current pass marked.

use std::collections::BTreeMap;

use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};

use crate::model::MemoryBlock;
use crate::state::View;

fn mib(b: u64) -> String {
    format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0))
}

/// The most bytes live at any one pass.
pub fn lower_bound(blocks: &[&MemoryBlock], passes: usize) -> u64 {
    let mut live = vec![0u64; passes + 1];
    for b in blocks {
        for slot in live.iter_mut().take(b.last.min(passes) + 1).skip(b.first) {
            *slot += b.bytes;
        }
    }
    live.into_iter().max().unwrap_or(0)
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let passes = model.passes.len().max(1);
    let mut pools: BTreeMap<&str, Vec<&MemoryBlock>> = BTreeMap::new();
    for b in &model.memory {
        pools.entry(b.pool.as_str()).or_default().push(b);
    }
    if pools.is_empty() {
        ui.label("no placed resources");
        return;
    }
    egui::ScrollArea::vertical()
        .id_salt("memory")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            for (pool, blocks) in pools {
                let extent = blocks.iter().map(|b| b.offset + b.bytes).max().unwrap_or(0);
                ui.label(format!(
                    "{pool}: {} placed, {} lower bound, {} resources",
                    mib(extent),
                    mib(lower_bound(&blocks, passes)),
                    blocks.len()
                ));
                let (rect, response) =
                    ui.allocate_exact_size(Vec2::new(ui.available_width(), 140.0), Sense::hover());
                let painter = ui.painter_at(rect);
                painter.rect_filled(rect, 0.0, Color32::from_gray(20));
                let x = |p: usize| rect.left() + rect.width() * p as f32 / passes as f32;
                let y =
                    |o: u64| rect.top() + rect.height() * (o as f64 / extent.max(1) as f64) as f32;
                let mut hovered = None;
                for b in &blocks {
                    let r = Rect::from_min_max(
                        Pos2::new(x(b.first), y(b.offset)),
                        Pos2::new(x(b.last + 1), y(b.offset + b.bytes).max(y(b.offset) + 1.0)),
                    );
                    let hue = (b.resource.index() as f32 * 0.618_034).fract();
                    let fill: Color32 = egui::ecolor::Hsva::new(hue, 0.55, 0.75, 1.0).into();
                    painter.rect_filled(r, 1.0, fill);
                    painter.rect_stroke(
                        r,
                        1.0,
                        Stroke::new(0.5, Color32::BLACK),
                        egui::StrokeKind::Inside,
                    );
                    if response.hover_pos().is_some_and(|h| r.contains(h)) {
                        hovered = Some(*b);
                    }
                }
                let cx = x(app.selection.pass) + (x(1) - x(0)) / 2.0;
                painter.line_segment(
                    [Pos2::new(cx, rect.top()), Pos2::new(cx, rect.bottom())],
                    Stroke::new(1.5, Color32::WHITE),
                );
                if let Some(b) = hovered {
                    let name = &model.resources[b.resource.index()].name;
                    let pass = |i: usize| model.passes.get(i).map_or("?", |p| p.name.as_str());
                    response.on_hover_text(format!(
                        "{name}\n{} at offset {:#x}\n{} .. {}",
                        mib(b.bytes),
                        b.offset,
                        pass(b.first),
                        pass(b.last)
                    ));
                }
                ui.add_space(6.0);
            }
        });
}
