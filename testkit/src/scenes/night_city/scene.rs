//! The procedural district and how the world is drawn: scene constants shared with the shaders
//! (`scene.wgsl`, `geometry_prep.wgsl`), the meshes, the world's draws in the base pass's order
//! with the seed's stencil values, and depth-only passes over them for other views.

use serde_json::{Value, json};

use std::collections::BTreeSet;
use std::sync::OnceLock;

use super::helpers::{object, raster, sampled, sampler, storage, with};
use framelab_core::capture::shaders::reflect;
use framelab_core::shader::{ShaderError, ValidatedShader};

/// Cars, pedestrians, holographic signs.
pub(super) const KIND_COUNTS: [u32; 3] = [768, 1024, 224];
pub(super) const CANDIDATES: u32 = KIND_COUNTS[0] + KIND_COUNTS[1] + KIND_COUNTS[2];
pub(super) const BOX_INDICES: u32 = 36;
const CAPSULE_SEGMENTS: u32 = 12;
/// Two spheres (segments x segments/2 quads) and the cylinder between them.
pub(super) const CAPSULE_INDICES: u32 =
    2 * (CAPSULE_SEGMENTS * (CAPSULE_SEGMENTS / 2) * 6) + CAPSULE_SEGMENTS * 6;
pub(super) const LIGHT_COUNT: u32 = 256;

/// Local lights by day (the street's own) and at night (every neon sign lit).
pub(super) fn light_count(day: bool) -> u32 {
    if day { LIGHT_COUNT } else { 1024 }
}
pub(super) const SHADOWED_LIGHTS: u32 = 10;
/// The debug group of the lighting and shadow passes.
pub(super) const LIGHTS: &[&str] = &["Lights and shadows"];

const FIRST_CAR: u32 = CANDIDATES;
const FIRST_PEDESTRIAN: u32 = CANDIDATES + KIND_COUNTS[0];
const FIRST_SIGN: u32 = CANDIDATES + KIND_COUNTS[0] + KIND_COUNTS[1];

/// The street grid of `city_blocks` and `city_lots`.
fn city() -> Value {
    json!({"blocks_x": 4, "blocks_z": 6, "block_size": 40, "street_width": 12,
           "min_height": 12, "max_height": 95, "buildings_per_block": 4})
}
pub(super) const BUILDINGS_PER_BLOCK: u32 = 4;
pub(super) const BUILDINGS: u32 = 4 * 6 * BUILDINGS_PER_BLOCK;

/// The source engine's structure-of-arrays vertex layout.
fn soa() -> Vec<Value> {
    vec![
        json!({"slot": 0, "attributes": [{"semantic": "POSITION0", "format": "snorm16x4", "location": 0}]}),
        json!({"slot": 1, "attributes": [{"semantic": "TEXCOORD0", "format": "float16x2", "location": 1}]}),
        json!({"slot": 2, "attributes": [
            {"semantic": "NORMAL0", "format": "packed_snorm10x3", "location": 2},
            {"semantic": "TANGENT0", "format": "packed_snorm10x3", "location": 3},
        ]}),
        json!({"slot": 3, "attributes": [
            {"semantic": "COLOR0", "format": "unorm8x4", "location": 4},
            {"semantic": "TEXCOORD1", "format": "float16x2", "location": 5},
        ]}),
    ]
}

fn mesh(name: &str, generator: &str, seed: u32, params: Value, index_format: &str) -> Value {
    json!({
        "name": name,
        "source": {"generator": {"name": generator, "seed": seed, "params": params}},
        "index_format": index_format,
        "streams": soa(),
    })
}

