//! RenderDoc captures of real programs (`tests/fixtures/rdc/`): each is imported through
//! `renderdoccmd convert`, checked against RenderDoc's own account of it (the
//! `.rdc.renderdoc.json` beside it, written by `scripts/renderdoc_reference.py` from
//! RenderDoc's replay, not by framelab), replayed to the image RenderDoc's replay presented,
//! clean under the Khronos validation layer, and compared with GFXReconstruct's capture of the
//! same vkcube frame. Damaged captures, conversions and converters give located errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{Scratch, framelab, gfxr_fixture, json, repo, stderr};

/// RenderDoc captures, each with `<name>.rdc.renderdoc.json` and `<name>.rdc.ref.png`.
const CAPTURES: [&str; 5] = [
    "vkcube_frame183",
    "vkd3d_gears_f3445",
    "mpv_testsrc_f73",
    "framelab_inspect_f117",
    "qt6quick_text_f296",
];

fn fixture(name: &str) -> PathBuf {
    repo().join("tests/fixtures/rdc").join(name)
}

fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-rdc-{name}"))
}

/// Imports `input` into `dir/<stem>.json` with `--json`, returning the capture's path and the
/// summary.
fn import(input: &Path, dir: &Path, stem: &str) -> (PathBuf, Value) {
    let capture = dir.join(format!("{stem}.json"));
    let out = framelab(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
        "--json",
    ]);
    assert!(out.status.success(), "{stem}: {}", stderr(&out));
    (capture, json(&out))
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// RenderDoc's format names where they differ from the capture format's.
fn renderdoc_format(ours: &str) -> &str {
    match ours {
        "D16_UNORM" => "D16",
        "D32_FLOAT" => "D32",
        "D24_UNORM_S8_UINT" => "D24S8",
        other => other,
    }
}

