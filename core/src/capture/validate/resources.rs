//! Resources: resolved extents, formats, mips, flags and initial contents (their placement
//! in heaps is `placement`).

use std::collections::BTreeSet;

use super::{MSAA_PLACEMENT_ALIGNMENT, PLACEMENT_ALIGNMENT, Validator, is_depth_family};
use crate::capture::diag::JsonPath;
use crate::capture::dxgi::FormatInfo;
use crate::capture::format::{
    BufferKind, Extent, InitialContents, MipLevels, Placement, RelativeSize, Resource,
    ResourceFlag, ResourceKind,
};
use crate::capture::generators;
use crate::capture::generators::{Content, Seeded};
use crate::capture::model::{HeapDesc, InitialDesc, ResourceDesc, ResourceId};
use crate::capture::support::Support;
use crate::text::human_bytes;

/// Resolved dimensions of a resource (all 1 for buffers).
#[derive(Clone, Copy, Debug)]
pub(super) struct Dims {
    width: u32,
    height: u32,
    depth: u32,
    layers: u32,
    mips: u32,
    samples: u32,
}

/// Largest resource whose initial contents framelab generates in memory.
pub const MAX_GENERATED_BYTES: u64 = 1 << 30;

impl Dims {
    const ONE: Dims = Dims {
        width: 1,
        height: 1,
        depth: 1,
        layers: 1,
        mips: 1,
        samples: 1,
    };
}

impl<'a> Validator<'a> {
    pub(super) fn resolve_extent(
        &mut self,
        e: &Extent,
        output: u32,
        path: &JsonPath,
    ) -> Option<u32> {
        let out = f64::from(output);
        let (value, multiple) = match e {
            Extent::Texels(v) => {
                return match u32::try_from(*v) {
                    Ok(0) | Err(_) => {
                        self.diags.error(
                            "size",
                            path,
                            format!("size {v} must be between 1 and {}", u32::MAX),
                        );
                        None
                    }
                    Ok(v) => Some(v),
                };
            }
            Extent::Named(RelativeSize::Full) => (out, None),
            Extent::Named(RelativeSize::Half) => ((out / 2.0).ceil(), None),
            Extent::Named(RelativeSize::Quarter) => ((out / 4.0).ceil(), None),
            Extent::Scaled { scale, multiple_of } => {
                if !(scale.is_finite() && *scale > 0.0 && *scale <= 16.0) {
                    self.diags.error(
                        "size",
                        path,
                        format!("relative scale {scale} must be in (0, 16]"),
                    );
                    return None;
                }
                if *multiple_of == Some(0) {
                    self.diags.error(
                        "size",
                        &path.field("multiple_of"),
                        "multiple_of must be at least 1",
                    );
                    return None;
                }
                ((out * scale).ceil(), *multiple_of)
            }
        };
        let mut v = value.max(1.0) as u64;
        if let Some(m) = multiple {
            v = v.div_ceil(u64::from(m)) * u64::from(m);
        }
        u32::try_from(v).ok().or_else(|| {
            self.diags.error("size", path, "resolved size overflows");
            None
        })
    }

    pub(super) fn check_resources(&mut self, heaps: &[HeapDesc]) -> Option<Vec<ResourceDesc>> {
        let raw = self.raw;
        let mut out = Vec::new();
        let mut total: u64 = 0;
        let mut ok = true;
        for (i, r) in raw.resources.iter().enumerate() {
            let path = self.root.field("resources").index(i);
            match self.check_resource(i, r, &path, heaps) {
                Some(desc) => {
                    total = total.saturating_add(desc.bytes);
                    out.push(desc);
                }
                None => ok = false,
            }
        }
        let max = self.options.limits.max_total_bytes;
        if total > max {
            self.diags.error(
                "limit",
                &self.root.field("resources"),
                format!(
                    "resources declare {} in total, over the limit of {}; nothing was allocated",
                    human_bytes(total),
                    human_bytes(max)
                ),
            );
            ok = false;
        }
        ok.then_some(out)
    }

