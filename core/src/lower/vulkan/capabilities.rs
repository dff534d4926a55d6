//! SPIR-V capabilities against the device wgpu makes. A module handed to the driver as it is
//! (passthrough) may declare only capabilities whose Vulkan requirement (the registry's
//! `<spirvcapabilities>`) that device meets: Vulkan 1.0's own, those of a feature wgpu turns
//! on when framelab asks for a wgpu feature (asked for where the adapter has it), and those
//! met by the device's version or properties. Anything else would make the driver run a
//! module the device was not created for (the validation layer's
//! `VUID-VkShaderModuleCreateInfo-pCode-01091`), so it is refused with the capability and
//! its requirement named.

use rspirv::spirv::Capability as C;
use wgpu_types::Features;

/// What a capability needs of the replay device.
#[derive(Debug, PartialEq)]
pub(super) enum Need {
    /// Met by every device wgpu makes (Vulkan 1.0's core, features wgpu always turns on
    /// where the adapter has them, subgroup operations the device reports).
    Met,
    /// Met where the device was made with this wgpu feature.
    Wgpu(Features),
    /// A Vulkan feature or extension wgpu never turns on.
    Never(&'static str),
}

/// The need of capability `c` (the registry's requirement, as wgpu's Vulkan backend meets it).
pub(super) fn need(c: rspirv::spirv::Capability) -> Need {
    match c {
        C::Matrix
        | C::Shader
        | C::InputAttachment
        | C::Sampled1D
        | C::Image1D
        | C::SampledBuffer
        | C::ImageBuffer
        | C::ImageQuery
        | C::DerivativeControl
        | C::StorageImageExtendedFormats
        // Vulkan 1.1 and 1.2 core, with no feature.
        | C::DeviceGroup
        | C::ShaderNonUniform
        // wgpu turns on imageCubeArray and sampleRateShading wherever the adapter has them.
        | C::ImageCubeArray
        | C::SampledCubeArray
        | C::SampleRateShading
        | C::InterpolationFunction
        // Met by Vulkan 1.3's format features, which wgpu's devices have.
        | C::StorageImageReadWithoutFormat
        | C::StorageImageWriteWithoutFormat
        // Subgroup operations: device properties, not features.
        | C::GroupNonUniform
        | C::GroupNonUniformVote
        | C::GroupNonUniformArithmetic
        | C::GroupNonUniformBallot
        | C::GroupNonUniformShuffle
        | C::GroupNonUniformShuffleRelative
        | C::GroupNonUniformClustered
        | C::GroupNonUniformQuad => Need::Met,
        C::ClipDistance => Need::Wgpu(Features::CLIP_DISTANCES),
        C::Float64 => Need::Wgpu(Features::SHADER_F64),
        C::Int64 => Need::Wgpu(Features::SHADER_INT64),
        C::Int16 => Need::Wgpu(Features::SHADER_I16),
        C::DrawParameters => Need::Wgpu(Features::SHADER_DRAW_INDEX),
        // wgpu turns on shaderFloat16 and 16-bit buffer access together, with shaderInt8.
        C::Float16 | C::StorageBuffer16BitAccess | C::UniformAndStorageBuffer16BitAccess => {
            Need::Wgpu(Features::SHADER_F16)
        }
        C::DemoteToHelperInvocation => {
            Need::Never("VK_EXT_shader_demote_to_helper_invocation's shaderDemoteToHelperInvocation")
        }
        C::VulkanMemoryModel | C::VulkanMemoryModelDeviceScope => {
            Need::Never("VK_KHR_vulkan_memory_model's vulkanMemoryModel")
        }
        C::StorageInputOutput16 => Need::Never("storageInputOutput16"),
        C::StoragePushConstant16 => Need::Never("storagePushConstant16"),
        C::StorageBuffer8BitAccess
        | C::UniformAndStorageBuffer8BitAccess
        | C::StoragePushConstant8 => Need::Never("VK_KHR_8bit_storage"),
        C::Int8 => Need::Never("shaderInt8"),
        C::Geometry => Need::Never("geometryShader"),
        C::Tessellation => Need::Never("tessellationShader"),
        C::TessellationPointSize | C::GeometryPointSize => {
            Need::Never("shaderTessellationAndGeometryPointSize")
        }
        C::ImageGatherExtended => Need::Never("shaderImageGatherExtended"),
        C::StorageImageMultisample | C::ImageMSArray => {
            Need::Never("shaderStorageImageMultisample")
        }
        C::CullDistance => Need::Never("shaderCullDistance"),
        C::MinLod => Need::Never("shaderResourceMinLod"),
        C::SparseResidency => Need::Never("shaderResourceResidency"),
        C::MultiViewport => Need::Never("multiViewport"),
        C::MultiView => Need::Never("multiview"),
        C::ShaderViewportIndex | C::ShaderLayer | C::ShaderViewportIndexLayerEXT => {
            Need::Never("shaderOutputViewportIndex / shaderOutputLayer")
        }
        C::StencilExportEXT => Need::Never("VK_EXT_shader_stencil_export"),
        C::FragmentBarycentricKHR => Need::Never("VK_KHR_fragment_shader_barycentric"),
        C::FragmentShaderPixelInterlockEXT
        | C::FragmentShaderSampleInterlockEXT
        | C::FragmentShaderShadingRateInterlockEXT => {
            Need::Never("VK_EXT_fragment_shader_interlock")
        }
        C::Int64Atomics => Need::Never("shaderBufferInt64Atomics"),
        C::AtomicFloat32AddEXT | C::AtomicFloat64AddEXT => {
            Need::Never("VK_EXT_shader_atomic_float")
        }
        C::PhysicalStorageBufferAddresses => Need::Never("bufferDeviceAddress"),
        C::RuntimeDescriptorArray => Need::Never("runtimeDescriptorArray"),
        C::TransformFeedback | C::GeometryStreams => Need::Never("VK_EXT_transform_feedback"),
        _ => Need::Never("a device feature or extension wgpu does not turn on"),
    }
}

/// The wgpu features a passthrough module's `capabilities` need, or the first capability
/// no device wgpu makes has, with its requirement.
pub(super) fn features_for(
    capabilities: &[rspirv::spirv::Capability],
) -> Result<Features, (rspirv::spirv::Capability, &'static str)> {
    let mut features = Features::empty();
    for &c in capabilities {
        match need(c) {
            Need::Met => {}
            Need::Wgpu(f) => features |= f,
            Need::Never(what) => return Err((c, what)),
        }
    }
    Ok(features)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn core_capabilities_are_met_and_the_rest_named() {
        assert_eq!(
            features_for(&[C::Shader, C::Matrix, C::ImageQuery]),
            Ok(Features::empty())
        );
        assert_eq!(
            features_for(&[C::Shader, C::ClipDistance, C::Float64]),
            Ok(Features::CLIP_DISTANCES | Features::SHADER_F64)
        );
        let (c, what) = features_for(&[C::Shader, C::DemoteToHelperInvocation]).unwrap_err();
        assert_eq!(c, C::DemoteToHelperInvocation);
        assert!(what.contains("shaderDemoteToHelperInvocation"));
    }
}
