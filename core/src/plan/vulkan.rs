//! The replay plan's Vulkan half: an imported frame's pipelines at wgpu level. Shaders are
//! the application's SPIR-V, rewritten for wgpu (`crate::spirv`); bind group layouts come
//! from the captured set layouts and what the shaders use; every draw and dispatch carries its
//! own pipeline, bind groups, vertex and index buffers, dynamic state and push constants, as
//! the application recorded them. Re-exported by `crate::plan`.

use super::targets::{ColorTarget, DepthTarget};

#[derive(Debug, Clone, Default)]
pub struct VkPlan {
    pub shaders: Vec<SpirvShader>,
    /// Entries of each bind group layout, sorted by binding.
    pub group_layouts: Vec<Vec<wgpu_types::BindGroupLayoutEntry>>,
    pub pipelines: Vec<VkPipelineSpec>,
}

impl VkPlan {
    pub fn is_empty(&self) -> bool {
        self.pipelines.is_empty()
    }
}

/// How a shader reaches the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShaderPath {
    /// naga parsed and validated it; wgpu translates it for whatever backend it runs on.
    Naga,
    /// Handed to the Vulkan driver as it is (after the rewrite).
    Passthrough,
}

impl ShaderPath {
    pub fn name(self) -> &'static str {
        match self {
            ShaderPath::Naga => "naga",
            ShaderPath::Passthrough => "passthrough",
        }
    }
}

#[derive(Debug, Clone)]
pub struct SpirvShader {
    /// As named in messages: the module, its stage and the pipeline it was made for.
    pub name: String,
    pub entry: String,
    pub stage: wgpu_types::ShaderStages,
    /// The module rewritten for wgpu's binding numbers, where naga's front end and validator
    /// accept it (wgpu then renumbers for whatever backend runs it).
    pub naga: Option<Vec<u32>>,
    /// The module rewritten for the numbers wgpu's Vulkan backend gives its descriptor set
    /// layouts, for the driver as it is.
    pub passthrough: Vec<u32>,
    /// The entry point's workgroup size (compute).
    pub workgroup: [u32; 3],
}

#[derive(Debug, Clone)]
pub struct VkPipelineSpec {
    pub name: String,
    /// Bind group layouts by set number (`None`: a set the shaders do not use).
    pub groups: Vec<Option<usize>>,
    /// Push-constant bytes, at most the device's immediate size.
    pub immediate_size: u32,
    pub kind: VkPipelineKind,
}

#[derive(Debug, Clone)]
pub enum VkPipelineKind {
    Render(Box<VkRenderPipeline>),
    Compute { shader: usize },
}

#[derive(Debug, Clone)]
pub struct VkRenderPipeline {
    pub vertex: usize,
    pub fragment: Option<usize>,
    pub buffers: Vec<VkVertexLayout>,
    pub primitive: wgpu_types::PrimitiveState,
    pub depth_stencil: Option<wgpu_types::DepthStencilState>,
    pub targets: Vec<Option<wgpu_types::ColorTargetState>>,
    pub samples: u32,
    pub alpha_to_coverage: bool,
    /// Which samples the draws write (wgpu's multisample mask).
    pub sample_mask: u64,
}

#[derive(Debug, Clone)]
pub struct VkVertexLayout {
    /// The Vulkan binding, which is the wgpu vertex buffer slot.
    pub slot: u32,
    pub stride: u64,
    pub step: wgpu_types::VertexStepMode,
    pub attributes: Vec<wgpu_types::VertexAttribute>,
}

/// A bind group of one draw or dispatch.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct VkGroup {
    pub layout: usize,
    /// (wgpu binding, what is bound), sorted by binding.
    pub entries: Vec<(u32, VkResource)>,
}

/// What a descriptor binds, with the view a Vulkan image view describes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum VkResource {
    Texture {
        texture: usize,
        /// `None`: the texture's own format (depth and stencil views).
        format: Option<wgpu_types::TextureFormat>,
        dimension: wgpu_types::TextureViewDimension,
        aspect: wgpu_types::TextureAspect,
        base_mip: u32,
        mips: Option<u32>,
        base_layer: u32,
        layers: Option<u32>,
    },
    Buffer {
        buffer: usize,
        offset: u64,
        size: Option<u64>,
    },
    Sampler(usize),
}

#[derive(Debug, Clone)]
pub struct VkRasterOp {
    pub color: Vec<ColorTarget>,
    pub depth: Option<DepthTarget>,
    pub draws: Vec<VkDrawOp>,
    /// Attachment rectangles cleared between the draws, in order.
    pub clears: Vec<VkClearOp>,
    /// The attachments' width and height.
    pub extent: [u32; 2],
    /// The attachments' sample count.
    pub samples: u32,
    /// Attachments copied between the draws for draws that read what the pass renders, in
    /// draw order: the render pass is ended before each one and begun again after it.
    pub fetches: Vec<VkFetch>,
}

