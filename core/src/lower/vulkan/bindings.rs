//! Bind groups of one imported draw or dispatch: the descriptors its pipeline's shaders use
//! (by reflection), each checked against the captured set layout and turned into wgpu layout
//! entries and bound resources. Descriptors no shader uses are left out, as Vulkan lets them
//! be; one a shader uses and the draw lacks is an error.

use std::collections::BTreeMap;

use wgpu_types as wgpu;

use super::{Fail, VkProblem, stage_of, states};
use crate::capture::model::*;
use crate::capture::vk_model::*;
use crate::lower::Lowering;
use crate::plan::*;
use crate::spirv::{ResourceKind, ResourceVar};

/// The wgpu bindings of each set, sorted: the rewrite numbers SPIR-V bindings by them.
pub(super) type SetBindings = BTreeMap<u32, Vec<u32>>;

/// What the rewrite needs of a draw's bindings: the wgpu bindings of each set, and the format
/// of each uniform texel buffer (its buffer view's, which the shader does not state).
pub(super) struct Bound {
    pub sets: SetBindings,
    pub texel_formats: Vec<(u32, u32, rspirv::spirv::ImageFormat)>,
    /// The LOD bias (as bits) of the sampler at each (set, binding) where it changes what is
    /// read: the rewrite adds it to the shader's samples.
    pub lod_bias: Vec<(u32, u32, u32)>,
    /// The component swizzle of the sampled view at each (set, binding) where it is not the
    /// identity, as `spirv::RewriteOptions::swizzles` codes: the rewrite applies it.
    pub swizzles: Vec<(u32, u32, [u8; 4])>,
    /// The uniform blocks laid out past std140, bound as read-only storage buffers: the
    /// rewrite reads them as storage blocks (`spirv::RewriteOptions::storage_blocks`).
    pub storage_blocks: Vec<(u32, u32)>,
    /// The uniform blocks whose only breaks of std140 are arrays of 32-bit scalars: the rewrite
    /// widens those to vectors (`spirv::RewriteOptions::std140_blocks`) and they stay uniform.
    pub std140_blocks: Vec<(u32, u32)>,
    /// The samplers that take unnormalized coordinates (`spirv::RewriteOptions::unnormalized`):
    /// wgpu's take normalized ones, so the rewrite divides each sample's coordinate.
    pub unnormalized: Vec<(u32, u32, bool)>,
    /// The samplers that mirror once and clamp on some axes (`spirv::RewriteOptions::
    /// mirror_once`): wgpu has no such address mode, so the rewrite mirrors the coordinate.
    pub mirror_once: Vec<(u32, u32, u8)>,
    /// The wgpu binding (before the doubling that makes room for split samplers) of each
    /// element past the first of a split descriptor array, by (set, binding the split gave):
    /// numbered on past the set layout's highest binding, in order.
    pub elements: BTreeMap<(u32, u32), u32>,
}

/// The number that stands for Vulkan binding `b` of `set` in wgpu's bindings (doubled, and
/// one more for a split sampler): itself, or where `b` is an element of a split descriptor
/// array past the first, its number in `elements`.
pub(super) fn wgpu_base(elements: &BTreeMap<(u32, u32), u32>, set: u32, b: u32) -> u32 {
    elements.get(&(set, b)).copied().unwrap_or(b)
}

/// The SPIR-V image format a texel buffer view of `VK_FORMAT_*` reads in, where the rewrite
/// unpacks it.
fn texel_format(vk: &str) -> Option<rspirv::spirv::ImageFormat> {
    use rspirv::spirv::ImageFormat as F;
    Some(match vk.strip_prefix("VK_FORMAT_").unwrap_or(vk) {
        "R8_UNORM" => F::R8,
        "R8_UINT" => F::R8ui,
        "R8G8_UNORM" => F::Rg8,
        "R8G8_UINT" => F::Rg8ui,
        "R8G8B8A8_UNORM" => F::Rgba8,
        "R8G8B8A8_UINT" => F::Rgba8ui,
        "R16_UNORM" => F::R16,
        "R16_UINT" => F::R16ui,
        "R16G16_UNORM" => F::Rg16,
        "R16G16_UINT" => F::Rg16ui,
        "R32_SFLOAT" => F::R32f,
        "R32_UINT" => F::R32ui,
        "R32_SINT" => F::R32i,
        "R32G32_SFLOAT" => F::Rg32f,
        "R32G32_UINT" => F::Rg32ui,
        "R32G32_SINT" => F::Rg32i,
        "R32G32B32A32_SFLOAT" => F::Rgba32f,
        "R32G32B32A32_UINT" => F::Rgba32ui,
        "R32G32B32A32_SINT" => F::Rgba32i,
        _ => return None,
    })
}

