//! The Vulkan objects an imported frame's draws and dispatches run with: SPIR-V shader
//! modules, samplers, descriptor set layouts, pipeline layouts and pipelines with their whole
//! fixed-function state, each by name. Enumerants keep their Vulkan names and flags their
//! Vulkan bits, so nothing is lost in translation; a draw or dispatch names the pipeline
//! bound when it was recorded.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The Vulkan objects of an imported frame: the pipelines its draws and dispatches bound with
/// the layouts and modules they name, and every sampler the application created (descriptor
/// writes name samplers, and a frame's writes may predate it).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VulkanObjects {
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shader_modules: Vec<ShaderModule>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samplers: Vec<VkSampler>,
    /// The image views the draws' and dispatches' descriptors name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub image_views: Vec<VkImageView>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub set_layouts: Vec<SetLayout>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pipeline_layouts: Vec<PipelineLayout>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pipelines: Vec<Pipeline>,
}

/// A SPIR-V module.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShaderModule {
    pub name: String,
    /// The module's code, relative to the capture: exactly the bytes the application gave
    /// `vkCreateShaderModule`. Absent when the source holds no code (a JSON Lines stream).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// `codeSize` in bytes.
    pub size: u64,
}

/// A `VkSamplerCreateInfo`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkSampler {
    pub name: String,
    pub mag_filter: String,
    pub min_filter: String,
    pub mipmap_mode: String,
    pub address_mode_u: String,
    pub address_mode_v: String,
    pub address_mode_w: String,
    pub mip_lod_bias: f32,
    /// `maxAnisotropy` when anisotropy is enabled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_anisotropy: Option<f32>,
    /// `compareOp` when comparison is enabled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare_op: Option<String>,
    pub min_lod: f32,
    pub max_lod: f32,
    pub border_color: String,
    /// The colour of a `VK_BORDER_COLOR_*_CUSTOM_EXT` border
    /// (`VkSamplerCustomBorderColorCreateInfoEXT`): `float32`, or `int32` for an integer one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub custom_border_color: Option<[f64; 4]>,
    #[serde(default)]
    pub unnormalized_coordinates: bool,
    /// `VK_SAMPLER_CREATE_NON_SEAMLESS_CUBE_MAP_BIT_EXT`: a cube map filtered within each
    /// face (zink sets it for OpenGL's default, seamless filtering off).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub non_seamless_cube: bool,
}

/// A `VkImageView`: the image (a resource) and what of it the view sees.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkImageView {
    pub name: String,
    pub image: String,
    /// `VK_IMAGE_VIEW_TYPE_*`.
    pub view_type: String,
    /// `VK_FORMAT_*`.
    pub format: String,
    /// `VkImageAspectFlags`.
    pub aspect: u32,
    #[serde(default)]
    pub base_mip: u32,
    /// Absent: every level from `base_mip`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mips: Option<u32>,
    #[serde(default)]
    pub base_layer: u32,
    /// Absent: every layer from `base_layer`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<u32>,
    /// The channel each of R, G, B and A reads (`RRRG`; `0` and `1` for the constants), where
    /// the view's `components` are not the identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swizzle: Option<String>,
}

/// A descriptor a draw or dispatch could reach: in set `set`, at `binding` and array
/// `element`, as the set held it when the command was recorded (dynamic offsets applied).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkDescriptor {
    pub set: u32,
    pub binding: u32,
    #[serde(default)]
    pub element: u32,
    /// `VK_DESCRIPTOR_TYPE_*` without the prefix (`COMBINED_IMAGE_SAMPLER`).
    pub descriptor_type: String,
    /// The buffer or image (through `view`), by resource name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resource: Option<String>,
    /// An image view of `vulkan.image_views`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<String>,
    /// A sampler of `vulkan.samplers`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampler: Option<String>,
    /// Buffers: the bytes bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<u64>,
    /// Texel buffers: the buffer view's `VK_FORMAT_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
}

/// A `VkDescriptorSetLayout`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SetLayout {
    pub name: String,
    /// `VkDescriptorSetLayoutCreateFlags` (e.g. 0x1, push descriptors).
    #[serde(default)]
    pub flags: u32,
    pub bindings: Vec<LayoutBinding>,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LayoutBinding {
    pub binding: u32,
    /// `VK_DESCRIPTOR_TYPE_*`.
    pub descriptor_type: String,
    pub count: u32,
    /// `VkShaderStageFlags`.
    pub stages: u32,
    /// Samplers fixed in the layout, by name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub immutable_samplers: Vec<String>,
}