pub(super) fn meshes() -> Vec<Value> {
    // VB7: three float4 rows of each instance's transform.
    let rows: Vec<Value> = (0..3)
        .map(|r| json!({"semantic": format!("INSTANCE{r}"), "format": "float32x4", "location": 6 + r}))
        .collect();
    let mut streams = soa();
    streams.push(json!({"slot": 7, "step": "instance", "attributes": rows}));
    let one_per_block = with(city(), json!({"buildings_per_block": 1}));
    vec![
        // Instanced boxes, one per building lot.
        with(
            mesh("buildings", "box", 21, json!({"size": 1}), "uint16"),
            json!({"streams": streams, "instance_count": BUILDINGS,
                   "instances": {"name": "city_lots", "seed": 21, "params": city()}}),
        ),
        // One box per block: the CSM proxy's simple meshes.
        mesh("block_proxies", "city_blocks", 21, one_per_block, "uint32"),
        mesh(
            "ground",
            "grid",
            22,
            json!({"size": 1200, "divisions": 160}),
            "uint32",
        ),
        mesh(
            "terrain_chunk",
            "grid",
            23,
            json!({"size": 300, "divisions": 48}),
            "uint32",
        ),
        // A terrain chunk's footprint in 4x4 cells: the layer maps see chunks from above, where
        // every attribute is affine across the chunk, so the 48x48 grid only multiplied the
        // fragments shaded along its triangles' edges (1.8 per texel).
        mesh(
            "terrain_chunk_lod",
            "grid",
            23,
            json!({"size": 300, "divisions": 4}),
            "uint32",
        ),
        mesh(
            "water",
            "water_plate",
            24,
            json!({"size": 600, "divisions": 96, "height": 0}),
            "uint32",
        ),
        // The same flat plate in 4x4 cells: the top-down ocean height map needs its footprint
        // only (every attribute is affine across it), and the 96x96 grid's 57-pixel triangles
        // made lavapipe shade 2.2 fragments per texel along their edges.
        mesh(
            "water_lod",
            "water_plate",
            24,
            json!({"size": 600, "divisions": 4, "height": 0}),
            "uint32",
        ),
        mesh("box", "box", 25, json!({"size": 1}), "uint16"),
        mesh(
            "capsule",
            "capsule",
            26,
            json!({"radius": 0.3, "height": 1.8, "segments": CAPSULE_SEGMENTS}),
            "uint16",
        ),
        mesh(
            "trees",
            "foliage_cards",
            27,
            json!({"count": 140, "area": 100, "height": 6, "width": 4}),
            "uint32",
        ),
        mesh(
            "decal_quad",
            "grid",
            28,
            json!({"size": 1, "divisions": 1}),
            "uint16",
        ),
    ]
}

/// Every member of `scene.wgsl`'s `Params`, overridden per draw.
pub(super) fn scene_defaults() -> Value {
    json!({
        "view": 0, "material": 0, "light": 0, "instance_base": 0,
        "offset": [0, 0, 0, 0], "scale": [1, 1, 1, 0], "object_mask": 0,
        "probe": [0, 0, 0, 0], "face": 0,
    })
}

/// A draw of `mesh` through vertex entry `vertex` with scene parameters `params`; `stencil`
/// and `indirect` (an offset into `draw_args`) are not parameters but draw fields.
pub(super) fn d(label: &str, mesh: &str, vertex: &str, params: Value) -> Value {
    let mut params = params;
    let mut out = json!({"label": label, "mesh": mesh, "vertex": vertex});
    if let Some(p) = params.as_object_mut() {
        if let Some(s) = p.remove("stencil") {
            out["stencil_reference"] = s;
        }
        if let Some(i) = p.remove("indirect") {
            out["indirect"] = json!({"buffer": "draw_args", "offset": i});
        }
        if !p.is_empty() {
            out["params"] = params;
        }
    }
    out
}

/// Which parts of the world a view draws.
#[derive(Clone, Copy, Debug)]
pub(super) struct World {
    pub shadow: bool,
    pub instances: bool,
    pub foliage: bool,
    pub ground: bool,
}

impl World {
    pub(super) const ALL: World = World {
        shadow: false,
        instances: true,
        foliage: true,
        ground: true,
    };
    pub(super) const SHADOW: World = World {
        shadow: true,
        ..World::ALL
    };
}

