//! Real programs' frames replayed: each binary capture is imported, replayed through wgpu on
//! the available adapter, and the image it presents (the manifest entry marked `presented`)
//! compared with the screenshot `gfxrecon-replay --screenshot-all` took of the same capture on
//! the same device, with the golden metric and tolerance. What the replay cannot do is an
//! error naming the pass, the shader and the feature; a damaged module never reaches the
//! driver; the Khronos validation layer reports nothing on the replay of any of them.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{framelab, gfxr_fixture, stderr};

/// Captures whose presented image is compared with `<name>.ref.png`.
const REPLAYED: [&str; 6] = [
    "vkcube_f3",
    "vkcube_f3_zstd",
    "vkcubepp_f3",
    "vkd3d_triangle_f1",
    "vkd3d_gears_f2",
    "framelab_inspect_f3",
];

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("framelab-gfxr-replay-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Imports `name` into `dir`, returning the capture's path.
fn import(name: &str, dir: &Path) -> PathBuf {
    let capture = dir.join(format!("{name}.json"));
    let out = framelab(&[
        "import",
        gfxr_fixture(&format!("{name}.gfxr")).to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    capture
}

fn manifest(out: &Path) -> Vec<Value> {
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap())
            .unwrap();
    m["files"].as_array().unwrap().clone()
}

#[test]
fn real_frames_replay_to_the_image_they_presented() {
    let mut failures = Vec::new();
    for name in REPLAYED {
        let dir = temp(name);
        let capture = import(name, &dir);
        let out = dir.join("out");
        let run = framelab(&[
            "replay",
            capture.to_str().unwrap(),
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        let notes = stderr(&run);
        assert!(
            notes.contains(" path"),
            "{name}: the replay names no shader path:\n{notes}"
        );
        let files = manifest(&out);
        let presented: Vec<&Value> = files
            .iter()
            .filter(|f| f["presented"] == Value::Bool(true))
            .collect();
        assert_eq!(presented.len(), 1, "{name}: one presented image");
        let image = image::open(out.join(presented[0]["file"].as_str().unwrap()))
            .unwrap()
            .to_rgba8();
        let reference = image::open(gfxr_fixture(&format!("{name}.ref.png")))
            .unwrap()
            .to_rgba8();
        let c = crate::golden::compare(&image, &reference);
        eprintln!(
            "{name}: mean FLIP {:.4}, 99th percentile {:.4}",
            c.mean, c.p99
        );
        if c.mean > crate::golden::MEAN_TOLERANCE || c.p99 > crate::golden::P99_TOLERANCE {
            failures.push(format!(
                "{name}: mean FLIP {:.4} (max {}), 99th percentile {:.4} (max {})",
                c.mean,
                crate::golden::MEAN_TOLERANCE,
                c.p99,
                crate::golden::P99_TOLERANCE
            ));
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
