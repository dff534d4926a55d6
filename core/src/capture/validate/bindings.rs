//! Shader bindings: the view each one names (format, dimension, mips, layers, bytes) and
//! indirect arguments.

use super::{Validator, view_dimension_ok};
use crate::capture::diag::{Diagnostics, JsonPath};
use crate::capture::dxgi;
use crate::capture::dxgi::FormatInfo;
use crate::capture::format::{
    Access, Binding, BufferKind, IndirectArgs, Range, ResourceFlag, ResourceKind,
};
use crate::capture::model::{
    AccessSource, BindingDesc, BindingTarget, ResourceAccess, ResourceDesc, ResourceId, SamplerId,
    Subresources,
};
use crate::capture::support::Support;

/// Largest uniform (constant) buffer view.
pub const MAX_UNIFORM_BINDING_BYTES: u64 = 65_536;

impl<'a> Validator<'a> {
    pub(super) fn check_binding(
        &mut self,
        pass: &str,
        var: &str,
        b: &Binding,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Option<BindingDesc> {
        let valid_ident = !var.is_empty()
            && var.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !var.starts_with(|c: char| c.is_ascii_digit());
        if !valid_ident {
            self.diags.error(
                "binding",
                path,
                format!("\"{var}\" is not a WGSL identifier"),
            );
        }
        match (&b.resource, &b.sampler) {
            (Some(_), Some(_)) => {
                self.diags.error(
                    "binding",
                    path,
                    "a binding names a `resource` or a `sampler`, not both",
                );
                None
            }
            (None, None) => {
                self.diags.error(
                    "binding",
                    path,
                    "a binding needs a `resource` or a `sampler`",
                );
                None
            }
            (None, Some(s)) => {
                if b.access.is_some()
                    || b.mips.is_some()
                    || b.layers.is_some()
                    || b.format.is_some()
                    || b.bytes.is_some()
                {
                    self.diags.error(
                        "binding",
                        path,
                        "a sampler binding takes no access, range or format",
                    );
                }
                let id = self.lookup("sampler", s, &path.field("sampler"))?;
                Some(BindingDesc {
                    variable: var.to_owned(),
                    target: BindingTarget::Sampler(SamplerId(id)),
                    access: None,
                    range: None,
                    previous_frame: false,
                })
            }
            (Some(rname), None) => {
                let id = self.lookup("resource", rname, &path.field("resource"))?;
                let r = &resources?[id as usize];
                let Some(access) = b.access else {
                    self.diags.error("binding", path, format!(
                        "binding \"{var}\" of pass \"{pass}\" needs an `access` (sampled, storage_read, storage_write, storage_read_write or uniform)"
                    ));
                    return None;
                };
                if !self.check_binding_access(pass, r, access, path) {
                    return None;
                }
                let view_kind = b.dimension.unwrap_or(r.kind);
                if let Some(dim) = b.dimension
                    && !view_dimension_ok(r.kind, dim)
                {
                    self.diags.error(
                        "binding",
                        &path.field("dimension"),
                        format!(
                            "a {} view of {} \"{}\" is not allowed",
                            dim.as_str(),
                            r.kind.as_str(),
                            r.name
                        ),
                    );
                }
                let view_format = if r.is_texture() {
                    let f = self.view_format(r, b.format.as_deref(), &path.field("format"))?;
                    if access.is_unordered(r.is_texture()) && !Support::of(f).typed_uav_store {
                        self.diags.error(
                            "format-usage",
                            &path.field("access"),
                            format!(
                                "{} cannot be a storage texture (\"{}\" in pass \"{pass}\"): D3D12 has no typed unordered-access store for it (none for sRGB, depth/stencil, block-compressed, shared-exponent, 1-bit, packed 4:2:2 or XR-bias formats); bind a view of another format of its family",
                                f.name, r.name
                            ),
                        );
                    }
                    Some(f)
                } else {
                    if b.format.is_some() && r.buffer_kind != Some(BufferKind::Typed) {
                        self.diags.error(
                            "binding",
                            &path.field("format"),
                            "only typed buffers take a view format",
                        );
                    } else if r.buffer_kind == Some(BufferKind::Typed) {
                        self.typed_buffer_view(r, b.format.as_deref(), path);
                    }
                    None
                };
                let range = self.binding_range(r, access, b, path);
                accesses.push(ResourceAccess {
                    resource: r.id,
                    access,
                    range,
                    reads: access.reads(),
                    writes: access.writes(),
                    source: AccessSource::Binding(var.to_owned()),
                });
                Some(BindingDesc {
                    variable: var.to_owned(),
                    target: BindingTarget::Resource {
                        resource: r.id,
                        view_format,
                        view_kind,
                    },
                    access: Some(access),
                    range: Some(range),
                    previous_frame: r.history && !access.writes() && !self.written.contains(&r.id),
                })
            }
        }
    }

    /// The access against the resource's flags, kind and samples; `false` when it is not a
    /// shader binding access at all.
    fn check_binding_access(
        &mut self,
        pass: &str,
        r: &ResourceDesc,
        access: Access,
        path: &JsonPath,
    ) -> bool {
        if !access.is_shader_binding() {
            let home = match access {
                Access::ColorAttachment => "`color_attachments`",
                Access::DepthRead | Access::DepthWrite => "`depth_stencil`",
                Access::IndirectArgs => "a draw's or dispatch's `indirect`",
                Access::CopySrc | Access::CopyDst => "`copies`",
                Access::ResolveSrc | Access::ResolveDst => "`resolve`",
                Access::VertexBuffer | Access::IndexBuffer => "`meshes`",
                _ => "`present`",
            };
            self.diags.error(
                "binding-access",
                &path.field("access"),
                format!(
                    "{} is not a shader binding access; declare it in {home}",
                    access.as_str()
                ),
            );
            return false;
        }
        if access.is_unordered(r.is_texture()) && !r.has_flag(ResourceFlag::AllowUnorderedAccess) {
            self.diags.error("binding-flags", &path.field("access"), format!(
                "\"{}\" is bound for {} access in pass \"{pass}\" but lacks ALLOW_UNORDERED_ACCESS", r.name, access.as_str()
            ));
        }
        if access == Access::Sampled && r.has_flag(ResourceFlag::DenyShaderResource) {
            self.diags.error(
                "binding-flags",
                &path.field("access"),
                format!(
                    "\"{}\" has DENY_SHADER_RESOURCE and cannot be sampled",
                    r.name
                ),
            );
        }
        if access == Access::Uniform && r.is_texture() {
            self.diags.error(
                "binding-access",
                &path.field("access"),
                format!("texture \"{}\" cannot be a uniform buffer", r.name),
            );
        }
        if r.samples > 1 && access.is_unordered(r.is_texture()) {
            self.diags.error(
                "binding-access",
                &path.field("access"),
                "multisampled textures cannot be storage-bound",
            );
        }
        true
    }

    /// The subresources a binding views: mips and layers of a texture, bytes of a buffer.
    fn binding_range(
        &mut self,
        r: &ResourceDesc,
        access: Access,
        b: &Binding,
        path: &JsonPath,
    ) -> Subresources {
        if r.is_texture() {
            if b.bytes.is_some() {
                self.diags.error(
                    "binding",
                    &path.field("bytes"),
                    "`bytes` applies to buffers",
                );
            }
            if access.is_unordered(r.is_texture())
                && b.mips.is_none_or(|m| m.count != Some(1))
                && r.mip_levels > 1
            {
                self.diags.error("binding", &path.field("mips"), format!(
                    "a storage view of \"{}\" selects exactly one mip (`mips: {{\"base\": M, \"count\": 1}}`)", r.name
                ));
            }
            self.view_range(r, b.mips.as_ref(), b.layers.as_ref(), path)
        } else {
            if b.mips.is_some() || b.layers.is_some() {
                self.diags
                    .error("binding", path, "mip and layer ranges apply to textures");
            }
            let mut range = Subresources::whole(r);
            if let Some(bytes) = &b.bytes {
                if bytes.size == 0
                    || bytes
                        .offset
                        .checked_add(bytes.size)
                        .is_none_or(|e| e > r.bytes)
                {
                    self.diags.error(
                        "binding",
                        &path.field("bytes"),
                        format!(
                            "byte range {}+{} is outside buffer \"{}\" of {} bytes",
                            bytes.offset, bytes.size, r.name, r.bytes
                        ),
                    );
                }
                range.byte_offset = bytes.offset;
                range.byte_size = bytes.size;
            }
            if access == Access::Uniform
                && range.byte_size > MAX_UNIFORM_BINDING_BYTES
                && !self.vulkan()
            {
                let at = if b.bytes.is_some() {
                    path.field("bytes")
                } else {
                    path.clone()
                };
                self.diags.error(
                    "binding",
                    &at,
                    format!(
                        "a uniform binding views at most {MAX_UNIFORM_BINDING_BYTES} bytes (D3D12's 4096 constants, WebGPU's maxUniformBufferBindingSize); this one views {} of \"{}\": bind a `bytes` range or use a storage binding",
                        range.byte_size, r.name
                    ),
                );
            }
            range
        }
    }

    /// A typed buffer view, read or written, of any access: its format (the binding's, else
    /// the buffer's) must be a typed member of the buffer format's family, and one a buffer
    /// can hold (no depth/stencil, block-compressed or video format).
    fn typed_buffer_view(&mut self, r: &ResourceDesc, view: Option<&str>, path: &JsonPath) {
        let Some(resource_format) = r.format else {
            return;
        };
        let fpath = path.field("format");
        let f = match view {
            Some(view) => {
                let Some(f) = self.lookup_format(view, &fpath) else {
                    return;
                };
                if !dxgi::view_compatible(resource_format, f) {
                    self.diags.error("view-format", &fpath, format!(
                        "view format {} is not compatible with \"{}\" ({}); only typeless resources can be viewed in another format of their family",
                        f.name, r.name, resource_format.name
                    ));
                    return;
                }
                f
            }
            None => resource_format,
        };
        if f.is_typeless() {
            let typed = dxgi::all()
                .iter()
                .find(|t| {
                    t.typeless_family == Some(f.name) && !t.is_typeless() && !t.is_depth_stencil()
                })
                .map_or(String::new(), |t| format!(" (e.g. {})", t.name));
            self.diags.error(
                "typeless-view",
                if view.is_some() { &fpath } else { path },
                format!(
                    "typed view of buffer \"{}\" has the typeless format {}: typed buffer views (Buffer<T>, RWBuffer<T>, texel buffers) need a typed format; give the binding a `format` from its family{typed}",
                    r.name, f.name
                ),
            );
        } else if f.is_depth_stencil() || f.is_block_compressed() || f.is_video_or_palette() {
            self.diags.error(
                "format-usage",
                if view.is_some() { &fpath } else { path },
                format!(
                    "typed view of buffer \"{}\" has format {}: buffers hold no depth/stencil, block-compressed or video formats",
                    r.name, f.name
                ),
            );
        }
    }

    /// The format a view of `r` uses: the resource's, or a compatible reinterpretation.
    pub(super) fn view_format(
        &mut self,
        r: &ResourceDesc,
        view: Option<&str>,
        path: &JsonPath,
    ) -> Option<&'static FormatInfo> {
        let resource_format = r.format?;
        let Some(view) = view else {
            if resource_format.is_typeless() {
                self.diags.error(
                    "typeless-view",
                    path,
                    format!(
                        "\"{}\" is {}: a view needs a typed `format` from its family",
                        r.name, resource_format.name
                    ),
                );
                return None;
            }
            return Some(resource_format);
        };
        let f = self.lookup_format(view, path)?;
        // A Vulkan image made with VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT (or a swapchain's) is
        // viewed as its sRGB or linear twin without being typeless.
        let twins = |a: &FormatInfo, b: &FormatInfo| a.name.strip_suffix("_SRGB") == Some(b.name);
        let vulkan_twin = self.vulkan() && (twins(f, resource_format) || twins(resource_format, f));
        if !dxgi::view_compatible(resource_format, f) && !vulkan_twin {
            self.diags.error("view-format", path, format!(
                "view format {} is not compatible with \"{}\" ({}); only typeless resources can be viewed in another format of their family",
                f.name, r.name, resource_format.name
            ));
            return None;
        }
        Some(f)
    }

