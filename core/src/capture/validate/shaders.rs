//! Shader files and what passes ask of them: each file is read and validated through naga once
//! (`load_shader`), and each pass's entry points, bindings, parameters and vertex inputs are
//! checked against the reflected interface (`check_shader_use`), so a name the shader does not
//! declare is reported with its JSON path and a suggestion instead of failing the replay.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;

use super::Validator;
use crate::capture::diag::{JsonPath, suggest};
use crate::capture::format::{ParamValue, Pass};
use crate::capture::shaders::{self, Shader, ShaderId, ShaderInterface, Stage};

/// Why a shader file a pass names cannot be used.
#[derive(Debug, thiserror::Error)]
enum ShaderFileError {
    #[error("cannot read {file}: {error}")]
    Read { file: String, error: std::io::Error },
    /// Over the size limit for a shader (or, replaced since it was resolved, not regular).
    #[error("{0}")]
    File(crate::files::FileError),
    #[error("{0}")]
    Invalid(crate::shader::ShaderError),
}

impl<'a> Validator<'a> {
    /// Reads and validates the shader at `resolved` the first time a pass names it.
    pub(super) fn load_shader(
        &mut self,
        file: &str,
        resolved: &Path,
        path: &JsonPath,
    ) -> Option<ShaderId> {
        if let Some(&known) = self.shader_ids.get(resolved) {
            return known;
        }
        let name = resolved.display().to_string();
        let loaded = crate::files::read_to_string(resolved, crate::files::SHADER)
            .map_err(|e| match e {
                crate::files::FileError::Io { error, .. } => ShaderFileError::Read {
                    file: name.clone(),
                    error,
                },
                e => ShaderFileError::File(e),
            })
            .and_then(|source| {
                crate::shader::validate_wgsl(&name, &source)
                    .map(|v| (source, v))
                    .map_err(ShaderFileError::Invalid)
            });
        let id = match loaded {
            Ok((source, validated)) => {
                let id = ShaderId(self.shaders.len() as u32);
                self.shaders.push(Shader {
                    id,
                    file: file.to_owned(),
                    path: resolved.to_owned(),
                    source: source.into(),
                    interface: shaders::reflect(&validated),
                    validated: Arc::new(validated),
                });
                Some(id)
            }
            Err(problem) => {
                self.diags.error("shader", path, problem.to_string());
                None
            }
        };
        self.shader_ids.insert(resolved.to_owned(), id);
        id
    }

    /// Checks that what pass `p` names exists in its shader, with the right stage.
    pub(super) fn check_shader_use(&mut self, p: &Pass, id: ShaderId, path: &JsonPath) {
        let Some(s) = &p.shader else { return };
        let interface = self.shaders[id.index()].interface.clone();
        let file = s.file.as_str();
        let spath = path.field("shader");
        let entries = [
            (&s.vertex, Stage::Vertex, "vertex"),
            (&s.fragment, Stage::Fragment, "fragment"),
            (&s.compute, Stage::Compute, "compute"),
        ];
        for (entry, stage, field) in entries {
            if let Some(entry) = entry {
                self.check_entry(&interface, file, entry, stage, &spath.field(field));
            }
        }
        for (k, d) in p.draws.iter().enumerate() {
            let dpath = path.field("draws").index(k);
            if let Some(entry) = &d.vertex {
                self.check_entry(
                    &interface,
                    file,
                    entry,
                    Stage::Vertex,
                    &dpath.field("vertex"),
                );
            }
            if let Some(entry) = &d.fragment {
                self.check_entry(
                    &interface,
                    file,
                    entry,
                    Stage::Fragment,
                    &dpath.field("fragment"),
                );
            }
            self.check_params(&interface, file, &d.params, &dpath.field("params"));
            let vertex = d.vertex.as_ref().or(s.vertex.as_ref());
            if let Some(inputs) = vertex
                .and_then(|v| interface.entry_points.get(v))
                .map(|e| &e.vertex_inputs)
            {
                self.check_vertex_inputs(inputs, d.mesh.as_deref(), file, &dpath);
            }
        }
        for (k, d) in p.dispatches.iter().enumerate() {
            let dpath = path.field("dispatches").index(k);
            if let Some(entry) = &d.entry {
                self.check_entry(
                    &interface,
                    file,
                    entry,
                    Stage::Compute,
                    &dpath.field("entry"),
                );
            }
            self.check_params(&interface, file, &d.params, &dpath.field("params"));
        }
        for variable in p.bindings.keys() {
            if !interface.bindings.contains_key(variable) {
                let suggestion = suggest(variable, interface.bindings.keys().map(String::as_str));
                self.diags.error_with_suggestion(
                    "binding",
                    &path.field("bindings").field(variable),
                    format!(
                        "pass \"{}\" binds \"{variable}\" but {file} declares no resource variable of that name",
                        p.name
                    ),
                    suggestion,
                );
            }
        }
        // The access each binding declares against what the variable is: wgpu builds the
        // layout from the access, and a mismatch only shows as a GPU validation error.
        for (variable, b) in &p.bindings {
            let Some(kind) = interface.kinds.get(variable) else {
                continue;
            };
            let bpath = path.field("bindings").field(variable);
            match (b.access, &b.resource, &b.sampler) {
                (Some(access), Some(_), _) if !kind.accepts(access) => self.diags.error(
                    "binding-access",
                    &bpath.field("access"),
                    format!(
                        "\"{variable}\" is {} in {file}, but pass \"{}\" binds it for {} access",
                        kind.describe(),
                        p.name,
                        access.as_str()
                    ),
                ),
                (_, Some(_), _) if *kind == crate::capture::shaders::VarKind::Sampler => self.diags.error(
                    "binding-access",
                    &bpath,
                    format!("\"{variable}\" is a sampler in {file}: bind a `sampler`, not a resource"),
                ),
                (_, None, Some(_)) if *kind != crate::capture::shaders::VarKind::Sampler => self.diags.error(
                    "binding-access",
                    &bpath.field("sampler"),
                    format!("\"{variable}\" is {} in {file}, not a sampler", kind.describe()),
                ),
                _ => {}
            }
        }
        self.check_params(&interface, file, &p.params, &path.field("params"));
    }

