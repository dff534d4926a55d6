//! The capture file format, version 1: the serde types a capture JSON file deserialises into.
//!
//! These types mirror the file one to one. Names that refer to other objects (resources, heaps,
//! queues, formats) stay strings here so that validation can report every unknown name at once
//! with a suggestion, instead of stopping at serde's first error; `validate` turns a `RawCapture`
//! into the typed `Capture`. The JSON Schema (`framelab schema`) is generated from these types,
//! so every doc comment here is also the documentation editors show.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The only format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// A GPU frame: what it allocates, where, and the passes that run on which queue.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawCapture {
    /// Format version; must be 1.
    pub format_version: u32,
    /// Short name of the frame, shown in reports.
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The output resolution at `--scale 1`; relative sizes resolve against it.
    pub resolution: Resolution,
    /// The adapter the frame was captured on, as far as validation rules depend on it.
    #[serde(default)]
    pub adapter: AdapterModel,
    /// Camera for the frame constants (view/projection) and its motion between frames.
    pub camera: Camera,
    /// Frame-level constants: time and sky.
    #[serde(default)]
    pub frame: FrameConstants,
    /// Explicit D3D12 heaps that placed resources live in.
    #[serde(default)]
    pub heaps: Vec<Heap>,
    #[serde(default)]
    pub resources: Vec<Resource>,
    #[serde(default)]
    pub descriptor_heaps: Vec<DescriptorHeap>,
    #[serde(default)]
    pub samplers: Vec<Sampler>,
    /// Command queues. Every pass runs on one of them.
    pub queues: Vec<Queue>,
    /// Fences that passes signal and wait on to order work across queues.
    #[serde(default)]
    pub fences: Vec<Fence>,
    #[serde(default)]
    pub meshes: Vec<Mesh>,
    /// Passes in the order the application recorded them (per queue, this is submission order).
    #[serde(default)]
    pub passes: Vec<Pass>,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Resolution {
    pub width: u32,
    pub height: u32,
}

/// Properties of the capturing adapter that D3D12's validity rules depend on.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AdapterModel {
    /// `numa`: a discrete GPU with its own memory (L1 is video memory, not CPU-visible);
    /// `uma`: one memory shared by CPU and GPU (only L0 exists).
    #[serde(default = "default_architecture")]
    pub architecture: MemoryArchitecture,
    /// D3D12_RESOURCE_HEAP_TIER: 1 means a heap holds only one of buffers, RT/DS textures or
    /// other textures; 2 allows mixing.
    #[serde(default = "default_tier")]
    pub resource_heap_tier: u8,
}

impl Default for AdapterModel {
    fn default() -> Self {
        Self {
            architecture: default_architecture(),
            resource_heap_tier: default_tier(),
        }
    }
}

fn default_architecture() -> MemoryArchitecture {
    MemoryArchitecture::Numa
}
fn default_tier() -> u8 {
    2
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MemoryArchitecture {
    Numa,
    Uma,
}

/// A perspective camera. Frame constants (view, projection, previous-frame matrices, jitter)
/// are computed from it for every replayed frame.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
    #[serde(default = "default_near")]
    pub near: f32,
    #[serde(default = "default_far")]
    pub far: f32,
    /// World-space movement of the camera per frame, so that motion vectors and temporal
    /// passes see real motion when several frames are replayed.
    #[serde(default)]
    pub velocity: [f32; 3],
    /// Sub-pixel jitter sequence length (Halton 2,3); 0 disables jitter.
    #[serde(default = "default_jitter")]
    pub jitter_phases: u32,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_near() -> f32 {
    0.1
}
fn default_far() -> f32 {
    1000.0
}
fn default_jitter() -> u32 {
    8
}

/// Frame-level constants available to every shader.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FrameConstants {
    /// Time of the first replayed frame, in seconds.
    #[serde(default)]
    pub time_seconds: f32,
    /// Seconds between frames.
    #[serde(default = "default_dt")]
    pub delta_seconds: f32,
    /// Direction *towards* the sun (need not be normalised).
    #[serde(default = "default_sun")]
    pub sun_direction: [f32; 3],
    /// Sun colour times illuminance, linear.
    #[serde(default = "default_sun_color")]
    pub sun_color: [f32; 3],
    /// Direction towards the moon.
    #[serde(default = "default_moon")]
    pub moon_direction: [f32; 3],
    #[serde(default = "default_moon_color")]
    pub moon_color: [f32; 3],
    /// Camera exposure multiplier applied before tone mapping.
    #[serde(default = "default_exposure")]
    pub exposure: f32,
    /// Cascaded shadow maps for the sun (or the moon when the sun is below the horizon).
    #[serde(default)]
    pub shadow_cascades: ShadowCascades,
    /// Half-width in metres of the orthographic top view centred under the camera (sky
    /// visibility and mini-map passes use it as `top_view_proj`).
    #[serde(default = "default_top_view_extent")]
    pub top_view_extent: f32,
}