/// One used descriptor: its variable, and every stage that uses it.
struct Used {
    var: ResourceVar,
    stages: wgpu::ShaderStages,
    shader: String,
    /// A uniform block some stage lays out past std140: bound as a read-only storage buffer.
    as_storage: bool,
    /// A uniform block whose scalar arrays every stage's rewrite widens to std140 instead.
    widen: bool,
}

type Entry = (wgpu::BindGroupLayoutEntry, VkResource);

impl<'c> Lowering<'c> {
    /// The reflection of module `m` for entry point `entry`, read once: the descriptors the
    /// functions it reaches use.
    pub(super) fn vk_reflect(
        &mut self,
        m: usize,
        entry: &str,
    ) -> Result<&crate::spirv::Reflection, Fail> {
        let key = (m, entry.to_owned());
        if !self.vk.reflections.contains_key(&key) {
            let words = self.vk_words(m)?;
            let name = &self.vk_model()?.modules[m].name;
            let spirv = |error| VkProblem::Spirv {
                shader: name.clone(),
                error,
            };
            let mut r = crate::spirv::reflect(&words).map_err(spirv)?;
            let usages = crate::spirv::usage_by_entry(&words).map_err(spirv)?;
            // A descriptor the entry point's code never names is no binding of the draw's:
            // Vulkan lets the set hold anything there, and the rewrite removes the variable.
            if let Some(usages) = usages.get(entry) {
                r.resources
                    .retain(|v| usages.get(&(v.set, v.binding)).is_none_or(|u| u.used));
            }
            self.vk.reflections.insert(key.clone(), r);
        }
        Ok(&self.vk.reflections[&key])
    }

    /// Module `m`'s words as the lowering reads them: with its descriptor arrays split into
    /// one variable per element (`spirv::arrays`), each element's binding made by
    /// `spirv::element_binding`.
    pub(super) fn vk_words(&mut self, m: usize) -> Result<std::sync::Arc<Vec<u32>>, Fail> {
        let model = self.vk_model()?;
        let module = &model.modules[m];
        let words = module.words.as_ref().ok_or_else(|| VkProblem::NoCode {
            module: module.name.clone(),
        })?;
        let split = match self.vk.split_words.entry(m) {
            std::collections::btree_map::Entry::Occupied(e) => e.get().clone(),
            std::collections::btree_map::Entry::Vacant(e) => {
                let split = crate::spirv::split_descriptor_arrays(words).map_err(|error| {
                    VkProblem::Spirv {
                        shader: module.name.clone(),
                        error,
                    }
                })?;
                e.insert(split.map(std::sync::Arc::new)).clone()
            }
        };
        Ok(split.unwrap_or_else(|| words.clone()))
    }

