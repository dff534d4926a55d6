//! Classes of Vulkan a real frame may use, member by member, on small synthetic edits of a
//! real program's capture: dynamic state baked into pipeline variants, sampler fields,
//! secondary command buffers inside a render pass, and commands the replay cannot reproduce
//! refused with their pass named. The coverage table is held against the registry.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use crate::common::{Scratch, framelab, gfxr_fixture, stderr, stdout};

pub(crate) fn temp(name: &str) -> Scratch {
    Scratch::temp(&format!("framelab-vk-classes-{name}"))
}

/// Imports `source` to `capture`, which must succeed; what the import printed.
fn import(source: &Path, capture: &Path) -> String {
    let out = framelab(&[
        "import",
        source.to_str().unwrap(),
        "-o",
        capture.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    stdout(&out)
}

/// vkcube's third frame imported from its binary capture into `dir`.
pub(crate) fn vkcube(dir: &Path) -> PathBuf {
    let capture = dir.join("vkcube.json");
    import(&gfxr_fixture("vkcube_f3.gfxr"), &capture);
    capture
}

pub(crate) fn edit(capture: &Path, change: impl FnOnce(&mut Value)) {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(capture).unwrap()).unwrap();
    change(&mut v);
    std::fs::write(capture, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

/// The one draw of vkcube's frame and its pipeline's graphics state.
pub(crate) fn draw_and_state(v: &mut Value) -> (&mut Value, &mut Value) {
    let Value::Object(root) = v else {
        panic!("a capture is an object")
    };
    let mut pipelines = None;
    let mut passes = None;
    for (k, val) in root.iter_mut() {
        match k.as_str() {
            "vulkan" => pipelines = Some(&mut val["pipelines"][0]["graphics"]),
            "passes" => passes = Some(val),
            _ => {}
        }
    }
    let draw = passes
        .unwrap()
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["draws"].as_array().is_some_and(|d| !d.is_empty()))
        .map(|p| &mut p["draws"][0])
        .unwrap();
    (&mut draw["vulkan_state"], pipelines.unwrap())
}

/// Replays `capture`, which must be refused (exit 1) with nothing written to its export
/// folder; what the replay said.
pub(crate) fn replay_fails(capture: &Path) -> String {
    let out = capture.with_extension("refused");
    let run = framelab(&[
        "replay",
        capture.to_str().unwrap(),
        "--frames",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(!out.join("manifest.json").exists(), "nothing half-written");
    stderr(&run)
}

fn reference() -> image::RgbaImage {
    image::open(gfxr_fixture("vkcube_f3.ref.png"))
        .unwrap()
        .to_rgba8()
}

/// Every dynamic state vkcube's pipeline has fixed, declared dynamic instead with the same
/// values set by the command buffer: the baked variant draws the same image. Set otherwise
/// (front faces culled), the image changes; never set, or of a class wgpu has no twin for,
/// the replay is refused naming the state, the pass and the draw.
#[test]
fn dynamic_state_is_baked_into_pipeline_variants() {
    let dir = temp("dynamic");
    let capture = vkcube(&dir);
    let same = json!({
        "cull_mode": 2,
        "front_face": "VK_FRONT_FACE_COUNTER_CLOCKWISE",
        "topology": "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST",
        "primitive_restart_enable": false,
        "rasterizer_discard_enable": false,
        "depth_test_enable": true,
        "depth_write_enable": true,
        "depth_compare_op": "VK_COMPARE_OP_LESS_OR_EQUAL",
        "depth_bounds_test_enable": false,
        "stencil_test_enable": false,
        "depth_bias_enable": false,
        "line_width": 4.0,
        "color_write_enable": [true],
    });
    edit(&capture, |v| {
        let (draw, g) = draw_and_state(v);
        let states = g["dynamic_states"].as_array_mut().unwrap();
        for s in [
            "CULL_MODE",
            "FRONT_FACE",
            "PRIMITIVE_TOPOLOGY",
            "PRIMITIVE_RESTART_ENABLE",
            "RASTERIZER_DISCARD_ENABLE",
            "DEPTH_TEST_ENABLE",
            "DEPTH_WRITE_ENABLE",
            "DEPTH_COMPARE_OP",
            "DEPTH_BOUNDS_TEST_ENABLE",
            "DEPTH_BOUNDS",
            "STENCIL_TEST_ENABLE",
            "DEPTH_BIAS_ENABLE",
            "DEPTH_BIAS",
            "LINE_WIDTH",
            "COLOR_WRITE_ENABLE_EXT",
        ] {
            states.push(json!(format!("VK_DYNAMIC_STATE_{s}")));
        }
        // The pipeline's own values say otherwise: only the draw's count.
        g["cull_mode"] = json!(0);
        g["depth_stencil"]["depth_test"] = json!(false);
        draw["dynamic"] = same.clone();
    });
    let image = crate::common::replay_presented(&capture, &dir.join("same"));
    crate::golden::within("vkcube with dynamic state", &image, &reference()).unwrap();

    // Front faces culled and the depth test off: the cube is drawn inside out.
    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"]["cull_mode"] = json!(1);
        draw["dynamic"]["depth_test_enable"] = json!(false);
    });
    let image = crate::common::replay_presented(&capture, &dir.join("front"));
    assert!(
        crate::golden::within("vkcube culled inside out", &image, &reference()).is_err(),
        "the draw's cull mode and depth test reached the pipeline"
    );

    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"].as_object_mut().unwrap().remove("cull_mode");
    });
    let err = replay_fails(&capture);
    for part in [
        "draw 0",
        "pipeline_40",
        "dynamic cull mode the draw never set",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }

    edit(&capture, |v| {
        let (draw, g) = draw_and_state(v);
        draw["dynamic"] = same.clone();
        g["dynamic_states"]
            .as_array_mut()
            .unwrap()
            .push(json!("VK_DYNAMIC_STATE_POLYGON_MODE_EXT"));
    });
    let err = replay_fails(&capture);
    for part in [
        "pass \"render_pass\"",
        "draw 0",
        "VK_DYNAMIC_STATE_POLYGON_MODE_EXT",
        "pipeline_40",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
}

/// A depth bias the draw switches on with a fractional constant factor: wgpu takes whole
/// numbers, so the replay takes the nearest and says so, naming the pipeline.
#[test]
fn a_fractional_depth_bias_is_rounded_with_a_note() {
    let dir = temp("bias");
    let capture = vkcube(&dir);
    edit(&capture, |v| {
        let (draw, g) = draw_and_state(v);
        let states = g["dynamic_states"].as_array_mut().unwrap();
        states.push(json!("VK_DYNAMIC_STATE_DEPTH_BIAS"));
        states.push(json!("VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE"));
        draw["dynamic"] = json!({"depth_bias": [0.4, 0.0, 0.0], "depth_bias_enable": true});
    });
    let (_, said) = crate::common::replay_export(&capture, &dir.join("out"));
    assert!(
        said.contains("pipeline pipeline_40: depth bias constant factor 0.4 taken as 0"),
        "{said}"
    );
}

/// Sampler fields: a LOD bias on a view of one mip level sampled with one filter up and down
/// changes nothing and replays to the program's image. A clamp-to-border sampler replays
/// through wgpu's border feature; an integer opaque border colour is refused by name. With a
/// different minification filter the bias decides which filter a pixel gets, so it must
/// reach the shader: biased far up (every pixel minified, bilinear) and far down (every pixel
/// magnified, nearest) the images differ.
#[test]
fn sampler_fields_replay_or_are_refused_by_name() {
    let dir = temp("sampler");
    let capture = vkcube(&dir);
    edit(&capture, |v| {
        let s = &mut v["vulkan"]["samplers"][0];
        s["mip_lod_bias"] = json!(-0.5);
        for k in ["address_mode_u", "address_mode_v", "address_mode_w"] {
            s[k] = json!("VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER");
        }
    });
    let image = crate::common::replay_presented(&capture, &dir.join("moot"));
    crate::golden::within("vkcube, biased and bordered", &image, &reference()).unwrap();
    // Filtering within each face of a cube changes nothing on vkcube's 2D view.
    edit(&capture, |v| {
        v["vulkan"]["samplers"][0]["non_seamless_cube"] = json!(true);
    });
    let image = crate::common::replay_presented(&capture, &dir.join("faces"));
    crate::golden::within("vkcube, non-seamless", &image, &reference()).unwrap();

    edit(&capture, |v| {
        v["vulkan"]["samplers"][0]["border_color"] = json!("VK_BORDER_COLOR_INT_OPAQUE_BLACK");
    });
    let err = replay_fails(&capture);
    for part in ["sampler_26", "VK_BORDER_COLOR_INT_OPAQUE_BLACK", "draw 0"] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
    // A custom border colour wgpu has as one of its own replays; another is refused, named.
    let custom = |colour: Value, out: &str| {
        edit(&capture, |v| {
            let s = &mut v["vulkan"]["samplers"][0];
            s["border_color"] = json!("VK_BORDER_COLOR_FLOAT_CUSTOM_EXT");
            s["custom_border_color"] = colour.clone();
        });
        crate::common::replay_presented(&capture, &dir.join(out))
    };
    let image = custom(json!([1.0, 1.0, 1.0, 1.0]), "custom");
    crate::golden::within("vkcube, custom white border", &image, &reference()).unwrap();
    edit(&capture, |v| {
        v["vulkan"]["samplers"][0]["custom_border_color"] = json!([0.5, 0.25, 0.0, 1.0]);
    });
    let err = replay_fails(&capture);
    for part in [
        "sampler_26 with a custom border colour (0.5, 0.25, 0, 1;",
        "VK_BORDER_COLOR_FLOAT_CUSTOM_EXT",
        "draw 0",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }

    let biased = |bias: f32, out: &str| {
        edit(&capture, |v| {
            let s = &mut v["vulkan"]["samplers"][0];
            s["border_color"] = json!("VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE");
            s["min_filter"] = json!("VK_FILTER_LINEAR");
            // A level of detail clamped to 0 would always magnify; let it rise.
            s["max_lod"] = json!(16.0);
            s["mip_lod_bias"] = json!(bias);
        });
        crate::common::replay_presented(&capture, &dir.join(out))
    };
    let (up, down) = (biased(8.0, "up"), biased(-8.0, "down"));
    // Bilinear against nearest on a magnified texture: thousands of pixels, subtly (lavapipe
    // is deterministic: without the bias in the shader, not one would differ).
    let differing = up
        .pixels()
        .zip(down.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > 1000,
        "the sampler's bias reached the shader's samples: {differing} pixels differ"
    );
    crate::golden::within("bias -8: nearest, as the program drew", &down, &reference()).unwrap();
}

/// A sampler's custom border colour comes in from its create info's chain
/// (`VkSamplerCustomBorderColorCreateInfoEXT`), as the border's type reads it.
#[test]
fn custom_border_colours_are_imported_from_the_samplers_chain() {
    let dir = temp("custom-border");
    for (border, colour, expected) in [
        (
            "VK_BORDER_COLOR_FLOAT_CUSTOM_EXT",
            "float32",
            json!([0.25, 0.5, 0.75, 1.0]),
        ),
        (
            "VK_BORDER_COLOR_INT_CUSTOM_EXT",
            "int32",
            json!([3.0, 0.0, 7.0, 1.0]),
        ),
    ] {
        let (v, _) = import_stream(&dir, |lines| {
            lines
                .into_iter()
                .map(|l| {
                    if !l.contains("\"vkCreateSampler\"") {
                        return l;
                    }
                    let mut call: Value = serde_json::from_str(&l).unwrap();
                    let ci = &mut call["vkFunc"]["args"]["pCreateInfo"];
                    ci["borderColor"] = json!(border);
                    let mut value = json!({"float32": [0.0, 0.0, 0.0, 0.0], "int32": [0, 0, 0, 0], "uint32": [0, 0, 0, 0]});
                    value[colour] = if colour == "int32" {
                        json!([3, 0, 7, 1])
                    } else {
                        json!([0.25, 0.5, 0.75, 1.0])
                    };
                    ci["pNext"] = json!({
                        "sType": "VK_STRUCTURE_TYPE_SAMPLER_CUSTOM_BORDER_COLOR_CREATE_INFO_EXT",
                        "pNext": null,
                        "customBorderColor": value,
                        "format": "VK_FORMAT_R8G8B8A8_UNORM",
                    });
                    call.to_string()
                })
                .collect()
        });
        let s = &v["vulkan"]["samplers"][0];
        assert_eq!(s["border_color"], json!(border));
        assert_eq!(s["custom_border_color"], expected, "{border}");
    }
}

/// vkcube's JSON Lines stream, its lines edited by `change`, imported; the capture and what
/// `import` printed.
fn import_stream(dir: &Path, change: impl FnOnce(Vec<String>) -> Vec<String>) -> (Value, String) {
    let text = std::fs::read_to_string(gfxr_fixture("vkcube_f3.jsonl")).unwrap();
    let lines = change(text.lines().map(str::to_owned).collect());
    let stream = dir.join("edited.jsonl");
    std::fs::write(&stream, lines.join("\n") + "\n").unwrap();
    let capture = dir.join("edited.json");
    let said = import(&stream, &capture);
    let v = serde_json::from_str(&std::fs::read_to_string(&capture).unwrap()).unwrap();
    (v, said)
}

/// The command buffer of a line, and its function's name.
fn call_of(line: &str) -> Option<(u64, String)> {
    let v: Value = serde_json::from_str(line).ok()?;
    let f = &v["vkFunc"];
    Some((
        f["args"]["commandBuffer"].as_u64()?,
        f["name"].as_str()?.to_owned(),
    ))
}

/// A `vkCmd*` line of command buffer `cb` with `args`.
fn cmd_line(index: u64, name: &str, cb: u64, mut args: Value) -> String {
    args["commandBuffer"] = json!(cb);
    json!({"index": index, "vkFunc": {"name": name, "args": args}}).to_string()
}

fn draws(v: &Value) -> Vec<&Value> {
    v["passes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|p| p["draws"].as_array().into_iter().flatten())
        .collect()
}

/// Each `vkCmdSet*` of dynamic state before a draw reaches the draw's state in the capture.
#[test]
fn dynamic_state_calls_reach_the_draws() {
    let dir = temp("set-calls");
    let (v, _) = import_stream(&dir, |lines| {
        let mut out = Vec::new();
        for line in lines {
            if let Some((cb, name)) = call_of(&line)
                && name == "vkCmdDraw"
            {
                out.push(cmd_line(1, "vkCmdSetCullMode", cb, json!({"cullMode": 1})));
                out.push(cmd_line(
                    1,
                    "vkCmdSetDepthBias",
                    cb,
                    json!({"depthBiasConstantFactor": 2.0, "depthBiasClamp": 0.0, "depthBiasSlopeFactor": 1.5}),
                ));
                out.push(cmd_line(
                    1,
                    "vkCmdSetStencilCompareMask",
                    cb,
                    json!({"faceMask": 2, "compareMask": 15}),
                ));
                out.push(cmd_line(
                    1,
                    "vkCmdSetStencilOpEXT",
                    cb,
                    json!({"faceMask": 3, "failOp": "VK_STENCIL_OP_KEEP", "passOp": "VK_STENCIL_OP_REPLACE", "depthFailOp": "VK_STENCIL_OP_ZERO", "compareOp": "VK_COMPARE_OP_EQUAL"}),
                ));
            }
            out.push(line);
        }
        out
    });
    let draws = draws(&v);
    assert!(!draws.is_empty());
    for d in draws {
        let dynamic = &d["vulkan_state"]["dynamic"];
        assert_eq!(dynamic["cull_mode"], json!(1), "{d}");
        assert_eq!(dynamic["depth_bias"], json!([2.0, 0.0, 1.5]), "{d}");
        // The back face only: the front keeps the value it would have had (the same).
        assert_eq!(dynamic["stencil_compare_mask"], json!([15, 15]), "{d}");
        assert_eq!(
            dynamic["stencil_op"][1]["pass_op"],
            json!("VK_STENCIL_OP_REPLACE")
        );
    }
}

/// A `vkCmdSet*` the import cannot read leaves its state unknown, not at the value set
/// before: a draw whose pipeline takes that state dynamically is refused with the setter
/// named; a state the pipeline does not take, or one set again readably, changes nothing.
#[test]
fn a_dynamic_state_set_by_an_unreadable_call_refuses_the_draws_that_use_it() {
    let dir = temp("unread-state");
    let unreadable = |extra: Option<String>| {
        move |lines: Vec<String>| {
            let mut out = Vec::new();
            for line in lines {
                if let Some((cb, name)) = call_of(&line)
                    && name == "vkCmdDraw"
                {
                    // No height: the viewport cannot be read.
                    let broken = json!({"firstViewport": 0, "viewportCount": 1,
                        "pViewports": [{"x": 0.0, "y": 0.0, "width": 64.0, "minDepth": 0.0, "maxDepth": 1.0}]});
                    out.push(cmd_line(9, "vkCmdSetViewport", cb, broken));
                    out.push(cmd_line(10, "vkCmdSetDepthBias", cb, json!({})));
                    if let Some(e) = &extra {
                        out.push(e.replace("CB", &cb.to_string()));
                    }
                }
                out.push(line);
            }
            out
        }
    };
    let (v, said) = import_stream(&dir, unreadable(None));
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    for part in [
        "VK_DYNAMIC_STATE_VIEWPORT dynamically",
        "vkCmdSetViewport #9",
        "(vkCmdDraw #",
    ] {
        assert!(why.contains(part), "missing {part:?} in {why:?}");
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }
    assert!(!why.contains("DEPTH_BIAS"), "{why:?}");

    let again = json!({"firstViewport": 0, "viewportCount": 1,
        "pViewports": [{"x": 0.0, "y": 0.0, "width": 64.0, "height": 64.0, "minDepth": 0.0, "maxDepth": 1.0}]});
    let set = cmd_line(11, "vkCmdSetViewport", 0, again)
        .replace("\"commandBuffer\":0", "\"commandBuffer\":CB");
    let (v, _) = import_stream(&dir, unreadable(Some(set)));
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    assert!(!why.contains("VK_DYNAMIC_STATE"), "{why:?}");
    assert!(!draws(&v).is_empty());
    for d in draws(&v) {
        assert_eq!(
            d["vulkan_state"]["viewport"],
            json!([0.0, 0.0, 64.0, 64.0, 0.0, 1.0])
        );
    }
}

/// The draws of each render pass moved into a secondary command buffer executed inside it
/// (`VK_SUBPASS_CONTENTS_SECONDARY_COMMAND_BUFFERS`): imported into the same passes, with
/// the same draws, as the program recorded them inline.
#[test]
fn secondary_command_buffers_continue_their_render_pass() {
    let dir = temp("secondary");
    let (inline, _) = import_stream(&dir, |lines| lines);
    let (nested, said) = import_stream(&dir, |lines| {
        let mut out = Vec::new();
        let mut inside = std::collections::BTreeSet::new();
        for line in lines {
            let Some((cb, name)) = call_of(&line) else {
                out.push(line);
                continue;
            };
            let secondary = cb + 1_000_000;
            match name.as_str() {
                "vkCmdBeginRenderPass" => {
                    inside.insert(cb);
                    out.push(line.replace(
                        "VK_SUBPASS_CONTENTS_INLINE",
                        "VK_SUBPASS_CONTENTS_SECONDARY_COMMAND_BUFFERS",
                    ));
                }
                "vkCmdEndRenderPass" => {
                    inside.remove(&cb);
                    out.push(cmd_line(
                        1,
                        "vkCmdExecuteCommands",
                        cb,
                        json!({"commandBufferCount": 1, "pCommandBuffers": [secondary]}),
                    ));
                    out.push(line);
                }
                _ if inside.contains(&cb) => out.push(line.replace(
                    &format!("\"commandBuffer\":{cb}"),
                    &format!("\"commandBuffer\":{secondary}"),
                )),
                _ => out.push(line),
            }
        }
        out
    });
    assert!(!said.contains("outside a render pass"), "{said}");
    let (a, b) = (draws(&inline), draws(&nested));
    assert!(!a.is_empty());
    assert_eq!(a, b, "the same draws, in the same passes");
    let names = |v: &Value| -> Vec<Value> {
        v["passes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].clone())
            .collect()
    };
    assert_eq!(names(&inline), names(&nested));
}

/// `vkCmdDrawIndirectCount` (and its indexed, KHR and AMD names) becomes an indirect draw whose
/// count the GPU reads: the arguments' buffer and offset, the count's buffer and offset and the
/// most records, each buffer by its name; its records must lie packed, as wgpu reads them
/// (records any other distance apart refuse the frame, naming the call and pass; with one
/// record the distance is never used). Here vkcube's draws replaced by such a call over its
/// first uniform buffer.
#[test]
fn draw_counts_read_on_the_gpu_are_imported_as_counted_indirect_draws() {
    let dir = temp("draw-count");
    let counted = |max: u64, stride: u64| {
        move |lines: Vec<String>| -> Vec<String> {
            lines
                .into_iter()
                .map(|line| match call_of(&line) {
                    Some((cb, name)) if name == "vkCmdDraw" => cmd_line(
                        7,
                        "vkCmdDrawIndirectCountKHR",
                        cb,
                        json!({"buffer": 28, "offset": 64, "countBuffer": 28,
                               "countBufferOffset": 4, "maxDrawCount": max, "stride": stride}),
                    ),
                    _ => line,
                })
                .collect()
        }
    };
    // (A JSON Lines stream never replays: it holds no shader code. Nothing more is said.)
    let refused = |v: &Value| {
        v["source"]["not_replayable"]
            .as_str()
            .unwrap_or_default()
            .contains("vkCmdDrawIndirectCount")
    };
    let (v, said) = import_stream(&dir, counted(3, 16));
    assert!(!refused(&v), "{said}");
    let d = draws(&v);
    assert_eq!(d.len(), 1, "the frame's one draw");
    let buffer = d[0]["indirect"]["buffer"].clone();
    assert!(buffer.is_string(), "{}", d[0]);
    assert_eq!(
        d[0]["indirect"],
        json!({"buffer": buffer, "offset": 64,
               "count": {"buffer": buffer, "offset": 4, "max_draws": 3}})
    );
    // One record: its distance from the next is never used.
    let (v, said) = import_stream(&dir, counted(1, 40));
    assert!(!refused(&v), "{said}");
    let (v, said) = import_stream(&dir, counted(2, 32));
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    for part in [
        "an indirect draw count over records 32 bytes apart (wgpu reads them packed, 16 bytes each)",
        "vkCmdDrawIndirectCountKHR #7",
        "pass \"render_pass\"",
    ] {
        assert!(why.contains(part), "missing {part:?} in {why:?}");
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }
}

/// Work the replay cannot reproduce, met in an imported frame, makes the frame refuse to
/// replay with the command and the pass named: here a vertex count from transform feedback,
/// a clear of attachment layers beyond the first, and draws recorded outside any render pass.
#[test]
fn work_the_replay_cannot_do_is_refused_with_its_pass() {
    let dir = temp("refused");
    let (v, said) = import_stream(&dir, |lines| {
        let mut out = Vec::new();
        for line in lines {
            let call = call_of(&line);
            out.push(line);
            if let Some((cb, name)) = call
                && name == "vkCmdBeginRenderPass"
            {
                out.push(cmd_line(7, "vkCmdDrawIndirectByteCountEXT", cb, json!({})));
                out.push(cmd_line(
                    8,
                    "vkCmdClearAttachments",
                    cb,
                    clear_args(
                        &[(1, 0)],
                        json!([{"rect": rect(0, 0, 8, 8), "baseArrayLayer": 1, "layerCount": 1}]),
                    ),
                ));
            }
        }
        out
    });
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    for part in [
        "vkCmdDrawIndirectByteCountEXT",
        "transform feedback: wgpu has none",
        "vkCmdDrawIndirectByteCountEXT #7",
        "pass \"render_pass\"",
        "vkCmdClearAttachments: clears of layers other than the first",
        "vkCmdClearAttachments #8",
    ] {
        assert!(why.contains(part), "missing {part:?} in {why:?}");
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }

    let (v, _) = import_stream(&dir, |lines| {
        lines
            .into_iter()
            .filter(|l| {
                !call_of(l)
                    .is_some_and(|(_, n)| n == "vkCmdBeginRenderPass" || n == "vkCmdEndRenderPass")
            })
            .collect()
    });
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    assert!(
        why.contains("draws outside a render pass instance (vkCmdDraw #"),
        "{why:?}"
    );
}

fn rect(x: i64, y: i64, w: u64, h: u64) -> Value {
    json!({"offset": {"x": x, "y": y}, "extent": {"width": w, "height": h}})
}

/// `vkCmdClearAttachments` arguments: (aspect mask, colour attachment) pairs, each cleared to
/// a value of its own, and the rectangles.
fn clear_args(attachments: &[(u64, u64)], rects: Value) -> Value {
    let list: Vec<Value> = attachments
        .iter()
        .enumerate()
        .map(|(k, &(aspects, slot))| {
            let f = 0.25 * k as f64;
            json!({
                "aspectMask": aspects,
                "colorAttachment": slot,
                "clearValue": {
                    "color": {"float32": [1.0, f, 0.0, 1.0], "int32": [0, 0, 0, 0], "uint32": [0, 0, 0, 0]},
                    "depthStencil": {"depth": 0.5, "stencil": 3},
                },
            })
        })
        .collect();
    json!({
        "attachmentCount": list.len(),
        "pAttachments": list,
        "rectCount": rects.as_array().map_or(0, Vec::len),
        "pRects": rects,
    })
}

/// A `vkCmdClearAttachments` between vkcube's draws reaches its pass: the colour attachment
/// by the pass's own index, the depth value (vkcube's depth format has no stencil, so the
/// stencil aspect is dropped), each rectangle, and the draw it comes before.
#[test]
fn attachment_clears_reach_their_pass() {
    let dir = temp("clear-import");
    let (v, said) = import_stream(&dir, |lines| {
        let mut out = Vec::new();
        for line in lines {
            let call = call_of(&line);
            if let Some((cb, name)) = &call
                && name == "vkCmdEndRenderPass"
            {
                out.push(cmd_line(
                    9,
                    "vkCmdClearAttachments",
                    *cb,
                    clear_args(
                        &[(1, 0), (2 | 4, 0)],
                        json!([{"rect": rect(4, 8, 16, 32), "baseArrayLayer": 0, "layerCount": 1}]),
                    ),
                ));
            }
            out.push(line);
        }
        out
    });
    // The stream holds no shader code, which is all that keeps it from replaying.
    let why = v["source"]["not_replayable"].as_str().unwrap_or_default();
    assert!(!why.contains("Clear"), "{why}\n{said}");
    let pass = v["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["attachment_clears"].is_array())
        .expect("a pass with the clear");
    let draws = pass["draws"].as_array().unwrap().len();
    assert_eq!(
        pass["attachment_clears"],
        json!([{
            "before_draw": draws,
            "colors": [{"attachment": 0, "value": [1.0, 0.0, 0.0, 1.0]}],
            "depth": 0.5,
            "rects": [[4, 8, 16, 32]],
        }])
    );
}

/// vkcube's pass with a rectangle cleared to red across the cube's left edge: after the
/// cube's draw the whole rectangle is red; before it, the cube covers the red where it lies;
/// before it with the depth cleared to 0 as well, the cube fails its depth test there and the
/// rectangle stays red, and so it does with the depth attachment in a read-only layout.
/// Outside the rectangle the image is vkcube's own. A clear of an
/// attachment the pass lacks is refused before anything is replayed.
#[test]
fn attachment_clears_are_drawn_between_the_draws() {
    let dir = temp("clear-rects");
    let capture = vkcube(&dir);
    let reference = reference();
    let [x0, y0, w, h] = [40u32, 200, 200, 100];
    let set = |before: u32, depth: Option<f32>, attachment: u32| {
        edit(&capture, |v| {
            let pass = v["passes"]
                .as_array_mut()
                .unwrap()
                .iter_mut()
                .find(|p| p["draws"].as_array().is_some_and(|d| !d.is_empty()))
                .unwrap();
            pass["attachment_clears"] = json!([{
                "before_draw": before,
                "colors": [{"attachment": attachment, "value": [1.0, 0.0, 0.0, 1.0]}],
                "depth": depth,
                "rects": [[x0, y0, w, h]],
            }]);
        });
    };
    let near = |a: &image::Rgba<u8>, b: [u8; 3]| (0..3).all(|c| a[c].abs_diff(b[c]) <= 3);
    let rgb = |p: &image::Rgba<u8>| [p[0], p[1], p[2]];
    let inside = |x: u32, y: u32| (x0..x0 + w).contains(&x) && (y0..y0 + h).contains(&y);
    let check = |name: &str, expect_red: &dyn Fn(u32, u32) -> bool| {
        let image = crate::common::replay_presented(&capture, &dir.join(name));
        let mut wrong = 0u32;
        for (x, y, p) in image.enumerate_pixels() {
            let want = if inside(x, y) && expect_red(x, y) {
                [255, 0, 0]
            } else {
                rgb(reference.get_pixel(x, y))
            };
            if !near(p, want) {
                wrong += 1;
            }
        }
        // Edges of the cube rasterised a little differently from the reference's driver.
        assert!(
            wrong < 200,
            "{name}: {wrong} pixels are not what the clear makes"
        );
    };
    // Where the reference shows vkcube's grey background, not the cube.
    let background = |x: u32, y: u32| near(reference.get_pixel(x, y), [51, 51, 51]);
    assert!((x0..x0 + w).any(|x| background(x, y0)) && (x0..x0 + w).any(|x| !background(x, y0)));

    set(1, None, 0);
    check("after", &|_, _| true);
    set(0, None, 0);
    check("before", &|x, y| background(x, y));
    set(0, Some(0.0), 0);
    check("before-depth", &|_, _| true);
    // The depth attachment in a read-only layout, cleared anyway (zink clears OpenArena's
    // depth under its 3D HUD icons so): writable for the pass, the same image.
    edit(&capture, |v| {
        let passes = v["passes"].as_array_mut().unwrap();
        let pass = passes
            .iter_mut()
            .find(|p| p["attachment_clears"].is_array());
        pass.unwrap()["depth_stencil"]["read_only"] = json!(true);
    });
    check("read-only-depth", &|_, _| true);

    set(1, None, 3);
    let err = replay_fails(&capture);
    assert!(
        err.contains("colour attachment 3 of a pass with 1"),
        "{err}"
    );
}

/// Every member of every class the registry names has a row in the coverage table, and
/// `docs/coverage.md` is the table as `coverage::markdown` writes it.
#[test]
fn the_coverage_table_covers_the_registry() {
    use framelab_core::coverage;
    for class in &coverage::CLASSES {
        let members = coverage::registry_members(class);
        assert!(
            members.len() >= 4,
            "{}: the registry has its members",
            class.title
        );
        let missing: Vec<&str> = members
            .iter()
            .copied()
            .filter(|m| (class.verdict)(m).is_none())
            .collect();
        assert!(
            missing.is_empty(),
            "{}: no row for {missing:?}",
            class.title
        );
    }
    for page in ["README.md", "docs/importing.md"] {
        let text = std::fs::read_to_string(crate::common::repo().join(page)).unwrap();
        assert!(
            text.contains(&coverage::summary()),
            "{page}: the coverage summary is out of date; it is:\n{}",
            coverage::summary()
        );
    }
    let doc = std::fs::read_to_string(crate::common::repo().join("docs/coverage.md")).unwrap();
    let table = coverage::markdown();
    assert!(
        doc.contains(&table),
        "docs/coverage.md is out of date: regenerate it with `framelab coverage > docs/coverage.md`"
    );
}

/// A uniform buffer bound at an offset the program's device allowed (16-byte steps) and
/// wgpu's alignment does not: vkcube's matrices moved 48 bytes into their buffer behind bytes
/// that would draw nothing, and the descriptor's offset moved with them. The replay copies
/// the range into a buffer of its own and draws the program's image. (The new contents are
/// a file of the buffer's own, as captures written before contents shared one file had.)
#[test]
fn buffers_bound_below_wgpu_alignment_are_rebased() {
    let dir = temp("rebased");
    let capture = vkcube(&dir);
    let frame: Value = serde_json::from_str(&std::fs::read_to_string(&capture).unwrap()).unwrap();
    let buffer = frame["resources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "buffer_28")
        .unwrap();
    let (file, offset, size) = (
        buffer["initial"]["file"]["path"].as_str().unwrap(),
        buffer["initial"]["file"]["offset"].as_u64().unwrap() as usize,
        buffer["size"].as_u64().unwrap() as usize,
    );
    let pack = std::fs::read(dir.join(file)).unwrap();
    let mut bytes: Vec<u8> = std::iter::repeat_n(1.0e9f32.to_le_bytes(), 12)
        .flatten()
        .collect();
    bytes.extend(&pack[offset..offset + size]);
    std::fs::write(dir.join("vkcube.contents/buffer_28.bin"), &bytes).unwrap();
    edit(&capture, |v| {
        for r in v["resources"].as_array_mut().unwrap() {
            if r["name"] == "buffer_28" {
                r["size"] = json!(bytes.len());
                r["initial"] = json!({"file": {"path": "vkcube.contents/buffer_28.bin"}});
            }
        }
        let (draw, _) = draw_and_state(v);
        let uniform = draw["descriptors"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .find(|d| d["descriptor_type"] == "UNIFORM_BUFFER")
            .unwrap();
        uniform["offset"] = json!(48);
    });
    let image = crate::common::replay_presented(&capture, &dir.join("out"));
    crate::golden::within("vkcube, matrices at offset 48", &image, &reference()).unwrap();
}

/// What the replay cannot do is said at import, with the pass, the draw and the class, and
/// `replay` refuses it (exit 1) before writing anything: vkcube's pipeline edited in its
/// binary capture to declare a dynamic polygon mode. Unedited, the import says it replays.
#[test]
fn the_import_says_whether_the_frame_replays() {
    let dir = temp("verdict");
    let said = import(&gfxr_fixture("vkcube_f3.gfxr"), &dir.join("plain.json"));
    assert!(said.contains("replays: yes"), "{said}");

    let edited = dir.join("edited.gfxr");
    crate::common::edited_fixture(
        "vkcube_f3.gfxr",
        &edited,
        "73:pCreateInfos[0].pDynamicState.pDynamicStates[1]=VK_DYNAMIC_STATE_POLYGON_MODE_EXT",
    );
    let capture = dir.join("edited.json");
    let said = import(&edited, &capture);
    for part in [
        "replays: no",
        "pass \"render_pass\", draw 0",
        "VK_DYNAMIC_STATE_POLYGON_MODE_EXT",
        "pipeline_40",
    ] {
        assert!(said.contains(part), "missing {part:?} in:\n{said}");
    }
    replay_fails(&capture);
}

/// vkcube's pipeline with the extended-dynamic-state-3 and vertex-input states declared
/// dynamic and set by the draw to what the pipeline had: the baked variant draws the same
/// image. Every colour channel masked off by the draw, or every sample, the cube is gone; a
/// state wgpu has no
/// twin for switched on (alpha to one), or a dynamic state the draw never set, is refused
/// naming it, the pass and the draw.
#[test]
fn extended_dynamic_state_is_baked_into_pipeline_variants() {
    let dir = temp("extended");
    let capture = vkcube(&dir);
    let same = json!({
        "vertex_input": {"bindings": [], "attributes": []},
        "polygon_mode": "VK_POLYGON_MODE_FILL",
        "depth_clamp_enable": false,
        "depth_clip_enable": true,
        "depth_clip_negative_one_to_one": false,
        "alpha_to_coverage_enable": false,
        "alpha_to_one_enable": false,
        "rasterization_samples": "VK_SAMPLE_COUNT_1_BIT",
        "sample_mask": [4294967295u32],
        "color_blend_enable": [false],
        "color_write_mask": [15],
        "logic_op_enable": false,
        "provoking_vertex_mode": "VK_PROVOKING_VERTEX_MODE_LAST_VERTEX_EXT",
        "line_rasterization_mode": "VK_LINE_RASTERIZATION_MODE_BRESENHAM_EXT",
        "line_stipple_enable": false,
        "patch_control_points": 3,
    });
    edit(&capture, |v| {
        let (draw, g) = draw_and_state(v);
        let states = g["dynamic_states"].as_array_mut().unwrap();
        for s in [
            "VERTEX_INPUT_EXT",
            "POLYGON_MODE_EXT",
            "DEPTH_CLAMP_ENABLE_EXT",
            "DEPTH_CLIP_ENABLE_EXT",
            "DEPTH_CLIP_NEGATIVE_ONE_TO_ONE_EXT",
            "ALPHA_TO_COVERAGE_ENABLE_EXT",
            "ALPHA_TO_ONE_ENABLE_EXT",
            "RASTERIZATION_SAMPLES_EXT",
            "SAMPLE_MASK_EXT",
            "COLOR_BLEND_ENABLE_EXT",
            "COLOR_WRITE_MASK_EXT",
            "LOGIC_OP_ENABLE_EXT",
            "PROVOKING_VERTEX_MODE_EXT",
            "LINE_RASTERIZATION_MODE_EXT",
            "LINE_STIPPLE_ENABLE_EXT",
            "LINE_STIPPLE_EXT",
            "PATCH_CONTROL_POINTS_EXT",
        ] {
            states.push(json!(format!("VK_DYNAMIC_STATE_{s}")));
        }
        // The pipeline's own values say otherwise: only the draw's count.
        g["polygon_mode"] = json!("VK_POLYGON_MODE_LINE");
        g["blend"][0]["write_mask"] = json!(0);
        draw["dynamic"] = json!({"extended": same.clone()});
    });
    let image = crate::common::replay_presented(&capture, &dir.join("same"));
    crate::golden::within("vkcube with extended dynamic state", &image, &reference()).unwrap();

    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"]["extended"]["color_write_mask"] = json!([0]);
    });
    let image = crate::common::replay_presented(&capture, &dir.join("masked"));
    assert!(
        crate::golden::within("vkcube masked off", &image, &reference()).is_err(),
        "the draw's colour write mask reached the pipeline"
    );

    // An empty sample mask writes no sample: the cube is gone too.
    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"]["extended"] = same.clone();
        draw["dynamic"]["extended"]["sample_mask"] = json!([0]);
    });
    let image = crate::common::replay_presented(&capture, &dir.join("no-samples"));
    assert!(
        crate::golden::within("vkcube with no samples", &image, &reference()).is_err(),
        "the draw's sample mask reached the pipeline"
    );

    // Depth clipped and clamped is clipped; neither is wgpu's unclipped (clamped) depth where
    // the clamp changes nothing: vkcube's D16 attachment clamps at the test anyway.
    for (clip, clamp) in [(true, true), (false, false)] {
        edit(&capture, |v| {
            let (draw, _) = draw_and_state(v);
            draw["dynamic"]["extended"] = same.clone();
            draw["dynamic"]["extended"]["depth_clip_enable"] = json!(clip);
            draw["dynamic"]["extended"]["depth_clamp_enable"] = json!(clamp);
        });
        let image = crate::common::replay_presented(&capture, &dir.join(format!("clip-{clip}")));
        crate::golden::within("vkcube, depth clip and clamp alike", &image, &reference()).unwrap();
    }
    // Into a floating-point depth attachment, unclamped depths would stay out of range.
    let mut depth = Value::Null;
    edit(&capture, |v| {
        for r in v["resources"].as_array_mut().unwrap() {
            if r["name"] == json!("image_21") {
                depth = r.clone();
                r["format"] = json!("D32_FLOAT");
                // Twice the bytes: its own memory, and no snapshot of the D16 contents.
                let r = r.as_object_mut().unwrap();
                r.remove("placement");
                r.remove("initial");
            }
        }
    });
    let err = replay_fails(&capture);
    for part in [
        "draw 0",
        "depth clipping off with depth clamping off",
        "floating-point",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
    edit(&capture, |v| {
        for r in v["resources"].as_array_mut().unwrap() {
            if r["name"] == json!("image_21") {
                *r = depth.clone();
            }
        }
    });

    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"]["extended"] = same.clone();
        draw["dynamic"]["extended"]["alpha_to_one_enable"] = json!(true);
    });
    let err = replay_fails(&capture);
    for part in ["pass \"render_pass\"", "draw 0", "alpha to one"] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }

    edit(&capture, |v| {
        let (draw, _) = draw_and_state(v);
        draw["dynamic"]["extended"] = same.clone();
        draw["dynamic"]["extended"]
            .as_object_mut()
            .unwrap()
            .remove("polygon_mode");
    });
    let err = replay_fails(&capture);
    assert!(
        err.contains("dynamic polygon mode the draw never set"),
        "{err}"
    );
}