/// How the four shadow cascades are fitted to the view frustum: practical split scheme
/// (`split_lambda` blends logarithmic and linear splits) up to `max_distance`, each cascade a
/// bounding sphere of its frustum slice snapped to whole texels of a `resolution` map so the
/// shadows do not shimmer as the camera moves.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShadowCascades {
    #[serde(default = "default_cascade_resolution")]
    pub resolution: u32,
    #[serde(default = "default_split_lambda")]
    pub split_lambda: f32,
    #[serde(default = "default_shadow_distance")]
    pub max_distance: f32,
}

impl Default for ShadowCascades {
    fn default() -> Self {
        Self {
            resolution: default_cascade_resolution(),
            split_lambda: default_split_lambda(),
            max_distance: default_shadow_distance(),
        }
    }
}

fn default_cascade_resolution() -> u32 {
    2048
}
fn default_split_lambda() -> f32 {
    0.75
}
fn default_shadow_distance() -> f32 {
    200.0
}
fn default_top_view_extent() -> f32 {
    256.0
}

impl Default for FrameConstants {
    fn default() -> Self {
        Self {
            time_seconds: 0.0,
            delta_seconds: default_dt(),
            sun_direction: default_sun(),
            sun_color: default_sun_color(),
            moon_direction: default_moon(),
            moon_color: default_moon_color(),
            exposure: default_exposure(),
            shadow_cascades: ShadowCascades::default(),
            top_view_extent: default_top_view_extent(),
        }
    }
}

fn default_dt() -> f32 {
    1.0 / 60.0
}
fn default_sun() -> [f32; 3] {
    [0.3, 0.8, 0.4]
}
fn default_sun_color() -> [f32; 3] {
    [1.0, 0.95, 0.9]
}
fn default_moon() -> [f32; 3] {
    [-0.3, 0.6, -0.5]
}
fn default_moon_color() -> [f32; 3] {
    [0.05, 0.06, 0.09]
}
fn default_exposure() -> f32 {
    1.0
}

// ---------------------------------------------------------------------------------------------
// Heaps

/// A D3D12 heap (`D3D12_HEAP_DESC`): a block of memory that placed resources are put in.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Heap {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: HeapType,
    /// Only for CUSTOM heaps; must be UNKNOWN (or absent) otherwise.
    #[serde(default = "unknown_page")]
    pub cpu_page_property: CpuPageProperty,
    /// Only for CUSTOM heaps; must be UNKNOWN (or absent) otherwise.
    #[serde(default = "unknown_pool")]
    pub memory_pool: MemoryPool,
    /// Size in bytes.
    pub size: u64,
    /// 65536 (64 KiB, the default) or 4194304 (4 MiB, needed for MSAA textures).
    #[serde(default = "default_heap_alignment")]
    pub alignment: u64,
    /// D3D12_HEAP_FLAGS; ALLOW_ONLY_* and ALLOW_ALL_BUFFERS_AND_TEXTURES are aliases of DENY_*
    /// combinations and are accepted as such.
    #[serde(default)]
    pub flags: Vec<HeapFlag>,
}

