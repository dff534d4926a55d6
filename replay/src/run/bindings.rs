//! Bind groups by WGSL variable name: reflection of each variable's slot and view dimension,
//! the `frame` and `params` uniforms, capture bindings for both frame parities, cached views.

use std::collections::{BTreeMap, BTreeSet};

use framelab_core::plan::{BindTarget, Binding, Params, TextureSpec};
use framelab_core::uniforms;

use super::{Groups, ReplayError, Session};
/// The WGSL global variable named `variable`.
pub(super) fn global<'m>(
    module: &'m naga::Module,
    variable: &str,
) -> Option<&'m naga::GlobalVariable> {
    module
        .global_variables
        .iter()
        .find(|(_, v)| v.name.as_deref() == Some(variable))
        .map(|(_, v)| v)
}

pub(super) fn view_dimension(
    module: &naga::Module,
    variable: &str,
) -> Option<wgpu::TextureViewDimension> {
    let var = global(module, variable)?;
    match module.types[var.ty].inner {
        naga::TypeInner::Image { dim, arrayed, .. } => Some(match (dim, arrayed) {
            (naga::ImageDimension::D1, _) => wgpu::TextureViewDimension::D1,
            (naga::ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
            (naga::ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
            (naga::ImageDimension::D3, _) => wgpu::TextureViewDimension::D3,
            (naga::ImageDimension::Cube, false) => wgpu::TextureViewDimension::Cube,
            (naga::ImageDimension::Cube, true) => wgpu::TextureViewDimension::CubeArray,
        }),
        _ => None,
    }
}

/// Whether a texture variable samples unsigned integers: on a depth-stencil texture that is a
/// view of the stencil aspect (D3D12's X32_TYPELESS_G8X24_UINT / X24_TYPELESS_G8_UINT SRVs).
pub(super) fn samples_uint(module: &naga::Module, variable: &str) -> bool {
    global(module, variable).is_some_and(|v| {
        matches!(
            module.types[v.ty].inner,
            naga::TypeInner::Image {
                class: naga::ImageClass::Sampled {
                    kind: naga::ScalarKind::Uint,
                    ..
                },
                ..
            }
        )
    })
}

pub(super) fn binding_slot(module: &naga::Module, variable: &str) -> Option<(u32, u32)> {
    global(module, variable).and_then(|v| v.binding.as_ref().map(|b| (b.group, b.binding)))
}

/// Which bind-group set each draw or dispatch uses: 0 (the pass's) or, when it has its own
/// parameters, the next one made for its pipeline (keyed by entry point).
pub(super) fn set_indices<K: Ord>(items: impl Iterator<Item = (K, bool)>) -> Vec<usize> {
    let mut next: BTreeMap<K, usize> = BTreeMap::new();
    items
        .map(|(key, own)| {
            if own {
                let n = next.entry(key).or_insert(0);
                *n += 1;
                *n
            } else {
                0
            }
        })
        .collect()
}

/// A view of one mip and one layer (or the whole depth of a 3D mip).
pub(crate) fn single_view(
    t: &wgpu::Texture,
    spec: &TextureSpec,
    mip: u32,
    layer: u32,
    format: Option<wgpu::TextureFormat>,
) -> wgpu::TextureView {
    let d3 = spec.dimension == wgpu::TextureDimension::D3;
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some(&spec.name),
        format,
        dimension: Some(if d3 {
            wgpu::TextureViewDimension::D3
        } else {
            wgpu::TextureViewDimension::D2
        }),
        usage: None,
        aspect: wgpu::TextureAspect::All,
        base_mip_level: mip,
        mip_level_count: Some(1),
        base_array_layer: if d3 { 0 } else { layer },
        array_layer_count: Some(1),
    })
}