/// vkcube's texture view pointed at the swapchain image its pass renders to (a feedback loop;
/// Vulkan lets a subpass read its own attachment): the replay ends the render pass before the
/// draw, copies the attachment as cleared and lets the draw sample the copy, so the cube is
/// the grey clear colour, shaded, where it had been the coloured logo, and the import says
/// how the draw was replayed.
#[test]
fn a_pass_reading_its_own_attachment_reads_a_copy_taken_before_the_draw() {
    let dir = temp("feedback");
    let capture = vkcube(&dir);
    let original = crate::common::replay_presented(&capture, &dir.join("original"));
    let background = *original.get_pixel(0, 0);
    let coloured = |p: &image::Rgba<u8>| p[0] != p[1] || p[1] != p[2];
    assert!(original.pixels().filter(|p| coloured(p)).count() > 10_000);
    point_the_texture_at_the_pass_target(&capture);
    let image = crate::common::replay_presented(&capture, &dir.join("fetched"));
    let coloured = image.pixels().filter(|p| coloured(p)).count();
    assert_eq!(coloured, 0, "{coloured} pixels are not grey");
    let shaded = image.pixels().filter(|p| **p != background).count();
    assert!(shaded > 10_000, "the cube is not drawn ({shaded} pixels)");
}

/// vkcube's texture view, and the draw's descriptor, pointed at the swapchain image its pass
/// renders to.
pub(crate) fn point_the_texture_at_the_pass_target(capture: &Path) {
    edit(capture, |v| {
        let view = &mut v["vulkan"]["image_views"][0];
        view["image"] = json!("swapchain_0");
        view["format"] = json!("VK_FORMAT_B8G8R8A8_UNORM");
        let (draw, _) = draw_and_state(v);
        for d in draw["descriptors"].as_array_mut().unwrap() {
            if d["view"] == json!("view_27") {
                d["resource"] = json!("swapchain_0");
            }
        }
    });
}