fn unknown_page() -> CpuPageProperty {
    CpuPageProperty::Unknown
}
fn unknown_pool() -> MemoryPool {
    MemoryPool::Unknown
}
fn default_heap_alignment() -> u64 {
    65536
}

/// D3D12_HEAP_TYPE.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum HeapType {
    /// GPU-only memory, fastest for the GPU.
    Default,
    /// CPU-writable, GPU-readable (write-combined system memory on NUMA).
    Upload,
    /// GPU-writable, CPU-readable (cached system memory).
    Readback,
    /// Page property and memory pool given explicitly.
    Custom,
}

/// D3D12_CPU_PAGE_PROPERTY.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum CpuPageProperty {
    Unknown,
    NotAvailable,
    WriteCombine,
    WriteBack,
}

/// D3D12_MEMORY_POOL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum MemoryPool {
    #[serde(rename = "UNKNOWN")]
    Unknown,
    /// System memory (the only pool on UMA).
    L0,
    /// Video memory on NUMA adapters; not CPU-accessible.
    L1,
}

/// D3D12_HEAP_FLAGS members.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum HeapFlag {
    None,
    Shared,
    DenyBuffers,
    AllowDisplay,
    SharedCrossAdapter,
    DenyRtDsTextures,
    DenyNonRtDsTextures,
    HardwareProtected,
    AllowWriteWatch,
    AllowShaderAtomics,
    AllowAllBuffersAndTextures,
    AllowOnlyBuffers,
    AllowOnlyNonRtDsTextures,
    AllowOnlyRtDsTextures,
}

// ---------------------------------------------------------------------------------------------
// Resources

/// A buffer or texture (`D3D12_RESOURCE_DESC` plus how it is placed and filled).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Resource {
    /// Stable name that passes, tools and tests refer to.
    pub name: String,
    pub kind: ResourceKind,
    /// DXGI format name (e.g. `R10G10B10A2_UNORM`), required for textures; buffers may give one
    /// for typed views.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    /// Texture width: texels, or relative to the output resolution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<Extent>,
    /// Texture height (1D textures: absent or 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<Extent>,
    /// Depth of a 3D texture, in texels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<u32>,
    /// Array layers (2D arrays; a cube has 6 per cube, so a cube array gives a multiple of 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array_layers: Option<u32>,
    /// Mip levels: a count, or `"full"` for the whole chain down to 1x1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mip_levels: Option<MipLevels>,
    /// MSAA sample count (1, 2, 4, 8, 16).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<u32>,
    /// Buffer size in bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<u64>,
    /// Element stride in bytes for structured buffers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stride: Option<u32>,
    /// How shaders view a buffer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub buffer_kind: Option<BufferKind>,
    /// D3D12_RESOURCE_FLAGS.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flags: Vec<ResourceFlag>,
    /// Where the memory comes from; committed in a DEFAULT heap when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<Placement>,
    /// Contents before the first pass; undefined when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialContents>,
    /// Read by the next frame (TAA history, previous depth): replay keeps two copies and swaps
    /// them between frames, and reads of it within a frame see the previous frame's contents.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub history: bool,
    /// A frame output besides the presented image: keeps the passes writing it alive when
    /// culling.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub output: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ResourceKind {
    Buffer,
    #[serde(rename = "texture_1d")]
    Texture1D,
    #[serde(rename = "texture_2d")]
    Texture2D,
    #[serde(rename = "texture_2d_array")]
    Texture2DArray,
    TextureCube,
    #[serde(rename = "texture_3d")]
    Texture3D,
}

impl ResourceKind {
    pub fn is_texture(self) -> bool {
        self != ResourceKind::Buffer
    }
    pub fn as_str(self) -> &'static str {
        match self {
            ResourceKind::Buffer => "buffer",
            ResourceKind::Texture1D => "texture_1d",
            ResourceKind::Texture2D => "texture_2d",
            ResourceKind::Texture2DArray => "texture_2d_array",
            ResourceKind::TextureCube => "texture_cube",
            ResourceKind::Texture3D => "texture_3d",
        }
    }
}

