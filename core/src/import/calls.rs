//! Which Vulkan function a stream line calls, decoded once from its name as the line is read.
//!
//! The importer's passes match on these variants rather than on names, so aliases (the `KHR`
//! and `2` spellings of one function) are folded in one place, and a function the importer
//! handles cannot be missed by a pass for a misspelt name. Arguments stay JSON until the pass
//! that needs them reads them, so that a malformed argument is reported (and the call left
//! out) exactly where it matters.

use crate::coverage::Verdict;

/// An image or a buffer: the calls that come in both flavours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Object {
    Image,
    Buffer,
}

impl Object {
    /// The member naming the handle.
    pub fn key(self) -> &'static str {
        match self {
            Object::Image => "image",
            Object::Buffer => "buffer",
        }
    }
}

/// What a host wait waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wait {
    Fences,
    Semaphores,
    Idle,
}

/// A Vulkan function outside command buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    /// A `vkCmd*` function: recorded into its command buffer.
    Cmd(CmdFunc),
    AllocateCommandBuffers,
    /// `vkBeginCommandBuffer` or `vkResetCommandBuffer`: the buffer starts empty.
    ResetCommandBuffer,
    FreeCommandBuffers,
    ResetCommandPool,
    /// `vkDestroyCommandPool`: its command buffers go with it.
    DestroyCommandPool,
    /// `vkQueueSubmit`, or (`v2`) `vkQueueSubmit2`.
    QueueSubmit {
        v2: bool,
    },
    QueuePresent,
    /// `vkAcquireNextImageKHR`, or (`v2`) `vkAcquireNextImage2KHR`.
    AcquireNextImage {
        v2: bool,
    },
    /// A host wait: `vkWaitForFences`, `vkWaitSemaphores`, `vkQueueWaitIdle`,
    /// `vkDeviceWaitIdle`.
    HostWait(Wait),
    QueueFamilyProperties,
    MemoryProperties,
    GetDeviceQueue,
    GetDeviceQueue2,
    AllocateMemory,
    /// `vkCreateInstance`, `vkCreateDevice`: the extensions they enable.
    CreateInstance,
    CreateDevice,
    CreateImage,
    CreateBuffer,
    MemoryRequirements(Object),
    BindMemory(Object),
    BindMemory2(Object),
    CreateImageView,
    CreateBufferView,
    CreateRenderPass,
    CreateFramebuffer,
    AllocateDescriptorSets,
    UpdateDescriptorSets,
    UpdateDescriptorSetWithTemplate,
    CreateDescriptorUpdateTemplate,
    CreateSwapchain,
    CreateSemaphore,
    GetSwapchainImages,
    SetDebugUtilsObjectName,
    DebugMarkerSetObjectName,
    MapMemory,
    /// `vkDestroyImage` or `vkDestroyBuffer`.
    Destroy(Object),
    CreateShaderModule,
    CreateSampler,
    CreateDescriptorSetLayout,
    CreatePipelineLayout,
    /// `vkCreateGraphicsPipelines`, or (`compute`) `vkCreateComputePipelines`.
    CreatePipelines {
        compute: bool,
    },
    /// Creates or records nothing framelab models.
    Other,
}

/// The source and destination kinds of a copy command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CopyKind {
    BufferToBuffer,
    BufferToImage,
    ImageToBuffer,
    ImageToImage,
}

impl CopyKind {
    /// The members naming the source and the destination.
    pub fn keys(self) -> (&'static str, &'static str) {
        match self {
            CopyKind::BufferToBuffer => ("srcBuffer", "dstBuffer"),
            CopyKind::BufferToImage => ("srcBuffer", "dstImage"),
            CopyKind::ImageToBuffer => ("srcImage", "dstBuffer"),
            CopyKind::ImageToImage => ("srcImage", "dstImage"),
        }
    }

    /// The member of the `*2` variant that holds the arguments.
    pub fn info_key(self) -> &'static str {
        match self {
            CopyKind::BufferToBuffer => "pCopyBufferInfo",
            CopyKind::BufferToImage => "pCopyBufferToImageInfo",
            CopyKind::ImageToBuffer => "pCopyImageToBufferInfo",
            CopyKind::ImageToImage => "pCopyImageInfo",
        }
    }
}

