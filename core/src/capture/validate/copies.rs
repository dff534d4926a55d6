//! Copies, recorded barriers, and fences between queues.

use std::collections::BTreeMap;

use super::Validator;
use crate::capture::diag::{JsonPath, suggest};
use crate::capture::format::{
    Access, BarrierType, Copy, CopyLocation, Name, RecordedBarrier, ResourceFlag, ResourceState,
    SplitFlag,
};
use crate::capture::model::{
    AccessSource, CopyDesc, CopyLocationDesc, FenceId, HeapDesc, PassDesc, PlacementDesc,
    RecordedBarrierDesc, ResourceAccess, ResourceDesc, ResourceId, Subresources, VulkanBarrierDesc,
};

impl<'a> Validator<'a> {
    pub(super) fn check_copy(
        &mut self,
        c: &Copy,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        accesses: &mut Vec<ResourceAccess>,
        index: usize,
    ) -> Option<CopyDesc> {
        let src = self.lookup(
            "resource",
            &c.src.resource,
            &path.field("src").field("resource"),
        );
        let dst = self.lookup(
            "resource",
            &c.dst.resource,
            &path.field("dst").field("resource"),
        );
        let resources = resources?;
        let (src, dst) = (&resources[src? as usize], &resources[dst? as usize]);
        let before = self.diags.error_count();
        let mut ranges = [Subresources::whole(src), Subresources::whole(dst)];
        match (src.is_texture(), dst.is_texture()) {
            (false, false) => self.copy_buffers(c, path, src, dst, &mut ranges),
            (true, true) => self.copy_textures(c, path, src, dst, &mut ranges)?,
            (texture_src, _) => self.copy_footprint(c, path, src, dst, texture_src, &mut ranges)?,
        }
        if self.diags.error_count() > before {
            return None;
        }
        let loc = |l: &CopyLocation, r: &ResourceDesc| CopyLocationDesc {
            resource: r.id,
            mip: l.mip,
            layer: l.layer,
            origin: l.origin,
            offset: l.offset,
            size: l.size,
            bytes_per_row: l.bytes_per_row,
        };
        accesses.push(ResourceAccess {
            resource: src.id,
            access: Access::CopySrc,
            range: ranges[0],
            reads: true,
            writes: false,
            source: AccessSource::Copy(index),
        });
        accesses.push(ResourceAccess {
            resource: dst.id,
            access: Access::CopyDst,
            range: ranges[1],
            reads: false,
            writes: true,
            source: AccessSource::Copy(index),
        });
        Some(CopyDesc {
            src: loc(&c.src, src),
            dst: loc(&c.dst, dst),
            extent: c.extent,
            host: c.host,
        })
    }

    /// A buffer-to-buffer copy: both ranges inside their buffers, no overlap within one.
    fn copy_buffers(
        &mut self,
        c: &Copy,
        path: &JsonPath,
        src: &ResourceDesc,
        dst: &ResourceDesc,
        ranges: &mut [Subresources; 2],
    ) {
        let size = c
            .src
            .size
            .or(c.dst.size)
            .unwrap_or(src.bytes.saturating_sub(c.src.offset));
        for (i, (r, loc, side)) in [(src, &c.src, "src"), (dst, &c.dst, "dst")]
            .into_iter()
            .enumerate()
        {
            if loc.offset.checked_add(size).is_none_or(|e| e > r.bytes) {
                self.diags.error(
                    "copy",
                    &path.field(side),
                    format!(
                        "copying {size} bytes at offset {} overruns \"{}\" ({} bytes)",
                        loc.offset, r.name, r.bytes
                    ),
                );
            }
            ranges[i].byte_offset = loc.offset;
            ranges[i].byte_size = size;
        }
        if src.id == dst.id
            && c.src.offset < c.dst.offset + size
            && c.dst.offset < c.src.offset + size
        {
            self.diags.error(
                "copy",
                path,
                format!("source and destination ranges of \"{}\" overlap", src.name),
            );
        }
    }

