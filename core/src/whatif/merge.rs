//! `--merge A+B`: two raster passes made one render pass where they can be: the second's draws
//! follow the first's on the same attachments, so what the first stores and the second loads
//! stays in the render pass. Every reason two passes cannot be one is an `Unmergeable` naming
//! it; what the merged frame does to synchronization is then the static verdict's to say.

use serde::Serialize;

use super::EditError;
use crate::analysis::lints::{conflict, unordered_inside};
use crate::capture::format::{LoadOp, Pass, PassKind, RawCapture, ShaderRef};
use crate::capture::model::{Capture, PassDesc};

/// Why two passes cannot be one render pass.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Unmergeable {
    #[error("the capture already has a pass \"{0}\"")]
    NameTaken(String),
    #[error("\"{pass}\" is a {kind} pass: only raster passes merge into one render pass")]
    NotRaster { pass: String, kind: &'static str },
    #[error(
        "\"{a}\" runs on queue {queue_a} and \"{b}\" on {queue_b}: one render pass is on one queue"
    )]
    Queues {
        a: String,
        queue_a: String,
        b: String,
        queue_b: String,
    },
    #[error(
        "\"{a}\" renders to {targets_a} and \"{b}\" to {targets_b}: one render pass has one set of attachments"
    )]
    Attachments {
        a: String,
        targets_a: String,
        b: String,
        targets_b: String,
    },
    #[error(
        "colour attachment {index} (\"{resource}\") blends or masks differently in the two passes: a pass has one blend state per attachment"
    )]
    Blend { index: usize, resource: String },
    #[error("\"{a}\" and \"{b}\" bind depth \"{resource}\" one read-only and the other writable")]
    DepthAccess {
        a: String,
        b: String,
        resource: String,
    },
    #[error("\"{pass}\" {} \"{resource}\" as it begins: a render pass keeps its attachments from one draw to the next", begins(*.load))]
    Begins {
        pass: String,
        resource: String,
        load: LoadOp,
    },
    #[error(
        "\"{a}\" and \"{b}\" differ in fixed-function state (depth, stencil or rasterizer): a pass has one"
    )]
    State { a: String, b: String },
    #[error(
        "\"{a}\" draws with {shader_a} and \"{b}\" with {shader_b}: a pass has one shader file"
    )]
    Shaders {
        a: String,
        shader_a: String,
        b: String,
        shader_b: String,
    },
    #[error(
        "\"{pass}\" waits on fence \"{fence}\" before it begins: its draws cannot move ahead of the wait into \"{first}\""
    )]
    Waits {
        pass: String,
        fence: String,
        first: String,
    },
    #[error("both passes bind \"{0}\", to different views: one render pass binds one")]
    Binding(String),
    #[error("both passes set parameter \"{0}\", to different values: a pass has one")]
    Parameter(String),
    #[error(
        "\"{writer}\" writes \"{resource}\", which \"{reader}\" uses ({access}): inside one render pass no barrier can order them"
    )]
    Within {
        writer: String,
        resource: String,
        reader: String,
        access: &'static str,
    },
    #[error("\"{between}\", recorded between them, {} \"{resource}\", which \"{second}\" {}: \"{second}\" cannot move ahead of it", verb(*.between_writes), verb(*.second_writes))]
    Between {
        between: String,
        between_writes: bool,
        resource: String,
        second: String,
        second_writes: bool,
    },
    #[error(
        "\"{second}\"'s recorded barrier {index} is on \"{resource}\", which \"{first}\" uses: no barrier fits between the draws of one render pass"
    )]
    Barrier {
        second: String,
        index: usize,
        resource: String,
        first: String,
    },
}

fn begins(load: LoadOp) -> &'static str {
    match load {
        LoadOp::Clear => "clears",
        LoadOp::Discard => "discards",
        LoadOp::Load => "loads",
    }
}

fn verb(writes: bool) -> &'static str {
    if writes { "writes" } else { "reads" }
}

/// Merges the passes named `a` and `b` (in either order) into one pass at the earlier one's
/// place, named `a+b`; what was done, in words.
pub(super) fn merge(
    raw: &mut RawCapture,
    frame: &Capture,
    (a, b): (&str, &str),
    edit: &str,
) -> Result<String, EditError> {
    let no = |why: Unmergeable| EditError::CannotMerge {
        edit: edit.to_owned(),
        why: Box::new(why),
    };
    let place = |name: &str| {
        raw.passes
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| EditError::UnknownPass {
                edit: edit.to_owned(),
                pass: name.to_owned(),
            })
    };
    let (mut i, mut j) = (place(a)?, place(b)?);
    if i > j {
        std::mem::swap(&mut i, &mut j);
    }
    let (first, second) = (&raw.passes[i], &raw.passes[j]);
    let name = format!("{}+{}", first.name, second.name);
    if raw.passes.iter().any(|p| p.name == name) {
        return Err(no(Unmergeable::NameTaken(name)));
    }
    compatible(first, second).map_err(no)?;
    if let (Some(fa), Some(fb)) = (
        described(frame, &first.name),
        described(frame, &second.name),
    ) {
        within(frame, fa, fb).map_err(no)?;
        for between in &raw.passes[i + 1..j] {
            if let Some(fc) = described(frame, &between.name) {
                crossed(frame, fc, fb).map_err(no)?;
            }
        }
        hoisted(frame, fa, fb).map_err(no)?;
    }
    let second = raw.passes.remove(j);
    let (first_name, second_name) = (raw.passes[i].name.clone(), second.name.clone());
    joined(&mut raw.passes[i], second, name.clone()).map_err(no)?;
    Ok(format!(
        "passes \"{first_name}\" and \"{second_name}\" merged into one render pass \"{name}\""
    ))
}