    pub(super) fn check_resource(
        &mut self,
        index: usize,
        r: &Resource,
        path: &JsonPath,
        heaps: &[HeapDesc],
    ) -> Option<ResourceDesc> {
        let errors_before = self.diags.error_count();
        let flags: BTreeSet<ResourceFlag> = r.flags.iter().copied().collect();
        let format = r
            .format
            .as_deref()
            .and_then(|f| self.lookup_format(f, &path.field("format")));
        let (dims, bytes) = if r.kind == ResourceKind::Buffer {
            (Dims::ONE, self.buffer_bytes(r, path, format, &flags))
        } else {
            self.texture_dims(r, path, format, &flags, errors_before)?
        };
        let samples = dims.samples;

        // The alignment the API reported (a Vulkan buffer's may be 64 bytes) is what the
        // resource is placed at and takes in memory; D3D12's when none was reported (or one
        // that is no power of two, which `check_placement` refuses).
        let alignment = match &r.placement {
            Some(Placement::Placed {
                alignment: Some(a), ..
            }) if a.is_power_of_two() => *a,
            _ if samples > 1 => MSAA_PLACEMENT_ALIGNMENT,
            _ => PLACEMENT_ALIGNMENT,
        };
        let placement = self.check_placement(r, path, heaps, bytes, alignment, samples, &flags);
        let aligned_bytes = bytes.div_ceil(alignment).saturating_mul(alignment);
        let initial = self.initial_contents(r, path, bytes);
        if r.history && r.output {
            self.diags.warning(
                "resource-flags",
                &path.field("output"),
                format!("\"{}\" is both history and output", r.name),
            );
        }
        if r.swapchain {
            self.check_swapchain_image(r, path);
        }
        if self.diags.error_count() > errors_before {
            return None;
        }
        Some(ResourceDesc {
            id: ResourceId(index as u32),
            name: r.name.clone(),
            kind: r.kind,
            format,
            width: dims.width,
            height: dims.height,
            depth: dims.depth,
            array_layers: dims.layers,
            mip_levels: dims.mips,
            samples,
            buffer_kind: (r.kind == ResourceKind::Buffer)
                .then(|| r.buffer_kind.unwrap_or(BufferKind::Raw)),
            stride: r.stride,
            bytes,
            aligned_bytes,
            alignment,
            flags,
            placement: placement?,
            initial,
            history: r.history,
            output: r.output,
            swapchain: r.swapchain,
        })
    }

