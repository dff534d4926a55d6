//! Lowering: a validated capture, in DAG order, becomes a `crate::plan::Plan`, the
//! only place capture types meet wgpu. Usage flags come from every access (`usage`), formats
//! from `formats`, resources and their initial contents from side files or generators
//! (`resources`, `generate`, `meshes`), fixed-function state from `states`, and each pass
//! becomes the wgpu-level operation it describes (`passes`). Reads of a `history` resource
//! before the frame writes it are marked as previous-frame reads.

mod cross_pass;
pub mod formats;
pub mod frame;
pub mod generate;
mod meshes;
pub mod packed16;
mod passes;
pub mod repack;
mod resources;
mod states;
mod usage;
mod vulkan;

pub use vulkan::VkProblem;

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::plan::*;
use wgpu_types::Features;

use crate::capture::model::*;
use crate::capture::shaders::ShaderId;

/// Device features requested when the adapter has them.
pub fn wanted_features() -> Features {
    Features::TIMESTAMP_QUERY
        | Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | Features::TIMESTAMP_QUERY_INSIDE_PASSES
        | Features::PIPELINE_STATISTICS_QUERY
        | Features::TEXTURE_COMPRESSION_BC
        | Features::DEPTH32FLOAT_STENCIL8
        | Features::TEXTURE_FORMAT_16BIT_NORM
        | Features::RG11B10UFLOAT_RENDERABLE
        | Features::FLOAT32_FILTERABLE
        | Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
        // Imported Vulkan frames: their SPIR-V where naga cannot take it, their push
        // constants, and depth clamping.
        | Features::PASSTHROUGH_SHADERS
        | Features::IMMEDIATES
        | Features::DEPTH_CLIP_CONTROL
        | Features::CLEAR_TEXTURE
        // Imported samplers that clamp to a border colour, and dual-source blending.
        | Features::ADDRESS_MODE_CLAMP_TO_BORDER
        | Features::DUAL_SOURCE_BLENDING
        // What imported modules' SPIR-V capabilities need (`vulkan::capabilities`).
        | Features::CLIP_DISTANCES
        | Features::SHADER_F64
        | Features::SHADER_INT64
        | Features::SHADER_I16
        | Features::SHADER_F16
        | Features::SHADER_DRAW_INDEX
        // Imported indirect draws whose count the GPU reads (`vkCmdDrawIndirectCount`).
        | Features::MULTI_DRAW_INDIRECT_COUNT
        // Imported polygons drawn as lines or points, and vertex shaders that write storage.
        | Features::POLYGON_MODE_LINE
        | Features::POLYGON_MODE_POINT
        | Features::VERTEX_WRITABLE_STORAGE
}

#[derive(Debug, thiserror::Error)]
pub enum LowerError {
    #[error(
        "resource \"{resource}\" ({format}) cannot be replayed: {reason} (used by pass \"{pass}\")"
    )]
    Format {
        resource: String,
        format: String,
        reason: formats::FormatError,
        pass: String,
    },
    #[error("resource \"{resource}\": {problem}")]
    Contents {
        resource: String,
        problem: ContentsError,
    },
    #[error("mesh \"{mesh}\": {problem}")]
    Mesh { mesh: String, problem: MeshError },
    #[error("pass \"{pass}\": {problem}")]
    Pass { pass: String, problem: PassError },
    #[error("{0}")]
    NotReplayable(String),
    #[error("pass \"{pass}\", {work}: {problem}")]
    Vulkan {
        pass: String,
        work: String,
        problem: VkProblem,
    },
    #[error("pass \"{pass}\" needs {feature}, which adapter {adapter} does not support")]
    MissingFeature {
        pass: String,
        feature: String,
        adapter: String,
    },
}

/// Why a texture's or buffer's initial contents cannot be made. The reasons are part of the
/// message rather than error sources: the commands print the message alone.
#[derive(Debug, thiserror::Error)]
pub enum ContentsError {
    #[error(
        "a generator cannot write {format:?} (block-compressed or depth): give the texture a side file"
    )]
    Unwritable { format: wgpu_types::TextureFormat },
    #[error("reading {}: {error}", path.display())]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    /// Over what the capture declares for it, or not a regular file.
    #[error("{0}")]
    File(crate::files::FileError),
    #[error("side file is shorter than the texture")]
    ShortFile {
        path: PathBuf,
        needed: usize,
        len: usize,
    },
}

/// Why a mesh cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("its generator produced no vertices")]
    NoVertices,
    #[error("{vertices} vertices do not fit 16-bit indices")]
    TooManyFor16BitIndices { vertices: usize },
    #[error("reading {}: {error}", path.display())]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    /// Over what the capture declares for it, or not a regular file.
    #[error("{0}")]
    File(crate::files::FileError),
    #[error("side file too short")]
    ShortFile {
        path: PathBuf,
        needed: usize,
        len: usize,
    },
}

