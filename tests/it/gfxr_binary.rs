//! `framelab import app.gfxr`: GFXReconstruct's binary captures of real programs read
//! directly. Each is checked against `gfxrecon-convert`'s JSON Lines of the same file
//! (same passes, draws, dispatches, resources and recorded barriers), its SPIR-V side files
//! against `spirv-val` and against the modules `gfxrecon-extract` pulled from the same file,
//! one texture against the image the program loads, and bad input against the located
//! error it must give.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{framelab, json, repo, stderr, stdout};

fn fixture(name: &str) -> PathBuf {
    repo().join("tests/fixtures/gfxr").join(name)
}

/// Binary captures with their JSON Lines conversion beside them (`<name>.jsonl`).
const CAPTURES: [&str; 2] = ["vkcube_f3", "vkd3d_triangle_f1"];

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("framelab-gfxr-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Imports `input` to `out` with `--json`; the summary.
fn import(input: &Path, out: &Path) -> Value {
    let o = framelab(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        o.status.success(),
        "import {} failed:\n{}",
        input.display(),
        stderr(&o)
    );
    json(&o)
}

/// The capture with what may differ between the two routes removed: where it came from, and
/// the contents only the binary file holds.
fn comparable(path: &Path) -> Value {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let o = v.as_object_mut().unwrap();
    o.remove("description");
    o.remove("source");
    for r in o["resources"].as_array_mut().unwrap() {
        r.as_object_mut().unwrap().remove("initial");
    }
    v
}

#[test]
fn binary_and_json_lines_of_the_same_frame_agree() {
    let dir = temp_dir("agree");
    for name in CAPTURES {
        let bin = import(
            &fixture(&format!("{name}.gfxr")),
            &dir.join(format!("b_{name}.json")),
        );
        let text = import(
            &fixture(&format!("{name}.jsonl")),
            &dir.join(format!("j_{name}.json")),
        );
        for key in [
            "calls",
            "frames_in_stream",
            "passes",
            "passes_by_kind",
            "draws",
            "dispatches",
            "images",
            "buffers",
            "heaps",
            "queues",
            "recorded_barriers",
            "fences",
        ] {
            assert_eq!(
                bin[key], text[key],
                "{name}: `{key}` differs between the routes"
            );
        }
        assert!(bin["passes"].as_u64().unwrap() > 0, "{name}: no passes");
        let (b, j) = (
            comparable(&dir.join(format!("b_{name}.json"))),
            comparable(&dir.join(format!("j_{name}.json"))),
        );
        assert_eq!(b["passes"], j["passes"], "{name}: passes differ");
        assert_eq!(b["resources"], j["resources"], "{name}: resources differ");
        assert_eq!(b, j, "{name}: the captures differ");
        assert_eq!(bin["dialect"], "binary");
        assert_eq!(text["dialect"], "0.9.x");
    }
}

/// `spirv-val`'s verdict on a module.
fn spirv_val(path: &Path) -> std::process::Output {
    std::process::Command::new("spirv-val")
        .arg(path)
        .output()
        .expect("spirv-val (Debian spirv-tools) runs")
}

#[test]
fn spirv_side_files_validate_and_are_the_modules_the_application_created() {
    let dir = temp_dir("spirv");
    for name in CAPTURES {
        let out = dir.join(format!("{name}.json"));
        let summary = import(&fixture(&format!("{name}.gfxr")), &out);
        let modules = summary["shader_modules"].as_u64().unwrap();
        assert!(modules > 0, "{name}: no shader modules");
        let mut ours = Vec::new();
        for e in std::fs::read_dir(dir.join(format!("{name}.shaders"))).unwrap() {
            let path = e.unwrap().path();
            let o = spirv_val(&path);
            assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
            ours.push(std::fs::read(&path).unwrap());
        }
        assert_eq!(ours.len() as u64, modules);
        // The modules gfxrecon-extract took from the same file, byte for byte.
        let mut theirs = Vec::new();
        for e in std::fs::read_dir(fixture(&format!("extracted/{name}"))).unwrap() {
            theirs.push(std::fs::read(e.unwrap().path()).unwrap());
        }
        ours.sort();
        theirs.sort();
        theirs.dedup();
        ours.dedup();
        assert_eq!(
            ours, theirs,
            "{name}: SPIR-V differs from gfxrecon-extract's"
        );
    }
}

#[test]
fn the_vkcube_texture_is_the_logo_the_program_loads() {
    let dir = temp_dir("logo");
    let out = dir.join("vkcube.json");
    let summary = import(&fixture("vkcube_f3.gfxr"), &out);
    assert!(summary["contents"]["resources"].as_u64().unwrap() >= 2);
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let texture = capture["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["format"] == "R8G8B8A8_UNORM" && r["width"] == 256 && r["height"] == 256)
        .expect("vkcube's 256x256 texture");
    let path = texture["initial"]["file"]["path"]
        .as_str()
        .expect("a contents file");
    let bytes = std::fs::read(dir.join(path)).unwrap();
    let logo = image::open(fixture("lunarg.png")).unwrap().to_rgba8();
    assert_eq!(logo.dimensions(), (256, 256));
    assert_eq!(bytes.len(), 256 * 256 * 4);
    let differing = bytes
        .chunks_exact(4)
        .zip(logo.pixels())
        .filter(|(a, b)| a[..3] != b.0[..3])
        .count();
    assert_eq!(differing, 0, "{differing} texels differ from lunarg.ppm");
}

#[test]
fn analysis_works_on_a_binary_import_and_replay_says_what_is_missing() {
    let dir = temp_dir("analyse");
    let out = dir.join("vkd3d.json");
    import(&fixture("vkd3d_triangle_f1.gfxr"), &out);
    let a = framelab(&["analyze", out.to_str().unwrap()]);
    assert!(a.status.success(), "{}", stderr(&a));
    assert!(stdout(&a).contains("passes"), "{}", stdout(&a));
    let r = framelab(&["replay", out.to_str().unwrap(), "--scale", "0.25"]);
    assert_eq!(r.status.code(), Some(1));
    let e = stderr(&r);
    assert!(
        e.contains("SPIR-V modules") && e.contains("pipelines"),
        "{e}"
    );
}

/// A copy of a fixture with `edit` applied, written to `dir`.
fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut Vec<u8>)) -> PathBuf {
    let mut bytes = std::fs::read(fixture(name)).unwrap();
    edit(&mut bytes);
    let path = dir.join(format!("edited_{name}"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Byte offsets of every block header after the file header.
fn block_offsets(bytes: &[u8]) -> Vec<usize> {
    let options = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut at = 16 + 8 * options;
    let mut out = Vec::new();
    while at + 12 <= bytes.len() {
        out.push(at);
        let size = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
        at += 12 + size;
    }
    out
}

/// Runs an import that must fail: its message, after checking nothing was written.
fn refused(input: &Path, dir: &Path) -> String {
    let out = dir.join("refused.json");
    let o = framelab(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}\n{}", stdout(&o), stderr(&o));
    assert!(!out.exists(), "a refused import wrote {}", out.display());
    stderr(&o)
}

#[test]
fn bad_binary_input_gets_a_located_error() {
    let dir = temp_dir("bad");
    let name = "vkcube_f3.gfxr";
    let blocks = block_offsets(&std::fs::read(fixture(name)).unwrap());
    // Cut inside the tenth block.
    let cut = blocks[10] + 20;
    let e = refused(&edited(&dir, name, |b| b.truncate(cut)), &dir);
    assert!(
        e.contains(&format!("block 10 at byte {}", blocks[10])) && e.contains("truncated"),
        "{e}"
    );
    // A compression tag no GFXReconstruct writes.
    let e = refused(
        &edited(&dir, name, |b| {
            b[20..24].copy_from_slice(&7u32.to_le_bytes())
        }),
        &dir,
    );
    assert!(
        e.contains("file header") && e.contains("unknown compression type 7"),
        "{e}"
    );
    // A size near u64::MAX.
    let at = blocks[5];
    let e = refused(
        &edited(&dir, name, |b| {
            b[at..at + 8].copy_from_slice(&(u64::MAX - 3).to_le_bytes())
        }),
        &dir,
    );
    assert!(
        e.contains(&format!("block 5 at byte {at}")) && e.contains("over the"),
        "{e}"
    );
    // Compressed data that is not LZ4: the first compressed call's payload overwritten.
    let bytes = std::fs::read(fixture(name)).unwrap();
    let call = *blocks
        .iter()
        .find(|&&o| u32::from_le_bytes(bytes[o + 8..o + 12].try_into().unwrap()) == 0x8000_0004)
        .unwrap();
    let size = u64::from_le_bytes(bytes[call..call + 8].try_into().unwrap()) as usize;
    let index = blocks.iter().position(|&o| o == call).unwrap();
    let e = refused(
        &edited(&dir, name, |b| b[call + 32..call + 12 + size].fill(0xff)),
        &dir,
    );
    assert!(
        e.contains(&format!("block {index} at byte {call}")) && e.contains("LZ4"),
        "{e}"
    );
    // Not a capture at all, and an empty file.
    let e = refused(
        &edited(&dir, name, |b| b[..4].copy_from_slice(b"GFXQ")),
        &dir,
    );
    assert!(
        e.contains("no API calls") || e.contains("not a GFXReconstruct"),
        "{e}"
    );
    let e = refused(&edited(&dir, name, |b| b.truncate(10)), &dir);
    assert!(e.contains("file header"), "{e}");
}

#[test]
fn unknown_call_ids_are_skipped_and_counted() {
    let dir = temp_dir("unknown");
    let name = "vkcube_f3.gfxr";
    let bytes = std::fs::read(fixture(name)).unwrap();
    // Every vkCreateFence call's id replaced by one no Vulkan version has: the frame still
    // imports (its passes need no fence) and the summary counts them.
    let blocks = block_offsets(&bytes);
    let mut changed = 0;
    let path = edited(&dir, name, |b| {
        for &o in &blocks {
            let kind = u32::from_le_bytes(b[o + 8..o + 12].try_into().unwrap());
            let id = u32::from_le_bytes(b[o + 12..o + 16].try_into().unwrap());
            if kind & 0x7fff_ffff == 4 && id == 0x1_1023 {
                b[o + 12..o + 16].copy_from_slice(&0x1_fff0u32.to_le_bytes());
                changed += 1;
            }
        }
    });
    assert!(changed > 0);
    let summary = import(&path, &dir.join("unknown.json"));
    let skipped = summary["skipped"].as_array().unwrap();
    let entry = skipped
        .iter()
        .find(|s| {
            s["what"]
                .as_str()
                .unwrap()
                .contains("unknown call id 0x1fff0")
        })
        .unwrap_or_else(|| panic!("not counted: {skipped:?}"));
    assert_eq!(entry["count"], changed);
}
