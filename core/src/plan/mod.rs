//! The replay plan: a frame at wgpu level (textures and buffers with their contents, samplers,
//! meshes as vertex streams, WGSL sources, and passes in execution order). `lower` builds it
//! from a validated capture and framelab-replay runs it; nothing here knows the capture format
//! or DXGI, and its vocabulary is wgpu's own plain data (`wgpu-types`), handed to the device as
//! it is.

use crate::capture::model::{PassId, QueueId};

mod targets;
mod vulkan;

pub use targets::{ColorTarget, DepthTarget};
pub use vulkan::*;

#[derive(Debug, Clone)]
pub struct Plan {
    pub textures: Vec<TextureSpec>,
    pub buffers: Vec<BufferSpec>,
    pub samplers: Vec<SamplerSpec>,
    pub meshes: Vec<MeshSpec>,
    pub shaders: Vec<ShaderSource>,
    /// Passes in execution order.
    pub passes: Vec<PassSpec>,
    /// An imported frame's pipelines (empty for a capture written for framelab).
    pub vk: VkPlan,
}

#[derive(Debug, Clone)]
pub struct TextureSpec {
    pub name: String,
    pub format: wgpu_types::TextureFormat,
    pub dimension: wgpu_types::TextureDimension,
    /// Width, height, and depth or array layers.
    pub size: wgpu_types::Extent3d,
    pub mip_levels: u32,
    pub samples: u32,
    pub usage: wgpu_types::TextureUsages,
    /// Formats its views take besides `format` (its sRGB twin).
    pub view_formats: Vec<wgpu_types::TextureFormat>,
    /// Contents per mip (every layer, or the 3D volume, of that mip), tightly packed.
    pub initial: Option<Vec<Vec<u8>>>,
    /// Two copies swapped between frames; reads marked `previous_frame` see the other one.
    pub history: bool,
    /// Is a cube (or cube array) for view purposes.
    pub cube: bool,
}

#[derive(Debug, Clone)]
pub struct BufferSpec {
    pub name: String,
    pub size: u64,
    pub usage: wgpu_types::BufferUsages,
    pub initial: Option<Vec<u8>>,
    pub history: bool,
}

#[derive(Debug, Clone)]
pub struct SamplerSpec {
    pub name: String,
    pub address: [wgpu_types::AddressMode; 3],
    pub mag: wgpu_types::FilterMode,
    pub min: wgpu_types::FilterMode,
    pub mip: wgpu_types::MipmapFilterMode,
    pub lod: (f32, f32),
    pub compare: Option<wgpu_types::CompareFunction>,
    pub anisotropy: u16,
    /// What a clamp-to-border address reads outside the texture (needs the adapter's
    /// `ADDRESS_MODE_CLAMP_TO_BORDER`).
    pub border: Option<wgpu_types::SamplerBorderColor>,
}

#[derive(Debug, Clone)]
pub struct MeshSpec {
    pub name: String,
    pub streams: Vec<StreamSpec>,
    pub indices: Option<(Vec<u8>, wgpu_types::IndexFormat, u32)>,
    pub vertex_count: u32,
    pub instance_count: u32,
}

#[derive(Debug, Clone)]
pub struct StreamSpec {
    pub slot: u32,
    pub data: Vec<u8>,
    pub stride: u64,
    pub step: wgpu_types::VertexStepMode,
    /// (format, byte offset within the element, shader location)
    pub attributes: Vec<(wgpu_types::VertexFormat, u64, u32)>,
}

#[derive(Debug, Clone)]
pub struct ShaderSource {
    /// As named in messages (the capture's relative path).
    pub name: String,
    pub source: String,
    /// The module parsed and validated once, by whoever built the plan; the session reflects
    /// bindings and uniforms from it instead of parsing the source again.
    pub validated: std::sync::Arc<crate::shader::ValidatedShader>,
}

pub use crate::uniforms::Params;

#[derive(Debug, Clone)]
pub struct PassSpec {
    /// The capture pass it replays.
    pub id: PassId,
    /// As named in labels and messages.
    pub name: String,
    /// The capture queue it came from (wgpu replays every pass on one queue).
    pub queue: QueueId,
    pub op: PassOp,
}

