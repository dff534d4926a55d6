//! `framelab import app.gfxr`: GFXReconstruct's binary captures of real programs read
//! directly. Each is checked against `gfxrecon-convert`'s JSON Lines of the same file
//! (same passes, draws, dispatches, resources and recorded barriers), its SPIR-V side files
//! against `spirv-val` and against the modules `gfxrecon-extract` pulled from the same file,
//! one texture against the image the program loads, and bad input against the located
//! error it must give.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{Scratch, framelab, gfxr_fixture, json, stderr, stdout};

/// Binary captures with their JSON Lines conversion beside them (`<name>.jsonl`) and the
/// modules `gfxrecon-extract` pulled from them (`extracted/<name>/`).
const CAPTURES: [&str; 11] = [
    "vkcube_f3",
    "vkcube_staging",
    "vkcube_f3_zlib",
    "vkcube_f3_zstd",
    "vkcube_f3_none",
    "vkcube_whole",
    "vkcubepp_f3",
    "vkd3d_triangle_f1",
    "vkd3d_gears_f2",
    "mpv_testsrc_f5",
    "framelab_inspect_f3",
];

/// `gfxrecon-convert` writes floats with six decimals; the binary holds the exact value.
const CONVERTER_FLOAT_STEP: f64 = 1e-6;

/// Whether two captures are the same, numbers that are not integers within the
/// converter's rounding.
fn same(a: &Value, b: &Value, path: &str) -> Result<(), String> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) if !(x.is_u64() && y.is_u64()) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            if (x - y).abs() <= CONVERTER_FLOAT_STEP {
                Ok(())
            } else {
                Err(format!("{path}: {x} vs {y}"))
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .try_for_each(|(i, (x, y))| same(x, y, &format!("{path}[{i}]"))),
        (Value::Object(x), Value::Object(y)) if x.len() == y.len() => {
            x.iter().try_for_each(|(k, v)| {
                same(
                    v,
                    y.get(k).ok_or(format!("{path}.{k}: missing"))?,
                    &format!("{path}.{k}"),
                )
            })
        }
        _ if a == b => Ok(()),
        _ => Err(format!("{path}: {a} vs {b}")),
    }
}

pub(crate) fn temp_dir(tag: &str) -> Scratch {
    Scratch::temp(&format!("framelab-gfxr-{tag}"))
}

/// Imports `input` to `out` with `--json`; the summary.
pub(crate) fn import(input: &Path, out: &Path) -> Value {
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
/// what only the binary file holds (contents, module code, specialization values, push
/// constants).
/// Whether a pass copies bytes the CPU wrote during the frame (only the binary holds them).
fn is_host_write(pass: &Value) -> bool {
    pass["copies"]
        .as_array()
        .is_some_and(|c| !c.is_empty() && c.iter().all(|c| c["host"] == Value::Bool(true)))
}

fn comparable(path: &Path) -> Value {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let o = v.as_object_mut().unwrap();
    o.remove("description");
    o.remove("source");
    // What kind of memory each heap is comes from the device's memory types, which a trimmed
    // binary capture records as meta-data and the JSON Lines stream leaves out
    // (`memory_kinds_come_from_the_binary_capture` checks them).
    o.remove("adapter");
    for h in o["heaps"].as_array_mut().unwrap() {
        let h = h.as_object_mut().unwrap();
        for key in ["type", "cpu_page_property", "memory_pool"] {
            h.remove(key);
        }
    }
    // Host writes during the frame, and the buffers holding their bytes, come only from the
    // binary route.
    let mut uploads = std::collections::BTreeSet::new();
    o["passes"].as_array_mut().unwrap().retain(|p| {
        if is_host_write(p) {
            for c in p["copies"].as_array().unwrap() {
                uploads.insert(c["src"]["resource"].as_str().unwrap().to_owned());
            }
            false
        } else {
            true
        }
    });
    o["resources"]
        .as_array_mut()
        .unwrap()
        .retain(|r| !uploads.contains(r["name"].as_str().unwrap()));
    for r in o["resources"].as_array_mut().unwrap() {
        let r = r.as_object_mut().unwrap();
        r.remove("initial");
        // A buffer the frame writes in host-visible memory is one the CPU reads: known only
        // where the memory types are.
        r.remove("output");
    }
    for pass in o["passes"].as_array_mut().unwrap() {
        // Whether a storage binding is read, written or both is in the shader code only the
        // binary capture holds; the JSON Lines route counts each as read-write.
        for b in pass
            .get_mut("bindings")
            .and_then(Value::as_object_mut)
            .into_iter()
            .flat_map(|m| m.values_mut())
        {
            if b["access"]
                .as_str()
                .is_some_and(|a| a.starts_with("storage_"))
            {
                b["access"] = Value::from("storage");
            }
        }
        for key in ["draws", "dispatches"] {
            for w in pass
                .get_mut(key)
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                if let Some(state) = w.get_mut("vulkan_state").and_then(Value::as_object_mut) {
                    state.remove("push_constants");
                    if state.is_empty() {
                        w.as_object_mut().unwrap().remove("vulkan_state");
                    }
                }
            }
        }
    }
    if let Some(vk) = o.get_mut("vulkan") {
        for m in vk["shader_modules"].as_array_mut().unwrap() {
            m.as_object_mut().unwrap().remove("file");
        }
        for p in vk["pipelines"].as_array_mut().unwrap() {
            for s in p["stages"].as_array_mut().unwrap() {
                for c in s
                    .get_mut("specialization")
                    .and_then(Value::as_array_mut)
                    .into_iter()
                    .flatten()
                {
                    c.as_object_mut().unwrap().remove("value");
                }
            }
        }
    }
    v
}