/// A `vkCmd*` function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmdFunc {
    BindPipeline,
    SetViewport,
    SetScissor,
    SetBlendConstants,
    SetStencilReference,
    PushConstants,
    BindDescriptorSets,
    PushDescriptorSet,
    PushDescriptorSetWithTemplate,
    BindVertexBuffers,
    BindIndexBuffer,
    Draw {
        indexed: bool,
    },
    DrawIndirect {
        indexed: bool,
    },
    /// `vkCmdDrawIndirectCount` and its KHR and AMD names: the count read on the GPU.
    DrawIndirectCount {
        indexed: bool,
    },
    /// `vkCmdDrawMultiEXT` / `vkCmdDrawMultiIndexedEXT`: a list of draws in one call.
    DrawMulti {
        indexed: bool,
    },
    Dispatch,
    DispatchIndirect,
    /// `vkCmdPipelineBarrier` or `vkCmdWaitEvents`: stage masks on the call.
    PipelineBarrier,
    PipelineBarrier2,
    WaitEvents2,
    BeginRenderPass,
    NextSubpass,
    /// The end of a render pass instance or of dynamic rendering.
    EndRender,
    BeginRendering,
    /// A copy; `v2`: the arguments sit in a `*Info` structure.
    Copy {
        kind: CopyKind,
        v2: bool,
    },
    ClearImage,
    /// Rectangles of the render pass's attachments cleared between draws.
    ClearAttachments,
    FillBuffer,
    ResolveImage,
    BeginDebugLabel,
    BeginDebugMarker,
    EndLabel,
    ExecuteCommands,
    /// Scaled blits: no pass kind holds them.
    Blit,
    /// A `vkCmdSet*` of dynamic state the draws' pipeline variants are baked from.
    SetState(SetState),
    /// Work the replay cannot reproduce (`coverage::command` says why): kept in the recording,
    /// so a frame that runs it is refused with its pass named.
    Refused,
    /// Queries, markers and the like: changes nothing the replay reproduces
    /// (`coverage::command` says why).
    Other,
}

/// The `vkCmdSet*` calls whose values are kept for the draws after them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetState {
    DepthBias,
    DepthBiasEnable,
    LineWidth,
    DepthBounds,
    DepthBoundsTestEnable,
    StencilCompareMask,
    StencilWriteMask,
    StencilOp,
    CullMode,
    FrontFace,
    PrimitiveTopology,
    PrimitiveRestartEnable,
    RasterizerDiscardEnable,
    DepthTestEnable,
    DepthWriteEnable,
    DepthCompareOp,
    StencilTestEnable,
    ColorWriteEnable,
    LogicOp,
    VertexInput,
    PolygonMode,
    DepthClampEnable,
    DepthClipEnable,
    DepthClipNegativeOneToOne,
    AlphaToCoverageEnable,
    AlphaToOneEnable,
    RasterizationSamples,
    SampleMask,
    ColorBlendEnable,
    ColorBlendEquation,
    ColorWriteMask,
    LogicOpEnable,
    ProvokingVertexMode,
    LineRasterizationMode,
    LineStippleEnable,
    PatchControlPoints,
}

