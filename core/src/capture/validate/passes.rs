//! Passes: kind, queue, shader entry points, attachments, draws, dispatches and accesses.

use super::Validator;
use crate::capture::diag::JsonPath;
use crate::capture::dxgi::FormatInfo;
use crate::capture::format::{
    Access, Blend, BlendPreset, LoadOp, ParamValue, Pass, PassKind, QueueType, RenderState,
    ResourceFlag, ResourceKind, StencilOp,
};
use crate::capture::formats;
use crate::capture::model::{
    AccessSource, ClearDesc, ColorAttachmentDesc, DepthStencilDesc, FenceId, HeapDesc, MeshDesc,
    PassDesc, PassId, QueueCapabilities, QueueId, ResourceAccess, ResourceDesc, ResourceId,
    ShaderDesc, Subresources,
};
use crate::capture::support::Support;

/// What the sections of a pass's check share besides the pass itself.
pub(super) struct PassContext<'c> {
    pub(super) caps: Option<QueueCapabilities>,
    pub(super) meshes: Option<&'c [MeshDesc]>,
    pub(super) state: RenderState,
}

/// Deepest marker nesting accepted (reports and the DOT emitter walk it).
pub const MAX_MARKER_DEPTH: usize = 64;
/// Most (access, subresource) pairs the analysis tracks: a small capture whose accesses each
/// span thousands of layers and mips would otherwise expand to gigabytes.
pub const MAX_SUBRESOURCE_USES: u64 = 1 << 22;

impl<'a> Validator<'a> {
    pub(super) fn check_passes(
        &mut self,
        resources: &Option<Vec<ResourceDesc>>,
        heaps: &[HeapDesc],
        meshes: &Option<Vec<MeshDesc>>,
    ) -> Option<Vec<PassDesc>> {
        let mut out = Vec::new();
        let mut ok = true;
        let mut uses: u64 = 0;
        for (i, p) in self.raw.passes.iter().enumerate() {
            let path = self.root.field("passes").index(i);
            if p.markers.len() > MAX_MARKER_DEPTH {
                self.diags.error(
                    "limit",
                    &path.field("markers"),
                    format!(
                        "{} nested markers is over the limit of {MAX_MARKER_DEPTH}",
                        p.markers.len()
                    ),
                );
                ok = false;
                continue;
            }
            // Markers are shown as a pass's path in tables, graphs and diffs.
            for (k, m) in p.markers.iter().enumerate() {
                if m.chars().any(char::is_control) {
                    self.diags.error(
                        "name",
                        &path.field("markers").index(k),
                        format!(
                            "marker \"{}\" holds a control character",
                            crate::text::one_line(m)
                        ),
                    );
                }
            }
            match self.check_pass(i, p, &path, resources.as_deref(), heaps, meshes.as_deref()) {
                Some(mut pass) => {
                    if let Some(id) = pass.shader.as_ref().map(|s| s.id) {
                        self.check_shader_use(p, id, &path);
                        let interface = self.shaders[id.index()].interface.clone();
                        self.cover_dispatches(
                            p,
                            &mut pass,
                            &interface,
                            resources.as_deref(),
                            &path,
                        );
                    }
                    // The analysis tracks every subresource each access touches.
                    uses += pass
                        .accesses
                        .iter()
                        .map(|a| {
                            u64::from(a.range.mip_count) * u64::from(a.range.layer_count.max(1))
                        })
                        .sum::<u64>();
                    self.written.extend(
                        pass.accesses
                            .iter()
                            .filter(|a| a.writes)
                            .map(|a| a.resource),
                    );
                    out.push(pass);
                }
                None => ok = false,
            }
        }
        if uses > MAX_SUBRESOURCE_USES {
            self.diags.error(
                "limit",
                &self.root.field("passes"),
                format!(
                    "the passes touch {uses} subresources in total (each access counts every mip and layer of its range), over the limit of {MAX_SUBRESOURCE_USES} the analysis tracks"
                ),
            );
            return None;
        }
        (ok && resources.is_some()).then_some(out)
    }