/// A texture dimension: absolute texels, or relative to the output resolution (`"full"`,
/// `"half"`, `"quarter"`, `{ "scale": 0.125 }`, optionally rounded up to a multiple).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Extent {
    Texels(u64),
    Named(RelativeSize),
    Scaled {
        /// Fraction of the output dimension; the result is rounded up.
        scale: f64,
        /// Round the result up to a multiple of this (e.g. 8 for tile grids).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        multiple_of: Option<u32>,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum RelativeSize {
    Full,
    Half,
    Quarter,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum MipLevels {
    Count(u32),
    Chain(FullChain),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FullChain {
    Full,
}

/// How shaders see a buffer (HLSL's view types).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BufferKind {
    /// StructuredBuffer / RWStructuredBuffer: elements of `stride` bytes.
    Structured,
    /// ByteAddressBuffer: 32-bit words addressed in bytes (also used for indirect arguments).
    ByteAddress,
    /// Untyped memory: vertex, index and constant data, copy sources.
    Raw,
    /// Buffer<T>: elements of the buffer's `format`.
    Typed,
}

/// D3D12_RESOURCE_FLAGS members.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum ResourceFlag {
    AllowRenderTarget,
    AllowDepthStencil,
    AllowUnorderedAccess,
    DenyShaderResource,
    AllowCrossAdapter,
    AllowSimultaneousAccess,
    VideoDecodeReferenceOnly,
    RaytracingAccelerationStructure,
}

/// Where a resource's memory comes from.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Placement {
    /// CreateCommittedResource: an implicit heap of its own.
    Committed {
        #[serde(default = "default_heap_type")]
        heap_type: HeapType,
    },
    /// CreatePlacedResource: at `offset` bytes into a named heap.
    Placed { heap: String, offset: u64 },
    /// CreateReservedResource: virtual address range only; tiles are mapped later.
    Reserved,
}

fn default_heap_type() -> HeapType {
    HeapType::Default
}

/// Contents of a resource before the frame starts.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialContents {
    /// Raw bytes from a file next to the capture (tightly packed subresources, mip-major).
    File { path: String },
    /// A named procedural generator with a seed and generator parameters.
    Generator {
        name: String,
        #[serde(default)]
        seed: u64,
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        params: BTreeMap<String, ParamValue>,
    },
}

/// A number or a small vector of numbers.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum ParamValue {
    Scalar(f64),
    Vector(Vec<f64>),
}

// ---------------------------------------------------------------------------------------------
// Descriptors and samplers

/// A descriptor heap (`D3D12_DESCRIPTOR_HEAP_DESC`).
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DescriptorHeap {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: DescriptorHeapType,
    /// Number of descriptors.
    pub capacity: u32,
    /// Whether shaders can reference it (only CBV_SRV_UAV and SAMPLER heaps can be).
    #[serde(default)]
    pub shader_visible: bool,
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize, JsonSchema,
)]
pub enum DescriptorHeapType {
    #[serde(rename = "CBV_SRV_UAV")]
    CbvSrvUav,
    #[serde(rename = "SAMPLER")]
    Sampler,
    #[serde(rename = "RTV")]
    Rtv,
    #[serde(rename = "DSV")]
    Dsv,
}

/// A static sampler.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sampler {
    pub name: String,
    #[serde(default = "linear")]
    pub min_filter: Filter,
    #[serde(default = "linear")]
    pub mag_filter: Filter,
    #[serde(default = "linear")]
    pub mip_filter: Filter,
    #[serde(default = "clamp")]
    pub address_u: AddressMode,
    #[serde(default = "clamp")]
    pub address_v: AddressMode,
    #[serde(default = "clamp")]
    pub address_w: AddressMode,
    /// Comparison function for shadow-map samplers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare: Option<CompareFunction>,
    /// 1 disables anisotropic filtering; up to 16.
    #[serde(default = "one")]
    pub max_anisotropy: u16,
    #[serde(default)]
    pub lod_min: f32,
    #[serde(default = "lod_max")]
    pub lod_max: f32,
}

