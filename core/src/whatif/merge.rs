//! `--merge A+B`: two raster passes made one render pass where they can be: the second's draws
//! follow the first's on the same attachments, so what the first stores and the second loads
//! stays in the render pass. Every reason two passes cannot be one is an error naming it; what
//! the merged frame does to synchronization is then the static verdict's to say.

use std::collections::BTreeMap;

use serde::Serialize;

use super::EditError;
use crate::capture::format::{LoadOp, Pass, PassKind, RawCapture};
use crate::capture::model::{AccessSource, Capture, PassDesc, ResourceAccess};

/// Merges the passes named `a` and `b` (in either order) into one pass at the earlier one's
/// place, named `a+b`; what was done, in words.
pub(super) fn merge(
    raw: &mut RawCapture,
    frame: &Capture,
    (a, b): (&str, &str),
    edit: &str,
) -> Result<String, EditError> {
    let no = |why: String| EditError::CannotMerge {
        edit: edit.to_owned(),
        why,
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
        return Err(no(format!("the capture already has a pass \"{name}\"")));
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

/// What the two passes are, apart from their draws, must be one render pass's.
fn compatible(a: &Pass, b: &Pass) -> Result<(), String> {
    for p in [a, b] {
        if p.kind != PassKind::Raster {
            return Err(format!(
                "\"{}\" is a {} pass: only raster passes merge into one render pass",
                p.name,
                p.kind.as_str()
            ));
        }
    }
    if a.queue != b.queue {
        return Err(format!(
            "\"{}\" runs on queue {} and \"{}\" on {}: one render pass is on one queue",
            a.name, a.queue, b.name, b.queue
        ));
    }
    let targets = |p: &Pass| {
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
        t.join(", ")
    };
    let same_targets = a.color_attachments.len() == b.color_attachments.len()
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
        };
    if !same_targets {
        return Err(format!(
            "\"{}\" renders to {} and \"{}\" to {}: one render pass has one set of attachments",
            a.name,
            or_none(targets(a)),
            b.name,
            or_none(targets(b))
        ));
    }
    for (k, (x, y)) in a
        .color_attachments
        .iter()
        .zip(&b.color_attachments)
        .enumerate()
    {
        if !same(&x.blend, &y.blend) || x.write_mask != y.write_mask {
            return Err(format!(
                "colour attachment {k} (\"{}\") blends or masks differently in the two passes: \
                 a pass has one blend state per attachment",
                x.resource
            ));
        }
        if y.load != LoadOp::Load {
            return Err(begins(b, &y.resource, y.load));
        }
    }
    if let (Some(x), Some(y)) = (&a.depth_stencil, &b.depth_stencil) {
        if x.read_only != y.read_only || x.stencil_read_only != y.stencil_read_only {
            return Err(format!(
                "\"{}\" binds depth \"{}\" read-only in one pass and writable in the other",
                a.name, x.resource
            ));
        }
        for load in [y.depth_load, y.stencil_load] {
            if load != LoadOp::Load {
                return Err(begins(b, &y.resource, load));
            }
        }
    }
    if !same(&a.state, &b.state) {
        return Err(format!(
            "\"{}\" and \"{}\" differ in fixed-function state (depth, stencil or rasterizer): \
             a pass has one",
            a.name, b.name
        ));
    }
    match (&a.shader, &b.shader) {
        (Some(x), Some(y)) if x.file != y.file => {
            return Err(format!(
                "\"{}\" draws with {} and \"{}\" with {}: a pass has one shader file",
                a.name, x.file, b.name, y.file
            ));
        }
        (Some(_), None) | (None, Some(_)) => {
            return Err(format!(
                "one of \"{}\" and \"{}\" names a WGSL shader and the other none",
                a.name, b.name
            ));
        }
        _ => {}
    }
    if let Some(f) = b.wait.first() {
        return Err(format!(
            "\"{}\" waits on fence \"{f}\" before it begins: its draws cannot move ahead of the \
             wait into \"{}\"",
            b.name, a.name
        ));
    }
    Ok(())
}

fn or_none(s: String) -> String {
    if s.is_empty() {
        "nothing".to_owned()
    } else {
        s
    }
}

fn begins(p: &Pass, resource: &str, load: LoadOp) -> String {
    let what = match load {
        LoadOp::Clear => "clears",
        LoadOp::Discard => "discards",
        LoadOp::Load => "loads",
    };
    format!(
        "\"{}\" {what} \"{resource}\" as it begins: a render pass keeps its attachments from \
         one draw to the next",
        p.name
    )
}

fn attachment(access: &ResourceAccess) -> bool {
    matches!(
        access.source,
        AccessSource::ColorAttachment(_) | AccessSource::DepthStencil
    )
}

/// Whether `x` and `y` touch the same bytes or texels, one of them writing.
fn conflict(x: &ResourceAccess, y: &ResourceAccess) -> bool {
    x.resource == y.resource && (x.writes || y.writes) && x.range.overlaps(&y.range)
}

/// Within one render pass nothing orders a draw's shader accesses after an earlier draw's but
/// the attachments' rasterization order: the second pass may not read or write what the first
/// touches, other than through the attachments both share.
pub(super) fn within(frame: &Capture, a: &PassDesc, b: &PassDesc) -> Result<(), String> {
    for x in &a.accesses {
        for y in b.accesses.iter().filter(|y| conflict(x, y)) {
            if attachment(x) && attachment(y) {
                continue;
            }
            let (writer, reader, how) = if x.writes {
                (a, b, y.access.as_str())
            } else {
                (b, a, x.access.as_str())
            };
            return Err(format!(
                "\"{}\" writes \"{}\", which \"{}\" uses ({how}): inside one render pass no \
                 barrier can order them",
                writer.name,
                frame.resource(x.resource).name,
                reader.name
            ));
        }
    }
    Ok(())
}

/// A pass recorded between the two keeps its place after the second moves ahead of it: it may
/// not write what the second uses, nor use what the second writes.
fn crossed(frame: &Capture, between: &PassDesc, b: &PassDesc) -> Result<(), String> {
    for x in &between.accesses {
        if let Some(y) = b.accesses.iter().find(|y| conflict(x, y)) {
            return Err(format!(
                "\"{}\", recorded between them, {} \"{}\", which \"{}\" {}: \"{}\" cannot move \
                 ahead of it",
                between.name,
                if x.writes { "writes" } else { "reads" },
                frame.resource(x.resource).name,
                b.name,
                if y.writes { "writes" } else { "reads" },
                b.name
            ));
        }
    }
    Ok(())
}

/// The second pass's recorded barriers move ahead of the first's draws: none may touch what the
/// first uses.
fn hoisted(frame: &Capture, a: &PassDesc, b: &PassDesc) -> Result<(), String> {
    for (k, barrier) in b.barriers.iter().enumerate() {
        let touched = [barrier.resource, barrier.resource_before]
            .into_iter()
            .flatten();
        for r in touched {
            if a.accesses.iter().any(|x| x.resource == r) {
                return Err(format!(
                    "\"{}\"'s recorded barrier {k} is on \"{}\", which \"{}\" uses: no barrier \
                     fits between the draws of one render pass",
                    b.name,
                    frame.resource(r).name,
                    a.name
                ));
            }
        }
    }
    Ok(())
}

/// `b` appended to `a`: draws after draws, bindings and parameters joined, the second's stores
/// and signals kept, its barriers ahead of the merged pass.
fn joined(a: &mut Pass, b: Pass, name: String) -> Result<(), String> {
    for (variable, binding) in b.bindings {
        match a.bindings.get(&variable) {
            Some(have) if !same(have, &binding) => {
                return Err(format!(
                    "both passes bind \"{variable}\", to different views: one render pass binds \
                     one"
                ));
            }
            Some(_) => {}
            None => {
                a.bindings.insert(variable, binding);
            }
        }
    }
    let mut params = BTreeMap::new();
    for (k, v) in b.params {
        match a.params.get(&k) {
            Some(have) if !same(have, &v) => {
                return Err(format!(
                    "both passes set parameter \"{k}\", to different values: a pass has one"
                ));
            }
            _ => {
                params.insert(k, v);
            }
        }
    }
    a.params.extend(params);
    let offset = a.draws.len() as u32;
    let entries = |s: &Option<crate::capture::format::ShaderRef>| {
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
