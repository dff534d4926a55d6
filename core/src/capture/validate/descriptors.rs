//! Descriptor heaps, samplers and meshes.

use std::collections::{BTreeMap, BTreeSet};

use super::{Validator, mesh_file_bytes};
use crate::capture::diag::JsonPath;
use crate::capture::format::{DescriptorHeapType, Filter, Mesh, MeshSource, StepMode};
use crate::capture::generators;
use crate::capture::generators::{Content, Seeded, Shape};
use crate::capture::model::{
    DescriptorHeapDesc, DescriptorHeapId, MeshDesc, MeshId, MeshSourceDesc,
};

impl<'a> Validator<'a> {
    pub(super) fn check_descriptor_heaps(&mut self) -> Vec<DescriptorHeapDesc> {
        let limits = self.options.limits;
        let mut out = Vec::new();
        let mut visible: BTreeMap<DescriptorHeapType, usize> = BTreeMap::new();
        for (i, h) in self.raw.descriptor_heaps.iter().enumerate() {
            let path = self.root.field("descriptor_heaps").index(i);
            if h.capacity == 0 {
                self.diags.error(
                    "descriptor-heap",
                    &path.field("capacity"),
                    "capacity must be at least 1",
                );
            }
            let ty = h.heap_type;
            if h.shader_visible && matches!(ty, DescriptorHeapType::Rtv | DescriptorHeapType::Dsv) {
                self.diags.error(
                    "descriptor-heap",
                    &path.field("shader_visible"),
                    format!(
                        "descriptor heap \"{}\": RTV and DSV heaps cannot be shader-visible",
                        h.name
                    ),
                );
            }
            if h.shader_visible {
                let max = match ty {
                    DescriptorHeapType::Sampler => limits.max_sampler_descriptors,
                    _ => limits.max_cbv_srv_uav_descriptors,
                };
                if h.capacity > max {
                    self.diags.error("limit", &path.field("capacity"), format!(
                        "shader-visible descriptor heap \"{}\" has {} descriptors; the limit is {max}", h.name, h.capacity
                    ));
                }
                if let Some(first) = visible.insert(ty, i) {
                    self.diags.warning("descriptor-heap", &path.field("shader_visible"), format!(
                        "a second shader-visible heap of this type (first: descriptor_heaps[{first}]); only one of each can be bound at a time"
                    ));
                }
            }
            out.push(DescriptorHeapDesc {
                id: DescriptorHeapId(i as u32),
                name: h.name.clone(),
                heap_type: ty,
                capacity: h.capacity,
                shader_visible: h.shader_visible,
            });
        }
        out
    }

    pub(super) fn check_samplers(&mut self) {
        for (i, s) in self.raw.samplers.iter().enumerate() {
            let path = self.root.field("samplers").index(i);
            if !(1..=16).contains(&s.max_anisotropy) {
                self.diags.error(
                    "sampler",
                    &path.field("max_anisotropy"),
                    "max_anisotropy must be 1..16",
                );
            }
            if s.max_anisotropy > 1
                && (s.min_filter != Filter::Linear
                    || s.mag_filter != Filter::Linear
                    || s.mip_filter != Filter::Linear)
            {
                self.diags.error(
                    "sampler",
                    &path.field("max_anisotropy"),
                    "anisotropic filtering needs linear min, mag and mip filters",
                );
            }
            if !(s.lod_min >= 0.0 && s.lod_max >= s.lod_min) {
                self.diags.error(
                    "sampler",
                    &path.field("lod_max"),
                    format!(
                        "need 0 <= lod_min <= lod_max ({}, {})",
                        s.lod_min, s.lod_max
                    ),
                );
            }
        }
    }

    pub(super) fn check_meshes(&mut self) -> Option<Vec<MeshDesc>> {
        let mut out = Vec::new();
        let mut ok = true;
        for (i, m) in self.raw.meshes.iter().enumerate() {
            let path = self.root.field("meshes").index(i);
            let errors_before = self.diags.error_count();
            self.check_mesh_streams(m, &path);
            let source = self.mesh_source(m, &path);
            self.check_mesh_instances(m, &path);
            match source {
                Some(source) if self.diags.error_count() == errors_before => out.push(MeshDesc {
                    id: MeshId(i as u32),
                    name: m.name.clone(),
                    source,
                    streams: m.streams.clone(),
                    index_format: m.index_format,
                    vertex_count: m.vertex_count,
                    index_count: m.index_count,
                    instance_count: m.instance_count,
                    instances: m.instances.as_ref().and_then(|g| {
                        Some(Seeded {
                            generator: Content::new(&g.name, &g.params)?,
                            seed: g.seed,
                        })
                    }),
                }),
                _ => ok = false,
            }
        }
        ok.then_some(out)
    }

