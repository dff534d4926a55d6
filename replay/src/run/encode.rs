//! Encoding one pass into a command encoder: raster (targets, draws, indirect), compute
//! (dispatches, indirect), copies, clears, resolves, mip generation. Passes without a pass
//! object of their own get their timestamps written on the encoder where the adapter allows.

use framelab_core::plan::{
    ClearOp, ColorTarget, ComputeOp, CopyEnd, CopyOp, DepthTarget, PassOp, RasterOp, TextureSpec,
};

use super::create::{extent, texel};
use super::pipelines::{Stages, buffer_layout};
use super::stamps::Stamps;

/// The pipeline statistics query a pass writes, if the frame counts it (see `counters`).
pub(super) type Stat<'q> = Option<(&'q wgpu::QuerySet, u32)>;
use super::{Prepared, ReplayError, Session};

fn render_stamps(stamps: Stamps<'_>) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    stamps.map(|(set, start, end)| wgpu::RenderPassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: start,
        end_of_pass_write_index: Some(end),
    })
}

fn compute_stamps(stamps: Stamps<'_>) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
    stamps.map(|(set, start, end)| wgpu::ComputePassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: start,
        end_of_pass_write_index: Some(end),
    })
}

/// A render pass over one colour target, stored, with no depth, timestamps or queries: the
/// passes the replay draws itself (mip generation, blits).
pub(super) fn one_target<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Why one pass could not be recorded; the session reports it as that pass's error.
#[derive(Debug, thiserror::Error)]
pub(super) enum EncodeError {
    #[error("pass was not prepared")]
    NotPrepared,
    #[error("no pipeline for `{0}`")]
    NoPipeline(String),
    #[error("a dispatch without groups")]
    NoGroups,
    #[error("mip pipeline missing")]
    NoMipPipeline,
    #[error(
        "clearing unordered-access texture \"{texture}\" to a non-zero value is not supported; clear it as a render target"
    )]
    NonZeroTextureClear { texture: String },
    #[error("{0}")]
    Mapping(wgpu::MapRangeError),
}

impl Session {
    fn tex_at(&self, t: usize, parity: usize) -> &wgpu::Texture {
        &self.textures[t][parity]
    }

    fn buf_at(&self, b: usize, parity: usize) -> &wgpu::Buffer {
        &self.buffers[b][parity]
    }

