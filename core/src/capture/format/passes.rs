//! Passes: kinds, shader references, bindings with their access and ranges, attachments.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{
    AttachmentClear, Blend, Blit, Clear, Copy, DepthStencilAttachment, Dispatch, Draw,
    GenerateMips, ParamValue, RecordedBarrier, RecordedTiming, RenderState, Resolve, ResourceKind,
};

/// One pass: a unit of GPU work on one queue with its declared resource accesses.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Pass {
    /// Unique name.
    pub name: String,
    /// Queue name.
    pub queue: String,
    pub kind: PassKind,
    /// Enclosing event/marker groups, outermost first (like PIX event groups).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<String>,
    /// WGSL shader for raster and compute passes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shader: Option<ShaderRef>,
    /// WGSL global variable name -> the resource view bound to it.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bindings: BTreeMap<String, Binding>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub color_attachments: Vec<ColorAttachment>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_stencil: Option<DepthStencilAttachment>,
    /// Fixed-function state for raster passes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<RenderState>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub draws: Vec<Draw>,
    /// For imported raster passes: rectangles of the pass's own attachments set to a value
    /// between its draws (`vkCmdClearAttachments`), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub attachment_clears: Vec<AttachmentClear>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dispatches: Vec<Dispatch>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub copies: Vec<Copy>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clears: Vec<Clear>,
    /// For blit passes: scaled, filtered copies, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blits: Vec<Blit>,
    /// For resolve passes: the multisampled source and single-sampled destination.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolve: Option<Resolve>,
    /// For mip-generation passes: the texture whose mips 1.. are built from mip 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generate_mips: Option<GenerateMips>,
    /// For present passes: the image presented.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub present: Option<String>,
    /// Per-pass parameters, packed by member name into the shader's `params` uniform struct.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
    /// Barriers the application recorded before this pass, as a real capture shows them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub barriers: Vec<RecordedBarrier>,
    /// Fences signalled after the pass.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub signal: Vec<String>,
    /// Fences waited on before the pass.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wait: Vec<String>,
    /// GPU time recorded at capture, if the capture tool measured it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timing: Option<RecordedTiming>,
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum PassKind {
    Raster,
    Compute,
    Copy,
    Blit,
    Clear,
    Resolve,
    GenerateMips,
    Present,
}

impl PassKind {
    pub fn as_str(self) -> &'static str {
        match self {
            PassKind::Raster => "raster",
            PassKind::Compute => "compute",
            PassKind::Copy => "copy",
            PassKind::Blit => "blit",
            PassKind::Clear => "clear",
            PassKind::Resolve => "resolve",
            PassKind::GenerateMips => "generate_mips",
            PassKind::Present => "present",
        }
    }
}

/// A WGSL file and its entry points.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaderRef {
    /// Path relative to the capture file.
    pub file: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fragment: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compute: Option<String>,
}

/// A resource view bound to a WGSL variable, or a sampler.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Binding {
    /// Resource name (absent when `sampler` is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resource: Option<String>,
    /// Sampler name, for WGSL `sampler` / `sampler_comparison` variables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampler: Option<String>,
    /// How the shader uses the view: sampled, storage_read, storage_write, storage_read_write
    /// or uniform.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub access: Option<Access>,
    /// Mip range of the view; all mips when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mips: Option<Range>,
    /// Array layer range (cube faces count as layers); all layers when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Range>,
    /// View format reinterpreting a typeless resource (e.g. R16_UNORM on R16_TYPELESS).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    /// View dimension if it differs from the resource (e.g. `texture_2d_array` over a cube).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimension: Option<ResourceKind>,
    /// Byte range of a buffer view; the whole buffer when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<ByteRange>,
}

/// A contiguous range `[base, base + count)`; `count` absent means "to the end".
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Range {
    #[serde(default)]
    pub base: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ByteRange {
    pub offset: u64,
    pub size: u64,
}

/// How a pass touches a resource. Shader bindings use the first five; the rest arise from
/// attachments, draws, copies and the other pass kinds.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Access {
    Sampled,
    StorageRead,
    StorageWrite,
    StorageReadWrite,
    Uniform,
    IndirectArgs,
    VertexBuffer,
    IndexBuffer,
    CopySrc,
    CopyDst,
    ColorAttachment,
    DepthRead,
    DepthWrite,
    ResolveSrc,
    ResolveDst,
    Present,
}

impl Access {
    pub fn as_str(self) -> &'static str {
        match self {
            Access::Sampled => "sampled",
            Access::StorageRead => "storage_read",
            Access::StorageWrite => "storage_write",
            Access::StorageReadWrite => "storage_read_write",
            Access::Uniform => "uniform",
            Access::IndirectArgs => "indirect_args",
            Access::VertexBuffer => "vertex_buffer",
            Access::IndexBuffer => "index_buffer",
            Access::CopySrc => "copy_src",
            Access::CopyDst => "copy_dst",
            Access::ColorAttachment => "color_attachment",
            Access::DepthRead => "depth_read",
            Access::DepthWrite => "depth_write",
            Access::ResolveSrc => "resolve_src",
            Access::ResolveDst => "resolve_dst",
            Access::Present => "present",
        }
    }
    /// Whether the access modifies the resource.
    pub fn writes(self) -> bool {
        matches!(
            self,
            Access::StorageWrite
                | Access::StorageReadWrite
                | Access::CopyDst
                | Access::ColorAttachment
                | Access::DepthWrite
                | Access::ResolveDst
        )
    }
    /// Whether the access reads the resource's previous contents (attachments loaded with
    /// `load` read too, which the graph decides from the attachment, not from the access).
    pub fn reads(self) -> bool {
        !matches!(
            self,
            Access::StorageWrite | Access::CopyDst | Access::ResolveDst | Access::ColorAttachment
        )
    }
    /// Whether a shader binding (as opposed to an attachment or command argument) may use it.
    pub fn is_shader_binding(self) -> bool {
        matches!(
            self,
            Access::Sampled
                | Access::StorageRead
                | Access::StorageWrite
                | Access::StorageReadWrite
                | Access::Uniform
        )
    }
    /// Whether the access is an unordered-access (UAV) use. A read-only storage *buffer*
    /// (`var<storage, read>`) is a shader resource view in D3D12 terms; a read-only storage
    /// *texture* is still a UAV.
    pub fn is_unordered(self, texture: bool) -> bool {
        match self {
            Access::StorageWrite | Access::StorageReadWrite => true,
            Access::StorageRead => texture,
            _ => false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LoadOp {
    Load,
    Clear,
    Discard,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StoreOp {
    Store,
    Discard,
}

/// A render target view written by a raster pass.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColorAttachment {
    pub resource: String,
    #[serde(default)]
    pub mip: u32,
    /// Array layer (or cube face, or 3D slice).
    #[serde(default)]
    pub layer: u32,
    /// View format for typeless resources.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    #[serde(default = "load_op_load")]
    pub load: LoadOp,
    #[serde(default = "store_op_store")]
    pub store: StoreOp,
    /// Clear colour when `load` is `clear`.
    #[serde(default)]
    pub clear: [f64; 4],
    /// Blend state of this target; opaque when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend: Option<Blend>,
    /// Channels written (a subset of "rgba"); all when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub write_mask: Option<String>,
}

pub(crate) fn load_op_load() -> LoadOp {
    LoadOp::Load
}
pub(crate) fn store_op_store() -> StoreOp {
    StoreOp::Store
}
