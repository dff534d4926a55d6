//! Passes at wgpu level, one function per pass kind: bindings resolved to plan indices (with
//! previous-frame reads of history resources), raster passes with their targets, state and
//! draws, compute passes with their dispatches, copies, clears, resolves, mip generation and
//! present.

use std::collections::BTreeMap;

use crate::plan::*;
use wgpu_types::{self as wgpu, Features};

use super::{LowerError, Lowering, PassError, formats, states};
use crate::capture::format::{self as cf, LoadOp, PassKind, ResourceKind, StoreOp};
use crate::capture::model::*;

/// (base mip, mips, base layer, layers) of a range; a volume has one layer.
fn range_of(r: &ResourceDesc, s: &Subresources) -> (u32, u32, u32, u32) {
    (
        s.mip_base,
        s.mip_count.max(1),
        s.layer_base,
        if r.kind == ResourceKind::Texture3D {
            1
        } else {
            s.layer_count.max(1)
        },
    )
}

fn params(p: &BTreeMap<String, cf::ParamValue>) -> Params {
    p.iter()
        .map(|(k, v)| {
            (
                k.clone(),
                match v {
                    cf::ParamValue::Scalar(x) => vec![*x],
                    cf::ParamValue::Vector(xs) => xs.clone(),
                },
            )
        })
        .collect()
}

pub(super) fn pass_error(p: &PassDesc, problem: PassError) -> LowerError {
    LowerError::Pass {
        pass: p.name.clone(),
        problem,
    }
}

impl<'c> Lowering<'c> {
    pub(super) fn pass(&mut self, p: &'c PassDesc) -> Result<(), LowerError> {
        // An imported frame's draws and dispatches run with their Vulkan pipelines (a render
        // pass without draws still loads, clears and stores its attachments, also in a frame
        // that binds no pipeline at all and so has no `vulkan` section).
        let imported = self.imported();
        let shader = self.shader(p);
        let bindings = if imported {
            Vec::new()
        } else {
            self.bindings(p)?
        };
        let op = match p.kind {
            PassKind::Raster if imported => self.vk_raster(p)?,
            PassKind::Compute if imported => self.vk_compute(p)?,
            PassKind::Raster => self.raster(p, shader.unwrap_or(0), bindings)?,
            PassKind::Compute => self.compute(p, shader.unwrap_or(0), bindings)?,
            PassKind::Copy => self.copies(p)?,
            PassKind::Blit => self.blits(p)?,
            PassKind::Clear => self.clears(p)?,
            PassKind::Resolve => {
                let (s, d) = p
                    .resolve
                    .ok_or_else(|| pass_error(p, PassError::NoResolve))?;
                PassOp::Resolve {
                    src: self.tex(p, s)?,
                    dst: self.tex(p, d)?,
                }
            }
            PassKind::GenerateMips => {
                let (r, range) = p
                    .generate_mips
                    .ok_or_else(|| pass_error(p, PassError::NoGenerateMips))?;
                PassOp::GenerateMips {
                    texture: self.tex(p, r)?,
                    base_layer: range.layer_base,
                    layers: range.layer_count.max(1),
                }
            }
            PassKind::Present => PassOp::Present {
                texture: self.tex(
                    p,
                    p.present
                        .ok_or_else(|| pass_error(p, PassError::NothingToPresent))?,
                )?,
            },
        };
        self.plan.passes.push(PassSpec {
            id: p.id,
            name: p.name.clone(),
            queue: p.queue,
            op,
        });
        Ok(())
    }

    pub(super) fn tex(&self, p: &PassDesc, r: ResourceId) -> Result<usize, LowerError> {
        self.texture_of.get(&r).copied().ok_or_else(|| {
            pass_error(
                p,
                PassError::NotCreated {
                    resource: self.capture.resource(r).name.clone(),
                },
            )
        })
    }