    /// A buffer's size, kind, stride and flags; its byte size (0 when invalid).
    fn buffer_bytes(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        format: Option<&'static FormatInfo>,
        flags: &BTreeSet<ResourceFlag>,
    ) -> u64 {
        let limits = self.options.limits;
        let mut bytes: u64 = 0;
        for (field, present) in [
            ("width", r.width.is_some()),
            ("height", r.height.is_some()),
            ("depth", r.depth.is_some()),
            ("array_layers", r.array_layers.is_some()),
            ("mip_levels", r.mip_levels.is_some()),
            ("samples", r.samples.is_some()),
        ] {
            if present {
                self.diags.error(
                    "resource-kind",
                    &path.field(field),
                    format!("buffer \"{}\" cannot have `{field}`", r.name),
                );
            }
        }
        match r.size {
            None => self.diags.error(
                "resource-size",
                path,
                format!("buffer \"{}\" needs a `size` in bytes", r.name),
            ),
            Some(0) => self.diags.error(
                "resource-size",
                &path.field("size"),
                "buffer size must be non-zero",
            ),
            Some(s) if s > limits.max_buffer_bytes => self.diags.error(
                "limit",
                &path.field("size"),
                format!(
                    "buffer \"{}\" of {} exceeds the maximum buffer size {}",
                    r.name,
                    human_bytes(s),
                    human_bytes(limits.max_buffer_bytes)
                ),
            ),
            Some(s) => bytes = s,
        }
        let kind = r.buffer_kind.unwrap_or(BufferKind::Raw);
        match (kind, r.stride) {
            (BufferKind::Structured, None) => self.diags.error(
                "buffer-stride",
                path,
                format!("structured buffer \"{}\" needs a `stride`", r.name),
            ),
            (BufferKind::Structured, Some(0)) => self.diags.error(
                "buffer-stride",
                &path.field("stride"),
                "stride must be non-zero",
            ),
            (BufferKind::Structured, Some(s)) if !bytes.is_multiple_of(u64::from(s)) => {
                self.diags.error(
                    "buffer-stride",
                    &path.field("size"),
                    format!(
                        "structured buffer \"{}\": size {bytes} is not a multiple of stride {s}",
                        r.name
                    ),
                );
            }
            (BufferKind::ByteAddress, _) if !bytes.is_multiple_of(4) => self.diags.error(
                "buffer-stride",
                &path.field("size"),
                format!(
                    "byte-address buffer \"{}\": size {bytes} is not a multiple of 4",
                    r.name
                ),
            ),
            (BufferKind::Typed, _) if format.is_none() => self.diags.error(
                "buffer-format",
                path,
                format!("typed buffer \"{}\" needs a `format`", r.name),
            ),
            (_, Some(_)) if kind != BufferKind::Structured => self.diags.error(
                "buffer-stride",
                &path.field("stride"),
                format!(
                    "`stride` only applies to structured buffers (\"{}\" is {})",
                    r.name,
                    kind.name()
                ),
            ),
            _ => {}
        }
        for flag in [
            ResourceFlag::AllowRenderTarget,
            ResourceFlag::AllowDepthStencil,
        ] {
            if flags.contains(&flag) {
                self.diags.error(
                    "resource-flags",
                    &path.field("flags"),
                    format!("buffer \"{}\" cannot have {}", r.name, flag.name()),
                );
            }
        }
        bytes
    }

    /// A texture's dimensions, mips, samples and byte size, checked against its kind, the
    /// limits, its format and its flags; `None` when they cannot be sized.
    fn texture_dims(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        format: Option<&'static FormatInfo>,
        flags: &BTreeSet<ResourceFlag>,
        errors_before: usize,
    ) -> Option<(Dims, u64)> {
        if r.size.is_some() || r.stride.is_some() || r.buffer_kind.is_some() {
            self.diags.error(
                "resource-kind",
                path,
                format!(
                    "texture \"{}\" cannot have `size`, `stride` or `buffer_kind`",
                    r.name
                ),
            );
        }
        let Some(format) = format else {
            if r.format.is_none() {
                self.diags.error(
                    "resource-format",
                    path,
                    format!("texture \"{}\" needs a `format`", r.name),
                );
            }
            return None;
        };
        if format.is_video_or_palette() {
            self.diags.error("format-usage", &path.field("format"), format!(
                "{} is a video/palette format; framelab replays only colour, depth and block-compressed textures", format.name
            ));
        }
        let (width, height, depth, layers) = self.texture_extent(r, path)?;
        self.texture_limits(r, path, width, height, depth, layers);
        // D3D12 sizes block-compressed textures in whole blocks from the top mip down.
        if format.is_block_compressed()
            && (width % format.block_width != 0 || height % format.block_height != 0)
        {
            let at = if width % format.block_width != 0 {
                "width"
            } else {
                "height"
            };
            self.diags.error(
                "format-usage",
                &path.field(at),
                format!(
                    "\"{}\" is {}, a {}x{} block format, so its top mip must be a multiple of the block; it is {width}x{height}{}",
                    r.name,
                    format.name,
                    format.block_width,
                    format.block_height,
                    if matches!(r.width, Some(Extent::Texels(_))) { "" } else { " at this scale" }
                ),
            );
        }
        if self.diags.error_count() > errors_before {
            return None;
        }
        let (mips, samples) =
            self.texture_mips_samples(r, path, format, flags, (width, height, depth));
        self.texture_format_flags(r, path, format, flags);
        let dims = Dims {
            width,
            height,
            depth,
            layers,
            mips,
            samples,
        };
        let bytes = self.texture_bytes(r, path, format, dims)?;
        Some((dims, bytes))
    }

