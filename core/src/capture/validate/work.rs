//! The work a pass records: draws (meshes, counts, instances, indirect arguments, stencil
//! references) and dispatches (group counts against the limits, indirect arguments, the
//! texture a dispatch covers resolved to group counts at the replayed scale).

use super::passes::PassContext;
use super::{DISPATCH_ARGS, DRAW_ARGS, DRAW_INDEXED_ARGS, Validator};
use crate::capture::diag::JsonPath;
use crate::capture::format::ResourceKind;
use crate::capture::format::StepMode;
use crate::capture::format::{Access, Draw, IndirectArgs, Pass, PassKind};
use crate::capture::model::{
    AccessSource, DispatchDesc, DrawDesc, MeshDesc, MeshId, PassDesc, ResourceAccess, ResourceDesc,
    Subresources,
};
use crate::capture::shaders::ShaderInterface;

/// Most instances one draw may ask for, and most vertices times instances: a draw of 2^32
/// instances would replay for hours on a software rasterizer.
pub const MAX_DRAW_INSTANCES: u32 = 1 << 24;
pub const MAX_DRAW_VERTICES: u64 = 1 << 32;
/// Vertex, index and instance ids are 32-bit and a draw's range is a `Range<u32>` (wgpu) or a
/// start plus a count the API adds in 32 bits (D3D12, Vulkan): its end must fit in a u32.
pub const DRAW_ID_RANGE: u64 = u32::MAX as u64;

impl<'a> Validator<'a> {
    pub(super) fn pass_draws(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        cx: &PassContext<'_>,
    ) -> Vec<DrawDesc> {
        let mut draws = Vec::new();
        for (i, d) in p.draws.iter().enumerate() {
            let dpath = path.field("draws").index(i);
            let mesh = d
                .mesh
                .as_ref()
                .and_then(|m| self.lookup("mesh", m, &dpath.field("mesh")));
            let mesh_desc = mesh.and_then(|m| cx.meshes.map(|ms| &ms[m as usize]));
            if d.mesh.is_none() && d.count.is_none() && d.indirect.is_none() {
                self.diags.error(
                    "draw",
                    &dpath,
                    "a draw without a mesh needs a `count` (vertices generated in the shader)",
                );
            }
            self.draw_limits(d, &dpath);
            if let (Some(m), Some(count)) = (mesh_desc, d.count)
                && let Some(avail) = m.drawn_elements()
                && u64::from(d.first) + u64::from(count) > avail
            {
                self.diags.error(
                    "draw",
                    &dpath.field("count"),
                    format!(
                        "draw reads elements {}..{} of mesh \"{}\", which has {avail}: lower `first` or `count`",
                        d.first,
                        u64::from(d.first) + u64::from(count),
                        m.name
                    ),
                );
            }
            self.draw_ranges(d, &dpath, mesh_desc);
            self.draw_rules(p, d, &dpath, cx);
            self.draw_buffers(d, &dpath, resources, accesses, i);
            let indexed =
                mesh_desc.is_some_and(|m| m.index_format.is_some()) || d.index_buffer.is_some();
            let indirect = d.indirect.as_ref().and_then(|ind| {
                let record = if indexed {
                    DRAW_INDEXED_ARGS
                } else {
                    DRAW_ARGS
                };
                // Records packed one after another, as many as the count may name.
                let records = ind
                    .count
                    .as_ref()
                    .map_or(1, |c| u64::from(c.max_draws.max(1)));
                self.check_indirect(
                    ind,
                    record.saturating_mul(records),
                    &dpath.field("indirect"),
                    resources,
                    accesses,
                    AccessSource::Indirect(i),
                )
            });
            let draw_count = d
                .indirect
                .as_ref()
                .and_then(|ind| ind.count.as_ref())
                .and_then(|c| {
                    let at = IndirectArgs {
                        buffer: c.buffer.clone(),
                        offset: c.offset,
                        count: None,
                    };
                    let (buffer, offset) = self.check_indirect(
                        &at,
                        4,
                        &dpath.field("indirect").field("count"),
                        resources,
                        accesses,
                        AccessSource::Indirect(i),
                    )?;
                    Some((buffer, offset, c.max_draws))
                });
            draws.push(DrawDesc {
                label: d.label.clone(),
                vertex: d.vertex.clone(),
                fragment: d.fragment.clone(),
                mesh: mesh.map(MeshId),
                count: d.count,
                instances: d.instances,
                first: d.first,
                first_instance: d.first_instance,
                base_vertex: d.base_vertex,
                indirect,
                draw_count,
                stencil_reference: d.stencil_reference,
                depth_only: d.depth_only,
                params: d.params.clone(),
                vk: self.vk_work(d.pipeline.as_deref(), &d.vulkan_state),
            });
        }

        draws
    }