    pub(super) fn encode(
        &self,
        i: usize,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        stamps: Stamps<'_>,
        inside_encoders: bool,
        stat: Option<super::counters::PassQueries<'_>>,
    ) -> Result<(), ReplayError> {
        let first_query = stat.and_then(|q| q.get(0));
        let pass = &self.plan.passes[i];
        let err = |e: EncodeError| ReplayError::Pass {
            pass: pass.name.clone(),
            message: e.to_string(),
        };
        let stamp_encoder = |encoder: &mut wgpu::CommandEncoder, at_end: bool| {
            if let (Some((set, start, end)), true) = (stamps, inside_encoders) {
                let index = if at_end { Some(end) } else { start };
                if let Some(index) = index {
                    encoder.write_timestamp(set, index);
                }
            }
        };
        match (&pass.op, &self.prepared[i]) {
            (PassOp::Raster(r), prepared @ Prepared::Raster { .. }) => self
                .encode_raster(
                    &pass.name,
                    r,
                    prepared,
                    parity,
                    encoder,
                    (stamps, first_query),
                )
                .map_err(err)?,
            (PassOp::Compute(c), prepared @ Prepared::Compute { .. }) => self
                .encode_compute(
                    &pass.name,
                    c,
                    prepared,
                    parity,
                    encoder,
                    (stamps, first_query),
                )
                .map_err(err)?,
            (PassOp::VkRaster(r), Prepared::VkWork(groups)) => {
                self.shadows_in(groups, encoder);
                self.encode_vk_render_passes(
                    (i, &pass.name),
                    r,
                    groups,
                    parity,
                    encoder,
                    (stamps, stat),
                );
                self.shadows_out(groups, encoder);
            }
            (PassOp::VkCompute(c), Prepared::VkWork(groups)) => {
                self.shadows_in(groups, encoder);
                let cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(&pass.name),
                    timestamp_writes: compute_stamps(stamps),
                });
                self.encode_vk_compute(c, groups, cp, first_query);
                self.shadows_out(groups, encoder);
            }
            (PassOp::Copy(copies), _) => {
                stamp_encoder(encoder, false);
                for c in copies {
                    self.encode_copy(c, parity, encoder).map_err(err)?;
                }
                stamp_encoder(encoder, true);
            }
            (PassOp::Blit(blits), Prepared::Blit(prepared)) => {
                stamp_encoder(encoder, false);
                self.encode_blits(&pass.name, blits, prepared, parity, encoder)
                    .map_err(err)?;
                stamp_encoder(encoder, true);
            }
            (PassOp::Clear(clears), _) => {
                stamp_encoder(encoder, false);
                for c in clears {
                    self.encode_clear(encoder, c, parity).map_err(err)?;
                }
                stamp_encoder(encoder, true);
            }
            (PassOp::Resolve { src, dst }, _) => {
                self.encode_resolve(&pass.name, *src, *dst, parity, encoder, stamps);
            }
            (
                PassOp::GenerateMips {
                    texture,
                    base_layer,
                    layers,
                },
                _,
            ) => {
                stamp_encoder(encoder, false);
                self.encode_mips(
                    *texture,
                    *base_layer..*base_layer + *layers,
                    parity,
                    encoder,
                )
                .map_err(err)?;
                stamp_encoder(encoder, true);
            }
            (PassOp::Present { .. }, _) => {
                stamp_encoder(encoder, false);
                stamp_encoder(encoder, true);
            }
            _ => return Err(err(EncodeError::NotPrepared)),
        }
        Ok(())
    }

    fn encode_raster(
        &self,
        name: &str,
        r: &RasterOp,
        prepared: &Prepared,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        (stamps, stat): (Stamps<'_>, Stat<'_>),
    ) -> Result<(), EncodeError> {
        let Prepared::Raster {
            pipelines,
            groups,
            draw_groups,
        } = prepared
        else {
            return Err(EncodeError::NotPrepared);
        };
        let buf = |b: usize| self.buf_at(b, parity);
        let mut rp = self.begin_render(
            name,
            (&r.color, r.depth.as_ref()),
            parity,
            encoder,
            render_stamps(stamps),
        );
        if let Some((set, q)) = stat {
            rp.begin_pipeline_statistics_query(set, q);
        }
        rp.set_stencil_reference(r.stencil_reference);
        for (d, set) in r.draws.iter().zip(draw_groups).take(self.steps()) {
            let key = Stages::of(d, r);
            let (Some(pipeline), Some(sets)) = (pipelines.get(&key), groups.get(&key)) else {
                return Err(EncodeError::NoPipeline(key.to_string()));
            };
            rp.set_pipeline(pipeline);
            for (g, bg) in &sets[*set][parity] {
                rp.set_bind_group(*g, bg, &[]);
            }
            if let Some(reference) = d.stencil_reference {
                rp.set_stencil_reference(reference);
            }
            let mesh = d.mesh.map(|m| &self.meshes[m]);
            if let Some(mesh) = mesh {
                for (slot, b) in &mesh.streams {
                    rp.set_vertex_buffer(*slot, b.slice(..));
                }
            }
            match (mesh.and_then(|m| m.index.as_ref()), d.indirect) {
                (Some((ib, format, _)), Some((b, offset))) => {
                    rp.set_index_buffer(ib.slice(..), *format);
                    match d.draw_count {
                        Some((c, at, most)) => {
                            rp.multi_draw_indexed_indirect_count(buf(b), offset, buf(c), at, most);
                        }
                        None => rp.draw_indexed_indirect(buf(b), offset),
                    }
                }
                (None, Some((b, offset))) => match d.draw_count {
                    Some((c, at, most)) => {
                        rp.multi_draw_indirect_count(buf(b), offset, buf(c), at, most)
                    }
                    None => rp.draw_indirect(buf(b), offset),
                },
                (Some((ib, format, n)), None) => {
                    rp.set_index_buffer(ib.slice(..), *format);
                    let count = d.count.unwrap_or(*n);
                    let instances = if d.instances == 1 {
                        mesh.map_or(1, |m| m.instance_count.max(1))
                    } else {
                        d.instances
                    };
                    rp.draw_indexed(
                        d.first..d.first.saturating_add(count),
                        d.base_vertex,
                        d.first_instance..d.first_instance.saturating_add(instances),
                    );
                }
                (None, None) => {
                    let count = d.count.or(mesh.map(|m| m.vertex_count)).unwrap_or(3);
                    let instances = if d.instances == 1 {
                        mesh.map_or(1, |m| m.instance_count.max(1))
                    } else {
                        d.instances
                    };
                    rp.draw(
                        d.first..d.first.saturating_add(count),
                        d.first_instance..d.first_instance.saturating_add(instances),
                    );
                }
            }
        }
        if stat.is_some() {
            rp.end_pipeline_statistics_query();
        }
        Ok(())
    }

    /// Begins a render pass on the targets' views, with the pass's timestamps.
    pub(super) fn begin_render<'e>(
        &self,
        name: &str,
        (color, depth): (&[ColorTarget], Option<&DepthTarget>),
        parity: usize,
        encoder: &'e mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let color_views: Vec<wgpu::TextureView> = color
            .iter()
            .map(|c| self.view(c.texture, parity, c.mip, c.layer, Some(c.format)))
            .collect();
        let depth_view = depth.map(|d| self.view(d.texture, parity, d.mip, d.layer, None));
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> = color
            .iter()
            .zip(&color_views)
            .map(|(c, view)| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: (self.plan.textures[c.texture].dimension
                        == wgpu::TextureDimension::D3)
                        .then_some(c.layer),
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: match c.load {
                            Some(color) => wgpu::LoadOp::Clear(color),
                            None if c.discard_load => wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            None => wgpu::LoadOp::Load,
                        },
                        store: if c.store {
                            wgpu::StoreOp::Store
                        } else {
                            wgpu::StoreOp::Discard
                        },
                    },
                })
            })
            .collect();
        let depth_attachment = depth.zip(depth_view.as_ref()).map(|(d, view)| {
            let stencil = d.format.has_stencil_aspect();
            // A format without depth (Stencil8) takes no depth operations at all.
            wgpu::RenderPassDepthStencilAttachment {
                view,
                depth_ops: if d.read_only && d.sampled || !d.format.has_depth_aspect() {
                    None
                } else {
                    Some(wgpu::Operations {
                        load: d
                            .depth_clear
                            .map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                        store: if d.depth_store {
                            wgpu::StoreOp::Store
                        } else {
                            wgpu::StoreOp::Discard
                        },
                    })
                },
                stencil_ops: (stencil && !(d.stencil_read_only && d.sampled)).then(|| {
                    wgpu::Operations {
                        load: d
                            .stencil_clear
                            .map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
                        store: if d.stencil_store {
                            wgpu::StoreOp::Store
                        } else {
                            wgpu::StoreOp::Discard
                        },
                    }
                }),
            }
        });
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &attachments,
            depth_stencil_attachment: depth_attachment,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    fn encode_compute(
        &self,
        name: &str,
        c: &ComputeOp,
        prepared: &Prepared,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        (stamps, stat): (Stamps<'_>, Stat<'_>),
    ) -> Result<(), EncodeError> {
        let Prepared::Compute {
            pipelines,
            groups,
            dispatch_groups,
        } = prepared
        else {
            return Err(EncodeError::NotPrepared);
        };
        let buf = |b: usize| self.buf_at(b, parity);
        let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: compute_stamps(stamps),
        });
        if let Some((set, q)) = stat {
            cp.begin_pipeline_statistics_query(set, q);
        }
        for (d, set) in c.dispatches.iter().zip(dispatch_groups).take(self.steps()) {
            let entry = d.entry.as_ref().unwrap_or(&c.entry);
            let (Some(pipeline), Some(sets)) = (pipelines.get(entry), groups.get(entry)) else {
                return Err(EncodeError::NoPipeline(entry.clone()));
            };
            cp.set_pipeline(pipeline);
            for (g, bg) in &sets[*set][parity] {
                cp.set_bind_group(*g, bg, &[]);
            }
            match (d.groups, d.indirect) {
                (_, Some((b, offset))) => cp.dispatch_workgroups_indirect(buf(b), offset),
                (Some([x, y, z]), None) => cp.dispatch_workgroups(x, y, z),
                (None, None) => return Err(EncodeError::NoGroups),
            }
        }
        if stat.is_some() {
            cp.end_pipeline_statistics_query();
        }
        Ok(())
    }

    fn encode_copy(
        &self,
        c: &CopyOp,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), EncodeError> {
        if let Some(layout) = c.unpack {
            return self.encode_unpack(c, layout, parity, encoder);
        }
        if c.depth {
            return self.encode_depth_copy(c, parity, encoder);
        }
        let tex = |t: usize| self.tex_at(t, parity);
        let buf = |b: usize| self.buf_at(b, parity);
        match (&c.src, &c.dst) {
            (
                CopyEnd::Buffer {
                    buffer: a,
                    offset: oa,
                    ..
                },
                CopyEnd::Buffer {
                    buffer: b,
                    offset: ob,
                    ..
                },
            ) => {
                encoder.copy_buffer_to_buffer(buf(*a), *oa, buf(*b), *ob, c.bytes);
            }
            (
                CopyEnd::Texture {
                    texture: a,
                    mip: ma,
                    layer: la,
                    origin: oa,
                },
                CopyEnd::Texture {
                    texture: b,
                    mip: mb,
                    layer: lb,
                    origin: ob,
                },
            ) => {
                encoder.copy_texture_to_texture(
                    texel(tex(*a), &self.plan.textures[*a], *ma, *la, *oa),
                    texel(tex(*b), &self.plan.textures[*b], *mb, *lb, *ob),
                    extent(c.extent),
                );
            }
            (CopyEnd::Buffer { .. }, CopyEnd::Texture { .. }) => {
                if let Some((b, t)) = self.copy_sides(&c.src, &c.dst, parity) {
                    buffer_texture_copy(encoder, true, b, t, c.extent);
                }
            }
            (CopyEnd::Texture { .. }, CopyEnd::Buffer { .. }) => {
                if let Some((b, t)) = self.copy_sides(&c.dst, &c.src, parity) {
                    buffer_texture_copy(encoder, false, b, t, c.extent);
                }
            }
        }
        Ok(())
    }

    /// The two ends of a buffer-texture copy, whichever way it goes.
    fn copy_sides(
        &self,
        buffer_end: &CopyEnd,
        texture_end: &CopyEnd,
        parity: usize,
    ) -> Option<(BufferSide<'_>, TextureSide<'_>)> {
        let (
            CopyEnd::Buffer {
                buffer,
                offset,
                bytes_per_row,
            },
            CopyEnd::Texture {
                texture,
                mip,
                layer,
                origin,
            },
        ) = (buffer_end, texture_end)
        else {
            return None;
        };
        Some((
            BufferSide {
                buffer: self.buf_at(*buffer, parity),
                offset: *offset,
                bytes_per_row: *bytes_per_row,
            },
            TextureSide {
                texture: self.tex_at(*texture, parity),
                spec: &self.plan.textures[*texture],
                mip: *mip,
                layer: *layer,
                origin: *origin,
            },
        ))
    }

    fn encode_resolve(
        &self,
        name: &str,
        src: usize,
        dst: usize,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
        stamps: Stamps<'_>,
    ) {
        let src_view = self.view(src, parity, 0, 0, None);
        let dst_view = self.view(dst, parity, 0, 0, None);
        let _rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &src_view,
                depth_slice: None,
                resolve_target: Some(&dst_view),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: render_stamps(stamps),
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }

    fn encode_mips(
        &self,
        texture: usize,
        layers: std::ops::Range<u32>,
        parity: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), EncodeError> {
        let spec = &self.plan.textures[texture];
        let (pipeline, sampler) = self
            .mip_pipelines
            .get(&format!("{:?}", spec.format))
            .ok_or(EncodeError::NoMipPipeline)?;
        let layout = pipeline.get_bind_group_layout(0);
        for layer in layers.clone() {
            for mip in 1..spec.mip_levels {
                let dst = self.view(texture, parity, mip, layer, None);
                let bg = self
                    .mip_groups
                    .borrow_mut()
                    .entry((texture, parity, mip, layer, None))
                    .or_insert_with(|| {
                        let src = self.view(texture, parity, mip - 1, layer, None);
                        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("mip source"),
                            layout: &layout,
                            entries: &[
                                wgpu::BindGroupEntry {
                                    binding: 0,
                                    resource: wgpu::BindingResource::TextureView(&src),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 1,
                                    resource: wgpu::BindingResource::Sampler(sampler),
                                },
                            ],
                        })
                    })
                    .clone();
                let mut rp = one_target(
                    encoder,
                    "mip",
                    &dst,
                    wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                );
                rp.set_pipeline(pipeline);
                rp.set_bind_group(0, &bg, &[]);
                rp.draw(0..3, 0..1);
            }
        }
        Ok(())
    }

    pub(super) fn encode_clear(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        c: &ClearOp,
        parity: usize,
    ) -> Result<(), EncodeError> {
        match c {
            ClearOp::Attachment {
                texture,
                format,
                base_mip,
                mips,
                base_layer,
                layers,
                value,
                stencil,
            } => {
                let spec = &self.plan.textures[*texture];
                for mip in *base_mip..base_mip + mips {
                    for layer in *base_layer..base_layer + layers {
                        let view = self.view(
                            *texture,
                            parity,
                            mip,
                            layer,
                            if format.has_depth_aspect() {
                                None
                            } else {
                                Some(*format)
                            },
                        );
                        let depth = format.has_depth_aspect();
                        let color = [Some(wgpu::RenderPassColorAttachment {
                            view: &view,
                            depth_slice: (spec.dimension == wgpu::TextureDimension::D3)
                                .then_some(layer),
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color {
                                    r: value[0],
                                    g: value[1],
                                    b: value[2],
                                    a: value[3],
                                }),
                                store: wgpu::StoreOp::Store,
                            },
                        })];
                        let _rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("clear"),
                            color_attachments: if depth { &[] } else { &color },
                            depth_stencil_attachment: depth.then(|| {
                                wgpu::RenderPassDepthStencilAttachment {
                                    view: &view,
                                    depth_ops: format.has_depth_aspect().then_some(
                                        wgpu::Operations {
                                            load: wgpu::LoadOp::Clear(value[0] as f32),
                                            store: wgpu::StoreOp::Store,
                                        },
                                    ),
                                    stencil_ops: format.has_stencil_aspect().then_some(
                                        wgpu::Operations {
                                            load: wgpu::LoadOp::Clear(*stencil),
                                            store: wgpu::StoreOp::Store,
                                        },
                                    ),
                                }
                            }),
                            timestamp_writes: None,
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                    }
                }
                Ok(())
            }
            ClearOp::Texture {
                texture,
                base_mip,
                mips,
                base_layer,
                layers,
                value,
            } => {
                if value.iter().any(|v| *v != 0.0) {
                    return Err(EncodeError::NonZeroTextureClear {
                        texture: self.plan.textures[*texture].name.clone(),
                    });
                }
                let spec = &self.plan.textures[*texture];
                encoder.clear_texture(
                    &self.textures[*texture][parity],
                    &wgpu::ImageSubresourceRange {
                        aspect: wgpu::TextureAspect::All,
                        base_mip_level: *base_mip,
                        mip_level_count: Some(*mips),
                        base_array_layer: *base_layer,
                        array_layer_count: (spec.dimension != wgpu::TextureDimension::D3)
                            .then_some(*layers),
                    },
                );
                Ok(())
            }
            ClearOp::Buffer { buffer, value } => {
                let b = &self.buffers[*buffer][parity];
                if *value == 0 {
                    encoder.clear_buffer(b, 0, None);
                } else {
                    let words = vec![*value; (b.size() / 4) as usize];
                    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                    let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("clear value"),
                        size: b.size(),
                        usage: wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: true,
                    });
                    staging
                        .slice(..)
                        .get_mapped_range_mut()
                        .map_err(EncodeError::Mapping)?
                        .copy_from_slice(&bytes);
                    staging.unmap();
                    encoder.copy_buffer_to_buffer(&staging, 0, b, 0, b.size());
                }
                Ok(())
            }
        }
    }
}

