//! Stand-ins for empty descriptors: `VK_NULL_HANDLE` written where a resource goes (the
//! nullDescriptor feature of VK_EXT_robustness2), whose loads give zero and whose stores and
//! atomics are discarded. The replay binds a blank (zero-filled, never written by the frame)
//! buffer or image of the type the shader declares, one per kind and shared, and says so in a
//! note. Null descriptors it has no stand-in for (texel buffers, input attachments,
//! multisampled images, depth comparisons) are refused by name.

use wgpu_types as wgpu;

use super::{Fail, VkProblem, states};
use crate::capture::model::*;
use crate::lower::Lowering;
use crate::plan::*;
use crate::spirv::{ResourceKind, ResourceVar, ScalarKind};

/// Where an empty descriptor is: set, binding and array element.
pub(super) type Slot = (u32, u32, u32);

/// A null descriptor the replay has no stand-in for, named with its slot and shader.
pub(super) fn refused(what: &str, (set, binding, element): Slot, shader: &str) -> Fail {
    VkProblem::Unsupported {
        feature: format!(
            "a null {what} descriptor (set {set} binding {binding} element {element} of shader {shader}): the replay has no blank to stand in for it"
        ),
    }
    .into()
}

/// The whole of blank texture `texture`, seen as `view` with `layers` layers.
fn blank_view(
    texture: usize,
    format: wgpu::TextureFormat,
    view: wgpu::TextureViewDimension,
    layers: u32,
) -> VkResource {
    VkResource::Texture {
        texture,
        format: Some(format),
        dimension: view,
        aspect: wgpu::TextureAspect::All,
        base_mip: 0,
        mips: Some(1),
        base_layer: 0,
        layers: Some(layers),
    }
}

