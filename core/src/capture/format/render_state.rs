//! Fixed-function raster state: depth-stencil attachment, culling, topology, stencil, blending.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{CompareFunction, LoadOp, StoreOp, load_op_load, store_op_store};

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
    /// Where the stencil aspect's access differs from the depth's: Vulkan's
    /// `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL` (stencil written, depth only tested) and
    /// the reverse. Absent: as `read_only`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_read_only: Option<bool>,
}

pub(crate) fn one_f64() -> f64 {
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

pub(crate) fn cull_back() -> CullMode {
    CullMode::Back
}
pub(crate) fn ccw() -> FrontFace {
    FrontFace::Ccw
}
pub(crate) fn triangle_list() -> Topology {
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

pub(crate) fn byte_mask() -> u32 {
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

pub(crate) fn always() -> CompareFunction {
    CompareFunction::Always
}
pub(crate) fn keep() -> StencilOp {
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
#[serde(
    untagged,
    expecting = "expected a blend preset (\"opaque\", \"alpha\", \"premultiplied_alpha\", \"additive\", \"multiply\") or {\"color\": {...}, \"alpha\": {...}}"
)]
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

pub(crate) fn blend_add() -> BlendOp {
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
