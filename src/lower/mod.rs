//! Lowering: a validated capture, in DAG order, becomes a `framelab_replay::plan::Plan`.
//! Usage flags come from every access, formats from `formats`, initial contents from side
//! files or generators, and each pass becomes the wgpu-level operation it describes. Reads of a
//! `history` resource before the frame writes it are marked as previous-frame reads.

pub mod formats;
pub mod frame;
pub mod generate;

use std::collections::{BTreeMap, BTreeSet};

use framelab_replay::plan::*;
use framelab_replay::wgpu::{self, Features};

use crate::capture::format::{self as cf, Access, LoadOp, PassKind, ResourceKind, StoreOp};
use crate::capture::model::*;

/// Device features requested when the adapter has them.
pub fn wanted_features() -> Features {
    Features::TIMESTAMP_QUERY
        | Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | Features::TIMESTAMP_QUERY_INSIDE_PASSES
        | Features::TEXTURE_COMPRESSION_BC
        | Features::DEPTH32FLOAT_STENCIL8
        | Features::TEXTURE_FORMAT_16BIT_NORM
        | Features::RG11B10UFLOAT_RENDERABLE
        | Features::FLOAT32_FILTERABLE
        | Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
}

#[derive(Debug, thiserror::Error)]
pub enum LowerError {
    #[error(
        "resource \"{resource}\" ({format}) cannot be replayed: {reason} (used by pass \"{pass}\")"
    )]
    Format {
        resource: String,
        format: String,
        reason: String,
        pass: String,
    },
    #[error("resource \"{resource}\": {message}")]
    Contents { resource: String, message: String },
    #[error("mesh \"{mesh}\": {message}")]
    Mesh { mesh: String, message: String },
    #[error("pass \"{pass}\": {message}")]
    Pass { pass: String, message: String },
    #[error("pass \"{pass}\" needs {feature}, which adapter {adapter} does not support")]
    MissingFeature {
        pass: String,
        feature: String,
        adapter: String,
    },
}

/// A lowered frame, with the plan index of each capture resource.
#[derive(Debug)]
pub struct Lowered {
    pub plan: Plan,
    pub texture_of: BTreeMap<ResourceId, usize>,
    pub buffer_of: BTreeMap<ResourceId, usize>,
    /// The capture pass of each plan pass.
    pub pass_ids: Vec<PassId>,
    pub notes: Vec<String>,
}

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

fn compare(c: cf::CompareFunction) -> wgpu::CompareFunction {
    use cf::CompareFunction as C;
    match c {
        C::Never => wgpu::CompareFunction::Never,
        C::Less => wgpu::CompareFunction::Less,
        C::Equal => wgpu::CompareFunction::Equal,
        C::LessEqual => wgpu::CompareFunction::LessEqual,
        C::Greater => wgpu::CompareFunction::Greater,
        C::NotEqual => wgpu::CompareFunction::NotEqual,
        C::GreaterEqual => wgpu::CompareFunction::GreaterEqual,
        C::Always => wgpu::CompareFunction::Always,
    }
}

fn stencil_op(o: cf::StencilOp) -> wgpu::StencilOperation {
    use cf::StencilOp as S;
    match o {
        S::Keep => wgpu::StencilOperation::Keep,
        S::Zero => wgpu::StencilOperation::Zero,
        S::Replace => wgpu::StencilOperation::Replace,
        S::Invert => wgpu::StencilOperation::Invert,
        S::IncrementClamp => wgpu::StencilOperation::IncrementClamp,
        S::DecrementClamp => wgpu::StencilOperation::DecrementClamp,
        S::IncrementWrap => wgpu::StencilOperation::IncrementWrap,
        S::DecrementWrap => wgpu::StencilOperation::DecrementWrap,
    }
}

