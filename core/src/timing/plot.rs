//! The timing diff as a picture: one line per pass (and the frame total) from the low to the
//! high end of its 95% interval with a dot at the observed change, coloured by verdict, against
//! zero and the ± threshold, so a reader sees at a glance what moved and how surely.

use plotters::prelude::*;

use super::diff::{DiffReport, RowKind, Verdict};

#[derive(Debug, thiserror::Error)]
#[error("drawing the diff plot: {0}")]
pub struct PlotError(String);

/// The diff's total and passes as an SVG document.
pub fn svg(d: &DiffReport) -> Result<String, PlotError> {
    let rows: Vec<_> = d
        .rows
        .iter()
        .filter(|r| matches!(r.kind, RowKind::Total | RowKind::Pass))
        .collect();
    let names: Vec<String> = rows
        .iter()
        .map(|r| match &r.renamed_from {
            Some(old) => format!("{} (was {old})", r.name),
            None => r.name.clone(),
        })
        .collect();
    let t = d.threshold_pct;
    let (lo, hi) = rows
        .iter()
        .flat_map(|r| {
            let [a, b] = r.interval_pct.unwrap_or([r.change_pct, r.change_pct]);
            [a, b, r.change_pct]
        })
        .filter(|v| v.is_finite())
        .fold((-2.0 * t, 2.0 * t), |(a, b), v| (a.min(v), b.max(v)));
    let pad = (hi - lo) * 0.05;
    let n = rows.len().max(1);
    let mut out = String::new();
    {
        let err = |e: &dyn std::fmt::Display| PlotError(e.to_string());
        let height = 90 + 22 * n as u32;
        let root = SVGBackend::with_string(&mut out, (960, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let caption = format!(
            "{} (A) against {} (B): change of each pass's median GPU time, 95% interval",
            d.a.capture, d.b.capture
        );
        let mut chart = ChartBuilder::on(&root)
            .margin(12)
            .caption(caption, ("sans-serif", 15))
            .x_label_area_size(36)
            .y_label_area_size(240)
            .build_cartesian_2d((lo - pad)..(hi + pad), -0.5f64..(n as f64 - 0.5))
            .map_err(|e| err(&e))?;
        let label = |y: &f64| {
            let i = n as f64 - 1.0 - y.round();
            names.get(i as usize).cloned().unwrap_or_default()
        };
        chart
            .configure_mesh()
            .y_labels(n)
            .y_label_formatter(&label)
            .x_desc("change of the median (%)")
            .disable_y_mesh()
            .draw()
            .map_err(|e| err(&e))?;
        let span = [-0.5, n as f64 - 0.5];
        for (x, style) in [
            (0.0, BLACK.stroke_width(1)),
            (t, RGBColor(200, 120, 0).stroke_width(1)),
            (-t, RGBColor(200, 120, 0).stroke_width(1)),
        ] {
            chart
                .draw_series(LineSeries::new(span.iter().map(|&y| (x, y)), style))
                .map_err(|e| err(&e))?;
        }
        for (i, r) in rows.iter().enumerate() {
            let y = n as f64 - 1.0 - i as f64;
            let colour = match r.verdict {
                Verdict::Regression => RGBColor(200, 30, 30),
                Verdict::Improvement => RGBColor(30, 140, 60),
                _ => RGBColor(110, 110, 110),
            };
            if let Some([a, b]) = r.interval_pct {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(a, y), (b, y)],
                        colour.stroke_width(3),
                    )))
                    .map_err(|e| err(&e))?;
            }
            chart
                .draw_series(std::iter::once(Circle::new(
                    (r.change_pct, y),
                    4,
                    colour.filled(),
                )))
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    Ok(out)
}
