//! A pass as a viewer lists it, in text: its draws, dispatches, copies and clears; its
//! bindings and attachments; its render or pipeline state; its recorded barriers. The
//! inspector's panels and any other viewer show these lines as they are, so a pass reads the
//! same wherever it is shown, and the derived barriers beside them are `BarrierReport`'s.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::capture::format::{ParamValue, PassKind};
use crate::capture::model::{BindingTarget, Capture, PassDesc, ResourceId};
use crate::capture::vk_model::VkWork;

/// A serde enum's name as the capture spells it.
pub fn spelled(x: &impl Serialize) -> String {
    match serde_json::to_value(x) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(v) => v.to_string(),
        Err(_) => String::new(),
    }
}

/// One line per draw, dispatch, copy, clear, resolve, mip generation and present.
pub fn work(c: &Capture, p: &PassDesc) -> Vec<String> {
    let name = |r| c.resource(r).name.clone();
    // An imported draw or dispatch names the Vulkan pipeline it runs with.
    let pipeline = |vk: &Option<Box<VkWork>>| {
        vk.as_ref()
            .and_then(|w| c.vulkan.as_ref()?.pipelines.get(w.pipeline))
            .map_or(String::new(), |pl| format!(" with {}", pl.name))
    };
    let mut out = Vec::new();
    for (i, d) in p.draws.iter().enumerate() {
        let what = d.label.clone().unwrap_or_else(|| format!("draw {i}"));
        let args = match (&d.indirect, d.mesh) {
            (Some((buf, offset)), _) => format!("indirect from {} @ {offset}", name(*buf)),
            (None, Some(m)) => format!(
                "mesh {} x{} instances",
                c.meshes[m.index()].name,
                d.instances
            ),
            (None, None) => format!(
                "{} vertices x{} instances",
                d.count.unwrap_or(0),
                d.instances
            ),
        };
        out.push(format!("{what}: {args}{}", pipeline(&d.vk)));
    }
    for (i, d) in p.dispatches.iter().enumerate() {
        let what = d.label.clone().unwrap_or_else(|| format!("dispatch {i}"));
        let args = match (&d.indirect, d.groups) {
            (Some((buf, offset)), _) => format!("indirect from {} @ {offset}", name(*buf)),
            (None, Some([x, y, z])) => format!("{x}x{y}x{z} groups"),
            (None, None) => "no groups".to_owned(),
        };
        out.push(format!("{what}: {args}{}", pipeline(&d.vk)));
    }
    for cp in &p.copies {
        out.push(format!(
            "copy {} mip {} -> {} mip {}",
            name(cp.src.resource),
            cp.src.mip,
            name(cp.dst.resource),
            cp.dst.mip
        ));
    }
    for cl in &p.clears {
        out.push(format!("clear {} to {:?}", name(cl.resource), cl.value));
    }
    if let Some((src, dst)) = p.resolve {
        out.push(format!("resolve {} -> {}", name(src), name(dst)));
    }
    if let Some((r, range)) = &p.generate_mips {
        out.push(format!(
            "generate mips of {} ({})",
            name(*r),
            range.describe(true)
        ));
    }
    if let Some(r) = p.present {
        out.push(format!("present {}", name(r)));
    }
    out
}

/// Each binding: its shader variable, and what it binds (resource, view, access, range).
pub fn bindings(c: &Capture, p: &PassDesc) -> Vec<(String, String)> {
    p.bindings
        .iter()
        .map(|b| {
            let target = match &b.target {
                BindingTarget::Resource {
                    resource,
                    view_format,
                    view_kind,
                } => {
                    let r = c.resource(*resource);
                    let mut s = format!(
                        "{}{} as {}",
                        r.name,
                        if b.previous_frame {
                            " (previous frame)"
                        } else {
                            ""
                        },
                        view_kind.as_str()
                    );
                    if let Some(f) = view_format {
                        s.push_str(&format!(" {}", f.name));
                    }
                    if let Some(a) = b.access {
                        s.push_str(&format!(", {}", a.as_str()));
                    }
                    if let Some(range) = &b.range {
                        s.push_str(&format!(", {}", range.describe(r.is_texture())));
                    }
                    s
                }
                BindingTarget::Sampler(s) => format!("sampler {}", c.samplers[s.index()].name),
            };
            (b.variable.clone(), target)
        })
        .collect()
}

/// An attachment of a pass: its slot (`color 0`, `depth`), its resource and the rest.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachmentText {
    pub slot: String,
    pub resource: ResourceId,
    pub text: String,
}