fn described<'a>(frame: &'a Capture, name: &str) -> Option<&'a PassDesc> {
    frame.passes.iter().find(|p| p.name == name)
}

/// The two values serialize alike (the capture format's own equality).
fn same<T: Serialize>(a: &T, b: &T) -> bool {
    serde_json::to_value(a).ok() == serde_json::to_value(b).ok()
}

/// A pass's attachments in words: `"composite" mip 0 layer 0, depth "depth" mip 0 layer 0`.
fn targets(p: &Pass) -> String {
    let mut t: Vec<String> = p
        .color_attachments
        .iter()
        .map(|c| format!("\"{}\" mip {} layer {}", c.resource, c.mip, c.layer))
        .collect();
    if let Some(d) = &p.depth_stencil {
        t.push(format!(
            "depth \"{}\" mip {} layer {}",
            d.resource, d.mip, d.layer
        ));
    }
    if t.is_empty() {
        "nothing".to_owned()
    } else {
        t.join(", ")
    }
}

/// The same views: resource, subresource and view format of every attachment.
fn same_targets(a: &Pass, b: &Pass) -> bool {
    a.color_attachments.len() == b.color_attachments.len()
        && a.color_attachments
            .iter()
            .zip(&b.color_attachments)
            .all(|(x, y)| {
                (&x.resource, x.mip, x.layer, &x.format) == (&y.resource, y.mip, y.layer, &y.format)
            })
        && match (&a.depth_stencil, &b.depth_stencil) {
            (None, None) => true,
            (Some(x), Some(y)) => {
                (&x.resource, x.mip, x.layer, &x.format) == (&y.resource, y.mip, y.layer, &y.format)
            }
            _ => false,
        }
}

/// What the two passes are, apart from their draws, must be one render pass's.
fn compatible(a: &Pass, b: &Pass) -> Result<(), Unmergeable> {
    for p in [a, b] {
        if p.kind != PassKind::Raster {
            return Err(Unmergeable::NotRaster {
                pass: p.name.clone(),
                kind: p.kind.as_str(),
            });
        }
    }
    if a.queue != b.queue {
        return Err(Unmergeable::Queues {
            a: a.name.clone(),
            queue_a: a.queue.clone(),
            b: b.name.clone(),
            queue_b: b.queue.clone(),
        });
    }
    if !same_targets(a, b) {
        return Err(Unmergeable::Attachments {
            a: a.name.clone(),
            targets_a: targets(a),
            b: b.name.clone(),
            targets_b: targets(b),
        });
    }
    loaded(a, b)?;
    if !same(&a.state, &b.state) {
        return Err(Unmergeable::State {
            a: a.name.clone(),
            b: b.name.clone(),
        });
    }
    let file = |s: &Option<ShaderRef>| s.as_ref().map(|s| s.file.clone());
    if file(&a.shader) != file(&b.shader) {
        let or_none = |s: Option<String>| s.unwrap_or_else(|| "no WGSL shader".to_owned());
        return Err(Unmergeable::Shaders {
            a: a.name.clone(),
            shader_a: or_none(file(&a.shader)),
            b: b.name.clone(),
            shader_b: or_none(file(&b.shader)),
        });
    }
    if let Some(f) = b.wait.first() {
        return Err(Unmergeable::Waits {
            pass: b.name.clone(),
            fence: f.clone(),
            first: a.name.clone(),
        });
    }
    Ok(())
}