/// A copy of colour attachment `color`'s subresource into texture `copy`, taken before draw
/// `before` (after the clears recorded before it): Vulkan lets a subpass read its own
/// attachment (an input attachment, "framebuffer fetch"; a feedback-loop layout), wgpu does
/// not read and render one subresource in one pass, so the draws read the copy. What they
/// see is everything drawn before them, which a pipeline barrier inside the subpass gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VkFetch {
    pub before: usize,
    pub color: usize,
    pub copy: usize,
}

impl VkRasterOp {
    /// The draws of each render pass the op is replayed as: split before each fetch. A
    /// fetch before the first draw leaves a first pass of no draws, which still loads or
    /// clears the attachments and runs the clears recorded before it.
    pub fn segments(&self) -> Vec<std::ops::Range<usize>> {
        let mut starts: Vec<usize> = self.fetches.iter().map(|f| f.before).collect();
        starts.dedup();
        let mut out = Vec::with_capacity(starts.len() + 1);
        let mut from = 0;
        for s in starts {
            out.push(from..s);
            from = s;
        }
        out.push(from..self.draws.len());
        out
    }
}

/// A `vkCmdClearAttachments`, drawn before draw `before` (after the last where it is the draw
/// count): each rectangle covered with the values, through the scissor.
#[derive(Debug, Clone, PartialEq)]
pub struct VkClearOp {
    pub before: usize,
    /// Per colour target, the value it is cleared to; `None` where it keeps its contents.
    pub colors: Vec<Option<[f64; 4]>>,
    pub depth: Option<f32>,
    pub stencil: Option<u32>,
    /// `[x, y, width, height]`, clipped to the attachments.
    pub rects: Vec<[u32; 4]>,
}

#[derive(Debug, Clone)]
pub struct VkDrawOp {
    pub pipeline: usize,
    /// By set number.
    pub groups: Vec<Option<VkGroup>>,
    /// (slot, buffer, offset).
    pub vertex_buffers: Vec<(u32, usize, u64)>,
    pub index: Option<(usize, u64, wgpu_types::IndexFormat)>,
    /// `[x, y, width, height, min depth, max depth]` in framebuffer pixels.
    pub viewport: Option<[f32; 6]>,
    /// `[x, y, width, height]`, clipped to the target.
    pub scissor: Option<[u32; 4]>,
    pub immediates: Vec<u8>,
    pub blend_constant: Option<[f64; 4]>,
    pub stencil_reference: Option<u32>,
    pub count: u32,
    pub instances: u32,
    pub first: u32,
    pub first_instance: u32,
    pub base_vertex: i32,
    pub indirect: Option<(usize, u64)>,
    /// Count buffer, offset and most records of a draw whose count the GPU reads.
    pub draw_count: Option<(usize, u64, u32)>,
}

#[derive(Debug, Clone)]
pub struct VkComputeOp {
    pub dispatches: Vec<VkDispatchOp>,
}

#[derive(Debug, Clone)]
pub struct VkDispatchOp {
    pub pipeline: usize,
    pub groups: Vec<Option<VkGroup>>,
    pub immediates: Vec<u8>,
    pub workgroups: Option<[u32; 3]>,
    pub indirect: Option<(usize, u64)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raster(draws: usize, befores: &[usize]) -> VkRasterOp {
        let draw = VkDrawOp {
            pipeline: 0,
            groups: Vec::new(),
            vertex_buffers: Vec::new(),
            index: None,
            viewport: None,
            scissor: None,
            immediates: Vec::new(),
            blend_constant: None,
            stencil_reference: None,
            count: 3,
            instances: 1,
            first: 0,
            first_instance: 0,
            base_vertex: 0,
            indirect: None,
            draw_count: None,
        };
        VkRasterOp {
            color: Vec::new(),
            depth: None,
            draws: vec![draw; draws],
            clears: Vec::new(),
            extent: [1, 1],
            samples: 1,
            fetches: befores
                .iter()
                .enumerate()
                .map(|(k, &before)| VkFetch {
                    before,
                    color: k % 2,
                    copy: 9,
                })
                .collect(),
        }
    }

    /// A pass is split before each draw that reads a copy, once however many attachments it
    /// copies there; a copy before the first draw leaves a first pass of no draws, which
    /// still runs the load and clear.
    #[test]
    fn a_pass_is_split_before_each_fetching_draw() {
        assert_eq!(raster(3, &[]).segments(), vec![0..3]);
        assert_eq!(raster(4, &[2, 2]).segments(), vec![0..2, 2..4]);
        assert_eq!(raster(4, &[0, 3]).segments(), vec![0..0, 0..3, 3..4]);
    }
}