/// A `VkPipelineLayout`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PipelineLayout {
    pub name: String,
    /// Set layouts by set number.
    pub set_layouts: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub push_constants: Vec<PushConstantRange>,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PushConstantRange {
    /// `VkShaderStageFlags`.
    pub stages: u32,
    pub offset: u32,
    pub size: u32,
}

/// A graphics or compute pipeline.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Pipeline {
    pub name: String,
    /// `VK_PIPELINE_BIND_POINT_GRAPHICS` or `VK_PIPELINE_BIND_POINT_COMPUTE`.
    pub bind_point: String,
    pub layout: String,
    pub stages: Vec<PipelineStage>,
    /// Fixed-function state (graphics pipelines).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub graphics: Option<Box<GraphicsState>>,
}

/// One shader stage of a pipeline.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PipelineStage {
    /// `VK_SHADER_STAGE_*_BIT`.
    pub stage: String,
    pub module: String,
    pub entry: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub specialization: Vec<SpecConstant>,
}

/// A specialization constant: its id, size, and value read from `pData` (little-endian,
/// `size` bytes, at most 8). The value is absent where the source holds no data (a JSON
/// Lines stream gives only `pData`'s address).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpecConstant {
    pub id: u32,
    pub size: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<u64>,
}

/// A graphics pipeline's fixed-function state.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GraphicsState {
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertex_bindings: Vec<VertexBinding>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes: Vec<VertexAttributeVk>,
    /// `VK_PRIMITIVE_TOPOLOGY_*`.
    pub topology: String,
    #[serde(default)]
    pub primitive_restart: bool,
    pub polygon_mode: String,
    /// `VkCullModeFlags`.
    pub cull_mode: u32,
    pub front_face: String,
    #[serde(default)]
    pub depth_clamp: bool,
    #[serde(default)]
    pub rasterizer_discard: bool,
    /// (constant factor, clamp, slope factor) when depth bias is enabled, or when the draws
    /// switch it (`VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE`). Likewise `depth_stencil`'s faces
    /// are kept where the draws switch the stencil test.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bias: Option<[f32; 3]>,
    pub line_width: f32,
    /// `VK_SAMPLE_COUNT_*_BIT`.
    pub samples: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_stencil: Option<DepthStencilVk>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blend: Vec<BlendAttachment>,
    #[serde(default)]
    pub blend_constants: [f32; 4],
    /// `VK_LOGIC_OP_*` when logic ops are enabled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logic_op: Option<String>,
    /// Viewports and scissors fixed in the pipeline, as `[x, y, width, height]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub viewports: Vec<[f32; 4]>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scissors: Vec<[i64; 4]>,
    /// `VK_DYNAMIC_STATE_*`: state the draws set instead.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dynamic_states: Vec<String>,
    /// The subpass of the render pass the pipeline was made for.
    #[serde(default)]
    pub subpass: u32,
    /// Clip-space depth from -w to w, as OpenGL has it
    /// (`VkPipelineViewportDepthClipControlCreateInfoEXT::negativeOneToOne`, or its dynamic
    /// state): the replay maps it to Vulkan's 0 to w in the last vertex stage.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub depth_negative_one_to_one: bool,
    /// Flat inputs take the last vertex's values (`VK_PROVOKING_VERTEX_MODE_LAST_VERTEX_EXT`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub provoking_vertex_last: bool,
    /// `alphaToCoverageEnable`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub alpha_to_coverage: bool,
    /// `alphaToOneEnable`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub alpha_to_one: bool,
    /// `pSampleMask`'s first word, where the pipeline gives one (all samples otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_mask: Option<u32>,
    /// `VK_LINE_RASTERIZATION_MODE_*` other than the default, where the pipeline
    /// (`VkPipelineRasterizationLineStateCreateInfoEXT`) or its dynamic state gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_rasterization_mode: Option<String>,
    /// `stippledLineEnable`, from the same structure or its dynamic state.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub line_stipple: bool,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexBinding {
    pub binding: u32,
    pub stride: u32,
    /// `VK_VERTEX_INPUT_RATE_*`.
    pub input_rate: String,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VertexAttributeVk {
    pub location: u32,
    pub binding: u32,
    /// `VK_FORMAT_*`.
    pub format: String,
    pub offset: u32,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DepthStencilVk {
    pub depth_test: bool,
    pub depth_write: bool,
    /// `VK_COMPARE_OP_*`.
    pub depth_compare: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bounds: Option<[f32; 2]>,
    #[serde(default)]
    pub stencil_test: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub front: Option<StencilFaceVk>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub back: Option<StencilFaceVk>,
}

impl DepthStencilVk {
    /// What a pipeline without depth-stencil state does: neither tests nor writes.
    pub fn off() -> Self {
        DepthStencilVk {
            depth_test: false,
            depth_write: false,
            depth_compare: "VK_COMPARE_OP_ALWAYS".to_owned(),
            depth_bounds: None,
            stencil_test: false,
            front: None,
            back: None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StencilFaceVk {
    pub fail_op: String,
    pub pass_op: String,
    pub depth_fail_op: String,
    pub compare_op: String,
    pub compare_mask: u32,
    pub write_mask: u32,
    pub reference: u32,
}

/// One colour attachment's blend state.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlendAttachment {
    pub enable: bool,
    pub src_color: String,
    pub dst_color: String,
    pub color_op: String,
    pub src_alpha: String,
    pub dst_alpha: String,
    pub alpha_op: String,
    /// `VkColorComponentFlags`.
    pub write_mask: u32,
}

/// The dynamic state and push constants in effect for an imported draw or dispatch, as the
/// command buffer set them before it.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkCommandState {
    /// `vkCmdSetViewport`'s first viewport: `[x, y, width, height, min depth, max depth]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viewport: Option<[f32; 6]>,
    /// `vkCmdSetScissor`'s first scissor: `[x, y, width, height]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scissor: Option<[i64; 4]>,
    /// `vkCmdSetBlendConstants`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend_constants: Option<[f32; 4]>,
    /// `vkCmdSetStencilReference`: (front, back).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_reference: Option<[u32; 2]>,
    /// The other dynamic state the command buffer set before the draw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamic: Option<Box<VkDynamicValues>>,
    /// The push-constant bytes from offset 0 up to the last byte written, as hex (bytes never
    /// written are zero). Absent where the source holds no values (a JSON Lines stream gives
    /// only `pValues`' address).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub push_constants: Option<String>,
    /// The descriptors of the sets bound at its bind point, in set, binding, element order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub descriptors: Vec<VkDescriptor>,
    /// The vertex buffers bound (draws), by binding number.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertex_buffers: Vec<VkVertexBuffer>,
    /// The index buffer bound (indexed draws).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index_buffer: Option<VkIndexBuffer>,
}

/// Fixed-function state a draw ran with where its pipeline declares it dynamic, beyond
/// viewport, scissor, blend constants and stencil reference: each member is what the last
/// `vkCmdSet*` call of its kind in the command buffer set, absent where none was made. The
/// replay bakes what the pipeline declares dynamic into a pipeline variant per value.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkDynamicValues {
    /// `vkCmdSetDepthBias`: (constant factor, clamp, slope factor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bias: Option<[f32; 3]>,
    /// `vkCmdSetDepthBiasEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bias_enable: Option<bool>,
    /// `vkCmdSetLineWidth`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_width: Option<f32>,
    /// `vkCmdSetDepthBounds`: (min, max).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bounds: Option<[f32; 2]>,
    /// `vkCmdSetDepthBoundsTestEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_bounds_test_enable: Option<bool>,
    /// `vkCmdSetStencilCompareMask`: (front, back).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_compare_mask: Option<[u32; 2]>,
    /// `vkCmdSetStencilWriteMask`: (front, back).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_write_mask: Option<[u32; 2]>,
    /// `vkCmdSetStencilOp`: (front, back).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_op: Option<[VkStencilOps; 2]>,
    /// `vkCmdSetCullMode`: `VkCullModeFlags`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cull_mode: Option<u32>,
    /// `vkCmdSetFrontFace`: `VK_FRONT_FACE_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub front_face: Option<String>,
    /// `vkCmdSetPrimitiveTopology`: `VK_PRIMITIVE_TOPOLOGY_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub topology: Option<String>,
    /// `vkCmdSetPrimitiveRestartEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub primitive_restart_enable: Option<bool>,
    /// `vkCmdSetRasterizerDiscardEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rasterizer_discard_enable: Option<bool>,
    /// `vkCmdSetDepthTestEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_test_enable: Option<bool>,
    /// `vkCmdSetDepthWriteEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_write_enable: Option<bool>,
    /// `vkCmdSetDepthCompareOp`: `VK_COMPARE_OP_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_compare_op: Option<String>,
    /// `vkCmdSetStencilTestEnable`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stencil_test_enable: Option<bool>,
    /// `vkCmdSetColorWriteEnableEXT`, per colour attachment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color_write_enable: Option<Vec<bool>>,
    /// `vkCmdSetLogicOpEXT`: `VK_LOGIC_OP_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logic_op: Option<String>,
    /// `vkCmdBindVertexBuffers2`'s strides: (binding, stride).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertex_strides: Vec<[u64; 2]>,
    /// Extended dynamic state 3 and vertex input (`VK_EXT_extended_dynamic_state3`,
    /// `VK_EXT_vertex_input_dynamic_state`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extended: Option<Box<VkExtendedDynamicValues>>,
}

/// The values of `vkCmdSetVertexInputEXT` and the extended-dynamic-state-3 setters; each is
/// what the last call of its kind set, absent where none was made. Per-attachment values are
/// indexed by colour attachment (`null` where no call named it).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkExtendedDynamicValues {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_input: Option<VkVertexInput>,
    /// `VK_POLYGON_MODE_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon_mode: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_clamp_enable: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_clip_enable: Option<bool>,
    /// OpenGL's clip-space depth, -w to w, instead of Vulkan's 0 to w.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_clip_negative_one_to_one: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_to_coverage_enable: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_to_one_enable: Option<bool>,
    /// `VK_SAMPLE_COUNT_*_BIT`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rasterization_samples: Option<String>,
    /// `vkCmdSetSampleMaskEXT`'s words.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_mask: Option<Vec<u32>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub color_blend_enable: Vec<Option<bool>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub color_blend_equation: Vec<Option<VkBlendEquation>>,
    /// `VkColorComponentFlags`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub color_write_mask: Vec<Option<u32>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logic_op_enable: Option<bool>,
    /// `VK_PROVOKING_VERTEX_MODE_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provoking_vertex_mode: Option<String>,
    /// `VK_LINE_RASTERIZATION_MODE_*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_rasterization_mode: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_stipple_enable: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_control_points: Option<u32>,
}

