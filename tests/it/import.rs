//! `framelab import`: real GFXReconstruct streams (three bundled samples, vkcube and framelab's
//! own replay captured on lavapipe, and a 1.x-dialect stream written from the converter's
//! documented output) imported and checked against what the stream says, counted here
//! independently of the importer; the Vulkan barrier lints on them; the round trip of the
//! example capture through a real capture; bad input.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use framelab_core::capture::dxgi;
use serde_json::Value;

use crate::common::{Scratch, framelab, gfxr_fixture, json, repo, stderr, stdout};

const STREAMS: [&str; 6] = [
    "vkd3d_triangle.jsonl",
    "wgpu30_compute.jsonl",
    "wgpu30_egui_kittest.jsonl",
    "vkcube_lavapipe.jsonl",
    "framelab_example_replay.jsonl",
    "v1_dynamic_rendering.jsonl",
];

/// What a stream's submitted command buffers hold, counted by replaying the stream's calls
/// naively: commands recorded since each vkBeginCommandBuffer, counted when submitted.
#[derive(Debug, Default, PartialEq)]
struct Counts {
    draws: usize,
    dispatches: usize,
    render_pass_instances: usize,
    barriers: usize,
    copies: usize,
    clears: usize,
    presents: usize,
    /// (format, width, height) of every image the stream creates, swapchain images included.
    images: BTreeSet<(String, u64, u64)>,
}

fn calls(path: &Path) -> Vec<(String, Value)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter_map(|v| {
            let f = v.get("vkFunc").or_else(|| v.get("function"))?;
            Some((f["name"].as_str()?.to_owned(), f["args"].clone()))
        })
        .collect()
}

fn counts(path: &Path) -> Counts {
    let mut c = Counts::default();
    let mut recorded: HashMap<u64, Vec<(String, Value)>> = HashMap::new();
    let mut swapchain_extent = None;
    for (name, args) in calls(path) {
        if let Some(cb) = args.get("commandBuffer").and_then(Value::as_u64)
            && name.starts_with("vkCmd")
        {
            recorded
                .entry(cb)
                .or_default()
                .push((name.clone(), args.clone()));
        }
        match name.as_str() {
            "vkBeginCommandBuffer" => {
                recorded.insert(args["commandBuffer"].as_u64().unwrap(), Vec::new());
            }
            "vkCreateImage" => {
                let ci = &args["pCreateInfo"];
                c.images.insert((
                    ci["format"].as_str().unwrap().to_owned(),
                    ci["extent"]["width"].as_u64().unwrap(),
                    ci["extent"]["height"].as_u64().unwrap(),
                ));
            }
            "vkCreateSwapchainKHR" => {
                let ci = &args["pCreateInfo"];
                swapchain_extent = Some((
                    ci["imageFormat"].as_str().unwrap().to_owned(),
                    ci["imageExtent"]["width"].as_u64().unwrap(),
                    ci["imageExtent"]["height"].as_u64().unwrap(),
                ));
            }
            "vkQueuePresentKHR" => c.presents += 1,
            "vkQueueSubmit" | "vkQueueSubmit2" => {
                for s in args["pSubmits"].as_array().unwrap() {
                    let cbs: Vec<u64> = match s.get("pCommandBuffers") {
                        Some(Value::Array(a)) => a.iter().filter_map(Value::as_u64).collect(),
                        _ => s
                            .get("pCommandBufferInfos")
                            .and_then(Value::as_array)
                            .map(|a| {
                                a.iter()
                                    .filter_map(|i| i["commandBuffer"].as_u64())
                                    .collect()
                            })
                            .unwrap_or_default(),
                    };
                    for cb in cbs {
                        for (cmd, a) in recorded.get(&cb).into_iter().flatten() {
                            match cmd.as_str() {
                                "vkCmdDraw" | "vkCmdDrawIndexed" => c.draws += 1,
                                "vkCmdDrawIndirect" | "vkCmdDrawIndexedIndirect" => {
                                    c.draws += a["drawCount"].as_u64().unwrap() as usize
                                }
                                "vkCmdDispatch" => c.dispatches += 1,
                                "vkCmdBeginRenderPass" | "vkCmdBeginRendering" => {
                                    c.render_pass_instances += 1
                                }
                                "vkCmdCopyBuffer"
                                | "vkCmdCopyBufferToImage"
                                | "vkCmdCopyImageToBuffer"
                                | "vkCmdCopyImage" => c.copies += 1,
                                "vkCmdFillBuffer"
                                | "vkCmdClearColorImage"
                                | "vkCmdUpdateBuffer" => c.clears += 1,
                                "vkCmdPipelineBarrier" => {
                                    for key in [
                                        "pMemoryBarriers",
                                        "pBufferMemoryBarriers",
                                        "pImageMemoryBarriers",
                                    ] {
                                        c.barriers += a[key].as_array().map_or(0, Vec::len);
                                    }
                                }
                                "vkCmdPipelineBarrier2" => {
                                    let d = &a["pDependencyInfo"];
                                    for key in [
                                        "pMemoryBarriers",
                                        "pBufferMemoryBarriers",
                                        "pImageMemoryBarriers",
                                    ] {
                                        c.barriers += d[key].as_array().map_or(0, Vec::len);
                                    }
                                }
                                _ => {}
                            }
                        }
                    }
                }
            }
            _ => {}
        }
    }
    c.images.extend(swapchain_extent);
    c
}

