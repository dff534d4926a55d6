//! Small builders for the passes of the Night City frame: bindings, attachments, draws and
//! dispatches as the capture format spells them, so each pass below reads like its manifest
//! entry. Values are untyped here and checked against the format's types when the capture is
//! assembled.

use serde_json::{Map, Value, json};

/// `base` with every field of `extra` (an object) set on it.
pub(super) fn with(mut base: Value, extra: Value) -> Value {
    if let (Some(b), Value::Object(e)) = (base.as_object_mut(), extra) {
        for (k, v) in e {
            b.insert(k, v);
        }
    }
    base
}

pub(super) fn sampled(resource: &str) -> Value {
    json!({"resource": resource, "access": "sampled"})
}

pub(super) fn storage(resource: &str, access: &str) -> Value {
    json!({"resource": resource, "access": access})
}

/// Sampled bindings of whole resources, each under its own name.
pub(super) fn sampled_each(names: &[&str]) -> Value {
    object(names.iter().map(|n| ((*n).to_owned(), sampled(n))))
}

/// The G-buffer and the full-resolution depth, as every deferred lighting pass reads them.
pub(super) const GBUFFER: [&str; 4] = [
    "gbuffer_albedo",
    "gbuffer_normal",
    "gbuffer_material",
    "depth_r32",
];

/// One mip of `resource` as a storage view.
pub(super) fn storage_mip(resource: &str, mip: u32) -> Value {
    with(
        storage(resource, "storage_write"),
        json!({"mips": {"base": mip, "count": 1}}),
    )
}

/// The depth buffer viewed as its depth (R32) or its stencil (R8 UINT).
pub(super) fn depth_view() -> Value {
    with(
        sampled("depth"),
        json!({"format": "R32_FLOAT_X8X24_TYPELESS"}),
    )
}
pub(super) fn stencil_view() -> Value {
    with(
        sampled("depth"),
        json!({"format": "X32_TYPELESS_G8X24_UINT"}),
    )
}

pub(super) fn sampler(name: &str) -> Value {
    json!({ "sampler": name })
}

/// A draw of three vertices the vertex shader places over the whole target.
pub(super) fn fullscreen(label: &str) -> Value {
    json!({"label": label, "count": 3})
}

/// A colour attachment cleared to zero.
pub(super) fn color(resource: &str) -> Value {
    json!({"resource": resource, "load": "clear", "clear": [0, 0, 0, 0]})
}

pub(super) fn groups(x: u32, y: u32, z: u32) -> Value {
    json!({ "groups": [x, y, z] })
}

/// A dispatch of one thread per texel of `resource`'s mip `mip` as replayed: at a reduced
/// `--scale` it shrinks with the texture instead of running the 1080p frame's threads, most
/// of which would write nothing (at scale 0.25, 15 in 16).
pub(super) fn cover(resource: &str, mip: u32) -> Value {
    json!({ "cover": {"resource": resource, "mip": mip} })
}

pub(super) fn markers(groups: &[&str]) -> Vec<String> {
    std::iter::once("Frame")
        .chain(groups.iter().copied())
        .map(str::to_owned)
        .collect()
}

/// A raster pass on the graphics queue; `rest` adds or overrides fields.
pub(super) fn raster(
    name: &str,
    groups: &[&str],
    shader: &str,
    (vertex, fragment): (&str, Option<&str>),
    colors: Vec<Value>,
    rest: Value,
) -> Value {
    let mut shader = json!({"file": format!("shaders/{shader}"), "vertex": vertex});
    if let Some(f) = fragment {
        shader["fragment"] = json!(f);
    }
    with(
        json!({
            "name": name,
            "queue": "graphics",
            "kind": "raster",
            "markers": markers(groups),
            "shader": shader,
            "color_attachments": colors,
        }),
        rest,
    )
}

/// A raster pass of one full-screen triangle into `colors`, reading `bindings`; `rest` adds
/// or overrides fields.
pub(super) fn fullscreen_pass(
    name: &str,
    groups: &[&str],
    (shader, fragment): (&str, &str),
    colors: Vec<Value>,
    bindings: Value,
    rest: Value,
) -> Value {
    raster(
        name,
        groups,
        shader,
        ("vs_fullscreen", Some(fragment)),
        colors,
        with(
            json!({"bindings": bindings, "draws": [fullscreen(name)]}),
            rest,
        ),
    )
}

/// A compute pass on the async compute queue; `rest` adds or overrides fields.
pub(super) fn compute(
    name: &str,
    groups: &[&str],
    shader: &str,
    entry: &str,
    dispatches: Vec<Value>,
    rest: Value,
) -> Value {
    with(
        json!({
            "name": name,
            "queue": "compute",
            "kind": "compute",
            "markers": markers(groups),
            "shader": {"file": format!("shaders/{shader}"), "compute": entry},
            "dispatches": dispatches,
        }),
        rest,
    )
}

/// An object from `(key, value)` pairs, for bindings built in loops.
pub(super) fn object(entries: impl IntoIterator<Item = (String, Value)>) -> Value {
    Value::Object(entries.into_iter().collect::<Map<String, Value>>())
}