    pub(super) fn vk_groups(
        &mut self,
        p: &PassDesc,
        pipe: &VkPipeline,
        work: &VkWork,
    ) -> Result<(Vec<Option<VkGroup>>, Bound), Fail> {
        let model = self.vk_model()?;
        let mut used = self.vk_used(pipe)?;
        let layout = &model.pipeline_layouts[pipe.layout];
        let mut per_set: BTreeMap<u32, Vec<Entry>> = BTreeMap::new();
        let mut texel_formats = Vec::new();
        let mut lod_bias = Vec::new();
        let mut unnormalized = Vec::new();
        let mut mirror_once = Vec::new();
        let mut swizzles = Vec::new();
        let mut storage_blocks = Vec::new();
        let mut std140_blocks = Vec::new();
        let mut elements = BTreeMap::new();
        for (&(set, split_binding), u) in used.iter_mut() {
            // An element of a split array (`spirv::arrays`) is that array's descriptor there.
            let (binding, element) = crate::spirv::binding_element(split_binding);
            // One stage that cannot widen the block makes it a storage buffer for all.
            u.widen &= !u.as_storage;
            if u.as_storage {
                storage_blocks.push((set, split_binding));
            } else if u.widen {
                std140_blocks.push((set, split_binding));
            }
            let lb = layout
                .sets
                .get(set as usize)
                .map(|&s| &model.set_layouts[s])
                .and_then(|l| {
                    let i = l.bindings.iter().position(|b| b.binding == binding)?;
                    Some((&l.bindings[i], l.immutable[i].get(element as usize).copied()))
                })
                .ok_or_else(|| {
                    VkProblem::Missing(format!(
                        "shader {} uses set {set} binding {binding}, which pipeline layout {} lacks",
                        u.shader, layout.name
                    ))
                })?;
            if u.var.count.is_some_and(|n| n != 1) {
                return Err(VkProblem::Unsupported {
                    feature: format!(
                        "a descriptor array of unbounded length (set {set} binding {binding}) in shader {}",
                        u.shader
                    ),
                }
                .into());
            }
            if element >= lb.0.count {
                return Err(VkProblem::Missing(format!(
                    "shader {} uses element {element} of set {set} binding {binding}, which the set layout gives {} descriptors",
                    u.shader, lb.0.count
                ))
                .into());
            }
            let base = if element == 0 {
                binding
            } else {
                let base =
                    split_element_binding(model, layout, &elements, (set, split_binding), u)?;
                elements.insert((set, split_binding), base);
                base
            };
            let at = |d: &&VkBound| d.set == set && d.binding == binding && d.element == element;
            if matches!(u.var.kind, ResourceKind::UniformTexelBuffer) {
                let f = texel_view_format(
                    work.descriptors.iter().find(at),
                    (set, binding, element),
                    u,
                )?;
                texel_formats.push((set, split_binding, f));
            }
            if let Some(takes) = descriptor_types_of(&u.var.kind) {
                let declared =
                    lb.0.descriptor_type
                        .strip_prefix("VK_DESCRIPTOR_TYPE_")
                        .unwrap_or(&lb.0.descriptor_type);
                if !takes.contains(&declared) {
                    return Err(VkProblem::Missing(format!(
                        "shader {} reads set {set} binding {binding} as {}, which a {declared} descriptor of the set layout is not (VUID-VkGraphicsPipelineCreateInfo-layout-07990)",
                        u.shader,
                        takes.join(" or ")
                    ))
                    .into());
                }
            }
            let d = work.descriptors.iter().find(at);
            let (entries, bias) = self.vk_entries(p, d, (set, binding, element, base), u, lb)?;
            if let Some(bias) = bias {
                lod_bias.push((set, split_binding, bias.to_bits()));
            }
            let sampler = d.and_then(|d| d.sampler).or(lb.1);
            let samples = entries
                .iter()
                .any(|(_, r)| matches!(r, VkResource::Sampler(_)));
            if let Some(s) =
                sampler.filter(|&s| samples && model.samplers[s].unnormalized_coordinates)
            {
                // Vulkan allows such a sampler one filter for both.
                let nearest = model.samplers[s].mag_filter.ends_with("NEAREST");
                unnormalized.push((set, split_binding, nearest));
            }
            if let Some(axes) = sampler
                .filter(|_| samples)
                .map(|s| super::states::mirror_once_axes(&model.samplers[s]))
                .filter(|&a| a != 0)
            {
                mirror_once.push((set, split_binding, axes));
            }
            let permutation = d
                .and_then(|d| d.view)
                .and_then(|v| self.vk_view_permutation(v));
            if let Some(sw) = sampled_swizzle(model, d, &lb.0.descriptor_type, permutation) {
                swizzles.push((set, split_binding, sw));
            }
            per_set.entry(set).or_default().extend(entries);
        }
        let (groups, sets) = self.vk_group_layouts(per_set);
        Ok((
            groups,
            Bound {
                sets,
                texel_formats,
                lod_bias,
                swizzles,
                storage_blocks,
                std140_blocks,
                unnormalized,
                mirror_once,
                elements,
            },
        ))
    }