fn blend(b: &cf::Blend) -> Option<wgpu::BlendState> {
    use cf::{BlendFactor as F, BlendOp as O, BlendPreset as P};
    let factor = |f: F| match f {
        F::Zero => wgpu::BlendFactor::Zero,
        F::One => wgpu::BlendFactor::One,
        F::Src => wgpu::BlendFactor::Src,
        F::OneMinusSrc => wgpu::BlendFactor::OneMinusSrc,
        F::SrcAlpha => wgpu::BlendFactor::SrcAlpha,
        F::OneMinusSrcAlpha => wgpu::BlendFactor::OneMinusSrcAlpha,
        F::Dst => wgpu::BlendFactor::Dst,
        F::OneMinusDst => wgpu::BlendFactor::OneMinusDst,
        F::DstAlpha => wgpu::BlendFactor::DstAlpha,
        F::OneMinusDstAlpha => wgpu::BlendFactor::OneMinusDstAlpha,
        F::Constant => wgpu::BlendFactor::Constant,
    };
    let op = |o: O| match o {
        O::Add => wgpu::BlendOperation::Add,
        O::Subtract => wgpu::BlendOperation::Subtract,
        O::ReverseSubtract => wgpu::BlendOperation::ReverseSubtract,
        O::Min => wgpu::BlendOperation::Min,
        O::Max => wgpu::BlendOperation::Max,
    };
    match b {
        cf::Blend::Preset(P::Opaque) => None,
        cf::Blend::Preset(P::Alpha) => Some(wgpu::BlendState::ALPHA_BLENDING),
        cf::Blend::Preset(P::PremultipliedAlpha) => {
            Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)
        }
        cf::Blend::Preset(P::Additive) => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::OVER,
        }),
        cf::Blend::Preset(P::Multiply) => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Dst,
                dst_factor: wgpu::BlendFactor::Zero,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::OVER,
        }),
        cf::Blend::Custom { color, alpha } => Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: factor(color.src),
                dst_factor: factor(color.dst),
                operation: op(color.op),
            },
            alpha: wgpu::BlendComponent {
                src_factor: factor(alpha.src),
                dst_factor: factor(alpha.dst),
                operation: op(alpha.op),
            },
        }),
    }
}

fn params(p: &BTreeMap<String, cf::ParamValue>) -> Params {
    p.iter()
        .map(|(k, v)| {
            let values = match v {
                cf::ParamValue::Scalar(x) => vec![*x],
                cf::ParamValue::Vector(xs) => xs.clone(),
            };
            (k.clone(), values)
        })
        .collect()
}

fn vertex_format(f: cf::VertexFormat) -> wgpu::VertexFormat {
    use cf::VertexFormat as V;
    match f {
        V::Snorm16x4 => wgpu::VertexFormat::Snorm16x4,
        V::Snorm16x2 => wgpu::VertexFormat::Snorm16x2,
        V::Unorm16x2 => wgpu::VertexFormat::Unorm16x2,
        V::Float16x2 => wgpu::VertexFormat::Float16x2,
        V::Float16x4 => wgpu::VertexFormat::Float16x4,
        // WebGPU fetches 10:10:10:2 only as unsigned normalised, so packed normals are stored
        // biased (n * 0.5 + 0.5) and shaders unpack them with `n * 2.0 - 1.0`.
        V::PackedSnorm10x3 => wgpu::VertexFormat::Unorm10_10_10_2,
        V::Unorm8x4 => wgpu::VertexFormat::Unorm8x4,
        V::Snorm8x4 => wgpu::VertexFormat::Snorm8x4,
        V::Uint8x4 => wgpu::VertexFormat::Uint8x4,
        V::Float32 => wgpu::VertexFormat::Float32,
        V::Float32x2 => wgpu::VertexFormat::Float32x2,
        V::Float32x3 => wgpu::VertexFormat::Float32x3,
        V::Float32x4 => wgpu::VertexFormat::Float32x4,
        V::Uint32 => wgpu::VertexFormat::Uint32,
        V::Uint32x2 => wgpu::VertexFormat::Uint32x2,
    }
}