/// The second pass takes the attachments as the first leaves them, with the same blend and
/// depth access.
fn loaded(a: &Pass, b: &Pass) -> Result<(), Unmergeable> {
    let begun = |resource: &str, load| Unmergeable::Begins {
        pass: b.name.clone(),
        resource: resource.to_owned(),
        load,
    };
    for (index, (x, y)) in a
        .color_attachments
        .iter()
        .zip(&b.color_attachments)
        .enumerate()
    {
        if !same(&x.blend, &y.blend) || x.write_mask != y.write_mask {
            return Err(Unmergeable::Blend {
                index,
                resource: x.resource.clone(),
            });
        }
        if y.load != LoadOp::Load {
            return Err(begun(&y.resource, y.load));
        }
    }
    if let (Some(x), Some(y)) = (&a.depth_stencil, &b.depth_stencil) {
        if x.read_only != y.read_only || x.stencil_read_only != y.stencil_read_only {
            return Err(Unmergeable::DepthAccess {
                a: a.name.clone(),
                b: b.name.clone(),
                resource: x.resource.clone(),
            });
        }
        for load in [y.depth_load, y.stencil_load] {
            if load != LoadOp::Load {
                return Err(begun(&y.resource, load));
            }
        }
    }
    Ok(())
}

/// Within one render pass nothing orders a draw's shader accesses after an earlier draw's but
/// the attachments' rasterization order: the second pass may not read or write what the first
/// touches, other than through the attachments both share.
pub(super) fn within(frame: &Capture, a: &PassDesc, b: &PassDesc) -> Result<(), Unmergeable> {
    match unordered_inside(frame, a, b) {
        Some(u) => Err(Unmergeable::Within {
            writer: u.writer.name.clone(),
            resource: u.resource.to_owned(),
            reader: u.reader.name.clone(),
            access: u.access,
        }),
        None => Ok(()),
    }
}

/// A pass recorded between the two keeps its place after the second moves ahead of it: it may
/// not write what the second uses, nor use what the second writes.
fn crossed(frame: &Capture, between: &PassDesc, b: &PassDesc) -> Result<(), Unmergeable> {
    for x in &between.accesses {
        if let Some(y) = b.accesses.iter().find(|y| conflict(x, y)) {
            return Err(Unmergeable::Between {
                between: between.name.clone(),
                between_writes: x.writes,
                resource: frame.resource(x.resource).name.clone(),
                second: b.name.clone(),
                second_writes: y.writes,
            });
        }
    }
    Ok(())
}

/// The second pass's recorded barriers move ahead of the first's draws: none may touch what the
/// first uses.
fn hoisted(frame: &Capture, a: &PassDesc, b: &PassDesc) -> Result<(), Unmergeable> {
    for (index, barrier) in b.barriers.iter().enumerate() {
        let touched = [barrier.resource, barrier.resource_before]
            .into_iter()
            .flatten();
        for r in touched {
            if a.accesses.iter().any(|x| x.resource == r) {
                return Err(Unmergeable::Barrier {
                    second: b.name.clone(),
                    index,
                    resource: frame.resource(r).name.clone(),
                    first: a.name.clone(),
                });
            }
        }
    }
    Ok(())
}

/// The bindings and parameters both set must agree.
fn agreed(a: &Pass, b: &Pass) -> Result<(), Unmergeable> {
    for (variable, binding) in &b.bindings {
        if a.bindings
            .get(variable)
            .is_some_and(|have| !same(have, binding))
        {
            return Err(Unmergeable::Binding(variable.clone()));
        }
    }
    for (name, value) in &b.params {
        if a.params.get(name).is_some_and(|have| !same(have, value)) {
            return Err(Unmergeable::Parameter(name.clone()));
        }
    }
    Ok(())
}

/// `b` appended to `a`: draws after draws, bindings and parameters joined, the second's stores
/// and signals kept, its barriers ahead of the merged pass.
fn joined(a: &mut Pass, b: Pass, name: String) -> Result<(), Unmergeable> {
    agreed(a, &b)?;
    for (variable, binding) in b.bindings {
        a.bindings.entry(variable).or_insert(binding);
    }
    for (k, v) in b.params {
        a.params.entry(k).or_insert(v);
    }
    let offset = a.draws.len() as u32;
    let entries = |s: &Option<ShaderRef>| {
        s.as_ref()
            .map_or((None, None), |s| (s.vertex.clone(), s.fragment.clone()))
    };
    let (a_vertex, a_fragment) = entries(&a.shader);
    let (b_vertex, b_fragment) = entries(&b.shader);
    for mut d in b.draws {
        if d.vertex.is_none() && b_vertex != a_vertex {
            d.vertex = b_vertex.clone();
        }
        if d.fragment.is_none() && b_fragment != a_fragment {
            d.fragment = b_fragment.clone();
        }
        a.draws.push(d);
    }
    a.attachment_clears
        .extend(b.attachment_clears.into_iter().map(|mut c| {
            c.before_draw += offset;
            c
        }));
    for (x, y) in a.color_attachments.iter_mut().zip(&b.color_attachments) {
        x.store = y.store;
    }
    if let (Some(x), Some(y)) = (&mut a.depth_stencil, &b.depth_stencil) {
        x.depth_store = y.depth_store;
        x.stencil_store = y.stencil_store;
    }
    a.barriers.extend(b.barriers);
    a.signal.extend(b.signal);
    a.timing = None;
    a.name = name;
    Ok(())
}