    /// Each (set, binding) the pipeline's stages use: the stages, the variable as every
    /// stage declares it, and whether a uniform block is widened or read as storage.
    fn vk_used(&mut self, pipe: &VkPipeline) -> Result<BTreeMap<(u32, u32), Used>, Fail> {
        let model = self.vk_model()?;
        let mut used: BTreeMap<(u32, u32), Used> = BTreeMap::new();
        for stage in &pipe.stages {
            let (s, _) = stage_of(&stage.stage)?;
            let shader = model.modules[stage.module].name.clone();
            for var in &self.vk_reflect(stage.module, &stage.entry)?.resources {
                used.entry((var.set, var.binding))
                    .and_modify(|u| {
                        u.stages |= s;
                        u.var.non_writable &= var.non_writable;
                        u.var.non_readable &= var.non_readable;
                        u.var.block_size = u.var.block_size.max(var.block_size);
                    })
                    .or_insert_with(|| Used {
                        var: var.clone(),
                        stages: s,
                        shader: shader.clone(),
                        as_storage: false,
                        widen: false,
                    });
            }
            for b in self.vk_beyond_std140(stage.module)? {
                if let Some(u) = used.get_mut(&(b.set, b.binding)) {
                    if let Some(end) = b.widened_end {
                        u.var.block_size = u.var.block_size.max(Some(end));
                        u.widen = true;
                        continue;
                    }
                    if let Some(why) = &b.beyond_std430 {
                        return Err(VkProblem::Unsupported {
                        feature: format!(
                            "a uniform block in scalar layout (set {} binding {} of shader {shader}: {}, and {why}; a storage buffer reads by std430's rules, and scalar layout needs a device feature wgpu does not enable)",
                            b.set, b.binding, b.problem
                        ),
                    }
                    .into());
                    }
                    u.as_storage = true;
                }
            }
        }
        Ok(used)
    }

    /// The bind group of each set, its layout shared with every equal one of the plan.
    fn vk_group_layouts(
        &mut self,
        per_set: BTreeMap<u32, Vec<Entry>>,
    ) -> (Vec<Option<VkGroup>>, SetBindings) {
        let last = per_set.keys().next_back().map_or(0, |&s| s as usize + 1);
        let mut groups = vec![None; last];
        let mut sets = SetBindings::new();
        for (set, mut entries) in per_set {
            entries.sort_by_key(|(e, _)| e.binding);
            let layout_entries: Vec<wgpu::BindGroupLayoutEntry> =
                entries.iter().map(|(e, _)| *e).collect();
            let index = match self
                .plan
                .vk
                .group_layouts
                .iter()
                .position(|l| *l == layout_entries)
            {
                Some(i) => i,
                None => {
                    self.plan.vk.group_layouts.push(layout_entries.clone());
                    self.plan.vk.group_layouts.len() - 1
                }
            };
            sets.insert(set, layout_entries.iter().map(|e| e.binding).collect());
            groups[set as usize] = Some(VkGroup {
                layout: index,
                entries: entries.into_iter().map(|(e, r)| (e.binding, r)).collect(),
            });
        }
        (groups, sets)
    }

    /// The uniform blocks of module `m` laid out past std140, found once.
    fn vk_beyond_std140(&mut self, m: usize) -> Result<Vec<crate::spirv::BeyondStd140>, Fail> {
        if !self.vk.beyond_std140.contains_key(&m) {
            let words = self.vk_words(m)?;
            let found = crate::spirv::uniform_blocks_beyond_std140(&words);
            self.vk.beyond_std140.insert(m, found);
        }
        Ok(self.vk.beyond_std140[&m].clone())
    }

