//! The `vulkan` section of an imported capture: every name it uses resolves (pipeline ->
//! layout -> set layouts -> immutable samplers, stage -> module, draw or dispatch ->
//! pipeline of the right bind point), names are unique per kind, and each SPIR-V file is
//! there, of the size the module declares, starts with SPIR-V's magic number and has the
//! entry point each stage names for that stage.

use std::collections::{BTreeMap, BTreeSet};

use super::{JsonPath, Validator};
use std::sync::Arc;

use crate::capture::format::{
    MipLevels, PassKind, Resource, ResourceKind, VkCommandState, VkDescriptor, VkImageView,
    VulkanObjects,
};
use crate::capture::model::ResourceId;
use crate::capture::vk_model::*;
use crate::files;

/// Indices of the section's pipelines, image views and samplers by name: every draw and
/// dispatch names them, so each is looked up once, not searched for.
#[derive(Default)]
pub(super) struct VkNames {
    pipelines: std::collections::HashMap<String, usize>,
    views: std::collections::HashMap<String, usize>,
    samplers: std::collections::HashMap<String, usize>,
}

/// Each module's entry points and bytes, by name (`None` where the capture holds no code).
type ModuleCode<'v> = BTreeMap<&'v str, Option<(Vec<(u32, String)>, Vec<u8>)>>;

/// SPIR-V's magic number, the first word of every module.
const SPIRV_MAGIC: u32 = 0x0723_0203;
/// `OpEntryPoint`: execution model, function id, name, interface.
const OP_ENTRY_POINT: u32 = 15;

/// The `(execution model, name)` of every entry point of a SPIR-V module; `None` when the
/// words are not SPIR-V. Only `OpEntryPoint` is read: each instruction states its own word
/// count, so the walk needs nothing else of the grammar.
pub fn entry_points(bytes: &[u8]) -> Option<Vec<(u32, String)>> {
    if !bytes.len().is_multiple_of(4) || bytes.len() < 20 {
        return None;
    }
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if words[0] != SPIRV_MAGIC {
        return None;
    }
    let mut out = Vec::new();
    let mut at = 5;
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        if count == 0 || at + count > words.len() {
            return None;
        }
        if opcode == OP_ENTRY_POINT && count >= 4 {
            let text: Vec<u8> = words[at + 3..at + count]
                .iter()
                .flat_map(|w| w.to_le_bytes())
                .take_while(|b| *b != 0)
                .collect();
            out.push((words[at + 1], String::from_utf8_lossy(&text).into_owned()));
        }
        at += count;
    }
    Some(out)
}

/// The SPIR-V execution model of a `VK_SHADER_STAGE_*_BIT`.
fn execution_model(stage: &str) -> Option<u32> {
    Some(match stage {
        "VK_SHADER_STAGE_VERTEX_BIT" => 0,
        "VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT" => 1,
        "VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT" => 2,
        "VK_SHADER_STAGE_GEOMETRY_BIT" => 3,
        "VK_SHADER_STAGE_FRAGMENT_BIT" => 4,
        "VK_SHADER_STAGE_COMPUTE_BIT" => 5,
        _ => return None,
    })
}

/// Names of one kind, each once; a repeated one is an error at its path.
fn unique<'n>(
    v: &mut Validator<'_>,
    names: impl Iterator<Item = (&'n str, JsonPath)>,
    kind: &str,
) -> BTreeSet<&'n str> {
    let mut seen = BTreeSet::new();
    for (n, path) in names {
        if !seen.insert(n) {
            v.diags
                .error("vulkan", &path, format!("{kind} \"{n}\" is defined twice"));
        }
    }
    seen
}

