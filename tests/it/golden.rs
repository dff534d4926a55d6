//! Golden-image comparison: one metric and one tolerance for every image test. The metric is
//! NVIDIA's FLIP (`nv-flip`), which scores each pixel by how visible the difference is to a
//! viewer (colour and edges, at a standard viewing distance), so a tolerance means "looks the
//! same" rather than "same bytes". A missing golden fails (set FRAMELAB_BLESS=1 to write it,
//! which still fails so it gets reviewed); a mismatch writes `<golden>-actual.png` and
//! `<golden>-diff.png` (the FLIP error map) next to the golden.

use std::path::Path;

/// Mean FLIP error allowed over the image (0 identical, 1 as different as can be).
pub const MEAN_TOLERANCE: f64 = 0.01;
/// The 99th percentile of per-pixel FLIP error allowed: rasterisation on other drivers may
/// differ along edges, not across the image.
pub const P99_TOLERANCE: f64 = 0.2;

pub struct Comparison {
    pub mean: f64,
    pub p99: f64,
    /// The per-pixel error, as a colour-mapped picture.
    pub map: image::RgbImage,
}

pub fn compare(a: &image::RgbaImage, b: &image::RgbaImage) -> Comparison {
    let f = framelab_replay::compare::flip(b, a).expect("image sizes differ");
    Comparison {
        mean: f.mean,
        p99: f.p99,
        map: f.map,
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
        c.map.save(&diff_out).unwrap();
        panic!(
            "{} differs from {}: mean FLIP error {:.4} (max {:.4}), 99th percentile {:.4} (max {:.4}); wrote {} and {}",
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

/// `image` against `reference` with the golden metric: `Err` naming `what` and both figures
/// when it is past the tolerance. The figures are printed either way.
pub fn within(
    what: &str,
    image: &image::RgbaImage,
    reference: &image::RgbaImage,
) -> Result<(), String> {
    let c = compare(image, reference);
    eprintln!(
        "{what}: mean FLIP {:.4}, 99th percentile {:.4}",
        c.mean, c.p99
    );
    if c.mean > MEAN_TOLERANCE || c.p99 > P99_TOLERANCE {
        return Err(format!(
            "{what}: mean FLIP {:.4} (max {MEAN_TOLERANCE}), 99th percentile {:.4} (max {P99_TOLERANCE})",
            c.mean, c.p99
        ));
    }
    Ok(())
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
