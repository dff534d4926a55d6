//! Resources: kinds, extents (absolute or relative to the output), mips, flags, placement and
//! initial contents.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::HeapType;

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
    /// One of a swapchain's images: the presentation engine owns it, so a frame that leaves it
    /// idle (it presents another) is not told the image is unused.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub swapchain: bool,
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
#[serde(
    untagged,
    expecting = "expected a texel count, \"full\", \"half\", \"quarter\" or {\"scale\": fraction, \"multiple_of\": n}"
)]
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
#[serde(
    untagged,
    expecting = "expected a mip level count or \"full\" (the whole chain)"
)]
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
    /// CreatePlacedResource (or vkBind*Memory): at `offset` bytes into a named heap.
    Placed {
        heap: String,
        offset: u64,
        /// Placement alignment the API reported for this resource (Vulkan's
        /// `VkMemoryRequirements::alignment`); D3D12's 64 KiB (4 MiB for MSAA) when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alignment: Option<u64>,
    },
    /// CreateReservedResource: virtual address range only; tiles are mapped later.
    Reserved,
}

pub(crate) fn default_heap_type() -> HeapType {
    HeapType::Default
}

/// Contents of a resource before the frame starts.
#[derive(Clone, Debug, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialContents {
    /// Raw bytes from a file next to the capture (tightly packed subresources, mip-major).
    File {
        path: String,
        /// Where the resource's bytes start in the file, which then holds other resources'
        /// contents too (an import writes one file for all of a frame's); absent, the file is
        /// the resource's alone.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        offset: Option<u64>,
    },
    /// Contents from before the captured frames that the capture does not hold: written
    /// through mapped memory, by earlier frames, or restored from a trimmed capture's state
    /// snapshot. Imported captures only; nothing to replay from.
    BeforeCapture {},
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
#[serde(untagged, expecting = "expected a number or an array of numbers")]
pub enum ParamValue {
    Scalar(f64),
    Vector(Vec<f64>),
}

impl ResourceFlag {
    /// The name reports and messages use (D3D12's spelling where it has one).
    pub fn name(self) -> &'static str {
        match self {
            ResourceFlag::AllowRenderTarget => "ALLOW_RENDER_TARGET",
            ResourceFlag::AllowDepthStencil => "ALLOW_DEPTH_STENCIL",
            ResourceFlag::AllowUnorderedAccess => "ALLOW_UNORDERED_ACCESS",
            ResourceFlag::DenyShaderResource => "DENY_SHADER_RESOURCE",
            ResourceFlag::AllowCrossAdapter => "ALLOW_CROSS_ADAPTER",
            ResourceFlag::AllowSimultaneousAccess => "ALLOW_SIMULTANEOUS_ACCESS",
            ResourceFlag::VideoDecodeReferenceOnly => "VIDEO_DECODE_REFERENCE_ONLY",
            ResourceFlag::RaytracingAccelerationStructure => "RAYTRACING_ACCELERATION_STRUCTURE",
        }
    }
}

impl BufferKind {
    /// The name reports and messages use (D3D12's spelling where it has one).
    pub fn name(self) -> &'static str {
        match self {
            BufferKind::Structured => "structured",
            BufferKind::ByteAddress => "byte_address",
            BufferKind::Raw => "raw",
            BufferKind::Typed => "typed",
        }
    }
}