    /// A draw's instances and vertex invocations within what a draw may run.
    fn draw_limits(&mut self, d: &Draw, dpath: &JsonPath) {
        if d.instances == 0 {
            self.diags
                .warning("draw", &dpath.field("instances"), "draw of zero instances");
        }
        if d.instances > MAX_DRAW_INSTANCES {
            self.diags.error(
                "limit",
                &dpath.field("instances"),
                format!(
                    "{} instances is over the limit of {MAX_DRAW_INSTANCES} per draw",
                    d.instances
                ),
            );
        } else if let Some(count) = d.count
            && u64::from(count) * u64::from(d.instances) > MAX_DRAW_VERTICES
        {
            self.diags.error(
            "limit",
            &dpath.field("count"),
            format!(
                "{count} vertices x {} instances is over the limit of {MAX_DRAW_VERTICES} vertex invocations per draw",
                d.instances
            ),
        );
        }
    }

    /// Stencil reference and depth-only draws against their pass's state and targets.
    fn draw_rules(&mut self, p: &Pass, d: &Draw, dpath: &JsonPath, cx: &PassContext<'_>) {
        let name = &p.name;
        if d.stencil_reference.is_some_and(|r| r > 255) {
            self.diags.error(
                "draw",
                &dpath.field("stencil_reference"),
                "stencil reference is 8 bits (0..255)",
            );
        }
        if d.depth_only && d.fragment.is_some() {
            self.diags.error(
                "draw",
                &dpath.field("fragment"),
                "a depth-only draw runs no fragment shader: drop `fragment` or `depth_only`",
            );
        }
        if d.depth_only && (!p.color_attachments.is_empty() || p.depth_stencil.is_none()) {
            self.diags.error(
            "draw",
            &dpath.field("depth_only"),
            format!(
                "a depth-only draw runs no fragment shader, so pass \"{name}\" must have a depth target and no colour targets"
            ),
        );
        }
        if d.stencil_reference.is_some() && cx.state.stencil.is_none() {
            self.diags.error(
                "draw",
                &dpath.field("stencil_reference"),
                format!("pass \"{name}\" sets a stencil reference but has no stencil state"),
            );
        }
    }

    pub(super) fn pass_dispatches(
        &mut self,
        p: &'a Pass,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
    ) -> Vec<DispatchDesc> {
        let name = &p.name;
        let mut dispatches = Vec::new();
        if p.kind == PassKind::Compute && p.dispatches.is_empty() {
            self.diags.error(
                "dispatch",
                path,
                format!("compute pass \"{name}\" has no dispatches"),
            );
        }
        for (i, d) in p.dispatches.iter().enumerate() {
            let dpath = path.field("dispatches").index(i);
            let given = [d.groups.is_some(), d.indirect.is_some(), d.cover.is_some()];
            match (&d.groups, &d.indirect) {
                _ if given.iter().filter(|&&g| g).count() > 1 => self.diags.error(
                    "dispatch",
                    &dpath,
                    "give one of `groups`, `indirect` and `cover`",
                ),
                (None, None) if d.cover.is_some() => {}
                (None, None) => self.diags.error(
                    "dispatch",
                    &dpath,
                    "a dispatch needs `groups`, `indirect` or `cover`",
                ),
                (Some(g), None) => {
                    let max = self.options.limits.max_dispatch_groups;
                    if g.contains(&0) || g.iter().any(|&x| x > max) {
                        self.diags.error(
                            "dispatch",
                            &dpath.field("groups"),
                            format!("group counts {g:?} must each be 1..{max}"),
                        );
                    }
                }
                (None, Some(_)) | (Some(_), Some(_)) => {}
            }
            if d.indirect.as_ref().is_some_and(|ind| ind.count.is_some()) {
                self.diags.error(
                    "indirect",
                    &dpath.field("indirect").field("count"),
                    "a dispatch reads one record of indirect arguments; a draw count is for draws",
                );
            }
            let indirect = d.indirect.as_ref().and_then(|ind| {
                self.check_indirect(
                    ind,
                    DISPATCH_ARGS,
                    &dpath.field("indirect"),
                    resources,
                    accesses,
                    AccessSource::Indirect(i),
                )
            });
            dispatches.push(DispatchDesc {
                label: d.label.clone(),
                entry: d.entry.clone(),
                groups: d.groups,
                indirect,
                params: d.params.clone(),
                vk: self.vk_work(d.pipeline.as_deref(), &d.vulkan_state),
            });
        }

        dispatches
    }