/// A compressed texture's whole mip chain uploaded as a Vulkan program does it (Warzone 2100's
/// BC7 terrain pages): one copy per mip with tightly packed rows, the mips smaller than a block
/// copied with their own size (2x2, 1x1) and one row of blocks at a pitch wgpu cannot align.
/// wgpu takes whole blocks and no pitch for one row: the replay gives it that, and the frame
/// replays.
#[test]
fn compressed_mip_tails_upload_as_vulkan_copies_them() {
    let dir = temp("bc-mips");
    let capture = vkcube(&dir);
    let contents = dir.join("bc_upload.bin");
    // Four BC7 blocks for mip 0 (8x8), one each for mips 1, 2 and 3: mode 6, all one colour.
    let block: [u8; 16] = [
        0x40, 0xfe, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00,
    ];
    std::fs::write(&contents, block.repeat(7)).unwrap();
    edit(&capture, |v| {
        let resources = v["resources"].as_array_mut().unwrap();
        resources.push(json!({
            "name": "bc_page", "kind": "texture_2d", "format": "BC7_UNORM",
            "width": 8, "height": 8, "mip_levels": 4,
            "initial": {"before_capture": {}},
        }));
        resources.push(json!({
            "name": "bc_upload", "kind": "buffer", "size": 112,
            "initial": {"file": {"path": "bc_upload.bin"}},
        }));
        let queue = v["passes"][0]["queue"].clone();
        let copy = |mip: u32, offset: u64, side: u32, pitch: u32| {
            json!({
                "src": {"resource": "bc_upload", "offset": offset, "bytes_per_row": pitch},
                "dst": {"resource": "bc_page", "mip": mip},
                "extent": [side, side, 1],
            })
        };
        v["passes"].as_array_mut().unwrap().insert(
            0,
            json!({
                "name": "upload_bc_page", "queue": queue, "kind": "copy",
                "copies": [copy(0, 0, 8, 32), copy(1, 64, 4, 16), copy(2, 80, 2, 16), copy(3, 96, 1, 16)],
            }),
        );
    });
    // The replay runs every copy (a copy wgpu refused would stop it with exit 1); the page,
    // never sampled, is not decoded for export.
    let out = dir.join("out");
    crate::common::replay_presented(&capture, &out);
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert!(
        manifest["skipped"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s["resource"] == json!("bc_page")),
        "{manifest}"
    );
}

