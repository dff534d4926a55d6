//! Every WGSL file under `captures/` parses and validates with naga, without a GPU.

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
            framelab_core::shader::validate_wgsl(&f.display().to_string(), &source)
                .err()
                .map(|e| e.report)
        })
        .collect();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}

/// WGSL has no includes, so the Night City shaders repeat the few functions and constants that
/// define the world (the terrain height, its noise, the position decoding, the cluster grid,
/// the city layout, depth reconstruction, luminance, the environment BRDF). Every copy must be
/// the same text, or passes would disagree about where the ground is or which cluster a pixel
/// falls in.
#[test]
fn shared_world_functions_agree_across_night_city_shaders() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../captures/night_city/shaders");
    let mut files = Vec::new();
    wgsl_files(&dir, &mut files);
    files.sort();
    let shared = [
        "fn terrain_height(",
        "fn fbm2(",
        "fn noise2(",
        "fn hash21(",
        "fn decode_position(",
        "fn vs_fullscreen(",
        "fn cluster_slice(",
        "fn cluster_first_slot(",
        "fn cascade_matrix(",
        "fn radical_inverse(",
        "fn ggx_sample(",
        "fn world_position(",
        "fn linear_depth(",
        "fn luminance(",
        "fn env_brdf(",
    ];
    for head in shared {
        let mut copies: Vec<(String, String)> = Vec::new();
        for f in &files {
            let source = std::fs::read_to_string(f).unwrap();
            if let Some(start) = source.find(head) {
                // The function runs to the first line that is a lone closing brace.
                let body = &source[start..];
                let end = body.find("\n}\n").map_or(body.len(), |e| e + 2);
                copies.push((f.display().to_string(), body[..end].to_owned()));
            }
        }
        assert!(!copies.is_empty(), "no shader defines {head}");
        for (file, text) in &copies[1..] {
            assert_eq!(
                text, &copies[0].1,
                "{head}...) in {file} differs from {}",
                copies[0].0
            );
        }
    }
    // Constants of the same name hold the same value everywhere.
    let mut consts: std::collections::BTreeMap<String, (String, String)> = Default::default();
    for f in &files {
        for line in std::fs::read_to_string(f).unwrap().lines() {
            let Some(rest) = line.strip_prefix("const ") else {
                continue;
            };
            let name = rest.split(':').next().unwrap().to_owned();
            let file = f.display().to_string();
            if let Some((first, text)) = consts.get(&name) {
                assert_eq!(line, text, "const {name} in {file} differs from {first}");
            } else {
                consts.insert(name, (file, line.to_owned()));
            }
        }
    }
    assert!(consts.contains_key("CLUSTER_SLICES"), "{consts:?}");
}