/// Imports a fixture through the command line into a scratch folder; the capture as JSON, its
/// file, and the folder (removed when dropped).
fn import_cli(name: &str, extra: &[&str]) -> (Value, PathBuf, Scratch) {
    let dir = Scratch::temp("framelab-import");
    let out = dir.join(name.replace(".jsonl", &format!("{}.json", extra.join("_"))));
    let input = gfxr_fixture(name);
    let mut args = vec![
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ];
    args.extend_from_slice(extra);
    let o = framelab(&args);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let summary = json(&o);
    assert_eq!(summary["file"], input.to_str().unwrap());
    let capture: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    (capture, out, dir)
}

fn passes(c: &Value) -> &Vec<Value> {
    c["passes"].as_array().unwrap()
}

fn kind_count(c: &Value, kind: &str) -> usize {
    passes(c).iter().filter(|p| p["kind"] == kind).count()
}

#[test]
fn every_stream_imports_as_it_was_recorded() {
    for name in STREAMS {
        let expected = counts(&gfxr_fixture(name));
        let (c, out, _dir) = import_cli(name, &[]);
        let ps = passes(&c);
        let draws: usize = ps
            .iter()
            .map(|p| p["draws"].as_array().map_or(0, Vec::len))
            .sum();
        let dispatches: usize = ps
            .iter()
            .map(|p| p["dispatches"].as_array().map_or(0, Vec::len))
            .sum();
        let copies: usize = ps.iter().filter(|p| p["kind"] == "copy").count();
        let clears: usize = ps.iter().filter(|p| p["kind"] == "clear").count();
        let recorded: usize = ps
            .iter()
            .flat_map(|p| p["barriers"].as_array().into_iter().flatten())
            .filter(|b| {
                b["vulkan"]["origin"]
                    .as_str()
                    .unwrap()
                    .starts_with("vkCmdPipelineBarrier")
            })
            .count();
        assert_eq!(draws, expected.draws, "{name}: draws");
        assert_eq!(dispatches, expected.dispatches, "{name}: dispatches");
        assert_eq!(
            kind_count(&c, "raster"),
            expected.render_pass_instances,
            "{name}: render pass instances"
        );
        assert_eq!(copies, expected.copies, "{name}: copies");
        assert_eq!(clears, expected.clears, "{name}: clears");
        assert_eq!(
            kind_count(&c, "present"),
            expected.presents,
            "{name}: presents"
        );
        assert_eq!(recorded, expected.barriers, "{name}: recorded barriers");
        // Every imported texture is an image the stream created, in its format and size.
        for r in c["resources"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["kind"] != "buffer")
        {
            let format = r["format"].as_str().unwrap();
            let size = (r["width"].as_u64().unwrap(), r["height"].as_u64().unwrap());
            let found = expected.images.iter().any(|(vk, w, h)| {
                (*w, *h) == size && dxgi::lookup_vk(vk).is_some_and(|f| f.name == format)
            });
            assert!(
                found,
                "{name}: {} ({format} {size:?}) is not an image of the stream",
                r["name"]
            );
        }
        // What every later command accepts.
        let o = framelab(&["validate", out.to_str().unwrap()]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
}

#[test]
fn formats_barriers_and_placements_are_the_streams() {
    let (c, _, _) = import_cli("wgpu30_egui_kittest.jsonl", &[]);
    let res: BTreeMap<&str, &Value> = c["resources"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["name"].as_str().unwrap(), r))
        .collect();
    // vkCreateImage #205: R8G8B8A8_UNORM 2048x32, usage TRANSFER_DST | SAMPLED (6), bound at
    // 630784 in memory 10 with the 16-byte alignment vkGetImageMemoryRequirements gave.
    let font = res["egui_texid_Managed(0)"];
    assert_eq!(
        (
            font["format"].as_str(),
            font["width"].as_u64(),
            font["height"].as_u64()
        ),
        (Some("R8G8B8A8_UNORM"), Some(2048), Some(32))
    );
    assert_eq!(font["placement"]["placed"]["offset"], 630784);
    assert_eq!(font["placement"]["placed"]["alignment"], 16);
    // The render target's copy back to the CPU keeps the frame's work alive.
    assert!(res.values().any(|r| r["output"] == true));
    // vkCmdPipelineBarrier #99: TOP_OF_PIPE -> TRANSFER, none -> TRANSFER_WRITE, whole buffer 9.
    let b = passes(&c)
        .iter()
        .flat_map(|p| p["barriers"].as_array().into_iter().flatten())
        .find(|b| b["vulkan"]["origin"] == "vkCmdPipelineBarrier #99")
        .unwrap();
    assert_eq!(b["type"], "vulkan");
    assert_eq!(
        b["vulkan"]["src_stages"],
        serde_json::json!(["TOP_OF_PIPE"])
    );
    assert_eq!(
        b["vulkan"]["dst_stages"],
        serde_json::json!(["TRANSFER", "BOTTOM_OF_PIPE"])
    );
    assert_eq!(
        b["vulkan"]["dst_access"],
        serde_json::json!(["TRANSFER_WRITE"])
    );
    // The egui pass: its label, eight indexed draws with their vertex and index buffers.
    let egui = passes(&c)
        .iter()
        .find(|p| p["name"] == "Egui Render Pass")
        .unwrap();
    assert_eq!(
        egui["markers"],
        serde_json::json!(["frame 0", "Egui Render Pass"])
    );
    let draws = egui["draws"].as_array().unwrap();
    assert_eq!(draws.len(), 8);
    assert_eq!(draws[0]["count"], 30);
    assert!(draws.iter().all(
        |d| d["index_buffer"].is_string() && d["vertex_buffers"].as_array().unwrap().len() == 1
    ));
    // Render pass 103 clears its one attachment (VK_ATTACHMENT_LOAD_OP_CLEAR).
    assert_eq!(egui["color_attachments"][0]["load"], "clear");
}

#[test]
fn a_missing_barrier_is_reported_in_vulkan_terms() {
    // vkd3d clears the swapchain image in one render pass and loads it in a second; neither
    // declares a subpass dependency, and with no layout change there is no implicit one:
    // nothing orders the first pass's store with the second's load. It then presents
    // waiting on no semaphore, so nothing orders the transition to PRESENT_SRC_KHR before
    // the presentation engine's read.
    let (_, out, _dir) = import_cli("vkd3d_triangle.jsonl", &[]);
    let o = framelab(&["analyze", out.to_str().unwrap(), "--json"]);
    let lints = json(&o)["lints"].as_array().unwrap().clone();
    let missing: Vec<&Value> = lints.iter().filter(|l| l["code"] == "FL020").collect();
    assert_eq!(missing.len(), 2, "{missing:?}");
    // Each is shown on its pass: the render pass that loads, the present.
    let c: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let kind_of = |lint: &Value| {
        let name = lint["pass"].as_str().expect("the finding names its pass");
        passes(&c).iter().find(|p| p["name"] == name).unwrap()["kind"].clone()
    };
    assert_eq!(kind_of(missing[0]), "raster");
    assert_eq!(kind_of(missing[1]), "present");
    let present = missing[1]["message"].as_str().unwrap();
    for part in [
        "vkQueuePresentKHR #157",
        "PRESENT_AFTER_WRITE",
        "of vkCmdPipelineBarrier #154",
    ] {
        assert!(present.contains(part), "{present}");
    }
    let m = missing[0]["message"].as_str().unwrap();
    for part in [
        "vkCmdBeginRenderPass #151",
        "READ_AFTER_WRITE",
        "\"swapchain_0\"",
        "(load op LOAD)",
        "(store op STORE) of vkCmdEndRenderPass #146",
    ] {
        assert!(m.contains(part), "{m}");
    }
    // A well-synchronised stream has no missing barrier at all.
    for clean in [
        "vkcube_lavapipe.jsonl",
        "wgpu30_egui_kittest.jsonl",
        "framelab_example_replay.jsonl",
    ] {
        let (_, out, _dir) = import_cli(clean, &[]);
        let o = framelab(&["analyze", out.to_str().unwrap(), "--json"]);
        let lints = json(&o)["lints"].as_array().unwrap().clone();
        assert!(
            !lints.iter().any(|l| l["code"] == "FL020"),
            "{clean}: {lints:?}"
        );
    }
    // `--deny` gates CI on it.
    let o = framelab(&["analyze", out.to_str().unwrap(), "--deny", "FL020"]);
    assert!(!o.status.success());
}

#[test]
fn the_1x_dialect_with_frames_queues_and_semaphores() {
    let (c, _, _) = import_cli("v1_dynamic_rendering.jsonl", &[]);
    let names: Vec<&str> = passes(&c)
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "density",
            "render_pass",
            "density (frame 1)",
            "render_pass (frame 1)"
        ]
    );
    assert_eq!(
        passes(&c)[2]["markers"],
        serde_json::json!(["frame 1", "density"])
    );
    let queues: BTreeMap<&str, &str> = c["queues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| (q["name"].as_str().unwrap(), q["type"].as_str().unwrap()))
        .collect();
    assert_eq!(
        queues,
        BTreeMap::from([("compute", "compute"), ("graphics", "graphics")])
    );
    // The semaphore each frame signals on the compute queue and waits on for the graphics one.
    assert_eq!(c["fences"].as_array().unwrap().len(), 2);
    assert_eq!(passes(&c)[0]["signal"], passes(&c)[1]["wait"]);
    // Two dispatches between barriers are one compute pass; dynamic rendering is a raster pass.
    assert_eq!(passes(&c)[0]["dispatches"].as_array().unwrap().len(), 2);
    assert_eq!(passes(&c)[1]["color_attachments"][0]["load"], "clear");
    // Flags as symbols and as hex both read: usage 0xc is SAMPLED | STORAGE.
    let density = c["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "density")
        .unwrap();
    assert_eq!(
        density["flags"],
        serde_json::json!(["ALLOW_UNORDERED_ACCESS"])
    );
    assert_eq!(density["placement"]["placed"]["offset"], 524288);

    let (one, _, _) = import_cli("v1_dynamic_rendering.jsonl", &["--frame", "1"]);
    let names: Vec<&str> = passes(&one)
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["density (frame 1)", "render_pass (frame 1)"]);
    let o = framelab(&[
        "import",
        gfxr_fixture("v1_dynamic_rendering.jsonl").to_str().unwrap(),
        "-o",
        "/dev/null",
        "--frame",
        "7",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("frame 7 was asked for, but the stream holds 2 frame(s)"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn the_example_capture_survives_a_round_trip_through_gfxreconstruct() {
    // The fixture is `framelab replay captures/example/frame.json --scale 0.25 --frames 1`
    // captured by GFXReconstruct 0.9.18 on lavapipe and converted to JSON Lines.
    let (c, out, _dir) = import_cli("framelab_example_replay.jsonl", &[]);
    let imported = json(&framelab(&["info", out.to_str().unwrap(), "--json"]));
    let original = json(&framelab(&[
        "info",
        "captures/example/frame.json",
        "--json",
        "--scale",
        "0.25",
    ]));
    let res = |info: &Value, name: &str| -> Value {
        info["resources"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == name)
            .cloned()
            .unwrap()
    };
    let family = |f: &str| {
        dxgi::lookup(f)
            .map(|i| i.typeless_family.unwrap_or(i.name))
            .unwrap()
    };
    let mut at = 0;
    for p in original["passes"].as_array().unwrap() {
        let name = p["name"].as_str().unwrap();
        match p["kind"].as_str().unwrap() {
            "raster" | "compute" => {
                let ip = imported["passes"].as_array().unwrap()[at..]
                    .iter()
                    .position(|q| q["name"] == name)
                    .map(|i| i + at)
                    .unwrap_or_else(|| panic!("{name} is not imported after pass {at}"));
                let q = &imported["passes"][ip];
                assert_eq!(q["kind"], p["kind"], "{name}");
                assert_eq!(q["draws"], p["draws"], "{name}");
                assert_eq!(q["dispatches"], p["dispatches"], "{name}");
                // Attachments and storage targets: the same textures, formats and sizes.
                for w in p["writes"].as_array().unwrap() {
                    let w = w.as_str().unwrap();
                    let (a, b) = (res(&original, w), res(&imported, w));
                    if a["kind"] == "buffer" {
                        continue;
                    }
                    assert!(
                        q["writes"].as_array().unwrap().iter().any(|x| x == w),
                        "{name} writes {w}"
                    );
                    assert_eq!(
                        (&a["width"], &a["height"]),
                        (&b["width"], &b["height"]),
                        "{w}"
                    );
                    assert_eq!(
                        family(a["format"].as_str().unwrap()),
                        family(b["format"].as_str().unwrap()),
                        "{w}"
                    );
                }
                at = ip + 1;
            }
            "generate_mips" => {
                // wgpu builds mips one render pass per level, each writing the next level.
                let target = p["writes"][0].as_str().unwrap();
                let levels = res(&original, target)["mip_levels"].as_u64().unwrap();
                let mips: Vec<u64> = passes(&c)
                    .iter()
                    .filter(|q| q["markers"].as_array().unwrap().iter().any(|m| m == "mip"))
                    .filter_map(|q| q["color_attachments"].as_array()?.first().cloned())
                    .filter(|a| a["resource"] == target)
                    .map(|a| a["mip"].as_u64().unwrap_or(0))
                    .collect();
                assert_eq!(mips, (1..levels).collect::<Vec<_>>(), "{name}");
            }
            _ => {}
        }
    }
    // The upload and the clear: a copy into the noise source and a fill of the indirect arguments.
    assert!(passes(&c).iter().any(|q| {
        q["kind"] == "copy"
            && q["copies"]
                .as_array()
                .unwrap()
                .iter()
                .any(|x| x["dst"]["resource"] == "noise_src")
    }));
    assert!(
        passes(&c)
            .iter()
            .any(|q| q["kind"] == "clear" && q["clears"][0]["resource"] == "draw_args")
    );
}

#[test]
fn imported_captures_are_analysed_not_replayed() {
    let (_, out, _dir) = import_cli("vkcube_lavapipe.jsonl", &[]);
    let o = framelab(&["replay", out.to_str().unwrap(), "--scale", "0.25"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("captured by GFXReconstruct 0.9.18")
            && e.contains("no shader code")
            && e.contains("not replayed"),
        "{e}"
    );
    for cmd in ["graph", "info"] {
        let o = framelab(&[cmd, out.to_str().unwrap()]);
        assert!(o.status.success(), "{cmd}: {}", stderr(&o));
    }
    let o = framelab(&[
        "diff",
        "--structure",
        out.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("no structural"), "{}", stdout(&o));
}

#[test]
fn unreadable_streams_are_located_and_write_nothing() {
    let dir = Scratch::temp("framelab-import-bad");
    let text = std::fs::read_to_string(gfxr_fixture("vkd3d_triangle.jsonl")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let truncated = &lines[40][..lines[40].len() / 2].to_owned();
    lines[40] = truncated;
    let cases: [(&str, String, &str); 6] = [
        ("truncated.jsonl", lines.join("\n"), ":41: truncated JSON"),
        ("empty.jsonl", String::new(), "the file is empty"),
        (
            "capture.jsonl",
            std::fs::read_to_string(repo().join("captures/example/frame.json")).unwrap(),
            "already a framelab capture (it has `format_version`)",
        ),
        (
            "document.jsonl",
            "{\n  \"a\": 1\n}\n".to_owned(),
            "a JSON document over several lines, not a JSON Lines stream",
        ),
        (
            "not_lines.jsonl",
            "[1, 2, 3]\n".to_owned(),
            ":1: expected a JSON object",
        ),
        (
            "binary.jsonl",
            "\u{0}\u{1}gfxr".to_owned(),
            "neither a GFXReconstruct binary capture",
        ),
    ];
    for (name, body, message) in cases {
        let input = dir.join(name);
        std::fs::write(&input, body).unwrap();
        let out = dir.join(format!("{name}.json"));
        let o = framelab(&[
            "import",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{name}");
        assert!(stderr(&o).contains(message), "{name}: {}", stderr(&o));
        assert!(!out.exists(), "{name}: a capture was written");
    }
    let o = framelab(&[
        "import",
        dir.to_str().unwrap(),
        "-o",
        dir.join("x.json").to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("is not a regular file"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn edits_that_cannot_land_are_named_and_write_nothing() {
    let dir = Scratch::temp("framelab-edit");
    let source = gfxr_fixture("vkd3d_gears_f2.gfxr");
    let out = dir.join("out.gfxr");
    let edit = |set: &str| {
        framelab(&[
            "edit",
            source.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--set",
            set,
        ])
    };
    for (set, says) in [
        ("99999:srcStageMask=1", "has no block 99999"),
        (
            "176:pImageMemoryBarriers[3].srcAccessMask=0",
            "no number at `pImageMemoryBarriers[3].srcAccessMask`",
        ),
        (
            "176:srcStageMask=0x100000000",
            "does not fit the 4-byte field",
        ),
        ("0:srcStageMask=1", "not a call"),
    ] {
        let run = edit(set);
        assert_eq!(run.status.code(), Some(1), "{set}");
        assert!(stderr(&run).contains(says), "{set}: {}", stderr(&run));
        assert!(!out.exists(), "{set}: something was written");
    }
    let bad = edit("176:srcStageMask");
    assert_eq!(
        bad.status.code(),
        Some(2),
        "a malformed edit is a usage error"
    );
    // An edit that lands changes that one field: the import sees the weaker barrier.
    let run = edit("176:dstStageMask=VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT");
    assert!(run.status.success(), "{}", stderr(&run));
    let c = dir.join("edited.json");
    let imported = framelab(&["import", out.to_str().unwrap(), "-o", c.to_str().unwrap()]);
    assert!(imported.status.success(), "{}", stderr(&imported));
    let edited: Value = serde_json::from_str(&std::fs::read_to_string(&c).unwrap()).unwrap();
    let stages: Vec<Value> = passes(&edited)
        .iter()
        .flat_map(|p| p["barriers"].as_array().cloned().unwrap_or_default())
        .filter(|b| b["vulkan"]["origin"] == "vkCmdPipelineBarrier #176")
        .map(|b| b["vulkan"]["dst_stages"].clone())
        .collect();
    assert_eq!(
        stages,
        [serde_json::json!(["BOTTOM_OF_PIPE"])],
        "the barrier at block 176"
    );
}

#[test]
fn debug_names_are_cleaned_and_never_make_names_collide() {
    // The 1.x fixture edited: its second frame signals a second semaphore, both named alike by
    // the application; its image "hdr_color" renamed with terminal escapes in the name.
    let text = std::fs::read_to_string(gfxr_fixture("v1_dynamic_rendering.jsonl")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let create = lines
        .iter()
        .position(|l| l.contains("\"vkCreateSemaphore\""))
        .unwrap();
    let second = lines[create].replace("\"pSemaphore\":50", "\"pSemaphore\":51");
    let submits: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].contains("\"semaphore\":50"))
        .collect();
    assert_eq!(submits.len(), 4, "two signals and two waits");
    for &i in &submits[2..] {
        lines[i] = lines[i].replace("\"semaphore\":50", "\"semaphore\":51");
    }
    let name = |handle: u64, object: &str, name: &str| {
        serde_json::json!({"index": 0, "function": {"name": "vkSetDebugUtilsObjectNameEXT",
            "thread": 1, "return": "VK_SUCCESS", "args": {"device": 3, "pNameInfo": {
            "sType": "VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT", "pNext": null,
            "objectType": object, "objectHandle": handle, "pObjectName": name}}}})
        .to_string()
    };
    let added = [
        second,
        name(50, "VK_OBJECT_TYPE_SEMAPHORE", "relay"),
        name(51, "VK_OBJECT_TYPE_SEMAPHORE", "relay"),
        name(11, "VK_OBJECT_TYPE_IMAGE", "\u{1b}[2Jhdr\u{7}"),
    ];
    lines.splice(create + 1..create + 1, added);
    let (_, c, dir) = import_lines("names", &lines);
    let fences: Vec<&str> = c["fences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert_eq!(fences, ["relay#1", "relay@51#1"]);
    assert!(
        c["resources"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| r["name"] == "\u{fffd}[2Jhdr\u{fffd}"),
        "{}",
        c["resources"]
    );

    // A capture written with such a name is refused, the name shown escaped.
    let mut raw = c.clone();
    raw["resources"][0]["name"] = "\u{1b}[31mred".into();
    let bad = dir.join("bad.json");
    std::fs::write(&bad, serde_json::to_string(&raw).unwrap()).unwrap();
    let o = framelab(&["validate", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("resources[0] name \"\\u{1b}[31mred\" holds a control character"),
        "{e}"
    );
    assert!(
        !e.contains('\u{1b}'),
        "a raw escape reached the terminal: {e:?}"
    );
}

/// `lines` written as a stream and imported in a scratch folder (kept while the result is):
/// the summary and the capture as JSON.
fn import_lines(tag: &str, lines: &[String]) -> (Value, Value, Scratch) {
    let dir = Scratch::temp(&format!("framelab-import-{tag}"));
    let input = dir.join(format!("{tag}.jsonl"));
    std::fs::write(&input, lines.join("\n") + "\n").unwrap();
    let out = dir.join(format!("{tag}.json"));
    let summary = crate::gfxr_binary::import(&input, &out);
    let capture = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    (summary, capture, dir)
}

/// vkcube's stream with `edit` applied to its lines, imported: the summary as JSON.
fn import_edited(tag: &str, edit: impl FnOnce(&mut Vec<String>)) -> Value {
    let text = std::fs::read_to_string(gfxr_fixture("vkcube_f3.jsonl")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    edit(&mut lines);
    import_lines(tag, &lines).0
}

/// The index of the line recording vkCmdDraw into command buffer `cb`.
fn draw_line(lines: &[String], cb: u64) -> usize {
    let key = format!("\"commandBuffer\":{cb},");
    lines
        .iter()
        .position(|l| l.contains("\"vkCmdDraw\"") && l.contains(&key))
        .unwrap()
}

fn left_out(summary: &Value, what: &str) -> bool {
    summary["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .any(|k| k["what"].as_str().unwrap().contains(what))
}

#[test]
fn what_a_few_lines_ask_to_walk_or_emit_is_bounded() {
    // Each of vkcube's three command buffers executes the next a hundred times in place of
    // its draw (the third the second again): about 10^8 commands at four levels, which
    // took minutes to walk. The submission is sized first and left out, at once.
    let nested = import_edited("nested", |lines| {
        for (cb, next) in [(41, 42), (42, 43), (43, 42)] {
            let at = draw_line(lines, cb);
            let list = vec![next.to_string(); 100].join(",");
            lines[at] = format!(
                "{{\"index\":900,\"vkFunc\":{{\"name\":\"vkCmdExecuteCommands\",\"args\":{{\"commandBuffer\":{cb},\"commandBufferCount\":100,\"pCommandBuffers\":[{list}]}}}}}}"
            );
        }
    });
    assert!(
        left_out(&nested, "submissions of over 1048576 commands"),
        "{nested}"
    );
    // One command buffer of 200 draws submitted 1,000 times: 200,000 draws, of which the
    // import keeps 131,072 and names the rest.
    let repeated = import_edited("repeated", |lines| {
        let at = draw_line(lines, 41);
        let draw = lines[at].clone();
        lines.splice(at..=at, std::iter::repeat_n(draw, 200));
        let submit = lines
            .iter()
            .position(|l| l.contains("\"vkQueueSubmit\""))
            .unwrap();
        let list = vec!["41"; 1000].join(",");
        lines[submit] = lines[submit].replace(
            "\"commandBufferCount\":1,\"pCommandBuffers\":[41]",
            &format!("\"commandBufferCount\":1000,\"pCommandBuffers\":[{list}]"),
        );
        assert!(lines[submit].contains("[41,41"));
    });
    let draws = repeated["draws"].as_u64().unwrap();
    assert!((131_000..=131_072).contains(&draws), "{draws}");
    assert!(
        left_out(&repeated, "beyond the limit of 131072: not imported"),
        "{repeated}"
    );
    // What is left is not the frame: it does not replay, and says why.
    let why = repeated["not_replayable"].as_str().unwrap_or_default();
    assert!(
        why.contains("beyond the limit of 131072: not imported in or after pass"),
        "{why}"
    );
}

#[test]
fn captures_of_other_tools_are_named_not_parsed() {
    let gfxr = gfxr_fixture("vkcube_f3.gfxr");
    let jsonl = gfxr_fixture("vkcube_f3.jsonl");
    for (cmd, file, code, what) in [
        (
            "validate",
            &gfxr,
            1,
            "a GFXReconstruct capture (.gfxr), not a framelab capture",
        ),
        (
            "replay",
            &gfxr,
            1,
            "a GFXReconstruct capture (.gfxr), not a framelab capture",
        ),
        (
            "info",
            &jsonl,
            1,
            "a GFXReconstruct JSON Lines stream (gfxrecon-convert), not a framelab capture",
        ),
        (
            "diff",
            &jsonl,
            2,
            "a GFXReconstruct JSON Lines stream (gfxrecon-convert), not a framelab capture",
        ),
    ] {
        let f = file.to_str().unwrap();
        let o = if cmd == "diff" {
            framelab(&[cmd, f, f])
        } else {
            framelab(&[cmd, f])
        };
        assert_eq!(o.status.code(), Some(code), "{cmd}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains(what) && e.contains("framelab import"),
            "{cmd}: {e}"
        );
    }
}

#[test]
fn debug_labels_are_cleaned_and_an_empty_one_names_nothing() {
    let label = |name: &str| {
        serde_json::json!({"index": 901, "vkFunc": {"name": "vkCmdBeginDebugUtilsLabelEXT",
            "args": {"commandBuffer": 41, "pLabelInfo": {
            "sType": "VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT", "pNext": null,
            "pLabelName": name, "color": [0.0, 0.0, 0.0, 0.0]}}}})
        .to_string()
    };
    let end = "{\"index\":902,\"vkFunc\":{\"name\":\"vkCmdEndDebugUtilsLabelEXT\",\"args\":{\"commandBuffer\":41}}}";
    let text = std::fs::read_to_string(gfxr_fixture("vkcube_f3.jsonl")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let key = "\"commandBuffer\":41,";
    let begin = lines
        .iter()
        .position(|l| l.contains("\"vkCmdBeginRenderPass\"") && l.contains(key))
        .unwrap();
    let finish = lines
        .iter()
        .position(|l| l.contains("\"vkCmdEndRenderPass\"") && l.contains("\"commandBuffer\":41}"))
        .unwrap();
    lines.splice(finish + 1..finish + 1, [end.to_owned(), end.to_owned()]);
    lines.splice(begin..begin, [label("\u{1b}[2Jsky"), label(" ")]);
    let (_, c, dir) = import_lines("labels", &lines);
    let pass = passes(&c)
        .iter()
        .find(|p| p["name"] == "\u{fffd}[2Jsky")
        .unwrap_or_else(|| panic!("{}", c["passes"]));
    assert_eq!(
        pass["markers"],
        serde_json::json!(["frame 0", "\u{fffd}[2Jsky"])
    );
    let v = framelab(&["validate", dir.join("labels.json").to_str().unwrap()]);
    assert!(v.status.success(), "{}", stderr(&v));
}

#[test]
fn notes_count_only_the_imported_frames() {
    // vkcube's whole run waits on its acquire semaphore once a frame: importing its third
    // frame notes one wait, not the three frames' (and more) read before it.
    let dir = Scratch::temp("framelab-import-notes");
    let out = dir.join("third.json");
    let o = framelab(&[
        "import",
        gfxr_fixture("vkcube_whole.gfxr").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--frame",
        "2",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&o);
    let waits = summary["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .find(|k| k["what"].as_str().unwrap().contains("no queue signal"))
        .unwrap_or_else(|| panic!("{summary}"));
    assert_eq!(waits["count"], 1, "{summary}");
}

#[test]
fn a_name_from_the_stream_stays_on_its_line() {
    // The stream's header names the tool: here with a line of its own and an escape in it.
    let dir = Scratch::temp("framelab-import-oneline");
    let text = std::fs::read_to_string(gfxr_fixture("vkcube_f3.jsonl")).unwrap();
    let (header, rest) = text.split_once('\n').unwrap();
    assert!(header.contains("\"gfxrecon-version\""), "{header}");
    let forged = "{\"header\":{\"json-version\":\"0.8.0\",\"gfxrecon-version\":\"0.9\\nerror: forged\\u001b[2J\"}}";
    let input = dir.join("forged.jsonl");
    std::fs::write(&input, format!("{forged}\n{rest}")).unwrap();
    let out = dir.join("forged.json");
    let o = framelab(&[
        "import",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = stdout(&o);
    // Cleaned as the importer cleans every name it reads: control characters replaced.
    assert!(
        summary.contains("0.9\u{fffd}error: forged\u{fffd}[2J"),
        "{summary}"
    );
    assert!(
        !summary.lines().any(|l| l.starts_with("error: forged")),
        "{summary}"
    );
}
