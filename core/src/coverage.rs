//! What the replay of a real Vulkan frame does with each member of each class of Vulkan a
//! program can use: every `vkCmd*` command, every dynamic state, every sampler address mode
//! and border colour, every descriptor type, every image format. A member is replayed natively, emulated (the
//! text says how), has no effect on what the replay reproduces (the text says why), or is
//! refused at import and by `replay` with the pass and draw named.
//!
//! The importer and the lowering ask this table, so what it says is what they do; a test
//! holds it against the registry (the generated decoding tables), so a member nobody thought
//! of still gets a row, and docs/coverage.md is checked against `markdown()`.

/// The replay's answer for one member of a class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// wgpu does what the capture says.
    Native,
    /// Done another way with the same result; the text says how.
    Emulated(&'static str),
    /// Changes nothing the replay reproduces; the text says why.
    NoEffect(&'static str),
    /// A `vkCmdSet*` call: its value reaches the draws whose pipeline declares this dynamic
    /// state, and the state's own row says what the replay does with it.
    Sets(&'static str),
    /// The frame is refused at import and by `replay`, naming the pass and draw; the text
    /// says why.
    Refused(&'static str),
}

impl Verdict {
    fn cells(self) -> (&'static str, &'static str) {
        match self {
            Verdict::Native => ("native", ""),
            Verdict::Emulated(how) => ("emulated", how),
            Verdict::NoEffect(why) => ("no effect", why),
            Verdict::Sets(state) => ("sets", state),
            Verdict::Refused(why) => ("refused", why),
        }
    }
}

const BAKED: Verdict = Verdict::Emulated(
    "the value set before each draw is baked into a pipeline variant, created once per value",
);
const PER_DRAW: Verdict = Verdict::Emulated("set on the render pass before each draw");
const NO_WGPU_STATE: Verdict =
    Verdict::Refused("wgpu has no such state; refused where a draw's pipeline declares it");

/// Every `VK_DYNAMIC_STATE_*` of the registry.
pub fn dynamic_state(name: &str) -> Option<Verdict> {
    let short = name.strip_prefix("VK_DYNAMIC_STATE_")?;
    Some(match short {
        "VIEWPORT" | "SCISSOR" | "VIEWPORT_WITH_COUNT" | "SCISSOR_WITH_COUNT" => Verdict::Emulated(
            "the first viewport and scissor set before each draw, set on the render pass (wgpu has one of each)",
        ),
        "BLEND_CONSTANTS" | "STENCIL_REFERENCE" => PER_DRAW,
        "DEPTH_BIAS" | "DEPTH_BIAS_ENABLE" => Verdict::Emulated(
            "baked into a pipeline variant per value; a constant factor that is not a whole number is taken as the nearest one, with a note (wgpu takes whole numbers: each biased depth moves by under one resolvable step)",
        ),
        "LINE_WIDTH" => Verdict::Emulated(
            "no effect on triangles filled; lines wider than 1 are refused (wgpu draws 1-pixel lines)",
        ),
        "DEPTH_BOUNDS" => Verdict::Emulated(
            "no effect while the depth bounds test is off; the test itself is refused (wgpu has none)",
        ),
        "DEPTH_BOUNDS_TEST_ENABLE" => Verdict::Emulated(
            "baked while off; a draw with the test on is refused (wgpu has no depth bounds test)",
        ),
        "STENCIL_COMPARE_MASK" | "STENCIL_WRITE_MASK" => Verdict::Emulated(
            "baked into a pipeline variant per value; different masks per face are refused (wgpu has one of each)",
        ),
        "CULL_MODE"
        | "FRONT_FACE"
        | "PRIMITIVE_TOPOLOGY"
        | "PRIMITIVE_RESTART_ENABLE"
        | "DEPTH_TEST_ENABLE"
        | "DEPTH_WRITE_ENABLE"
        | "DEPTH_COMPARE_OP"
        | "STENCIL_TEST_ENABLE"
        | "STENCIL_OP"
        | "VERTEX_INPUT_BINDING_STRIDE" => BAKED,
        "RASTERIZER_DISCARD_ENABLE" => Verdict::Emulated(
            "baked while off; a draw with discard on rasterizes nothing and is replayed as one of no vertices (refused where a stage before rasterization writes storage)",
        ),
        "COLOR_WRITE_ENABLE_EXT" => {
            Verdict::Emulated("baked into the colour targets' write masks per value")
        }
        "LOGIC_OP_EXT" => Verdict::Emulated(
            "no effect while logic ops are off; logic ops themselves are refused (wgpu has none)",
        ),
        "RAY_TRACING_PIPELINE_STACK_SIZE_KHR" => {
            Verdict::NoEffect("only ray tracing pipelines read it, and they are refused")
        }
        "VERTEX_INPUT_EXT" => Verdict::Emulated(
            "the bindings and attributes set before each draw replace the pipeline's in a variant per value; an instance divisor other than 1 is refused (wgpu steps every instance)",
        ),
        "POLYGON_MODE_EXT" | "DEPTH_CLAMP_ENABLE_EXT" | "RASTERIZATION_SAMPLES_EXT" => BAKED,
        "COLOR_BLEND_ENABLE_EXT" | "COLOR_BLEND_EQUATION_EXT" | "COLOR_WRITE_MASK_EXT" => {
            Verdict::Emulated(
                "baked into the colour targets' blend states per value, attachment by attachment",
            )
        }
        "LOGIC_OP_ENABLE_EXT" => Verdict::Emulated(
            "baked while off; a draw with logic ops on is refused (wgpu has none)",
        ),
        "DEPTH_CLIP_ENABLE_EXT" => Verdict::Emulated(
            "baked: clipping opposite to clamping as it is (wgpu's unclipped depth clamps); both on as clipped (what survives the clip is in range); both off as unclipped where the clamp changes nothing (no depth attachment, or a fixed-point one, whose test clamps, with the depth range [0, 1]), refused into a floating-point one",
        ),
        "DEPTH_CLIP_NEGATIVE_ONE_TO_ONE_EXT" => Verdict::Emulated(
            "OpenGL's depth range (-w to w) mapped to Vulkan's in the vertex shader: z becomes (z + w) / 2 before each return",
        ),
        "SAMPLE_MASK_EXT" | "ALPHA_TO_COVERAGE_ENABLE_EXT" => {
            Verdict::Emulated("baked into the pipeline variant's multisample state per value")
        }
        "ALPHA_TO_ONE_ENABLE_EXT" => Verdict::Emulated(
            "baked while off; alpha to one on, dynamic or in the pipeline, is refused (wgpu has none)",
        ),
        "PROVOKING_VERTEX_MODE_EXT" => Verdict::Emulated(
            "no effect unless the fragment shader reads a flat input; there, each triangle of a list, strip or fan is drawn from a rearranged index list that starts it at its last vertex (wgpu takes the first's); lines, indirect draws and indices written during the frame are refused",
        ),
        "LINE_RASTERIZATION_MODE_EXT" => Verdict::Emulated(
            "no effect on triangles filled; Bresenham and rectangular lines drawn in the driver's default mode, with a note; smooth lines refused (wgpu has none)",
        ),
        "LINE_STIPPLE_ENABLE_EXT" => {
            Verdict::Emulated("baked while off; stippled lines are refused (wgpu has none)")
        }
        "LINE_STIPPLE_EXT" => {
            Verdict::Emulated("no effect while line stipple is off; stippled lines are refused")
        }
        "PATCH_CONTROL_POINTS_EXT" => {
            Verdict::NoEffect("only tessellation reads it, and tessellation stages are refused")
        }
        "TESSELLATION_DOMAIN_ORIGIN_EXT"
        | "RASTERIZATION_STREAM_EXT"
        | "CONSERVATIVE_RASTERIZATION_MODE_EXT"
        | "EXTRA_PRIMITIVE_OVERESTIMATION_SIZE_EXT"
        | "SAMPLE_LOCATIONS_ENABLE_EXT"
        | "COLOR_BLEND_ADVANCED_EXT" => Verdict::Refused(
            "tessellation, transform feedback streams, conservative rasterization, sample locations and advanced blending: wgpu has none",
        ),
        "VIEWPORT_W_SCALING_NV"
        | "DISCARD_RECTANGLE_EXT"
        | "SAMPLE_LOCATIONS_EXT"
        | "VIEWPORT_SHADING_RATE_PALETTE_NV"
        | "VIEWPORT_COARSE_SAMPLE_ORDER_NV"
        | "EXCLUSIVE_SCISSOR_NV"
        | "FRAGMENT_SHADING_RATE_KHR"
        | "VIEWPORT_W_SCALING_ENABLE_NV"
        | "VIEWPORT_SWIZZLE_NV"
        | "COVERAGE_TO_COLOR_ENABLE_NV"
        | "COVERAGE_TO_COLOR_LOCATION_NV"
        | "COVERAGE_MODULATION_MODE_NV"
        | "COVERAGE_MODULATION_TABLE_ENABLE_NV"
        | "COVERAGE_MODULATION_TABLE_NV"
        | "SHADING_RATE_IMAGE_ENABLE_NV"
        | "REPRESENTATIVE_FRAGMENT_TEST_ENABLE_NV"
        | "COVERAGE_REDUCTION_MODE_NV" => NO_WGPU_STATE,
        _ => return None,
    })
}

/// The dynamic state `vkCmdSet*` command `command` sets (`vkCmdSetCullModeEXT`:
/// `VK_DYNAMIC_STATE_CULL_MODE`), for the commands that set one.
pub fn state_set_by(command: &str) -> Option<&'static str> {
    setter_state(command.strip_prefix("vkCmdSet")?)
}

/// Whether two dynamic-state names are one state, an extension's spelling or the core one.
pub fn same_state(a: &str, b: &str) -> bool {
    let bare = |s: &str| s.trim_end_matches("_EXT").trim_end_matches("_KHR").len();
    let (la, lb) = (bare(a), bare(b));
    la == lb && a[..la] == b[..lb]
}

/// The dynamic state a `vkCmdSet*` command sets, for the commands that set one.
fn setter_state(short: &str) -> Option<&'static str> {
    let base = ["EXT", "KHR", "NV"]
        .iter()
        .find_map(|s| short.strip_suffix(s))
        .unwrap_or(short);
    Some(match base {
        "Viewport" => "VK_DYNAMIC_STATE_VIEWPORT",
        "Scissor" => "VK_DYNAMIC_STATE_SCISSOR",
        "ViewportWithCount" => "VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT",
        "ScissorWithCount" => "VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT",
        "LineWidth" => "VK_DYNAMIC_STATE_LINE_WIDTH",
        "DepthBias" => "VK_DYNAMIC_STATE_DEPTH_BIAS",
        "BlendConstants" => "VK_DYNAMIC_STATE_BLEND_CONSTANTS",
        "DepthBounds" => "VK_DYNAMIC_STATE_DEPTH_BOUNDS",
        "StencilCompareMask" => "VK_DYNAMIC_STATE_STENCIL_COMPARE_MASK",
        "StencilWriteMask" => "VK_DYNAMIC_STATE_STENCIL_WRITE_MASK",
        "StencilReference" => "VK_DYNAMIC_STATE_STENCIL_REFERENCE",
        "CullMode" => "VK_DYNAMIC_STATE_CULL_MODE",
        "FrontFace" => "VK_DYNAMIC_STATE_FRONT_FACE",
        "PrimitiveTopology" => "VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY",
        "DepthTestEnable" => "VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE",
        "DepthWriteEnable" => "VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE",
        "DepthCompareOp" => "VK_DYNAMIC_STATE_DEPTH_COMPARE_OP",
        "DepthBoundsTestEnable" => "VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE",
        "StencilTestEnable" => "VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE",
        "StencilOp" => "VK_DYNAMIC_STATE_STENCIL_OP",
        "RasterizerDiscardEnable" => "VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE",
        "DepthBiasEnable" => "VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE",
        "PrimitiveRestartEnable" => "VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE",
        "LogicOp" => "VK_DYNAMIC_STATE_LOGIC_OP_EXT",
        "ColorWriteEnable" => "VK_DYNAMIC_STATE_COLOR_WRITE_ENABLE_EXT",
        "VertexInput" => "VK_DYNAMIC_STATE_VERTEX_INPUT_EXT",
        "PatchControlPoints" => "VK_DYNAMIC_STATE_PATCH_CONTROL_POINTS_EXT",
        "TessellationDomainOrigin" => "VK_DYNAMIC_STATE_TESSELLATION_DOMAIN_ORIGIN_EXT",
        "DepthClampEnable" => "VK_DYNAMIC_STATE_DEPTH_CLAMP_ENABLE_EXT",
        "PolygonMode" => "VK_DYNAMIC_STATE_POLYGON_MODE_EXT",
        "RasterizationSamples" => "VK_DYNAMIC_STATE_RASTERIZATION_SAMPLES_EXT",
        "SampleMask" => "VK_DYNAMIC_STATE_SAMPLE_MASK_EXT",
        "AlphaToCoverageEnable" => "VK_DYNAMIC_STATE_ALPHA_TO_COVERAGE_ENABLE_EXT",
        "AlphaToOneEnable" => "VK_DYNAMIC_STATE_ALPHA_TO_ONE_ENABLE_EXT",
        "LogicOpEnable" => "VK_DYNAMIC_STATE_LOGIC_OP_ENABLE_EXT",
        "ColorBlendEnable" => "VK_DYNAMIC_STATE_COLOR_BLEND_ENABLE_EXT",
        "ColorBlendEquation" => "VK_DYNAMIC_STATE_COLOR_BLEND_EQUATION_EXT",
        "ColorWriteMask" => "VK_DYNAMIC_STATE_COLOR_WRITE_MASK_EXT",
        "RasterizationStream" => "VK_DYNAMIC_STATE_RASTERIZATION_STREAM_EXT",
        "ConservativeRasterizationMode" => "VK_DYNAMIC_STATE_CONSERVATIVE_RASTERIZATION_MODE_EXT",
        "ExtraPrimitiveOverestimationSize" => {
            "VK_DYNAMIC_STATE_EXTRA_PRIMITIVE_OVERESTIMATION_SIZE_EXT"
        }
        "DepthClipEnable" => "VK_DYNAMIC_STATE_DEPTH_CLIP_ENABLE_EXT",
        "SampleLocationsEnable" => "VK_DYNAMIC_STATE_SAMPLE_LOCATIONS_ENABLE_EXT",
        "ColorBlendAdvanced" => "VK_DYNAMIC_STATE_COLOR_BLEND_ADVANCED_EXT",
        "ProvokingVertexMode" => "VK_DYNAMIC_STATE_PROVOKING_VERTEX_MODE_EXT",
        "LineRasterizationMode" => "VK_DYNAMIC_STATE_LINE_RASTERIZATION_MODE_EXT",
        "LineStippleEnable" => "VK_DYNAMIC_STATE_LINE_STIPPLE_ENABLE_EXT",
        "DepthClipNegativeOneToOne" => "VK_DYNAMIC_STATE_DEPTH_CLIP_NEGATIVE_ONE_TO_ONE_EXT",
        "LineStipple" => "VK_DYNAMIC_STATE_LINE_STIPPLE_EXT",
        "DiscardRectangle" => "VK_DYNAMIC_STATE_DISCARD_RECTANGLE_EXT",
        "SampleLocations" => "VK_DYNAMIC_STATE_SAMPLE_LOCATIONS_EXT",
        "ViewportWScaling" => "VK_DYNAMIC_STATE_VIEWPORT_W_SCALING_NV",
        "ViewportWScalingEnable" => "VK_DYNAMIC_STATE_VIEWPORT_W_SCALING_ENABLE_NV",
        "ViewportSwizzle" => "VK_DYNAMIC_STATE_VIEWPORT_SWIZZLE_NV",
        "ViewportShadingRatePalette" => "VK_DYNAMIC_STATE_VIEWPORT_SHADING_RATE_PALETTE_NV",
        "CoarseSampleOrder" => "VK_DYNAMIC_STATE_VIEWPORT_COARSE_SAMPLE_ORDER_NV",
        "ExclusiveScissor" => "VK_DYNAMIC_STATE_EXCLUSIVE_SCISSOR_NV",
        "FragmentShadingRate" | "FragmentShadingRateEnum" => {
            "VK_DYNAMIC_STATE_FRAGMENT_SHADING_RATE_KHR"
        }
        "CoverageToColorEnable" => "VK_DYNAMIC_STATE_COVERAGE_TO_COLOR_ENABLE_NV",
        "CoverageToColorLocation" => "VK_DYNAMIC_STATE_COVERAGE_TO_COLOR_LOCATION_NV",
        "CoverageModulationMode" => "VK_DYNAMIC_STATE_COVERAGE_MODULATION_MODE_NV",
        "CoverageModulationTableEnable" => "VK_DYNAMIC_STATE_COVERAGE_MODULATION_TABLE_ENABLE_NV",
        "CoverageModulationTable" => "VK_DYNAMIC_STATE_COVERAGE_MODULATION_TABLE_NV",
        "CoverageReductionMode" => "VK_DYNAMIC_STATE_COVERAGE_REDUCTION_MODE_NV",
        "ShadingRateImageEnable" => "VK_DYNAMIC_STATE_SHADING_RATE_IMAGE_ENABLE_NV",
        "RepresentativeFragmentTestEnable" => {
            "VK_DYNAMIC_STATE_REPRESENTATIVE_FRAGMENT_TEST_ENABLE_NV"
        }
        "RayTracingPipelineStackSize" => "VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR",
        _ => return None,
    })
}

const NOT_READ_BACK: Verdict =
    Verdict::NoEffect("queries are not replayed: their results reach no image or buffer");
const SYNC_ONLY: Verdict = Verdict::NoEffect(
    "synchronization only: the replay orders the passes itself (the static check reads it)",
);
const LABEL: Verdict = Verdict::Emulated("kept as the pass's debug label");
const NO_DEVICE_STATE: Verdict =
    Verdict::NoEffect("a marker for tools and debuggers: nothing on the device changes");

/// Every `vkCmd*` command of the registry.
pub fn command(name: &str) -> Option<Verdict> {
    let short = name.strip_prefix("vkCmd")?;
    if let Some(state) = short.strip_prefix("Set").and_then(setter_state) {
        return Some(Verdict::Sets(state));
    }
    // The core name: without its vendor suffix, then without its `2` revision.
    let unvendored = ["KHR", "EXT", "AMD"]
        .iter()
        .find_map(|s| short.strip_suffix(s))
        .unwrap_or(short);
    let base = unvendored.strip_suffix('2').unwrap_or(unvendored);
    Some(match (base, short) {
        ("BeginRenderPass" | "NextSubpass" | "EndRenderPass", _)
        | ("BeginRendering" | "EndRendering", _) => Verdict::Emulated(
            "each subpass or rendering instance becomes a raster pass with its load and store operations",
        ),
        ("BindPipeline" | "BindDescriptorSets" | "BindIndexBuffer" | "BindVertexBuffers", _)
        | ("PushConstants", _) => Verdict::Native,
        ("PushDescriptorSet" | "PushDescriptorSetWithTemplate", _) => {
            Verdict::Emulated("the pushed descriptors become the draw's bind group")
        }
        ("Draw" | "DrawIndexed" | "DrawIndirect" | "DrawIndexedIndirect", _) => Verdict::Native,
        ("Dispatch" | "DispatchIndirect", _) => Verdict::Native,
        ("DispatchBase", _) => Verdict::Emulated("a base of (0, 0, 0) is a plain dispatch"),
        ("CopyBuffer" | "CopyBufferToImage" | "CopyImageToBuffer" | "CopyImage", _) => {
            Verdict::Native
        }
        ("ClearColorImage" | "ClearDepthStencilImage", _) => Verdict::Emulated(
            "a clear pass of the image's subresources, the colour read through the image's format (integers for an integer image)",
        ),
        ("FillBuffer" | "UpdateBuffer", _) => {
            Verdict::Emulated("a copy pass writing the bytes the program wrote")
        }
        ("BlitImage", _) => Verdict::Emulated(
            "a blit pass, drawn: each destination texel centre mapped to the source by the specification's formula, read nearest or bilinear with clamp-to-edge (cubic filters, 3D regions, depth, stencil and integer formats refused)",
        ),
        ("ResolveImage", _) => Verdict::Emulated("a resolve pass"),
        ("PipelineBarrier", _) | ("WaitEvents", _) => SYNC_ONLY,
        ("SetEvent" | "ResetEvent", _) => SYNC_ONLY,
        ("ExecuteCommands", _) => Verdict::Emulated(
            "the secondary command buffers' commands in the primary's order, inside its render pass instance where one is open",
        ),
        (
            "BeginDebugUtilsLabel" | "EndDebugUtilsLabel" | "DebugMarkerBegin" | "DebugMarkerEnd",
            _,
        ) => LABEL,
        ("InsertDebugUtilsLabel" | "DebugMarkerInsert", _) => NO_DEVICE_STATE,
        (
            _,
            "SetCheckpointNV" | "SetPerformanceMarkerINTEL" | "SetPerformanceStreamMarkerINTEL",
        )
        | (_, "SetPerformanceOverrideINTEL") => NO_DEVICE_STATE,
        (_, "SetDeviceMask" | "SetDeviceMaskKHR") => {
            Verdict::NoEffect("one device replays the whole frame")
        }
        ("BeginQuery" | "EndQuery" | "ResetQueryPool" | "WriteTimestamp", _)
        | (_, "BeginQueryIndexedEXT" | "EndQueryIndexedEXT") => NOT_READ_BACK,
        ("CopyQueryPoolResults", _) => Verdict::NoEffect(
            "query results are the capturing device's timings and counts, which no other device reproduces: the destination keeps the contents it had (wgpu resolves its timestamps this way, into buffers only the host reads)",
        ),
        ("ClearAttachments", _) => Verdict::Emulated(
            "a draw of each rectangle inside the render pass, writing the clear value to the attachments named and nothing else (colour blending off, depth and stencil tests always pass; an integer colour attachment takes the value's integers, read through its format; clears of other than the first layer refused)",
        ),
        (_, "DrawIndirectCount" | "DrawIndexedIndirectCount")
        | (_, "DrawIndirectCountKHR" | "DrawIndexedIndirectCountKHR")
        | (_, "DrawIndirectCountAMD" | "DrawIndexedIndirectCountAMD") => Verdict::Emulated(
            "wgpu's multi_draw_indirect_count (the adapter's MULTI_DRAW_INDIRECT_COUNT feature, refused by name without it); records a stride apart other than their own size are refused",
        ),
        (_, "DrawMultiEXT" | "DrawMultiIndexedEXT") => Verdict::Emulated(
            "one draw per list entry, with the call's instances (and `pVertexOffset` for every indexed entry where given)",
        ),
        (_, "DrawIndirectByteCountEXT")
        | (_, "BeginTransformFeedbackEXT" | "EndTransformFeedbackEXT")
        | (_, "BindTransformFeedbackBuffersEXT") => {
            Verdict::Refused("transform feedback: wgpu has none")
        }
        (_, "BeginConditionalRenderingEXT" | "EndConditionalRenderingEXT") => {
            Verdict::Refused("conditional rendering: wgpu has none")
        }
        (_, s) if s.starts_with("DrawMeshTasks") || s.starts_with("DrawCluster") => {
            Verdict::Refused("mesh and cluster shading: wgpu's mesh shaders are not used")
        }
        (_, s)
            if s.starts_with("TraceRays")
                || s.contains("AccelerationStructure")
                || s.contains("Micromap")
                || s == "BindPipelineShaderGroupNV"
                || s == "BindInvocationMaskHUAWEI" =>
        {
            Verdict::Refused("ray tracing: wgpu's ray queries are not used")
        }
        (_, "BindShadingRateImageNV") => Verdict::Refused("shading rate images: wgpu has none"),
        (_, "WriteBufferMarkerAMD" | "WriteBufferMarker2AMD") => Verdict::NoEffect(
            "progress markers for crash diagnosis, read by the host: the destination keeps the contents it had",
        ),
        (_, "ExecuteGeneratedCommandsNV" | "PreprocessGeneratedCommandsNV") => {
            Verdict::Refused("device-generated commands: wgpu has none")
        }
        (_, "OpticalFlowExecuteNV") => Verdict::Refused("optical flow: wgpu has none"),
        _ if short.starts_with("Set") => {
            Verdict::Refused("a state no dynamic state of the registry names")
        }
        _ => return None,
    })
}

/// Every `VK_SAMPLER_ADDRESS_MODE_*`.
pub fn address_mode(name: &str) -> Option<Verdict> {
    Some(match name.strip_prefix("VK_SAMPLER_ADDRESS_MODE_")? {
        "REPEAT" | "MIRRORED_REPEAT" | "CLAMP_TO_EDGE" => Verdict::Native,
        "CLAMP_TO_BORDER" => Verdict::Emulated(
            "wgpu's ADDRESS_MODE_CLAMP_TO_BORDER feature where the adapter has it, refused where it does not",
        ),
        "MIRROR_CLAMP_TO_EDGE" => Verdict::Emulated(
            "wgpu has no mirror-once address mode: the sampler clamps to the edge and each sample through it takes the absolute value of the coordinate on that axis in the shader (texel -1-i is where -u falls, so the same texels are picked and weighed); cube maps ignore it",
        ),
        _ => return None,
    })
}

/// Every `VK_BORDER_COLOR_*`.
pub fn border_color(name: &str) -> Option<Verdict> {
    Some(match name.strip_prefix("VK_BORDER_COLOR_")? {
        "FLOAT_TRANSPARENT_BLACK"
        | "INT_TRANSPARENT_BLACK"
        | "FLOAT_OPAQUE_BLACK"
        | "FLOAT_OPAQUE_WHITE" => Verdict::Native,
        "INT_OPAQUE_BLACK" | "INT_OPAQUE_WHITE" => Verdict::Refused(
            "wgpu's border colours are float: an integer opaque border reads differently",
        ),
        "FLOAT_CUSTOM_EXT" | "INT_CUSTOM_EXT" => Verdict::Emulated(
            "the colour from VkSamplerCustomBorderColorCreateInfoEXT: one wgpu has (transparent black of either type, opaque black or white as floats) is that one; any other is refused by name with its colour (wgpu has no custom border colours)",
        ),
        _ => return None,
    })
}

/// Every member of `VkSamplerCreateInfo`.
pub fn sampler_field(name: &str) -> Option<Verdict> {
    Some(match name {
        "sType" | "pNext" => Verdict::NoEffect("structure bookkeeping"),
        "flags" => Verdict::Emulated(
            "NON_SEAMLESS_CUBE_MAP (zink's, for OpenGL's default): the same samples through nearest filters; a cube map filtered linearly through it is refused (wgpu filters across the faces' edges); the subsampled flags concern fragment density maps, which no imported frame renders",
        ),
        "magFilter" | "minFilter" | "mipmapMode" | "compareOp" => Verdict::Native,
        "minLod" | "maxLod" => Verdict::Emulated(
            "wgpu's LOD clamps, with a negative bound taken as 0 (the same levels and filter: Vulkan magnifies at LOD 0 or less)",
        ),
        "compareEnable" => Verdict::Native,
        "addressModeU" | "addressModeV" | "addressModeW" => {
            Verdict::Emulated("per address mode; see that table")
        }
        "anisotropyEnable" | "maxAnisotropy" => Verdict::Emulated(
            "wgpu's anisotropy clamp, 1 to 16, with every filter linear (wgpu filters anisotropically only so); where the sampler says nearest, which Vulkan leaves to the implementation, a note says so (lavapipe filters linearly too)",
        ),
        "borderColor" => Verdict::Emulated(
            "read only where an address mode clamps to the border; see that table",
        ),
        "mipLodBias" => Verdict::Emulated(
            "wgpu has no LOD bias: added to every sample taken through the sampler by a SPIR-V rewrite (a Bias operand, or added to the shader's own bias or Lod), except where it changes nothing (one mip level, one filter up and down); samples with explicit gradients are refused",
        ),
        "unnormalizedCoordinates" => Verdict::Emulated(
            "wgpu samples with normalized coordinates: each sample through the sampler has its coordinate divided by the image's level-0 size in the shader (OpImageQuerySizeLod); any sample Vulkan does not allow such a sampler is refused by name",
        ),
        _ => return None,
    })
}

/// Every `VK_DESCRIPTOR_TYPE_*`.
pub fn descriptor_type(name: &str) -> Option<Verdict> {
    Some(match name.strip_prefix("VK_DESCRIPTOR_TYPE_")? {
        "SAMPLER" => Verdict::Native,
        "SAMPLED_IMAGE" => Verdict::Emulated(NULL_IMAGE),
        "STORAGE_IMAGE" => Verdict::Emulated(
            "native; a null descriptor (or one never written) is a blank 1x1 2D storage image of the shader's format, its writes lost and its reads zero, named in a note; other dimensions refused",
        ),
        "STORAGE_BUFFER" => Verdict::Emulated(
            "native; a null descriptor is a blank buffer of zeros the size of the shader's block, its writes lost (kept apart from the blanks only read), named in a note",
        ),
        "UNIFORM_BUFFER" => Verdict::Emulated(
            "native for std140 blocks; a std430 block's arrays of 32-bit scalars (zink's word arrays) are widened in the SPIR-V to arrays of 4-vectors at stride 16, the same bytes, so it stays a uniform block; another std430 block is bound as a read-only storage buffer, the SPIR-V moved to the StorageBuffer class; scalar layout past std430 is refused; a null descriptor reads a blank buffer of zeros, named in a note",
        ),
        "STORAGE_BUFFER_DYNAMIC" => {
            Verdict::Emulated("the dynamic offset is added to the binding's offset at import")
        }
        "UNIFORM_BUFFER_DYNAMIC" => Verdict::Emulated(
            "the dynamic offset is added to the binding's offset at import; std430 blocks as for uniform buffers",
        ),
        "COMBINED_IMAGE_SAMPLER" => Verdict::Emulated(
            "split into a texture and a sampler binding, the SPIR-V rewritten to match; a null image view as for sampled images",
        ),
        "UNIFORM_TEXEL_BUFFER" | "STORAGE_TEXEL_BUFFER" => Verdict::Emulated(
            "where the code only reads it, in a format the rewrite unpacks: a read-only storage buffer of words, each texel read rewritten into a load and unpack; a written texel buffer and a null one are refused",
        ),
        "INPUT_ATTACHMENT" => Verdict::Emulated(
            "bound as a texture of the attachment's view, each subpassLoad rewritten to a fetch at the fragment's own position (OpImageFetch at ivec2(gl_FragCoord.xy)); an attachment the same subpass renders to (framebuffer fetch) is read from a copy taken before each draw that reads it (the render pass ended and begun again around the copy; multisampled and depth/stencil attachments refused), and a null one is refused",
        ),
        "INLINE_UNIFORM_BLOCK" => Verdict::Refused("inline uniform blocks are not imported yet"),
        "ACCELERATION_STRUCTURE_KHR" | "ACCELERATION_STRUCTURE_NV" => {
            Verdict::Refused("ray tracing: wgpu's ray queries are not used")
        }
        "MUTABLE_EXT" => Verdict::Refused("mutable descriptors are not imported yet"),
        "SAMPLE_WEIGHT_IMAGE_QCOM" | "BLOCK_MATCH_IMAGE_QCOM" => {
            Verdict::Refused("image processing descriptors: wgpu has none")
        }
        _ => return None,
    })
}

/// What a null sampled image reads (the nullDescriptor feature of VK_EXT_robustness2).
const NULL_IMAGE: &str = "native; a null descriptor reads a blank 1x1 image of the shader's sample type and dimension, zero in every channel (its size queries give 1 where Vulkan's give 0), named in a note; a null multisampled or depth-compared image is refused";

/// Every `VK_FORMAT_*` an image can be made in: every one is imported (with its DXGI twin or
/// under its Vulkan name), and the lowering replays it in the wgpu format with the same bits,
/// holds it rearranged, or refuses it with the family's reason.
pub fn format(name: &str) -> Option<Verdict> {
    use crate::lower::formats::{FormatError, Repack, twin};
    if name == "VK_FORMAT_UNDEFINED" {
        return Some(Verdict::NoEffect(
            "no image is made in it: a view or description that says it takes another's format",
        ));
    }
    let info = crate::capture::dxgi::lookup_vk(name)?;
    Some(match twin(info.name) {
        Ok(_) => match Repack::of(info.name) {
            Some(Repack::SwapRb10) => Verdict::Emulated(
                "held as wgpu's RGB10A2 with red and blue exchanged in its contents; a copy between it and a buffer is refused",
            ),
            Some(Repack::SwapRb8) => Verdict::Emulated(
                "held as wgpu's RGBA8 with red and blue exchanged in its contents; a copy between it and a buffer is refused",
            ),
            Some(Repack::Widen3 { .. }) => Verdict::Emulated(
                "held as wgpu's four-channel twin (RGBA8, RGBA16, RGBA32 in the same numbers), its contents widened on upload with a fourth channel of one, which is what a sampled view of a format without alpha reads; rendering into it, a blit into it and a copy between it and a buffer are refused",
            ),
            Some(Repack::Unpack16(_)) => Verdict::Emulated(
                "held as wgpu's RGBA8, each channel widened to 8 bits (sampled within half a step of 255 of the program's value): contents unpacked on upload, a copy from a buffer drawn texel by texel from the buffer's words, a view of the same bit fields in another order read through a swizzle; rendering into it and a copy out of it to a buffer are refused",
            ),
            None if crate::lower::formats::opaque_bc1(name) => Verdict::Emulated(
                "held as BC1 with alpha where the adapter has BC compression: the same blocks, whose three-colour entries decode to alpha 0 there and 1 here, so each sampled view of it reads alpha as one; a blit from it is refused",
            ),
            None if name.starts_with("VK_FORMAT_BC") => Verdict::Emulated(
                "native where the adapter has BC compression (wgpu's TEXTURE_COMPRESSION_BC, asked for by the pass)",
            ),
            None => Verdict::Native,
        },
        Err(FormatError::NoWebGpuFormat { reason, .. }) => Verdict::Refused(reason.text()),
        Err(FormatError::NoTypedView { .. }) => {
            Verdict::Refused("a typeless format needs a typed view")
        }
    })
}

/// One class of the table: its title, the registry's name for it, and its verdicts.
pub struct Class {
    pub title: &'static str,
    /// The registry enum or structure whose members the class covers, or `vkCmd` for the
    /// commands.
    pub registry: &'static str,
    pub verdict: fn(&str) -> Option<Verdict>,
}

impl std::fmt::Debug for Class {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.title)
    }
}