    /// Slots, attributes and locations of a mesh's vertex streams.
    fn check_mesh_streams(&mut self, m: &Mesh, path: &JsonPath) {
        if m.streams.is_empty() {
            self.diags.error(
                "mesh",
                &path.field("streams"),
                format!("mesh \"{}\" has no vertex streams", m.name),
            );
        }
        let mut slots = BTreeSet::new();
        let mut locations = BTreeSet::new();
        for (s, stream) in m.streams.iter().enumerate() {
            let spath = path.field("streams").index(s);
            if !slots.insert(stream.slot) {
                self.diags.error(
                    "mesh",
                    &spath.field("slot"),
                    format!("slot {} is used twice", stream.slot),
                );
            }
            if stream.slot >= 16 {
                self.diags.error(
                    "mesh",
                    &spath.field("slot"),
                    "vertex buffer slots are 0..15",
                );
            }
            if stream.attributes.is_empty() {
                self.diags.error(
                    "mesh",
                    &spath.field("attributes"),
                    "a stream needs at least one attribute",
                );
            }
            for (a, attr) in stream.attributes.iter().enumerate() {
                if !locations.insert(attr.location) {
                    self.diags.error(
                        "mesh",
                        &spath.field("attributes").index(a).field("location"),
                        format!(
                            "location {} is used twice in mesh \"{}\"",
                            attr.location, m.name
                        ),
                    );
                }
            }
            if stream.step == StepMode::Instance && m.instance_count.is_none() {
                self.diags.error(
                    "mesh",
                    path,
                    format!(
                        "mesh \"{}\" has a per-instance stream (slot {}) but no `instance_count`",
                        m.name, stream.slot
                    ),
                );
            }
        }
    }

    /// A mesh's contents: a side file of the size its streams need, or a generator.
    fn mesh_source(&mut self, m: &Mesh, path: &JsonPath) -> Option<MeshSourceDesc> {
        match &m.source {
            MeshSource::File { path: rel } => {
                let fpath = path.field("source").field("file").field("path");
                if m.vertex_count.is_none() {
                    self.diags.error(
                        "mesh",
                        path,
                        format!("mesh \"{}\" from a file needs `vertex_count`", m.name),
                    );
                }
                if m.index_format.is_some() && m.index_count.is_none() {
                    self.diags.error(
                        "mesh",
                        path,
                        format!(
                            "indexed mesh \"{}\" from a file needs `index_count`",
                            m.name
                        ),
                    );
                }
                let resolved = self.side_file(rel, &fpath);
                if let Some(p) = &resolved {
                    let expected = mesh_file_bytes(m);
                    if let (Some(expected), Ok(meta)) = (expected, std::fs::metadata(p))
                        && meta.len() != expected
                    {
                        self.diags.error("side-file", &fpath, format!(
                            "\"{rel}\" has {} bytes; the streams and indices of mesh \"{}\" need {expected}", meta.len(), m.name
                        ));
                    }
                }
                resolved.map(MeshSourceDesc::File)
            }
            MeshSource::Generator { name, seed, params } => {
                let known = self.check_generator_params(
                    generators::MESH_GENERATORS,
                    name,
                    params,
                    &path.field("source").field("generator"),
                );
                Shape::new(name, params).filter(|_| known).map(|generator| {
                    MeshSourceDesc::Generator(Seeded {
                        generator,
                        seed: *seed,
                    })
                })
            }
        }
    }

    /// `instances` applies to generator meshes and names a generator of instance rows.
    fn check_mesh_instances(&mut self, m: &Mesh, path: &JsonPath) {
        if let Some(g) = &m.instances {
            let ipath = path.field("instances");
            if matches!(m.source, MeshSource::File { .. }) {
                self.diags.error(
                "mesh",
                &ipath,
                format!(
                    "mesh \"{}\" reads its instance rows from its side file; `instances` applies to generator meshes",
                    m.name
                ),
            );
            } else if !Content::new(&g.name, &g.params).is_some_and(|c| c.makes_instance_rows()) {
                self.diags.error(
                    "unknown-generator",
                    &ipath.field("name"),
                    format!(
                        "\"{}\" does not make instance rows (use instances or city_lots)",
                        g.name
                    ),
                );
            } else {
                self.check_generator_params(
                    generators::CONTENT_GENERATORS,
                    &g.name,
                    &g.params,
                    &ipath,
                );
            }
        }
    }
}