    /// The wgpu entries (one, or a texture and a sampler) of one used descriptor, and the LOD
    /// bias of its sampler where the shader must add it.
    fn vk_entries(
        &mut self,
        p: &PassDesc,
        d: Option<&VkBound>,
        (set, binding, element, base): (u32, u32, u32, u32),
        u: &Used,
        (lb, immutable): (&crate::capture::format::LayoutBinding, Option<usize>),
    ) -> Result<(Vec<Entry>, Option<f32>), Fail> {
        let mut bias = None;
        let ty = lb
            .descriptor_type
            .strip_prefix("VK_DESCRIPTOR_TYPE_")
            .unwrap_or(&lb.descriptor_type);
        let missing = || {
            VkProblem::Missing(format!(
                "shader {} uses set {set} binding {binding} ({ty}), and the draw has nothing bound there",
                u.shader
            ))
        };
        let null = |what: &str| super::blanks::refused(what, (set, binding, element), &u.shader);
        let entry = |b: u32, ty: wgpu::BindingType| wgpu::BindGroupLayoutEntry {
            binding: b,
            visibility: u.stages,
            ty,
            count: None,
        };
        let wb = base * 2;
        let entries = match ty {
            "UNIFORM_BUFFER"
            | "UNIFORM_BUFFER_DYNAMIC"
            | "STORAGE_BUFFER"
            | "STORAGE_BUFFER_DYNAMIC" => {
                let d = d.ok_or_else(missing)?;
                let (kind, resource) =
                    self.vk_buffer_binding(p, d, ty, (set, binding, element), u)?;
                vec![(
                    entry(
                        wb,
                        wgpu::BindingType::Buffer {
                            ty: kind,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                    ),
                    resource,
                )]
            }
            // Read as words: the rewrite unpacks each texel (`crate::spirv`).
            "STORAGE_TEXEL_BUFFER" | "UNIFORM_TEXEL_BUFFER" => {
                let d = d.ok_or_else(missing)?;
                let Some(r) = d.resource else {
                    return Err(null(ty));
                };
                let buffer = self.buf(p, r)?;
                vec![(
                    entry(
                        wb,
                        wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Storage { read_only: true },
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                    ),
                    VkResource::Buffer {
                        buffer,
                        offset: d.offset.unwrap_or(0),
                        // Whole words: the buffer itself is padded to them.
                        size: d
                            .range
                            .filter(|&r| r != u64::MAX)
                            .map(|r| r.div_ceil(4) * 4),
                    },
                )]
            }
            "SAMPLER" => {
                let s = d
                    .and_then(|d| d.sampler)
                    .or(immutable)
                    .ok_or_else(missing)?;
                // A separate sampler meets its views in the shader: any view may be mipped.
                bias = self.vk_bias(s, None);
                vec![self.vk_sampler_entry(wb, u.stages, s, None)?]
            }
            // An input attachment is read as a texture at the fragment's position
            // (`spirv::subpass`): the subpass that wrote it is a render pass of its own.
            "SAMPLED_IMAGE" | "COMBINED_IMAGE_SAMPLER" | "INPUT_ATTACHMENT" => {
                let d = d.ok_or_else(missing)?;
                let (ty, resource) = match d.view {
                    Some(view) => self.vk_texture(p, view, &u.var, false)?,
                    None if ty == "INPUT_ATTACHMENT" => return Err(null(ty)),
                    None => {
                        let compares = d.sampler.or(immutable).is_some_and(|s| {
                            self.vk_model()
                                .is_ok_and(|m| m.samplers[s].compare_op.is_some())
                        });
                        self.vk_blank_sampled(
                            p,
                            (set, binding, element),
                            &u.var,
                            &u.shader,
                            compares,
                        )?
                    }
                };
                let (levels, cube, texture) = texture_facts(&resource, &self.plan.textures);
                let mut out = vec![(entry(wb, ty), resource)];
                if ty_is_combined(&lb.descriptor_type) {
                    let s = d.sampler.or(immutable).ok_or_else(missing)?;
                    if cube {
                        self.vk_seamless(s)?;
                    }
                    bias = self.vk_bias(s, Some(levels));
                    out.push(self.vk_sampler_entry(wb + 1, u.stages, s, texture)?);
                }
                out
            }
            "STORAGE_IMAGE" => match d.and_then(|d| d.view) {
                Some(view) => {
                    let (ty, resource) = self.vk_texture(p, view, &u.var, true)?;
                    vec![(entry(wb, ty), resource)]
                }
                None => {
                    let (ty, resource) = self
                        .vk_blank_storage(p, (set, binding, element), &u.var)
                        .ok_or_else(missing)?;
                    vec![(entry(wb, ty), resource)]
                }
            },
            other => {
                return Err(VkProblem::Unsupported {
                    feature: format!(
                        "{other} descriptors (set {set} binding {binding} of shader {})",
                        u.shader
                    ),
                }
                .into());
            }
        };
        Ok((entries, bias))
    }

    /// A uniform or storage buffer descriptor: how wgpu binds it (a uniform block that
    /// cannot be widened to std140 is read as storage) and the range bound, a null descriptor
    /// reading a blank buffer.
    fn vk_buffer_binding(
        &mut self,
        p: &PassDesc,
        d: &VkBound,
        ty: &str,
        at: (u32, u32, u32),
        u: &Used,
    ) -> Result<(wgpu::BufferBindingType, VkResource), Fail> {
        let kind = if ty.starts_with("UNIFORM") && !u.as_storage {
            wgpu::BufferBindingType::Uniform
        } else {
            wgpu::BufferBindingType::Storage {
                read_only: u.var.non_writable || u.as_storage,
            }
        };
        let buffer = match d.resource {
            Some(r) => self.buf(p, r)?,
            None => self.vk_blank_buffer(p, at, &u.var),
        };
        if u.as_storage {
            self.plan.buffers[buffer].usage |= wgpu::BufferUsages::STORAGE;
        }
        let resource = VkResource::Buffer {
            buffer,
            offset: d.offset.unwrap_or(0),
            // A uniform block's size is whole 16-byte steps (std140) where a program may bind
            // only to its last member's end, or less than the block where the shader reads
            // only the start (Vulkan asks only that reads stay inside the range); wgpu asks
            // for the whole block. The replay pads past the buffer's end.
            size: d.range.filter(|&r| r != u64::MAX).map(|r| {
                let r = r.max(u.var.block_size.unwrap_or(0));
                if matches!(kind, wgpu::BufferBindingType::Uniform) {
                    r.div_ceil(16) * 16
                } else {
                    r
                }
            }),
        };
        Ok((kind, resource))
    }

    /// Refuses sampler `s` on a cube map where it filters within each face
    /// (`VK_SAMPLER_CREATE_NON_SEAMLESS_CUBE_MAP_BIT_EXT`) and filters linearly: wgpu filters
    /// across the faces' edges. With nearest filters every texel read is the same.
    fn vk_seamless(&self, s: usize) -> Result<(), Fail> {
        let sampler = &self.vk_model()?.samplers[s];
        let linear = |f: &str| f.ends_with("LINEAR");
        if sampler.non_seamless_cube && (linear(&sampler.mag_filter) || linear(&sampler.min_filter))
        {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a cube map filtered linearly within each face (sampler {} with VK_SAMPLER_CREATE_NON_SEAMLESS_CUBE_MAP_BIT_EXT): wgpu filters cube maps across their faces",
                    sampler.name
                ),
            }
            .into());
        }
        Ok(())
    }

    /// Sampler `s`'s LOD bias where it would change what is read through a view of `levels`
    /// mip levels (`None`: not known here): the shader then adds it (`spirv::bias`).
    fn vk_bias(&self, s: usize, levels: Option<u32>) -> Option<f32> {
        let sampler = &self.vk_model().ok()?.samplers[s];
        (!states::bias_is_moot(sampler, levels.unwrap_or(u32::MAX))).then_some(sampler.mip_lod_bias)
    }

    /// Sampler `s`'s binding; `texture`, the plan texture a combined image sampler pairs it
    /// with. A depth or stencil texture read through a linear sampler that does not compare
    /// is read nearest: no format of those aspects need be filterable (lavapipe's are not;
    /// `VUID-vkCmdDraw-magFilter-04553`, which vkBasalt's depth effects break), and where the
    /// driver filters anyway its reads at texel centres are the nearest texel's.
    fn vk_sampler_entry(
        &mut self,
        binding: u32,
        visibility: wgpu::ShaderStages,
        s: usize,
        texture: Option<usize>,
    ) -> Result<Entry, Fail> {
        let model = self.vk_model()?;
        let sampler = &model.samplers[s];
        let comparison = sampler.compare_op.is_some();
        let linear = [&sampler.mag_filter, &sampler.min_filter]
            .iter()
            .any(|f| f.ends_with("LINEAR"));
        let nearest = !comparison
            && linear
            && texture.is_some_and(|t| {
                let f = self.plan.textures[t].format;
                f.has_depth_aspect() || f.has_stencil_aspect()
            });
        if nearest {
            self.notes.push(format!(
                "sampler {} reads a depth or stencil texture linearly without comparing, which needs a filterable format: read nearest",
                sampler.name
            ));
        }
        let index = self.vk_sampler(s, nearest)?;
        Ok((
            wgpu::BindGroupLayoutEntry {
                binding,
                visibility,
                ty: wgpu::BindingType::Sampler(if comparison {
                    wgpu::SamplerBindingType::Comparison
                } else if nearest {
                    wgpu::SamplerBindingType::NonFiltering
                } else {
                    wgpu::SamplerBindingType::Filtering
                }),
                count: None,
            },
            VkResource::Sampler(index),
        ))
    }

    /// A sampled or storage texture through image view `v`.
    fn vk_texture(
        &self,
        p: &PassDesc,
        v: usize,
        var: &ResourceVar,
        storage: bool,
    ) -> Result<(wgpu::BindingType, VkResource), Fail> {
        let model = self.vk_model()?;
        let view = &model.views[v];
        // A sampled view's swizzle is applied in the shader (`sampled_swizzle`); a storage
        // view must have none (VUID-VkWriteDescriptorSet-descriptorType-00336).
        if let Some(sw) = view.swizzle.filter(|_| storage) {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a view with its components swizzled ({sw:?}, view {}): wgpu views have no swizzle",
                    view.name
                ),
            }
            .into());
        }
        let texture = self.tex(p, view.image)?;
        let spec = &self.plan.textures[texture];
        let dimension = match view
            .view_type
            .strip_prefix("VK_IMAGE_VIEW_TYPE_")
            .unwrap_or(&view.view_type)
        {
            "1D" => wgpu::TextureViewDimension::D1,
            "2D" => wgpu::TextureViewDimension::D2,
            "3D" => wgpu::TextureViewDimension::D3,
            "CUBE" => wgpu::TextureViewDimension::Cube,
            "2D_ARRAY" => wgpu::TextureViewDimension::D2Array,
            "CUBE_ARRAY" => wgpu::TextureViewDimension::CubeArray,
            other => {
                return Err(VkProblem::Unsupported {
                    feature: format!("image view type {other} (view {})", view.name),
                }
                .into());
            }
        };
        let has_depth = spec.format.has_depth_aspect();
        let has_stencil = spec.format.has_stencil_aspect();
        // VkImageAspectFlags: colour 1, depth 2, stencil 4.
        let aspect = if view.aspect & 4 != 0 && has_stencil {
            wgpu::TextureAspect::StencilOnly
        } else if has_depth && has_stencil {
            wgpu::TextureAspect::DepthOnly
        } else {
            wgpu::TextureAspect::All
        };
        let format = if has_depth || has_stencil {
            None
        } else {
            Some(self.vk_view_format(p, texture, &view.format)?)
        };
        if storage && self.vk_view_permutation(v).is_some() {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a storage image through view {} ({}), whose 16-bit layout orders the image's channels otherwise",
                    view.name, view.format
                ),
            }
            .into());
        }
        let resource = VkResource::Texture {
            texture,
            format,
            dimension,
            aspect,
            base_mip: view.base_mip,
            mips: view.mips,
            base_layer: view.base_layer,
            layers: view.layers,
        };
        let ty = if storage {
            let format = format.ok_or_else(|| VkProblem::Unsupported {
                feature: format!("a depth or stencil storage image (view {})", view.name),
            })?;
            wgpu::BindingType::StorageTexture {
                access: super::states::storage_access(var),
                format,
                view_dimension: dimension,
            }
        } else {
            let depth_compare = match &var.kind {
                ResourceKind::SampledImage(i) | ResourceKind::CombinedImageSampler(i) => {
                    i.depth == Some(true)
                }
                _ => false,
            };
            let sample_type = if aspect == wgpu::TextureAspect::StencilOnly {
                wgpu::TextureSampleType::Uint
            } else if has_depth {
                if depth_compare {
                    wgpu::TextureSampleType::Depth
                } else {
                    wgpu::TextureSampleType::Float { filterable: false }
                }
            } else {
                let f = format.unwrap_or(spec.format);
                f.sample_type(None, Some(self.available))
                    .unwrap_or(wgpu::TextureSampleType::Float { filterable: false })
            };
            // A multisampled texture is only fetched, never filtered (WebGPU's rule).
            let multisampled = spec.samples > 1;
            let sample_type = match sample_type {
                wgpu::TextureSampleType::Float { .. } if multisampled => {
                    wgpu::TextureSampleType::Float { filterable: false }
                }
                other => other,
            };
            wgpu::BindingType::Texture {
                sample_type,
                view_dimension: dimension,
                multisampled,
            }
        };
        Ok((ty, resource))
    }
}