/// `vkCmdSetVertexInputEXT`: the vertex buffer bindings and attributes, replacing the
/// pipeline's.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkVertexInput {
    pub bindings: Vec<VkVertexBindingDivisor>,
    pub attributes: Vec<VertexAttributeVk>,
}

/// A vertex binding as `vkCmdSetVertexInputEXT` gives it, with its instance divisor.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkVertexBindingDivisor {
    pub binding: u32,
    pub stride: u32,
    /// `VK_VERTEX_INPUT_RATE_*`.
    pub input_rate: String,
    pub divisor: u32,
}

/// One colour attachment's `vkCmdSetColorBlendEquationEXT`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkBlendEquation {
    pub src_color: String,
    pub dst_color: String,
    pub color_op: String,
    pub src_alpha: String,
    pub dst_alpha: String,
    pub alpha_op: String,
}

impl VkDynamicValues {
    pub fn is_empty(&self) -> bool {
        *self == VkDynamicValues::default()
    }
}

/// One face's `vkCmdSetStencilOp`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkStencilOps {
    pub fail_op: String,
    pub pass_op: String,
    pub depth_fail_op: String,
    pub compare_op: String,
}

/// A `vkCmdBindVertexBuffers` binding.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkVertexBuffer {
    pub binding: u32,
    pub resource: String,
    #[serde(default)]
    pub offset: u64,
}

/// A `vkCmdBindIndexBuffer` binding.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VkIndexBuffer {
    pub resource: String,
    #[serde(default)]
    pub offset: u64,
    /// `VK_INDEX_TYPE_UINT16` or `VK_INDEX_TYPE_UINT32`.
    pub index_type: String,
}

impl VkCommandState {
    pub fn is_empty(&self) -> bool {
        *self == VkCommandState::default()
    }
}
