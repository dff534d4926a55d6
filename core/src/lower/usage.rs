//! What the passes do with each resource, gathered before anything is created: wgpu usage
//! flags, whether it is bound as depth, its first typed view (the format a typeless resource
//! becomes) and the first pass that touches it (named when its format cannot be replayed).

use std::collections::{BTreeMap, BTreeSet};

use wgpu_types as wgpu;

use crate::capture::dxgi::FormatInfo;
use crate::capture::format::{Access, ResourceFlag};
use crate::capture::model::*;

#[derive(Debug, Default)]
pub(super) struct Usage<'c> {
    pub textures: BTreeMap<ResourceId, wgpu::TextureUsages>,
    pub buffers: BTreeMap<ResourceId, wgpu::BufferUsages>,
    pub depth_bound: BTreeSet<ResourceId>,
    pub first_view: BTreeMap<ResourceId, &'static FormatInfo>,
    pub first_user: BTreeMap<ResourceId, &'c str>,
}

impl<'c> Usage<'c> {
    pub(super) fn of(capture: &'c Capture, passes: &[&'c PassDesc]) -> Usage<'c> {
        let mut u = Usage::default();
        for p in passes {
            for a in &p.accesses {
                u.first_user.entry(a.resource).or_insert(&p.name);
                if capture.resource(a.resource).is_texture() {
                    u.texture_access(a.resource, a.access);
                } else {
                    u.buffer_access(a.resource, a.access);
                }
            }
            for b in &p.bindings {
                if let BindingTarget::Resource {
                    resource,
                    view_format: Some(f),
                    ..
                } = b.target
                    && !f.is_typeless()
                {
                    u.first_view.entry(resource).or_insert(f);
                }
            }
            for c in &p.color_attachments {
                u.first_view.entry(c.resource).or_insert(c.format);
            }
            // A blit is drawn: its source is sampled and its destination rendered to.
            for b in &p.blits {
                if let Some(t) = u.textures.get_mut(&b.src.resource) {
                    *t |= wgpu::TextureUsages::TEXTURE_BINDING;
                }
                if let Some(t) = u.textures.get_mut(&b.dst.resource) {
                    *t |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                }
            }
            // A copy from a buffer into a 16-bit packed image is drawn (`packed16`), and one
            // into a 24-bit or float depth image without stencil: the buffer is read as
            // storage, the image rendered to.
            for c in &p.copies {
                let (src, dst) = (
                    capture.resource(c.src.resource),
                    capture.resource(c.dst.resource),
                );
                if !src.is_texture()
                    && dst.is_texture()
                    && dst.format.is_some_and(|f| {
                        super::packed16::layout(f.name).is_some()
                            || (f.is_depth_format() && f.stencil_bits == 0 && f.depth_bits > 16)
                    })
                {
                    if let Some(b) = u.buffers.get_mut(&src.id) {
                        *b |= wgpu::BufferUsages::STORAGE;
                    }
                    if let Some(t) = u.textures.get_mut(&dst.id) {
                        *t |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                    }
                }
            }
            // A clear of a render or depth target is drawn: a render pass that clears it.
            for c in &p.clears {
                if clears_by_drawing(capture.resource(c.resource))
                    && let Some(t) = u.textures.get_mut(&c.resource)
                {
                    *t |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                }
            }
            if let Some((r, _)) = p.generate_mips
                && let Some(t) = u.textures.get_mut(&r)
            {
                *t |= wgpu::TextureUsages::TEXTURE_BINDING;
            }
        }
        for r in &capture.resources {
            if r.has_flag(ResourceFlag::AllowDepthStencil) {
                u.depth_bound.insert(r.id);
            }
        }
        u
    }

    fn texture_access(&mut self, r: ResourceId, access: Access) {
        let u = self
            .textures
            .entry(r)
            .or_insert(wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST);
        match access {
            Access::Sampled => *u |= wgpu::TextureUsages::TEXTURE_BINDING,
            Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite => {
                *u |= wgpu::TextureUsages::STORAGE_BINDING
            }
            Access::ColorAttachment | Access::ResolveDst | Access::ResolveSrc => {
                *u |= wgpu::TextureUsages::RENDER_ATTACHMENT
            }
            Access::DepthRead | Access::DepthWrite => {
                *u |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                self.depth_bound.insert(r);
            }
            _ => {}
        }
    }

    fn buffer_access(&mut self, r: ResourceId, access: Access) {
        let u = self
            .buffers
            .entry(r)
            .or_insert(wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST);
        match access {
            Access::Uniform => *u |= wgpu::BufferUsages::UNIFORM,
            Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite => {
                *u |= wgpu::BufferUsages::STORAGE
            }
            Access::IndirectArgs => *u |= wgpu::BufferUsages::INDIRECT,
            Access::VertexBuffer => *u |= wgpu::BufferUsages::VERTEX,
            Access::IndexBuffer => *u |= wgpu::BufferUsages::INDEX,
            _ => {}
        }
    }
}

/// Whether a clear of `r` is a render pass that clears it (a render or depth target) rather
/// than a texture clear.
pub(super) fn clears_by_drawing(r: &ResourceDesc) -> bool {
    r.has_flag(ResourceFlag::AllowRenderTarget) || r.has_flag(ResourceFlag::AllowDepthStencil)
}