/// The buffer end of a buffer-texture copy.
struct BufferSide<'a> {
    buffer: &'a wgpu::Buffer,
    offset: u64,
    bytes_per_row: Option<u32>,
}

/// The texture end of a buffer-texture copy.
struct TextureSide<'a> {
    texture: &'a wgpu::Texture,
    spec: &'a TextureSpec,
    mip: u32,
    layer: u32,
    origin: [u32; 3],
}

/// One buffer-texture copy (`to_texture`, or back) of extent `e`. wgpu wants a buffer's rows
/// 256 bytes apart; Vulkan lets them lie closer (`bufferRowLength`), so such a copy goes one
/// block row at a time: a single row needs no row pitch, and its offset only the texel block's
/// alignment, which Vulkan demands too.
fn buffer_texture_copy(
    encoder: &mut wgpu::CommandEncoder,
    to_texture: bool,
    b: BufferSide<'_>,
    t: TextureSide<'_>,
    e: [u32; 3],
) {
    let mut copy = |buffer: wgpu::TexelCopyBufferInfo<'_>,
                    texture: wgpu::TexelCopyTextureInfo<'_>,
                    size: wgpu::Extent3d| {
        if to_texture {
            encoder.copy_buffer_to_texture(buffer, texture, size);
        } else {
            encoder.copy_texture_to_buffer(texture, buffer, size);
        }
    };
    // Vulkan copies a compressed mip smaller than a block (a 2x2 BC7 mip) with its own size;
    // wgpu takes whole blocks, which is what the mip holds.
    let (bw, bh) = t.spec.format.block_dimensions();
    let e = [e[0].max(1).next_multiple_of(bw), e[1].max(1), e[2]];
    let height = e[1].next_multiple_of(bh);
    let (rows, images) = (height.div_ceil(bh), e[2].max(1));
    let Some(pitch) = b
        .bytes_per_row
        .filter(|p| p % wgpu::COPY_BYTES_PER_ROW_ALIGNMENT != 0 && (rows > 1 || images > 1))
    else {
        // One row of blocks needs no row pitch, and wgpu refuses one it cannot align.
        let single = rows <= 1 && images <= 1;
        let mut layout = buffer_layout(b.buffer, b.offset, b.bytes_per_row, t.spec, e);
        if single {
            layout.layout.bytes_per_row = None;
            layout.layout.rows_per_image = None;
        }
        copy(
            layout,
            texel(t.texture, t.spec, t.mip, t.layer, t.origin),
            extent([e[0], height, e[2]]),
        );
        return;
    };
    let is_3d = t.spec.dimension == wgpu::TextureDimension::D3;
    for z in 0..images {
        for r in 0..rows {
            let row = u64::from(z) * u64::from(rows) + u64::from(r);
            let (layer, oz) = if is_3d {
                (t.layer, t.origin[2] + z)
            } else {
                (t.layer + z, t.origin[2])
            };
            copy(
                wgpu::TexelCopyBufferInfo {
                    buffer: b.buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: b.offset + row * u64::from(pitch),
                        bytes_per_row: None,
                        rows_per_image: None,
                    },
                },
                texel(
                    t.texture,
                    t.spec,
                    t.mip,
                    layer,
                    [t.origin[0], t.origin[1] + r * bh, oz],
                ),
                wgpu::Extent3d {
                    width: e[0],
                    height: bh,
                    depth_or_array_layers: 1,
                },
            );
        }
    }
}