    /// A texture-to-texture copy: compatible elements, equal samples, regions inside the mips.
    fn copy_textures(
        &mut self,
        c: &Copy,
        path: &JsonPath,
        src: &ResourceDesc,
        dst: &ResourceDesc,
        ranges: &mut [Subresources; 2],
    ) -> Option<()> {
        let (sf, df) = (src.format?, dst.format?);
        if sf.bits_per_element != df.bits_per_element || sf.block_width != df.block_width {
            self.diags.error(
                "copy",
                path,
                format!(
                    "cannot copy {} into {}: element sizes differ ({} and {} bits)",
                    sf.name, df.name, sf.bits_per_element, df.bits_per_element
                ),
            );
        }
        if src.samples != dst.samples {
            self.diags.error(
                "copy",
                path,
                "copies need equal sample counts; use a resolve pass",
            );
        }
        let (sw, sh, sd) = src.mip_extent(c.src.mip);
        let extent = c.extent.unwrap_or([
            sw.saturating_sub(c.src.origin[0]),
            sh.saturating_sub(c.src.origin[1]),
            sd.saturating_sub(c.src.origin[2]),
        ]);
        for (i, (r, loc, side)) in [(src, &c.src, "src"), (dst, &c.dst, "dst")]
            .into_iter()
            .enumerate()
        {
            ranges[i] = self.single_subresource(r, loc.mip, loc.layer, &path.field(side));
            let (w, h, d) = r.mip_extent(loc.mip.min(r.mip_levels.saturating_sub(1)));
            let fits = (0..3).all(|k| {
                u64::from(loc.origin[k]) + u64::from(extent[k]) <= u64::from([w, h, d][k])
            });
            if !fits {
                self.diags.error(
                    "copy",
                    &path.field(side),
                    format!(
                        "region {:?}+{:?} is outside mip {} of \"{}\" ({w}x{h}x{d})",
                        loc.origin, extent, loc.mip, r.name
                    ),
                );
            }
        }
        if src.id == dst.id && ranges[0].overlaps(&ranges[1]) {
            self.diags.error(
                "copy",
                path,
                format!(
                    "copy within \"{}\" reads and writes the same subresource",
                    src.name
                ),
            );
        }
        Some(())
    }

    /// A copy between a texture and a buffer: the buffer holds the placed footprint with rows
    /// aligned to D3D12_TEXTURE_DATA_PITCH_ALIGNMENT (Vulkan: any row length).
    fn copy_footprint(
        &mut self,
        c: &Copy,
        path: &JsonPath,
        src: &ResourceDesc,
        dst: &ResourceDesc,
        texture_src: bool,
        ranges: &mut [Subresources; 2],
    ) -> Option<()> {
        let (tex, buf, tloc, bloc, tside, bside) = if texture_src {
            (src, dst, &c.src, &c.dst, "src", "dst")
        } else {
            (dst, src, &c.dst, &c.src, "dst", "src")
        };
        let f = tex.format?;
        let ti = if texture_src { 0 } else { 1 };
        ranges[ti] = self.single_subresource(tex, tloc.mip, tloc.layer, &path.field(tside));
        let (w, h, d) = tex.mip_extent(tloc.mip.min(tex.mip_levels.saturating_sub(1)));
        let extent = c.extent.unwrap_or([w, h, d]);
        let blocks_w = u64::from(extent[0].div_ceil(f.block_width));
        let rows = u64::from(extent[1].div_ceil(f.block_height));
        let row_bytes = blocks_w * u64::from(f.bits_per_element) / 8;
        let pitch = bloc
            .bytes_per_row
            .map(u64::from)
            .unwrap_or(if self.vulkan() {
                row_bytes
            } else {
                row_bytes.div_ceil(256) * 256
            });
        if pitch < row_bytes {
            self.diags.error(
                "copy",
                &path.field(bside).field("bytes_per_row"),
                format!(
                    "bytes_per_row {pitch} is less than a row of {} texels ({row_bytes} bytes)",
                    extent[0]
                ),
            );
        }
        if pitch % 256 != 0 && !self.vulkan() {
            self.diags.error("copy", &path.field(bside).field("bytes_per_row"), format!(
                "bytes_per_row {pitch} must be a multiple of 256 (D3D12_TEXTURE_DATA_PITCH_ALIGNMENT)"
            ));
        }
        // Every slice but the last whole, then the last one's rows up to its last texel.
        let needed = pitch * rows * u64::from(extent[2].max(1).saturating_sub(1))
            + pitch * rows.saturating_sub(1)
            + row_bytes;
        if bloc
            .offset
            .checked_add(needed)
            .is_none_or(|e| e > buf.bytes)
        {
            self.diags.error("copy", &path.field(bside), format!(
                "the footprint of {}x{}x{} texels needs {needed} bytes at offset {} but \"{}\" has {}",
                extent[0], extent[1], extent[2], bloc.offset, buf.name, buf.bytes
            ));
        }
        ranges[1 - ti].byte_offset = bloc.offset;
        ranges[1 - ti].byte_size = needed.max(1);
        Some(())
    }