    /// Width, height, depth and layers as the kind allows them.
    fn texture_extent(&mut self, r: &Resource, path: &JsonPath) -> Option<(u32, u32, u32, u32)> {
        let width = match &r.width {
            Some(e) => self.resolve_extent(e, self.width, &path.field("width"))?,
            None => {
                self.diags.error(
                    "resource-size",
                    path,
                    format!("texture \"{}\" needs a `width`", r.name),
                );
                return None;
            }
        };
        let height = match (&r.height, r.kind) {
            (Some(e), ResourceKind::Texture1D) => {
                let h = self.resolve_extent(e, self.height, &path.field("height"))?;
                if h != 1 {
                    self.diags.error(
                        "resource-size",
                        &path.field("height"),
                        "a 1D texture has height 1",
                    );
                }
                1
            }
            (None, ResourceKind::Texture1D) => 1,
            (Some(e), _) => self.resolve_extent(e, self.height, &path.field("height"))?,
            (None, _) => {
                self.diags.error(
                    "resource-size",
                    path,
                    format!("texture \"{}\" needs a `height`", r.name),
                );
                return None;
            }
        };
        let mut depth = r.depth.unwrap_or(1);
        if r.kind == ResourceKind::Texture3D {
            if r.depth.is_none() || depth == 0 {
                self.diags.error(
                    "resource-size",
                    path,
                    format!("3D texture \"{}\" needs a non-zero `depth`", r.name),
                );
                return None;
            }
            if r.array_layers.is_some_and(|l| l != 1) {
                self.diags.error(
                    "resource-kind",
                    &path.field("array_layers"),
                    "3D textures have no array layers",
                );
            }
        } else if r.depth.is_some_and(|d| d != 1) {
            self.diags.error(
                "resource-kind",
                &path.field("depth"),
                format!(
                    "`depth` applies to 3D textures; \"{}\" is {}",
                    r.name,
                    r.kind.as_str()
                ),
            );
            depth = 1;
        }
        let mut layers = r
            .array_layers
            .unwrap_or(if r.kind == ResourceKind::TextureCube {
                6
            } else {
                1
            });
        if r.kind == ResourceKind::Texture3D {
            layers = 1;
        }
        if layers == 0 {
            self.diags.error(
                "resource-size",
                &path.field("array_layers"),
                "array_layers must be at least 1",
            );
            return None;
        }
        if r.kind == ResourceKind::TextureCube {
            if !layers.is_multiple_of(6) {
                self.diags.error("resource-size", &path.field("array_layers"), format!(
                    "cube texture \"{}\" has {layers} layers; a cube (array) needs a multiple of 6", r.name
                ));
            }
            if width != height {
                self.diags.error(
                    "resource-size",
                    &path.field("height"),
                    format!(
                        "cube texture \"{}\" faces must be square, not {width}x{height}",
                        r.name
                    ),
                );
            }
        }
        if matches!(r.kind, ResourceKind::Texture2D | ResourceKind::Texture1D) && layers != 1 {
            self.diags.error(
                "resource-kind",
                &path.field("array_layers"),
                format!(
                    "\"{}\" has {layers} layers; use kind texture_2d_array",
                    r.name
                ),
            );
        }
        Some((width, height, depth, layers))
    }