/// Draws of the world, in the base pass's order, with the stencil values the seed describes.
pub(super) fn world_draws(w: World) -> Vec<Value> {
    let mut draws = vec![with(
        d(
            "static meshes: buildings",
            "buildings",
            "vs_building",
            json!({"material": 0, "object_mask": 0}),
        ),
        json!({ "instances": BUILDINGS }),
    )];
    if w.ground {
        draws.push(d(
            "ground",
            "ground",
            "vs_terrain",
            json!({"material": 1, "object_mask": 1}),
        ));
        if !w.shadow {
            draws.push(d(
                "water",
                "water",
                "vs_water",
                json!({"material": 3, "object_mask": 1, "offset": [0, 0, 380, 0]}),
            ));
        }
    }
    if w.instances {
        let people = |label: &str, vertex: &str, stencil: u32| {
            d(
                label,
                "capsule",
                vertex,
                json!({"material": 5, "object_mask": 3,
                "instance_base": FIRST_PEDESTRIAN, "indirect": 20, "stencil": stencil}),
            )
        };
        draws.push(d(
            "holographic signs",
            "box",
            "vs_instanced",
            json!({"material": 2, "instance_base": FIRST_SIGN, "indirect": 40}),
        ));
        draws.push(d(
            "cars",
            "box",
            "vs_instanced",
            json!({"material": 4, "object_mask": 2, "instance_base": FIRST_CAR, "indirect": 0}),
        ));
        draws.push(people("characters: bodies", "vs_character_body", 0x15));
        draws.push(people("characters: faces", "vs_character_head", 0x35));
    }
    if w.foliage {
        // The riverside park either side of the main street, which runs on to the water.
        for (side, x) in [("west", -62), ("east", 47)] {
            draws.push(d(
                &format!("foliage {side}"),
                "trees",
                "vs_foliage",
                json!({"material": 6, "object_mask": 1, "offset": [x, 0, 158, 0],
                                "scale": [0.9, 1, 0.22, 0], "stencil": 0xA0}),
            ));
        }
    }
    if !w.shadow && w.instances {
        // Zebra crossings where the view street meets the cross streets.
        for (k, z) in [-58, -6, 46, 98].into_iter().enumerate() {
            draws.push(d(
                &format!("decals: crossing {k}"),
                "decal_quad",
                "vs_static",
                json!({"material": 7, "offset": [-6, 0, z, 0], "scale": [11, 1, 7, 0]}),
            ));
        }
        for (label, vertex) in [
            ("fur mask", "vs_character_hair"),
            ("fur", "vs_character_fur"),
        ] {
            draws.push(d(
                label,
                "capsule",
                vertex,
                json!({"material": 8, "object_mask": 3,
                "instance_base": FIRST_PEDESTRIAN, "indirect": 20, "stencil": 0x95}),
            ));
        }
    }
    draws
}

/// The draws seen from another view: no stencil, and `params` set on every draw.
pub(super) fn with_view(draws: Vec<Value>, params: Value) -> Vec<Value> {
    draws
        .into_iter()
        .map(|mut dr| {
            if let Some(o) = dr.as_object_mut() {
                o.remove("stencil_reference");
                let existing = o.remove("params").unwrap_or_else(|| json!({}));
                o.insert("params".into(), with(existing, params.clone()));
            }
            dr
        })
        .collect()
}

/// What a pass asks of `scene.wgsl`, or of the world's draws, that is not there.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{0}")]
    Shader(&'static ShaderError),
    #[error("scene.wgsl has no entry point \"{entry}\"")]
    NoEntryPoint { entry: String },
    #[error("the world has no draw \"{label}\"")]
    NoDraw { label: String },
}

/// `scene.wgsl` as framelab's validation sees it: validated and reflected once, so a pass
/// binds (and the analysis sees) exactly the resources its entry points read, as the shader
/// says rather than as a table beside it would.
fn scene_shader() -> Result<&'static ValidatedShader, SceneError> {
    static SCENE: OnceLock<Result<ValidatedShader, ShaderError>> = OnceLock::new();
    SCENE
        .get_or_init(|| {
            let source = include_str!("../../../../captures/night_city/shaders/scene.wgsl");
            framelab_core::shader::validate_wgsl("scene.wgsl", source)
        })
        .as_ref()
        .map_err(SceneError::Shader)
}

/// The capture binding of `scene.wgsl`'s global `name`: a storage buffer, a sampler or a
/// sampled texture of the same name; `None` for the uniforms the replay fills itself.
fn scene_binding(module: &naga::Module, name: &str) -> Option<Value> {
    let (_, var) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.name.as_deref() == Some(name))?;
    Some(match (var.space, &module.types[var.ty].inner) {
        (naga::AddressSpace::Storage { access }, _) => {
            let writes = access.contains(naga::StorageAccess::STORE);
            storage(
                name,
                if writes {
                    "storage_read_write"
                } else {
                    "storage_read"
                },
            )
        }
        (_, naga::TypeInner::Sampler { .. }) => sampler(name),
        (_, naga::TypeInner::Image { .. }) => sampled(name),
        _ => return None,
    })
}

/// Sets a `scene.wgsl` pass's bindings from the globals its entry points and its draws'
/// entry points use.
pub(super) fn scene_bindings(mut pass: Value) -> Result<Value, SceneError> {
    let shader = scene_shader()?;
    let interface = reflect(shader);
    let mut entries: Vec<&str> = ["vertex", "fragment"]
        .into_iter()
        .filter_map(|key| pass["shader"][key].as_str())
        .collect();
    if let Some(draws) = pass["draws"].as_array() {
        entries.extend(draws.iter().filter_map(|d| d["vertex"].as_str()));
    }
    let mut names: BTreeSet<&str> = BTreeSet::new();
    for entry in entries {
        let globals = interface
            .globals_used_by(entry)
            .ok_or_else(|| SceneError::NoEntryPoint {
                entry: entry.to_owned(),
            })?;
        names.extend(globals.iter().map(String::as_str));
    }
    let bindings = names
        .into_iter()
        .filter_map(|n| Some((n.to_owned(), scene_binding(&shader.module, n)?)));
    pass["bindings"] = object(bindings);
    Ok(pass)
}