    /// An indirect-argument buffer and offset at plan level.
    pub(super) fn indirect(
        &self,
        p: &PassDesc,
        indirect: Option<(ResourceId, u64)>,
    ) -> Result<Option<(usize, u64)>, LowerError> {
        indirect
            .map(|(b, o)| self.buf(p, b).map(|i| (i, o)))
            .transpose()
    }

    /// A draw count's buffer at plan level; the pass then needs wgpu's
    /// `MULTI_DRAW_INDIRECT_COUNT`.
    pub(super) fn draw_count(
        &mut self,
        p: &'c PassDesc,
        count: Option<(ResourceId, u64, u32)>,
    ) -> Result<Option<(usize, u64, u32)>, LowerError> {
        let Some((b, offset, most)) = count else {
            return Ok(None);
        };
        *self.pass_features.entry(&p.name).or_default() |= Features::MULTI_DRAW_INDIRECT_COUNT;
        Ok(Some((self.buf(p, b)?, offset, most)))
    }

    pub(super) fn buf(&self, p: &PassDesc, r: ResourceId) -> Result<usize, LowerError> {
        self.buffer_of.get(&r).copied().ok_or_else(|| {
            pass_error(
                p,
                PassError::NotCreated {
                    resource: self.capture.resource(r).name.clone(),
                },
            )
        })
    }

    /// The plan index of the pass's shader, adding it on first use.
    fn shader(&mut self, p: &PassDesc) -> Option<usize> {
        let s = p.shader.as_ref()?;
        let next = self.plan.shaders.len();
        let i = *self.shader_index.entry(s.id).or_insert(next);
        if i == next {
            let shader = self.capture.shader(s.id);
            self.plan.shaders.push(ShaderSource {
                name: shader.path.display().to_string(),
                source: shader.source.to_string(),
                validated: shader.validated.clone(),
            });
        }
        Some(i)
    }

    /// Bindings validation found reading a history resource's previous-frame copy address the
    /// other half of its ping-pong pair.
    fn bindings(&self, p: &PassDesc) -> Result<Vec<Binding>, LowerError> {
        let mut bindings = Vec::new();
        for b in &p.bindings {
            let target = match &b.target {
                BindingTarget::Sampler(s) => BindTarget::Sampler(s.index()),
                BindingTarget::Resource {
                    resource,
                    view_format,
                    ..
                } => {
                    let r = self.capture.resource(*resource);
                    let range = b.range.unwrap_or_else(|| Subresources::whole(r));
                    let previous_frame = b.previous_frame;
                    if r.is_texture() {
                        let t = self.tex(p, *resource)?;
                        let format =
                            formats::view_format(self.plan.textures[t].format, *view_format)
                                .map_err(|e| pass_error(p, PassError::ViewFormat(e)))?;
                        let (base_mip, mips, base_layer, layers) = range_of(r, &range);
                        BindTarget::Texture {
                            texture: t,
                            format,
                            base_mip,
                            mips,
                            base_layer,
                            layers,
                            previous_frame,
                        }
                    } else {
                        let whole = range.byte_offset == 0 && range.byte_size == r.bytes;
                        BindTarget::Buffer {
                            buffer: self.buf(p, *resource)?,
                            offset: range.byte_offset,
                            size: (!whole).then_some(range.byte_size),
                            previous_frame,
                        }
                    }
                }
            };
            bindings.push(Binding {
                variable: b.variable.clone(),
                target,
            });
        }
        Ok(bindings)
    }