impl Validator<'_> {
    pub(super) fn check_vulkan(&mut self) {
        let raw = self.raw;
        let root = self.root.field("vulkan");
        let resources: BTreeSet<&str> = raw.resources.iter().map(|r| r.name.as_str()).collect();
        let Some(vk) = &raw.vulkan else {
            self.check_descriptors(&resources, &BTreeSet::new(), &BTreeSet::new());
            self.check_pipeline_uses(None);
            return;
        };
        let samplers = unique(
            self,
            vk.samplers
                .iter()
                .enumerate()
                .map(|(i, s)| (s.name.as_str(), root.field("samplers").index(i))),
            "sampler",
        );
        let sets = unique(
            self,
            vk.set_layouts
                .iter()
                .enumerate()
                .map(|(i, s)| (s.name.as_str(), root.field("set_layouts").index(i))),
            "set layout",
        );
        let layouts = unique(
            self,
            vk.pipeline_layouts
                .iter()
                .enumerate()
                .map(|(i, s)| (s.name.as_str(), root.field("pipeline_layouts").index(i))),
            "pipeline layout",
        );
        unique(
            self,
            vk.pipelines
                .iter()
                .enumerate()
                .map(|(i, s)| (s.name.as_str(), root.field("pipelines").index(i))),
            "pipeline",
        );
        for (i, l) in vk.set_layouts.iter().enumerate() {
            for (j, b) in l.bindings.iter().enumerate() {
                for (k, s) in b.immutable_samplers.iter().enumerate() {
                    if !samplers.contains(s.as_str()) {
                        let p = root
                            .field("set_layouts")
                            .index(i)
                            .field("bindings")
                            .index(j)
                            .field("immutable_samplers")
                            .index(k);
                        self.diags
                            .error("vulkan", &p, format!("no sampler \"{s}\""));
                    }
                }
            }
        }
        for (i, l) in vk.pipeline_layouts.iter().enumerate() {
            for (j, s) in l.set_layouts.iter().enumerate() {
                if !sets.contains(s.as_str()) {
                    let p = root
                        .field("pipeline_layouts")
                        .index(i)
                        .field("set_layouts")
                        .index(j);
                    self.diags
                        .error("vulkan", &p, format!("no set layout \"{s}\""));
                }
            }
        }
        let views = unique(
            self,
            vk.image_views
                .iter()
                .enumerate()
                .map(|(i, v)| (v.name.as_str(), root.field("image_views").index(i))),
            "image view",
        );
        self.check_image_views(vk, &root);
        self.check_descriptors(&resources, &views, &samplers);
        let modules = self.check_modules(vk, &root);
        self.check_pipelines(vk, &root, &layouts, &modules);
        self.check_pipeline_uses(Some(vk));
        if !self.diags.has_errors() {
            let model = self.vk_model(vk, modules);
            let index = |names: Vec<&String>| {
                names
                    .into_iter()
                    .enumerate()
                    .map(|(i, n)| (n.clone(), i))
                    .collect()
            };
            self.vk_names = Some(VkNames {
                pipelines: index(vk.pipelines.iter().map(|p| &p.name).collect()),
                views: index(model.views.iter().map(|v| &v.name).collect()),
                samplers: index(model.samplers.iter().map(|s| &s.name).collect()),
            });
            self.vk_model = Some(model);
        }
    }

    /// Each image view names a resource, lies within it and swizzles by Vulkan's letters.
    fn check_image_views(&mut self, vk: &VulkanObjects, root: &JsonPath) {
        let raw = self.raw;
        for (i, v) in vk.image_views.iter().enumerate() {
            let path = root.field("image_views").index(i);
            if let Some(text) = &v.swizzle
                && swizzle(text).is_none()
            {
                self.diags.error(
                    "vulkan",
                    &path.field("swizzle"),
                    format!("swizzle {text:?} is not four of R, G, B, A, 0 and 1"),
                );
            }
            match self
                .resources
                .get(&v.image)
                .map(|r| &raw.resources[r as usize])
            {
                None => self.diags.error(
                    "vulkan",
                    &path.field("image"),
                    format!("no resource \"{}\"", v.image),
                ),
                Some(r) => {
                    if let Some(why) = view_outside(v, r) {
                        self.diags.error("vulkan", &path, why);
                    }
                }
            }
        }
    }

    /// Each pipeline names a known layout, and each stage a module with that entry point.
    fn check_pipelines(
        &mut self,
        vk: &VulkanObjects,
        root: &JsonPath,
        layouts: &BTreeSet<&str>,
        modules: &ModuleCode<'_>,
    ) {
        for (i, p) in vk.pipelines.iter().enumerate() {
            let path = root.field("pipelines").index(i);
            if !layouts.contains(p.layout.as_str()) {
                self.diags.error(
                    "vulkan",
                    &path.field("layout"),
                    format!("no pipeline layout \"{}\"", p.layout),
                );
            }
            for (j, st) in p.stages.iter().enumerate() {
                let sp = path.field("stages").index(j);
                match modules.get(st.module.as_str()) {
                    None => self.diags.error(
                        "vulkan",
                        &sp.field("module"),
                        format!("no shader module \"{}\"", st.module),
                    ),
                    // A module whose code the source did not hold cannot be checked further.
                    Some(None) => {}
                    Some(Some((entries, _))) => {
                        let model = execution_model(&st.stage);
                        if !entries
                            .iter()
                            .any(|(m, n)| *n == st.entry && model.is_none_or(|x| x == *m))
                        {
                            self.diags.error(
                                "vulkan",
                                &sp.field("entry"),
                                format!(
                                    "module \"{}\" has no {} entry point \"{}\"",
                                    st.module, st.stage, st.entry
                                ),
                            );
                        }
                    }
                }
            }
        }
    }

    /// The section by index, once every name in it is known to resolve.
    fn vk_model(&self, vk: &VulkanObjects, mut code: ModuleCode<'_>) -> VkModel {
        let index = |names: Vec<&str>| -> BTreeMap<String, usize> {
            names
                .into_iter()
                .enumerate()
                .map(|(i, n)| (n.to_owned(), i))
                .collect()
        };
        let samplers = index(vk.samplers.iter().map(|s| s.name.as_str()).collect());
        let sets = index(vk.set_layouts.iter().map(|s| s.name.as_str()).collect());
        let layouts = index(
            vk.pipeline_layouts
                .iter()
                .map(|s| s.name.as_str())
                .collect(),
        );
        let modules = index(vk.shader_modules.iter().map(|s| s.name.as_str()).collect());
        VkModel {
            modules: vk
                .shader_modules
                .iter()
                .map(|m| VkModule {
                    name: m.name.clone(),
                    file: m.file.clone(),
                    words: code.remove(m.name.as_str()).flatten().map(|(_, bytes)| {
                        Arc::new(
                            bytes
                                .chunks_exact(4)
                                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                                .collect(),
                        )
                    }),
                })
                .collect(),
            samplers: vk.samplers.clone(),
            views: vk
                .image_views
                .iter()
                .filter_map(|v| {
                    Some(VkView {
                        name: v.name.clone(),
                        image: ResourceId(self.resources.get(&v.image)?),
                        view_type: v.view_type.clone(),
                        format: v.format.clone(),
                        aspect: v.aspect,
                        base_mip: v.base_mip,
                        mips: v.mips,
                        base_layer: v.base_layer,
                        layers: v.layers,
                        swizzle: v.swizzle.as_deref().and_then(swizzle),
                    })
                })
                .collect(),
            set_layouts: vk
                .set_layouts
                .iter()
                .map(|l| VkSetLayout {
                    name: l.name.clone(),
                    flags: l.flags,
                    bindings: l.bindings.clone(),
                    immutable: l
                        .bindings
                        .iter()
                        .map(|b| {
                            b.immutable_samplers
                                .iter()
                                .filter_map(|s| samplers.get(s).copied())
                                .collect()
                        })
                        .collect(),
                })
                .collect(),
            pipeline_layouts: vk
                .pipeline_layouts
                .iter()
                .map(|l| VkPipelineLayout {
                    name: l.name.clone(),
                    sets: l
                        .set_layouts
                        .iter()
                        .filter_map(|s| sets.get(s).copied())
                        .collect(),
                    push_size: l
                        .push_constants
                        .iter()
                        .map(|r| r.offset.saturating_add(r.size))
                        .max()
                        .unwrap_or(0),
                })
                .collect(),
            pipelines: vk
                .pipelines
                .iter()
                .map(|p| VkPipeline {
                    name: p.name.clone(),
                    compute: p.bind_point.contains("COMPUTE"),
                    layout: layouts.get(&p.layout).copied().unwrap_or(0),
                    stages: p
                        .stages
                        .iter()
                        .filter_map(|s| {
                            Some(VkStage {
                                stage: s.stage.clone(),
                                module: modules.get(&s.module).copied()?,
                                entry: s.entry.clone(),
                                specialization: s
                                    .specialization
                                    .iter()
                                    .map(|c| (c.id, c.size, c.value))
                                    .collect(),
                            })
                        })
                        .collect(),
                    graphics: p.graphics.clone(),
                })
                .collect(),
        }
    }

    /// The Vulkan state of one draw or dispatch by index (`None` when it names no pipeline or
    /// the capture has no `vulkan` section).
    pub(super) fn vk_work(
        &self,
        pipeline: Option<&str>,
        state: &VkCommandState,
    ) -> Option<Box<VkWork>> {
        let names = self.vk_names.as_ref()?;
        let pipeline = *names.pipelines.get(pipeline?)?;
        let resource = |n: &str| self.resources.get(n).map(ResourceId);
        let descriptors = state
            .descriptors
            .iter()
            .map(|d| VkBound {
                set: d.set,
                binding: d.binding,
                element: d.element,
                descriptor_type: d.descriptor_type.clone(),
                resource: d.resource.as_deref().and_then(resource),
                view: d.view.as_deref().and_then(|v| names.views.get(v).copied()),
                sampler: d
                    .sampler
                    .as_deref()
                    .and_then(|v| names.samplers.get(v).copied()),
                offset: d.offset,
                range: d.range,
                format: d.format.clone(),
            })
            .collect();
        Some(Box::new(VkWork {
            pipeline,
            viewport: state.viewport,
            scissor: state.scissor,
            blend_constants: state.blend_constants,
            stencil_reference: state.stencil_reference,
            dynamic: state.dynamic.clone(),
            push_constants: state.push_constants.as_deref().and_then(hex_bytes),
            descriptors,
            vertex_buffers: state
                .vertex_buffers
                .iter()
                .filter_map(|v| Some((v.binding, resource(&v.resource)?, v.offset)))
                .collect(),
            index_buffer: state.index_buffer.as_ref().and_then(|i| {
                Some((
                    resource(&i.resource)?,
                    i.offset,
                    i.index_type.ends_with("UINT32"),
                ))
            }),
        }))
    }

    /// Each module's entry points, read from its file (`None` where there is no file).
    fn check_modules<'v>(&mut self, vk: &'v VulkanObjects, root: &JsonPath) -> ModuleCode<'v> {
        let mut out = BTreeMap::new();
        for (i, m) in vk.shader_modules.iter().enumerate() {
            let path = root.field("shader_modules").index(i);
            if out.contains_key(m.name.as_str()) {
                self.diags.error(
                    "vulkan",
                    &path,
                    format!("shader module \"{}\" is defined twice", m.name),
                );
            }
            let entries = m.file.as_ref().and_then(|rel| {
                let fp = path.field("file");
                let full = self.side_file(rel, &fp)?;
                let bytes = match files::read(&full, files::side_file(m.size)) {
                    Ok(b) => b,
                    Err(e) => {
                        self.diags.error("side-file", &fp, e.to_string());
                        return None;
                    }
                };
                if bytes.len() as u64 != m.size {
                    self.diags.error(
                        "side-file",
                        &fp,
                        format!("\"{rel}\" has {} bytes; module \"{}\" is {} bytes", bytes.len(), m.name, m.size),
                    );
                    return None;
                }
                let entries = entry_points(&bytes);
                if entries.is_none() {
                    self.diags.error("side-file", &fp, format!("\"{rel}\" is not SPIR-V (no magic number, or an instruction runs past the end)"));
                }
                entries.map(|e| (e, bytes))
            });
            out.insert(m.name.as_str(), entries);
        }
        out
    }

    /// Every descriptor a draw or dispatch carries names a resource, image view and sampler
    /// that exist.
    fn check_descriptors(
        &mut self,
        resources: &BTreeSet<&str>,
        views: &BTreeSet<&str>,
        samplers: &BTreeSet<&str>,
    ) {
        let raw = self.raw;
        let buffer_sizes: BTreeMap<&str, u64> = raw
            .resources
            .iter()
            .filter(|r| r.kind == ResourceKind::Buffer)
            .filter_map(|r| Some((r.name.as_str(), r.size?)))
            .collect();
        for (i, pass) in raw.passes.iter().enumerate() {
            let path = self.root.field("passes").index(i);
            let states = pass
                .draws
                .iter()
                .enumerate()
                .map(|(j, d)| (&d.vulkan_state, path.field("draws").index(j)))
                .chain(
                    pass.dispatches
                        .iter()
                        .enumerate()
                        .map(|(j, d)| (&d.vulkan_state, path.field("dispatches").index(j))),
                );
            for (state, p) in states {
                let sp = p.field("vulkan_state");
                if let Some(hex) = &state.push_constants
                    && hex_bytes(hex).is_none()
                {
                    self.diags.error(
                        "vulkan",
                        &sp.field("push_constants"),
                        "push constants must be hex digits, two per byte",
                    );
                }
                let buffers = state
                    .vertex_buffers
                    .iter()
                    .enumerate()
                    .map(|(k, v)| (&v.resource, sp.field("vertex_buffers").index(k)))
                    .chain(
                        state
                            .index_buffer
                            .iter()
                            .map(|i| (&i.resource, sp.field("index_buffer"))),
                    );
                for (name, bp) in buffers {
                    if !resources.contains(name.as_str()) {
                        self.diags.error(
                            "vulkan",
                            &bp.field("resource"),
                            format!("no resource \"{name}\""),
                        );
                    }
                }
                if let Some(i) = &state.index_buffer
                    && !matches!(
                        i.index_type.as_str(),
                        "VK_INDEX_TYPE_UINT16" | "VK_INDEX_TYPE_UINT32"
                    )
                {
                    self.diags.error(
                        "vulkan",
                        &sp.field("index_buffer").field("index_type"),
                        format!(
                            "index type \"{}\" is not VK_INDEX_TYPE_UINT16 or VK_INDEX_TYPE_UINT32",
                            i.index_type
                        ),
                    );
                }
                for (k, d) in state.descriptors.iter().enumerate() {
                    let dp = p.field("vulkan_state").field("descriptors").index(k);
                    let checks = [
                        (d.resource.as_deref(), resources, "resource", "resource"),
                        (d.view.as_deref(), views, "view", "image view"),
                        (d.sampler.as_deref(), samplers, "sampler", "sampler"),
                    ];
                    if let Some(why) = descriptor_outside(d, &buffer_sizes) {
                        self.diags.error("vulkan", &dp, why);
                    }
                    for (name, known, field, kind) in checks {
                        if let Some(n) = name
                            && !known.contains(n)
                        {
                            self.diags.error(
                                "vulkan",
                                &dp.field(field),
                                format!("no {kind} \"{n}\""),
                            );
                        }
                    }
                }
            }
        }
    }

    /// Every draw names a graphics pipeline and every dispatch a compute one, when they name
    /// one.
    fn check_pipeline_uses(&mut self, vk: Option<&VulkanObjects>) {
        let points: BTreeMap<&str, &str> = vk
            .map(|v| {
                v.pipelines
                    .iter()
                    .map(|p| (p.name.as_str(), p.bind_point.as_str()))
                    .collect()
            })
            .unwrap_or_default();
        let raw = self.raw;
        for (i, pass) in raw.passes.iter().enumerate() {
            let path = self.root.field("passes").index(i);
            let named = pass
                .draws
                .iter()
                .enumerate()
                .map(|(j, d)| {
                    (
                        d.pipeline.as_deref(),
                        path.field("draws").index(j),
                        "VK_PIPELINE_BIND_POINT_GRAPHICS",
                    )
                })
                .chain(pass.dispatches.iter().enumerate().map(|(j, d)| {
                    (
                        d.pipeline.as_deref(),
                        path.field("dispatches").index(j),
                        "VK_PIPELINE_BIND_POINT_COMPUTE",
                    )
                }));
            for (name, p, want) in named {
                let Some(name) = name else { continue };
                match points.get(name) {
                    None => self.diags.error(
                        "vulkan",
                        &p.field("pipeline"),
                        format!("no pipeline \"{name}\" in `vulkan.pipelines`"),
                    ),
                    Some(point) if *point != want => self.diags.error(
                        "vulkan",
                        &p.field("pipeline"),
                        format!(
                            "pipeline \"{name}\" binds to {point}; a {} needs {want}",
                            if pass.kind == PassKind::Compute {
                                "dispatch"
                            } else {
                                "draw"
                            }
                        ),
                    ),
                    Some(_) => {}
                }
            }
        }
    }
}

