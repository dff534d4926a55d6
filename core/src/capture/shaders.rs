//! Shaders, read and reflected once, at validation. Every WGSL file a capture names is read
//! from disk and validated through naga here, and nowhere else: what the rest of framelab needs
//! from a shader (its entry points with their stage, the globals each one uses, vertex input
//! locations, resource bindings, and the members of the `params` uniform) is kept as plain data
//! in the `Capture`, beside the validated module that lowering hands to the GPU side. So a
//! binding that names a missing variable is a validation error with its JSON path, not a replay
//! failure.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Arc;

use crate::shader::ValidatedShader;

/// Index of a shader in `Capture::shaders`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ShaderId(pub u32);

impl ShaderId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Vertex,
    Fragment,
    Compute,
}

impl Stage {
    pub fn name(self) -> &'static str {
        match self {
            Stage::Vertex => "vertex",
            Stage::Fragment => "fragment",
            Stage::Compute => "compute",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EntryPoint {
    pub stage: Stage,
    /// Names of the global variables it uses, directly or through functions it calls.
    pub globals: BTreeSet<String>,
    /// `@location`s of its vertex inputs (vertex entry points only).
    pub vertex_inputs: BTreeSet<u32>,
    /// (texture, sampler) variable pairs it samples with, directly or in functions it calls.
    pub sampling: BTreeSet<(String, String)>,
    /// `@workgroup_size` (compute entry points; 0s otherwise).
    pub workgroup_size: [u32; 3],
}

/// What framelab reads from a shader, as plain data.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ShaderInterface {
    pub entry_points: BTreeMap<String, EntryPoint>,
    /// Global resource variables (`@group @binding`) by name, with their (group, binding).
    pub bindings: BTreeMap<String, (u32, u32)>,
    /// Members of the `params` uniform struct, when the shader declares one.
    pub params: Option<Vec<String>>,
    /// What each resource variable is, which decides the accesses a binding may declare.
    pub kinds: BTreeMap<String, VarKind>,
}

/// A WGSL resource variable's address space and type, as far as binding accesses depend on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarKind {
    Uniform,
    StorageBuffer {
        writable: bool,
    },
    StorageTexture {
        readable: bool,
        writable: bool,
    },
    /// `texture_*` (sampled, depth or multisampled).
    Texture,
    Sampler,
}

impl VarKind {
    /// The binding accesses this variable accepts, and how WGSL spells the variable.
    pub fn accepts(self, access: crate::capture::format::Access) -> bool {
        use crate::capture::format::Access::*;
        match self {
            VarKind::Uniform => access == Uniform,
            VarKind::StorageBuffer { writable: false } => access == StorageRead,
            VarKind::StorageBuffer { writable: true } => {
                matches!(access, StorageWrite | StorageReadWrite)
            }
            VarKind::StorageTexture {
                readable: true,
                writable: true,
            } => access == StorageReadWrite,
            VarKind::StorageTexture {
                readable: true,
                writable: false,
            } => access == StorageRead,
            VarKind::StorageTexture { .. } => access == StorageWrite,
            VarKind::Texture => access == Sampled,
            VarKind::Sampler => false,
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            VarKind::Uniform => "var<uniform> (access `uniform`)",
            VarKind::StorageBuffer { writable: false } => {
                "var<storage, read> (access `storage_read`)"
            }
            VarKind::StorageBuffer { writable: true } => {
                "var<storage, read_write> (access `storage_read_write` or `storage_write`)"
            }
            VarKind::StorageTexture {
                readable: true,
                writable: true,
            } => "a read_write storage texture (access `storage_read_write`)",
            VarKind::StorageTexture {
                readable: true,
                writable: false,
            } => "a read-only storage texture (access `storage_read`)",
            VarKind::StorageTexture { .. } => {
                "a write-only storage texture (access `storage_write`)"
            }
            VarKind::Texture => "a sampled texture (access `sampled`)",
            VarKind::Sampler => "a sampler (bind a `sampler`, not a resource)",
        }
    }
}

impl ShaderInterface {
    /// Globals used by entry point `entry`, or `None` when the shader has no such entry point.
    pub fn globals_used_by(&self, entry: &str) -> Option<&BTreeSet<String>> {
        self.entry_points.get(entry).map(|e| &e.globals)
    }
}

/// A shader file as validation found it.
#[derive(Clone, Debug)]
pub struct Shader {
    pub id: ShaderId,
    /// As the capture names it (relative to the capture's folder).
    pub file: String,
    pub path: PathBuf,
    pub source: Arc<str>,
    pub interface: ShaderInterface,
    /// The naga module, validated; lowering hands it to the replay unchanged.
    pub validated: Arc<ValidatedShader>,
}

fn stage(s: naga::ShaderStage) -> Option<Stage> {
    match s {
        naga::ShaderStage::Vertex => Some(Stage::Vertex),
        naga::ShaderStage::Fragment => Some(Stage::Fragment),
        naga::ShaderStage::Compute => Some(Stage::Compute),
        _ => None,
    }
}