#[derive(Debug, Clone)]
pub enum PassOp {
    Raster(RasterOp),
    Compute(ComputeOp),
    Copy(Vec<CopyOp>),
    /// Scaled, filtered copies, each drawn into its destination region.
    Blit(Vec<BlitOp>),
    Clear(Vec<ClearOp>),
    Resolve {
        src: usize,
        dst: usize,
    },
    GenerateMips {
        texture: usize,
        base_layer: u32,
        layers: u32,
    },
    /// An imported render pass: each draw with its own Vulkan pipeline.
    VkRaster(VkRasterOp),
    /// An imported compute pass.
    VkCompute(VkComputeOp),
    /// The presented image; replay leaves it for export.
    Present {
        texture: usize,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub enum BindTarget {
    Texture {
        texture: usize,
        format: wgpu_types::TextureFormat,
        base_mip: u32,
        mips: u32,
        base_layer: u32,
        layers: u32,
        previous_frame: bool,
    },
    Buffer {
        buffer: usize,
        offset: u64,
        size: Option<u64>,
        previous_frame: bool,
    },
    Sampler(usize),
}

#[derive(Debug, Clone)]
pub struct Binding {
    pub variable: String,
    pub target: BindTarget,
}

#[derive(Debug, Clone)]
pub struct RasterOp {
    pub shader: usize,
    pub vertex: String,
    pub fragment: Option<String>,
    pub bindings: Vec<Binding>,
    pub params: Params,
    pub color: Vec<ColorTarget>,
    pub depth: Option<DepthTarget>,
    pub primitive: wgpu_types::PrimitiveState,
    pub depth_stencil: Option<wgpu_types::DepthStencilState>,
    pub stencil_reference: u32,
    pub draws: Vec<DrawOp>,
}

#[derive(Debug, Clone)]
pub struct DrawOp {
    pub label: Option<String>,
    pub vertex: Option<String>,
    /// The draw's own fragment entry point, when it differs from the pass's.
    pub fragment: Option<String>,
    pub mesh: Option<usize>,
    pub count: Option<u32>,
    pub instances: u32,
    pub first: u32,
    pub first_instance: u32,
    pub base_vertex: i32,
    pub indirect: Option<(usize, u64)>,
    /// Count buffer, offset and most records of a draw whose count the GPU reads.
    pub draw_count: Option<(usize, u64, u32)>,
    pub stencil_reference: Option<u32>,
    /// No fragment stage (see the format's `Draw::depth_only`).
    pub depth_only: bool,
    pub params: Params,
}

#[derive(Debug, Clone)]
pub struct ComputeOp {
    pub shader: usize,
    pub entry: String,
    pub bindings: Vec<Binding>,
    pub params: Params,
    pub dispatches: Vec<DispatchOp>,
}

#[derive(Debug, Clone)]
pub struct DispatchOp {
    pub entry: Option<String>,
    pub groups: Option<[u32; 3]>,
    pub indirect: Option<(usize, u64)>,
    pub params: Params,
}

#[derive(Debug, Clone)]
pub enum CopyEnd {
    Texture {
        texture: usize,
        mip: u32,
        layer: u32,
        origin: [u32; 3],
    },
    Buffer {
        buffer: usize,
        offset: u64,
        bytes_per_row: Option<u32>,
    },
}

/// A blit at wgpu level: both sides 2D subresources of colour textures, the destination
/// renderable, the source filterable where `linear`.
#[derive(Debug, Clone)]
pub struct BlitOp {
    pub src: usize,
    pub src_mip: u32,
    pub src_layer: u32,
    /// The corner the mapping starts from, then the opposite one, in texels.
    pub src_corners: [[u32; 2]; 2],
    pub dst: usize,
    pub dst_mip: u32,
    pub dst_layer: u32,
    pub dst_corners: [[u32; 2]; 2],
    pub linear: bool,
}

/// Where a 16-bit packed format keeps each channel: (shift, bits) of R, G, B and A in the
/// texel's word; 0 bits for a channel it lacks (`lower::packed16`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Packed16 {
    pub fields: [(u8, u8); 4],
}

#[derive(Debug, Clone)]
pub struct CopyOp {
    pub src: CopyEnd,
    pub dst: CopyEnd,
    /// A copy from a buffer into a texture held as RGBA8 for a 16-bit packed format: drawn,
    /// each texel unpacked from the buffer's words in this layout.
    pub unpack: Option<Packed16>,
    /// A copy from a buffer into a depth texture without stencil that WebGPU copies no buffer
    /// into (`Depth32Float`, `Depth24Plus`): drawn, each texel's depth read from the buffer's
    /// words (a float, or 24 normalized bits in the low bits of a word).
    pub depth: bool,
    /// Texel extent for texture copies; byte count for buffer-to-buffer copies in `[0]`.
    pub extent: [u32; 3],
    pub bytes: u64,
}

#[derive(Debug, Clone)]
pub enum ClearOp {
    /// Through a render pass clear (render targets and depth).
    Attachment {
        texture: usize,
        format: wgpu_types::TextureFormat,
        base_mip: u32,
        mips: u32,
        base_layer: u32,
        layers: u32,
        value: [f64; 4],
        stencil: u32,
    },
    /// `clear_texture` / `clear_buffer` (zero) for unordered-access resources; non-zero values
    /// are written from the CPU.
    Texture {
        texture: usize,
        base_mip: u32,
        mips: u32,
        base_layer: u32,
        layers: u32,
        value: [f64; 4],
    },
    Buffer {
        buffer: usize,
        value: u32,
    },
}