/// Lowers `capture` with passes in `order`. `available`: the device's features.
pub fn lower(
    capture: &Capture,
    order: &[PassId],
    available: Features,
    adapter: &str,
) -> Result<Lowered, LowerError> {
    let passes: Vec<&PassDesc> = order.iter().map(|&p| capture.pass(p)).collect();
    // Usage, depth binding, first typed view and first user of every resource.
    let mut tex_usage: BTreeMap<ResourceId, wgpu::TextureUsages> = BTreeMap::new();
    let mut buf_usage: BTreeMap<ResourceId, wgpu::BufferUsages> = BTreeMap::new();
    let mut depth_bound: BTreeSet<ResourceId> = BTreeSet::new();
    let mut first_view: BTreeMap<ResourceId, &'static crate::capture::dxgi::FormatInfo> =
        BTreeMap::new();
    let mut first_user: BTreeMap<ResourceId, &str> = BTreeMap::new();
    for p in &passes {
        for a in &p.accesses {
            first_user.entry(a.resource).or_insert(&p.name);
            let r = capture.resource(a.resource);
            if r.is_texture() {
                let u = tex_usage
                    .entry(a.resource)
                    .or_insert(wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST);
                match a.access {
                    Access::Sampled => *u |= wgpu::TextureUsages::TEXTURE_BINDING,
                    Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite => {
                        *u |= wgpu::TextureUsages::STORAGE_BINDING
                    }
                    Access::ColorAttachment | Access::ResolveDst | Access::ResolveSrc => {
                        *u |= wgpu::TextureUsages::RENDER_ATTACHMENT
                    }
                    Access::DepthRead | Access::DepthWrite => {
                        *u |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                        depth_bound.insert(a.resource);
                    }
                    _ => {}
                }
            } else {
                let u = buf_usage
                    .entry(a.resource)
                    .or_insert(wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST);
                match a.access {
                    Access::Uniform => *u |= wgpu::BufferUsages::UNIFORM,
                    Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite => {
                        *u |= wgpu::BufferUsages::STORAGE
                    }
                    Access::IndirectArgs => *u |= wgpu::BufferUsages::INDIRECT,
                    _ => {}
                }
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
                first_view.entry(resource).or_insert(f);
            }
        }
        for c in &p.color_attachments {
            first_view.entry(c.resource).or_insert(c.format);
        }
        if p.generate_mips.is_some()
            && let Some((r, _)) = p.generate_mips
            && let Some(u) = tex_usage.get_mut(&r)
        {
            *u |= wgpu::TextureUsages::TEXTURE_BINDING;
        }
    }
    for r in &capture.resources {
        if r.has_flag(cf::ResourceFlag::AllowDepthStencil) {
            depth_bound.insert(r.id);
        }
    }

    let mut plan = Plan {
        textures: Vec::new(),
        buffers: Vec::new(),
        samplers: Vec::new(),
        meshes: Vec::new(),
        shaders: Vec::new(),
        passes: Vec::new(),
    };
    let mut texture_of = BTreeMap::new();
    let mut buffer_of = BTreeMap::new();
    let mut notes = Vec::new();
    let mut pass_features: BTreeMap<&str, Features> = BTreeMap::new();
    for r in &capture.resources {
        let contents_err = |message: String| LowerError::Contents {
            resource: r.name.clone(),
            message,
        };
        if r.is_texture() {
            // Textures no kept pass touches are still created when they have contents to show.
            let usage = tex_usage.get(&r.id).copied().or_else(|| {
                (r.initial != InitialDesc::Undefined)
                    .then_some(wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST)
            });
            let Some(usage) = usage else { continue };
            let Some(info) = r.format else { continue };
            let lowered = match formats::lower(
                info,
                depth_bound.contains(&r.id),
                first_view.get(&r.id).copied(),
                available,
            ) {
                Ok(l) => l,
                Err(reason) => {
                    if let Some(pass) = first_user.get(&r.id) {
                        return Err(LowerError::Format {
                            resource: r.name.clone(),
                            format: info.name.to_owned(),
                            reason: reason.to_owned(),
                            pass: (*pass).to_owned(),
                        });
                    }
                    notes.push(format!(
                        "\"{}\" ({}) is not replayed: {reason}",
                        r.name, info.name
                    ));
                    continue;
                }
            };
            if let Some(n) = lowered.note {
                notes.push(format!("\"{}\": {n}", r.name));
            }
            if let Some(pass) = first_user.get(&r.id) {
                *pass_features.entry(pass).or_default() |= lowered.features;
            }
            let volume = r.kind == ResourceKind::Texture3D;
            let initial = match &r.initial {
                InitialDesc::Undefined => None,
                InitialDesc::Generator(contents) => {
                    let generated = generate::texture(
                        contents,
                        lowered.format,
                        r.width,
                        r.height,
                        if volume { r.depth } else { r.array_layers },
                        volume,
                        r.mip_levels,
                    );
                    match generated {
                        Ok(mips) => Some(mips),
                        // A texture no replayed pass uses is only there to be looked at: say
                        // why it is missing instead of failing the replay.
                        Err(message) if !first_user.contains_key(&r.id) => {
                            notes.push(format!("\"{}\" is not replayed: {message}", r.name));
                            continue;
                        }
                        Err(message) => return Err(contents_err(message)),
                    }
                }
                InitialDesc::File(path) => {
                    let bytes = std::fs::read(path)
                        .map_err(|e| contents_err(format!("reading {}: {e}", path.display())))?;
                    let mut mips = Vec::new();
                    let mut offset = 0usize;
                    for m in 0..r.mip_levels {
                        let (w, h, d) = r.mip_extent(m);
                        let size = info.surface_bytes(u64::from(w), u64::from(h)).unwrap_or(0)
                            as usize
                            * d as usize
                            * if volume { 1 } else { r.array_layers as usize };
                        mips.push(
                            bytes
                                .get(offset..offset + size)
                                .ok_or_else(|| {
                                    contents_err("side file is shorter than the texture".into())
                                })?
                                .to_vec(),
                        );
                        offset += size;
                    }
                    Some(mips)
                }
            };
            texture_of.insert(r.id, plan.textures.len());
            plan.textures.push(TextureSpec {
                name: r.name.clone(),
                format: lowered.format,
                dimension: match r.kind {
                    ResourceKind::Texture1D => wgpu::TextureDimension::D1,
                    ResourceKind::Texture3D => wgpu::TextureDimension::D3,
                    _ => wgpu::TextureDimension::D2,
                },
                size: wgpu::Extent3d {
                    width: r.width,
                    height: r.height,
                    depth_or_array_layers: if volume { r.depth } else { r.array_layers },
                },
                mip_levels: r.mip_levels,
                samples: r.samples,
                usage,
                initial,
                history: r.history,
                cube: r.kind == ResourceKind::TextureCube,
            });
        } else {
            let Some(&usage) = buf_usage.get(&r.id) else {
                continue;
            };
            let initial = match &r.initial {
                InitialDesc::Undefined => None,
                InitialDesc::Generator(contents) => Some(generate::buffer(contents, r.bytes)),
                InitialDesc::File(path) => Some(
                    std::fs::read(path)
                        .map_err(|e| contents_err(format!("reading {}: {e}", path.display())))?,
                ),
            };
            buffer_of.insert(r.id, plan.buffers.len());
            plan.buffers.push(BufferSpec {
                name: r.name.clone(),
                size: r.bytes,
                usage,
                initial,
                history: r.history,
            });
        }
    }
    for s in &capture.samplers {
        let address = |a: cf::AddressMode| match a {
            cf::AddressMode::Wrap => wgpu::AddressMode::Repeat,
            cf::AddressMode::Clamp => wgpu::AddressMode::ClampToEdge,
            cf::AddressMode::Mirror => wgpu::AddressMode::MirrorRepeat,
            cf::AddressMode::Border => wgpu::AddressMode::ClampToBorder,
        };
        let filter = |f: cf::Filter| {
            if f == cf::Filter::Linear {
                wgpu::FilterMode::Linear
            } else {
                wgpu::FilterMode::Nearest
            }
        };
        plan.samplers.push(SamplerSpec {
            name: s.name.clone(),
            address: [
                address(s.address_u),
                address(s.address_v),
                address(s.address_w),
            ],
            mag: filter(s.mag_filter),
            min: filter(s.min_filter),
            mip: if s.mip_filter == cf::Filter::Linear {
                wgpu::MipmapFilterMode::Linear
            } else {
                wgpu::MipmapFilterMode::Nearest
            },
            lod: (s.lod_min, s.lod_max),
            compare: s.compare.map(compare),
            anisotropy: s.max_anisotropy,
        });
    }
    for m in &capture.meshes {
        plan.meshes.push(lower_mesh(m)?);
    }

    // Read-only bindings of history resources the frame has not written yet see the previous
    // frame's copy; written bindings always address this frame's.
    let mut written: BTreeSet<ResourceId> = BTreeSet::new();
    let mut shader_index: BTreeMap<crate::capture::shaders::ShaderId, usize> = BTreeMap::new();
    for p in &passes {
        let perr = |message: String| LowerError::Pass {
            pass: p.name.clone(),
            message,
        };
        let tex = |r: ResourceId| {
            texture_of
                .get(&r)
                .copied()
                .ok_or_else(|| perr(format!("\"{}\" was not created", capture.resource(r).name)))
        };
        let buf = |r: ResourceId| {
            buffer_of
                .get(&r)
                .copied()
                .ok_or_else(|| perr(format!("\"{}\" was not created", capture.resource(r).name)))
        };
        let shader = match &p.shader {
            Some(s) => {
                let next = plan.shaders.len();
                let i = *shader_index.entry(s.id).or_insert(next);
                if i == next {
                    let shader = capture.shader(s.id);
                    plan.shaders.push(ShaderSource {
                        name: shader.path.display().to_string(),
                        source: shader.source.to_string(),
                        validated: shader.validated.clone(),
                    });
                }
                Some(i)
            }
            None => None,
        };
        let mut bindings = Vec::new();
        for b in &p.bindings {
            let target = match &b.target {
                BindingTarget::Sampler(s) => BindTarget::Sampler(s.index()),
                BindingTarget::Resource {
                    resource,
                    view_format,
                    ..
                } => {
                    let r = capture.resource(*resource);
                    let range = b.range.unwrap_or_else(|| Subresources::whole(r));
                    let read_only = b.access.is_some_and(|a| !a.writes());
                    let previous_frame = r.history && read_only && !written.contains(resource);
                    if r.is_texture() {
                        let t = tex(*resource)?;
                        let format = formats::view_format(plan.textures[t].format, *view_format)
                            .map_err(|e| perr(e.to_owned()))?;
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
                            buffer: buf(*resource)?,
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
        let op = match p.kind {
            PassKind::Raster => {
                let s = p.shader.as_ref().ok_or_else(|| perr("no shader".into()))?;
                let color = p
                    .color_attachments
                    .iter()
                    .map(|c| {
                        let t = tex(c.resource)?;
                        if plan.textures[t].format == wgpu::TextureFormat::Rg11b10Ufloat {
                            *pass_features.entry(&p.name).or_default() |=
                                Features::RG11B10UFLOAT_RENDERABLE;
                        }
                        Ok(ColorTarget {
                            texture: t,
                            format: formats::view_format(plan.textures[t].format, Some(c.format))
                                .map_err(|e| perr(e.to_owned()))?,
                            mip: c.mip,
                            layer: c.layer,
                            load: (c.load == LoadOp::Clear).then_some(wgpu::Color {
                                r: c.clear[0],
                                g: c.clear[1],
                                b: c.clear[2],
                                a: c.clear[3],
                            }),
                            discard_load: c.load == LoadOp::Discard,
                            store: c.store == StoreOp::Store,
                            blend: c.blend.as_ref().and_then(blend),
                            write_mask: c.write_mask.as_ref().map_or(wgpu::ColorWrites::ALL, |m| {
                                let mut w = wgpu::ColorWrites::empty();
                                for (ch, bit) in [
                                    ('r', wgpu::ColorWrites::RED),
                                    ('g', wgpu::ColorWrites::GREEN),
                                    ('b', wgpu::ColorWrites::BLUE),
                                    ('a', wgpu::ColorWrites::ALPHA),
                                ] {
                                    if m.contains(ch) {
                                        w |= bit;
                                    }
                                }
                                w
                            }),
                        })
                    })
                    .collect::<Result<Vec<_>, LowerError>>()?;
                let depth = match &p.depth_stencil {
                    Some(d) => {
                        let t = tex(d.resource)?;
                        Some(DepthTarget {
                            texture: t,
                            format: plan.textures[t].format,
                            mip: d.mip,
                            layer: d.layer,
                            depth_clear: (d.depth_load == LoadOp::Clear)
                                .then_some(d.depth_clear as f32),
                            depth_store: d.depth_store == StoreOp::Store,
                            stencil_clear: (d.stencil_load == LoadOp::Clear)
                                .then_some(d.stencil_clear),
                            stencil_store: d.stencil_store == StoreOp::Store,
                            read_only: d.read_only,
                        })
                    }
                    None => None,
                };
                let st = &p.state;
                let depth_stencil = depth.as_ref().map(|d| {
                    let face = |f: &cf::StencilFace| wgpu::StencilFaceState {
                        compare: compare(f.compare),
                        fail_op: stencil_op(f.fail),
                        depth_fail_op: stencil_op(f.depth_fail),
                        pass_op: stencil_op(f.pass),
                    };
                    let stencil = st
                        .stencil
                        .as_ref()
                        .map_or(wgpu::StencilState::default(), |s| wgpu::StencilState {
                            front: face(&s.front),
                            back: face(&s.back),
                            read_mask: s.read_mask,
                            write_mask: s.write_mask,
                        });
                    wgpu::DepthStencilState {
                        format: d.format,
                        depth_write_enabled: Some(st.depth_write && !d.read_only),
                        depth_compare: Some(
                            st.depth_compare
                                .map_or(wgpu::CompareFunction::Always, compare),
                        ),
                        stencil,
                        bias: wgpu::DepthBiasState {
                            constant: st.depth_bias,
                            slope_scale: st.depth_bias_slope,
                            clamp: 0.0,
                        },
                    }
                });
                let primitive = wgpu::PrimitiveState {
                    topology: match st.topology {
                        cf::Topology::PointList => wgpu::PrimitiveTopology::PointList,
                        cf::Topology::LineList => wgpu::PrimitiveTopology::LineList,
                        cf::Topology::LineStrip => wgpu::PrimitiveTopology::LineStrip,
                        cf::Topology::TriangleList => wgpu::PrimitiveTopology::TriangleList,
                        cf::Topology::TriangleStrip => wgpu::PrimitiveTopology::TriangleStrip,
                    },
                    front_face: if st.front_face == cf::FrontFace::Ccw {
                        wgpu::FrontFace::Ccw
                    } else {
                        wgpu::FrontFace::Cw
                    },
                    cull_mode: match st.cull {
                        cf::CullMode::None => None,
                        cf::CullMode::Front => Some(wgpu::Face::Front),
                        cf::CullMode::Back => Some(wgpu::Face::Back),
                    },
                    ..Default::default()
                };
                let draws = p
                    .draws
                    .iter()
                    .map(|d| {
                        Ok(DrawOp {
                            label: d.label.clone(),
                            vertex: d.vertex.clone(),
                            mesh: d.mesh.map(|m| m.index()),
                            count: d.count,
                            instances: d.instances,
                            first: d.first,
                            first_instance: d.first_instance,
                            base_vertex: d.base_vertex,
                            indirect: d
                                .indirect
                                .map(|(b, o)| buf(b).map(|i| (i, o)))
                                .transpose()?,
                            stencil_reference: d.stencil_reference,
                            params: params(&d.params),
                        })
                    })
                    .collect::<Result<Vec<_>, LowerError>>()?;
                PassOp::Raster(RasterOp {
                    shader: shader.unwrap_or(0),
                    vertex: s.vertex.clone().unwrap_or_default(),
                    fragment: s.fragment.clone(),
                    bindings,
                    params: params(&p.params),
                    color,
                    depth,
                    primitive,
                    depth_stencil,
                    stencil_reference: st.stencil.as_ref().map_or(0, |s| s.reference),
                    draws,
                })
            }
            PassKind::Compute => {
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
                            indirect: d
                                .indirect
                                .map(|(b, o)| buf(b).map(|i| (i, o)))
                                .transpose()?,
                            params: params(&d.params),
                        })
                    })
                    .collect::<Result<Vec<_>, LowerError>>()?;
                PassOp::Compute(ComputeOp {
                    shader: shader.unwrap_or(0),
                    entry,
                    bindings,
                    params: params(&p.params),
                    dispatches,
                })
            }
            PassKind::Copy => {
                let mut copies = Vec::new();
                for c in &p.copies {
                    let src_r = capture.resource(c.src.resource);
                    let end = |l: &CopyLocationDesc| -> Result<CopyEnd, LowerError> {
                        let r = capture.resource(l.resource);
                        Ok(if r.is_texture() {
                            CopyEnd::Texture {
                                texture: tex(l.resource)?,
                                mip: l.mip,
                                layer: l.layer,
                                origin: l.origin,
                            }
                        } else {
                            CopyEnd::Buffer {
                                buffer: buf(l.resource)?,
                                offset: l.offset,
                                bytes_per_row: l.bytes_per_row,
                            }
                        })
                    };
                    let extent = c.extent.unwrap_or_else(|| {
                        let tex_end = if src_r.is_texture() { &c.src } else { &c.dst };
                        let r = capture.resource(tex_end.resource);
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
                    copies.push(CopyOp {
                        src: end(&c.src)?,
                        dst: end(&c.dst)?,
                        extent,
                        bytes,
                    });
                }
                PassOp::Copy(copies)
            }
            PassKind::Clear => {
                let mut clears = Vec::new();
                for c in &p.clears {
                    let r = capture.resource(c.resource);
                    if r.is_texture() {
                        let t = tex(c.resource)?;
                        let (base_mip, mips, base_layer, layers) = range_of(r, &c.range);
                        let attachment = r.has_flag(cf::ResourceFlag::AllowRenderTarget)
                            || r.has_flag(cf::ResourceFlag::AllowDepthStencil);
                        clears.push(if attachment {
                            ClearOp::Attachment {
                                texture: t,
                                format: plan.textures[t].format,
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
                    } else {
                        clears.push(ClearOp::Buffer {
                            buffer: buf(c.resource)?,
                            value: c.value[0] as u32,
                        });
                    }
                }
                PassOp::Clear(clears)
            }
            PassKind::Resolve => {
                let (s, d) = p.resolve.ok_or_else(|| perr("no resolve".into()))?;
                PassOp::Resolve {
                    src: tex(s)?,
                    dst: tex(d)?,
                }
            }
            PassKind::GenerateMips => {
                let (r, range) = p
                    .generate_mips
                    .ok_or_else(|| perr("no generate_mips".into()))?;
                PassOp::GenerateMips {
                    texture: tex(r)?,
                    base_layer: range.layer_base,
                    layers: range.layer_count.max(1),
                }
            }
            PassKind::Present => PassOp::Present {
                texture: tex(p.present.ok_or_else(|| perr("nothing to present".into()))?)?,
            },
        };
        written.extend(p.accesses.iter().filter(|a| a.writes).map(|a| a.resource));
        let queue = capture.queue(p.queue).name.clone();
        plan.passes.push(PassSpec {
            name: p.name.clone(),
            queue,
            op,
        });
    }
    for (pass, needed) in &pass_features {
        let missing = *needed - available;
        if !missing.is_empty() {
            return Err(LowerError::MissingFeature {
                pass: (*pass).to_owned(),
                feature: format!("{missing:?}"),
                adapter: adapter.to_owned(),
            });
        }
    }
    Ok(Lowered {
        plan,
        texture_of,
        buffer_of,
        pass_ids: order.to_vec(),
        notes,
    })
}

fn lower_mesh(m: &MeshDesc) -> Result<MeshSpec, LowerError> {
    let err = |message: String| LowerError::Mesh {
        mesh: m.name.clone(),
        message,
    };
    let instance_count = m.instance_count.unwrap_or(1);
    let stride = |s: &cf::VertexStream| {
        s.attributes
            .iter()
            .map(|a| u64::from(a.format.size()))
            .sum::<u64>()
    };
    let (stream_data, indices, vertex_count) = match &m.source {
        MeshSourceDesc::Generator(shape) => {
            let data = generate::mesh(shape);
            if data.positions.is_empty() {
                return Err(err("its generator produced no vertices".to_owned()));
            }
            let streams = generate::encode_streams(
                &data,
                &m.streams,
                instance_count,
                shape.seed,
                m.instances.as_ref(),
            );
            let indices = m.index_format.map(|f| {
                let bytes: Vec<u8> = match f {
                    cf::IndexFormat::Uint16 => data
                        .indices
                        .iter()
                        .flat_map(|&i| (i as u16).to_le_bytes())
                        .collect(),
                    cf::IndexFormat::Uint32 => {
                        data.indices.iter().flat_map(|&i| i.to_le_bytes()).collect()
                    }
                };
                (bytes, f, data.indices.len() as u32)
            });
            if m.index_format == Some(cf::IndexFormat::Uint16) && data.positions.len() > 65536 {
                return Err(err(format!(
                    "{} vertices do not fit 16-bit indices",
                    data.positions.len()
                )));
            }
            (streams, indices, data.positions.len() as u32)
        }
        MeshSourceDesc::File(path) => {
            let bytes =
                std::fs::read(path).map_err(|e| err(format!("reading {}: {e}", path.display())))?;
            let vertex_count = m.vertex_count.unwrap_or(0);
            let mut offset = 0usize;
            let mut streams = Vec::new();
            for s in &m.streams {
                let count = if s.step == cf::StepMode::Vertex {
                    u64::from(vertex_count)
                } else {
                    u64::from(instance_count)
                };
                let size = (stride(s) * count) as usize;
                streams.push(
                    bytes
                        .get(offset..offset + size)
                        .ok_or_else(|| err("side file too short".into()))?
                        .to_vec(),
                );
                offset += size;
            }
            let indices = m.index_format.map(|f| {
                let n = m.index_count.unwrap_or(0);
                (bytes.get(offset..).unwrap_or_default().to_vec(), f, n)
            });
            (streams, indices, vertex_count)
        }
    };
    let streams = m
        .streams
        .iter()
        .zip(stream_data)
        .map(|(s, data)| {
            let mut offset = 0u64;
            let attributes = s
                .attributes
                .iter()
                .map(|a| {
                    let at = (vertex_format(a.format), offset, a.location);
                    offset += u64::from(a.format.size());
                    at
                })
                .collect();
            StreamSpec {
                slot: s.slot,
                data,
                stride: stride(s),
                step: if s.step == cf::StepMode::Vertex {
                    wgpu::VertexStepMode::Vertex
                } else {
                    wgpu::VertexStepMode::Instance
                },
                attributes,
            }
        })
        .collect();
    Ok(MeshSpec {
        name: m.name.clone(),
        streams,
        indices: indices.map(|(b, f, n)| {
            (
                b,
                if f == cf::IndexFormat::Uint16 {
                    wgpu::IndexFormat::Uint16
                } else {
                    wgpu::IndexFormat::Uint32
                },
                n,
            )
        }),
        vertex_count,
        instance_count,
    })
}