/// The one draw of vkcube's frame.
fn the_draw(v: &mut Value) -> &mut Value {
    v["passes"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["draws"].as_array().is_some_and(|d| !d.is_empty()))
        .map(|p| &mut p["draws"][0])
        .unwrap()
}

/// Triangle fans, which wgpu has none of, are drawn as an indexed list of the same
/// triangles: a fan of three vertices is the list's first triangle, pixel for pixel (and
/// not the whole cube). The provoking vertex decides only flat inputs: vkcube's fragment
/// shader has none, so with the last vertex provoking its frame is still the reference.
/// (Flat inputs from the last vertex, indexed and in strips, replay in ANGLE's frame,
/// `chromium_angle_f60`, among the real programs.)
#[test]
fn fans_and_the_last_provoking_vertex_draw_as_lists() {
    let dir = temp("fans");
    let capture = vkcube(&dir);
    let last = dir.join("last.json");
    std::fs::copy(&capture, &last).unwrap();
    edit(&last, |v| {
        let (_, g) = draw_and_state(v);
        g["provoking_vertex_last"] = json!(true);
    });
    let image = crate::common::replay_presented(&last, &dir.join("last"));
    crate::golden::within("vkcube, last vertex provoking", &image, &reference()).unwrap();

    let shape = |name: &str, topology: &str| {
        let path = dir.join(format!("{name}.json"));
        std::fs::copy(&capture, &path).unwrap();
        edit(&path, |v| {
            the_draw(v)["count"] = json!(3);
            let (_, g) = draw_and_state(v);
            g["topology"] = json!(topology);
        });
        crate::common::replay_presented(&path, &dir.join(name))
    };
    let list = shape("list", "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST");
    let fan = shape("fan", "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_FAN");
    assert!(
        list == fan,
        "a fan of three vertices draws the list's triangle"
    );
    assert!(list != image, "one triangle is not the cube");
}