/// Why a pass cannot become a wgpu-level operation. Validation rules most of these out; they
/// remain for captures that reach the lowering by another way.
#[derive(Debug, thiserror::Error)]
pub enum PassError {
    #[error("no resolve")]
    NoResolve,
    #[error("no generate_mips")]
    NoGenerateMips,
    #[error("nothing to present")]
    NothingToPresent,
    #[error("no shader")]
    NoShader,
    #[error("\"{resource}\" was not created")]
    NotCreated { resource: String },
    #[error("{0}")]
    ViewFormat(formats::FormatError),
    #[error("blit {index}: {why}")]
    Blit { index: usize, why: String },
    #[error(
        "copy {index}: \"{resource}\" ({format}) is {how}, and the other end of the copy is not: a copy moves the capture's bytes as they are"
    )]
    RepackedCopy {
        index: usize,
        resource: String,
        format: &'static str,
        how: &'static str,
    },
    #[error(
        "copy {index}: {bytes} bytes from byte {src_offset} of \"{src}\" to byte {dst_offset} of \"{dst}\": a buffer copy whose offsets or size are not whole 4-byte words (Vulkan copies bytes; WebGPU copies words, and the bytes that share the copy's first and last words are not known before the frame runs)"
    )]
    UnalignedBufferCopy {
        index: usize,
        src: String,
        dst: String,
        src_offset: u64,
        dst_offset: u64,
        bytes: u64,
    },
    #[error(
        "copy {index}: from a buffer into \"{resource}\" ({format:?}): WebGPU copies no buffer into a 24-bit or 32-bit float depth texture, and with stencil the copy may be the stencil's (the capture does not say which aspect), so it cannot be drawn either"
    )]
    CopyIntoDepth {
        index: usize,
        resource: String,
        format: wgpu_types::TextureFormat,
    },
}

/// A lowered frame: the plan, the plan index of each capture resource and the capture pass of
/// each plan pass.
#[derive(Debug)]
pub struct LoweredFrame {
    pub plan: Plan,
    pub texture_of: BTreeMap<ResourceId, usize>,
    pub buffer_of: BTreeMap<ResourceId, usize>,
    /// The capture pass of each plan pass.
    pub pass_ids: Vec<PassId>,
    pub notes: Vec<String>,
}

/// The lowering in progress: the plan so far and what later steps need from earlier ones.
struct Lowering<'c> {
    capture: &'c Capture,
    available: Features,
    usage: usage::Usage<'c>,
    plan: Plan,
    texture_of: BTreeMap<ResourceId, usize>,
    buffer_of: BTreeMap<ResourceId, usize>,
    notes: Vec<String>,
    /// Optional device features each pass needs (by pass name, so errors name it).
    pass_features: BTreeMap<&'c str, Features>,
    shader_index: BTreeMap<ShaderId, usize>,
    /// Textures held with their bytes rearranged (`formats::Repack`), by plan index.
    repacked: BTreeMap<usize, (&'static str, formats::Repack)>,
    vk: vulkan::VkLowering,
    texels: Texels,
}

/// What the lowering does with textures' contents: read them into the plan, to replay; or
/// leave them out, to judge whether the frame would replay. No decision of the lowering reads
/// a texel (buffers' bytes it does read: index lists, vertex strides), and validation has held
/// each texture's side file to its size, so the judgement is the same at a fraction of the
/// memory: a game's frame holds tens of megabytes of textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Texels {
    Load,
    LeaveOut,
}

/// Lowers `capture`'s passes in `order` for an adapter with the `available` features.
pub fn lower(
    capture: &Capture,
    order: &[PassId],
    available: Features,
    adapter: &str,
) -> Result<LoweredFrame, LowerError> {
    lower_with(capture, order, available, adapter, Texels::Load)
}

/// As [`lower`], with textures' contents loaded or left out (`texels`).
pub fn lower_with(
    capture: &Capture,
    order: &[PassId],
    available: Features,
    adapter: &str,
    texels: Texels,
) -> Result<LoweredFrame, LowerError> {
    if let Some(why) = capture.not_replayable() {
        return Err(LowerError::NotReplayable(why));
    }
    let passes: Vec<&PassDesc> = order.iter().map(|&p| capture.pass(p)).collect();
    let mut l = Lowering {
        capture,
        available,
        usage: usage::Usage::of(capture, &passes),
        plan: Plan {
            textures: Vec::new(),
            buffers: Vec::new(),
            samplers: Vec::new(),
            meshes: Vec::new(),
            shaders: Vec::new(),
            passes: Vec::new(),
            vk: VkPlan::default(),
        },
        texture_of: BTreeMap::new(),
        buffer_of: BTreeMap::new(),
        notes: Vec::new(),
        pass_features: BTreeMap::new(),
        shader_index: BTreeMap::new(),
        repacked: BTreeMap::new(),
        vk: vulkan::VkLowering::default(),
        texels,
    };
    for r in &capture.resources {
        l.resource(r)?;
    }
    l.plan.samplers = capture.samplers.iter().map(states::sampler).collect();
    for m in &capture.meshes {
        l.plan.meshes.push(meshes::lower_mesh(m)?);
    }
    for p in &passes {
        l.pass(p)?;
    }
    cross_pass::gather(&mut l.plan);
    cross_pass::keep_resolved(&mut l.plan);
    cross_pass::mark_sampled_depth(&mut l.plan);
    for (pass, needed) in &l.pass_features {
        let missing = *needed - available;
        if !missing.is_empty() {
            return Err(LowerError::MissingFeature {
                pass: (*pass).to_owned(),
                // As wgpu documents them (`Features::TEXTURE_COMPRESSION_BC`), not a bit dump.
                feature: missing
                    .iter_names()
                    .map(|(name, _)| format!("Features::{name}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                adapter: adapter.to_owned(),
            });
        }
    }
    Ok(LoweredFrame {
        plan: l.plan,
        texture_of: l.texture_of,
        buffer_of: l.buffer_of,
        pass_ids: order.to_vec(),
        notes: l.notes,
    })
}