    /// Dimensions and layers against the limits, before any size arithmetic.
    fn texture_limits(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        width: u32,
        height: u32,
        depth: u32,
        layers: u32,
    ) {
        let limits = self.options.limits;
        let (max_dim, dim_name) = match r.kind {
            ResourceKind::Texture1D => (limits.max_texture_1d, "1D"),
            ResourceKind::Texture3D => (limits.max_texture_3d, "3D"),
            _ => (limits.max_texture_2d, "2D"),
        };
        for (field, v) in [("width", width), ("height", height), ("depth", depth)] {
            if v > max_dim {
                self.diags.error(
                    "limit",
                    &path.field(field),
                    format!(
                        "{dim_name} texture \"{}\" {field} {v} exceeds the limit {max_dim}",
                        r.name
                    ),
                );
            }
        }
        if layers > limits.max_array_layers {
            self.diags.error(
                "limit",
                &path.field("array_layers"),
                format!(
                    "texture \"{}\" has {layers} array layers, over the limit {}",
                    r.name, limits.max_array_layers
                ),
            );
        }
    }

    /// Mip levels (at most the full chain) and sample count with their restrictions.
    fn texture_mips_samples(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        format: &FormatInfo,
        flags: &BTreeSet<ResourceFlag>,
        (width, height, depth): (u32, u32, u32),
    ) -> (u32, u32) {
        let full_chain = 32 - width.max(height).max(depth).leading_zeros();
        let mips = match r.mip_levels {
            None => 1,
            Some(MipLevels::Chain(_)) => full_chain,
            Some(MipLevels::Count(0)) => {
                self.diags.error(
                    "resource-size",
                    &path.field("mip_levels"),
                    "mip_levels must be at least 1",
                );
                1
            }
            Some(MipLevels::Count(m)) if m > full_chain => {
                self.diags.error("resource-size", &path.field("mip_levels"), format!(
                    "texture \"{}\" is {width}x{height}x{depth}: at most {full_chain} mips, not {m}", r.name
                ));
                1
            }
            Some(MipLevels::Count(m)) => m,
        };
        let samples = r.samples.unwrap_or(1);
        if !matches!(samples, 1 | 2 | 4 | 8 | 16) {
            self.diags.error(
                "resource-samples",
                &path.field("samples"),
                format!("sample count {samples} must be 1, 2, 4, 8 or 16"),
            );
        }
        if samples > 1 {
            if !matches!(
                r.kind,
                ResourceKind::Texture2D | ResourceKind::Texture2DArray
            ) {
                self.diags.error(
                    "resource-samples",
                    &path.field("samples"),
                    "only 2D textures can be multisampled",
                );
            }
            if mips != 1 {
                self.diags.error(
                    "resource-samples",
                    &path.field("mip_levels"),
                    "multisampled textures have one mip",
                );
            }
            if flags.contains(&ResourceFlag::AllowUnorderedAccess) {
                self.diags.error(
                    "resource-flags",
                    &path.field("flags"),
                    "multisampled textures cannot be unordered-access",
                );
            }
        }
        if format.is_block_compressed()
            && (width % format.block_width != 0 || height % format.block_height != 0)
            && mips == 1
        {
            self.diags.error("format-usage", &path.field("width"), format!(
                "{} texture \"{}\" must be a multiple of 4 in width and height ({width}x{height})", format.name, r.name
            ));
        }
        (mips, samples)
    }