/// A view's component swizzle, which wgpu's views lack, is applied to every texel the shader
/// reads through it: vkcube's texture viewed `RGBA` (the identity said out loud) draws the
/// reference, `0001` a black cube, and `BGRA` the reference with red and blue exchanged,
/// pixel for pixel (vkcube lights its texture by a scalar, and its background is grey).
#[test]
fn view_swizzles_are_applied_where_the_shader_reads() {
    let dir = temp("swizzled");
    let capture = vkcube(&dir);
    let swizzled = |name: &str, swizzle: &str| {
        let path = dir.join(format!("{name}.json"));
        std::fs::copy(&capture, &path).unwrap();
        edit(&path, |v| {
            v["vulkan"]["image_views"][0]["swizzle"] = json!(swizzle);
        });
        crate::common::replay_presented(&path, &dir.join(name))
    };
    let plain = crate::common::replay_presented(&capture, &dir.join("plain"));
    assert!(
        swizzled("identity", "RGBA") == plain,
        "the identity changes nothing"
    );
    let black = swizzled("black", "0001");
    let changed: Vec<_> = black
        .pixels()
        .zip(plain.pixels())
        .filter(|(b, p)| b != p)
        .collect();
    assert!(changed.len() > 10_000, "the cube is drawn through the view");
    assert!(
        changed.iter().all(|(b, _)| b.0[..3] == [0, 0, 0]),
        "what the view gives is black"
    );
    let swapped = swizzled("swapped", "BGRA");
    assert!(swapped != plain);
    for (s, p) in swapped.pixels().zip(plain.pixels()) {
        assert_eq!([s.0[0], s.0[1], s.0[2]], [p.0[2], p.0[1], p.0[0]]);
    }
    // A swizzle that is not four of R, G, B, A, 0 and 1 does not validate.
    edit(&capture, |v| {
        v["vulkan"]["image_views"][0]["swizzle"] = json!("RRX");
    });
    let err = replay_fails(&capture);
    assert!(err.contains("image_views[0].swizzle"), "{err}");
}

