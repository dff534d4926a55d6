//! The work inside passes (draws, dispatches, copies, clears, resolves, mip generation) and
//! the barriers and timings a capture recorded.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{ParamValue, Range, VkCommandState};

/// One draw call.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Draw {
    /// Label shown in event lists (e.g. "static meshes", "foliage").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Vertex entry point for this draw, if it differs from the shader's `vertex` (a pipeline
    /// change within the pass).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex: Option<String>,
    /// Fragment entry point for this draw, if it differs from the shader's `fragment` (an
    /// opaque variant without the alpha test's `discard`, which lets the GPU test depth before
    /// shading).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fragment: Option<String>,
    /// Mesh name; absent for full-screen draws that generate vertices in the shader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Vertex count (non-indexed) or index count (indexed); the mesh's when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    #[serde(default = "one_u32")]
    pub instances: u32,
    #[serde(default)]
    pub first: u32,
    #[serde(default)]
    pub first_instance: u32,
    #[serde(default)]
    pub base_vertex: i32,
    /// Vertex buffers bound for an imported draw (replayed draws take theirs from `mesh`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertex_buffers: Vec<String>,
    /// Index buffer bound for an imported indexed draw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_buffer: Option<String>,
    /// Arguments read from a buffer (DrawIndexedInstanced/DrawInstanced layout) instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect: Option<IndirectArgs>,
    /// The Vulkan pipeline bound when an imported draw was recorded (`vulkan.pipelines`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipeline: Option<String>,
    /// Dynamic viewport and scissor and push constants of an imported draw.
    #[serde(default, skip_serializing_if = "VkCommandState::is_empty")]
    pub vulkan_state: VkCommandState,
    /// The draw runs no fragment shader: opaque geometry in a pass without colour targets
    /// (shadow maps, a depth prepass), which the pass's fragment entry point (an alpha test)
    /// would only slow down. With no fragment stage the GPU tests depth before shading and
    /// runs no fragment invocations; alpha-tested draws of the same pass keep the shader.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub depth_only: bool,
    /// Stencil reference for this draw (OMSetStencilRef).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_reference: Option<u32>,
    /// Per-draw parameters overriding the pass's.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
}

pub(crate) fn one_u32() -> u32 {
    1
}

/// Indirect arguments in a buffer.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IndirectArgs {
    pub buffer: String,
    #[serde(default)]
    pub offset: u64,
    /// A draw's count read from a buffer on the GPU (`vkCmdDrawIndirectCount`, D3D12's
    /// `ExecuteIndirect` with a count buffer): that many records, at most `max_draws`, packed
    /// one after another from `offset`. Draws only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<DrawCount>,
}

/// Where an indirect draw's count is read (a 32-bit number), and the most records it draws.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DrawCount {
    pub buffer: String,
    #[serde(default)]
    pub offset: u64,
    pub max_draws: u32,
}

/// One compute dispatch.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Dispatch {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Entry point, if different from the shader's `compute` entry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub entry: Option<String>,
    /// Thread-group counts; absent when `indirect` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub groups: Option<[u32; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect: Option<IndirectArgs>,
    /// Instead of `groups`: enough thread groups for one thread per texel of this texture as
    /// replayed (its size at `--scale`), over the entry point's workgroup size, rounded up. A
    /// frame recorded at one resolution then dispatches what the replayed one needs, not
    /// threads that write nothing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cover: Option<Cover>,
    /// The Vulkan pipeline bound when an imported dispatch was recorded (`vulkan.pipelines`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipeline: Option<String>,
    /// Push constants of an imported dispatch.
    #[serde(default, skip_serializing_if = "VkCommandState::is_empty")]
    pub vulkan_state: VkCommandState,
    /// Per-dispatch parameters overriding the pass's.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
}

/// The texture (and mip) a dispatch covers with one thread per texel: width, height, and depth
/// (3D) or array layers.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Cover {
    pub resource: String,
    #[serde(default)]
    pub mip: u32,
}

/// A copy: buffer to buffer, buffer to texture, texture to buffer or texture to texture.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Copy {
    pub src: CopyLocation,
    pub dst: CopyLocation,
    /// Texel extent of the region; the whole source subresource when absent. For buffer to
    /// buffer copies, `size` in the locations is used instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extent: Option<[u32; 3]>,
    /// The source holds bytes the application's CPU wrote into mapped memory during the
    /// frame (an imported frame's host write): the submission that follows makes them
    /// visible, so Vulkan needs no barrier for them.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub host: bool,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CopyLocation {
    pub resource: String,
    /// Texture: mip level.
    #[serde(default)]
    pub mip: u32,
    /// Texture: array layer.
    #[serde(default)]
    pub layer: u32,
    /// Texture: texel origin.
    #[serde(default)]
    pub origin: [u32; 3],
    /// Buffer: byte offset.
    #[serde(default)]
    pub offset: u64,
    /// Buffer: bytes (buffer-to-buffer), or bytes per row of a texture footprint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<u64>,
    /// Buffer footprint of a texture copy: bytes per row (256-aligned in D3D12).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes_per_row: Option<u32>,
}

/// A scaled, filtered copy between regions of two textures (Vulkan's `vkCmdBlitImage`): each
/// destination texel centre maps linearly from the destination corners to the source corners
/// and the source is read there, clamped to its edge; a region whose corners run backwards on an
/// axis mirrors it. Formats convert as sampling and rendering would (sRGB decoded, then encoded).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Blit {
    pub src: BlitRegion,
    pub dst: BlitRegion,
    #[serde(default)]
    pub filter: BlitFilter,
}

