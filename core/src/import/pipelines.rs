//! The pipelines a stream creates and what they are made of: shader modules (their size;
//! the binary route adds their code), samplers, descriptor set layouts, pipeline layouts, and
//! graphics and compute pipelines with their fixed-function state, by handle. At the end, the
//! pipelines the imported draws and dispatches bound, and everything they name, become the
//! capture's `vulkan` section.

use std::cell::OnceCell;
use std::collections::{BTreeMap, BTreeSet};

use super::HashMap;
use std::sync::Arc;

use super::calls::Func;
use super::value::{Arg, Got};
use crate::capture::format::{
    BlendAttachment, DepthStencilVk, GraphicsState, LayoutBinding, Pipeline, PipelineLayout,
    PipelineStage, PushConstantRange, SetLayout, ShaderModule, SpecConstant, StencilFaceVk,
    VertexAttributeVk, VertexBinding, VkSampler, VulkanObjects,
};

/// A pipeline as created, naming the objects it uses by handle.
#[derive(Clone, Debug)]
struct Made {
    pipeline: Pipeline,
    layout: u64,
    modules: Vec<u64>,
}

/// Pipeline objects by handle.
#[derive(Debug, Default)]
pub struct Pipelines {
    modules: HashMap<u64, u64>,
    samplers: HashMap<u64, VkSampler>,
    /// Set layout -> (layout, immutable samplers by binding).
    set_layouts: HashMap<u64, (SetLayout, Vec<Vec<u64>>)>,
    layouts: HashMap<u64, (PipelineLayout, Vec<u64>)>,
    pipelines: HashMap<u64, Made>,
    /// Per shader module whose code the capture holds: the code, and its storage bindings
    /// as (set, binding, reads, writes) once a pipeline the frame binds asks for them.
    /// Parsing waits for that ask: an application creates far more modules than one frame
    /// uses, and parsing every one was most of an import's time. Modules with the same code
    /// (wgpu makes one per pipeline) share one entry, so each code is parsed once.
    storage: HashMap<u64, usize>,
    learned: Vec<Learned>,
    by_code: HashMap<Arc<[u8]>, usize>,
    /// Pipeline layout -> its compatibility id for each set (`compat_ids`).
    compat: HashMap<u64, Arc<[u64]>>,
    /// What each compatibility id stands for, so that equal definitions share one.
    compat_keys: HashMap<CompatKey, u64>,
}

/// What a pipeline layout's compatibility for set N depends on: N, the definitions of its set
/// layouts 0 to N, and its push-constant ranges (the specification's Pipeline Layout
/// Compatibility).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct CompatKey {
    set: u32,
    sets: Vec<SetDefinition>,
    push_constants: Vec<(u32, u32, u32)>,
}

/// A descriptor set layout as defined: its flags and bindings (number, type, count, stages,
/// immutable samplers), or the handle of one the stream never created (equal only to itself).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum SetDefinition {
    Known(u32, Vec<(u32, String, u32, u32, Vec<u64>)>),
    Unknown(u64),
}

/// A shader module's code and what parsing it taught, once asked.
#[derive(Debug)]
struct Learned {
    code: Arc<[u8]>,
    /// By entry point name; `None` where the code does not parse.
    bindings: OnceCell<Option<BTreeMap<String, Vec<Bound>>>>,
}

/// One descriptor variable of a module: where it is bound, whether it is a storage kind,
/// what the code does with it, and whether the code names it at all (static use).
#[derive(Debug, Clone, Copy)]
struct Bound {
    set: u32,
    binding: u32,
    storage: bool,
    reads: bool,
    writes: bool,
    used: bool,
}