/// Anisotropic filtering with nearest filters, whose scheme Vulkan leaves to the
/// implementation, is replayed with every filter linear (wgpu's only anisotropic sampler,
/// and what lavapipe does: vkmark's texture scene is pixel-identical so), said in a note:
/// vkcube's nearest sampler made anisotropic draws what the same sampler made linear and
/// anisotropic draws, and not what the plain nearest sampler draws.
#[test]
fn anisotropy_with_nearest_filters_is_linear_and_said() {
    let dir = temp("anisotropy");
    let capture = vkcube(&dir);
    let sampled = |name: &str, filter: &str| {
        let path = dir.join(format!("{name}.json"));
        std::fs::copy(&capture, &path).unwrap();
        edit(&path, |v| {
            let s = &mut v["vulkan"]["samplers"][0];
            s["max_anisotropy"] = json!(16.0);
            s["mag_filter"] = json!(format!("VK_FILTER_{filter}"));
            s["min_filter"] = json!(format!("VK_FILTER_{filter}"));
            s["mipmap_mode"] = json!(format!("VK_SAMPLER_MIPMAP_MODE_{filter}"));
        });
        let out = dir.join(name);
        let (_, notes) = crate::common::replay_export(&path, &out);
        (
            crate::common::replay_presented(&path, &dir.join(format!("{name}2"))),
            notes,
        )
    };
    let (nearest, notes) = sampled("nearest", "NEAREST");
    assert!(
        notes.contains("anisotropic filtering with a nearest filter"),
        "{notes}"
    );
    let (linear, notes) = sampled("linear", "LINEAR");
    assert!(!notes.contains("anisotropic filtering with a nearest filter"));
    assert!(
        nearest == linear,
        "nearest and anisotropic is linear and anisotropic"
    );
    let plain = crate::common::replay_presented(&capture, &dir.join("plain"));
    assert!(nearest != plain, "the filter changed");
}

/// A SPIR-V capability the device wgpu makes does not have is refused by name, with the
/// shader and the Vulkan feature it needs, before the driver sees the module: vkcube's
/// fragment shader edited to declare `SparseResidency` (shaderResourceResidency, which wgpu
/// never turns on; naga refuses the module, so it would go to the driver as it is).
#[test]
fn a_capability_wgpu_does_not_turn_on_is_refused_by_name() {
    let dir = temp("capability");
    let capture = vkcube(&dir);
    let module = dir.join("vkcube.shaders/module_38.spv");
    let mut words: Vec<u32> = std::fs::read(&module)
        .unwrap()
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    // After the header, the first instruction is `OpCapability Shader`: `SparseResidency`
    // (41) after it.
    assert_eq!(words[5], 0x0002_0011, "OpCapability first");
    words.splice(7..7, [0x0002_0011, 41]);
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(&module, &bytes).unwrap();
    edit(&capture, |v| {
        v["vulkan"]["shader_modules"][1]["size"] = json!(bytes.len());
    });
    let err = replay_fails(&capture);
    for part in [
        "SPIR-V capability SparseResidency",
        "module_38",
        "shaderResourceResidency",
        "draw 0",
    ] {
        assert!(err.contains(part), "missing {part:?} in:\n{err}");
    }
}