/// No device binds more descriptor sets than this (`maxBoundDescriptorSets` is 4-32).
const MAX_SETS: u32 = 32;

/// Why descriptor `d` cannot be: a set no device binds, or bytes past its buffer's end
/// (`range` may be `VK_WHOLE_SIZE`, `u64::MAX`: the rest of the buffer).
fn descriptor_outside(d: &VkDescriptor, buffer_sizes: &BTreeMap<&str, u64>) -> Option<String> {
    if d.set >= MAX_SETS {
        return Some(format!(
            "set {} is past the {MAX_SETS} sets any device binds",
            d.set
        ));
    }
    let size = *buffer_sizes.get(d.resource.as_deref()?)?;
    let offset = d.offset.unwrap_or(0);
    let end = match d.range {
        Some(u64::MAX) | None => offset,
        Some(r) => offset.saturating_add(r),
    };
    (offset > size || end > size).then(|| {
        format!(
            "binds bytes {offset}..{end} of \"{}\", which holds {size}",
            d.resource.as_deref().unwrap_or_default()
        )
    })
}

/// Why view `v` reaches past the mip levels or layers of `r`, where the capture states them.
fn view_outside(v: &VkImageView, r: &Resource) -> Option<String> {
    // Vulkan's `levelCount` and `layerCount` are never 0.
    for (what, count) in [("mip levels", v.mips), ("layers", v.layers)] {
        if count == Some(0) {
            return Some(format!("view \"{}\" takes 0 {what}", v.name));
        }
    }
    let range = |what: &str, base: u32, count: Option<u32>, total: u32| {
        let end = u64::from(base) + u64::from(count.unwrap_or(1).max(1));
        (end > u64::from(total)).then(|| {
            format!(
                "view \"{}\" reaches {what} {base}..{end} of \"{}\", which has {total}",
                v.name, r.name
            )
        })
    };
    let mips = match r.mip_levels {
        Some(MipLevels::Count(n)) => range("mip levels", v.base_mip, v.mips, n),
        None => range("mip levels", v.base_mip, v.mips, 1),
        Some(MipLevels::Chain(_)) => None,
    };
    let layers = match r.kind {
        ResourceKind::Texture3D | ResourceKind::Buffer => None,
        ResourceKind::TextureCube => range(
            "layers",
            v.base_layer,
            v.layers,
            r.array_layers.unwrap_or(6),
        ),
        _ => range(
            "layers",
            v.base_layer,
            v.layers,
            r.array_layers.unwrap_or(1),
        ),
    };
    mips.or(layers)
}

/// Push-constant bytes from their hex spelling; `None` for text that is not whole hex bytes
/// (validation reports it).
fn hex_bytes(text: &str) -> Option<Vec<u8>> {
    hex::decode(text).ok()
}

/// A view's `swizzle` as four components; `None` for text that is not four of `RGBA01`
/// (reported by `check_views`).
fn swizzle(text: &str) -> Option<[crate::capture::vk_model::Component; 4]> {
    let c: Vec<_> = text
        .chars()
        .map(crate::capture::vk_model::Component::of)
        .collect::<Option<_>>()?;
    c.try_into().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_points_of_a_minimal_module() {
        // Header, then OpEntryPoint GLCompute %1 "main".
        let name = u32::from_le_bytes(*b"main");
        let words = [
            SPIRV_MAGIC,
            0x0001_0000,
            0,
            2,
            0,
            (5 << 16) | 15,
            5,
            1,
            name,
            0,
        ];
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        assert_eq!(entry_points(&bytes), Some(vec![(5, "main".to_owned())]));
        assert_eq!(entry_points(&bytes[..bytes.len() - 4]), None);
        let mut bad = bytes.clone();
        bad[0] = 0;
        assert_eq!(entry_points(&bad), None);
    }
}