    fn raster(
        &mut self,
        p: &'c PassDesc,
        shader: usize,
        bindings: Vec<Binding>,
    ) -> Result<PassOp, LowerError> {
        let s = p
            .shader
            .as_ref()
            .ok_or_else(|| pass_error(p, PassError::NoShader))?;
        let color = self.color_targets(p)?;
        let depth = self.depth_target(p)?;
        let st = &p.state;
        let draws = p
            .draws
            .iter()
            .map(|d| {
                Ok(DrawOp {
                    label: d.label.clone(),
                    vertex: d.vertex.clone(),
                    fragment: d.fragment.clone(),
                    mesh: d.mesh.map(|m| m.index()),
                    count: d.count,
                    instances: d.instances,
                    first: d.first,
                    first_instance: d.first_instance,
                    base_vertex: d.base_vertex,
                    indirect: self.indirect(p, d.indirect)?,
                    draw_count: self.draw_count(p, d.draw_count)?,
                    stencil_reference: d.stencil_reference,
                    depth_only: d.depth_only,
                    params: params(&d.params),
                })
            })
            .collect::<Result<Vec<_>, LowerError>>()?;
        Ok(PassOp::Raster(RasterOp {
            shader,
            vertex: s.vertex.clone().unwrap_or_default(),
            fragment: s.fragment.clone(),
            bindings,
            params: params(&p.params),
            color,
            depth_stencil: depth.as_ref().map(|d| states::depth_stencil(st, d)),
            depth,
            primitive: states::primitive(st),
            stencil_reference: st.stencil.as_ref().map_or(0, |s| s.reference),
            draws,
        }))
    }

    /// Whether attachments stored with "don't care" are stored anyway: in a frame recorded
    /// from a Vulkan program, whose `VK_ATTACHMENT_STORE_OP_DONT_CARE` leaves the contents
    /// undefined, and whose drivers mostly keep them, which programs come to rely on (a
    /// post-processing layer sampling the depth a program discarded). wgpu's discard makes
    /// the next read see zeros, an image no driver of the program's showed.
    fn keeps_discarded(&self) -> bool {
        self.recorded_from_vulkan()
    }

    /// Whether the frame was recorded from a Vulkan program.
    fn recorded_from_vulkan(&self) -> bool {
        self.capture.origin.as_ref().is_some_and(|o| o.is_vulkan())
    }

    /// Whether the frame was imported from a Vulkan program: its pipelines are Vulkan's, or
    /// it says it was recorded from one (a frame that binds no pipeline has no `vulkan`
    /// section: Qt's `hellovulkanwindow` only clears).
    pub(super) fn imported(&self) -> bool {
        self.capture.vulkan.is_some() || self.recorded_from_vulkan()
    }

    pub(super) fn depth_target(&self, p: &PassDesc) -> Result<Option<DepthTarget>, LowerError> {
        let Some(d) = &p.depth_stencil else {
            return Ok(None);
        };
        let t = self.tex(p, d.resource)?;
        Ok(Some(DepthTarget {
            texture: t,
            format: self.plan.textures[t].format,
            mip: d.mip,
            layer: d.layer,
            depth_clear: (d.depth_load == LoadOp::Clear).then_some(d.depth_clear as f32),
            depth_store: d.depth_store == StoreOp::Store || self.keeps_discarded(),
            stencil_clear: (d.stencil_load == LoadOp::Clear).then_some(d.stencil_clear),
            stencil_store: d.stencil_store == StoreOp::Store || self.keeps_discarded(),
            read_only: d.read_only,
            stencil_read_only: d.stencil_read_only,
            sampled: false,
        }))
    }

    pub(super) fn color_targets(
        &mut self,
        p: &'c PassDesc,
    ) -> Result<Vec<ColorTarget>, LowerError> {
        let mut out = Vec::new();
        for c in &p.color_attachments {
            let t = self.tex(p, c.resource)?;
            if self.plan.textures[t].format == wgpu::TextureFormat::Rg11b10Ufloat {
                *self.pass_features.entry(&p.name).or_default() |=
                    Features::RG11B10UFLOAT_RENDERABLE;
            }
            out.push(ColorTarget {
                texture: t,
                format: formats::view_format(self.plan.textures[t].format, Some(c.format))
                    .map_err(|e| pass_error(p, PassError::ViewFormat(e)))?,
                mip: c.mip,
                layer: c.layer,
                load: (c.load == LoadOp::Clear).then_some(wgpu::Color {
                    r: c.clear[0],
                    g: c.clear[1],
                    b: c.clear[2],
                    a: c.clear[3],
                }),
                discard_load: c.load == LoadOp::Discard,
                store: c.store == StoreOp::Store || self.keeps_discarded(),
                blend: c.blend.as_ref().and_then(states::blend),
                write_mask: states::write_mask(c.write_mask.as_ref()),
            });
        }
        Ok(out)
    }