/// The depth-stencil view of the main depth buffer.
pub(super) fn depth_attach(extra: Value) -> Value {
    with(
        json!({"resource": "depth", "format": "D32_FLOAT_S8X24_UINT"}),
        extra,
    )
}

/// What a depth-only pass's fragment stage does.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Depth {
    /// `fs_depth`: cuts alpha-tested draws (foliage, fur) out; opaque draws run without it.
    AlphaTest,
    /// `fs_omni_depth`: writes every draw's distance to the light as its depth, seen through
    /// the light's paraboloid (`vs_omni_*`).
    Distance,
}

/// A depth-only `scene.wgsl` pass into `resource` (one layer), with optional depth bias.
pub(super) struct DepthOnly<'a> {
    pub name: &'a str,
    pub groups: &'a [&'a str],
    pub resource: &'a str,
    pub format: &'a str,
    pub layer: u32,
    pub bias: Option<(i32, f32)>,
    /// Back faces culled: a closed mesh's nearest surface to the light is a front face, so
    /// the map holds the same depth for a fraction of the rasterized fragments (the cascades
    /// and omni maps of the day frame: 17-77% fewer; 263 edge texels of a 4096x4096 cascade
    /// moved).
    pub cull_back: bool,
    pub depth: Depth,
}

/// Marks the draws `fs_depth` has nothing to cut out of (all but foliage and fur) as running
/// no fragment shader: with the alpha test's `discard` in the pipeline the GPU tests depth only
/// after shading, so every covered pixel of every layer ran it (the cascades shaded 4 times
/// their 4096x4096 area). Depth-only, they are tested before shading and shade nothing.
pub(super) fn opaque_depth_only(draws: Vec<Value>) -> Vec<Value> {
    draws
        .into_iter()
        .map(|mut dr| {
            let material = dr["params"]["material"].as_u64();
            if !matches!(material, Some(6 | 8)) {
                dr["depth_only"] = json!(true);
            }
            dr
        })
        .collect()
}

/// Gives the G-buffer draws with nothing to cut out (all but foliage, decals and fur) the
/// fragment entry point without `discard`: with it in the pipeline the GPU shades before it
/// tests depth, so base_material shaded every layer of the city (12 fragments per pixel).
pub(super) fn opaque_gbuffer(draws: Vec<Value>) -> Vec<Value> {
    draws
        .into_iter()
        .map(|mut dr| {
            let material = dr["params"]["material"].as_u64();
            if !matches!(material, Some(6..=8)) {
                dr["fragment"] = json!("fs_gbuffer_opaque");
            }
            dr
        })
        .collect()
}

/// A pass that only lays depth. With the alpha test (`fs_depth`), opaque draws go without
/// it, and the ground without the normal only shading would read (`vs_terrain_depth`; the
/// depth pre-pass keeps `vs_terrain`: base_material tests its depth for equality with the
/// same vertex shader's).
pub(super) fn depth_only(
    p: DepthOnly<'_>,
    draws: Vec<Value>,
    params: Value,
    rest: Value,
) -> Result<Value, SceneError> {
    let (entries, draws) = match p.depth {
        Depth::AlphaTest => {
            let draws = opaque_depth_only(draws)
                .into_iter()
                .map(|mut dr| {
                    if dr["vertex"] == "vs_terrain" && dr["depth_only"] == true {
                        dr["vertex"] = json!("vs_terrain_depth");
                    }
                    dr
                })
                .collect();
            (("vs_static", Some("fs_depth")), draws)
        }
        Depth::Distance => (("vs_omni_static", Some("fs_omni_depth")), draws),
    };
    let cull = if p.cull_back { "back" } else { "none" };
    let mut state = json!({"depth_compare": "less_equal", "depth_write": true, "cull": cull});
    if let Some((constant, slope)) = p.bias {
        state["depth_bias"] = json!(constant);
        state["depth_bias_slope"] = json!(slope);
    }
    scene_bindings(raster(
        p.name,
        p.groups,
        "scene.wgsl",
        entries,
        vec![],
        with(
            json!({
                "depth_stencil": {"resource": p.resource, "format": p.format, "layer": p.layer,
                                  "depth_load": "clear", "depth_clear": 1.0},
                "state": state,
                "params": with(scene_defaults(), params),
                "draws": draws,
            }),
            rest,
        ),
    ))
}
