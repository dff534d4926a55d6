//! Every WGSL file under `captures/` parses and validates with naga, without a GPU.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
}

#[test]
fn every_capture_shader_validates() {
    let captures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../captures");
    let mut files = Vec::new();
    wgsl_files(&captures, &mut files);
    files.sort();
    assert!(
        !files.is_empty(),
        "no shaders found under {}",
        captures.display()
    );
    let errors: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let source = std::fs::read_to_string(f).unwrap();
            framelab_replay::validate_wgsl(&f.display().to_string(), &source)
                .err()
                .map(|e| e.report)
        })
        .collect();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}