/// One side of a blit: a 2D subresource and two opposite corners in its texels.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlitRegion {
    pub resource: String,
    #[serde(default)]
    pub mip: u32,
    #[serde(default)]
    pub layer: u32,
    /// `[x, y]` of the corner the mapping starts from, then of the opposite corner, in texels
    /// of the mip (0 to its width or height).
    pub corners: [[u32; 2]; 2],
}

/// How a blit reads between source texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BlitFilter {
    #[default]
    Nearest,
    Linear,
}

/// Rectangles of a raster pass's attachments cleared between two of its draws
/// (`vkCmdClearAttachments`): the colour attachments named and the depth or stencil aspect
/// take their values inside each rectangle, whatever the draws' state; nothing else changes.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AttachmentClear {
    /// The draw this clear comes before; the pass's draw count for a clear after its last.
    pub before_draw: u32,
    /// Colour attachments cleared: index into the pass's `color_attachments`, and the value.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub colors: Vec<AttachmentClearColor>,
    /// Depth value the depth aspect is cleared to (0 to 1), when cleared.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<f32>,
    /// Stencil value the stencil aspect is cleared to, when cleared.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil: Option<u32>,
    /// `[x, y, width, height]` in the attachments' pixels.
    pub rects: Vec<[u32; 4]>,
}

/// One colour attachment an attachment clear sets, with its value.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AttachmentClearColor {
    pub attachment: u32,
    pub value: [f64; 4],
}

/// A clear of a whole resource range (ClearRenderTargetView / ClearUnorderedAccessView...).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Clear {
    pub resource: String,
    /// Colour, depth (first value) or integer UAV clear value.
    #[serde(default)]
    pub value: [f64; 4],
    #[serde(default)]
    pub stencil: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mips: Option<Range>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Range>,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Resolve {
    pub src: String,
    pub dst: String,
    /// Resolve format for typeless resources.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GenerateMips {
    pub resource: String,
    /// Layers to build; all when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Range>,
}

/// A barrier as the capturing tool recorded it (ResourceBarrier arguments).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RecordedBarrier {
    #[serde(rename = "type", default = "transition")]
    pub barrier_type: BarrierType,
    /// The resource (after-resource for aliasing barriers; absent for a global UAV barrier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resource: Option<String>,
    /// Aliasing barriers: the resource that stops using the memory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resource_before: Option<String>,
    /// Subresource range; all subresources when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mips: Option<Range>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<Range>,
    /// Transitions: states before (one state, or several read states combined).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub before: Option<States>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after: Option<States>,
    /// Split barriers: BEGIN_ONLY or END_ONLY half.
    #[serde(default = "split_none")]
    pub split: SplitFlag,
    /// The Vulkan barrier as recorded (type `vulkan` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vulkan: Option<VulkanBarrier>,
}

/// A Vulkan name: borrowed from framelab's tables when framelab wrote it (an import makes
/// thousands), owned when read from a file.
pub type Name = std::borrow::Cow<'static, str>;

/// A Vulkan image, buffer or global memory barrier in the application's own terms: stage and
/// access masks and image layouts, by their Vulkan names without the `VK_` prefix and `_BIT`
/// suffix (`COLOR_ATTACHMENT_OUTPUT`, `SHADER_READ_ONLY_OPTIMAL`).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VulkanBarrier {
    /// The call that recorded it (`vkCmdPipelineBarrier2 #1234`), or the render pass whose
    /// attachment layouts implied it.
    pub origin: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub src_stages: Vec<Name>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub src_access: Vec<Name>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dst_stages: Vec<Name>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dst_access: Vec<Name>,
    /// Image barriers: the layout before and after.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub old_layout: Option<Name>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub new_layout: Option<Name>,
    /// Queue family ownership transfer, when the families differ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub src_queue_family: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dst_queue_family: Option<u32>,
}

pub(crate) fn transition() -> BarrierType {
    BarrierType::Transition
}
pub(crate) fn split_none() -> SplitFlag {
    SplitFlag::None
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BarrierType {
    Transition,
    Uav,
    Aliasing,
    /// A Vulkan pipeline barrier (image, buffer or global memory barrier; see `vulkan`).
    Vulkan,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum SplitFlag {
    None,
    BeginOnly,
    EndOnly,
}

/// One resource state or a combination of read states.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(
    untagged,
    expecting = "expected a resource state name (e.g. \"RENDER_TARGET\") or an array of read states"
)]
pub enum States {
    One(ResourceState),
    Many(Vec<ResourceState>),
}

impl States {
    pub fn as_slice(&self) -> &[ResourceState] {
        match self {
            States::One(s) => std::slice::from_ref(s),
            States::Many(v) => v,
        }
    }
}

/// D3D12_RESOURCE_STATES members.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum ResourceState {
    Common,
    VertexAndConstantBuffer,
    IndexBuffer,
    RenderTarget,
    UnorderedAccess,
    DepthWrite,
    DepthRead,
    NonPixelShaderResource,
    PixelShaderResource,
    IndirectArgument,
    CopyDest,
    CopySource,
    ResolveDest,
    ResolveSource,
    GenericRead,
    AllShaderResource,
    Present,
}

impl ResourceState {
    /// Write states may not be combined with any other state.
    pub fn is_write(self) -> bool {
        matches!(
            self,
            ResourceState::RenderTarget
                | ResourceState::UnorderedAccess
                | ResourceState::DepthWrite
                | ResourceState::CopyDest
                | ResourceState::ResolveDest
        )
    }
}

/// A GPU time measured when the frame was captured.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RecordedTiming {
    pub gpu_ns: u64,
}
