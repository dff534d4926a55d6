//! Textures and buffers at wgpu level: formats lowered by usage, and initial contents from
//! generators or side files. A texture no replayed pass uses is still created when it has
//! contents to look at; one whose format cannot be replayed is a note unless a pass needs it.

use crate::plan::*;
use wgpu_types as wgpu;

use super::{ContentsError, LowerError, Lowering, formats, generate};
use crate::capture::dxgi::FormatInfo;
use crate::capture::format::ResourceKind;
use crate::capture::model::*;

impl<'c> Lowering<'c> {
    pub(super) fn resource(&mut self, r: &'c ResourceDesc) -> Result<(), LowerError> {
        if r.is_texture() {
            self.texture(r)
        } else {
            self.buffer(r)
        }
    }

    fn texture(&mut self, r: &'c ResourceDesc) -> Result<(), LowerError> {
        let contents_err = |problem: ContentsError| LowerError::Contents {
            resource: r.name.clone(),
            problem,
        };
        let usage = self.usage.textures.get(&r.id).copied().or_else(|| {
            (r.initial != InitialDesc::Undefined)
                .then_some(wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST)
        });
        let Some(mut usage) = usage else {
            return Ok(());
        };
        // wgpu makes a multisampled texture only to render into, also one the frame never
        // draws to (a program's spare per-swapchain-image target).
        if r.samples > 1 {
            usage |= wgpu::TextureUsages::RENDER_ATTACHMENT;
        }
        let Some(info) = r.format else { return Ok(()) };
        let first_user = self.usage.first_user.get(&r.id).copied();
        let lowered = match formats::lower(
            info,
            self.usage.depth_bound.contains(&r.id),
            self.usage.first_view.get(&r.id).copied(),
            self.available,
        ) {
            Ok(l) => l,
            Err(reason) => {
                if let Some(pass) = first_user {
                    return Err(LowerError::Format {
                        resource: r.name.clone(),
                        format: info.name.to_owned(),
                        reason,
                        pass: pass.to_owned(),
                    });
                }
                self.notes.push(format!(
                    "\"{}\" ({}) is not replayed: {reason}",
                    r.name, info.name
                ));
                return Ok(());
            }
        };
        if let Some(n) = lowered.note {
            self.notes.push(format!("\"{}\": {n}", r.name));
        }
        if let Some(pass) = first_user {
            *self.pass_features.entry(pass).or_default() |= lowered.features;
        }
        let volume = r.kind == ResourceKind::Texture3D;
        let initial = match &r.initial {
            InitialDesc::Undefined | InitialDesc::BeforeCapture => None,
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
                    // A texture no replayed pass uses is only there to be looked at: say why
                    // it is missing instead of failing the replay.
                    Err(problem) if first_user.is_none() => {
                        self.notes
                            .push(format!("\"{}\" is not replayed: {problem}", r.name));
                        return Ok(());
                    }
                    Err(problem) => return Err(contents_err(problem)),
                }
            }
            // wgpu copies into no depth format but Depth16Unorm (and no stencil): an imported
            // frame's depth snapshot is drawn into the texture instead (the replay writes each
            // texel's depth from a float copy of the snapshot), which it must render to; its
            // stencil, which the snapshot's depth aspect does not hold, starts cleared, and a
            // multisampled one, which no draw writes sample by sample, is left out. Both said.
            InitialDesc::File(path, offset)
                if lowered.format.is_depth_stencil_format()
                    && lowered.format != wgpu::TextureFormat::Depth16Unorm
                    && self.imported() =>
            {
                if r.samples > 1 || volume {
                    self.notes.push(format!(
                        "\"{}\": its multisampled {:?} contents are not loaded (wgpu copies into no depth format and draws no sample apart); it starts cleared",
                        r.name, lowered.format
                    ));
                    None
                } else {
                    if lowered.format.has_stencil_aspect() {
                        self.notes.push(format!(
                            "\"{}\": its depth is drawn from the capture's snapshot; its stencil, which the snapshot does not hold, starts cleared",
                            r.name
                        ));
                    }
                    usage |= wgpu::TextureUsages::RENDER_ATTACHMENT;
                    match self.texels {
                        super::Texels::LeaveOut => None,
                        super::Texels::Load => {
                            Some(texture_file(r, info, (path, *offset)).map_err(contents_err)?)
                        }
                    }
                }
            }
            InitialDesc::File(..) if self.texels == super::Texels::LeaveOut => None,
            InitialDesc::File(path, offset) => {
                let mut mips = texture_file(r, info, (path, *offset)).map_err(contents_err)?;
                if let Some(repack) = lowered.repack {
                    mips.iter_mut().for_each(|m| repack.apply(m));
                }
                Some(mips)
            }
        };
        if let Some(repack) = lowered.repack {
            self.repacked
                .insert(self.plan.textures.len(), (info.name, repack));
        }

        self.texture_of.insert(r.id, self.plan.textures.len());
        self.plan.textures.push(TextureSpec {
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
            view_formats: Vec::new(),
            initial,
            history: r.history,
            cube: r.kind == ResourceKind::TextureCube,
        });
        Ok(())
    }

    fn buffer(&mut self, r: &'c ResourceDesc) -> Result<(), LowerError> {
        let Some(&usage) = self.usage.buffers.get(&r.id) else {
            return Ok(());
        };
        let initial = match &r.initial {
            InitialDesc::Undefined | InitialDesc::BeforeCapture => None,
            InitialDesc::Generator(contents) => Some(generate::buffer(contents, r.bytes)),
            InitialDesc::File(path, offset) => {
                Some(read_side_file((path, *offset), r.bytes).map_err(|problem| {
                    LowerError::Contents {
                        resource: r.name.clone(),
                        problem,
                    }
                })?)
            }
        };
        self.buffer_of.insert(r.id, self.plan.buffers.len());
        self.plan.buffers.push(BufferSpec {
            name: r.name.clone(),
            size: r.bytes,
            usage,
            initial,
            history: r.history,
        });
        Ok(())
    }
}