/// The swizzle of the view descriptor `d` samples, where not the identity, as
/// `spirv::RewriteOptions::swizzles` codes.
fn sampled_swizzle(
    model: &VkModel,
    d: Option<&VkBound>,
    descriptor_type: &str,
    permutation: Option<[u8; 4]>,
) -> Option<[u8; 4]> {
    if !descriptor_type.ends_with("SAMPLED_IMAGE") && !ty_is_combined(descriptor_type) {
        return None;
    }
    let d = d?;
    let view = &model.views[d.view?];
    let sw = view.swizzle;
    // BC1 without alpha is held as BC1 with alpha: the view's alpha is one.
    let opaque = crate::lower::formats::opaque_bc1(&view.format);
    if sw.is_none() && permutation.is_none() && !opaque {
        return None;
    }
    // The view's channels are the image's permuted (`lower::packed16`); its swizzle picks
    // among the view's.
    let through = |c: u8| match permutation {
        Some(p) if c < 4 => p[c as usize],
        _ => c,
    };
    let codes = sw.map_or([0, 1, 2, 3], |sw| {
        sw.map(|c| match c {
            Component::R => 0,
            Component::G => 1,
            Component::B => 2,
            Component::A => 3,
            Component::Zero => crate::spirv::SWIZZLE_ZERO,
            Component::One => crate::spirv::SWIZZLE_ONE,
        })
    });
    let codes = codes.map(|c| {
        if opaque && c == 3 {
            crate::spirv::SWIZZLE_ONE
        } else {
            c
        }
    });
    Some(codes.map(through))
}

