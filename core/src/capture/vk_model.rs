//! The `vulkan` section of a validated capture, by index: modules with their SPIR-V words,
//! samplers, image views on resources, set and pipeline layouts, pipelines, and per draw or
//! dispatch the pipeline, dynamic state, push constants, descriptors and vertex and index
//! buffers it ran with. Validation resolves every name once; the lowering and the replay work
//! on these indices and never look a name up again.

use std::sync::Arc;

use super::format::{GraphicsState, LayoutBinding, VkDynamicValues, VkSampler};
use super::ids::ResourceId;

#[derive(Clone, Debug, Default)]
pub struct VkModel {
    pub modules: Vec<VkModule>,
    pub samplers: Vec<VkSampler>,
    pub views: Vec<VkView>,
    pub set_layouts: Vec<VkSetLayout>,
    pub pipeline_layouts: Vec<VkPipelineLayout>,
    pub pipelines: Vec<VkPipeline>,
}

#[derive(Clone, Debug)]
pub struct VkModule {
    pub name: String,
    /// The `.spv` file, relative to the capture, for messages.
    pub file: Option<String>,
    /// The code; `None` where the capture holds none (a JSON Lines import).
    pub words: Option<Arc<Vec<u32>>>,
}

#[derive(Clone, Debug)]
pub struct VkView {
    pub name: String,
    pub image: ResourceId,
    /// `VK_IMAGE_VIEW_TYPE_*`.
    pub view_type: String,
    /// `VK_FORMAT_*`.
    pub format: String,
    pub aspect: u32,
    pub base_mip: u32,
    pub mips: Option<u32>,
    pub base_layer: u32,
    pub layers: Option<u32>,
    /// What each of R, G, B and A reads, where not the identity.
    pub swizzle: Option<[Component; 4]>,
}

/// One channel of a view's component mapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Component {
    R,
    G,
    B,
    A,
    Zero,
    One,
}

impl Component {
    /// From its letter in a view's `swizzle` (`R`, `G`, `B`, `A`, `0`, `1`).
    pub fn of(c: char) -> Option<Component> {
        Some(match c {
            'R' => Component::R,
            'G' => Component::G,
            'B' => Component::B,
            'A' => Component::A,
            '0' => Component::Zero,
            '1' => Component::One,
            _ => return None,
        })
    }
}

#[derive(Clone, Debug)]
pub struct VkSetLayout {
    pub name: String,
    pub flags: u32,
    pub bindings: Vec<LayoutBinding>,
    /// Immutable samplers of each binding, as sampler indices (parallel to `bindings`).
    pub immutable: Vec<Vec<usize>>,
}

#[derive(Clone, Debug)]
pub struct VkPipelineLayout {
    pub name: String,
    /// Set layouts by set number.
    pub sets: Vec<usize>,
    /// Bytes of push constants the layout declares (the end of its last range).
    pub push_size: u32,
}

#[derive(Clone, Debug)]
pub struct VkPipeline {
    pub name: String,
    pub compute: bool,
    pub layout: usize,
    pub stages: Vec<VkStage>,
    pub graphics: Option<Box<GraphicsState>>,
}

#[derive(Clone, Debug)]
pub struct VkStage {
    /// `VK_SHADER_STAGE_*_BIT`.
    pub stage: String,
    pub module: usize,
    pub entry: String,
    /// (constant id, size, value) where the capture holds the value.
    pub specialization: Vec<(u32, u32, Option<u64>)>,
}

/// What one draw or dispatch ran with.
#[derive(Clone, Debug)]
pub struct VkWork {
    pub pipeline: usize,
    pub viewport: Option<[f32; 6]>,
    pub scissor: Option<[i64; 4]>,
    pub blend_constants: Option<[f32; 4]>,
    /// (front, back).
    pub stencil_reference: Option<[u32; 2]>,
    /// The other dynamic state set before the draw.
    pub dynamic: Option<Box<VkDynamicValues>>,
    /// Push-constant bytes from offset 0; `None` where the source held no values.
    pub push_constants: Option<Vec<u8>>,
    pub descriptors: Vec<VkBound>,
    /// (binding, buffer, offset).
    pub vertex_buffers: Vec<(u32, ResourceId, u64)>,
    /// (buffer, offset, 32-bit indices).
    pub index_buffer: Option<(ResourceId, u64, bool)>,
}

/// One descriptor a draw or dispatch could reach.
#[derive(Clone, Debug)]
pub struct VkBound {
    pub set: u32,
    pub binding: u32,
    pub element: u32,
    /// `VK_DESCRIPTOR_TYPE_*` without the prefix.
    pub descriptor_type: String,
    pub resource: Option<ResourceId>,
    pub view: Option<usize>,
    pub sampler: Option<usize>,
    pub offset: Option<u64>,
    pub range: Option<u64>,
    /// Texel buffers: the view's `VK_FORMAT_*`.
    pub format: Option<String>,
}