/// Every class the table covers.
pub const CLASSES: [Class; 7] = [
    Class {
        title: "Commands",
        registry: "vkCmd",
        verdict: command,
    },
    Class {
        title: "Dynamic states",
        registry: "VkDynamicState",
        verdict: dynamic_state,
    },
    Class {
        title: "Sampler fields",
        registry: "VkSamplerCreateInfo",
        verdict: sampler_field,
    },
    Class {
        title: "Sampler address modes",
        registry: "VkSamplerAddressMode",
        verdict: address_mode,
    },
    Class {
        title: "Border colours",
        registry: "VkBorderColor",
        verdict: border_color,
    },
    Class {
        title: "Descriptor types",
        registry: "VkDescriptorType",
        verdict: descriptor_type,
    },
    Class {
        title: "Image formats",
        registry: "VkFormat",
        verdict: format,
    },
];

/// The members of `class` the registry (the generated decoding tables) names, sorted.
pub fn registry_members(class: &Class) -> Vec<&'static str> {
    use crate::import::gfxr::tables;
    let mut out: Vec<&'static str> = if class.registry == "vkCmd" {
        tables::COMMANDS
            .iter()
            .map(|c| c.name)
            .filter(|n| n.starts_with("vkCmd"))
            .collect()
    } else if let Some(e) = tables::ENUMS.iter().find(|e| e.name == class.registry) {
        e.values.iter().map(|(_, n)| *n).collect()
    } else {
        tables::STRUCTS
            .iter()
            .find(|s| s.name == class.registry)
            .map(|s| s.members.iter().map(|f| f.name).collect())
            .unwrap_or_default()
    };
    out.sort_unstable();
    out.dedup();
    out
}