/// The descriptor types (without `VK_DESCRIPTOR_TYPE_`) that a shader variable of `kind` may
/// be bound to, by the specification's table of shader resources and descriptor types;
/// `None` where the lowering checks the kind elsewhere.
fn descriptor_types_of(kind: &ResourceKind) -> Option<&'static [&'static str]> {
    Some(match kind {
        ResourceKind::CombinedImageSampler(_) => &["COMBINED_IMAGE_SAMPLER"],
        ResourceKind::SampledImage(_) => &["SAMPLED_IMAGE", "COMBINED_IMAGE_SAMPLER"],
        ResourceKind::Sampler { .. } => &["SAMPLER", "COMBINED_IMAGE_SAMPLER"],
        ResourceKind::StorageImage(_) => &["STORAGE_IMAGE"],
        ResourceKind::InputAttachment { .. } => &["INPUT_ATTACHMENT"],
        _ => return None,
    })
}

fn ty_is_combined(descriptor_type: &str) -> bool {
    descriptor_type.ends_with("COMBINED_IMAGE_SAMPLER")
}

/// The binding number an element of a split descriptor array takes: past the set layout's
/// highest binding, after the elements split before it.
fn split_element_binding(
    model: &VkModel,
    layout: &VkPipelineLayout,
    elements: &BTreeMap<(u32, u32), u32>,
    (set, split_binding): (u32, u32),
    u: &Used,
) -> Result<u32, Fail> {
    let (binding, element) = crate::spirv::binding_element(split_binding);
    let highest = layout
        .sets
        .get(set as usize)
        .and_then(|&s| {
            model.set_layouts[s]
                .bindings
                .iter()
                .map(|b| b.binding)
                .max()
        })
        .unwrap_or(0);
    let before = elements.range((set, 0)..(set, split_binding)).count() as u32;
    let base = highest
        .checked_add(1 + before)
        .filter(|b| b.checked_mul(2).is_some_and(|w| w < u32::MAX))
        .ok_or_else(|| VkProblem::Unsupported {
            feature: format!(
                "element {element} of set {set} binding {binding} in shader {}: the set layout's bindings leave no number for it",
                u.shader
            ),
        })?;
    Ok(base)
}