/// Barriers the application recorded with vkCmdPipelineBarrier (render pass transitions are
/// not calls RenderDoc lists as barriers).
fn pipeline_barriers(capture: &Value) -> u64 {
    capture["passes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|p| p["barriers"].as_array().cloned().unwrap_or_default())
        .filter(|b| {
            b["vulkan"]["origin"]
                .as_str()
                .is_some_and(|o| o.starts_with("vkCmdPipelineBarrier"))
        })
        .count() as u64
}

fn passes_of_kind(capture: &Value, kind: &str) -> Vec<Value> {
    capture["passes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["kind"] == kind && !p["name"].as_str().unwrap().starts_with("host_write"))
        .cloned()
        .collect()
}

#[test]
fn renderdoc_frames_import_as_renderdoc_lists_them() {
    for name in CAPTURES {
        let dir = temp(&format!("lists-{name}"));
        let (path, summary) = import(&fixture(&format!("{name}.rdc")), &dir, name);
        let capture = read(&path);
        let theirs = read(&fixture(&format!("{name}.rdc.renderdoc.json")));
        let counts = &theirs["counts"];
        assert_eq!(summary["dialect"], "renderdoc", "{name}");
        assert!(
            summary["tool"].as_str().unwrap().contains("RenderDoc 1.24"),
            "{name}: {}",
            summary["tool"]
        );
        assert_eq!(summary["draws"], counts["draws"], "{name}: draws");
        assert_eq!(summary["dispatches"], counts["dispatches"], "{name}");
        assert_eq!(
            passes_of_kind(&capture, "raster").len() as u64,
            counts["render_passes"].as_u64().unwrap(),
            "{name}: render passes"
        );
        assert_eq!(
            passes_of_kind(&capture, "clear").len() as u64,
            counts["clears"].as_u64().unwrap(),
            "{name}: clears"
        );
        assert_eq!(
            passes_of_kind(&capture, "copy").len() as u64,
            counts["copies"].as_u64().unwrap(),
            "{name}: copies"
        );
        assert_eq!(
            passes_of_kind(&capture, "present").len() as u64,
            counts["presents"].as_u64().unwrap(),
            "{name}: presents"
        );
        // Each draw's vertex or index count and instance count, in order.
        let ours: Vec<(u64, u64)> = capture["passes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|p| p["draws"].as_array().cloned().unwrap_or_default())
            .map(|d| {
                let n = d["count"]
                    .as_u64()
                    .unwrap_or_else(|| panic!("{name}: a draw without a count: {d}"));
                (n, d["instances"].as_u64().unwrap_or(1))
            })
            .collect();
        let listed: Vec<(u64, u64)> = theirs["draws"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| {
                (
                    d["indices"].as_u64().unwrap(),
                    d["instances"].as_u64().unwrap(),
                )
            })
            .collect();
        assert_eq!(ours, listed, "{name}: draws");
        // Textures (format, size, levels, layers) and buffers (size), as multisets; the
        // buffers framelab adds to hold the frame's host writes are its own.
        let mut textures: Vec<String> = Vec::new();
        let mut buffers: Vec<u64> = Vec::new();
        for r in capture["resources"].as_array().unwrap() {
            if r["kind"] == "buffer" {
                if !r["name"].as_str().unwrap().starts_with("host_write_") {
                    buffers.push(r["size"].as_u64().unwrap());
                }
                continue;
            }
            textures.push(format!(
                "{} {}x{}x{} mips {} layers {}",
                renderdoc_format(r["format"].as_str().unwrap()),
                r["width"],
                r["height"],
                r.get("depth").and_then(Value::as_u64).unwrap_or(1),
                r.get("mip_levels").and_then(Value::as_u64).unwrap_or(1),
                r.get("array_layers").and_then(Value::as_u64).unwrap_or(1),
            ));
        }
        let mut listed_textures: Vec<String> = theirs["textures"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| {
                format!(
                    "{} {}x{}x{} mips {} layers {}",
                    t["format"].as_str().unwrap(),
                    t["width"],
                    t["height"],
                    t["depth"],
                    t["mips"],
                    t["layers"]
                )
            })
            .collect();
        textures.sort();
        listed_textures.sort();
        buffers.sort_unstable();
        assert_eq!(textures, listed_textures, "{name}: textures");
        let listed_buffers: Vec<u64> = theirs["buffers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b.as_u64().unwrap())
            .collect();
        assert_eq!(buffers, listed_buffers, "{name}: buffers");
        let listed_barriers: u64 = theirs["barriers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                b["image"].as_u64().unwrap()
                    + b["buffer"].as_u64().unwrap()
                    + b["memory"].as_u64().unwrap()
            })
            .sum();
        assert_eq!(
            pipeline_barriers(&capture),
            listed_barriers,
            "{name}: barriers"
        );
    }
}

fn within_tolerance(what: &str, image: &image::RgbaImage, reference: &image::RgbaImage) {
    if let Err(e) = crate::golden::within(what, image, reference) {
        panic!("{e}");
    }
}

#[test]
fn renderdoc_frames_replay_to_the_image_renderdoc_presented() {
    for name in CAPTURES {
        let dir = temp(&format!("replay-{name}"));
        let (capture, _) = import(&fixture(&format!("{name}.rdc")), &dir, name);
        let image = crate::common::replay_presented(&capture, &dir.join("out"));
        let reference = image::open(fixture(&format!("{name}.rdc.ref.png")))
            .unwrap()
            .to_rgba8();
        within_tolerance(name, &image, &reference);
    }
}

#[test]
fn renderdoc_frames_are_clean_under_the_validation_layer() {
    let dir = temp("validation-layer");
    crate::common::replays_clean_under_validation_layer(&dir, &CAPTURES, |name, dir| {
        import(&fixture(&format!("{name}.rdc")), dir, name).0
    });
}

/// A resource as both tools can name it: what it is, not the handle a tool gave it.
fn signature(r: &Value) -> String {
    format!(
        "{} {} {}x{} size {} mips {}",
        r["kind"].as_str().unwrap_or(""),
        r["format"].as_str().unwrap_or("-"),
        r["width"],
        r["height"],
        r["size"],
        r["mip_levels"]
    )
}

/// A capture's structure with every resource named by its signature: each pass's kind, work,
/// reads and writes, and its barriers (resource, layouts, stages, access), in order.
fn structure(capture: &Value) -> Vec<String> {
    let by_name: BTreeMap<String, String> = capture["resources"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["name"].as_str().unwrap().to_owned(), signature(r)))
        .collect();
    let mut out = Vec::new();
    for p in capture["passes"].as_array().unwrap() {
        out.push(format!(
            "pass {} {} draws {} dispatches {}",
            p["name"],
            p["kind"],
            p["draws"].as_array().map_or(0, Vec::len),
            p["dispatches"].as_array().map_or(0, Vec::len),
        ));
        let mut names = Vec::new();
        for key in ["bindings", "color_attachments", "clears"] {
            for b in p[key].as_array().cloned().unwrap_or_default() {
                names.push(format!(
                    "{key} {}",
                    by_name[b["resource"].as_str().unwrap()]
                ));
            }
        }
        if let Some(d) = p["depth_stencil"]["resource"].as_str() {
            names.push(format!("depth {}", by_name[d]));
        }
        names.sort();
        out.extend(names);
        for b in p["barriers"].as_array().cloned().unwrap_or_default() {
            let v = &b["vulkan"];
            out.push(format!(
                "barrier {} {} -> {} {} -> {} {} -> {}",
                by_name[b["resource"].as_str().unwrap()],
                v["old_layout"],
                v["new_layout"],
                v["src_stages"],
                v["dst_stages"],
                v["src_access"],
                v["dst_access"]
            ));
        }
    }
    out
}

/// vkcube turns its cube by a fixed step per frame, and the two tools count frames from
/// different starts (RenderDoc's frame 183 is GFXReconstruct's 184): the same frame captured
/// by both imports to the same passes, resources and barriers, and replays to the same image.
#[test]
fn renderdoc_and_gfxreconstruct_captures_of_one_frame_agree() {
    let dir = temp("both-tools");
    let (a, _) = import(&fixture("vkcube_frame183.rdc"), &dir, "rdc");
    let (b, _) = import(&gfxr_fixture("vkcube_f184.gfxr"), &dir, "gfxr");
    let (ca, cb) = (read(&a), read(&b));
    let (sa, sb) = (structure(&ca), structure(&cb));
    assert!(sa.len() > 4, "{sa:?}");
    assert_eq!(sa, sb);
    // The resources the frame uses are the same; RenderDoc keeps only those, while the
    // GFXReconstruct capture also holds vkcube's uniform buffers for its other swapchain
    // images, which no pass of this frame touches.
    let used = |c: &Value| -> Vec<String> {
        let text = serde_json::to_string(&c["passes"]).unwrap();
        let mut v: Vec<String> = c["resources"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| text.contains(&format!("\"{}\"", r["name"].as_str().unwrap())))
            .map(signature)
            .collect();
        v.sort();
        v
    };
    assert_eq!(used(&ca), used(&cb));
    let ia = crate::common::replay_presented(&a, &dir.join("out-rdc"));
    let ib = crate::common::replay_presented(&b, &dir.join("out-gfxr"));
    within_tolerance("RenderDoc against GFXReconstruct", &ia, &ib);
    // And the structural diff sees no pass added or removed.
    let diff = framelab(&[
        "diff",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--structure",
    ]);
    assert!(diff.status.success(), "{}", stderr(&diff));
    let text = crate::common::stdout(&diff);
    assert!(
        !text.contains("pass added") && !text.contains("pass removed"),
        "{text}"
    );
}

/// The imported frame works with every command: analyse, replay after a pass, inspect.
#[test]
fn an_imported_renderdoc_frame_is_analysed_replayed_and_inspected() {
    let dir = temp("commands");
    let (capture, _) = import(&fixture("vkd3d_gears_f3445.rdc"), &dir, "gears");
    let c = capture.to_str().unwrap();
    let analysis = framelab(&["analyze", "--json", c]);
    assert!(analysis.status.success(), "{}", stderr(&analysis));
    let order = json(&analysis)["order"].as_array().map_or(0, Vec::len);
    assert_eq!(
        order, 6,
        "two host writes, three render passes, the present"
    );
    let out = dir.join("after");
    let after = framelab(&[
        "replay",
        c,
        "--frames",
        "1",
        "--after",
        "render_pass 2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(after.status.success(), "{}", stderr(&after));
    assert!(out.join("manifest.json").is_file());
    let shot = dir.join("inspector.png");
    let inspect = framelab(&[
        "inspect",
        c,
        "--screenshot",
        shot.to_str().unwrap(),
        "--select",
        "render_pass 3",
    ]);
    assert!(inspect.status.success(), "{}", stderr(&inspect));
    let img = image::open(&shot).unwrap().to_rgba8();
    assert!(img.width() > 400 && img.height() > 300);
}

/// A converter standing in for renderdoccmd: a shell script that does `body` with the
/// arguments renderdoccmd gets (`convert -f IN -c zip.xml -o OUT`: `$7` is OUT).
fn fake_converter(dir: &Path, body: &str) -> PathBuf {
    let path = dir.join("fake-renderdoccmd");
    std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    path
}

/// Runs `framelab import` of vkcube's capture into `dir/out.json` with `env`, expecting
/// exit 1, an error containing every one of `parts`, and nothing written.
fn refused(dir: &Path, input: &Path, env: &[(&str, &std::ffi::OsStr)], parts: &[&str]) {
    let out_json = dir.join("out.json");
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_framelab"));
    cmd.args([
        "import",
        input.to_str().unwrap(),
        "-o",
        out_json.to_str().unwrap(),
    ])
    .current_dir(repo());
    for (k, v) in env {
        cmd.env(k, v);
    }
    let started = std::time::Instant::now();
    let out = cmd.output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{parts:?}: {err}");
    for p in parts {
        assert!(err.contains(p), "missing {p:?} in: {err}");
    }
    assert!(started.elapsed().as_secs() < 60, "{parts:?} took too long");
    assert!(!out_json.exists(), "{parts:?}: a capture was written");
    assert!(!dir.join("out.contents").exists() && !dir.join("out.shaders").exists());
}

#[test]
fn bad_renderdoc_input_is_refused_with_a_located_error() {
    let dir = temp("bad");
    let good = fixture("vkcube_frame183.rdc");
    let bytes = std::fs::read(&good).unwrap();
    // A truncated capture: renderdoccmd cannot read it.
    let truncated = dir.join("truncated.rdc");
    std::fs::write(&truncated, &bytes[..bytes.len() / 3]).unwrap();
    refused(
        &dir,
        &truncated,
        &[],
        &["truncated.rdc", "renderdoccmd convert failed"],
    );
    // A corrupt one: bytes changed all through its compressed sections.
    let mut damaged = bytes.clone();
    for i in (2000..damaged.len()).step_by(997) {
        damaged[i] ^= 0x5a;
    }
    let corrupt = dir.join("corrupt.rdc");
    std::fs::write(&corrupt, damaged).unwrap();
    refused(&dir, &corrupt, &[], &["corrupt.rdc", "convert failed"]);
    // No converter.
    refused(
        &dir,
        &good,
        &[(
            "FRAMELAB_RENDERDOCCMD",
            "/nonexistent/renderdoccmd".as_ref(),
        )],
        &["was not found", "apt-get install renderdoc"],
    );
    // A converter that hangs is stopped at the time limit.
    let hangs = fake_converter(&dir, "sleep 600");
    refused(
        &dir,
        &good,
        &[
            ("FRAMELAB_RENDERDOCCMD", hangs.as_os_str()),
            ("FRAMELAB_RENDERDOC_TIMEOUT", "1".as_ref()),
        ],
        &["did not finish within 1 s"],
    );
    // A converter that fails.
    let fails = fake_converter(&dir, "echo 'Error: cannot open capture' >&2; exit 3");
    refused(
        &dir,
        &good,
        &[("FRAMELAB_RENDERDOCCMD", fails.as_os_str())],
        &["convert failed", "cannot open capture"],
    );
    // Conversions edited: from another RenderDoc version, a member missing, a member said to
    // be huge, XML cut short.
    let real = dir.join("real");
    std::fs::create_dir_all(&real).unwrap();
    let xml = real.join("vkcube.zip.xml");
    let conv = std::process::Command::new("renderdoccmd")
        .args([
            "convert",
            "-f",
            good.to_str().unwrap(),
            "-c",
            "zip.xml",
            "-o",
        ])
        .arg(&xml)
        .output()
        .expect("renderdoccmd (apt-get install renderdoc)");
    assert!(conv.status.success(), "{}", stderr(&conv));
    let text = std::fs::read_to_string(&xml).unwrap();
    let zip = real.join("vkcube.zip");
    // Another capture's zip: its members are not the sizes this XML says.
    let other_zip = real.join("gears.zip");
    let conv = std::process::Command::new("renderdoccmd")
        .args([
            "convert",
            "-f",
            fixture("vkd3d_gears_f3445.rdc").to_str().unwrap(),
            "-c",
            "zip.xml",
            "-o",
        ])
        .arg(real.join("gears.zip.xml"))
        .output()
        .unwrap();
    assert!(conv.status.success(), "{}", stderr(&conv));
    let fake = fake_converter(
        &dir,
        &format!(
            "cp '{}' \"$7\" && cp '{}' \"${{7%.xml}}\"",
            xml.display(),
            other_zip.display()
        ),
    );
    refused(
        &dir,
        &good,
        &[("FRAMELAB_RENDERDOCCMD", fake.as_os_str())],
        &["member 000000 holds 0 bytes", "but the XML says 1560"],
    );
    let edits: [(&str, String, &[&str]); 4] = [
        (
            "version",
            text.replace("<chunks version=\"21\">", "<chunks version=\"22\">"),
            &["chunks are version 0x16", "RenderDoc 1.24"],
        ),
        (
            "missing",
            text.replace(
                "byteLength=\"1560\">0</buffer>",
                "byteLength=\"1560\">77</buffer>",
            ),
            &["vkCreateShaderModule", "member 000077"],
        ),
        (
            "huge",
            text.replace(
                "byteLength=\"1560\">0</buffer>",
                "byteLength=\"999999999999\">0</buffer>",
            ),
            &["vkCreateShaderModule", "999999999999"],
        ),
        (
            "cut",
            text[..text.len() / 2].to_owned(),
            &["converted XML", "truncated"],
        ),
    ];
    for (what, edited, parts) in edits {
        assert_ne!(edited, text, "{what}: the edit applies");
        let x = real.join(format!("{what}.zip.xml"));
        std::fs::write(&x, edited).unwrap();
        let fake = fake_converter(
            &dir,
            &format!(
                "cp '{}' \"$7\" && cp '{}' \"${{7%.xml}}\"",
                x.display(),
                zip.display()
            ),
        );
        refused(
            &dir,
            &good,
            &[("FRAMELAB_RENDERDOCCMD", fake.as_os_str())],
            parts,
        );
    }
}