impl SetState {
    fn of(short: &str) -> Option<SetState> {
        use SetState as S;
        let base = short.strip_suffix("EXT").unwrap_or(short);
        Some(match base {
            "DepthBias" => S::DepthBias,
            "DepthBiasEnable" => S::DepthBiasEnable,
            "LineWidth" => S::LineWidth,
            "DepthBounds" => S::DepthBounds,
            "DepthBoundsTestEnable" => S::DepthBoundsTestEnable,
            "StencilCompareMask" => S::StencilCompareMask,
            "StencilWriteMask" => S::StencilWriteMask,
            "StencilOp" => S::StencilOp,
            "CullMode" => S::CullMode,
            "FrontFace" => S::FrontFace,
            "PrimitiveTopology" => S::PrimitiveTopology,
            "PrimitiveRestartEnable" => S::PrimitiveRestartEnable,
            "RasterizerDiscardEnable" => S::RasterizerDiscardEnable,
            "DepthTestEnable" => S::DepthTestEnable,
            "DepthWriteEnable" => S::DepthWriteEnable,
            "DepthCompareOp" => S::DepthCompareOp,
            "StencilTestEnable" => S::StencilTestEnable,
            "ColorWriteEnable" => S::ColorWriteEnable,
            "LogicOp" => S::LogicOp,
            "VertexInput" => S::VertexInput,
            "PolygonMode" => S::PolygonMode,
            "DepthClampEnable" => S::DepthClampEnable,
            "DepthClipEnable" => S::DepthClipEnable,
            "DepthClipNegativeOneToOne" => S::DepthClipNegativeOneToOne,
            "AlphaToCoverageEnable" => S::AlphaToCoverageEnable,
            "AlphaToOneEnable" => S::AlphaToOneEnable,
            "RasterizationSamples" => S::RasterizationSamples,
            "SampleMask" => S::SampleMask,
            "ColorBlendEnable" => S::ColorBlendEnable,
            "ColorBlendEquation" => S::ColorBlendEquation,
            "ColorWriteMask" => S::ColorWriteMask,
            "LogicOpEnable" => S::LogicOpEnable,
            "ProvokingVertexMode" => S::ProvokingVertexMode,
            "LineRasterizationMode" => S::LineRasterizationMode,
            "LineStippleEnable" => S::LineStippleEnable,
            "PatchControlPoints" => S::PatchControlPoints,
            _ => return None,
        })
    }
}