#[test]
fn binary_and_json_lines_of_the_same_frame_agree() {
    let dir = temp_dir("agree");
    for name in CAPTURES {
        let bin = import(
            &gfxr_fixture(&format!("{name}.gfxr")),
            &dir.join(format!("b_{name}.json")),
        );
        let text = import(
            &gfxr_fixture(&format!("{name}.jsonl")),
            &dir.join(format!("j_{name}.json")),
        );
        let host_writes = {
            let c: Value = serde_json::from_str(
                &std::fs::read_to_string(dir.join(format!("b_{name}.json"))).unwrap(),
            )
            .unwrap();
            c["passes"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|p| is_host_write(p))
                .count() as u64
        };
        let mut bin = bin;
        if host_writes > 0 {
            bin["passes"] = (bin["passes"].as_u64().unwrap() - host_writes).into();
            let copies = bin["passes_by_kind"]["copy"].as_u64().unwrap() - host_writes;
            if copies == 0 {
                bin["passes_by_kind"]
                    .as_object_mut()
                    .unwrap()
                    .remove("copy");
            } else {
                bin["passes_by_kind"]["copy"] = copies.into();
            }
        }
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
        check_pipelines(&dir.join(format!("b_{name}.json")), name);
        let (b, j) = (
            comparable(&dir.join(format!("b_{name}.json"))),
            comparable(&dir.join(format!("j_{name}.json"))),
        );
        if let Err(e) = same(&b, &j, name) {
            panic!("the two routes differ at {e}");
        }
        assert_eq!(bin["dialect"], "binary");
        assert_eq!(text["dialect"], "0.9.x");
    }
}

/// A trimmed capture records the device's memory types as meta-data: lavapipe's one memory
/// type is device-local and host-visible, so the adapter is unified-memory and every heap
/// CPU-visible, write-back.
#[test]
fn memory_kinds_come_from_the_binary_capture() {
    let dir = temp_dir("memory-kinds");
    let path = dir.join("cube.json");
    import(&gfxr_fixture("vkcube_f3.gfxr"), &path);
    let c: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(c["adapter"]["architecture"], "uma");
    let heaps = c["heaps"].as_array().unwrap();
    assert!(!heaps.is_empty());
    for h in heaps {
        assert_eq!(h["type"], "CUSTOM", "{h}");
        assert_eq!(h["cpu_page_property"], "WRITE_BACK", "{h}");
        assert_eq!(h["memory_pool"], "L0", "{h}");
    }
}

