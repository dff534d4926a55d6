//! An imported pipeline stage's SPIR-V made ready for wgpu, and the path it takes to the
//! device. The module is rewritten (`crate::spirv::rewrite`): combined image samplers split,
//! bindings renumbered, and `gl_Position.y` negated where Vulkan's clip space (y down) must
//! become wgpu's (y up; wgpu's Vulkan backend flips the viewport back). The result goes
//! through naga's SPIR-V front end and validator: where naga accepts it, wgpu translates it
//! for any backend (the naga path, wgpu's binding numbers); where naga refuses it, it is
//! rewritten again for the numbers wgpu's Vulkan backend gives its descriptor set layouts (the
//! entries of each group in binding order, numbered from 0) and handed to the driver as it is
//! (passthrough).

use rspirv::spirv::ImageFormat;
use wgpu_types as wgpu;

use super::{Fail, VkProblem, stage_of};
use crate::capture::vk_model::{VkPipeline, VkStage};
use crate::lower::Lowering;
use crate::plan::SpirvShader;
use crate::spirv::{ResourceKind, RewriteOptions, Role};

/// A rewritten stage is shared by pipelines that agree on all of this.
#[derive(Clone, PartialEq, Eq, Hash)]
pub(super) struct ShaderKey {
    module: usize,
    entry: String,
    stage: String,
    flip: bool,
    /// OpenGL's depth range mapped to Vulkan's (`RewriteOptions::gl_depth`).
    gl_depth: bool,
    sets: Vec<(u32, Vec<u32>)>,
    specialization: Vec<(u32, u32, Option<u64>)>,
    texel_formats: Vec<(u32, u32, ImageFormat)>,
    /// Samplers' LOD bias by (set, binding), as bits.
    lod_bias: Vec<(u32, u32, u32)>,
    /// Sampled views' swizzles by (set, binding).
    swizzles: Vec<(u32, u32, [u8; 4])>,
    /// Uniform blocks read as storage blocks, by (set, binding).
    storage_blocks: Vec<(u32, u32)>,
    /// Uniform blocks whose scalar arrays are widened to std140, by (set, binding).
    std140_blocks: Vec<(u32, u32)>,
    /// Samplers taking unnormalized coordinates, by (set, binding).
    unnormalized: Vec<(u32, u32, bool)>,
    /// Samplers mirroring once, by (set, binding), with their axes.
    mirror_once: Vec<(u32, u32, u8)>,
    /// Fragment output locations with an attachment (`RewriteOptions::attached_outputs`).
    outputs: Option<u32>,
    /// Vertex inputs fetched as integers from scaled formats (`RewriteOptions::scaled_inputs`).
    scaled: Vec<(u32, crate::spirv::IntegerFetch)>,
}

/// wgpu's binding for the number `b` stands for (`bindings::wgpu_base`) in the role asked.
fn wgpu_binding(b: u32, role: Role) -> u32 {
    match role {
        Role::Whole | Role::SplitImage => b * 2,
        Role::SplitSampler => b * 2 + 1,
    }
}

/// Whether naga's front end and validator accept the module.
fn naga_accepts(words: &[u32]) -> bool {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let options = naga::front::spv::Options {
        // The rewrite already turned clip space around.
        adjust_coordinate_space: false,
        strict_capabilities: true,
        block_ctx_dump_prefix: None,
    };
    let Ok(module) = naga::front::spv::parse_u8_slice(&bytes, &options) else {
        return false;
    };
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default() | naga::valid::Capabilities::IMMEDIATES,
    )
    .validate(&module)
    .is_ok()
}