    /// The element (vertex or index) and instance ranges a direct draw reads, computed in 64
    /// bits: each must end within the 32-bit ids the GPU counts in (a range past 2^32 wraps
    /// to a small one) and within the mesh rows it reads where the capture states them. The
    /// `count` given with a mesh is checked by `pass_draws` itself (its message predates this).
    fn draw_ranges(&mut self, d: &Draw, dpath: &JsonPath, mesh: Option<&MeshDesc>) {
        if d.indirect.is_some() {
            return;
        }
        let indexed = mesh.is_some_and(|m| m.index_format.is_some()) || d.index_buffer.is_some();
        let (what, whats) = if indexed {
            ("index", "indices")
        } else {
            ("vertex", "vertices")
        };
        let available = mesh.and_then(MeshDesc::drawn_elements);
        if let Some(count) = d.count.map(u64::from).or(available) {
            let end = u64::from(d.first) + count;
            let field = if d.count.is_some() { "count" } else { "first" };
            if end > DRAW_ID_RANGE {
                self.diags.error(
                    "draw",
                    &dpath.field(field),
                    format!(
                        "draw reads {whats} {}..{end}, past the 32-bit {what} range (ends at most at {DRAW_ID_RANGE}): lower `first` or `count`",
                        d.first
                    ),
                );
            } else if d.count.is_none()
                && let (Some(m), Some(avail)) = (mesh, available)
                && end > avail
            {
                self.diags.error(
                    "draw",
                    &dpath.field("first"),
                    format!(
                        "draw reads elements {}..{end} of mesh \"{}\", which has {avail}: `first` must leave the mesh's {avail} elements in range, or give a smaller `count`",
                        d.first, m.name
                    ),
                );
            }
        }
        let rows = mesh.and_then(|m| {
            m.streams
                .iter()
                .any(|s| s.step == StepMode::Instance)
                .then(|| m.instance_count.unwrap_or(1))
        });
        // Replay draws every instance row of the mesh when the draw leaves `instances` at 1.
        let instances = if d.instances == 1 {
            mesh.map_or(1, |m| m.instance_count.unwrap_or(1).max(1))
        } else {
            d.instances
        };
        let end = u64::from(d.first_instance) + u64::from(instances);
        if end > DRAW_ID_RANGE {
            self.diags.error(
                "draw",
                &dpath.field("first_instance"),
                format!(
                    "draw reads instances {}..{end}, past the 32-bit instance range (ends at most at {DRAW_ID_RANGE}): lower `first_instance` or `instances`",
                    d.first_instance
                ),
            );
        } else if let (Some(m), Some(rows)) = (mesh, rows)
            && end > u64::from(rows)
        {
            self.diags.error(
                "draw",
                &dpath.field("first_instance"),
                format!(
                    "draw reads instances {}..{end} of mesh \"{}\", whose per-instance streams have {rows} rows: lower `first_instance` or `instances`",
                    d.first_instance, m.name
                ),
            );
        }
        // Indices address the mesh's own vertices, so a base_vertex that moves all of them
        // past either end (at or past the count, or at or below minus the count) reads only
        // outside the vertex buffer.
        if indexed
            && let Some(m) = mesh
            && let (Some(vertices), _) = m.elements()
            && vertices > 0
            && i128::from(d.base_vertex).abs() >= i128::from(vertices)
        {
            let side = if d.base_vertex < 0 { "before" } else { "past" };
            self.diags.error(
                "draw",
                &dpath.field("base_vertex"),
                format!(
                    "base_vertex {} moves every index {side} the {vertices} vertices of mesh \"{}\": every index would read outside it; give a base_vertex within -{vertices}..{vertices}",
                    d.base_vertex, m.name
                ),
            );
        }
    }