/// A side file of contents, of at most the `declared` bytes the capture gives it; or, from
/// `offset` in a file of many resources' contents, exactly those bytes.
fn read_side_file(
    (path, offset): (&std::path::Path, Option<u64>),
    declared: u64,
) -> Result<Vec<u8>, ContentsError> {
    let limit = crate::files::side_file(declared);
    match offset {
        None => crate::files::read(path, limit),
        Some(offset) => crate::files::read_range(path, offset, declared, limit),
    }
    .map_err(|e| match e {
        crate::files::FileError::Io { path, error } => ContentsError::Read { path, error },
        e => ContentsError::File(e),
    })
}

/// A texture's mips cut from its side file (every layer, or the volume, of a mip together).
fn texture_file(
    r: &ResourceDesc,
    info: &FormatInfo,
    (path, offset): (&std::path::Path, Option<u64>),
) -> Result<Vec<Vec<u8>>, ContentsError> {
    let volume = r.kind == ResourceKind::Texture3D;
    let mip_bytes = |m: u32| {
        let (w, h, d) = r.mip_extent(m);
        info.surface_bytes(u64::from(w), u64::from(h))
            .unwrap_or(0)
            .saturating_mul(u64::from(d))
            .saturating_mul(if volume { 1 } else { u64::from(r.array_layers) })
    };
    // Validation holds the file (or its range) to the resource's size; the mips are what is
    // cut from it.
    let declared = match offset {
        Some(_) => r.bytes,
        None => (0..r.mip_levels)
            .map(mip_bytes)
            .fold(0u64, u64::saturating_add)
            .max(r.bytes),
    };
    let bytes = read_side_file((path, offset), declared)?;
    let mut mips = Vec::new();
    let mut offset = 0usize;
    for m in 0..r.mip_levels {
        let size = usize::try_from(mip_bytes(m)).unwrap_or(usize::MAX);
        mips.push(
            bytes
                .get(offset..offset.saturating_add(size))
                .ok_or_else(|| ContentsError::ShortFile {
                    path: path.to_owned(),
                    needed: offset.saturating_add(size),
                    len: bytes.len(),
                })?
                .to_vec(),
        );
        offset += size;
    }
    Ok(mips)
}