/// The format a uniform texel buffer's view reads as, or why the replay cannot read it.
fn texel_view_format(
    found: Option<&VkBound>,
    (set, binding, element): (u32, u32, u32),
    u: &Used,
) -> Result<rspirv::spirv::ImageFormat, Fail> {
    if found.is_some_and(|d| d.resource.is_none()) {
        return Err(super::blanks::refused(
            "UNIFORM_TEXEL_BUFFER",
            (set, binding, element),
            &u.shader,
        ));
    }
    let view = found.and_then(|d| d.format.as_deref());
    view.and_then(texel_format).ok_or_else(|| {
        VkProblem::Unsupported {
            feature: format!(
                "a uniform texel buffer of format {} (set {set} binding {binding} of shader {})",
                view.unwrap_or("unknown"),
                u.shader
            ),
        }
        .into()
    })
}

/// A sampled resource's mip levels seen through its view, whether it is a cube, and its
/// texture (blank stand-ins have none).
fn texture_facts(
    resource: &VkResource,
    textures: &[crate::plan::TextureSpec],
) -> (u32, bool, Option<usize>) {
    match resource {
        VkResource::Texture {
            texture,
            base_mip,
            mips,
            dimension,
            ..
        } => (
            mips.unwrap_or(textures[*texture].mip_levels.saturating_sub(*base_mip)),
            matches!(
                dimension,
                wgpu::TextureViewDimension::Cube | wgpu::TextureViewDimension::CubeArray
            ),
            Some(*texture),
        ),
        _ => (u32::MAX, false, None),
    }
}