    pub(super) fn check_barrier(
        &mut self,
        b: &RecordedBarrier,
        path: &JsonPath,
        resources: Option<&[ResourceDesc]>,
        heaps: &[HeapDesc],
    ) -> Option<RecordedBarrierDesc> {
        let resource = match &b.resource {
            Some(n) => Some(self.lookup("resource", n, &path.field("resource"))?),
            None => None,
        };
        let resource_before = match &b.resource_before {
            Some(n) => Some(self.lookup("resource", n, &path.field("resource_before"))?),
            None => None,
        };
        let resources = resources?;
        let before: Vec<ResourceState> = b
            .before
            .as_ref()
            .map(|s| s.as_slice().to_vec())
            .unwrap_or_default();
        let after: Vec<ResourceState> = b
            .after
            .as_ref()
            .map(|s| s.as_slice().to_vec())
            .unwrap_or_default();
        match b.barrier_type {
            BarrierType::Transition => {
                if resource.is_none() {
                    self.diags
                        .error("barrier", path, "a transition barrier needs a `resource`");
                }
                if before.is_empty() || after.is_empty() {
                    self.diags.error(
                        "barrier",
                        path,
                        "a transition barrier needs `before` and `after` states",
                    );
                }
                if !before.is_empty() && before == after {
                    self.diags.error(
                        "barrier",
                        &path.field("after"),
                        "transition to the same state",
                    );
                }
                for (field, states) in [("before", &before), ("after", &after)] {
                    if states.len() > 1 && states.iter().any(|s| s.is_write()) {
                        self.diags.error(
                            "barrier",
                            &path.field(field),
                            "a write state cannot be combined with other states",
                        );
                    }
                }
            }
            BarrierType::Uav => {
                if let Some(id) = resource {
                    let r = &resources[id as usize];
                    if !r.has_flag(ResourceFlag::AllowUnorderedAccess) {
                        self.diags.error(
                            "barrier",
                            &path.field("resource"),
                            format!(
                                "UAV barrier on \"{}\", which lacks ALLOW_UNORDERED_ACCESS",
                                r.name
                            ),
                        );
                    }
                }
                if !before.is_empty() || !after.is_empty() {
                    self.diags
                        .error("barrier", path, "UAV barriers have no states");
                }
            }
            BarrierType::Vulkan => {
                if !before.is_empty() || !after.is_empty() {
                    self.diags.error(
                        "barrier",
                        path,
                        "Vulkan barriers give layouts and masks in `vulkan`, not D3D12 states",
                    );
                }
            }
            BarrierType::Aliasing => {
                if !before.is_empty() || !after.is_empty() {
                    self.diags
                        .error("barrier", path, "aliasing barriers have no states");
                }
                if let (Some(a), Some(b_)) = (resource_before, resource) {
                    let (ra, rb) = (&resources[a as usize], &resources[b_ as usize]);
                    let same_heap = match (&ra.placement, &rb.placement) {
                        (
                            PlacementDesc::Placed { heap: ha, .. },
                            PlacementDesc::Placed { heap: hb, .. },
                        ) => ha == hb,
                        _ => false,
                    };
                    if !same_heap {
                        let heap_name = |r: &ResourceDesc| match &r.placement {
                            PlacementDesc::Placed { heap, .. } => heaps[heap.index()].name.clone(),
                            _ => "no heap".to_owned(),
                        };
                        self.diags.error("barrier", path, format!(
                            "aliasing barrier between \"{}\" ({}) and \"{}\" ({}): only resources placed in one heap can alias",
                            ra.name, heap_name(ra), rb.name, heap_name(rb)
                        ));
                    }
                }
            }
        }
        let vulkan = self.check_vulkan_barrier(b, path);
        if b.split != SplitFlag::None && b.barrier_type != BarrierType::Transition {
            self.diags.error(
                "barrier",
                &path.field("split"),
                "only transitions can be split",
            );
        }
        let range = match resource {
            Some(id) if b.mips.is_some() || b.layers.is_some() => {
                let r = &resources[id as usize];
                Some(self.view_range(r, b.mips.as_ref(), b.layers.as_ref(), path))
            }
            _ => None,
        };
        Some(RecordedBarrierDesc {
            barrier_type: b.barrier_type,
            resource: resource.map(ResourceId),
            resource_before: resource_before.map(ResourceId),
            range,
            before,
            after,
            split: b.split,
            vulkan,
        })
    }

