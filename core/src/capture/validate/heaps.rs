//! Heaps: types, CPU page properties, memory pools, flags and the resource-heap tier rules.

use std::collections::BTreeSet;

use super::{MSAA_PLACEMENT_ALIGNMENT, PLACEMENT_ALIGNMENT, Validator, describe_allows};
use crate::capture::format::{CpuPageProperty, HeapFlag, HeapType, MemoryArchitecture, MemoryPool};
use crate::capture::model::{HeapAllows, HeapDesc, HeapId};

impl<'a> Validator<'a> {
    pub(super) fn check_heaps(&mut self) -> Vec<HeapDesc> {
        let raw = self.raw;
        let tier = raw.adapter.resource_heap_tier;
        let numa = raw.adapter.architecture == MemoryArchitecture::Numa;
        let mut out = Vec::new();
        for (i, h) in raw.heaps.iter().enumerate() {
            let path = self.root.field("heaps").index(i);
            if h.heap_type != HeapType::Custom {
                if h.cpu_page_property != CpuPageProperty::Unknown {
                    self.diags.error("heap-properties", &path.field("cpu_page_property"), format!(
                        "heap \"{}\" is {}: cpu_page_property must be UNKNOWN unless the type is CUSTOM",
                        h.name, h.heap_type.name()
                    ));
                }
                if h.memory_pool != MemoryPool::Unknown {
                    self.diags.error("heap-properties", &path.field("memory_pool"), format!(
                        "heap \"{}\" is {}: memory_pool must be UNKNOWN unless the type is CUSTOM",
                        h.name, h.heap_type.name()
                    ));
                }
            } else {
                if h.cpu_page_property == CpuPageProperty::Unknown {
                    self.diags.error("heap-properties", &path.field("cpu_page_property"), format!(
                        "CUSTOM heap \"{}\" must state its cpu_page_property (NOT_AVAILABLE, WRITE_COMBINE or WRITE_BACK)",
                        h.name
                    ));
                }
                if h.memory_pool == MemoryPool::Unknown {
                    self.diags.error(
                        "heap-properties",
                        &path.field("memory_pool"),
                        format!(
                            "CUSTOM heap \"{}\" must state its memory_pool (L0 or L1)",
                            h.name
                        ),
                    );
                }
                let cpu_visible = matches!(
                    h.cpu_page_property,
                    CpuPageProperty::WriteCombine | CpuPageProperty::WriteBack
                );
                if h.memory_pool == MemoryPool::L1 && cpu_visible && numa {
                    self.diags.error("heap-properties", &path.field("cpu_page_property"), format!(
                        "CUSTOM heap \"{}\": memory pool L1 with {} is invalid on a NUMA adapter (the CPU cannot access video memory)",
                        h.name, h.cpu_page_property.name()
                    ));
                }
                if h.memory_pool == MemoryPool::L1 && !numa {
                    self.diags.error(
                        "heap-properties",
                        &path.field("memory_pool"),
                        format!(
                            "CUSTOM heap \"{}\": memory pool L1 does not exist on a UMA adapter",
                            h.name
                        ),
                    );
                }
            }
            if h.alignment != 0
                && h.alignment != PLACEMENT_ALIGNMENT
                && h.alignment != MSAA_PLACEMENT_ALIGNMENT
            {
                self.diags.error(
                    "heap-alignment",
                    &path.field("alignment"),
                    format!(
                        "heap alignment {} must be 65536 (64 KiB) or 4194304 (4 MiB)",
                        h.alignment
                    ),
                );
            }
            if h.size == 0 {
                self.diags.error(
                    "heap-size",
                    &path.field("size"),
                    "heap size must be non-zero",
                );
            }
            let flags: BTreeSet<HeapFlag> = h.flags.iter().copied().collect();
            let mut deny_buffers = flags.contains(&HeapFlag::DenyBuffers);
            let mut deny_rt_ds = flags.contains(&HeapFlag::DenyRtDsTextures);
            let mut deny_non_rt_ds = flags.contains(&HeapFlag::DenyNonRtDsTextures);
            if flags.contains(&HeapFlag::AllowOnlyBuffers) {
                deny_rt_ds = true;
                deny_non_rt_ds = true;
            }
            if flags.contains(&HeapFlag::AllowOnlyNonRtDsTextures) {
                deny_buffers = true;
                deny_rt_ds = true;
            }
            if flags.contains(&HeapFlag::AllowOnlyRtDsTextures) {
                deny_buffers = true;
                deny_non_rt_ds = true;
            }
            let allows = HeapAllows {
                buffers: !deny_buffers,
                rt_ds_textures: !deny_rt_ds,
                other_textures: !deny_non_rt_ds,
            };
            let allowed = [allows.buffers, allows.rt_ds_textures, allows.other_textures]
                .iter()
                .filter(|a| **a)
                .count();
            if allowed == 0 {
                self.diags.error("heap-flags", &path.field("flags"), format!(
                    "heap \"{}\" denies buffers, RT/DS textures and other textures: it can hold nothing", h.name
                ));
            } else if tier == 1 && allowed > 1 {
                self.diags.error("heap-tier", &path.field("flags"), format!(
                    "heap \"{}\" may hold {}; resource heap tier 1 requires exactly one category \
                     (use ALLOW_ONLY_BUFFERS, ALLOW_ONLY_RT_DS_TEXTURES or ALLOW_ONLY_NON_RT_DS_TEXTURES)",
                    h.name, describe_allows(allows)
                ));
            }
            if tier == 1 && flags.contains(&HeapFlag::AllowAllBuffersAndTextures) {
                self.diags.error(
                    "heap-tier",
                    &path.field("flags"),
                    format!(
                        "heap \"{}\": ALLOW_ALL_BUFFERS_AND_TEXTURES needs resource heap tier 2",
                        h.name
                    ),
                );
            }
            if flags.contains(&HeapFlag::AllowAllBuffersAndTextures)
                && (deny_buffers || deny_rt_ds || deny_non_rt_ds)
            {
                self.diags.error("heap-flags", &path.field("flags"), format!(
                    "heap \"{}\": ALLOW_ALL_BUFFERS_AND_TEXTURES contradicts its DENY_/ALLOW_ONLY_ flags", h.name
                ));
            }
            out.push(HeapDesc {
                id: HeapId(i as u32),
                name: h.name.clone(),
                heap_type: h.heap_type,
                size: h.size,
                alignment: if h.alignment == 0 {
                    PLACEMENT_ALIGNMENT
                } else {
                    h.alignment
                },
                flags,
                allows,
            });
        }
        out
    }
}