/// `@location`s of a vertex entry point's arguments, including members of struct arguments.
fn vertex_inputs(module: &naga::Module, entry: &naga::EntryPoint) -> BTreeSet<u32> {
    let mut out = BTreeSet::new();
    for arg in &entry.function.arguments {
        if let Some(naga::Binding::Location { location, .. }) = arg.binding {
            out.insert(location);
        } else if let naga::TypeInner::Struct { members, .. } = &module.types[arg.ty].inner {
            for m in members {
                if let Some(naga::Binding::Location { location, .. }) = m.binding {
                    out.insert(location);
                }
            }
        }
    }
    out
}

/// Reflects a validated module into the interface framelab reads.
pub fn reflect(shader: &ValidatedShader) -> ShaderInterface {
    let module = &shader.module;
    let mut entry_points = BTreeMap::new();
    for (index, e) in module.entry_points.iter().enumerate() {
        let Some(st) = stage(e.stage) else { continue };
        let info = shader.info.get_entry_point(index);
        let globals = module
            .global_variables
            .iter()
            .filter(|(handle, _)| !info[*handle].is_empty())
            .filter_map(|(_, var)| var.name.clone())
            .collect();
        let name_of = |h: naga::Handle<naga::GlobalVariable>| {
            module.global_variables[h].name.clone().unwrap_or_default()
        };
        let sampling = info
            .sampling_set
            .iter()
            .map(|k| (name_of(k.image), name_of(k.sampler)))
            .collect();
        let inputs = if st == Stage::Vertex {
            vertex_inputs(module, e)
        } else {
            BTreeSet::new()
        };
        entry_points.insert(
            e.name.clone(),
            EntryPoint {
                stage: st,
                globals,
                vertex_inputs: inputs,
                sampling,
                workgroup_size: e.workgroup_size,
            },
        );
    }
    let bindings = module
        .global_variables
        .iter()
        .filter_map(|(_, var)| {
            let b = var.binding.as_ref()?;
            Some((var.name.clone()?, (b.group, b.binding)))
        })
        .collect();
    let kinds = module
        .global_variables
        .iter()
        .filter_map(|(_, var)| {
            var.binding.as_ref()?;
            let kind = match var.space {
                naga::AddressSpace::Uniform => VarKind::Uniform,
                naga::AddressSpace::Storage { access } => VarKind::StorageBuffer {
                    writable: access.contains(naga::StorageAccess::STORE),
                },
                _ => match &module.types[var.ty].inner {
                    naga::TypeInner::Image {
                        class: naga::ImageClass::Storage { access, .. },
                        ..
                    } => VarKind::StorageTexture {
                        readable: access.contains(naga::StorageAccess::LOAD),
                        writable: access.contains(naga::StorageAccess::STORE),
                    },
                    naga::TypeInner::Image { .. } => VarKind::Texture,
                    naga::TypeInner::Sampler { .. } => VarKind::Sampler,
                    _ => return None,
                },
            };
            Some((var.name.clone()?, kind))
        })
        .collect();
    let params = crate::uniforms::uniform_struct(module, "params").map(|(_, m)| m);
    ShaderInterface {
        entry_points,
        bindings,
        params,
        kinds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_points_report_their_stage_globals_and_vertex_inputs() {
        let src = "
            struct Params { tint: vec4<f32>, gain: f32 }
            @group(0) @binding(0) var<uniform> params: Params;
            @group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
            @group(0) @binding(2) var albedo: texture_2d<f32>;
            struct In { @location(0) p: vec3<f32>, @location(3) uv: vec2<f32> }
            fn fetch(i: u32) -> vec4<f32> { return positions[i]; }
            @vertex fn vs(v: In, @location(5) extra: f32, @builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> { return fetch(i) + vec4(v.p, extra); }
            @fragment fn fs() -> @location(0) vec4<f32> { return textureLoad(albedo, vec2<i32>(0, 0), 0) * params.tint; }
        ";
        let shader = crate::shader::validate_wgsl("s.wgsl", src).unwrap();
        let i = reflect(&shader);
        let vs = &i.entry_points["vs"];
        assert_eq!(vs.stage, Stage::Vertex);
        assert_eq!(vs.globals.iter().collect::<Vec<_>>(), ["positions"]);
        assert_eq!(
            vs.vertex_inputs.iter().copied().collect::<Vec<_>>(),
            [0, 3, 5]
        );
        let fs = &i.entry_points["fs"];
        assert_eq!(fs.stage, Stage::Fragment);
        assert_eq!(fs.globals.iter().collect::<Vec<_>>(), ["albedo", "params"]);
        assert!(fs.sampling.is_empty(), "textureLoad takes no sampler");
        assert_eq!(i.bindings["albedo"], (0, 2));
        assert_eq!(
            i.params.as_deref(),
            Some(&["tint".to_owned(), "gain".to_owned()][..])
        );
        assert!(i.globals_used_by("missing").is_none());
    }

    #[test]
    fn sampling_pairs_follow_calls() {
        let src = "
            @group(0) @binding(0) var noise: texture_2d<f32>;
            @group(0) @binding(1) var aniso: sampler;
            fn look(uv: vec2<f32>) -> vec4<f32> { return textureSample(noise, aniso, uv); }
            @fragment fn fs(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> { return look(uv); }
        ";
        let shader = crate::shader::validate_wgsl("s.wgsl", src).unwrap();
        let i = reflect(&shader);
        assert_eq!(
            i.entry_points["fs"].sampling.iter().collect::<Vec<_>>(),
            [&("noise".to_owned(), "aniso".to_owned())]
        );
    }
}