/// A format wgpu has only in another channel order (`A2R10G10B10`, ReShade's `RGB10A2` as
/// vkBasalt makes it) is held in wgpu's (`Rgb10a2Unorm`) with red and blue exchanged on the
/// way in: a texel the capture wrote red reads red. A copy between such a texture and a
/// buffer, or a texture held as its format says (`A2B10G10R10`, the same wgpu format), would
/// move bytes laid out otherwise: refused with the copy and the texture named.
#[test]
fn formats_held_in_another_channel_order_read_as_the_capture_wrote_them() {
    let dir = temp("a2r10");
    let capture = vkcube(&dir);
    // Texel 0 red, texel 1 blue, both opaque: A in bits 30-31, R in 20-29, B in 0-9.
    let red: u32 = 3 << 30 | 1023 << 20;
    let blue: u32 = 3 << 30 | 1023;
    let bytes: Vec<u8> = [red, blue].iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(dir.join("a2r10.bin"), &bytes).unwrap();
    std::fs::write(dir.join("upload.bin"), &bytes).unwrap();
    edit(&capture, |v| {
        v["resources"].as_array_mut().unwrap().extend([
            json!({
                "name": "a2r10_page", "kind": "texture_2d",
                "format": "VK_FORMAT_A2R10G10B10_UNORM_PACK32",
                "width": 2, "height": 1,
                "initial": {"file": {"path": "a2r10.bin"}},
            }),
            json!({
                "name": "upload", "kind": "buffer", "size": 8,
                "initial": {"file": {"path": "upload.bin"}},
            }),
            json!({
                "name": "a2b10_page", "kind": "texture_2d",
                "format": "VK_FORMAT_A2B10G10R10_UNORM_PACK32",
                "width": 2, "height": 1,
                "initial": {"file": {"path": "a2r10.bin"}},
            }),
        ]);
    });
    let out = dir.join("out");
    let (manifest, _) = crate::common::replay_export(&capture, &out);
    let file = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["resource"] == json!("a2r10_page"))
        .unwrap_or_else(|| panic!("a2r10_page not exported: {manifest}"))["file"]
        .as_str()
        .unwrap()
        .to_owned();
    let page = image::open(out.join(file)).unwrap().to_rgba8();
    assert_eq!(page.get_pixel(0, 0).0, [255, 0, 0, 255]);
    assert_eq!(page.get_pixel(1, 0).0, [0, 0, 255, 255]);

    for (src, dst, pitch) in [
        ("upload", "a2r10_page", Some(256)),
        ("a2r10_page", "a2b10_page", None),
    ] {
        let copied = dir.join(format!("{src}-{dst}.json"));
        std::fs::copy(&capture, &copied).unwrap();
        edit(&copied, |v| {
            let queue = v["passes"][0]["queue"].clone();
            let mut from = json!({"resource": src});
            if let Some(pitch) = pitch {
                from["offset"] = json!(0);
                from["bytes_per_row"] = json!(pitch);
            }
            v["passes"].as_array_mut().unwrap().insert(
                0,
                json!({
                    "name": "copy_page", "queue": queue, "kind": "copy",
                    "copies": [{"src": from, "dst": {"resource": dst}, "extent": [2, 1, 1]}],
                }),
            );
        });
        let err = replay_fails(&copied);
        for part in [
            "copy_page",
            "copy 0: \"a2r10_page\" (VK_FORMAT_A2R10G10B10_UNORM_PACK32)",
            "red and blue exchanged",
        ] {
            assert!(
                err.contains(part),
                "{src} -> {dst}: missing {part:?} in:\n{err}"
            );
        }
    }
}

/// A framebuffer of two layers (layered rendering: a shader's `gl_Layer` picks the layer each
/// primitive goes to) is refused at import with the count and the pass, since the replay
/// renders one layer of each attachment; with one layer the same frame is not.
#[test]
fn layered_rendering_is_refused_at_import() {
    let dir = temp("layered");
    let layered = |layers: u32| {
        let (v, _) = import_stream(&dir, |lines| {
            lines
                .into_iter()
                .map(|l| {
                    if l.contains("\"vkCreateFramebuffer\"") {
                        l.replace("\"layers\":1", &format!("\"layers\":{layers}"))
                    } else {
                        l
                    }
                })
                .collect()
        });
        v["source"]["not_replayable"]
            .as_str()
            .unwrap_or("")
            .to_owned()
    };
    let why = layered(2);
    for part in ["layered rendering (2 framebuffer layers", "render_pass"] {
        assert!(why.contains(part), "missing {part:?} in: {why}");
    }
    assert!(!layered(1).contains("layered"), "{}", layered(1));
}

/// A buffer copy of bytes that are not whole 4-byte words (vkd3d's triangle's vertex upload,
/// a `host_write` pass, edited to copy 82 of its 84 bytes): Vulkan copies bytes, WebGPU words,
/// so the replay refuses it with its pass and copy named, exit 1 and nothing written, where
/// wgpu's validation would otherwise stop it mid-frame.
#[test]
fn buffer_copies_of_partial_words_are_refused_with_their_pass() {
    let dir = temp("unaligned-copy");
    let capture = dir.join("triangle.json");
    import(&gfxr_fixture("vkd3d_triangle_f1.gfxr"), &capture);
    let mut pass = String::new();
    edit(&capture, |v| {
        let p = v["passes"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .find(|p| p["name"].as_str().unwrap_or("").starts_with("host_write"))
            .expect("vkd3d uploads its vertices from the host");
        pass = p["name"].as_str().unwrap().to_owned();
        for end in ["src", "dst"] {
            p["copies"][0][end]["size"] = json!(82);
        }
    });
    let err = replay_fails(&capture);
    assert!(
        err.contains(&format!("pass \"{pass}\""))
            && err.contains("copy 0: 82 bytes")
            && err.contains("not whole 4-byte words"),
        "{err}"
    );
}

/// A frame that reads what the capture holds no contents for before it writes it is said to,
/// at import (in its replay verdict) and by each replay (a note naming the resource and the
/// pass): the planted write-after-read stream's `buffer_53` is copied from before the frame
/// writes it, and its contents from earlier frames are not in the capture, so it starts
/// cleared. A frame whose reads all follow its writes or the capture's contents says nothing.
#[test]
fn reads_of_contents_the_capture_lacks_are_named() {
    let dir = temp("unknown-reads");
    let capture = dir.join("war.json");
    let said = import(&gfxr_fixture("write_after_read.gfxr"), &capture);
    assert!(
        said.contains("replays: yes")
            && said.contains("but 1 resource it reads before writing starts cleared")
            && said.contains("first \"buffer_53\", read by pass \"copy_buffer 2\""),
        "{said}"
    );
    let (_, said) = crate::common::replay_export(&capture, &dir.join("out"));
    assert!(
        said.contains(
            "note: \"buffer_53\" is read by pass \"copy_buffer 2\" before the frame writes it"
        ),
        "{said}"
    );
    let cube = import(&gfxr_fixture("vkcube_f3.gfxr"), &dir.join("cube.json"));
    assert!(
        !cube.contains("start cleared") && !cube.contains("starts cleared"),
        "{cube}"
    );
}

/// A draw that rasterizes nothing (cull mode `FRONT_AND_BACK` on triangles, or the rasterizer
/// discarding; wgpu has neither) replays as a draw of no vertices: vkcube's pipeline so edited
/// presents its clear colour alone. `FRONT_AND_BACK` culls polygons only: as a line list the
/// cube's edges are drawn.
#[test]
fn draws_that_rasterize_nothing_replay_as_no_vertices() {
    let dir = temp("nothing");
    let presented = |name: &str, change: &dyn Fn(&mut Value)| -> image::RgbaImage {
        let at = dir.join(name);
        std::fs::create_dir_all(&at).unwrap();
        let capture = vkcube(&at);
        edit(&capture, |v| change(draw_and_state(v).1));
        crate::common::replay_presented(&capture, &at.join("out"))
    };
    let clear_only = |img: &image::RgbaImage| img.pixels().all(|p| p.0[..3] == [51, 51, 51]);
    assert!(!clear_only(&reference()), "vkcube draws its cube");
    assert!(clear_only(
        &presented("cull", &|g| g["cull_mode"] = json!(3))
    ));
    assert!(clear_only(&presented("discard", &|g| {
        g["rasterizer_discard"] = json!(true);
    })));
    let lines = presented("lines", &|g| {
        g["cull_mode"] = json!(3);
        g["topology"] = json!("VK_PRIMITIVE_TOPOLOGY_LINE_LIST");
    });
    assert!(!clear_only(&lines), "lines are not culled");
}

/// Null descriptors (VK_EXT_robustness2's nullDescriptor: `VK_NULL_HANDLE` written where a
/// resource goes): vkcube's stream with its texture's view and its uniform buffer written
/// null imports descriptors of their type with no resource (the sampler kept), where before
/// the write left the slot as it was. Replayed, a blank stands in, said in a note: with the
/// texture null every face reads zero (black) on the program's own background; with the
/// uniform buffer null every vertex sits at the origin and only the clear is left. A null image
/// read through a comparing sampler is refused by name.
#[test]
fn null_descriptors_read_zero_through_blank_stand_ins() {
    let dir = temp("null");
    let (v, _) = import_stream(&dir, |lines| {
        lines
            .into_iter()
            .map(|l| {
                if l.contains("vkUpdateDescriptorSets") {
                    l.replace("\"imageView\":27", "\"imageView\":0")
                        .replace("\"buffer\":28", "\"buffer\":0")
                } else {
                    l
                }
            })
            .collect()
    });
    let draw = draws(&v)[0].clone();
    let descriptors = draw["vulkan_state"]["descriptors"].as_array().unwrap();
    assert_eq!(
        descriptors,
        &vec![
            json!({"set": 0, "binding": 0, "element": 0, "descriptor_type": "UNIFORM_BUFFER"}),
            json!({"set": 0, "binding": 1, "element": 0, "descriptor_type": "COMBINED_IMAGE_SAMPLER", "sampler": "sampler_26"}),
        ]
    );

    let capture = vkcube(&dir);
    let reference = reference();
    let background = *reference.get_pixel(0, 0);
    let null_at = |capture: &Path, binding: usize| {
        edit(capture, |v| {
            let (state, _) = draw_and_state(v);
            let d = state["descriptors"][binding].as_object_mut().unwrap();
            d.remove("resource");
            d.remove("view");
        })
    };
    null_at(&capture, 1);
    let out = dir.join("texture");
    let (m, said) = crate::common::replay_export(&capture, &out);
    let note =
        "set 0 binding 1 element 0 is empty in the captured descriptor set; a blank 1x1 image";
    assert!(said.contains(note), "missing {note:?} in:\n{said}");
    let file = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["presented"] == json!(true))
        .and_then(|f| f["file"].as_str())
        .unwrap();
    let image = image::open(out.join(file)).unwrap().to_rgba8();
    let (mut cube, mut black) = (0, 0);
    for (ours, theirs) in image.pixels().zip(reference.pixels()) {
        if *theirs == background {
            assert_eq!(
                ours.0[..3],
                background.0[..3],
                "the background is the program's"
            );
        } else {
            cube += 1;
            black += usize::from(ours.0[..3] == [0, 0, 0]);
        }
    }
    assert!(cube > 10_000, "the cube covers {cube} pixels");
    // Edge pixels blend the background in.
    assert!(
        black * 100 > cube * 95,
        "{black} of {cube} cube pixels black"
    );

    let bare = dir.join("bare.json");
    std::fs::copy(&capture, &bare).unwrap();
    null_at(&bare, 0);
    let image = crate::common::replay_presented(&bare, &dir.join("bare"));
    assert!(
        image.pixels().all(|p| p.0[..3] == background.0[..3]),
        "with no transforms nothing is drawn but the clear"
    );

    edit(&capture, |v| {
        v["vulkan"]["samplers"][0]["compare_op"] = json!("VK_COMPARE_OP_LESS");
    });
    let err = replay_fails(&capture);
    let refusal = "a null depth-compared image descriptor (set 0 binding 1 element 0";
    assert!(err.contains(refusal), "missing {refusal:?} in:\n{err}");
}