    pub(super) fn check_fences(&mut self, passes: &Option<Vec<PassDesc>>) {
        let Some(passes) = passes else { return };
        let mut signalled: BTreeMap<FenceId, &PassDesc> = BTreeMap::new();
        for p in passes {
            for (i, f) in p.signal.iter().enumerate() {
                if let Some(first) = signalled.insert(*f, p) {
                    self.diags.error("fence", &self.root.field("passes").index(p.id.index()).field("signal").index(i), format!(
                        "fence \"{}\" is signalled by \"{}\" and again by \"{}\"; a fence is signalled once per frame",
                        self.raw.fences[f.index()].name, first.name, p.name
                    ));
                    signalled.insert(*f, first);
                }
            }
        }
        for p in passes {
            for (i, f) in p.wait.iter().enumerate() {
                let path = self
                    .root
                    .field("passes")
                    .index(p.id.index())
                    .field("wait")
                    .index(i);
                let fence = &self.raw.fences[f.index()].name;
                match signalled.get(f) {
                    None => self.diags.error("fence", &path, format!(
                        "pass \"{}\" waits on fence \"{fence}\", which no pass signals: the queue would wait forever", p.name
                    )),
                    Some(s) if s.queue == p.queue => self.diags.error("fence", &path, format!(
                        "pass \"{}\" waits on fence \"{fence}\" signalled on its own queue by \"{}\"; queue order already covers that",
                        p.name, s.name
                    )),
                    Some(_) => {}
                }
            }
        }
        for (i, f) in self.raw.fences.iter().enumerate() {
            if !signalled.contains_key(&FenceId(i as u32)) {
                self.diags.warning(
                    "fence",
                    &self.root.field("fences").index(i),
                    format!("fence \"{}\" is never signalled", f.name),
                );
            }
        }
    }

    /// The `vulkan` detail of a barrier: present exactly for type `vulkan`, known stage,
    /// access and layout names.
    fn check_vulkan_barrier(
        &mut self,
        b: &RecordedBarrier,
        path: &JsonPath,
    ) -> Option<VulkanBarrierDesc> {
        use crate::capture::vulkan::{AccessFlags, ImageLayout, PipelineStages};
        let vpath = path.field("vulkan");
        let v = match (&b.vulkan, b.barrier_type) {
            (Some(v), BarrierType::Vulkan) => v,
            (None, BarrierType::Vulkan) => {
                self.diags.error(
                    "barrier",
                    path,
                    "a `vulkan` barrier needs its `vulkan` detail",
                );
                return None;
            }
            (Some(_), _) => {
                self.diags.error(
                    "barrier",
                    &vpath,
                    "only barriers of type `vulkan` carry a `vulkan` detail",
                );
                return None;
            }
            (None, _) => return None,
        };
        let mut unknown = |bad: &str, known: &[(&str, u64)], field: &str| {
            let suggestion = suggest(bad, known.iter().map(|(n, _)| *n));
            let what = if field.ends_with("stages") {
                "pipeline stage"
            } else {
                "access flag"
            };
            self.diags.error_with_suggestion(
                "barrier",
                &vpath.field(field),
                format!("unknown Vulkan {what} \"{bad}\""),
                suggestion,
            );
        };
        let mut stages = |names: &Vec<Name>, field: &str| {
            PipelineStages::parse(names).unwrap_or_else(|bad| {
                unknown(bad.0, PipelineStages::NAMES, field);
                PipelineStages::EMPTY
            })
        };
        let src_stages = stages(&v.src_stages, "src_stages");
        let dst_stages = stages(&v.dst_stages, "dst_stages");
        let mut access = |names: &Vec<Name>, field: &str| {
            AccessFlags::parse(names).unwrap_or_else(|bad| {
                unknown(bad.0, AccessFlags::NAMES, field);
                AccessFlags::EMPTY
            })
        };
        let src_access = access(&v.src_access, "src_access");
        let dst_access = access(&v.dst_access, "dst_access");
        let mut layout = |name: &Option<Name>, field: &str| {
            let n = name.as_deref()?;
            let found = ImageLayout::from_name(n);
            if found.is_none() {
                let suggestion = suggest(n, ImageLayout::ALL.iter().map(|l| l.name()));
                self.diags.error_with_suggestion(
                    "barrier",
                    &vpath.field(field),
                    format!("unknown Vulkan image layout \"{n}\""),
                    suggestion,
                );
            }
            found
        };
        let old_layout = layout(&v.old_layout, "old_layout");
        let new_layout = layout(&v.new_layout, "new_layout");
        if old_layout.is_some() != new_layout.is_some() {
            self.diags.error(
                "barrier",
                &vpath,
                "an image barrier gives both `old_layout` and `new_layout`",
            );
        }
        let queue_transfer = match (v.src_queue_family, v.dst_queue_family) {
            (Some(a), Some(b)) if a != b => Some((a, b)),
            _ => None,
        };
        Some(VulkanBarrierDesc {
            origin: v.origin.clone(),
            src_stages,
            src_access,
            dst_stages,
            dst_access,
            old_layout,
            new_layout,
            queue_transfer,
        })
    }
}
