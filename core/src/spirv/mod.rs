//! Vulkan SPIR-V as captured from applications, made fit for wgpu. Imported frames carry the
//! applications' own shader modules; wgpu runs them through `create_shader_module_passthrough`,
//! which takes SPIR-V as is, so what wgpu cannot express has to be rewritten first. This module
//! owns both halves: `reflect` reads a module's interface (entry points, descriptor bindings,
//! push-constant size, capabilities) so a layout can be built for it, and `rewrite` reshapes the
//! module to that layout (combined image samplers split into an image and a sampler, bindings
//! renumbered, gl_Position's y negated for wgpu's flipped viewport). `usage` says which
//! bindings the code reads and writes, for the synchronization check.

mod array_decl;
mod arrays;
mod bias;
mod carry;
mod demote;
mod dispatch;
mod entry;
mod index;
mod index_params;
mod indexing;
mod layout;
mod memory_model;
mod mirror_once;
mod ops;
mod outputs;
mod param_copies;
mod params;
mod reclass;
mod reflect;
mod rewrite;
mod scaled;
mod specop;
mod std140;
mod storage;
mod subpass;
mod swizzle;
#[cfg(test)]
mod tests;
mod texel;
mod unnormalized;
mod unused;
mod usage;

/// Words in the module header (magic, version, generator, bound, schema).
const HEADER_WORDS: usize = 5;

use std::fmt;

use rspirv::spirv::{Capability, Dim, ExecutionModel, ImageFormat};

pub use arrays::{binding_element, element_binding, split_descriptor_arrays};
pub use layout::{BeyondStd140, uniform_blocks_beyond_std140};
pub use reflect::reflect;
pub use rewrite::rewrite;
pub use swizzle::{ONE as SWIZZLE_ONE, ZERO as SWIZZLE_ZERO};
pub use usage::{Usage, usage, usage_by_entry};

/// Why a module could not be read, reflected or rewritten.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SpirvError {
    #[error("SPIR-V is made of 32-bit words; {len} bytes is not a whole number of them")]
    NotWords { len: usize },
    #[error("not SPIR-V: the first word is {found:#010x}, not the magic number 0x07230203")]
    BadMagic { found: u32 },
    #[error("malformed SPIR-V at word {at_word}: {detail}")]
    Malformed { at_word: usize, detail: String },
    #[error("unsupported {feature}: {detail}")]
    Unsupported {
        feature: &'static str,
        detail: String,
    },
    #[error("the module has no {model:?} entry point named {name:?}")]
    EntryPointNotFound { model: ExecutionModel, name: String },
    #[error("set {set} binding {binding} ({role}) is not in the layout")]
    BindingNotInLayout { set: u32, binding: u32, role: Role },
    #[error("the module uses every id up to {bound}; none is left for the rewrite")]
    IdsExhausted { bound: u32 },
}

/// What [`usage`] gives: per (set, binding), what the code does there.
pub type Usages = std::collections::BTreeMap<(u32, u32), Usage>;

/// [`reflect`] and [`usage`] of one module, parsed once for both.
pub fn reflect_and_usage(words: &[u32]) -> Result<(Reflection, Usages), SpirvError> {
    let loaded = index::load(words)?;
    Ok((
        reflect::reflect_loaded(&loaded)?,
        usage::usage_loaded(&loaded, None)?,
    ))
}

/// SPIR-V words from the bytes of a .spv file. The file is little-endian as captured; a
/// byte-swapped magic number means a big-endian file, whose words are swapped back.
pub fn words(bytes: &[u8]) -> Result<Vec<u32>, SpirvError> {
    if !bytes.len().is_multiple_of(4) {
        return Err(SpirvError::NotWords { len: bytes.len() });
    }
    let mut words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    match words.first() {
        None => {
            return Err(SpirvError::Malformed {
                at_word: 0,
                detail: "the file is empty".to_owned(),
            });
        }
        Some(&m) if m == rspirv::spirv::MAGIC_NUMBER => {}
        Some(&m) if m == rspirv::spirv::MAGIC_NUMBER.swap_bytes() => {
            words.iter_mut().for_each(|w| *w = w.swap_bytes());
        }
        Some(&found) => return Err(SpirvError::BadMagic { found }),
    }
    Ok(words)
}