fn linear() -> Filter {
    Filter::Linear
}
fn clamp() -> AddressMode {
    AddressMode::Clamp
}
fn one() -> u16 {
    1
}
fn lod_max() -> f32 {
    32.0
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    Point,
    Linear,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AddressMode {
    Wrap,
    Clamp,
    Mirror,
    Border,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CompareFunction {
    Never,
    Less,
    Equal,
    LessEqual,
    Greater,
    NotEqual,
    GreaterEqual,
    Always,
}

// ---------------------------------------------------------------------------------------------
// Queues and fences

/// A command queue (`D3D12_COMMAND_LIST_TYPE`): graphics queues can do everything, compute
/// queues compute and copies, copy queues only copies.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Queue {
    pub name: String,
    #[serde(rename = "type")]
    pub queue_type: QueueType,
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum QueueType {
    Graphics,
    Compute,
    Copy,
}

/// A fence. A pass lists the fences it signals when it finishes and the fences it waits for
/// before it starts; this is how work on different queues is ordered.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Fence {
    pub name: String,
}

// ---------------------------------------------------------------------------------------------
// Meshes

/// Geometry: structure-of-arrays vertex streams and an optional index buffer.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Mesh {
    pub name: String,
    /// Where the vertex and index data come from.
    pub source: MeshSource,
    /// Vertex streams, one per input slot, each with its own format.
    pub streams: Vec<VertexStream>,
    /// Index format; non-indexed when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_format: Option<IndexFormat>,
    /// Vertex count; required for file sources (generators compute it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_count: Option<u32>,
    /// Index count; required for indexed file sources.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_count: Option<u32>,
    /// Instance count of per-instance streams; required when any stream steps per instance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instance_count: Option<u32>,
    /// Content generator of the per-instance transform rows of a generator mesh (`instances`
    /// scatters them, `city_lots` places one box per building lot); `instances` with the mesh's
    /// seed when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instances: Option<InstanceGenerator>,
}

/// A named content generator for per-instance rows, with its seed and parameters.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InstanceGenerator {
    pub name: String,
    #[serde(default)]
    pub seed: u64,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MeshSource {
    /// A binary file: each per-vertex stream's data in stream order, then per-instance streams,
    /// then the indices, tightly packed, little-endian.
    File { path: String },
    /// A procedural generator (grid, box, city_blocks, terrain, water_plate, foliage_cards,
    /// sphere, capsule) with a seed and its parameters.
    Generator {
        name: String,
        #[serde(default)]
        seed: u64,
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        params: BTreeMap<String, ParamValue>,
    },
}

/// One vertex buffer slot.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexStream {
    /// Input slot (VB0, VB1, ...).
    pub slot: u32,
    /// Attributes in the stream, interleaved within it in this order.
    pub attributes: Vec<VertexAttribute>,
    /// Per-vertex (default) or per-instance data.
    #[serde(default = "per_vertex")]
    pub step: StepMode,
}