impl Learned {
    /// The module's descriptor variables: whether its code names each, and what its
    /// instructions do with each, within what its NonWritable and NonReadable decorations
    /// allow. Code that does not parse teaches nothing (`None`: its storage bindings stay
    /// read-write for the check, and every binding counts as used).
    /// Static use is per entry point (`entry`): the functions it reaches.
    fn bindings(&self, entry: &str) -> Option<&[Bound]> {
        self.bindings
            .get_or_init(|| {
                let words = crate::spirv::words(&self.code).ok()?;
                let reflection = crate::spirv::reflect(&words).ok()?;
                let by_entry = crate::spirv::usage_by_entry(&words).ok()?;
                use crate::spirv::ResourceKind as K;
                let bound = |usage: &BTreeMap<(u32, u32), crate::spirv::Usage>| {
                    reflection
                        .resources
                        .iter()
                        .map(|r| {
                            let u = usage.get(&(r.set, r.binding)).copied().unwrap_or_default();
                            let storage = matches!(
                                r.kind,
                                K::StorageBuffer | K::StorageImage(_) | K::StorageTexelBuffer(_)
                            );
                            Bound {
                                set: r.set,
                                binding: r.binding,
                                storage,
                                reads: u.reads && !r.non_readable,
                                writes: u.writes && !r.non_writable,
                                used: u.used,
                            }
                        })
                        .collect::<Vec<_>>()
                };
                Some(
                    by_entry
                        .iter()
                        .map(|(name, usage)| (name.clone(), bound(usage)))
                        .collect(),
                )
            })
            .as_ref()?
            .get(entry)
            .map(Vec::as_slice)
    }
}

/// Whether a pipeline's shaders read and write a storage binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StorageUse {
    pub reads: bool,
    pub writes: bool,
}

/// The `VkShaderStageFlagBits` value of a `VK_SHADER_STAGE_*_BIT` name (0 for one the
/// importer does not know).
fn stage_bit(name: &str) -> u32 {
    match name.strip_prefix("VK_SHADER_STAGE_").unwrap_or(name) {
        "VERTEX_BIT" => 0x1,
        "TESSELLATION_CONTROL_BIT" => 0x2,
        "TESSELLATION_EVALUATION_BIT" => 0x4,
        "GEOMETRY_BIT" => 0x8,
        "FRAGMENT_BIT" => 0x10,
        "COMPUTE_BIT" => 0x20,
        _ => 0,
    }
}

pub fn module_name(h: u64) -> String {
    format!("module_{h}")
}

pub fn sampler_name(h: u64) -> String {
    format!("sampler_{h}")
}

pub fn pipeline_name(h: u64) -> String {
    format!("pipeline_{h}")
}

/// A `VkBool32` member.
pub(super) fn boolean(a: &Arg<'_>, key: &str) -> Got<bool> {
    Ok(a.get(key)?.u64()? != 0)
}

/// A `float` member.
pub(super) fn float(a: &Arg<'_>, key: &str) -> Got<f32> {
    Ok(a.get(key)?.f64()? as f32)
}

impl Pipelines {
    /// Keeps module `module`'s code for `storage_use`.
    pub fn learn_module(&mut self, module: u64, code: &[u8]) {
        let at = match self.by_code.get(code) {
            Some(&at) => at,
            None => {
                let code: Arc<[u8]> = code.into();
                self.learned.push(Learned {
                    code: code.clone(),
                    bindings: OnceCell::new(),
                });
                self.by_code.insert(code, self.learned.len() - 1);
                self.learned.len() - 1
            }
        };
        self.storage.insert(module, at);
    }

    /// How pipeline `pipeline`'s shaders use storage binding (`set`, `binding`): `None` when
    /// the code of one of its modules is not known.
    pub fn storage_use(&self, pipeline: u64, set: u32, binding: u32) -> Option<StorageUse> {
        let made = self.pipelines.get(&pipeline)?;
        let mut out = StorageUse {
            reads: false,
            writes: false,
        };
        for (stage, m) in made.pipeline.stages.iter().zip(&made.modules) {
            let learned = self.learned.get(*self.storage.get(m)?)?;
            for b in learned.bindings(&stage.entry).unwrap_or_default() {
                if b.storage && (b.set, b.binding) == (set, binding) {
                    out.reads |= b.reads;
                    out.writes |= b.writes;
                }
            }
        }
        Some(out)
    }

    /// The `VkShaderStageFlags` of the stages of pipeline `pipeline` whose code statically
    /// uses binding (`set`, `binding`) (0: none does): `None` when the code of one of its
    /// modules is not known or does not parse. A stage's entry point is taken with the
    /// functions it calls, not the module's other entry points.
    pub fn used_stages(&self, pipeline: u64, set: u32, binding: u32) -> Option<u32> {
        let made = self.pipelines.get(&pipeline)?;
        let mut stages = 0;
        for (stage, m) in made.pipeline.stages.iter().zip(&made.modules) {
            let learned = self.learned.get(*self.storage.get(m)?)?;
            if learned
                .bindings(&stage.entry)?
                .iter()
                .any(|b| b.used && (b.set, b.binding) == (set, binding))
            {
                stages |= stage_bit(&stage.stage);
            }
        }
        Some(stages)
    }