/// A module's interface: what a pipeline layout for it has to provide.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reflection {
    /// In module order.
    pub entry_points: Vec<EntryPoint>,
    /// Every variable decorated DescriptorSet and Binding, sorted by (set, binding), then by
    /// module order where variables alias one binding.
    pub resources: Vec<ResourceVar>,
    /// Bytes of the largest PushConstant block (0 when there is none): the furthest member
    /// offset plus that member's size.
    pub push_constant_size: u32,
    pub capabilities: Vec<Capability>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EntryPoint {
    pub model: ExecutionModel,
    pub name: String,
}

/// One descriptor variable.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResourceVar {
    pub set: u32,
    pub binding: u32,
    /// `Some(n)` for an array of n descriptors; `Some(0)` for a runtime-sized array.
    pub count: Option<u32>,
    pub kind: ResourceKind,
    /// NonWritable on the variable, or on every member of its block.
    pub non_writable: bool,
    /// NonReadable on the variable, or on every member of its block.
    pub non_readable: bool,
    /// The variable's result id.
    pub id: u32,
    /// Its OpName, when it has a non-empty one.
    pub name: Option<String>,
    /// For a uniform or storage buffer, the bytes its block's fixed part spans (the furthest
    /// member's end): what the shader may read, however little the program binds.
    pub block_size: Option<u64>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ResourceKind {
    /// Uniform storage class, Block struct.
    UniformBuffer,
    /// StorageBuffer storage class, or Uniform with a BufferBlock struct.
    StorageBuffer,
    /// SPIR-V does not say whether a sampler compares (that is in the sampler object), so
    /// `comparison` is always false here; the field is for the layout built from captured state.
    Sampler {
        comparison: bool,
    },
    SampledImage(ImageInfo),
    StorageImage(ImageInfo),
    CombinedImageSampler(ImageInfo),
    UniformTexelBuffer,
    StorageTexelBuffer(ImageFormat),
    InputAttachment {
        index: Option<u32>,
    },
    AccelerationStructure,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageInfo {
    pub dim: Dim,
    pub arrayed: bool,
    pub multisampled: bool,
    /// The Depth operand: `Some(false)` not depth, `Some(true)` depth, `None` not said.
    pub depth: Option<bool>,
    pub sampled_type: ScalarKind,
    pub format: ImageFormat,
}

/// The component type an image is sampled as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarKind {
    Float,
    Sint,
    Uint,
}

/// Which variable a new binding number is asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// A descriptor kept as it is.
    Whole,
    /// The image half of a combined image sampler.
    SplitImage,
    /// The sampler half of a combined image sampler.
    SplitSampler,
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Role::Whole => "whole",
            Role::SplitImage => "image of a combined image sampler",
            Role::SplitSampler => "sampler of a combined image sampler",
        })
    }
}