    pub(super) fn view_range(
        &mut self,
        r: &ResourceDesc,
        mips: Option<&Range>,
        layers: Option<&Range>,
        path: &JsonPath,
    ) -> Subresources {
        let mut range = Subresources::whole(r);
        let check = |diags: &mut Diagnostics,
                     field: &str,
                     given: Option<&Range>,
                     total: u32,
                     what: &str|
         -> (u32, u32) {
            let Some(g) = given else { return (0, total) };
            let count = g.count.unwrap_or(total.saturating_sub(g.base));
            if count == 0 || u64::from(g.base) + u64::from(count) > u64::from(total) {
                diags.error(
                    "subresource-range",
                    &path.field(field),
                    format!(
                        "{what} {}..{} of \"{}\" do not exist (it has {total})",
                        g.base,
                        u64::from(g.base) + u64::from(count),
                        r.name
                    ),
                );
                return (0, total);
            }
            (g.base, count)
        };
        let (mb, mc) = check(&mut self.diags, "mips", mips, r.mip_levels, "mips");
        let (lb, lc) = check(&mut self.diags, "layers", layers, r.array_layers, "layers");
        range.mip_base = mb;
        range.mip_count = mc;
        range.layer_base = lb;
        range.layer_count = lc;
        range
    }

    pub(super) fn single_subresource(
        &mut self,
        r: &ResourceDesc,
        mip: u32,
        layer: u32,
        path: &JsonPath,
    ) -> Subresources {
        let slices = if r.kind == ResourceKind::Texture3D {
            r.mip_extent(mip).2
        } else {
            r.array_layers
        };
        if mip >= r.mip_levels {
            self.diags.error(
                "subresource-range",
                &path.field("mip"),
                format!(
                    "\"{}\" has {} mips; mip {mip} does not exist",
                    r.name, r.mip_levels
                ),
            );
        }
        if layer >= slices {
            self.diags.error(
                "subresource-range",
                &path.field("layer"),
                format!(
                    "\"{}\" has {slices} layers/slices; layer {layer} does not exist",
                    r.name
                ),
            );
        }
        let mut range = Subresources::whole(r);
        range.mip_base = mip.min(r.mip_levels.saturating_sub(1));
        range.mip_count = 1;
        if r.kind != ResourceKind::Texture3D {
            range.layer_base = layer.min(r.array_layers.saturating_sub(1));
            range.layer_count = 1;
        }
        range
    }