    /// The `VkShaderStageFlags` of binding `binding` of set `set` in pipeline `pipeline`'s
    /// layout.
    pub fn binding_stages(&self, pipeline: u64, set: u32, binding: u32) -> Option<u32> {
        let made = self.pipelines.get(&pipeline)?;
        let (_, sets) = self.layouts.get(&made.layout)?;
        let (layout, _) = self.set_layouts.get(sets.get(set as usize)?)?;
        layout
            .bindings
            .iter()
            .find(|b| b.binding == binding)
            .map(|b| b.stages)
    }

    /// Graphics pipeline `pipeline`'s dynamic states (`None`: not a graphics pipeline the
    /// stream created).
    pub fn dynamic_states(&self, pipeline: u64) -> Option<&[String]> {
        let made = self.pipelines.get(&pipeline)?;
        Some(&made.pipeline.graphics.as_ref()?.dynamic_states)
    }

    /// Sampler `h` as created.
    pub fn sampler_of(&self, h: u64) -> Option<&VkSampler> {
        self.samplers.get(&h)
    }

    /// Pipeline layout `layout`'s compatibility id for each of its sets: two layouts are
    /// compatible for set N exactly where their ids for N are equal. `None` for a layout the
    /// stream never created.
    pub fn compat_ids(&self, layout: u64) -> Option<Arc<[u64]>> {
        self.compat.get(&layout).cloned()
    }

    fn compat_ids_of(&mut self, sets: &[u64], push: &[PushConstantRange]) -> Vec<u64> {
        let push_constants: Vec<(u32, u32, u32)> =
            push.iter().map(|r| (r.stages, r.offset, r.size)).collect();
        let mut defined = Vec::with_capacity(sets.len());
        let mut ids = Vec::with_capacity(sets.len());
        for (n, &s) in sets.iter().enumerate() {
            defined.push(match self.set_layouts.get(&s) {
                Some((layout, immutable)) => SetDefinition::Known(
                    layout.flags,
                    layout
                        .bindings
                        .iter()
                        .zip(immutable)
                        .map(|(b, fixed)| {
                            let ty = b.descriptor_type.clone();
                            (b.binding, ty, b.count, b.stages, fixed.clone())
                        })
                        .collect::<BTreeSet<_>>()
                        .into_iter()
                        .collect(),
                ),
                None => SetDefinition::Unknown(s),
            });
            let key = CompatKey {
                set: n as u32,
                sets: defined.clone(),
                push_constants: push_constants.clone(),
            };
            let next = self.compat_keys.len() as u64 + 1;
            ids.push(*self.compat_keys.entry(key).or_insert(next));
        }
        ids
    }

    /// Pipeline `pipeline`'s layout and the descriptor sets its shaders statically use
    /// (through the functions each entry point calls): `None` when the pipeline or the code
    /// of one of its modules is not known or does not parse.
    pub fn used_sets(&self, pipeline: u64) -> Option<(u64, BTreeSet<u32>)> {
        let made = self.pipelines.get(&pipeline)?;
        let mut sets = BTreeSet::new();
        for (stage, m) in made.pipeline.stages.iter().zip(&made.modules) {
            let learned = self.learned.get(*self.storage.get(m)?)?;
            sets.extend(
                learned
                    .bindings(&stage.entry)?
                    .iter()
                    .filter(|b| b.used)
                    .map(|b| b.set),
            );
        }
        Some((made.layout, sets))
    }