impl Func {
    pub fn of(name: &str) -> Func {
        if name.starts_with("vkCmd") {
            return Func::Cmd(CmdFunc::of(name));
        }
        let image = if name.contains("Image") {
            Object::Image
        } else {
            Object::Buffer
        };
        match name {
            "vkAllocateCommandBuffers" => Func::AllocateCommandBuffers,
            "vkBeginCommandBuffer" | "vkResetCommandBuffer" => Func::ResetCommandBuffer,
            "vkFreeCommandBuffers" => Func::FreeCommandBuffers,
            "vkResetCommandPool" => Func::ResetCommandPool,
            "vkDestroyCommandPool" => Func::DestroyCommandPool,
            "vkQueueSubmit" => Func::QueueSubmit { v2: false },
            "vkQueueSubmit2" | "vkQueueSubmit2KHR" => Func::QueueSubmit { v2: true },
            "vkQueuePresentKHR" => Func::QueuePresent,
            "vkAcquireNextImageKHR" => Func::AcquireNextImage { v2: false },
            "vkAcquireNextImage2KHR" => Func::AcquireNextImage { v2: true },
            "vkWaitForFences" => Func::HostWait(Wait::Fences),
            "vkWaitSemaphores" | "vkWaitSemaphoresKHR" => Func::HostWait(Wait::Semaphores),
            "vkQueueWaitIdle" | "vkDeviceWaitIdle" => Func::HostWait(Wait::Idle),
            "vkGetPhysicalDeviceQueueFamilyProperties"
            | "vkGetPhysicalDeviceQueueFamilyProperties2"
            | "vkGetPhysicalDeviceQueueFamilyProperties2KHR" => Func::QueueFamilyProperties,
            "vkGetPhysicalDeviceMemoryProperties"
            | "vkGetPhysicalDeviceMemoryProperties2"
            | "vkGetPhysicalDeviceMemoryProperties2KHR" => Func::MemoryProperties,
            "vkGetDeviceQueue" => Func::GetDeviceQueue,
            "vkGetDeviceQueue2" => Func::GetDeviceQueue2,
            "vkAllocateMemory" => Func::AllocateMemory,
            "vkCreateImage" => Func::CreateImage,
            "vkCreateDevice" => Func::CreateDevice,
            "vkCreateInstance" => Func::CreateInstance,
            "vkCreateBuffer" => Func::CreateBuffer,
            "vkGetImageMemoryRequirements"
            | "vkGetImageMemoryRequirements2"
            | "vkGetImageMemoryRequirements2KHR"
            | "vkGetBufferMemoryRequirements"
            | "vkGetBufferMemoryRequirements2"
            | "vkGetBufferMemoryRequirements2KHR" => Func::MemoryRequirements(image),
            "vkBindImageMemory" | "vkBindBufferMemory" => Func::BindMemory(image),
            "vkBindImageMemory2"
            | "vkBindImageMemory2KHR"
            | "vkBindBufferMemory2"
            | "vkBindBufferMemory2KHR" => Func::BindMemory2(image),
            "vkCreateImageView" => Func::CreateImageView,
            "vkCreateBufferView" => Func::CreateBufferView,
            "vkCreateRenderPass" | "vkCreateRenderPass2" | "vkCreateRenderPass2KHR" => {
                Func::CreateRenderPass
            }
            "vkCreateFramebuffer" => Func::CreateFramebuffer,
            "vkAllocateDescriptorSets" => Func::AllocateDescriptorSets,
            "vkUpdateDescriptorSets" => Func::UpdateDescriptorSets,
            "vkCreateDescriptorUpdateTemplate" | "vkCreateDescriptorUpdateTemplateKHR" => {
                Func::CreateDescriptorUpdateTemplate
            }
            "vkUpdateDescriptorSetWithTemplate" | "vkUpdateDescriptorSetWithTemplateKHR" => {
                Func::UpdateDescriptorSetWithTemplate
            }
            "vkCreateSwapchainKHR" => Func::CreateSwapchain,
            "vkCreateSemaphore" => Func::CreateSemaphore,
            "vkGetSwapchainImagesKHR" => Func::GetSwapchainImages,
            "vkSetDebugUtilsObjectNameEXT" => Func::SetDebugUtilsObjectName,
            "vkDebugMarkerSetObjectNameEXT" => Func::DebugMarkerSetObjectName,
            "vkMapMemory" | "vkMapMemory2KHR" | "vkMapMemory2" => Func::MapMemory,
            "vkDestroyImage" => Func::Destroy(Object::Image),
            "vkDestroyBuffer" => Func::Destroy(Object::Buffer),
            "vkCreateShaderModule" => Func::CreateShaderModule,
            "vkCreateSampler" => Func::CreateSampler,
            "vkCreateDescriptorSetLayout" => Func::CreateDescriptorSetLayout,
            "vkCreatePipelineLayout" => Func::CreatePipelineLayout,
            "vkCreateGraphicsPipelines" => Func::CreatePipelines { compute: false },
            "vkCreateComputePipelines" => Func::CreatePipelines { compute: true },
            _ => Func::Other,
        }
    }
}

impl CmdFunc {
    /// For draws (`Some(false)`) and dispatches (`Some(true)`): the bind point whose
    /// pipeline and descriptor sets they run with.
    pub fn work_point(self) -> Option<bool> {
        match self {
            CmdFunc::Draw { .. }
            | CmdFunc::DrawIndirect { .. }
            | CmdFunc::DrawIndirectCount { .. }
            | CmdFunc::DrawMulti { .. } => Some(false),
            CmdFunc::Dispatch | CmdFunc::DispatchIndirect => Some(true),
            _ => None,
        }
    }