    pub(super) fn check_indirect(
        &mut self,
        ind: &IndirectArgs,
        args_bytes: u64,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        source: AccessSource,
    ) -> Option<(ResourceId, u64)> {
        let id = self.lookup("resource", &ind.buffer, &path.field("buffer"))?;
        let r = &resources?[id as usize];
        if r.is_texture() {
            self.diags.error(
                "indirect",
                &path.field("buffer"),
                format!(
                    "indirect arguments must be in a buffer; \"{}\" is a texture",
                    r.name
                ),
            );
            return None;
        }
        if !ind.offset.is_multiple_of(4) {
            self.diags.error(
                "indirect",
                &path.field("offset"),
                "indirect argument offset must be a multiple of 4",
            );
        }
        if ind
            .offset
            .checked_add(args_bytes)
            .is_none_or(|e| e > r.bytes)
        {
            self.diags.error(
                "indirect",
                &path.field("offset"),
                format!(
                    "{args_bytes} bytes of arguments at offset {} overrun buffer \"{}\" ({} bytes)",
                    ind.offset, r.name, r.bytes
                ),
            );
        }
        let mut range = Subresources::whole(r);
        range.byte_offset = ind.offset;
        range.byte_size = args_bytes;
        accesses.push(ResourceAccess {
            resource: r.id,
            access: Access::IndirectArgs,
            range,
            reads: true,
            writes: false,
            source,
        });
        Some((r.id, ind.offset))
    }
}