fn per_vertex() -> StepMode {
    StepMode::Vertex
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexAttribute {
    /// HLSL semantic, e.g. POSITION0, TEXCOORD1, INSTANCE_TRANSFORM2.
    pub semantic: String,
    pub format: VertexFormat,
    /// WGSL `@location` the attribute feeds.
    pub location: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StepMode {
    Vertex,
    Instance,
}

/// Vertex attribute encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum VertexFormat {
    /// Four signed normalised 16-bit integers (positions scaled into [-1, 1]).
    Snorm16x4,
    Snorm16x2,
    Unorm16x2,
    Float16x2,
    Float16x4,
    /// Normal or tangent packed in 32 bits: 10:10:10:2, signed normalised.
    PackedSnorm10x3,
    Unorm8x4,
    Snorm8x4,
    Uint8x4,
    Float32,
    Float32x2,
    Float32x3,
    Float32x4,
    Uint32,
    Uint32x2,
}

impl VertexFormat {
    pub fn size(self) -> u32 {
        match self {
            VertexFormat::Snorm16x4 | VertexFormat::Float16x4 | VertexFormat::Float32x2 => 8,
            VertexFormat::Uint32x2 => 8,
            VertexFormat::Snorm16x2
            | VertexFormat::Unorm16x2
            | VertexFormat::Float16x2
            | VertexFormat::PackedSnorm10x3
            | VertexFormat::Unorm8x4
            | VertexFormat::Snorm8x4
            | VertexFormat::Uint8x4
            | VertexFormat::Float32
            | VertexFormat::Uint32 => 4,
            VertexFormat::Float32x3 => 12,
            VertexFormat::Float32x4 => 16,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum IndexFormat {
    Uint16,
    Uint32,
}

impl IndexFormat {
    pub fn size(self) -> u32 {
        match self {
            IndexFormat::Uint16 => 2,
            IndexFormat::Uint32 => 4,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Passes

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
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dispatches: Vec<Dispatch>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub copies: Vec<Copy>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clears: Vec<Clear>,
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
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Range {
    #[serde(default)]
    pub base: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
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

fn load_op_load() -> LoadOp {
    LoadOp::Load
}
fn store_op_store() -> StoreOp {
    StoreOp::Store
}

/// The depth-stencil view of a raster pass.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DepthStencilAttachment {
    pub resource: String,
    #[serde(default)]
    pub mip: u32,
    #[serde(default)]
    pub layer: u32,
    /// DSV format for typeless resources (D16_UNORM on R16_TYPELESS, ...).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    #[serde(default = "load_op_load")]
    pub depth_load: LoadOp,
    #[serde(default = "store_op_store")]
    pub depth_store: StoreOp,
    #[serde(default = "one_f64")]
    pub depth_clear: f64,
    #[serde(default = "load_op_load")]
    pub stencil_load: LoadOp,
    #[serde(default = "store_op_store")]
    pub stencil_store: StoreOp,
    #[serde(default)]
    pub stencil_clear: u32,
    /// Depth is bound read-only (D3D12 DEPTH_READ): tested, never written.
    #[serde(default)]
    pub read_only: bool,
}

fn one_f64() -> f64 {
    1.0
}

/// Fixed-function state of a raster pass.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RenderState {
    /// Depth comparison; no depth test when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_compare: Option<CompareFunction>,
    #[serde(default)]
    pub depth_write: bool,
    /// Constant depth bias and slope-scaled bias (shadow maps).
    #[serde(default)]
    pub depth_bias: i32,
    #[serde(default)]
    pub depth_bias_slope: f32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil: Option<StencilState>,
    #[serde(default = "cull_back")]
    pub cull: CullMode,
    #[serde(default = "ccw")]
    pub front_face: FrontFace,
    #[serde(default = "triangle_list")]
    pub topology: Topology,
}

impl Default for RenderState {
    fn default() -> Self {
        Self {
            depth_compare: None,
            depth_write: false,
            depth_bias: 0,
            depth_bias_slope: 0.0,
            stencil: None,
            cull: cull_back(),
            front_face: ccw(),
            topology: triangle_list(),
        }
    }
}

fn cull_back() -> CullMode {
    CullMode::Back
}
fn ccw() -> FrontFace {
    FrontFace::Ccw
}
fn triangle_list() -> Topology {
    Topology::TriangleList
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CullMode {
    None,
    Front,
    Back,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FrontFace {
    Ccw,
    Cw,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Topology {
    PointList,
    LineList,
    LineStrip,
    TriangleList,
    TriangleStrip,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StencilState {
    /// Reference value (draws may override it).
    #[serde(default)]
    pub reference: u32,
    #[serde(default = "byte_mask")]
    pub read_mask: u32,
    #[serde(default = "byte_mask")]
    pub write_mask: u32,
    #[serde(default)]
    pub front: StencilFace,
    #[serde(default)]
    pub back: StencilFace,
}

fn byte_mask() -> u32 {
    0xFF
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StencilFace {
    #[serde(default = "always")]
    pub compare: CompareFunction,
    #[serde(default = "keep")]
    pub fail: StencilOp,
    #[serde(default = "keep")]
    pub depth_fail: StencilOp,
    #[serde(default = "keep")]
    pub pass: StencilOp,
}

impl Default for StencilFace {
    fn default() -> Self {
        Self {
            compare: always(),
            fail: keep(),
            depth_fail: keep(),
            pass: keep(),
        }
    }
}

fn always() -> CompareFunction {
    CompareFunction::Always
}
fn keep() -> StencilOp {
    StencilOp::Keep
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StencilOp {
    Keep,
    Zero,
    Replace,
    Invert,
    IncrementClamp,
    DecrementClamp,
    IncrementWrap,
    DecrementWrap,
}

/// Blend state of one render target: a preset or explicit factors.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Blend {
    Preset(BlendPreset),
    Custom {
        color: BlendComponent,
        alpha: BlendComponent,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BlendPreset {
    Opaque,
    Alpha,
    PremultipliedAlpha,
    Additive,
    Multiply,
}

#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlendComponent {
    pub src: BlendFactor,
    pub dst: BlendFactor,
    #[serde(default = "blend_add")]
    pub op: BlendOp,
}

fn blend_add() -> BlendOp {
    BlendOp::Add
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BlendFactor {
    Zero,
    One,
    Src,
    OneMinusSrc,
    SrcAlpha,
    OneMinusSrcAlpha,
    Dst,
    OneMinusDst,
    DstAlpha,
    OneMinusDstAlpha,
    Constant,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BlendOp {
    Add,
    Subtract,
    ReverseSubtract,
    Min,
    Max,
}

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
    /// Arguments read from a buffer (DrawIndexedInstanced/DrawInstanced layout) instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect: Option<IndirectArgs>,
    /// Stencil reference for this draw (OMSetStencilRef).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_reference: Option<u32>,
    /// Per-draw parameters overriding the pass's.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
}

fn one_u32() -> u32 {
    1
}

/// Indirect arguments in a buffer.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IndirectArgs {
    pub buffer: String,
    #[serde(default)]
    pub offset: u64,
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
    /// Per-dispatch parameters overriding the pass's.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
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
}

fn transition() -> BarrierType {
    BarrierType::Transition
}
fn split_none() -> SplitFlag {
    SplitFlag::None
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BarrierType {
    Transition,
    Uav,
    Aliasing,
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
#[serde(untagged)]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_read_write_classification() {
        assert!(Access::StorageReadWrite.reads() && Access::StorageReadWrite.writes());
        assert!(!Access::StorageWrite.reads() && Access::StorageWrite.writes());
        assert!(Access::Sampled.reads() && !Access::Sampled.writes());
        assert!(Access::DepthWrite.reads() && Access::DepthWrite.writes());
        assert!(!Access::CopyDst.reads());
        assert!(Access::StorageRead.is_unordered(true) && !Access::StorageRead.is_unordered(false));
        assert!(!Access::Sampled.is_unordered(true));
    }

    #[test]
    fn extents_accept_every_spelling() {
        let parse = |s: &str| serde_json::from_str::<Extent>(s).unwrap();
        assert_eq!(parse("1024"), Extent::Texels(1024));
        assert_eq!(parse("\"half\""), Extent::Named(RelativeSize::Half));
        assert_eq!(
            parse(r#"{"scale": 0.125, "multiple_of": 8}"#),
            Extent::Scaled {
                scale: 0.125,
                multiple_of: Some(8)
            }
        );
        assert!(serde_json::from_str::<Extent>("\"double\"").is_err());
    }

    #[test]
    fn states_take_one_or_many() {
        let one: States = serde_json::from_str("\"RENDER_TARGET\"").unwrap();
        assert_eq!(one.as_slice(), [ResourceState::RenderTarget]);
        let many: States =
            serde_json::from_str(r#"["PIXEL_SHADER_RESOURCE", "NON_PIXEL_SHADER_RESOURCE"]"#)
                .unwrap();
        assert_eq!(many.as_slice().len(), 2);
        assert!(ResourceState::UnorderedAccess.is_write() && !ResourceState::CopySource.is_write());
    }
}