    pub fn of(name: &str) -> CmdFunc {
        use CmdFunc as C;
        use CopyKind as K;
        let copy = |kind, v2| C::Copy { kind, v2 };
        match name {
            "vkCmdBindPipeline" => C::BindPipeline,
            "vkCmdSetViewport" | "vkCmdSetViewportWithCount" | "vkCmdSetViewportWithCountEXT" => {
                C::SetViewport
            }
            "vkCmdSetScissor" | "vkCmdSetScissorWithCount" | "vkCmdSetScissorWithCountEXT" => {
                C::SetScissor
            }
            "vkCmdSetBlendConstants" => C::SetBlendConstants,
            "vkCmdSetStencilReference" => C::SetStencilReference,
            "vkCmdPushConstants" => C::PushConstants,
            "vkCmdBindDescriptorSets" => C::BindDescriptorSets,
            "vkCmdPushDescriptorSetKHR" | "vkCmdPushDescriptorSet" => C::PushDescriptorSet,
            "vkCmdPushDescriptorSetWithTemplateKHR" | "vkCmdPushDescriptorSetWithTemplate" => {
                C::PushDescriptorSetWithTemplate
            }
            "vkCmdBlitImage" | "vkCmdBlitImage2" | "vkCmdBlitImage2KHR" => C::Blit,
            "vkCmdBindVertexBuffers" | "vkCmdBindVertexBuffers2" | "vkCmdBindVertexBuffers2EXT" => {
                C::BindVertexBuffers
            }
            "vkCmdBindIndexBuffer" | "vkCmdBindIndexBuffer2KHR" | "vkCmdBindIndexBuffer2" => {
                C::BindIndexBuffer
            }
            "vkCmdDraw" => C::Draw { indexed: false },
            "vkCmdDrawIndexed" => C::Draw { indexed: true },
            "vkCmdDrawIndirect" => C::DrawIndirect { indexed: false },
            "vkCmdDrawIndexedIndirect" => C::DrawIndirect { indexed: true },
            "vkCmdDrawIndirectCount"
            | "vkCmdDrawIndirectCountKHR"
            | "vkCmdDrawIndirectCountAMD" => C::DrawIndirectCount { indexed: false },
            "vkCmdDrawIndexedIndirectCount"
            | "vkCmdDrawIndexedIndirectCountKHR"
            | "vkCmdDrawIndexedIndirectCountAMD" => C::DrawIndirectCount { indexed: true },
            "vkCmdDrawMultiEXT" => C::DrawMulti { indexed: false },
            "vkCmdDrawMultiIndexedEXT" => C::DrawMulti { indexed: true },
            "vkCmdDispatch" | "vkCmdDispatchBase" | "vkCmdDispatchBaseKHR" => C::Dispatch,
            "vkCmdDispatchIndirect" => C::DispatchIndirect,
            "vkCmdPipelineBarrier" | "vkCmdWaitEvents" => C::PipelineBarrier,
            "vkCmdPipelineBarrier2" | "vkCmdPipelineBarrier2KHR" => C::PipelineBarrier2,
            "vkCmdWaitEvents2" | "vkCmdWaitEvents2KHR" => C::WaitEvents2,
            "vkCmdBeginRenderPass" | "vkCmdBeginRenderPass2" | "vkCmdBeginRenderPass2KHR" => {
                C::BeginRenderPass
            }
            "vkCmdNextSubpass" | "vkCmdNextSubpass2" | "vkCmdNextSubpass2KHR" => C::NextSubpass,
            "vkCmdEndRenderPass"
            | "vkCmdEndRenderPass2"
            | "vkCmdEndRenderPass2KHR"
            | "vkCmdEndRendering"
            | "vkCmdEndRenderingKHR" => C::EndRender,
            "vkCmdBeginRendering" | "vkCmdBeginRenderingKHR" => C::BeginRendering,
            "vkCmdCopyBuffer" => copy(K::BufferToBuffer, false),
            "vkCmdCopyBufferToImage" => copy(K::BufferToImage, false),
            "vkCmdCopyImageToBuffer" => copy(K::ImageToBuffer, false),
            "vkCmdCopyImage" => copy(K::ImageToImage, false),
            "vkCmdCopyBuffer2" | "vkCmdCopyBuffer2KHR" => copy(K::BufferToBuffer, true),
            "vkCmdCopyBufferToImage2" | "vkCmdCopyBufferToImage2KHR" => {
                copy(K::BufferToImage, true)
            }
            "vkCmdCopyImageToBuffer2" | "vkCmdCopyImageToBuffer2KHR" => {
                copy(K::ImageToBuffer, true)
            }
            "vkCmdCopyImage2" | "vkCmdCopyImage2KHR" => copy(K::ImageToImage, true),
            "vkCmdClearColorImage" | "vkCmdClearDepthStencilImage" => C::ClearImage,
            "vkCmdClearAttachments" => C::ClearAttachments,
            "vkCmdFillBuffer" | "vkCmdUpdateBuffer" => C::FillBuffer,
            "vkCmdResolveImage" => C::ResolveImage,
            "vkCmdBeginDebugUtilsLabelEXT" => C::BeginDebugLabel,
            "vkCmdDebugMarkerBeginEXT" => C::BeginDebugMarker,
            "vkCmdEndDebugUtilsLabelEXT" | "vkCmdDebugMarkerEndEXT" => C::EndLabel,
            "vkCmdExecuteCommands" => C::ExecuteCommands,
            _ => {
                if let Some(set) = name.strip_prefix("vkCmdSet").and_then(SetState::of) {
                    return C::SetState(set);
                }
                // Everything else by the coverage table: a command it does not know is
                // refused rather than assumed harmless.
                match crate::coverage::command(name) {
                    Some(Verdict::Refused(_)) | None => C::Refused,
                    Some(_) => C::Other,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The importer looks commands up by binary search: the generated table must be sorted,
    /// and say core commands' versions and extension commands' extensions.
    #[test]
    fn what_provides_each_command_is_sorted_by_name() {
        use super::super::provided::PROVIDED;
        assert!(PROVIDED.windows(2).all(|w| w[0].0 < w[1].0));
        let of = |name: &str| {
            PROVIDED
                .binary_search_by(|(n, _)| (*n).cmp(name))
                .map(|i| PROVIDED[i].1)
        };
        assert_eq!(of("vkCmdDraw"), Ok("1.0"));
        assert_eq!(of("vkCmdBeginRendering"), Ok("1.3"));
        assert_eq!(of("vkCmdBeginRenderingKHR"), Ok("VK_KHR_dynamic_rendering"));
        assert_eq!(of("vkCmdBeginDebugUtilsLabelEXT"), Ok("VK_EXT_debug_utils"));
        assert_eq!(
            of("vkAcquireNextImage2KHR"),
            Ok("VK_KHR_swapchain,VK_KHR_device_group")
        );
    }

    #[test]
    fn aliases_fold_into_one_function() {
        assert_eq!(
            Func::of("vkQueueSubmit2KHR"),
            Func::QueueSubmit { v2: true }
        );
        assert_eq!(
            Func::of("vkGetBufferMemoryRequirements2"),
            Func::MemoryRequirements(Object::Buffer)
        );
        assert_eq!(
            Func::of("vkCmdCopyImageToBuffer2KHR"),
            Func::Cmd(CmdFunc::Copy {
                kind: CopyKind::ImageToBuffer,
                v2: true
            })
        );
        assert_eq!(
            Func::of("vkCmdSetViewport"),
            Func::Cmd(CmdFunc::SetViewport)
        );
        assert_eq!(
            Func::of("vkCmdSetLineWidth"),
            Func::Cmd(CmdFunc::SetState(SetState::LineWidth))
        );
        assert_eq!(
            Func::of("vkCmdSetCullModeEXT"),
            Func::Cmd(CmdFunc::SetState(SetState::CullMode))
        );
        assert_eq!(Func::of("vkCmdWriteTimestamp2"), Func::Cmd(CmdFunc::Other));
        assert_eq!(
            Func::of("vkCmdClearAttachments"),
            Func::Cmd(CmdFunc::ClearAttachments)
        );
        assert_eq!(
            Func::of("vkCmdDrawIndexedIndirectCountAMD"),
            Func::Cmd(CmdFunc::DrawIndirectCount { indexed: true })
        );
        assert_eq!(
            Func::of("vkCmdDrawIndirectByteCountEXT"),
            Func::Cmd(CmdFunc::Refused)
        );
        assert_eq!(Func::of("vkCmdFutureThing"), Func::Cmd(CmdFunc::Refused));
        assert_eq!(Func::of("vkCreateSampler"), Func::CreateSampler);
        assert_eq!(Func::of("vkCreateFence"), Func::Other);
    }
}