impl<'c> Lowering<'c> {
    pub(super) fn vk_shader(
        &mut self,
        pipe: &VkPipeline,
        stage: &VkStage,
        (flip, gl_depth): (bool, bool),
        bound: &super::bindings::Bound,
        attached: Option<u32>,
        scaled: &[(u32, crate::spirv::IntegerFetch)],
    ) -> Result<usize, Fail> {
        // Only the vertex stage fetches attributes.
        let scaled = if stage.stage == "VK_SHADER_STAGE_VERTEX_BIT" {
            scaled
        } else {
            &[]
        };
        let (sets, texel_formats) = (&bound.sets, &bound.texel_formats[..]);
        let lod_bias: Vec<(u32, u32, f32)> = bound
            .lod_bias
            .iter()
            .map(|&(s, b, bits)| (s, b, f32::from_bits(bits)))
            .collect();
        // Only a fragment stage's outputs meet the attachments.
        let outputs = attached.filter(|_| stage.stage == "VK_SHADER_STAGE_FRAGMENT_BIT");
        let key = ShaderKey {
            module: stage.module,
            entry: stage.entry.clone(),
            stage: stage.stage.clone(),
            flip,
            gl_depth,
            sets: sets.iter().map(|(s, b)| (*s, b.clone())).collect(),
            specialization: stage.specialization.clone(),
            texel_formats: texel_formats.to_vec(),
            lod_bias: bound.lod_bias.clone(),
            swizzles: bound.swizzles.clone(),
            storage_blocks: bound.storage_blocks.clone(),
            std140_blocks: bound.std140_blocks.clone(),
            unnormalized: bound.unnormalized.clone(),
            mirror_once: bound.mirror_once.clone(),
            outputs,
            scaled: scaled.to_vec(),
        };
        if let Some(&i) = self.vk.shaders.get(&key) {
            return Ok(i);
        }
        let model = self.vk_model()?;
        let module = &model.modules[stage.module];
        let (wgpu_stage, execution_model) = stage_of(&stage.stage)?;
        let name = format!(
            "{} ({} of pipeline {})",
            module.name,
            stage
                .stage
                .trim_start_matches("VK_SHADER_STAGE_")
                .trim_end_matches("_BIT")
                .to_lowercase(),
            pipe.name
        );
        let specialization: Vec<(u32, u64)> =
            stage
                .specialization
                .iter()
                .map(|&(id, _, value)| {
                    value.map(|v| (id, v)).ok_or_else(|| VkProblem::Missing(format!(
                    "shader {name}: specialization constant {id} has no value in the capture"
                )))
                })
                .collect::<Result<_, _>>()?;
        let flip = flip && wgpu_stage == wgpu::ShaderStages::VERTEX;
        let gl_depth = gl_depth && wgpu_stage == wgpu::ShaderStages::VERTEX;
        let base = |set: u32, b: u32| super::bindings::wgpu_base(&bound.elements, set, b);
        let used = |set: u32, b: u32, role: Role| -> Option<u32> {
            let w = wgpu_binding(base(set, b), role);
            sets.get(&set)?.contains(&w).then_some(w)
        };
        let spirv_error = |error| VkProblem::Spirv {
            shader: name.clone(),
            error,
        };
        let options = RewriteOptions {
            flip_y: flip,
            binding: &used,
            specialization: &specialization,
            texel_formats,
            lod_bias: &lod_bias,
            gl_depth,
            swizzles: &bound.swizzles,
            storage_blocks: &bound.storage_blocks,
            std140_blocks: &bound.std140_blocks,
            unnormalized: &bound.unnormalized,
            mirror_once: &bound.mirror_once,
            attached_outputs: outputs,
            scaled_inputs: scaled,
        };
        let words = self.vk_words(stage.module)?;
        let naga_words = crate::spirv::rewrite(&words, execution_model, &stage.entry, &options)
            .map_err(spirv_error)?;
        let rank = |set: u32, b: u32, role: Role| -> Option<u32> {
            let w = wgpu_binding(base(set, b), role);
            sets.get(&set)?
                .iter()
                .position(|&x| x == w)
                .map(|r| r as u32)
        };
        let passthrough = crate::spirv::rewrite(
            &words,
            execution_model,
            &stage.entry,
            &RewriteOptions {
                binding: &rank,
                ..options
            },
        )
        .map_err(spirv_error)?;
        let after = crate::spirv::reflect(&passthrough).map_err(spirv_error)?;
        let naga = self.vk_shader_checks(stage, &name, &after, naga_words)?;
        self.plan.vk.shaders.push(SpirvShader {
            name,
            entry: stage.entry.clone(),
            stage: wgpu_stage,
            naga,
            passthrough,
            workgroup: [1, 1, 1],
        });
        let i = self.plan.vk.shaders.len() - 1;
        self.vk.shaders.insert(key, i);
        Ok(i)
    }

    /// What the replay cannot run of a rewritten shader (texel buffers left, capabilities
    /// the device lacks), a note for demoted invocations, and the module naga takes, if it
    /// takes it (`None`: handed over as it is).
    fn vk_shader_checks(
        &mut self,
        stage: &VkStage,
        name: &str,
        after: &crate::spirv::Reflection,
        naga_words: Vec<u32>,
    ) -> Result<Option<Vec<u32>>, Fail> {
        // wgpu binds no texel buffer: the rewrite turns those a shader only reads into word
        // buffers, and what is left the replay cannot do.
        if let Some(r) = after.resources.iter().find(|r| {
            matches!(
                r.kind,
                ResourceKind::StorageTexelBuffer(_) | ResourceKind::UniformTexelBuffer
            )
        }) {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a texel buffer it writes, queries or reads in a format the rewrite does not unpack ({:?} at set {} binding {} of shader {name})",
                    r.kind, r.set, r.binding
                ),
            }
            .into());
        }
        if self
            .vk_reflect(stage.module, &stage.entry)?
            .capabilities
            .contains(&rspirv::spirv::Capability::DemoteToHelperInvocation)
        {
            let note = format!(
                "shader {name}: demote to helper invocation taken as OpKill (wgpu's device has no demote): a pixel's neighbours in its quad may take other derivatives after it discards"
            );
            if !self.notes.contains(&note) {
                self.notes.push(note);
            }
        }
        // naga writes what its own translation needs; a module handed over as it is must
        // not declare what the device was not made for.
        let naga = naga_accepts(&naga_words).then_some(naga_words);
        if naga.is_none() {
            let needed = super::capabilities::features_for(&after.capabilities).map_err(
                |(c, what)| VkProblem::Unsupported {
                    feature: format!(
                        "SPIR-V capability {c:?} (shader {name}), which needs {what}: wgpu's device does not turn it on"
                    ),
                },
            )?;
            let missing = needed - self.available;
            if !missing.is_empty() {
                return Err(VkProblem::Unsupported {
                    feature: format!(
                        "a SPIR-V capability of shader {name} that needs wgpu's {missing:?}, which the adapter lacks"
                    ),
                }
                .into());
            }
        }
        Ok(naga)
    }
}