    fn check_entry(
        &mut self,
        interface: &ShaderInterface,
        file: &str,
        entry: &str,
        stage: Stage,
        path: &JsonPath,
    ) {
        match interface.entry_points.get(entry) {
            Some(e) if e.stage == stage => {}
            Some(e) => self.diags.error(
                "shader",
                path,
                format!(
                    "\"{entry}\" in {file} is a {} entry point, not a {} one",
                    e.stage.name(),
                    stage.name()
                ),
            ),
            None => {
                let same_stage = interface
                    .entry_points
                    .iter()
                    .filter(|(_, e)| e.stage == stage)
                    .map(|(n, _)| n.as_str());
                let suggestion = suggest(entry, same_stage);
                self.diags.error_with_suggestion(
                    "shader",
                    path,
                    format!("{file} has no {} entry point \"{entry}\"", stage.name()),
                    suggestion,
                );
            }
        }
    }

    fn check_params(
        &mut self,
        interface: &ShaderInterface,
        file: &str,
        params: &BTreeMap<String, ParamValue>,
        path: &JsonPath,
    ) {
        let Some(first) = params.keys().next() else {
            return;
        };
        let Some(members) = &interface.params else {
            self.diags.error(
                "parameter",
                &path.field(first),
                format!("parameter \"{first}\" given but {file} declares no `params` uniform"),
            );
            return;
        };
        for key in params.keys().filter(|k| !members.contains(k)) {
            let suggestion = suggest(key, members.iter().map(String::as_str));
            self.diags.error_with_suggestion(
                "parameter",
                &path.field(key),
                format!("{file}'s `params` uniform has no member \"{key}\""),
                suggestion,
            );
        }
    }

    /// Every `@location` the vertex entry point reads must come from the draw's mesh.
    fn check_vertex_inputs(
        &mut self,
        inputs: &BTreeSet<u32>,
        mesh: Option<&str>,
        file: &str,
        path: &JsonPath,
    ) {
        let provided: BTreeSet<u32> = mesh
            .and_then(|name| self.meshes.get(name))
            .map(|i| &self.raw.meshes[i as usize])
            .map(|m| {
                m.streams
                    .iter()
                    .flat_map(|s| s.attributes.iter().map(|a| a.location))
                    .collect()
            })
            .unwrap_or_default();
        if mesh.is_some() && provided.is_empty() {
            return; // An unknown mesh is reported where the draw names it.
        }
        let missing: Vec<String> = inputs
            .difference(&provided)
            .map(|l| format!("@location({l})"))
            .collect();
        if !missing.is_empty() {
            let source = mesh.map_or("a draw without a mesh".to_owned(), |m| {
                format!("mesh \"{m}\"")
            });
            self.diags.error(
                "vertex-input",
                &path.field(if mesh.is_some() { "mesh" } else { "vertex" }),
                format!(
                    "the vertex entry point in {file} reads {} but {source} has no attribute there",
                    missing.join(", ")
                ),
            );
        }
    }
}
