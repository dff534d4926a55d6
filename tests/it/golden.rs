//! Golden-image comparison: one metric and one tolerance for every image test. A missing golden
//! fails (set FRAMELAB_BLESS=1 to write it, which still fails so it gets reviewed); a mismatch
//! writes `<golden>-actual.png` and `<golden>-diff.png` next to the golden.

use std::path::Path;

/// Mean absolute per-channel error allowed (0..1 scale).
pub const MEAN_TOLERANCE: f64 = 2.0 / 255.0;
/// The 99th percentile of per-pixel maximum channel error allowed: rasterisation on other
/// drivers may differ along edges, not across the image.
pub const P99_TOLERANCE: f64 = 48.0 / 255.0;

pub struct Comparison {
    pub mean: f64,
    pub p99: f64,
}

pub fn compare(a: &image::RgbaImage, b: &image::RgbaImage) -> Comparison {
    assert_eq!(a.dimensions(), b.dimensions(), "image sizes differ");
    let mut per_pixel: Vec<f64> = Vec::with_capacity((a.width() * a.height()) as usize);
    let mut sum = 0.0;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let mut worst = 0.0f64;
        for c in 0..4 {
            let d = (f64::from(pa[c]) - f64::from(pb[c])).abs() / 255.0;
            sum += d;
            worst = worst.max(d);
        }
        per_pixel.push(worst);
    }
    per_pixel.sort_by(f64::total_cmp);
    let p99 = per_pixel[((per_pixel.len() as f64 * 0.99) as usize).min(per_pixel.len() - 1)];
    Comparison {
        mean: sum / (per_pixel.len() * 4) as f64,
        p99,
    }
}

pub fn assert_matches_golden(actual_path: &Path, golden: &Path) {
    let actual = image::open(actual_path).unwrap().to_rgba8();
    if !golden.exists() {
        if std::env::var_os("FRAMELAB_BLESS").is_some() {
            std::fs::copy(actual_path, golden).unwrap();
            panic!(
                "golden {} written from this run: review it and commit it",
                golden.display()
            );
        }
        panic!(
            "golden {} is missing (run with FRAMELAB_BLESS=1 to write it from this run)",
            golden.display()
        );
    }
    let expected = image::open(golden).unwrap().to_rgba8();
    let c = compare(&actual, &expected);
    if c.mean > MEAN_TOLERANCE || c.p99 > P99_TOLERANCE {
        let stem = golden.with_extension("");
        let actual_out = stem.with_file_name(format!(
            "{}-actual.png",
            stem.file_name().unwrap().to_string_lossy()
        ));
        let diff_out = stem.with_file_name(format!(
            "{}-diff.png",
            stem.file_name().unwrap().to_string_lossy()
        ));
        actual.save(&actual_out).unwrap();
        let diff = image::RgbaImage::from_fn(actual.width(), actual.height(), |x, y| {
            let (p, q) = (actual.get_pixel(x, y), expected.get_pixel(x, y));
            let d =
                |c: usize| ((i32::from(p[c]) - i32::from(q[c])).unsigned_abs() * 4).min(255) as u8;
            image::Rgba([d(0), d(1), d(2), 255])
        });
        diff.save(&diff_out).unwrap();
        panic!(
            "{} differs from {}: mean error {:.4} (max {:.4}), 99th percentile {:.4} (max {:.4}); wrote {} and {}",
            actual_path.display(),
            golden.display(),
            c.mean,
            MEAN_TOLERANCE,
            c.p99,
            P99_TOLERANCE,
            actual_out.display(),
            diff_out.display()
        );
    }
}

/// Inspector panel snapshots (egui_kittest): a pixel fails when its YIQ distance exceeds
/// `UI_PIXEL_THRESHOLD` (kittest's default 0.6 absorbs backend anti-aliasing differences);
/// up to `UI_FAILED_PIXELS` may fail, so a moved separator or a changed label still does.
pub const UI_PIXEL_THRESHOLD: f32 = 0.6;
pub const UI_FAILED_PIXELS: usize = 8;

/// Where the inspector's blessed panel images live and how they are compared. A missing image
/// fails; `UPDATE_SNAPSHOTS=1` writes it from the run.
pub fn ui_snapshot_options() -> framelab_ui::egui_kittest::SnapshotOptions {
    framelab_ui::egui_kittest::SnapshotOptions::new()
        .threshold(UI_PIXEL_THRESHOLD)
        .max_failed_pixels(UI_FAILED_PIXELS)
        .output_path(crate::common::repo().join("tests/goldens/inspector"))
}