/// Every draw and dispatch of a binary import names a pipeline of the right kind whose
/// stages' modules have code files, and every such file is one of the side files.
fn check_pipelines(path: &Path, name: &str) {
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let vk = &capture["vulkan"];
    let pipelines: std::collections::BTreeMap<&str, &Value> = vk["pipelines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["name"].as_str().unwrap(), p))
        .collect();
    let mut work = 0;
    for pass in capture["passes"].as_array().unwrap() {
        for (key, point) in [
            ("draws", "VK_PIPELINE_BIND_POINT_GRAPHICS"),
            ("dispatches", "VK_PIPELINE_BIND_POINT_COMPUTE"),
        ] {
            for w in pass
                .get(key)
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
            {
                let p = pipelines[w["pipeline"]
                    .as_str()
                    .unwrap_or_else(|| panic!("{name}: {w} names no pipeline"))];
                assert_eq!(p["bind_point"], point, "{name}");
                work += 1;
            }
        }
    }
    assert!(work > 0, "{name}: no draws or dispatches");
    for m in vk["shader_modules"].as_array().unwrap() {
        let file = path.parent().unwrap().join(m["file"].as_str().unwrap());
        assert_eq!(
            std::fs::metadata(&file).unwrap().len(),
            m["size"].as_u64().unwrap(),
            "{name}"
        );
    }
}

/// `spirv-val`'s verdict on a module.
fn spirv_val(path: &Path) -> std::process::Output {
    std::process::Command::new("spirv-val")
        .arg(path)
        .output()
        .expect("spirv-val (Debian spirv-tools) runs")
}

/// SPIR-V's `OpSource` with source language 10 (WGSL), which naga writes and Debian's
/// SPIRV-Tools 2023.1 predates.
const WGSL_SOURCE: u32 = 10;

/// A module validates: as it is, or, when the only complaint is naga's WGSL source
/// language, with that operand set to Unknown (the validator's version, not the module).
fn validates(path: &Path) -> Result<(), String> {
    let o = spirv_val(path);
    if o.status.success() {
        return Ok(());
    }
    let e = stderr(&o);
    if !e.contains(&format!("Invalid source language operand: {WGSL_SOURCE}")) {
        return Err(e);
    }
    let mut words: Vec<u32> = std::fs::read(path)
        .unwrap()
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut at = 5;
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        // OpSource (3): the source language is its first operand.
        if opcode == 3 && words[at + 1] == WGSL_SOURCE {
            words[at + 1] = 0;
        }
        at += count.max(1);
    }
    let copy = path.with_extension("unknown-source.spv");
    std::fs::write(
        &copy,
        words
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    let o = spirv_val(&copy);
    std::fs::remove_file(&copy).unwrap();
    if o.status.success() {
        Ok(())
    } else {
        Err(stderr(&o))
    }
}

#[test]
fn spirv_side_files_validate_and_are_the_modules_the_application_created() {
    let dir = temp_dir("spirv");
    for name in CAPTURES {
        let out = dir.join(format!("{name}.json"));
        let summary = import(&gfxr_fixture(&format!("{name}.gfxr")), &out);
        let modules = summary["shader_modules"].as_u64().unwrap();
        assert!(modules > 0, "{name}: no shader modules");
        let mut ours = Vec::new();
        for e in std::fs::read_dir(dir.join(format!("{name}.shaders"))).unwrap() {
            let path = e.unwrap().path();
            if let Err(e) = validates(&path) {
                panic!("{}: {e}", path.display());
            }
            ours.push(std::fs::read(&path).unwrap());
        }
        assert_eq!(ours.len() as u64, modules);
        // The modules gfxrecon-extract took from the same file, byte for byte.
        let mut theirs = Vec::new();
        for e in std::fs::read_dir(gfxr_fixture(&format!("extracted/{name}"))).unwrap() {
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

/// vkcube's texture as the import wrote it from `capture`.
fn vkcube_texture(capture: &str, extra: &[&str]) -> Vec<u8> {
    let dir = temp_dir(&format!("logo-{capture}"));
    let out = dir.join("vkcube.json");
    let mut args = vec![
        "import".to_owned(),
        gfxr_fixture(capture).display().to_string(),
        "-o".to_owned(),
        out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    let o = framelab(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let texture = capture["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["format"] == "R8G8B8A8_UNORM" && r["width"] == 256 && r["height"] == 256)
        .expect("vkcube's 256x256 texture");
    let file = &texture["initial"]["file"];
    let path = file["path"].as_str().expect("a contents file");
    let offset = file["offset"].as_u64().unwrap_or(0) as usize;
    let size = texture_bytes(texture);
    std::fs::read(dir.join(path)).unwrap()[offset..offset + size].to_vec()
}

/// A 2D texture's bytes: one mip of four-byte texels.
fn texture_bytes(texture: &Value) -> usize {
    let dim = |k: &str| texture[k].as_u64().unwrap() as usize;
    dim("width") * dim("height") * 4
}

#[test]
fn the_vkcube_texture_is_the_logo_the_program_loads() {
    // From a trimmed capture's snapshot, from a whole capture's writes through a mapping
    // (vkcube on lavapipe samples a linear image it fills itself), as of frame 1, and from a
    // whole capture of `vkcube --use_staging` as of its last frame: the texture is what the
    // first frame's vkCmdCopyBufferToImage made of the staging buffer's mapped writes.
    let logo = image::open(gfxr_fixture("lunarg.png")).unwrap().to_rgba8();
    assert_eq!(logo.dimensions(), (256, 256));
    for (capture, extra) in [
        ("vkcube_f3.gfxr", &[][..]),
        ("vkcube_whole.gfxr", &["--frame", "1"][..]),
        ("vkcube_staging.gfxr", &["--frame", "2"][..]),
    ] {
        let bytes = vkcube_texture(capture, extra);
        assert_eq!(bytes.len(), 256 * 256 * 4);
        let differing = bytes
            .chunks_exact(4)
            .zip(logo.pixels())
            .filter(|(a, b)| a[..3] != b.0[..3])
            .count();
        assert_eq!(
            differing, 0,
            "{capture}: {differing} texels differ from lunarg.ppm"
        );
    }
}

/// A frame's contents are one file, each resource at its offset; an offset whose bytes the
/// file does not hold is refused by validation, naming the field, and by nothing later.
#[test]
fn contents_share_one_file_and_a_range_past_it_is_refused() {
    let dir = temp_dir("pack");
    let out = dir.join("vkcube.json");
    let run = framelab(&[
        "import",
        gfxr_fixture("vkcube_f3.gfxr").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let files: Vec<_> = std::fs::read_dir(dir.join("vkcube.contents"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files, ["contents.bin"], "one file for every resource");
    let mut capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let (index, resource) = capture["resources"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .find(|(_, r)| r["initial"]["file"]["offset"].is_u64())
        .map(|(i, r)| (i, r.clone()))
        .expect("a resource in the pack");
    let len = std::fs::metadata(dir.join("vkcube.contents/contents.bin"))
        .unwrap()
        .len();
    capture["resources"][index]["initial"]["file"]["offset"] =
        serde_json::json!(len - resource["size"].as_u64().unwrap_or(1) + 1);
    std::fs::write(&out, serde_json::to_string(&capture).unwrap()).unwrap();
    let run = framelab(&["validate", out.to_str().unwrap()]);
    assert!(!run.status.success());
    let said = stderr(&run) + &crate::common::stdout(&run);
    assert!(
        said.contains(&format!("resources[{index}].initial.file.offset")),
        "{said}"
    );
}

/// `tools/template-compute` writes its four descriptors (two storage buffers, a 16-byte
/// uniform range and a storage image) through update templates twice: into a descriptor set
/// with `vkUpdateDescriptorSetWithTemplate` for its first dispatch, and pushed with
/// `vkCmdPushDescriptorSetWithTemplateKHR` for its second, each with its own output buffer and
/// image. The binary import pairs the templates' data with their entries, so each dispatch
/// binds what the program wrote, and the shader's code says which storage bindings are read or
/// written; `gfxrecon-convert` 0.9.x writes no usable data there, and that import says so.
/// Apart from those bindings, the two routes give the same frame.
#[test]
fn update_templates_write_the_descriptors_the_program_wrote() {
    let dir = temp_dir("template");
    let (b, j) = (dir.join("b.json"), dir.join("j.json"));
    let summary = import(&gfxr_fixture("template_compute.gfxr"), &b).to_string();
    let text = framelab(&[
        "import",
        gfxr_fixture("template_compute.jsonl").to_str().unwrap(),
        "-o",
        j.to_str().unwrap(),
    ]);
    assert!(text.status.success(), "{}", stderr(&text));
    let said = String::from_utf8_lossy(&text.stdout).into_owned() + &stderr(&text);
    for call in [
        "vkUpdateDescriptorSetWithTemplate",
        "vkCmdPushDescriptorSetWithTemplateKHR",
    ] {
        assert!(
            said.contains(&format!(
                "{call}: the template's data is not in the stream (gfxrecon-convert 0.9.x writes none; import the .gfxr capture)"
            )),
            "{call}: {said}"
        );
    }
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&b).unwrap()).unwrap();
    let pass = capture["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["kind"] == "compute")
        .expect("the dispatches' pass");
    let dispatches = pass["dispatches"].as_array().unwrap();
    assert_eq!(dispatches.len(), 2);
    let mut written = Vec::new();
    for d in dispatches {
        let descriptors = d["vulkan_state"]["descriptors"]
            .as_array()
            .expect("the dispatch's descriptors");
        let seen: Vec<(u64, &str, Option<u64>, bool)> = descriptors
            .iter()
            .map(|d| {
                (
                    d["binding"].as_u64().unwrap(),
                    d["descriptor_type"].as_str().unwrap(),
                    d["range"].as_u64(),
                    d["view"].is_string(),
                )
            })
            .collect();
        assert_eq!(
            seen,
            [
                (0, "STORAGE_BUFFER", Some(u64::MAX), false),
                (1, "STORAGE_BUFFER", Some(u64::MAX), false),
                (2, "UNIFORM_BUFFER", Some(16), false),
                (3, "STORAGE_IMAGE", None, true),
            ]
        );
        written.push((
            descriptors[1]["resource"].as_str().unwrap(),
            descriptors[3]["resource"].as_str().unwrap(),
        ));
    }
    assert!(
        written[0].0 != written[1].0 && written[0].1 != written[1].1,
        "each dispatch writes its own buffer and image: {written:?}"
    );
    let bindings = pass["bindings"].as_object().unwrap();
    let access = |key: &str| bindings[key]["access"].as_str().unwrap();
    // From the shader's code: `input` is only read, the outputs and images only written.
    assert_eq!(
        [
            access("set0_binding0"),
            access("set0_binding1"),
            access("set0_binding1_v2"),
            access("set0_binding2"),
            access("set0_binding3"),
            access("set0_binding3_v2")
        ],
        [
            "storage_read",
            "storage_write",
            "storage_write",
            "uniform",
            "storage_write",
            "storage_write"
        ]
    );
    // The program maps the buffers its shader writes and reads the results: frame outputs,
    // so the dispatches that make them are not culled.
    for (results, _) in &written {
        let resource = capture["resources"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == *results)
            .unwrap();
        assert_eq!(resource["output"], Value::Bool(true), "{resource}");
    }
    // The read-back after the last submission is captured as writes through the mapping;
    // left out, they do not stand as the results' last writers, and analysis culls nothing.
    assert!(
        summary.contains("host writes after the frames' last GPU work: left out"),
        "{summary}"
    );
    let analysis = framelab(&["analyze", b.to_str().unwrap(), "--json"]);
    assert_eq!(json(&analysis)["culled"], Value::Array(Vec::new()));
    let strip = |path: &Path| {
        let mut v = comparable(path);
        for p in v["passes"].as_array_mut().unwrap() {
            let p = p.as_object_mut().unwrap();
            p.remove("bindings");
            for d in p
                .get_mut("dispatches")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                d.as_object_mut().unwrap().remove("vulkan_state");
            }
        }
        // The storage image's view is named by the descriptor only the binary route pairs.
        v["vulkan"].as_object_mut().unwrap().remove("image_views");
        v
    };
    if let Err(e) = same(&strip(&b), &strip(&j), "template_compute") {
        panic!("the two routes differ at {e}");
    }
}

/// The JSON Lines route holds no code: its import analyses but does not replay, and says
/// why; the binary import of the same frame analyses and replays.
#[test]
fn binary_imports_replay_and_json_lines_imports_say_why_not() {
    let dir = temp_dir("analyse");
    let bin = dir.join("vkd3d.json");
    import(&gfxr_fixture("vkd3d_triangle_f1.gfxr"), &bin);
    let a = framelab(&["analyze", bin.to_str().unwrap()]);
    assert!(a.status.success(), "{}", stderr(&a));
    assert!(stdout(&a).contains("passes"), "{}", stdout(&a));
    let r = framelab(&["replay", bin.to_str().unwrap(), "--frames", "1"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let text = dir.join("vkd3d_text.json");
    import(&gfxr_fixture("vkd3d_triangle_f1.jsonl"), &text);
    let r = framelab(&["replay", text.to_str().unwrap(), "--frames", "1"]);
    assert_eq!(r.status.code(), Some(1));
    let e = stderr(&r);
    assert!(e.contains("holds no shader code"), "{e}");
}

/// A copy of a fixture with `edit` applied, written to `dir`.
pub(crate) fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut Vec<u8>)) -> PathBuf {
    let mut bytes = std::fs::read(gfxr_fixture(name)).unwrap();
    edit(&mut bytes);
    let path = dir.join(format!("edited_{name}"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Byte offsets of every block header after the file header.
pub(crate) fn block_offsets(bytes: &[u8]) -> Vec<usize> {
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
pub(crate) fn refused(input: &Path, dir: &Path) -> String {
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
    let blocks = block_offsets(&std::fs::read(gfxr_fixture(name)).unwrap());
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
    let bytes = std::fs::read(gfxr_fixture(name)).unwrap();
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
    assert!(e.contains("neither a GFXReconstruct binary capture"), "{e}");
    let e = refused(&edited(&dir, name, |b| b.truncate(10)), &dir);
    assert!(e.contains("file header"), "{e}");
}

#[test]
fn unknown_call_ids_are_skipped_and_counted() {
    let dir = temp_dir("unknown");
    let name = "vkcube_f3.gfxr";
    let bytes = std::fs::read(gfxr_fixture(name)).unwrap();
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

#[test]
fn handles_never_created_are_left_out_not_fatal() {
    // In the uncompressed capture, vkCmdDraw's command buffer replaced by a handle nothing
    // created: the draw lands in no submitted command buffer, and the rest imports.
    let dir = temp_dir("handles");
    let name = "vkcube_f3_none.gfxr";
    let bytes = std::fs::read(gfxr_fixture(name)).unwrap();
    let mut changed = 0;
    let path = edited(&dir, name, |b| {
        for o in block_offsets(&bytes) {
            let kind = u32::from_le_bytes(b[o + 8..o + 12].try_into().unwrap());
            let id = u32::from_le_bytes(b[o + 12..o + 16].try_into().unwrap());
            if kind == 4 && id == VK_CMD_DRAW {
                // Block header, call id, thread id, then the command buffer.
                b[o + 24..o + 32].copy_from_slice(&0xdead_beef_u64.to_le_bytes());
                changed += 1;
            }
        }
    });
    // The snapshot re-records three command buffers; each draws once.
    assert_eq!(changed, 3);
    let summary = import(&path, &dir.join("handles.json"));
    assert_eq!(summary["draws"], 0);
    assert!(summary["passes"].as_u64().unwrap() >= 1);
}

/// GFXReconstruct's call id of `vkCmdDraw`.
const VK_CMD_DRAW: u32 = 0x1_106a;

#[test]
fn draws_carry_their_dynamic_state_and_push_constants() {
    // mpv's draw pushes 72 bytes of constants and sets a 640x360 viewport and scissor.
    let dir = temp_dir("state");
    let out = dir.join("mpv.json");
    import(&gfxr_fixture("mpv_testsrc_f5.gfxr"), &out);
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let draw = capture["passes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|p| {
            p.get("draws")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
        })
        .next()
        .expect("mpv's draw");
    let state = &draw["vulkan_state"];
    assert_eq!(
        state["viewport"],
        serde_json::json!([0.0, 0.0, 640.0, 360.0, 0.0, 0.0])
    );
    assert_eq!(state["scissor"], serde_json::json!([0, 0, 640, 360]));
    assert_eq!(state["push_constants"].as_str().unwrap().len(), 72 * 2);
    // vkcube's draw reads its uniform buffer and samples the logo through a view and sampler.
    let out = dir.join("cube.json");
    import(&gfxr_fixture("vkcube_f3.gfxr"), &out);
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let d = &capture["passes"][0]["draws"][0]["vulkan_state"]["descriptors"];
    assert_eq!(d[0]["descriptor_type"], "UNIFORM_BUFFER");
    assert_eq!(d[0]["range"], 1216);
    assert_eq!(d[1]["descriptor_type"], "COMBINED_IMAGE_SAMPLER");
    let view = &capture["vulkan"]["image_views"][0];
    assert_eq!(d[1]["view"], view["name"]);
    assert_eq!(view["format"], "VK_FORMAT_R8G8B8A8_UNORM");
    let sampler = capture["vulkan"]["samplers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == d[1]["sampler"])
        .expect("the draw's sampler");
    assert_eq!(sampler["mag_filter"], "VK_FILTER_NEAREST");
}

#[test]
fn every_live_allocation_and_resource_is_imported() {
    // vkd3d-gears creates two 1x1 images for null descriptors that no command uses; they and
    // every other allocation alive in the frame are part of what the application had
    // resident. Counted here from the JSON Lines stream: allocations not freed, each with the
    // images and buffers bound to it.
    let dir = temp_dir("alive");
    let text = std::fs::read_to_string(gfxr_fixture("vkd3d_gears_f2.jsonl")).unwrap();
    let mut allocations = std::collections::BTreeMap::new();
    let mut bound = std::collections::BTreeMap::<u64, Vec<u64>>::new();
    for line in text.lines() {
        let v: Value = serde_json::from_str(line).unwrap();
        let Some(f) = v.get("vkFunc") else { continue };
        let a = &f["args"];
        match f["name"].as_str().unwrap() {
            "vkAllocateMemory" => {
                allocations.insert(
                    a["pMemory"].as_u64().unwrap(),
                    a["pAllocateInfo"]["allocationSize"].as_u64().unwrap(),
                );
            }
            "vkFreeMemory" => {
                allocations.remove(&a["memory"].as_u64().unwrap());
            }
            "vkBindImageMemory" | "vkBindBufferMemory" => {
                let object = a.get("image").or_else(|| a.get("buffer")).unwrap();
                bound
                    .entry(a["memory"].as_u64().unwrap())
                    .or_default()
                    .push(object.as_u64().unwrap());
            }
            _ => {}
        }
    }
    for route in ["gfxr", "jsonl"] {
        let out = dir.join(format!("gears_{route}.json"));
        import(&gfxr_fixture(&format!("vkd3d_gears_f2.{route}")), &out);
        let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let heaps: std::collections::BTreeMap<String, u64> = capture["heaps"]
            .as_array()
            .unwrap()
            .iter()
            .map(|h| {
                (
                    h["name"].as_str().unwrap().to_owned(),
                    h["size"].as_u64().unwrap(),
                )
            })
            .collect();
        let expected: std::collections::BTreeMap<String, u64> = allocations
            .iter()
            .filter(|(m, _)| bound.contains_key(m))
            .map(|(m, size)| (format!("memory_{m}"), *size))
            .collect();
        assert_eq!(
            heaps, expected,
            "{route}: heaps against the stream's allocations"
        );
        let placed: std::collections::BTreeSet<String> = capture["resources"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|r| r["placement"]["placed"]["heap"].as_str().map(str::to_owned))
            .collect();
        assert_eq!(
            placed,
            expected.keys().cloned().collect(),
            "{route}: every allocation holds an imported resource"
        );
        let null_images = capture["resources"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["format"] == "R8G8B8A8_UNORM" && r["width"] == 1 && r["height"] == 1)
            .count();
        assert_eq!(
            null_images, 2,
            "{route}: vkd3d's two null-descriptor images"
        );
    }
}

#[test]
fn a_sparse_capture_is_refused_at_once() {
    // A capture header followed by 64 GiB of zeros (a sparse file): refused at its first
    // block, not read to its end.
    let dir = temp_dir("sparse");
    let path = dir.join("sparse.gfxr");
    let mut head = std::fs::read(gfxr_fixture("vkcube_f3.gfxr")).unwrap();
    head.truncate(24);
    std::fs::write(&path, &head).unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .unwrap()
        .set_len(64 << 30)
        .unwrap();
    let started = std::time::Instant::now();
    let e = refused(&path, &dir);
    assert!(
        e.contains("block 0 at byte 24") && e.contains("zero-filled"),
        "{e}"
    );
    // Generous for a loaded CI machine; reading the file would take minutes.
    assert!(started.elapsed() < std::time::Duration::from_secs(20));
}

/// The import benchmark's two floors read what an import reads: every block of the file,
/// and every call the importer models decoded, without a call failing to decode.
#[test]
fn the_benchmark_floors_read_what_the_import_reads() {
    use framelab_core::import::{ImportOptions, gfxr};
    use std::io::Cursor;
    let bytes = std::fs::read(gfxr_fixture("vkcube_f3.gfxr")).unwrap();
    let len = Some(bytes.len() as u64);
    let (blocks, decompressed) = gfxr::decompress_only(Cursor::new(&bytes), len).unwrap();
    let decoded = gfxr::decode_only(Cursor::new(&bytes), len).unwrap();
    let imported = gfxr::import(
        Cursor::new(&bytes),
        len,
        "vkcube_f3.gfxr",
        "vkcube_f3",
        &ImportOptions::default(),
    )
    .unwrap();
    let s = &imported.summary;
    assert_eq!(blocks, s.lines);
    assert!(decompressed > bytes.len() as u64, "{decompressed}");
    let not_modelled: u64 = s.not_modelled.values().sum();
    // Decoded: every modelled call, and the few unmodelled ones only the binary route reads.
    assert!(
        decoded >= s.calls - not_modelled && decoded < s.calls,
        "decoded {decoded} of {} calls ({not_modelled} not modelled)",
        s.calls
    );
    let truncated = &bytes[..bytes.len() - 7];
    let cut = Some(truncated.len() as u64);
    assert!(gfxr::decompress_only(Cursor::new(truncated), cut).is_err());
    assert!(gfxr::decode_only(Cursor::new(truncated), cut).is_err());
}

/// A clear value is a union the binary holds as four words; a depth attachment's clear reads
/// its first as a float depth and its second as the stencil value. vkcube's depth clear set
/// to 0.25 (`0x3E800000`) with `framelab edit` reaches the pass; the program's own 1.0 does
/// too.
#[test]
fn depth_clear_values_are_read_from_the_clear_values_words() {
    let dir = temp_dir("depth-clear");
    let edited = dir.join("quarter.gfxr");
    crate::common::edited_fixture(
        "vkcube_f3.gfxr",
        &edited,
        "91:pRenderPassBegin.pClearValues[1].color.uint32[0]=1048576000",
    );
    for (capture, depth) in [(gfxr_fixture("vkcube_f3.gfxr"), 1.0), (edited, 0.25)] {
        let out = dir.join("cube.json");
        import(&capture, &out);
        let c: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let ds = &c["passes"][0]["depth_stencil"];
        assert_eq!(ds["depth_load"], "clear", "{}", capture.display());
        assert_eq!(
            ds["depth_clear"].as_f64(),
            Some(depth),
            "{}",
            capture.display()
        );
    }
}

/// A colour clear component that is not a finite number (zink leaves the channels a
/// one-channel float attachment lacks as NaN) is written as 0, JSON holding no NaN, and the
/// imported capture loads; the other components keep their values. vkcube's green clear
/// component set to `0xFFFFFFFF`, a NaN, with `framelab edit`.
#[test]
fn colour_clears_that_are_not_numbers_are_written_as_zero() {
    let dir = temp_dir("nan-clear");
    let edited = dir.join("nan.gfxr");
    crate::common::edited_fixture(
        "vkcube_f3.gfxr",
        &edited,
        "91:pRenderPassBegin.pClearValues[0].color.uint32[1]=4294967295",
    );
    let out = dir.join("cube.json");
    import(&edited, &out);
    let c: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let clear = &c["passes"][0]["color_attachments"][0]["clear"];
    assert_eq!(clear, &serde_json::json!([0.2, 0.0, 0.2, 0.2]));
    let run = crate::common::framelab(&["validate", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", crate::common::stderr(&run));
}
