//! Frames a driver would reject, walked as classes rather than one example each: every variant
//! is an edit of the bundled example capture, validated in process, and must be refused with
//! the expected diagnostic code at the expected JSON path.

use std::path::Path;

use framelab_core::capture::load::parse;
use framelab_core::capture::validate::validate;
use framelab_core::capture::{CaptureError, Diagnostic, Options};
use serde_json::{Value, json};

use crate::common::repo;

fn example() -> Value {
    let text = std::fs::read_to_string(repo().join("captures/example/frame.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The errors `capture` gets, validated as if it were the example file (its side files resolve).
fn errors(capture: &Value) -> Vec<Diagnostic> {
    errors_as(capture, "captures/example/frame.json")
}

/// The errors `capture` gets, validated as if it were the file `at` (relative to the repository).
fn errors_as(capture: &Value, at: &str) -> Vec<Diagnostic> {
    let path = repo().join(at);
    let bytes = serde_json::to_vec(capture).unwrap();
    let raw = match parse(Path::new(&path), &bytes) {
        Ok(raw) => raw,
        Err(e) => panic!("edited capture does not parse: {e}"),
    };
    match validate(&raw, &path, &Options::default()) {
        Ok(_) => Vec::new(),
        Err(CaptureError::Invalid { diagnostics, .. }) => diagnostics
            .into_iter()
            .filter(|d| d.severity == framelab_core::capture::Severity::Error)
            .collect(),
        Err(e) => panic!("unexpected error: {e}"),
    }
}

fn has(errors: &[Diagnostic], code: &str, path: &str) -> bool {
    errors.iter().any(|d| d.code == code && d.path == path)
}

const NEAR: u32 = u32::MAX - 7;

/// Pass 4 ("scene") draws the indexed generator mesh "ground" (draw 0) and the indexed "orb"
/// through indirect arguments (draw 1); pass 5 draws a full-screen triangle without a mesh.
#[test]
fn draw_ranges_past_32_bits_are_refused() {
    // (pass, draw, fields set on the draw, path of the error)
    let direct: &[(usize, usize, Value, &str)] = &[
        // indexed: first index near 2^32 plus a count
        (4, 0, json!({"first": NEAR, "count": 96}), "count"),
        (4, 0, json!({"first": u32::MAX, "count": 1}), "count"),
        (4, 0, json!({"first": 1, "count": u32::MAX}), "count"),
        (4, 0, json!({"first": u32::MAX, "count": u32::MAX}), "count"),
        // non-indexed, no mesh: first vertex plus count
        (5, 0, json!({"first": NEAR, "count": 96}), "count"),
        (5, 0, json!({"first": u32::MAX, "count": 3}), "count"),
        (5, 0, json!({"first": 2, "count": u32::MAX}), "count"),
        // instanced: first instance plus instances, with and without a mesh
        (
            4,
            0,
            json!({"first_instance": NEAR, "instances": 16}),
            "first_instance",
        ),
        (
            4,
            0,
            json!({"first_instance": u32::MAX, "instances": 2}),
            "first_instance",
        ),
        (
            5,
            0,
            json!({"first_instance": NEAR, "instances": 16}),
            "first_instance",
        ),
        (
            5,
            0,
            json!({"first_instance": u32::MAX, "instances": 2}),
            "first_instance",
        ),
    ];
    let mut missed = Vec::new();
    for (pass, draw, fields, field) in direct {
        let mut c = example();
        let d = &mut c["passes"][*pass]["draws"][*draw];
        for (k, v) in fields.as_object().unwrap() {
            d[k] = v.clone();
        }
        let path = format!("$.passes[{pass}].draws[{draw}].{field}");
        let errs = errors(&c);
        if !has(&errs, "draw", &path) {
            missed.push(format!("{fields} on {path}: {errs:?}"));
        }
    }
    // Indirect arguments: offset plus the record's size near the u64 limit, and past the end.
    let offsets = [u64::MAX - 3, u64::MAX - 15, u64::MAX - 19, 1 << 63, !3];
    for offset in offsets {
        let mut c = example();
        c["passes"][4]["draws"][1]["indirect"]["offset"] = json!(offset);
        let path = "$.passes[4].draws[1].indirect.offset";
        let errs = errors(&c);
        if !has(&errs, "indirect", path) {
            missed.push(format!("indirect offset {offset}: {errs:?}"));
        }
    }
    assert!(missed.is_empty(), "accepted:\n{}", missed.join("\n"));
    // The unedited capture is valid, so each refusal above is the edit's.
    assert!(errors(&example()).is_empty());
}

/// Draws of a generator mesh (no counts in the capture) are held to what the generator
/// builds: for every shape, the example's ground draw (pass 4, draw 0, indexed) reading all
/// of the mesh's indices is accepted and one more is refused, and a base_vertex that moves
/// every index outside the vertices (at or past the count, or at or below minus it) is
/// refused while one just inside is accepted.
#[test]
fn draws_of_generator_meshes_stay_within_what_is_generated() {
    // (generator, params, vertices, indices), counted by hand from each shape's construction.
    let shapes = [
        ("grid", json!({"size": 2, "divisions": 4}), 25i64, 96u32),
        ("water_plate", json!({"divisions": 5}), 36, 150),
        ("terrain", json!({"resolution": 9, "octaves": 1}), 100, 486),
        ("box", json!({}), 24, 36),
        ("sphere", json!({"segments": 8, "rings": 4}), 45, 192),
        ("capsule", json!({"segments": 6}), 70, 252),
        ("foliage_cards", json!({"count": 5}), 40, 60),
        (
            "city_blocks",
            json!({"blocks_x": 2, "blocks_z": 3}),
            576,
            864,
        ),
    ];
    let draw = "$.passes[4].draws[0]";
    let mut wrong = Vec::new();
    for (name, params, vertices, indices) in shapes {
        let cases = [
            (json!({"first": 0, "count": indices}), None),
            (json!({"first": 1, "count": indices - 1}), None),
            (json!({"first": 0, "count": indices + 1}), Some("count")),
            (json!({"first": 1, "count": indices}), Some("count")),
            (json!({"first": indices}), Some("first")),
            (json!({"base_vertex": vertices - 1}), None),
            (json!({"base_vertex": 1 - vertices}), None),
            (json!({"base_vertex": vertices}), Some("base_vertex")),
            (json!({"base_vertex": -vertices}), Some("base_vertex")),
            (json!({"base_vertex": i32::MIN}), Some("base_vertex")),
        ];
        for (fields, refused) in cases {
            let mut c = example();
            c["meshes"][0]["source"]["generator"] =
                json!({"name": name, "seed": 1, "params": params});
            let d = &mut c["passes"][4]["draws"][0];
            for (k, v) in fields.as_object().unwrap() {
                d[k] = v.clone();
            }
            let errs = errors(&c);
            let ok = match refused {
                None => errs.is_empty(),
                Some(field) => has(&errs, "draw", &format!("{draw}.{field}")),
            };
            if !ok {
                wrong.push(format!(
                    "{name} {fields}: expected {refused:?}, got {errs:?}"
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every format of the DXGI table on every texture kind, bare, as a render target and as a
/// depth-stencil, against the rule D3D12 and Vulkan state:
/// - video and palette formats are no texture framelab replays;
/// - depth/stencil formats (and the typeless families holding only depth/stencil) exist on
///   1D and 2D textures (arrays, cubes) only, never 3D;
/// - block-compressed formats are 2D or 3D (a 1D texture is one texel high, never a block);
/// - ALLOW_DEPTH_STENCIL needs a depth format or its typeless family, and no 3D texture;
/// - ALLOW_RENDER_TARGET needs a format D3D12 renders to: not depth/stencil, block-compressed,
///   shared-exponent, 1-bit, packed 4:2:2, XR-bias or a depth aspect's read view.
#[test]
fn every_format_on_every_texture_kind_matches_the_rule() {
    use framelab_core::capture::dxgi::{self, Layout, Numeric};
    let text = std::fs::read_to_string(repo().join("tests/fixtures/minimal.json")).unwrap();
    let base: Value = serde_json::from_str(&text).unwrap();
    let kinds = [
        "texture_1d",
        "texture_2d",
        "texture_2d_array",
        "texture_cube",
        "texture_3d",
    ];
    let depth_typeless = [
        "R16_TYPELESS",
        "R32_TYPELESS",
        "R24G8_TYPELESS",
        "R32G8X24_TYPELESS",
    ];
    let mut wrong = Vec::new();
    for f in dxgi::all() {
        let depth_only = f.depth_bits > 0
            || f.stencil_bits > 0
            || matches!(f.name, "R24G8_TYPELESS" | "R32G8X24_TYPELESS");
        let bc = f.layout == Layout::BlockCompressed;
        let video = matches!(f.layout, Layout::Planar | Layout::Opaque)
            || f.channels.iter().any(|c| c.numeric == Numeric::Other);
        let color_target = !depth_only
            && !bc
            && !video
            && f.channels.first().map(|c| c.numeric) != Some(Numeric::SharedExp)
            && f.block_width == 1
            && f.block_height == 1
            && !matches!(f.name, "R1_UNORM" | "R10G10B10_XR_BIAS_A2_UNORM")
            // the read views of a depth/stencil family's aspects
            && !f.name.contains("_X8")
            && !f.name.starts_with('X');
        let depth_capable =
            (f.name.starts_with('D') && depth_only) || depth_typeless.contains(&f.name);
        for kind in kinds {
            for flag in [
                None,
                Some("ALLOW_RENDER_TARGET"),
                Some("ALLOW_DEPTH_STENCIL"),
            ] {
                let refused = f.name == "UNKNOWN"
                    || video
                    || (kind == "texture_3d" && depth_only)
                    || (kind == "texture_1d" && bc)
                    || (flag == Some("ALLOW_DEPTH_STENCIL")
                        && (!depth_capable || kind == "texture_3d"))
                    || (flag == Some("ALLOW_RENDER_TARGET") && !color_target);
                let mut probe = json!({
                    "name": "probe",
                    "kind": kind,
                    "format": f.name,
                    "width": 64,
                    "flags": flag.into_iter().collect::<Vec<_>>(),
                });
                match kind {
                    "texture_1d" => {}
                    "texture_3d" => {
                        probe["height"] = json!(64);
                        probe["depth"] = json!(4);
                    }
                    "texture_2d_array" => {
                        probe["height"] = json!(64);
                        probe["array_layers"] = json!(2);
                    }
                    "texture_cube" => {
                        probe["height"] = json!(64);
                        probe["array_layers"] = json!(6);
                    }
                    _ => probe["height"] = json!(64),
                }
                let mut c = base.clone();
                c["resources"].as_array_mut().unwrap().push(probe);
                let errs = errors_as(&c, "tests/fixtures/minimal.json");
                if refused == errs.is_empty() {
                    wrong.push(format!(
                        "{} {kind} {flag:?}: rule says {}, validate says {errs:?}",
                        f.name,
                        if refused { "refused" } else { "valid" }
                    ));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{}\n{} wrong",
        wrong.join("\n"),
        wrong.len()
    );
}

/// Every writable shader access to a typed buffer, with the view format taken from the buffer
/// or given on the binding, over every DXGI format of the table: a typed buffer view needs a
/// typed format a buffer can hold (not typeless, depth/stencil, block-compressed or video), and
/// a binding's format must be of the buffer format's family.
#[test]
fn typed_buffer_views_need_a_typed_format() {
    use framelab_core::capture::dxgi::{self, Layout, Numeric};
    let text = std::fs::read_to_string(repo().join("tests/fixtures/minimal.json")).unwrap();
    let base: Value = serde_json::from_str(&text).unwrap();
    // The fixture's shader variable is var<storage, read_write>, so it takes these two; the
    // view-format check runs the same way for every access of a buffer binding.
    let accesses = ["storage_read_write", "storage_write"];
    let mut wrong = Vec::new();
    for f in dxgi::all().iter().filter(|f| f.name != "UNKNOWN") {
        let holdable = |f: &dxgi::FormatInfo| {
            !f.is_typeless()
                && f.depth_bits == 0
                && f.stencil_bits == 0
                && f.layout == Layout::Linear
                && !f.channels.iter().any(|c| c.numeric == Numeric::Other)
        };
        // The view format: the buffer's own, or (for a typeless buffer) each of its family.
        let mut views: Vec<(Option<&str>, bool)> = vec![(None, holdable(f))];
        for member in dxgi::all()
            .iter()
            .filter(|m| m.typeless_family == Some(f.name))
        {
            views.push((Some(member.name), holdable(member)));
        }
        for (view, accepted) in views {
            for access in accesses {
                let mut c = base.clone();
                let d = &mut c["resources"][2];
                d["buffer_kind"] = json!("typed");
                d["format"] = json!(f.name);
                d.as_object_mut().unwrap().remove("stride");
                let b = &mut c["passes"][0]["bindings"]["particles"];
                b["access"] = json!(access);
                if let Some(v) = view {
                    b["format"] = json!(v);
                }
                let errs = errors_as(&c, "tests/fixtures/minimal.json");
                let at = "$.passes[0].bindings.particles";
                let refused = errs.iter().any(|d| d.path.starts_with(at));
                if refused == accepted {
                    wrong.push(format!(
                        "{} viewed as {view:?} for {access}: expected {}, got {errs:?}",
                        f.name,
                        if accepted { "valid" } else { "refused" }
                    ));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{}\n{} wrong",
        wrong.join("\n"),
        wrong.len()
    );
}

/// Instance ranges against the rows a mesh's per-instance streams hold: the night-city mesh
/// "buildings" has 96, drawn four at a time by pass 5.
#[test]
fn instance_ranges_past_the_mesh_rows_are_refused() {
    let at = "captures/night_city/main_street_day.json";
    let text = std::fs::read_to_string(repo().join(at)).unwrap();
    let base: Value = serde_json::from_str(&text).unwrap();
    assert!(errors_as(&base, at).is_empty());
    let cases = [
        json!({"first_instance": 93, "instances": 4}),
        json!({"first_instance": 96, "instances": 2}),
        // `instances` left at 1 draws every row of the mesh: 1..97.
        json!({"first_instance": 1, "instances": 1}),
        json!({"first_instance": NEAR, "instances": 16}),
    ];
    let mut missed = Vec::new();
    for fields in cases {
        let mut c = base.clone();
        let d = &mut c["passes"][5]["draws"][0];
        for (k, v) in fields.as_object().unwrap() {
            d[k] = v.clone();
        }
        let errs = errors_as(&c, at);
        if !has(&errs, "draw", "$.passes[5].draws[0].first_instance") {
            missed.push(format!("{fields}: {errs:?}"));
        }
    }
    assert!(missed.is_empty(), "accepted:\n{}", missed.join("\n"));
}

/// How many `view-hazard` errors `capture` gets, validated as the file `at`.
fn view_hazards(capture: &Value, at: &str) -> usize {
    errors_as(capture, at)
        .iter()
        .filter(|d| d.code == "view-hazard")
        .count()
}

/// Class: one texture subresource read through one binding and written through another in
/// one pass. Every sampled mip range of a 4-mip texture against a storage view of each mip:
/// refused exactly when the ranges share a mip.
#[test]
fn reading_and_writing_one_subresource_through_two_views_is_refused() {
    let text = std::fs::read_to_string(repo().join("tests/invalid/srv_uav_same_subresource.json"))
        .unwrap();
    let mut base: Value = serde_json::from_str(&text).unwrap();
    base["resources"][0]["mip_levels"] = json!(4);
    let mut walked = 0;
    for dst in 0..4u32 {
        for src_base in 0..4u32 {
            for src_count in 1..=(4 - src_base) {
                let mut c = base.clone();
                let b = &mut c["passes"][0]["bindings"];
                b["src"]["mips"] = json!({"base": src_base, "count": src_count});
                b["dst"]["mips"] = json!({"base": dst, "count": 1});
                let overlap = src_base <= dst && dst < src_base + src_count;
                let hazards = view_hazards(&c, "tests/invalid/srv_uav_same_subresource.json");
                assert_eq!(
                    hazards,
                    usize::from(overlap),
                    "src mips {src_base}+{src_count}, dst mip {dst}"
                );
                walked += 1;
            }
        }
    }
    assert_eq!(walked, 40);
}

/// The same class on a buffer: a storage-read range and a storage-write range of one buffer
/// in one pass, every pair of four 256-byte ranges and the whole buffer: refused exactly when
/// the bytes overlap.
#[test]
fn reading_and_writing_overlapping_buffer_bytes_through_two_views_is_refused() {
    let base = json!({
        "format_version": 1,
        "name": "buffer_view_hazard",
        "resolution": {"width": 64, "height": 64},
        "camera": {"position": [0, 2, -10], "target": [0, 0, 0], "fov_y_degrees": 60},
        "resources": [{"name": "words", "kind": "buffer", "buffer_kind": "structured", "stride": 4,
                       "size": 1024, "flags": ["ALLOW_UNORDERED_ACCESS"]}],
        "queues": [{"name": "gfx", "type": "graphics"}],
        "passes": [{"name": "bump", "queue": "gfx", "kind": "compute",
                    "shader": {"file": "buffer_view_hazard.wgsl", "compute": "cs_main"},
                    "bindings": {"src": {"resource": "words", "access": "storage_read"},
                                 "dst": {"resource": "words", "access": "storage_read_write"}},
                    "dispatches": [{"groups": [1, 1, 1]}]}]
    });
    let ranges: [Option<(u64, u64)>; 5] = [
        None,
        Some((0, 256)),
        Some((256, 256)),
        Some((512, 512)),
        Some((128, 256)),
    ];
    let span = |r: Option<(u64, u64)>| r.map_or((0, 1024), |(o, s)| (o, o + s));
    let mut walked = 0;
    for src in ranges {
        for dst in ranges {
            let mut c = base.clone();
            let b = &mut c["passes"][0]["bindings"];
            if let Some((offset, size)) = src {
                b["src"]["bytes"] = json!({"offset": offset, "size": size});
            }
            if let Some((offset, size)) = dst {
                b["dst"]["bytes"] = json!({"offset": offset, "size": size});
            }
            let (a, d) = (span(src), span(dst));
            let overlap = a.0 < d.1 && d.0 < a.1;
            let hazards = view_hazards(&c, "tests/invalid/buffer_view_hazard.json");
            assert_eq!(hazards, usize::from(overlap), "src {src:?}, dst {dst:?}");
            walked += 1;
        }
    }
    assert_eq!(walked, 25);
}

/// D3D12's support of each format, stated here apart from the table validation uses: which
/// formats can be rendered to, blended, and stored through a typed unordered-access view.
struct D3d12 {
    render_target: bool,
    blend: bool,
    typed_store: bool,
}

fn d3d12(f: &framelab_core::capture::dxgi::FormatInfo) -> D3d12 {
    use framelab_core::capture::dxgi::{Layout, Numeric};
    let numeric = f.channels.iter().find(|c| c.name != 'X').map(|c| c.numeric);
    let render_target = f.layout == Layout::Linear
        && f.depth_bits == 0
        && f.stencil_bits == 0
        && !f.channels.is_empty()
        && !matches!(
            numeric,
            Some(Numeric::Typeless | Numeric::SharedExp | Numeric::Other)
        )
        && !f.name.contains("_X8")
        && !f.name.starts_with('X')
        && !matches!(
            f.name,
            "R1_UNORM" | "R8G8_B8G8_UNORM" | "G8R8_G8B8_UNORM" | "R10G10B10_XR_BIAS_A2_UNORM"
        );
    let integer = matches!(numeric, Some(Numeric::Uint | Numeric::Sint));
    D3d12 {
        render_target,
        blend: render_target && !integer,
        typed_store: render_target && !f.srgb && !f.name.starts_with("R32G32B32_"),
    }
}

/// Class: a format used where D3D12 has no support for that use. Every typed DXGI format,
/// through every use that goes through a view of it: a clear through a render-target view
/// and through an unordered-access view (the resource's flag says which), a colour
/// attachment viewing a typeless resource as the format, the same with blending, and a
/// storage binding viewing it. Each use is refused exactly when D3D12 (or, for an attachment,
/// WebGPU, which framelab replays through) cannot do it.
#[test]
fn every_use_of_every_format_follows_d3d12_support() {
    use framelab_core::capture::dxgi;
    use framelab_core::capture::formats::not_renderable;
    let minimal: Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("tests/fixtures/minimal.json")).unwrap(),
    )
    .unwrap();
    let example = example();
    let mut wrong = Vec::new();
    let mut walked = 0;
    for f in dxgi::all().iter().filter(|f| {
        !f.is_typeless() && f.name != "UNKNOWN" && !f.is_video_or_palette() && !f.is_depth_format()
    }) {
        let support = d3d12(f);
        // Refused means a format-usage error at one of `paths` (the use, or the flag of the
        // resource it views, which no view can then pass); "*" means any error at all.
        let mut check = |what: &str, refused: bool, errs: &[Diagnostic], paths: &[&str]| {
            walked += 1;
            let got = if paths == ["*"] {
                !errs.is_empty()
            } else {
                errs.iter()
                    .any(|d| d.code == "format-usage" && paths.contains(&d.path.as_str()))
            };
            if got != refused {
                wrong.push(format!(
                    "{} {what}: expected {}, got {errs:?}",
                    f.name,
                    if refused { "refused" } else { "accepted" }
                ));
            }
        };
        // Clears: "color" in the minimal capture, cleared by pass 2.
        for (flag, supported) in [
            ("ALLOW_RENDER_TARGET", support.render_target),
            ("ALLOW_UNORDERED_ACCESS", support.typed_store),
        ] {
            let mut c = minimal.clone();
            c["resources"][0]["format"] = json!(f.name);
            c["resources"][0]["flags"] = json!([flag]);
            let errs = errors_as(&c, "tests/fixtures/minimal.json");
            check(
                &format!("cleared with {flag}"),
                !supported,
                &errs,
                &["$.resources[0].flags"],
            );
            check(
                &format!("cleared with {flag}, any error"),
                !supported,
                &errs,
                &["*"],
            );
        }
        // Views of a typeless family member: the example's "bloom" (pass 5's attachment) and
        // "ldr" (pass 7's storage binding) made the family, viewed as the member.
        let Some(family) = f.typeless_family else {
            continue;
        };
        for blend in [false, true] {
            let mut c = example.clone();
            c["resources"][7]["format"] = json!(family);
            let a = &mut c["passes"][5]["color_attachments"][0];
            a["format"] = json!(f.name);
            if blend {
                a["blend"] = json!("additive");
            }
            let errs = errors(&c);
            let at = "$.passes[5].color_attachments[0]";
            if blend {
                check(
                    "blended attachment",
                    support.render_target && !support.blend,
                    &errs,
                    &[&format!("{at}.blend")],
                );
            } else {
                check(
                    "attachment",
                    !support.render_target || not_renderable(f).is_some(),
                    &errs,
                    &[at, "$.resources[7].flags"],
                );
            }
        }
        let mut c = example.clone();
        c["resources"][8]["format"] = json!(family);
        c["passes"][7]["bindings"]["ldr"]["format"] = json!(f.name);
        let errs = errors(&c);
        check(
            "storage binding",
            !support.typed_store,
            &errs,
            &["$.passes[7].bindings.ldr.access", "$.resources[8].flags"],
        );
    }
    assert!(walked > 300, "walked only {walked} uses");
    assert!(
        wrong.is_empty(),
        "{}\n{} wrong",
        wrong.join("\n"),
        wrong.len()
    );
}