    fn compute(
        &self,
        p: &PassDesc,
        shader: usize,
        bindings: Vec<Binding>,
    ) -> Result<PassOp, LowerError> {
        let entry = p
            .shader
            .as_ref()
            .and_then(|s| s.compute.clone())
            .unwrap_or_default();
        let dispatches = p
            .dispatches
            .iter()
            .map(|d| {
                Ok(DispatchOp {
                    entry: d.entry.clone(),
                    groups: d.groups,
                    indirect: self.indirect(p, d.indirect)?,
                    params: params(&d.params),
                })
            })
            .collect::<Result<Vec<_>, LowerError>>()?;
        Ok(PassOp::Compute(ComputeOp {
            shader,
            entry,
            bindings,
            params: params(&p.params),
            dispatches,
        }))
    }

    fn copy_end(&self, p: &PassDesc, l: &CopyLocationDesc) -> Result<CopyEnd, LowerError> {
        Ok(if self.capture.resource(l.resource).is_texture() {
            CopyEnd::Texture {
                texture: self.tex(p, l.resource)?,
                mip: l.mip,
                layer: l.layer,
                origin: l.origin,
            }
        } else {
            CopyEnd::Buffer {
                buffer: self.buf(p, l.resource)?,
                offset: l.offset,
                bytes_per_row: l.bytes_per_row,
            }
        })
    }

    /// Refuses a copy whose two ends hold their bytes differently (`formats::Repack`): a copy
    /// moves the capture's bytes as they are, so a texture held rearranged may meet only one
    /// held the same way (a buffer holds the capture's bytes). A copy from a buffer into a
    /// texture held as RGBA8 for a 16-bit packed format is drawn instead, unpacking each
    /// texel: its layout is returned.
    fn copy_keeps_bytes(
        &self,
        p: &PassDesc,
        index: usize,
        src: &CopyEnd,
        dst: &CopyEnd,
    ) -> Result<Option<crate::plan::Packed16>, LowerError> {
        let held = |e: &CopyEnd| match e {
            CopyEnd::Texture { texture, .. } => self
                .repacked
                .get(texture)
                .map(|&(format, r)| (*texture, format, r)),
            CopyEnd::Buffer { .. } => None,
        };
        let (a, b) = (held(src), held(dst));
        if a.map(|h| h.2) == b.map(|h| h.2) {
            return Ok(None);
        }
        if let (CopyEnd::Buffer { .. }, None, Some((t, _, formats::Repack::Unpack16(layout)))) =
            (src, a, b)
            && self.plan.textures[t].dimension == wgpu::TextureDimension::D2
        {
            return Ok(Some(layout));
        }
        let Some((texture, format, repack)) = a.or(b) else {
            return Ok(None);
        };
        Err(pass_error(
            p,
            PassError::RepackedCopy {
                index,
                resource: self.plan.textures[texture].name.clone(),
                format,
                how: repack.describe(),
            },
        ))
    }