/// Clear colours are read through the format of what they clear, as the union member the
/// program filled for it: vkcube's stream with its swapchain made `R8G8B8A8_UINT` and its
/// texture `R8G8B8A8_SINT`, a `vkCmdClearAttachments` of the colour attachment and a
/// `vkCmdClearColorImage` of the texture added, each value's members disagreeing: the
/// attachment clear holds the `uint32` words, the image clear the `int32` ones.
#[test]
fn integer_clear_values_are_read_as_integers() {
    let dir = temp("integer-clears");
    let color =
        |f: [f64; 4], i: [i64; 4], u: [u64; 4]| json!({"float32": f, "int32": i, "uint32": u});
    let (v, said) = import_stream(&dir, |lines| {
        let mut out = Vec::new();
        for line in lines {
            let line = line
                .replace("VK_FORMAT_B8G8R8A8_UNORM", "VK_FORMAT_R8G8B8A8_UINT")
                .replace("VK_FORMAT_R8G8B8A8_UNORM", "VK_FORMAT_R8G8B8A8_SINT");
            match call_of(&line) {
                Some((cb, name)) if name == "vkCmdEndRenderPass" => {
                    let mut args = clear_args(
                        &[(1, 0)],
                        json!([{"rect": rect(0, 0, 8, 8), "baseArrayLayer": 0, "layerCount": 1}]),
                    );
                    args["pAttachments"][0]["clearValue"]["color"] =
                        color([1.0, 0.25, 0.0, 1.0], [0; 4], [7, 8, 9, 255]);
                    out.push(cmd_line(9, "vkCmdClearAttachments", cb, args));
                }
                Some((cb, name)) if name == "vkCmdBeginRenderPass" => {
                    let range = json!({"aspectMask": 1, "baseMipLevel": 0, "levelCount": 1, "baseArrayLayer": 0, "layerCount": 1});
                    out.push(cmd_line(
                        9,
                        "vkCmdClearColorImage",
                        cb,
                        json!({
                            "image": 24,
                            "imageLayout": "VK_IMAGE_LAYOUT_GENERAL",
                            "pColor": color([0.5; 4], [-3, 4, 5, 6], [4_294_967_293, 4, 5, 6]),
                            "rangeCount": 1,
                            "pRanges": [range],
                        }),
                    ));
                }
                _ => {}
            }
            out.push(line);
        }
        out
    });
    let passes = v["passes"].as_array().unwrap();
    let attachment = passes
        .iter()
        .find_map(|p| p["attachment_clears"].as_array())
        .unwrap_or_else(|| panic!("no attachment clear in:\n{said}"));
    assert_eq!(
        attachment[0]["colors"],
        json!([{"attachment": 0, "value": [7.0, 8.0, 9.0, 255.0]}])
    );
    let image = passes
        .iter()
        .flat_map(|p| p["clears"].as_array().into_iter().flatten())
        .find(|c| c["resource"] == "image_24")
        .unwrap_or_else(|| panic!("no clear of the texture in:\n{said}"));
    assert_eq!(image["value"], json!([-3.0, 4.0, 5.0, 6.0]));
}

/// An attachment clear of an integer colour attachment writes integers: vkcube's pass, its
/// draw taken out, given a second attachment in `R8G8B8A8_UINT` (loaded as `[1, 2, 3, 4]`)
/// and a clear of a 16x16 corner of both: the integer target holds `[7, 8, 9, 255]` there
/// and its load value elsewhere, the swapchain image red there.
#[test]
fn integer_attachment_clears_write_integers() {
    let dir = temp("integer-attachment");
    let capture = vkcube(&dir);
    edit(&capture, |v| {
        v["resources"].as_array_mut().unwrap().push(json!({
            "name": "integers", "kind": "texture_2d", "format": "R8G8B8A8_UINT",
            "width": 500, "height": 500, "flags": ["ALLOW_RENDER_TARGET"],
        }));
        let pass = &mut v["passes"][0];
        pass["draws"] = json!([]);
        pass["bindings"] = json!({});
        pass["color_attachments"]
            .as_array_mut()
            .unwrap()
            .push(json!({
                "resource": "integers", "mip": 0, "layer": 0, "load": "clear", "store": "store",
                "clear": [1, 2, 3, 4],
            }));
        pass["attachment_clears"] = json!([{
            "before_draw": 0,
            "colors": [
                {"attachment": 1, "value": [7, 8, 9, 255]},
                {"attachment": 0, "value": [1, 0, 0, 1]},
            ],
            "rects": [[0, 0, 16, 16]],
        }]);
    });
    let out = dir.join("out");
    let (m, _) = crate::common::replay_export(&capture, &out);
    let file = |name: &str| {
        m["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["resource"] == name)
            .cloned()
            .unwrap()
    };
    // Integer targets are written as 16-bit PNGs spanning the data's range.
    let integers = file("integers");
    let (lo, hi) = (
        integers["min"].as_f64().unwrap(),
        integers["max"].as_f64().unwrap(),
    );
    let image = image::open(out.join(integers["file"].as_str().unwrap()))
        .unwrap()
        .to_rgba16();
    let value = |x: u32, y: u32| -> Vec<f64> {
        image.get_pixel(x, y).0[..3]
            .iter()
            .map(|&c| (lo + f64::from(c) / 65535.0 * (hi - lo)).round())
            .collect()
    };
    assert_eq!(value(0, 0), [7.0, 8.0, 9.0]);
    assert_eq!(value(15, 15), [7.0, 8.0, 9.0]);
    assert_eq!(value(16, 16), [1.0, 2.0, 3.0]);
    assert_eq!(
        (lo, hi),
        (1.0, 255.0),
        "alpha 255 in the corner, 4 elsewhere"
    );
    let swapchain = image::open(out.join(file("swapchain_0")["file"].as_str().unwrap()))
        .unwrap()
        .to_rgba8();
    assert_eq!(swapchain.get_pixel(8, 8).0[..3], [255, 0, 0]);
}

/// A draw whose attributes read a vertex binding with no buffer bound (a null buffer, or
/// none ever bound) is refused naming the binding and the locations, not left to fail in the
/// driver: vkd3d's triangle with its vertex buffer taken out of the draw.
#[test]
fn a_vertex_binding_without_a_buffer_is_refused_by_name() {
    let dir = temp("no-vertex-buffer");
    let capture = dir.join("triangle.json");
    import(&gfxr_fixture("vkd3d_triangle_f1.gfxr"), &capture);
    edit(&capture, |v| {
        for p in v["passes"].as_array_mut().unwrap() {
            let draws = p.get_mut("draws").and_then(Value::as_array_mut);
            for d in draws.into_iter().flatten() {
                d["vulkan_state"]["vertex_buffers"] = json!([]);
                d.as_object_mut().unwrap().remove("vertex_buffers");
            }
        }
    });
    let err = replay_fails(&capture);
    let named = "draw 0: uses vertex binding 0 with no buffer bound (null, or never bound), which the attributes at locations [0, 1] read";
    assert!(err.contains(named), "missing {named:?} in:\n{err}");
}
