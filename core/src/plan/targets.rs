//! The attachments a render pass of the plan draws into, framelab's own passes and imported
//! ones alike: which texture subresource, how it is loaded and stored, how colour blends.

#[derive(Debug, Clone)]
pub struct ColorTarget {
    pub texture: usize,
    pub format: wgpu_types::TextureFormat,
    pub mip: u32,
    pub layer: u32,
    pub load: Option<wgpu_types::Color>,
    pub discard_load: bool,
    pub store: bool,
    pub blend: Option<wgpu_types::BlendState>,
    pub write_mask: wgpu_types::ColorWrites,
}

#[derive(Debug, Clone)]
pub struct DepthTarget {
    pub texture: usize,
    pub format: wgpu_types::TextureFormat,
    pub mip: u32,
    pub layer: u32,
    pub depth_clear: Option<f32>,
    pub depth_store: bool,
    pub stencil_clear: Option<u32>,
    pub stencil_store: bool,
    /// The depth aspect is read-only.
    pub read_only: bool,
    /// The stencil aspect is read-only.
    pub stencil_read_only: bool,
    /// The pass also reads the texture through a binding (`cross_pass::mark_sampled_depth`):
    /// its read-only aspects must be attached read-only. Otherwise they are attached as
    /// writable and left unwritten (the pipelines write no depth there), since a read-only
    /// attachment that stores its contents is a write the barriers before it do not cover.
    pub sampled: bool,
}