    fn copies(&self, p: &PassDesc) -> Result<PassOp, LowerError> {
        let mut copies = Vec::new();
        for c in &p.copies {
            let src_r = self.capture.resource(c.src.resource);
            let extent = c.extent.unwrap_or_else(|| {
                let tex_end = if src_r.is_texture() { &c.src } else { &c.dst };
                let r = self.capture.resource(tex_end.resource);
                let (w, h, d) = r.mip_extent(tex_end.mip);
                [
                    w.saturating_sub(tex_end.origin[0]),
                    h.saturating_sub(tex_end.origin[1]),
                    d.saturating_sub(tex_end.origin[2]).max(1),
                ]
            });
            let bytes = c
                .src
                .size
                .or(c.dst.size)
                .unwrap_or(src_r.bytes.saturating_sub(c.src.offset));
            let (src, dst) = (self.copy_end(p, &c.src)?, self.copy_end(p, &c.dst)?);
            let bytes = self.whole_words(c, &src, &dst, bytes);
            if let (CopyEnd::Buffer { offset: a, .. }, CopyEnd::Buffer { offset: b, .. }) =
                (&src, &dst)
                && (!a.is_multiple_of(4) || !b.is_multiple_of(4) || !bytes.is_multiple_of(4))
            {
                return Err(pass_error(
                    p,
                    PassError::UnalignedBufferCopy {
                        index: copies.len(),
                        src: self.capture.resource(c.src.resource).name.clone(),
                        dst: self.capture.resource(c.dst.resource).name.clone(),
                        src_offset: *a,
                        dst_offset: *b,
                        bytes,
                    },
                ));
            }
            // WebGPU copies no buffer into these depth formats: one without stencil (whose
            // aspect is then surely depth) is drawn, each texel's depth read from the buffer;
            // with stencil the copy may be the stencil's, which the capture does not say.
            let mut depth = false;
            if let (CopyEnd::Buffer { .. }, CopyEnd::Texture { texture, .. }) = (&src, &dst) {
                let t = &self.plan.textures[*texture];
                depth = matches!(
                    t.format,
                    wgpu::TextureFormat::Depth32Float | wgpu::TextureFormat::Depth24Plus
                ) && t.samples == 1
                    && t.dimension == wgpu::TextureDimension::D2;
                if !depth
                    && matches!(
                        t.format,
                        wgpu::TextureFormat::Depth32Float
                            | wgpu::TextureFormat::Depth32FloatStencil8
                            | wgpu::TextureFormat::Depth24Plus
                            | wgpu::TextureFormat::Depth24PlusStencil8
                    )
                {
                    return Err(pass_error(
                        p,
                        PassError::CopyIntoDepth {
                            index: copies.len(),
                            resource: t.name.clone(),
                            format: t.format,
                        },
                    ));
                }
            }
            let unpack = self.copy_keeps_bytes(p, copies.len(), &src, &dst)?;
            copies.push(CopyOp {
                src,
                dst,
                unpack,
                depth,
                extent,
                bytes,
            });
        }
        Ok(PassOp::Copy(copies))
    }

    /// The bytes a buffer copy moves on the GPU, in whole words where that changes nothing the
    /// frame holds: a copy from word-aligned offsets that ends at the end of the destination
    /// (a host write over a whole buffer of 39,198 bytes) runs on into the padding that rounds
    /// each replay buffer up to a whole word, which no Vulkan buffer has. Any other copy keeps
    /// its size.
    fn whole_words(&self, c: &CopyDesc, src: &CopyEnd, dst: &CopyEnd, bytes: u64) -> u64 {
        let (CopyEnd::Buffer { offset: a, .. }, CopyEnd::Buffer { offset: b, .. }) = (src, dst)
        else {
            return bytes;
        };
        let size = |r| self.capture.resource(r).bytes;
        let rounded = bytes.next_multiple_of(4);
        let ends_dst = b.checked_add(bytes) == Some(size(c.dst.resource));
        let fits_src = a
            .checked_add(rounded)
            .is_some_and(|end| end <= size(c.src.resource).next_multiple_of(4));
        if a.is_multiple_of(4) && b.is_multiple_of(4) && ends_dst && fits_src {
            rounded
        } else {
            bytes
        }
    }