impl Lowering<'_> {
    /// The plan's blank texture `name`, made on first use: `extent.0` texels square,
    /// `extent.1` layers, one level, zero-filled (wgpu clears what nothing wrote).
    fn vk_blank_texture(
        &mut self,
        name: String,
        (format, dimension): (wgpu::TextureFormat, wgpu::TextureDimension),
        (side, layers): (u32, u32),
        usage: wgpu::TextureUsages,
    ) -> usize {
        if let Some(t) = self.plan.textures.iter().position(|t| t.name == name) {
            return t;
        }
        self.plan.textures.push(TextureSpec {
            name,
            format,
            dimension,
            size: wgpu::Extent3d {
                width: side,
                height: side,
                depth_or_array_layers: layers,
            },
            mip_levels: 1,
            samples: 1,
            usage,
            view_formats: Vec::new(),
            initial: None,
            history: false,
            cube: layers == 6,
        });
        self.plan.textures.len() - 1
    }

    fn vk_blank_note(&mut self, p: &PassDesc, (set, binding, element): Slot, what: &str) {
        let note = format!(
            "pass \"{}\": set {set} binding {binding} element {element} is empty in the captured descriptor set; {what} stands in (reads give zero, writes are lost, as Vulkan's null descriptors)",
            p.name
        );
        if !self.notes.contains(&note) {
            self.notes.push(note);
        }
    }

    /// A zero-filled buffer for a null uniform or storage buffer descriptor: large enough for
    /// the block the shader declares (and one element of a runtime array after it), usable as
    /// either. Buffers written through are apart from those only read, so no null descriptor
    /// reads what another's stores left.
    pub(super) fn vk_blank_buffer(&mut self, p: &PassDesc, at: Slot, var: &ResourceVar) -> usize {
        let size = (var.block_size.unwrap_or(0) + 256).div_ceil(256) * 256;
        let written = matches!(var.kind, ResourceKind::StorageBuffer) && !var.non_writable;
        let name = format!(
            "blank {size}-byte buffer{}",
            if written { ", written" } else { "" }
        );
        let index = match self.plan.buffers.iter().position(|b| b.name == name) {
            Some(b) => b,
            None => {
                self.plan.buffers.push(BufferSpec {
                    name,
                    size,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE,
                    initial: None,
                    history: false,
                });
                self.plan.buffers.len() - 1
            }
        };
        self.vk_blank_note(p, at, &format!("a blank buffer of {size} zero bytes"));
        index
    }

    /// A blank 1x1 image (six layers for a cube) for a null sampled image or combined image
    /// sampler: four channels of zero in the sample type the shader declares (Vulkan's null
    /// image reads give zero in every channel, alpha too). Its size queries give 1, Vulkan's
    /// 0; the note says so.
    pub(super) fn vk_blank_sampled(
        &mut self,
        p: &PassDesc,
        at: Slot,
        var: &ResourceVar,
        shader: &str,
        compares: bool,
    ) -> Result<(wgpu::BindingType, VkResource), Fail> {
        let info = match &var.kind {
            ResourceKind::SampledImage(i) | ResourceKind::CombinedImageSampler(i) => *i,
            ResourceKind::InputAttachment { .. } => {
                return Err(refused("input attachment", at, shader));
            }
            _ => return Err(refused("image", at, shader)),
        };
        if info.multisampled {
            return Err(refused("multisampled image", at, shader));
        }
        // What a depth comparison against a null image gives is not zero but the comparison's
        // outcome against a texel Vulkan does not pin down.
        if compares || info.depth == Some(true) {
            return Err(refused("depth-compared image", at, shader));
        }
        use rspirv::spirv::Dim;
        use wgpu::{TextureDimension as D, TextureViewDimension as V};
        let (dimension, view, layers) = match (info.dim, info.arrayed) {
            (Dim::Dim1D, false) => (D::D1, V::D1, 1),
            (Dim::Dim2D, false) => (D::D2, V::D2, 1),
            (Dim::Dim2D, true) => (D::D2, V::D2Array, 1),
            (Dim::Dim3D, false) => (D::D3, V::D3, 1),
            (Dim::DimCube, false) => (D::D2, V::Cube, 6),
            (Dim::DimCube, true) => (D::D2, V::CubeArray, 6),
            _ => return Err(refused(&format!("{:?} image", info.dim), at, shader)),
        };
        let (format, sample_type) = match info.sampled_type {
            ScalarKind::Float => (
                wgpu::TextureFormat::Rgba8Unorm,
                wgpu::TextureSampleType::Float { filterable: true },
            ),
            ScalarKind::Sint => (
                wgpu::TextureFormat::Rgba8Sint,
                wgpu::TextureSampleType::Sint,
            ),
            ScalarKind::Uint => (
                wgpu::TextureFormat::Rgba8Uint,
                wgpu::TextureSampleType::Uint,
            ),
        };
        let (extent, usage) = ((1, layers), wgpu::TextureUsages::TEXTURE_BINDING);
        let texture = self.vk_blank_texture(
            format!("blank {format:?} {view:?} image"),
            (format, dimension),
            extent,
            usage,
        );
        self.vk_blank_note(
            p,
            at,
            "a blank 1x1 image (its size queries give 1 where Vulkan's give 0)",
        );
        let ty = wgpu::BindingType::Texture {
            sample_type,
            view_dimension: view,
            multisampled: false,
        };
        Ok((ty, blank_view(texture, format, view, layers)))
    }

    /// A blank 1x1 storage image for a storage-image descriptor the captured set leaves
    /// empty (FFmpeg's output array of three planes with one written for a one-plane frame).
    /// `None` where the shader's declared format or dimension has no wgpu storage twin.
    pub(super) fn vk_blank_storage(
        &mut self,
        p: &PassDesc,
        at: Slot,
        var: &ResourceVar,
    ) -> Option<(wgpu::BindingType, VkResource)> {
        let ResourceKind::StorageImage(info) = &var.kind else {
            return None;
        };
        let format = states::storage_format(info.format)?;
        let (dimension, view) = match (info.dim, info.arrayed) {
            (rspirv::spirv::Dim::Dim2D, false) => {
                (wgpu::TextureDimension::D2, wgpu::TextureViewDimension::D2)
            }
            _ => return None,
        };
        let usage = wgpu::TextureUsages::STORAGE_BINDING;
        let texture = self.vk_blank_texture(
            format!("blank {format:?} storage image"),
            (format, dimension),
            (1, 1),
            usage,
        );
        self.vk_blank_note(p, at, "a blank storage image");
        let ty = wgpu::BindingType::StorageTexture {
            access: super::states::storage_access(var),
            format,
            view_dimension: view,
        };
        Some((ty, blank_view(texture, format, view, 1)))
    }
}