    /// The format against the flags: depth, render-target, unordered-access, sRGB.
    fn texture_format_flags(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        format: &FormatInfo,
        flags: &BTreeSet<ResourceFlag>,
    ) {
        let ds = flags.contains(&ResourceFlag::AllowDepthStencil);
        let rt = flags.contains(&ResourceFlag::AllowRenderTarget);
        let uav = flags.contains(&ResourceFlag::AllowUnorderedAccess);
        let depth_capable = format.is_depth_format() || is_depth_family(format);
        if ds && !depth_capable {
            self.diags.error(
                "format-usage",
                &path.field("flags"),
                format!(
                    "\"{}\" has ALLOW_DEPTH_STENCIL but {} is not a depth format",
                    r.name, format.name
                ),
            );
        }
        if ds && (rt || uav) {
            self.diags.error("resource-flags", &path.field("flags"), format!(
                "\"{}\": ALLOW_DEPTH_STENCIL cannot be combined with ALLOW_RENDER_TARGET or ALLOW_UNORDERED_ACCESS", r.name
            ));
        }
        if ds && r.kind == ResourceKind::Texture3D {
            self.diags.error(
                "resource-flags",
                &path.field("flags"),
                "3D textures cannot be depth-stencil",
            );
        }
        // Depth/stencil formats exist on 1D and 2D textures only; with ALLOW_DEPTH_STENCIL the
        // flag check above already refuses the 3D texture.
        if r.kind == ResourceKind::Texture3D && format.is_depth_only() && !ds {
            self.diags.error(
                "format-usage",
                &path.field("format"),
                format!(
                    "{} is a depth/stencil format, which D3D12 and Vulkan allow only on 1D and 2D textures (arrays and cubes included), not on 3D texture \"{}\"; give it a colour format (R32_FLOAT for depth values) or make it 2D",
                    format.name, r.name
                ),
            );
        }
        // The per-format support of D3D12, for what the depth, block-compressed and sRGB
        // checks here do not already say.
        let support = Support::of(format);
        let explained = format.is_depth_format()
            || format.is_block_compressed()
            || format.is_video_or_palette();
        for (flag, set, supported, what) in [
            (
                "ALLOW_RENDER_TARGET",
                rt,
                support.render_target,
                "a render target",
            ),
            (
                "ALLOW_UNORDERED_ACCESS",
                uav,
                support.typed_uav_store || format.srgb,
                "an unordered-access (typed store) format",
            ),
        ] {
            if set && !supported && !explained {
                self.diags.error(
                    "format-usage",
                    &path.field("flags"),
                    format!(
                        "\"{}\" has {flag} but {} cannot be {what} in D3D12 (no depth/stencil, shared-exponent, 1-bit, packed 4:2:2 or XR-bias format can); drop the flag or use a colour format",
                        r.name, format.name
                    ),
                );
            }
        }
        if format.is_depth_format() && (rt || uav) {
            self.diags.error(
                "format-usage",
                &path.field("flags"),
                format!(
                    "{} is a depth format: it cannot be a render target or unordered-access",
                    format.name
                ),
            );
        }
        if format.is_block_compressed() && (rt || uav || ds) {
            self.diags.error("format-usage", &path.field("flags"), format!(
                "{} is block-compressed: it cannot be a render target, depth-stencil or unordered-access", format.name
            ));
        }
        if format.srgb && uav {
            self.diags.error("format-usage", &path.field("flags"), format!(
                "{} is sRGB: unordered-access views cannot be sRGB; create it typeless or non-sRGB", format.name
            ));
        }
        if flags.contains(&ResourceFlag::DenyShaderResource) && !ds {
            self.diags.error(
                "resource-flags",
                &path.field("flags"),
                "DENY_SHADER_RESOURCE requires ALLOW_DEPTH_STENCIL",
            );
        }
    }

    /// Bytes of every mip, layer and sample, with overflow checks.
    fn texture_bytes(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        format: &FormatInfo,
        d: Dims,
    ) -> Option<u64> {
        let Dims {
            width,
            height,
            depth,
            layers,
            mips,
            samples,
        } = d;
        let depth = if r.kind == ResourceKind::Texture3D {
            depth
        } else {
            1
        };
        let sum = format.texture_bytes((width, height, depth), layers, mips, samples);
        if sum.is_none() {
            self.diags.error(
                "limit",
                path,
                format!("texture \"{}\" size overflows 64 bits", r.name),
            );
        }
        sum
    }