/// The colour attachments in slot order, then the depth-stencil attachment.
pub fn attachments(p: &PassDesc) -> Vec<AttachmentText> {
    let mut out: Vec<AttachmentText> = p
        .color_attachments
        .iter()
        .enumerate()
        .map(|(i, a)| AttachmentText {
            slot: format!("color {i}"),
            resource: a.resource,
            text: format!(
                "mip {} layer {} ({}), load {}{}, store {}",
                a.mip,
                a.layer,
                a.format.name,
                spelled(&a.load),
                if spelled(&a.load) == "clear" {
                    format!(" {:?}", a.clear)
                } else {
                    String::new()
                },
                spelled(&a.store)
            ),
        })
        .collect();
    if let Some(d) = &p.depth_stencil {
        out.push(AttachmentText {
            slot: "depth".into(),
            resource: d.resource,
            text: format!(
                "mip {} ({}), depth load {} ({}) store {}, stencil load {} ({}) store {}{}",
                d.mip,
                d.format.name,
                spelled(&d.depth_load),
                d.depth_clear,
                spelled(&d.depth_store),
                spelled(&d.stencil_load),
                d.stencil_clear,
                spelled(&d.stencil_store),
                if d.read_only { ", read-only" } else { "" }
            ),
        });
    }
    out
}

/// The pass's shader and entry points, or an imported pass's pipelines (stages, then
/// topology, cull mode, front face, depth test and blending), or its declared render state.
pub fn state(c: &Capture, p: &PassDesc) -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Some(s) = &p.shader {
        out.push(("shader".to_owned(), c.shader(s.id).file.clone()));
        for (stage, entry) in [
            ("vertex", &s.vertex),
            ("fragment", &s.fragment),
            ("compute", &s.compute),
        ] {
            if let Some(e) = entry {
                out.push((stage.to_owned(), e.clone()));
            }
        }
    }
    // An imported pass's state is its draws' and dispatches' pipelines; a pass-level render
    // state would be made up.
    if c.vulkan.is_some() {
        out.extend(pipelines(c, p));
        return out;
    }
    // An import without code records no pipeline state: the defaults would be made up.
    if p.kind == PassKind::Raster
        && c.not_replayable().is_none()
        && let Ok(serde_json::Value::Object(m)) = serde_json::to_value(&p.state)
    {
        for (k, v) in m {
            let text = match v {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            };
            out.push((k, text));
        }
    }
    out
}

/// Each Vulkan pipeline the pass's draws and dispatches run with, once: its stages, and for a
/// graphics pipeline a line of its fixed-function state.
fn pipelines(c: &Capture, p: &PassDesc) -> Vec<(String, String)> {
    let Some(vk) = &c.vulkan else {
        return Vec::new();
    };
    let mut used: Vec<usize> = p
        .draws
        .iter()
        .filter_map(|d| d.vk.as_ref())
        .chain(p.dispatches.iter().filter_map(|d| d.vk.as_ref()))
        .map(|w| w.pipeline)
        .collect();
    used.sort_unstable();
    used.dedup();
    let mut out = Vec::new();
    for pl in used.iter().filter_map(|&i| vk.pipelines.get(i)) {
        let stages: Vec<String> = pl
            .stages
            .iter()
            .filter_map(|s| {
                let m = vk.modules.get(s.module)?;
                Some(format!(
                    "{} {}",
                    s.stage
                        .trim_start_matches("VK_SHADER_STAGE_")
                        .trim_end_matches("_BIT")
                        .to_lowercase(),
                    m.name
                ))
            })
            .collect();
        out.push((pl.name.clone(), stages.join(", ")));
        if let Some(g) = &pl.graphics {
            let short = |n: &str, prefix: &str| n.trim_start_matches(prefix).to_lowercase();
            let mut line = format!(
                "{}, cull {}, front {}",
                short(&g.topology, "VK_PRIMITIVE_TOPOLOGY_"),
                cull_mode(g.cull_mode),
                short(&g.front_face, "VK_FRONT_FACE_")
            );
            if let Some(d) = g.depth_stencil.as_ref().filter(|d| d.depth_test) {
                line += &format!(
                    ", depth {}{}",
                    short(&d.depth_compare, "VK_COMPARE_OP_"),
                    if d.depth_write { " write" } else { "" }
                );
            }
            if g.blend.iter().any(|b| b.enable) {
                line += ", blend";
            }
            out.push((String::new(), line));
        }
    }
    out
}

/// `VkCullModeFlags` in words: its two bits, front (1) and back (2).
fn cull_mode(flags: u32) -> &'static str {
    match (flags & 1 != 0, flags & 2 != 0) {
        (false, false) => "none",
        (true, false) => "front",
        (false, true) => "back",
        (true, true) => "both",
    }
}

/// The pass's parameters, each value as JSON.
pub fn params(p: &BTreeMap<String, ParamValue>) -> Vec<(String, String)> {
    p.iter()
        .map(|(k, v)| (k.clone(), serde_json::to_string(v).unwrap_or_default()))
        .collect()
}

