//! Work counters in the inspector: each pass's pipeline statistics and submitted work, with
//! the ratios read off them, in the pass details; and the measures the timeline can be
//! coloured by (any counter, or overdraw), on a ramp from the frame's smallest to its largest.

use egui::Color32;
use framelab_core::timing::counters::{NAMES, Ratios, Work, short};

use crate::model::Timings;

/// What the timeline can colour its bars by, besides the queue: the five counters, then
/// overdraw.
pub const MEASURES: [&str; 6] = [NAMES[0], NAMES[1], NAMES[2], NAMES[3], NAMES[4], "overdraw"];

/// Pass `i`'s value of measure `m` (see [`MEASURES`]), when counted.
pub fn measure(t: &Timings, i: usize, m: usize) -> Option<f64> {
    let c = t.passes.get(i).copied().flatten()?.counters?;
    match m {
        0..5 => Some(c[m] as f64),
        _ => {
            let w = t.work.get(i).cloned().flatten()?;
            Ratios::of(&c, &w).overdraw
        }
    }
}

/// A colour from dark blue (none) to orange-red (the frame's most), by the value's share of
/// the most: the passes that do the frame's work stand out, as bars of its time do.
pub fn ramp(value: f64, max: f64) -> Color32 {
    let x = if max > 0.0 {
        (value / max).clamp(0.0, 1.0) as f32
    } else {
        0.0
    };
    let lerp = |a: u8, b: u8| (f32::from(a) + (f32::from(b) - f32::from(a)) * x) as u8;
    Color32::from_rgb(lerp(40, 235), lerp(60, 90), lerp(120, 40))
}

/// The details section: counters, submitted work and ratios of pass `i`.
pub fn section(ui: &mut egui::Ui, t: Option<&Timings>, i: usize) {
    let counters = t.and_then(|t| t.passes.get(i).copied().flatten()?.counters);
    let work: Option<Work> = t.and_then(|t| t.work.get(i).cloned().flatten());
    let n = usize::from(counters.is_some()) * 5 + usize::from(work.is_some()) * 4;
    egui::CollapsingHeader::new(format!("Counters ({n})"))
        .default_open(counters.is_some())
        .show(ui, |ui| {
            if counters.is_none() && work.is_none() {
                ui.weak("not counted: the pass has no draws or dispatches, or the adapter no pipeline statistics");
                return;
            }
            egui::Grid::new("work").striped(true).show(ui, |ui| {
                let mut row = |k: &str, v: String| {
                    ui.label(egui::RichText::new(k).monospace());
                    ui.label(v);
                    ui.end_row();
                };
                if let Some(c) = counters {
                    for (name, v) in NAMES.iter().zip(c) {
                        row(name, format!("{v} ({})", short(v)));
                    }
                }
                if let Some(w) = &work {
                    row("draws / dispatches", format!("{} / {} ({} indirect)", w.draws, w.dispatches, w.indirect));
                    row("instances, indices, vertices", format!("{}, {}, {}", w.instances, w.indices, w.vertices));
                    row("render area", format!("{} px", w.render_area));
                    row("threads dispatched", w.threads.to_string());
                }
                if let (Some(c), Some(w)) = (counters, &work) {
                    let r = Ratios::of(&c, w);
                    let f = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
                    row("overdraw (fragments per pixel)", f(r.overdraw));
                    row("vertices per primitive", f(r.vertices_per_primitive));
                    row("fragments per primitive", f(r.fragments_per_primitive));
                    row("invocations per thread", f(r.invocations_per_thread));
                }
            });
        });
}