    /// Vertex and index buffers an imported draw names: buffers, read as such. Replayed
    /// draws take theirs from their mesh, so only a capture that cannot be replayed has them.
    fn draw_buffers(
        &mut self,
        d: &Draw,
        dpath: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        i: usize,
    ) {
        if (d.index_buffer.is_some() || !d.vertex_buffers.is_empty())
            && !self.not_replayable()
            && d.pipeline.is_none()
        {
            self.diags.error(
                "draw",
                dpath,
                "`vertex_buffers` and `index_buffer` describe draws of an imported capture; a replayed draw takes its buffers from its `mesh`",
            );
            return;
        }
        let named = d
            .vertex_buffers
            .iter()
            .enumerate()
            .map(|(k, b)| {
                (
                    b,
                    Access::VertexBuffer,
                    dpath.field("vertex_buffers").index(k),
                )
            })
            .chain(
                d.index_buffer
                    .iter()
                    .map(|b| (b, Access::IndexBuffer, dpath.field("index_buffer"))),
            );
        for (name, access, path) in named {
            let Some(id) = self.lookup("resource", name, &path) else {
                continue;
            };
            let Some(r) = resources.map(|rs| &rs[id as usize]) else {
                continue;
            };
            if r.is_texture() {
                self.diags.error(
                    "draw",
                    &path,
                    format!(
                        "\"{}\" is a texture, not a {} buffer",
                        r.name,
                        if access == Access::IndexBuffer {
                            "index"
                        } else {
                            "vertex"
                        }
                    ),
                );
                continue;
            }
            accesses.push(ResourceAccess {
                resource: r.id,
                access,
                range: Subresources::whole(r),
                reads: true,
                writes: false,
                source: AccessSource::DrawMesh(i),
            });
        }
    }

    /// Resolves each `cover` dispatch of `p` to group counts: its texture's size as replayed
    /// (at the mip asked for) over the entry point's workgroup size, rounded up. An entry
    /// point that does not exist is reported where the shader's use is checked.
    pub(super) fn cover_dispatches(
        &mut self,
        p: &Pass,
        pass: &mut PassDesc,
        interface: &ShaderInterface,
        resources: Option<&[ResourceDesc]>,
        path: &JsonPath,
    ) {
        let Some(resources) = resources else { return };
        for (i, d) in p.dispatches.iter().enumerate() {
            let Some(c) = &d.cover else { continue };
            let cpath = path.field("dispatches").index(i).field("cover");
            let Some(r) = resources.iter().find(|r| r.name == c.resource) else {
                self.diags.error(
                    "dispatch",
                    &cpath.field("resource"),
                    format!("no resource \"{}\" to cover", c.resource),
                );
                continue;
            };
            if !r.is_texture() {
                self.diags.error(
                    "dispatch",
                    &cpath.field("resource"),
                    format!(
                        "a dispatch covers a texture's texels; \"{}\" is a buffer",
                        r.name
                    ),
                );
                continue;
            }
            if c.mip >= r.mip_levels {
                self.diags.error(
                    "dispatch",
                    &cpath.field("mip"),
                    format!(
                        "\"{}\" has {} mip(s), no mip {}",
                        r.name, r.mip_levels, c.mip
                    ),
                );
                continue;
            }
            let entry = d
                .entry
                .as_ref()
                .or(p.shader.as_ref().and_then(|s| s.compute.as_ref()));
            let Some(size) = entry
                .and_then(|e| interface.entry_points.get(e))
                .map(|e| e.workgroup_size)
                .filter(|s| s.iter().all(|&n| n > 0))
            else {
                continue;
            };
            let depth = if r.kind == ResourceKind::Texture3D {
                (r.depth >> c.mip).max(1)
            } else {
                r.array_layers.max(1)
            };
            let extent = [(r.width >> c.mip).max(1), (r.height >> c.mip).max(1), depth];
            let groups = [0, 1, 2].map(|k| extent[k].div_ceil(size[k]));
            let max = self.options.limits.max_dispatch_groups;
            if groups.iter().any(|&g| g > max) {
                self.diags.error(
                    "dispatch",
                    &cpath,
                    format!(
                        "covering \"{}\" takes {groups:?} groups, over {max}",
                        r.name
                    ),
                );
                continue;
            }
            if let Some(slot) = pass.dispatches.get_mut(i) {
                slot.groups = Some(groups);
            }
        }
    }
}