/// A barrier the capture records before a pass, in the words of a derived one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordedBarrierText {
    /// `transition`, `uav`, `aliasing`, as the capture spells it.
    pub kind: String,
    /// The resource, or `(all)` for a global barrier.
    pub resource: String,
    pub subresource: String,
    /// `before -> after` states, or the resource an aliasing barrier hands over from.
    pub states: String,
    /// The Vulkan barrier it was imported from, if any (see `VulkanBarrierDesc::describe`).
    pub vulkan: String,
}

/// The barriers `p` records, in recorded order.
pub fn recorded_barriers(c: &Capture, p: &PassDesc) -> Vec<RecordedBarrierText> {
    p.barriers
        .iter()
        .map(|b| {
            let resource = b.resource.map(|r| c.resource(r));
            let states = |s: &[crate::capture::format::ResourceState]| {
                s.iter().map(spelled).collect::<Vec<_>>().join("|")
            };
            RecordedBarrierText {
                kind: spelled(&b.barrier_type),
                resource: resource.map_or("(all)".to_owned(), |r| r.name.clone()),
                subresource: match (&b.range, resource) {
                    (Some(range), Some(r)) => range.describe(r.is_texture()),
                    _ => "all".to_owned(),
                },
                states: match b.resource_before {
                    Some(before) => format!("{} -> ...", c.resource(before).name),
                    None if b.before.is_empty() && b.after.is_empty() => String::new(),
                    None => format!("{} -> {}", states(&b.before), states(&b.after)),
                },
                vulkan: b.vulkan.as_ref().map(|v| v.describe()).unwrap_or_default(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::model::Subresources;

    fn night_city() -> Capture {
        load("night_city/main_street_day.json")
    }

    fn load(capture: &str) -> Capture {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../captures")
            .join(capture);
        crate::pipeline::Validated::load(&path, &Default::default())
            .unwrap()
            .capture
    }

    #[test]
    fn cull_modes_are_read_bit_by_bit() {
        let words: Vec<&str> = (0..4).map(cull_mode).collect();
        assert_eq!(words, ["none", "front", "back", "both"]);
        assert_eq!(
            cull_mode(0x7fff_fffe),
            "back",
            "bits past the two are not cull bits"
        );
    }

    #[test]
    fn ranges_read_as_their_resource_kind() {
        let r = Subresources {
            mip_base: 1,
            mip_count: 2,
            layer_base: 0,
            layer_count: 6,
            byte_offset: 256,
            byte_size: 64,
        };
        assert_eq!(r.describe(true), "mips 1..3 layers 0..6");
        assert_eq!(r.describe(false), "bytes 256+64");
    }

    /// Every wait the capture declares is an edge from the one pass signalling its fence, in
    /// waiting order; the async compute queue's fences make some.
    #[test]
    fn fence_edges_join_each_wait_to_its_signal() {
        let c = night_city();
        let edges = c.fence_edges();
        let waits: usize = c.passes.iter().map(|p| p.wait.len()).sum();
        assert!(waits > 0, "the frame declares no waits");
        assert_eq!(edges.len(), waits);
        for (s, w) in &edges {
            let shared = c
                .pass(*w)
                .wait
                .iter()
                .any(|f| c.pass(*s).signal.contains(f));
            assert!(
                shared,
                "{} does not signal what {} waits on",
                c.pass(*s).name,
                c.pass(*w).name
            );
        }
        assert!(edges.windows(2).all(|e| e[0].1 <= e[1].1));
    }

    /// A pass's lines name what it does: its draws with their counts, its attachments with
    /// their load operations, its recorded barriers with their states.
    #[test]
    fn a_pass_reads_as_its_work_attachments_and_barriers() {
        let c = night_city();
        let raster = c
            .passes
            .iter()
            .find(|p| !p.draws.is_empty() && !p.color_attachments.is_empty())
            .unwrap();
        let work = work(&c, raster);
        assert_eq!(
            work.len(),
            raster.draws.len() + raster.copies.len() + raster.clears.len()
        );
        let slots = attachments(raster);
        assert_eq!(slots[0].slot, "color 0");
        assert_eq!(slots[0].resource, raster.color_attachments[0].resource);
        assert!(slots[0].text.contains("load "), "{}", slots[0].text);
        // The example records its barriers (Night City's are derived).
        let c = load("example/frame.json");
        let with_barrier = c.passes.iter().find(|p| !p.barriers.is_empty()).unwrap();
        let recorded = recorded_barriers(&c, with_barrier);
        assert_eq!(recorded.len(), with_barrier.barriers.len());
        assert!(
            recorded.iter().any(|b| b.states.contains(" -> ")),
            "{recorded:?}"
        );
    }
}