    /// Every attachment of a render pass has one sample count.
    fn check_sample_counts(
        &mut self,
        p: &Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &[ResourceAccess],
    ) {
        let Some(resources) = resources else { return };
        let mut seen: Vec<(String, u32)> = Vec::new();
        for a in accesses {
            if !matches!(
                a.source,
                AccessSource::ColorAttachment(_) | AccessSource::DepthStencil
            ) {
                continue;
            }
            if let Some(r) = resources.get(a.resource.index())
                && !seen.iter().any(|(n, _)| *n == r.name)
            {
                seen.push((r.name.clone(), r.samples));
            }
        }
        if seen.windows(2).any(|w| w[0].1 != w[1].1) {
            let list: Vec<String> = seen.iter().map(|(n, s)| format!("\"{n}\" {s}x")).collect();
            self.diags.error(
                "attachment",
                &path.field("color_attachments"),
                format!(
                    "the attachments of pass \"{}\" differ in sample count ({}): a render pass has one",
                    p.name,
                    list.join(", ")
                ),
            );
        }
    }

    pub(super) fn check_pass(
        &mut self,
        index: usize,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        heaps: &[HeapDesc],
        meshes: Option<&[MeshDesc]>,
    ) -> Option<PassDesc> {
        let errors_before = self.diags.error_count();
        let queue = self.lookup("queue", &p.queue, &path.field("queue"));
        let queue_type = queue.map(|q| self.raw.queues[q as usize].queue_type);
        let caps = queue_type.map(QueueCapabilities::of);
        let name = &p.name;

        self.check_pass_fields(p, path);
        if let (Some(caps), Some(qt)) = (caps, queue_type) {
            self.check_pass_queue(p, path, caps, qt);
        }
        let shader = self.pass_shader(p, path);

        let mut accesses: Vec<ResourceAccess> = Vec::new();
        let cx = PassContext {
            caps,
            meshes,
            state: p.state.clone().unwrap_or_default(),
        };

        // Bindings.
        let mut bindings = Vec::new();
        for (var, b) in &p.bindings {
            let bpath = path.field("bindings").field(var);
            if let Some(desc) = self.check_binding(name, var, b, &bpath, resources, &mut accesses) {
                bindings.push(desc);
            }
        }

        let (colors, attachment_size) = self.pass_colors(p, path, resources, &mut accesses);

        let (state, depth_stencil) =
            self.pass_depth_stencil(p, path, resources, &mut accesses, &cx, attachment_size);

        let draws = self.pass_draws(p, path, resources, &mut accesses, &cx);
        let attachment_clears = self.pass_attachment_clears(
            p,
            path,
            &colors,
            depth_stencil.as_ref(),
            attachment_size.map(|(w, h, _)| (w, h)),
        );
        self.check_feedback(p, path, resources, &accesses, &bindings);
        self.check_view_hazards(p, path, resources, &accesses, &bindings);
        self.check_sample_counts(p, path, resources, &accesses);

        let dispatches = self.pass_dispatches(p, path, resources, &mut accesses);

        // Copies.
        let mut copies = Vec::new();
        if p.kind == PassKind::Copy && p.copies.is_empty() {
            self.diags
                .error("copy", path, format!("copy pass \"{name}\" has no copies"));
        }
        for (i, c) in p.copies.iter().enumerate() {
            let cpath = path.field("copies").index(i);
            if let Some(copy) = self.check_copy(c, &cpath, resources, &mut accesses, i) {
                copies.push(copy);
            }
        }

        let clears = self.pass_clears(p, path, resources, &mut accesses, &cx);
        let blits = self.pass_blits(p, path, resources, &mut accesses);

        let resolve = self.pass_resolve(p, path, resources, &mut accesses);
        let generate_mips = self.pass_mips(p, path, resources, &mut accesses);

        let present = self.pass_present(p, path, resources, &mut accesses);

        // Parameters.
        for (key, value) in &p.params {
            if let ParamValue::Vector(v) = value
                && (v.is_empty() || v.len() > 16)
            {
                self.diags.error(
                    "parameter",
                    &path.field("params").field(key),
                    "vector parameters have 1..16 components",
                );
            }
        }

        // Recorded barriers.
        let mut barriers = Vec::new();
        for (i, b) in p.barriers.iter().enumerate() {
            let bpath = path.field("barriers").index(i);
            if let Some(desc) = self.check_barrier(b, &bpath, resources, heaps) {
                barriers.push(desc);
            }
        }

        // Fences.
        let signal: Vec<FenceId> = p
            .signal
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                self.lookup("fence", f, &path.field("signal").index(i))
                    .map(FenceId)
            })
            .collect();
        let wait: Vec<FenceId> = p
            .wait
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                self.lookup("fence", f, &path.field("wait").index(i))
                    .map(FenceId)
            })
            .collect();

        if self.diags.error_count() > errors_before || resources.is_none() {
            return None;
        }
        Some(PassDesc {
            id: PassId(index as u32),
            name: p.name.clone(),
            queue: QueueId(queue?),
            kind: p.kind,
            markers: p.markers.clone(),
            shader,
            bindings,
            color_attachments: colors,
            depth_stencil,
            state,
            draws,
            attachment_clears,
            dispatches,
            copies,
            clears,
            blits,
            resolve,
            generate_mips,
            present,
            params: p.params.clone(),
            barriers,
            signal,
            wait,
            recorded_gpu_ns: p.timing.as_ref().map(|t| t.gpu_ns),
            accesses,
        })
    }

    /// Fields that belong to another pass kind.
    fn check_pass_fields(&mut self, p: &Pass, path: &JsonPath) {
        let name = &p.name;
        let present_fields: [(&str, bool); 11] = [
            ("shader", p.shader.is_some()),
            ("color_attachments", !p.color_attachments.is_empty()),
            ("depth_stencil", p.depth_stencil.is_some()),
            ("state", p.state.is_some()),
            ("draws", !p.draws.is_empty()),
            ("dispatches", !p.dispatches.is_empty()),
            ("copies", !p.copies.is_empty()),
            ("clears", !p.clears.is_empty()),
            ("blits", !p.blits.is_empty()),
            ("resolve", p.resolve.is_some()),
            ("present", p.present.is_some()),
        ];
        let allowed: &[&str] = match p.kind {
            PassKind::Raster => &[
                "shader",
                "color_attachments",
                "depth_stencil",
                "state",
                "draws",
            ],
            PassKind::Compute => &["shader", "dispatches"],
            PassKind::Copy => &["copies"],
            PassKind::Blit => &["blits"],
            PassKind::Clear => &["clears"],
            PassKind::Resolve => &["resolve"],
            PassKind::GenerateMips => &[],
            PassKind::Present => &["present"],
        };
        for (field, present) in present_fields {
            if present && !allowed.contains(&field) {
                self.diags.error(
                    "pass-kind",
                    &path.field(field),
                    format!("{} pass \"{name}\" cannot have `{field}`", p.kind.as_str()),
                );
            }
        }
        if p.generate_mips.is_some() && p.kind != PassKind::GenerateMips {
            self.diags.error(
                "pass-kind",
                &path.field("generate_mips"),
                format!(
                    "{} pass \"{name}\" cannot have `generate_mips`",
                    p.kind.as_str()
                ),
            );
        }
        if !p.bindings.is_empty() && !matches!(p.kind, PassKind::Raster | PassKind::Compute) {
            self.diags.error(
                "pass-kind",
                &path.field("bindings"),
                format!(
                    "{} pass \"{name}\" has no shader to bind to",
                    p.kind.as_str()
                ),
            );
        }
    }

    /// What the pass kind needs from its queue (Vulkan's pipeline stage -> required queue
    /// capability table).
    fn check_pass_queue(
        &mut self,
        p: &Pass,
        path: &JsonPath,
        caps: QueueCapabilities,
        qt: QueueType,
    ) {
        let name = &p.name;
        let need = |graphics: bool, compute: bool| {
            (graphics && !caps.graphics) || (compute && !caps.compute)
        };
        let (bad, what) = match p.kind {
            PassKind::Raster => (
                need(true, false),
                "draws (vertex/fragment stages need a graphics queue)",
            ),
            PassKind::Compute => (
                need(false, true),
                "dispatches (the compute stage needs a compute or graphics queue)",
            ),
            PassKind::Resolve => (
                need(true, false),
                "resolves (ResolveSubresource runs on a graphics queue)",
            ),
            PassKind::Present => (
                need(true, false),
                "presents (only a graphics queue presents)",
            ),
            PassKind::Blit => (
                need(true, false),
                "blits (vkCmdBlitImage runs on a graphics queue)",
            ),
            PassKind::GenerateMips => (need(false, true), "mip generation (it runs shaders)"),
            PassKind::Clear => (false, ""),
            PassKind::Copy => (false, ""),
        };
        if bad {
            self.diags.error(
                "queue-capability",
                &path.field("queue"),
                format!(
                    "pass \"{name}\" {what}, but queue \"{}\" is a {} queue (can do: {})",
                    p.queue,
                    qt.name(),
                    caps.names().join(", ")
                ),
            );
        }
        let indirect = p.draws.iter().any(|d| d.indirect.is_some())
            || p.dispatches.iter().any(|d| d.indirect.is_some());
        if indirect && !caps.graphics && !caps.compute {
            self.diags.error("queue-capability", &path.field("queue"), format!(
                "pass \"{name}\" reads indirect arguments (DRAW_INDIRECT stage), which a copy queue cannot"
            ));
        }
    }

    /// The pass's shader: entry points its kind needs, the file read and reflected once.
    fn pass_shader(&mut self, p: &Pass, path: &JsonPath) -> Option<ShaderDesc> {
        let name = &p.name;
        let shader = p.shader.as_ref().and_then(|s| {
            let spath = path.field("shader");
            match p.kind {
                PassKind::Raster => {
                    if s.vertex.is_none() {
                        self.diags.error("shader", &spath, format!("raster pass \"{name}\" needs a `vertex` entry point"));
                    }
                    if s.fragment.is_none() && !p.color_attachments.is_empty() {
                        self.diags.error("shader", &spath, format!("raster pass \"{name}\" writes colour but has no `fragment` entry point"));
                    }
                    if s.compute.is_some() {
                        self.diags.error("shader", &spath.field("compute"), "a raster pass has no compute entry point");
                    }
                }
                PassKind::Compute => {
                    if s.vertex.is_some() || s.fragment.is_some() {
                        self.diags.error("shader", &spath, "a compute pass has only a `compute` entry point");
                    }
                    if s.compute.is_none() && p.dispatches.iter().any(|d| d.entry.is_none()) {
                        self.diags.error("shader", &spath, format!("compute pass \"{name}\" needs a `compute` entry point (or one per dispatch)"));
                    }
                }
                _ => {}
            }
            let file = self.side_file(&s.file, &spath.field("file"))?;
            let id = self.load_shader(&s.file, &file, &spath.field("file"))?;
            Some(ShaderDesc { id, vertex: s.vertex.clone(), fragment: s.fragment.clone(), compute: s.compute.clone() })
        });
        if matches!(p.kind, PassKind::Raster | PassKind::Compute)
            && p.shader.is_none()
            && !self.not_replayable()
            && !self.vulkan()
        {
            self.diags.error(
                "shader",
                path,
                format!("{} pass \"{name}\" needs a `shader`", p.kind.as_str()),
            );
        }
        shader
    }

    fn pass_colors(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> (Vec<ColorAttachmentDesc>, Option<(u32, u32, &'a str)>) {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let mut colors = Vec::new();
        for (i, a) in p.color_attachments.iter().enumerate() {
            let apath = path.field("color_attachments").index(i);
            let Some(id) = self.lookup("resource", &a.resource, &apath.field("resource")) else {
                continue;
            };
            let Some(r) = res(id) else { continue };
            let Some(format) = self.view_format(r, a.format.as_deref(), &apath.field("format"))
            else {
                continue;
            };
            if !r.has_flag(ResourceFlag::AllowRenderTarget) {
                self.diags.error("binding-flags", &apath.field("resource"), format!(
                    "\"{}\" is a colour attachment of pass \"{name}\" but lacks ALLOW_RENDER_TARGET", r.name
                ));
            }
            let support = Support::of(format);
            if format.is_typeless() || !support.render_target {
                self.diags.error(
                    "format-usage",
                    &apath,
                    format!(
                        "{} cannot be a colour attachment (\"{}\" in pass \"{name}\"): {}",
                        format.name,
                        r.name,
                        if format.is_typeless() {
                            "a render-target view needs a typed format; give the attachment a `format` from its family"
                        } else {
                            "D3D12 has no render-target support for it"
                        }
                    ),
                );
            } else if let Some(why) = formats::not_renderable(format) {
                self.diags.error(
                    "format-usage",
                    &apath,
                    format!(
                        "{} cannot be a colour attachment (\"{}\" in pass \"{name}\"): {why}",
                        format.name, r.name
                    ),
                );
            }
            if a.blend
                .as_ref()
                .is_some_and(|b| !matches!(b, Blend::Preset(BlendPreset::Opaque)))
                && support.render_target
                && !support.blend
            {
                self.diags.error(
                    "format-usage",
                    &apath.field("blend"),
                    format!("{} cannot blend (D3D12 blends no integer format); make the attachment opaque", format.name),
                );
            }
            if let Some(mask) = &a.write_mask
                && (mask.is_empty() || !mask.chars().all(|c| "rgba".contains(c)))
            {
                self.diags.error(
                    "attachment",
                    &apath.field("write_mask"),
                    format!("write_mask \"{mask}\" must be letters from \"rgba\""),
                );
            }
            let range = self.single_subresource(r, a.mip, a.layer, &apath);
            accesses.push(ResourceAccess {
                resource: r.id,
                access: Access::ColorAttachment,
                range,
                reads: a.load == LoadOp::Load,
                writes: true,
                source: AccessSource::ColorAttachment(i),
            });
            colors.push(ColorAttachmentDesc {
                resource: r.id,
                mip: a.mip,
                layer: a.layer,
                format,
                load: a.load,
                store: a.store,
                clear: a.clear,
                blend: a.blend.clone(),
                write_mask: a.write_mask.clone(),
            });
        }
        let mut attachment_size: Option<(u32, u32, &str)> = None;
        for c in &colors {
            if let Some(r) = res(c.resource.0) {
                let (w, h, _) = r.mip_extent(c.mip);
                match attachment_size {
                    None => attachment_size = Some((w, h, &self.raw.resources[r.id.index()].name)),
                    Some((aw, ah, first)) if (aw, ah) != (w, h) => self.diags.error("attachment", &path.field("color_attachments"), format!(
                        "attachments of pass \"{name}\" differ in size: \"{first}\" is {aw}x{ah}, \"{}\" is {w}x{h}", r.name
                    )),
                    _ => {}
                }
            }
        }

        (colors, attachment_size)
    }

    fn pass_depth_stencil(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        cx: &PassContext<'_>,
        attachment_size: Option<(u32, u32, &'a str)>,
    ) -> (RenderState, Option<DepthStencilDesc>) {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let state = cx.state.clone();
        let depth_stencil = p.depth_stencil.as_ref().and_then(|d| {
            let dpath = path.field("depth_stencil");
            let id = self.lookup("resource", &d.resource, &dpath.field("resource"))?;
            let r = res(id)?;
            let format = self.view_format(r, d.format.as_deref(), &dpath.field("format"))?;
            if !format.is_depth_format() {
                self.diags.error("format-usage", &dpath, format!(
                    "{} is not a depth format and cannot be the depth-stencil attachment (\"{}\" in pass \"{name}\")",
                    format.name, r.name
                ));
            }
            if !r.has_flag(ResourceFlag::AllowDepthStencil) {
                self.diags.error("binding-flags", &dpath.field("resource"), format!(
                    "\"{}\" is the depth-stencil attachment of pass \"{name}\" but lacks ALLOW_DEPTH_STENCIL", r.name
                ));
            }
            if state.stencil.is_some() && format.stencil_bits == 0 {
                self.diags.error("format-usage", &path.field("state").field("stencil"), format!(
                    "pass \"{name}\" uses stencil but {} has no stencil aspect", format.name
                ));
            }
            if let Some((aw, ah, first)) = attachment_size {
                let (w, h, _) = r.mip_extent(d.mip);
                if (aw, ah) != (w, h) {
                    self.diags.error("attachment", &dpath, format!(
                        "depth \"{}\" is {w}x{h} but colour attachment \"{first}\" is {aw}x{ah}", r.name
                    ));
                }
            }
            // Both APIs clear depth within [0, 1] (D3D12's ClearDepthStencilView, Vulkan
            // without VK_EXT_depth_range_unrestricted); so does wgpu.
            if d.depth_load == LoadOp::Clear && !(0.0..=1.0).contains(&d.depth_clear) {
                self.diags.error("attachment", &dpath.field("depth_clear"), format!(
                    "pass \"{name}\" clears depth to {}, outside [0, 1]", d.depth_clear
                ));
            }
            if d.read_only && state.depth_write {
                self.diags.error("attachment", &dpath.field("read_only"), format!(
                    "pass \"{name}\" binds depth read-only but its state has depth_write"
                ));
            }
            let stencil_writes = state.stencil.as_ref().is_some_and(|s| {
                s.write_mask != 0 && [&s.front, &s.back].iter().any(|f| {
                    [f.pass, f.fail, f.depth_fail].iter().any(|op| *op != StencilOp::Keep)
                })
            });
            // In a Vulkan render pass the store operation is itself a write access (STORE and
            // DONT_CARE both write the attachment), so an attachment in a writable layout is
            // written whatever the draws do; FL009 says when its draws never write it.
            let writes = !(d.read_only && d.stencil_read_only.unwrap_or(d.read_only)) && (state.depth_write || stencil_writes || d.depth_load == LoadOp::Clear || d.stencil_load == LoadOp::Clear || self.vulkan());
            let range = self.single_subresource(r, d.mip, d.layer, &dpath);
            accesses.push(ResourceAccess {
                resource: r.id,
                access: if writes { Access::DepthWrite } else { Access::DepthRead },
                range,
                // A format without stencil has no stencil contents to load.
                reads: d.depth_load == LoadOp::Load
                    || (format.stencil_bits > 0 && d.stencil_load == LoadOp::Load),
                writes,
                source: AccessSource::DepthStencil,
            });
            Some(DepthStencilDesc {
                resource: r.id,
                mip: d.mip,
                layer: d.layer,
                format,
                depth_load: d.depth_load,
                depth_store: d.depth_store,
                depth_clear: d.depth_clear,
                stencil_load: d.stencil_load,
                stencil_store: d.stencil_store,
                stencil_clear: d.stencil_clear,
                read_only: d.read_only,
                stencil_read_only: d.stencil_read_only.unwrap_or(d.read_only),
            })
        });
        if p.kind == PassKind::Raster {
            if p.color_attachments.is_empty() && p.depth_stencil.is_none() {
                self.diags.error(
                    "attachment",
                    path,
                    format!("raster pass \"{name}\" has no colour or depth attachment"),
                );
            }
            if (state.depth_compare.is_some() || state.depth_write || state.stencil.is_some())
                && p.depth_stencil.is_none()
            {
                self.diags.error("attachment", &path.field("state"), format!(
                    "pass \"{name}\" tests or writes depth/stencil but has no depth_stencil attachment"
                ));
            }
            if p.color_attachments.len() > 8 {
                self.diags.error(
                    "attachment",
                    &path.field("color_attachments"),
                    "at most 8 colour attachments",
                );
            }
            // An application's render pass may only clear (its load operations are the work).
            if p.draws.is_empty() && !self.vulkan() {
                self.diags.warning(
                    "no-draws",
                    &path.field("draws"),
                    format!("raster pass \"{name}\" issues no draws"),
                );
            }
        }

        (state, depth_stencil)
    }

    fn pass_clears(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        cx: &PassContext<'_>,
    ) -> Vec<ClearDesc> {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let mut clears = Vec::new();
        if p.kind == PassKind::Clear && p.clears.is_empty() {
            self.diags.error(
                "clear",
                path,
                format!("clear pass \"{name}\" has no clears"),
            );
        }
        for (i, c) in p.clears.iter().enumerate() {
            let cpath = path.field("clears").index(i);
            let Some(id) = self.lookup("resource", &c.resource, &cpath.field("resource")) else {
                continue;
            };
            let Some(r) = res(id) else { continue };
            let range = self.view_range(r, c.mips.as_ref(), c.layers.as_ref(), &cpath);
            // A clear goes through a typed view (RTV, DSV or UAV), and a clear names none.
            if let Some(f) = r.format
                && f.is_typeless()
                && !self.vulkan()
            {
                self.diags.error(
                    "clear",
                    &cpath.field("resource"),
                    format!(
                        "\"{}\" is {}: a clear needs a typed view, which a clear pass cannot name; clear it through a raster pass's attachment with a `format`",
                        r.name, f.name
                    ),
                );
            }
            let access = if self.vulkan() {
                // vkCmdClear*Image and vkCmdFillBuffer are transfer writes on any queue.
                Access::CopyDst
            } else if r.has_flag(ResourceFlag::AllowDepthStencil) {
                Access::DepthWrite
            } else if r.has_flag(ResourceFlag::AllowRenderTarget) {
                Access::ColorAttachment
            } else if r.has_flag(ResourceFlag::AllowUnorderedAccess) {
                Access::StorageWrite
            } else {
                self.diags.error("binding-flags", &cpath.field("resource"), format!(
                    "\"{}\" cannot be cleared: it has none of ALLOW_RENDER_TARGET, ALLOW_DEPTH_STENCIL, ALLOW_UNORDERED_ACCESS", r.name
                ));
                continue;
            };
            if let (Some(caps), true) = (
                cx.caps,
                !matches!(access, Access::StorageWrite | Access::CopyDst),
            ) && !caps.graphics
            {
                self.diags.error("queue-capability", &path.field("queue"), format!(
                        "clearing render target or depth \"{}\" needs a graphics queue; queue \"{}\" is not one", r.name, p.queue
                    ));
            }
            if let (Some(caps), Access::StorageWrite) = (cx.caps, access)
                && !caps.compute
            {
                self.diags.error("queue-capability", &path.field("queue"), format!(
                        "clearing unordered-access \"{}\" needs a compute or graphics queue; queue \"{}\" is a copy queue", r.name, p.queue
                    ));
            }
            accesses.push(ResourceAccess {
                resource: r.id,
                access,
                range,
                reads: false,
                writes: true,
                source: AccessSource::Clear(i),
            });
            clears.push(ClearDesc {
                resource: r.id,
                value: c.value,
                stencil: c.stencil,
                range,
            });
        }

        clears
    }

    fn pass_resolve(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Option<(ResourceId, ResourceId)> {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let resolve = p.resolve.as_ref().and_then(|rs| {
            let rpath = path.field("resolve");
            let src = self.lookup("resource", &rs.src, &rpath.field("src"));
            let dst = self.lookup("resource", &rs.dst, &rpath.field("dst"));
            let (src, dst) = (res(src?)?, res(dst?)?);
            if src.samples <= 1 {
                self.diags.error(
                    "resolve",
                    &rpath.field("src"),
                    format!("resolve source \"{}\" is not multisampled", src.name),
                );
            }
            if dst.samples != 1 {
                self.diags.error(
                    "resolve",
                    &rpath.field("dst"),
                    format!("resolve destination \"{}\" must have one sample", dst.name),
                );
            }
            if (src.width, src.height) != (dst.width, dst.height) {
                self.diags.error(
                    "resolve",
                    &rpath,
                    format!(
                        "resolve from {}x{} to {}x{}: sizes must match",
                        src.width, src.height, dst.width, dst.height
                    ),
                );
            }
            if let (Some(a), Some(b)) = (src.format, dst.format) {
                let family = |f: &'static FormatInfo| f.typeless_family.unwrap_or(f.name);
                if family(a) != family(b) {
                    self.diags.error(
                        "resolve",
                        &rpath,
                        format!("cannot resolve {} into {}", a.name, b.name),
                    );
                }
            }
            accesses.push(ResourceAccess {
                resource: src.id,
                access: Access::ResolveSrc,
                range: Subresources::whole(src),
                reads: true,
                writes: false,
                source: AccessSource::Resolve,
            });
            accesses.push(ResourceAccess {
                resource: dst.id,
                access: Access::ResolveDst,
                range: Subresources::whole(dst),
                reads: false,
                writes: true,
                source: AccessSource::Resolve,
            });
            Some((src.id, dst.id))
        });
        if p.kind == PassKind::Resolve && p.resolve.is_none() {
            self.diags.error(
                "resolve",
                path,
                format!("resolve pass \"{name}\" needs `resolve`"),
            );
        }

        resolve
    }

    fn pass_mips(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Option<(ResourceId, Subresources)> {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let generate_mips = p.generate_mips.as_ref().and_then(|g| {
            let gpath = path.field("generate_mips");
            let r = res(self.lookup("resource", &g.resource, &gpath.field("resource"))?)?;
            if r.mip_levels < 2 {
                self.diags.error(
                    "generate-mips",
                    &gpath.field("resource"),
                    format!("\"{}\" has one mip: nothing to generate", r.name),
                );
                return None;
            }
            if !r.has_flag(ResourceFlag::AllowRenderTarget) {
                self.diags.error(
                    "binding-flags",
                    &gpath.field("resource"),
                    format!(
                        "mip generation renders into \"{}\", which lacks ALLOW_RENDER_TARGET",
                        r.name
                    ),
                );
            }
            let range = self.view_range(r, None, g.layers.as_ref(), &gpath);
            let mut read = range;
            read.mip_count = r.mip_levels - 1;
            let mut write = range;
            write.mip_base = 1;
            write.mip_count = r.mip_levels - 1;
            accesses.push(ResourceAccess {
                resource: r.id,
                access: Access::Sampled,
                range: read,
                reads: true,
                writes: false,
                source: AccessSource::GenerateMips,
            });
            accesses.push(ResourceAccess {
                resource: r.id,
                access: Access::ColorAttachment,
                range: write,
                reads: false,
                writes: true,
                source: AccessSource::GenerateMips,
            });
            Some((r.id, range))
        });
        if p.kind == PassKind::GenerateMips && p.generate_mips.is_none() {
            self.diags.error(
                "generate-mips",
                path,
                format!("mip generation pass \"{name}\" needs `generate_mips`"),
            );
        }

        generate_mips
    }

    fn pass_present(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Option<ResourceId> {
        let name = &p.name;
        let res = |id: u32| resources.map(|r| &r[id as usize]);
        let present = p.present.as_ref().and_then(|name_| {
            let ppath = path.field("present");
            let r = res(self.lookup("resource", name_, &ppath)?)?;
            if !matches!(r.kind, ResourceKind::Texture2D) {
                self.diags.error(
                    "present",
                    &ppath,
                    format!(
                        "only a 2D texture can be presented; \"{}\" is {}",
                        r.name,
                        r.kind.as_str()
                    ),
                );
            }
            accesses.push(ResourceAccess {
                resource: r.id,
                access: Access::Present,
                range: Subresources::whole(r),
                reads: true,
                writes: false,
                source: AccessSource::Present,
            });
            Some(r.id)
        });
        if p.kind == PassKind::Present && p.present.is_none() {
            self.diags.error(
                "present",
                path,
                format!("present pass \"{name}\" needs `present`"),
            );
        }

        present
    }
}