    /// Blits, drawn by the replay: refused where a draw cannot do what the blit does (depth,
    /// stencil and integer formats, 1D textures, a destination wgpu cannot render to, linear
    /// filtering of a format wgpu does not filter).
    fn blits(&self, p: &PassDesc) -> Result<PassOp, LowerError> {
        let mut blits = Vec::new();
        for (index, b) in p.blits.iter().enumerate() {
            let refuse = |why: String| pass_error(p, PassError::Blit { index, why });
            let (src, dst) = (self.tex(p, b.src.resource)?, self.tex(p, b.dst.resource)?);
            for (side, t) in [(&b.src, src), (&b.dst, dst)] {
                let spec = &self.plan.textures[t];
                let r = self.capture.resource(side.resource);
                // Held as BC1 with alpha, it has alpha one only where a sampled view says so
                // (`formats::opaque_bc1`); the blit's draw reads the blocks as held.
                if r.format.is_some_and(|f| formats::opaque_bc1(f.name)) {
                    return Err(refuse(format!(
                        "\"{}\" is {}: a blit of BC1 without alpha is not replayed (held as BC1 with alpha, its blocks would give alpha 0 where Vulkan gives 1)",
                        r.name,
                        r.format.map_or("", |f| f.name)
                    )));
                }
                if spec.format.is_depth_stencil_format() {
                    return Err(refuse(format!(
                        "\"{}\" is {:?}: depth and stencil blits are not replayed (a draw writes no stencil, and depth only through the depth attachment)",
                        r.name, spec.format
                    )));
                }
                if matches!(
                    spec.format.sample_type(None, None),
                    Some(wgpu::TextureSampleType::Uint | wgpu::TextureSampleType::Sint)
                ) {
                    return Err(refuse(format!(
                        "\"{}\" is {:?}: integer-format blits are not replayed yet",
                        r.name, spec.format
                    )));
                }
                if spec.dimension != wgpu::TextureDimension::D2 {
                    return Err(refuse(format!(
                        "\"{}\" is not a 2D texture: wgpu renders only into 2D views",
                        r.name
                    )));
                }
            }
            // Drawn into RGBA8, a 16-bit packed destination would keep 8 bits a channel; a
            // three-channel one would take the source's alpha where it reads one.
            match self.repacked.get(&dst) {
                Some(&(format, formats::Repack::Unpack16(_))) => {
                    return Err(refuse(format!(
                        "the destination is {format}, held as RGBA8: a blit drawn into it would not keep its 4 to 6 bits a channel"
                    )));
                }
                Some(&(format, formats::Repack::Widen3 { .. })) => {
                    return Err(refuse(format!(
                        "the destination is {format}, held with a fourth channel of one: a blit drawn into it would write that channel"
                    )));
                }
                _ => {}
            }
            let (sf, df) = (
                self.plan.textures[src].format,
                self.plan.textures[dst].format,
            );
            if !df
                .guaranteed_format_features(Features::all())
                .allowed_usages
                .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
            {
                return Err(refuse(format!("{df:?} cannot be rendered to")));
            }
            if b.linear
                && sf.sample_type(None, None)
                    != Some(wgpu::TextureSampleType::Float { filterable: true })
            {
                return Err(refuse(format!(
                    "{sf:?} cannot be filtered linearly in wgpu"
                )));
            }
            blits.push(BlitOp {
                src,
                src_mip: b.src.mip,
                src_layer: b.src.layer,
                src_corners: b.src.corners,
                dst,
                dst_mip: b.dst.mip,
                dst_layer: b.dst.layer,
                dst_corners: b.dst.corners,
                linear: b.linear,
            });
        }
        Ok(PassOp::Blit(blits))
    }

    fn clears(&self, p: &PassDesc) -> Result<PassOp, LowerError> {
        let mut clears = Vec::new();
        for c in &p.clears {
            let r = self.capture.resource(c.resource);
            if !r.is_texture() {
                clears.push(ClearOp::Buffer {
                    buffer: self.buf(p, c.resource)?,
                    value: c.value[0] as u32,
                });
                continue;
            }
            let t = self.tex(p, c.resource)?;
            let (base_mip, mips, base_layer, layers) = range_of(r, &c.range);
            clears.push(if super::usage::clears_by_drawing(r) {
                ClearOp::Attachment {
                    texture: t,
                    format: self.plan.textures[t].format,
                    base_mip,
                    mips,
                    base_layer,
                    layers,
                    value: c.value,
                    stencil: c.stencil,
                }
            } else {
                ClearOp::Texture {
                    texture: t,
                    base_mip,
                    mips,
                    base_layer,
                    layers,
                    value: c.value,
                }
            });
        }
        Ok(PassOp::Clear(clears))
    }
}