    /// The resource's initial contents: a side file of exactly its size, or a generator.
    fn initial_contents(&mut self, r: &Resource, path: &JsonPath, bytes: u64) -> InitialDesc {
        match &r.initial {
            None => InitialDesc::Undefined,
            Some(InitialContents::BeforeCapture {}) => {
                // An imported frame's resources whose earlier contents the capture does not
                // hold replay from zeros, as wgpu creates them; the import says which.
                if !self.not_replayable() && !self.vulkan() {
                    self.diags.error(
                        "initial",
                        &path.field("initial"),
                        "`before_capture` contents describe an imported capture; a replayed resource takes a `file` or a `generator`",
                    );
                }
                InitialDesc::BeforeCapture
            }
            Some(InitialContents::File { path: rel, offset }) => {
                let at = path.field("initial").field("file").field("path");
                match self.side_file(rel, &at) {
                    Some(p) => {
                        if let Ok(meta) = std::fs::metadata(&p) {
                            let file = path.field("initial").field("file");
                            self.check_side_file_size(
                                rel,
                                meta.len(),
                                (*offset, bytes),
                                &r.name,
                                &file,
                            );
                        }
                        InitialDesc::File(p, *offset)
                    }
                    None => InitialDesc::Undefined,
                }
            }
            Some(InitialContents::Generator { name, seed, params }) => {
                if bytes > MAX_GENERATED_BYTES {
                    self.diags.error(
                        "limit",
                        &path.field("initial").field("generator"),
                        format!(
                            "\"{}\" is {bytes} bytes at this scale; contents generated on the CPU are limited to {MAX_GENERATED_BYTES} bytes (1 GiB): give it a file or a smaller size",
                            r.name
                        ),
                    );
                    return InitialDesc::Undefined;
                }
                let known = self.check_generator_params(
                    generators::CONTENT_GENERATORS,
                    name,
                    params,
                    &path.field("initial").field("generator"),
                );
                match Content::new(name, params).filter(|_| known) {
                    Some(generator) => InitialDesc::Generator(Seeded {
                        generator,
                        seed: *seed,
                    }),
                    None => InitialDesc::Undefined,
                }
            }
        }
    }
}

impl Validator<'_> {
    /// A side file of `len` bytes holds a resource of `bytes`: exactly, or from `offset` on
    /// where the file holds others' contents too.
    fn check_side_file_size(
        &mut self,
        rel: &str,
        len: u64,
        (offset, bytes): (Option<u64>, u64),
        name: &str,
        file: &JsonPath,
    ) {
        match offset {
            None if len != bytes => self.diags.error(
                "side-file",
                &file.field("path"),
                format!("\"{rel}\" has {len} bytes; resource \"{name}\" needs exactly {bytes}"),
            ),
            Some(o) if o.checked_add(bytes).is_none_or(|end| end > len) => self.diags.error(
                "side-file",
                &file.field("offset"),
                format!(
                    "\"{rel}\" has {len} bytes; resource \"{name}\" needs {bytes} from byte {o}"
                ),
            ),
            _ => {}
        }
    }

    /// A swapchain image is a 2D texture the presentation engine owns: no other frame copy,
    /// no contents framelab makes for it (a presented image comes from the frame or before it).
    fn check_swapchain_image(&mut self, r: &Resource, path: &JsonPath) {
        let why = if !matches!(
            r.kind,
            ResourceKind::Texture2D | ResourceKind::Texture2DArray
        ) {
            Some("only a 2D texture (or 2D array) can be a swapchain image")
        } else if r.history {
            Some("a swapchain image cannot be history: the presentation engine owns it")
        } else if matches!(
            r.initial,
            Some(InitialContents::File { .. } | InitialContents::Generator { .. })
        ) {
            Some(
                "a swapchain image's contents come from the frame or from before it (`before_capture`), not a file or generator",
            )
        } else {
            None
        };
        if let Some(why) = why {
            self.diags.error(
                "resource-flags",
                &path.field("swapchain"),
                format!("\"{}\": {why}", r.name),
            );
        }
    }
}