impl Session {
    /// Globals any of `entries` uses (missing entry points are reported by the caller).
    pub(super) fn used_by<'e>(
        &self,
        module: usize,
        entries: impl Iterator<Item = &'e String>,
    ) -> BTreeSet<String> {
        entries
            .filter_map(|e| self.modules[module].reflection.globals_used_by(e))
            .flatten()
            .collect()
    }

    /// The packed `params` uniform, when the pass's entry points use one.
    pub(super) fn params_buffer(
        &self,
        pass: &str,
        module: usize,
        params: &Params,
        used: &BTreeSet<String>,
    ) -> Result<Option<wgpu::Buffer>, ReplayError> {
        let m = &self.modules[module].reflection.module;
        if uniforms::uniform_struct(m, "params").is_none() || !used.contains("params") {
            if let Some(k) = params.keys().next() {
                return Err(ReplayError::Pass {
                    pass: pass.to_owned(),
                    message: format!(
                        "parameter \"{k}\" given but the shader declares no `params` uniform"
                    ),
                });
            }
            return Ok(None);
        }
        let bytes =
            uniforms::pack(m, "params", params, true).map_err(|source| ReplayError::Params {
                pass: pass.to_owned(),
                source,
            })?;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{pass} params")),
            size: (bytes.len() as u64).max(16),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&buffer, 0, &bytes);
        Ok(Some(buffer))
    }

    /// Bind groups for a pipeline whose entry points use `used`, for both frame parities.
    pub(super) fn bind_groups(
        &self,
        pass: &str,
        module: usize,
        used: &BTreeSet<String>,
        bindings: &[Binding],
        params: Option<&wgpu::Buffer>,
        layout: impl Fn(u32) -> wgpu::BindGroupLayout,
    ) -> Result<Groups, ReplayError> {
        let m = &self.modules[module];
        let err = |message: String| ReplayError::Pass {
            pass: pass.to_owned(),
            message,
        };
        let mut by_group: BTreeMap<u32, Vec<(u32, &str)>> = BTreeMap::new();
        for var in used {
            if let Some((g, b)) = binding_slot(&m.reflection.module, var) {
                by_group.entry(g).or_default().push((b, var.as_str()));
            }
        }
        let mut out: Groups = [Vec::new(), Vec::new()];
        for (parity, slot_groups) in out.iter_mut().enumerate() {
            for (&group, entries) in &by_group {
                let mut views: Vec<(u32, wgpu::TextureView)> = Vec::new();
                let mut resources: Vec<(u32, wgpu::BindingResource<'_>)> = Vec::new();
                for &(slot, var) in entries {
                    if var == "frame" {
                        let (buffer, _) = m
                            .frame_buffer
                            .as_ref()
                            .ok_or_else(|| err("`frame` is not a uniform struct".into()))?;
                        resources.push((slot, buffer.as_entire_binding()));
                        continue;
                    }
                    if var == "params" {
                        let buffer = params
                            .ok_or_else(|| err("the shader's `params` has no values".into()))?;
                        resources.push((slot, buffer.as_entire_binding()));
                        continue;
                    }
                    let b = bindings.iter().find(|b| b.variable == var).ok_or_else(|| {
                        err(format!("shader variable `{var}` (group {group}, binding {slot}) has no binding in the capture"))
                    })?;
                    match &b.target {
                        BindTarget::Texture {
                            texture,
                            format,
                            base_mip,
                            mips,
                            base_layer,
                            layers,
                            previous_frame,
                        } => {
                            let copy = if *previous_frame { 1 - parity } else { parity };
                            let tex = &self.textures[*texture][copy];
                            let spec = &self.plan.textures[*texture];
                            let dimension = view_dimension(&m.reflection.module, var);
                            let aspect = if format.has_stencil_aspect()
                                && samples_uint(&m.reflection.module, var)
                            {
                                wgpu::TextureAspect::StencilOnly
                            } else if format.has_depth_aspect() && format.has_stencil_aspect() {
                                wgpu::TextureAspect::DepthOnly
                            } else {
                                wgpu::TextureAspect::All
                            };
                            let layer_count = if spec.dimension == wgpu::TextureDimension::D3 {
                                None
                            } else {
                                Some(*layers)
                            };
                            let view_format = if format.has_depth_aspect() {
                                None
                            } else {
                                Some(*format)
                            };
                            views.push((
                                slot,
                                tex.create_view(&wgpu::TextureViewDescriptor {
                                    label: Some(var),
                                    format: view_format,
                                    dimension,
                                    usage: None,
                                    aspect,
                                    base_mip_level: *base_mip,
                                    mip_level_count: Some(*mips),
                                    base_array_layer: *base_layer,
                                    array_layer_count: layer_count,
                                }),
                            ));
                        }
                        BindTarget::Buffer {
                            buffer,
                            offset,
                            size,
                            previous_frame,
                        } => {
                            let copy = if *previous_frame { 1 - parity } else { parity };
                            resources.push((
                                slot,
                                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                    buffer: &self.buffers[*buffer][copy],
                                    offset: *offset,
                                    size: size.and_then(wgpu::BufferSize::new),
                                }),
                            ));
                        }
                        BindTarget::Sampler(s) => resources
                            .push((slot, wgpu::BindingResource::Sampler(&self.samplers[*s]))),
                    }
                }
                let mut entries: Vec<wgpu::BindGroupEntry<'_>> = resources
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                for (binding, view) in &views {
                    entries.push(wgpu::BindGroupEntry {
                        binding: *binding,
                        resource: wgpu::BindingResource::TextureView(view),
                    });
                }
                entries.sort_by_key(|e| e.binding);
                let bgl = layout(group);
                let bg = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(pass),
                    layout: &bgl,
                    entries: &entries,
                });
                slot_groups.push((group, bg));
            }
        }
        Ok(out)
    }

    /// Bind-group sets of one pipeline: the pass's, then one per draw or dispatch that has its
    /// own parameters (merged over the pass's). `used`: globals of this pipeline, and of the pass.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn group_sets<'p, L: Fn(u32) -> wgpu::BindGroupLayout>(
        &self,
        name: &str,
        module: usize,
        (used, all_used): (&BTreeSet<String>, &BTreeSet<String>),
        bindings: &[Binding],
        (pass_params, pass_buffer): (&Params, Option<&wgpu::Buffer>),
        own: impl Iterator<Item = &'p Params>,
        layout: &L,
    ) -> Result<Vec<Groups>, ReplayError> {
        let mut sets = vec![self.bind_groups(name, module, used, bindings, pass_buffer, layout)?];
        for params in own {
            let mut merged = pass_params.clone();
            merged.extend(params.clone());
            let buffer = self.params_buffer(name, module, &merged, all_used)?;
            sets.push(self.bind_groups(name, module, used, bindings, buffer.as_ref(), layout)?);
        }
        Ok(sets)
    }

    /// A cached single-mip, single-layer view of copy `copy` of texture `texture`.
    pub(super) fn view(
        &self,
        texture: usize,
        copy: usize,
        mip: u32,
        layer: u32,
        format: Option<wgpu::TextureFormat>,
    ) -> wgpu::TextureView {
        self.views
            .borrow_mut()
            .entry((texture, copy, mip, layer, format))
            .or_insert_with(|| {
                single_view(
                    &self.textures[texture][copy],
                    &self.plan.textures[texture],
                    mip,
                    layer,
                    format,
                )
            })
            .clone()
    }
}