    /// Applies a call that creates a pipeline object; `Ok(false)` for other calls.
    pub fn apply(&mut self, func: Func, args: &Arg<'_>) -> Got<bool> {
        match func {
            Func::CreateShaderModule => {
                let size = args.get("pCreateInfo")?.get("codeSize")?.u64()?;
                self.modules
                    .insert(args.get("pShaderModule")?.handle()?, size);
            }
            Func::CreateSampler => {
                let h = args.get("pSampler")?.handle()?;
                let s = sampler(&args.get("pCreateInfo")?, h)?;
                self.samplers.insert(h, s);
            }
            Func::CreateDescriptorSetLayout => {
                let h = args.get("pSetLayout")?.handle()?;
                let ci = args.get("pCreateInfo")?;
                let mut bindings = Vec::new();
                let mut immutable = Vec::new();
                for b in ci.list("pBindings")? {
                    let fixed: Vec<u64> = b
                        .list("pImmutableSamplers")?
                        .iter()
                        .map(Arg::handle)
                        .collect::<Got<_>>()?;
                    bindings.push(LayoutBinding {
                        binding: b.get("binding")?.u32()?,
                        descriptor_type: b.get("descriptorType")?.name()?,
                        count: b.get("descriptorCount")?.u32()?,
                        stages: b.get("stageFlags")?.u32()?,
                        immutable_samplers: Vec::new(),
                    });
                    immutable.push(fixed);
                }
                let layout = SetLayout {
                    name: format!("set_layout_{h}"),
                    flags: ci.get("flags")?.u32()?,
                    bindings,
                };
                self.set_layouts.insert(h, (layout, immutable));
            }
            Func::CreatePipelineLayout => {
                let h = args.get("pPipelineLayout")?.handle()?;
                let ci = args.get("pCreateInfo")?;
                let sets: Vec<u64> = ci
                    .list("pSetLayouts")?
                    .iter()
                    .map(Arg::handle)
                    .collect::<Got<_>>()?;
                let push_constants = ci
                    .list("pPushConstantRanges")?
                    .iter()
                    .map(|r| {
                        Ok(PushConstantRange {
                            stages: r.get("stageFlags")?.u32()?,
                            offset: r.get("offset")?.u32()?,
                            size: r.get("size")?.u32()?,
                        })
                    })
                    .collect::<Got<_>>()?;
                let layout = PipelineLayout {
                    name: format!("pipeline_layout_{h}"),
                    set_layouts: sets.iter().map(|s| format!("set_layout_{s}")).collect(),
                    push_constants,
                };
                let ids = self.compat_ids_of(&sets, &layout.push_constants);
                self.compat.insert(h, ids.into());
                self.layouts.insert(h, (layout, sets));
            }
            Func::CreatePipelines { compute } => {
                let infos = args.list("pCreateInfos")?;
                let handles = args.list("pPipelines")?;
                for (ci, h) in infos.iter().zip(&handles) {
                    let h = h.handle()?;
                    if h != 0 {
                        let made = pipeline(ci, h, compute)?;
                        self.pipelines.insert(h, made);
                    }
                }
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// The `vulkan` section for the pipelines `used` names, with everything they name;
    /// `files` gives each module's code file where the source held it.
    pub fn emit(
        &self,
        used: &BTreeSet<u64>,
        files: &BTreeMap<u64, String>,
    ) -> (VulkanObjects, Vec<String>) {
        let mut out = VulkanObjects::default();
        let mut notes = Vec::new();
        let (mut layouts, mut modules) = (BTreeSet::new(), BTreeSet::new());
        for h in used {
            match self.pipelines.get(h) {
                Some(m) => {
                    out.pipelines.push(m.pipeline.clone());
                    layouts.insert(m.layout);
                    modules.extend(m.modules.iter().copied());
                }
                None => notes.push(format!(
                    "pipeline {h} is bound but its creation is not in the capture"
                )),
            }
        }
        let mut sets = BTreeSet::new();
        for h in &layouts {
            if let Some((l, s)) = self.layouts.get(h) {
                out.pipeline_layouts.push(l.clone());
                sets.extend(s.iter().copied());
            }
        }
        let mut samplers = BTreeSet::new();
        for h in &sets {
            if let Some((l, fixed)) = self.set_layouts.get(h) {
                let mut l = l.clone();
                for (b, f) in l.bindings.iter_mut().zip(fixed) {
                    b.immutable_samplers = f.iter().map(|s| sampler_name(*s)).collect();
                    samplers.extend(f.iter().copied());
                }
                out.set_layouts.push(l);
            }
        }
        // Every sampler: descriptor writes name them too, not only layouts.
        samplers.extend(self.samplers.keys().copied());
        for h in &samplers {
            if let Some(s) = self.samplers.get(h) {
                out.samplers.push(s.clone());
            }
        }
        for h in &modules {
            if let Some(size) = self.modules.get(h) {
                out.shader_modules.push(ShaderModule {
                    name: module_name(*h),
                    file: files.get(h).cloned(),
                    size: *size,
                });
            }
        }
        (out, notes)
    }
}

fn sampler(ci: &Arg<'_>, h: u64) -> Got<VkSampler> {
    Ok(VkSampler {
        name: sampler_name(h),
        mag_filter: ci.get("magFilter")?.name()?,
        min_filter: ci.get("minFilter")?.name()?,
        mipmap_mode: ci.get("mipmapMode")?.name()?,
        address_mode_u: ci.get("addressModeU")?.name()?,
        address_mode_v: ci.get("addressModeV")?.name()?,
        address_mode_w: ci.get("addressModeW")?.name()?,
        mip_lod_bias: float(ci, "mipLodBias")?,
        max_anisotropy: if boolean(ci, "anisotropyEnable")? {
            Some(float(ci, "maxAnisotropy")?)
        } else {
            None
        },
        compare_op: if boolean(ci, "compareEnable")? {
            Some(ci.get("compareOp")?.name()?)
        } else {
            None
        },
        min_lod: float(ci, "minLod")?,
        max_lod: float(ci, "maxLod")?,
        border_color: ci.get("borderColor")?.name()?,
        custom_border_color: custom_border_color(ci)?,
        unnormalized_coordinates: boolean(ci, "unnormalizedCoordinates")?,
        // VK_SAMPLER_CREATE_NON_SEAMLESS_CUBE_MAP_BIT_EXT.
        non_seamless_cube: ci.opt("flags").and_then(|f| f.u64().ok()).unwrap_or(0) & 0x4 != 0,
    })
}

/// A custom border's colour (`VkSamplerCustomBorderColorCreateInfoEXT` in the chain), read as
/// the border's type says: `int32` for `VK_BORDER_COLOR_INT_CUSTOM_EXT`, else `float32`.
fn custom_border_color(ci: &Arg<'_>) -> Got<Option<[f64; 4]>> {
    let border = ci.get("borderColor")?.name()?;
    if !border.ends_with("_CUSTOM_EXT") {
        return Ok(None);
    }
    let mut next = ci.opt("pNext");
    while let Some(n) = next {
        if let Some(c) = n.opt("customBorderColor") {
            let v = super::commands::ClearColorValue::read(&c);
            let int = border.contains("_INT_");
            return Ok(if int { v.int32 } else { v.float32 });
        }
        next = n.opt("pNext");
    }
    Ok(None)
}

/// One stage: its module, entry point and specialization constants.
fn stage(s: &Arg<'_>) -> Got<(PipelineStage, u64)> {
    let module = s.get("module")?.handle()?;
    let mut specialization = Vec::new();
    if let Some(info) = s.opt("pSpecializationInfo") {
        // The binary capture holds the data; a JSON Lines stream only its address.
        let data: Option<Vec<u8>> = match info.opt("pData") {
            Some(d) if d.is_array() => Some(
                d.items()?
                    .iter()
                    .map(|b| b.u32().map(|v| v as u8))
                    .collect::<Got<_>>()?,
            ),
            _ => None,
        };
        for e in info.list("pMapEntries")? {
            let (offset, size) = (e.get("offset")?.u32()? as usize, e.get("size")?.u64()?);
            let value = data.as_ref().and_then(|d| {
                let bytes = d.get(offset..offset.checked_add(size.min(8) as usize)?)?;
                let mut v = [0u8; 8];
                v[..bytes.len()].copy_from_slice(bytes);
                Some(u64::from_le_bytes(v))
            });
            specialization.push(SpecConstant {
                id: e.get("constantID")?.u32()?,
                size: size as u32,
                value,
            });
        }
    }
    Ok((
        PipelineStage {
            stage: s.get("stage")?.name()?,
            module: module_name(module),
            entry: s.get("pName")?.str()?.to_owned(),
            specialization,
        },
        module,
    ))
}

fn pipeline(ci: &Arg<'_>, h: u64, compute: bool) -> Got<Made> {
    let stage_args = if compute {
        vec![ci.get("stage")?]
    } else {
        ci.list("pStages")?
    };
    let mut stages = Vec::new();
    let mut modules = Vec::new();
    for s in &stage_args {
        let (st, m) = stage(s)?;
        stages.push(st);
        modules.push(m);
    }
    let layout = ci.get("layout")?.handle()?;
    Ok(Made {
        pipeline: Pipeline {
            name: pipeline_name(h),
            bind_point: if compute {
                "VK_PIPELINE_BIND_POINT_COMPUTE"
            } else {
                "VK_PIPELINE_BIND_POINT_GRAPHICS"
            }
            .to_owned(),
            layout: format!("pipeline_layout_{layout}"),
            stages,
            graphics: if compute {
                None
            } else {
                Some(Box::new(graphics(ci)?))
            },
        },
        layout,
        modules,
    })
}

fn stencil_face(f: &Arg<'_>) -> Got<StencilFaceVk> {
    Ok(StencilFaceVk {
        fail_op: f.get("failOp")?.name()?,
        pass_op: f.get("passOp")?.name()?,
        depth_fail_op: f.get("depthFailOp")?.name()?,
        compare_op: f.get("compareOp")?.name()?,
        compare_mask: f.get("compareMask")?.u32()?,
        write_mask: f.get("writeMask")?.u32()?,
        reference: f.get("reference")?.u32()?,
    })
}

fn graphics(ci: &Arg<'_>) -> Got<GraphicsState> {
    let mut g = GraphicsState {
        topology: "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST".to_owned(),
        polygon_mode: "VK_POLYGON_MODE_FILL".to_owned(),
        front_face: "VK_FRONT_FACE_COUNTER_CLOCKWISE".to_owned(),
        line_width: 1.0,
        samples: "VK_SAMPLE_COUNT_1_BIT".to_owned(),
        subpass: ci.get("subpass")?.u32()?,
        ..GraphicsState::default()
    };
    // Read first: a state the draws may switch on needs the pipeline's values kept even
    // where the pipeline itself has it off.
    if let Some(d) = ci.opt("pDynamicState") {
        for s in d.list("pDynamicStates")? {
            g.dynamic_states.push(s.name()?);
        }
    }
    let dynamic = |state: &str| g.dynamic_states.iter().any(|s| s.ends_with(state));
    let (bias_switched, stencil_switched) = (
        dynamic("_DEPTH_BIAS_ENABLE"),
        dynamic("_STENCIL_TEST_ENABLE"),
    );
    if let Some(v) = ci.opt("pVertexInputState") {
        for b in v.list("pVertexBindingDescriptions")? {
            g.vertex_bindings.push(VertexBinding {
                binding: b.get("binding")?.u32()?,
                stride: b.get("stride")?.u32()?,
                input_rate: b.get("inputRate")?.name()?,
            });
        }
        for a in v.list("pVertexAttributeDescriptions")? {
            g.vertex_attributes.push(VertexAttributeVk {
                location: a.get("location")?.u32()?,
                binding: a.get("binding")?.u32()?,
                format: a.get("format")?.name()?,
                offset: a.get("offset")?.u32()?,
            });
        }
    }
    if let Some(ia) = ci.opt("pInputAssemblyState") {
        g.topology = ia.get("topology")?.name()?;
        g.primitive_restart = boolean(&ia, "primitiveRestartEnable")?;
    }
    if let Some(r) = ci.opt("pRasterizationState") {
        rasterization(&mut g, &r, bias_switched)?;
    }
    if let Some(m) = ci.opt("pMultisampleState") {
        g.samples = m.get("rasterizationSamples")?.name()?;
        g.alpha_to_coverage = boolean(&m, "alphaToCoverageEnable")?;
        g.alpha_to_one = boolean(&m, "alphaToOneEnable")?;
        // A mask with every sample of the count in it is no mask (a JSON Lines stream gives
        // only its address, so both routes agree on it).
        let count: u32 = g
            .samples
            .trim_start_matches("VK_SAMPLE_COUNT_")
            .trim_end_matches("_BIT")
            .parse()
            .unwrap_or(1);
        let every = u32::MAX >> (32 - count.clamp(1, 32));
        if let Some(first) = m.list("pSampleMask")?.first() {
            let mask = first.u32()?;
            g.sample_mask = (mask & every != every).then_some(mask);
        }
    }
    if let Some(d) = ci.opt("pDepthStencilState") {
        let stencil = boolean(&d, "stencilTestEnable")?;
        let faces = stencil || stencil_switched;
        g.depth_stencil = Some(DepthStencilVk {
            depth_test: boolean(&d, "depthTestEnable")?,
            depth_write: boolean(&d, "depthWriteEnable")?,
            depth_compare: d.get("depthCompareOp")?.name()?,
            depth_bounds: if boolean(&d, "depthBoundsTestEnable")? {
                Some([float(&d, "minDepthBounds")?, float(&d, "maxDepthBounds")?])
            } else {
                None
            },
            stencil_test: stencil,
            front: if faces {
                Some(stencil_face(&d.get("front")?)?)
            } else {
                None
            },
            back: if faces {
                Some(stencil_face(&d.get("back")?)?)
            } else {
                None
            },
        });
    }
    if let Some(c) = ci.opt("pColorBlendState") {
        color_blend(&mut g, &c)?;
    }
    if let Some(v) = ci.opt("pViewportState") {
        viewport_state(&mut g, &v)?;
    }
    Ok(g)
}

/// `VkPipelineRasterizationStateCreateInfo` and its chain (the depth bias kept where the
/// draws may switch it on).
fn rasterization(g: &mut GraphicsState, r: &Arg<'_>, bias_switched: bool) -> Got<()> {
    g.polygon_mode = r.get("polygonMode")?.name()?;
    g.cull_mode = r.get("cullMode")?.u32()?;
    g.front_face = r.get("frontFace")?.name()?;
    g.depth_clamp = boolean(r, "depthClampEnable")?;
    g.rasterizer_discard = boolean(r, "rasterizerDiscardEnable")?;
    g.line_width = float(r, "lineWidth")?;
    // `VkPipelineRasterizationProvokingVertexStateCreateInfoEXT` and
    // `VkPipelineRasterizationLineStateCreateInfoEXT`.
    let mut next = r.opt("pNext");
    while let Some(n) = next {
        if let Some(m) = n.opt("provokingVertexMode") {
            g.provoking_vertex_last = m.name()?.contains("LAST_VERTEX");
        }
        if let Some(m) = n.opt("lineRasterizationMode") {
            let m = m.name()?;
            g.line_rasterization_mode = (!m.ends_with("DEFAULT_EXT")).then_some(m);
            g.line_stipple = boolean(&n, "stippledLineEnable")?;
        }
        next = n.opt("pNext");
    }
    if boolean(r, "depthBiasEnable")? || bias_switched {
        g.depth_bias = Some([
            float(r, "depthBiasConstantFactor")?,
            float(r, "depthBiasClamp")?,
            float(r, "depthBiasSlopeFactor")?,
        ]);
    }
    Ok(())
}

/// `VkPipelineColorBlendStateCreateInfo`: each attachment's blend, the constants, the logic op.
fn color_blend(g: &mut GraphicsState, c: &Arg<'_>) -> Got<()> {
    for a in c.list("pAttachments")? {
        g.blend.push(BlendAttachment {
            enable: boolean(&a, "blendEnable")?,
            src_color: a.get("srcColorBlendFactor")?.name()?,
            dst_color: a.get("dstColorBlendFactor")?.name()?,
            color_op: a.get("colorBlendOp")?.name()?,
            src_alpha: a.get("srcAlphaBlendFactor")?.name()?,
            dst_alpha: a.get("dstAlphaBlendFactor")?.name()?,
            alpha_op: a.get("alphaBlendOp")?.name()?,
            write_mask: a.get("colorWriteMask")?.u32()?,
        });
    }
    let k = c.list("blendConstants")?;
    for (i, v) in k.iter().take(4).enumerate() {
        g.blend_constants[i] = v.f64()? as f32;
    }
    if boolean(c, "logicOpEnable")? {
        g.logic_op = Some(c.get("logicOp")?.name()?);
    }
    Ok(())
}

/// `VkPipelineViewportStateCreateInfo`: viewports, scissors and OpenGL's depth range.
fn viewport_state(g: &mut GraphicsState, v: &Arg<'_>) -> Got<()> {
    // OpenGL's depth range (`VkPipelineViewportDepthClipControlCreateInfoEXT`).
    let mut next = v.opt("pNext");
    while let Some(n) = next {
        if n.opt("negativeOneToOne").is_some() {
            g.depth_negative_one_to_one = boolean(&n, "negativeOneToOne")?;
        }
        next = n.opt("pNext");
    }
    for vp in v.list("pViewports")? {
        g.viewports.push([
            float(&vp, "x")?,
            float(&vp, "y")?,
            float(&vp, "width")?,
            float(&vp, "height")?,
        ]);
    }
    for s in v.list("pScissors")? {
        let (o, e) = (s.get("offset")?, s.get("extent")?);
        g.scissors.push([
            o.get("x")?.i64()?,
            o.get("y")?.i64()?,
            e.get("width")?.i64()?,
            e.get("height")?.i64()?,
        ]);
    }
    Ok(())
}