/// What `rewrite` is to do besides splitting combined image samplers.
pub struct RewriteOptions<'a> {
    /// Negate gl_Position.y written by the entry point: Vulkan's clip space has y down, and
    /// wgpu's Vulkan backend flips the viewport so that y is up. Only Vertex,
    /// TessellationEvaluation and Geometry entry points write the final position; it is ignored
    /// for the others.
    pub flip_y: bool,
    /// The new binding number for (set, binding, role); None means the binding is not in the
    /// layout, which is an error.
    pub binding: &'a dyn Fn(u32, u32, Role) -> Option<u32>,
    /// Specialization constants the pipeline gave, as (SpecId, value): each becomes a plain
    /// constant of that value (passthrough modules take no specialization in wgpu).
    pub specialization: &'a [(u32, u64)],
    /// The format of each uniform texel buffer, as (set, binding, format): the shader does not
    /// state it (the buffer view does), and its reads are unpacked in it.
    pub texel_formats: &'a [(u32, u32, ImageFormat)],
    /// The LOD bias of the sampler bound at each (set, binding, bias): added to every sample
    /// taken through it (`bias`), since wgpu's samplers have none.
    pub lod_bias: &'a [(u32, u32, f32)],
    /// Map the position's depth from OpenGL's clip range (-w to w) to Vulkan's (0 to w) in the
    /// entry point that writes the final position, as `flip_y` finds it.
    pub gl_depth: bool,
    /// The component swizzle of the view bound at each (set, binding), as codes (0 to 3 a
    /// channel, [`SWIZZLE_ZERO`], [`SWIZZLE_ONE`]): applied to every texel read through it
    /// (`swizzle`), since wgpu's views have none.
    pub swizzles: &'a [(u32, u32, [u8; 4])],
    /// The uniform blocks, by (set, binding), to read as read-only storage blocks
    /// (`storage`): laid out past std140, which wgpu's uniform bindings keep.
    pub storage_blocks: &'a [(u32, u32)],
    /// The uniform blocks, by (set, binding), whose arrays of 32-bit scalars at stride 4 are
    /// widened to arrays of 4-vectors (`std140`), so that they stay uniform blocks.
    pub std140_blocks: &'a [(u32, u32)],
    /// The samplers, by (set, binding), that take unnormalized coordinates, and whether they
    /// filter nearest: each sample through them has its coordinate divided by the image's
    /// size (`unnormalized`), a nearest one's first put at its texel's centre.
    pub unnormalized: &'a [(u32, u32, bool)],
    /// The samplers, by (set, binding), that mirror once and clamp on some axes (bit 0 `u`,
    /// 1 `v`, 2 `w`): each sample through them takes those coordinate components' absolute
    /// value (`mirror_once`), and the sampler clamps to the edge.
    pub mirror_once: &'a [(u32, u32, u8)],
    /// The fragment output locations with a colour attachment, a bit each (`outputs`): the
    /// others become private variables. `None` leaves every output.
    pub attached_outputs: Option<u32>,
    /// The vertex inputs, by location, whose attribute wgpu has no format for and that are
    /// fetched as integers: each becomes an integer input converted to the float it declared
    /// where loaded (`scaled`).
    pub scaled_inputs: &'a [(u32, IntegerFetch)],
}

/// How a vertex input whose attribute wgpu has no format for is fetched, and so how the
/// rewrite turns what is fetched into the float the shader declared (`scaled`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntegerFetch {
    /// A scaled format (`USCALED`, `SSCALED`: 3 read as 3.0) fetched as the integers it holds.
    Scaled { signed: bool },
    /// A packed 2-10-10-10 format fetched as its 32-bit word: red in the low ten bits
    /// (`A2B10G10R10`) or in bits 20 to 29 (`A2R10G10B10`), its channels signed or not,
    /// normalized (`UNORM`, `SNORM`) or scaled.
    Packed {
        red_low: bool,
        signed: bool,
        normalized: bool,
    },
}

impl fmt::Debug for RewriteOptions<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RewriteOptions")
            .field("flip_y", &self.flip_y)
            .finish_non_exhaustive()
    }
}

/// Whether the module decorates anything `Flat` (a fragment shader's flat inputs, whose value
/// the provoking vertex decides). A module that does not parse counts as having some.
pub fn has_flat(words: &[u32]) -> bool {
    let Ok(loaded) = index::load(words) else {
        return true;
    };
    loaded.module.annotations.iter().any(|i| {
        i.operands.iter().any(|o| {
            matches!(
                o,
                rspirv::dr::Operand::Decoration(rspirv::spirv::Decoration::Flat)
            )
        })
    })
}

/// Whether any function of the module uses a PushConstant variable (declaring one, and
/// listing it in an entry point's interface, reads nothing). A module that does not parse
/// counts as reading.
pub fn reads_push_constants(words: &[u32]) -> bool {
    use rspirv::dr::Operand;
    let Ok(loaded) = index::load(words) else {
        return true;
    };
    let module = &loaded.module;
    let blocks: Vec<u32> = module
        .types_global_values
        .iter()
        .filter(|i| {
            i.class.opcode == rspirv::spirv::Op::Variable
                && i.operands.first()
                    == Some(&Operand::StorageClass(
                        rspirv::spirv::StorageClass::PushConstant,
                    ))
        })
        .filter_map(|i| i.result_id)
        .collect();
    !blocks.is_empty()
        && module.functions.iter().any(|f| {
            f.all_inst_iter().any(|i| {
                i.operands
                    .iter()
                    .any(|o| matches!(o, Operand::IdRef(id) if blocks.contains(id)))
            })
        })
}