/// How many members of each class get each verdict, as the Markdown table the README and
/// docs/importing.md show.
pub fn summary() -> String {
    let mut s = String::from(
        "| class (registry) | members | native | emulated | no effect | setters | refused |\n| --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for class in &CLASSES {
        let members = registry_members(class);
        let count = |k: &str| {
            members
                .iter()
                .filter(|m| (class.verdict)(m).is_some_and(|v| v.cells().0 == k))
                .count()
        };
        let setters = match count("sets") {
            0 => "-".to_owned(),
            n => n.to_string(),
        };
        s.push_str(&format!(
            "| {} (`{}`) | {} | {} | {} | {} | {setters} | {} |\n",
            class.title,
            class.registry,
            members.len(),
            count("native"),
            count("emulated"),
            count("no effect"),
            count("refused"),
        ));
    }
    s
}

/// The whole table as Markdown, one section per class, as `docs/coverage.md` shows it.
pub fn markdown() -> String {
    let mut s = String::new();
    for class in &CLASSES {
        let members = registry_members(class);
        let count = |k: &str| {
            members
                .iter()
                .filter(|m| (class.verdict)(m).is_some_and(|v| v.cells().0 == k))
                .count()
        };
        s.push_str(&format!(
            "#### {} ({} in the registry: {} native, {} emulated, {} no effect, {} setters, {} refused)\n\n| member | replay | how or why |\n| --- | --- | --- |\n",
            class.title,
            members.len(),
            count("native"),
            count("emulated"),
            count("no effect"),
            count("sets"),
            count("refused"),
        ));
        for m in members {
            let (kind, text) = (class.verdict)(m).map_or(("missing", ""), Verdict::cells);
            s.push_str(&format!("| `{m}` | {kind} | {text} |\n"));
        }
        s.push('\n');
    }
    s
}
