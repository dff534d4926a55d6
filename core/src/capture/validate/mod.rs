//! Semantic validation: `RawCapture` in, `Capture` out, or every problem found.
//!
//! The rules come from D3D12 and Vulkan: heap property and flag rules per resource-heap tier,
//! placement alignment, resource flag combinations, format versus usage, binding access versus
//! resource flags, and what each queue type may execute (Vulkan's pipeline-stage/queue table).
//! Limits are checked before anything is sized or allocated, with arithmetic that cannot
//! overflow. Unknown names get a did-you-mean suggestion.

use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};

mod attachment_clears;
mod bindings;
mod blits;
mod copies;
mod descriptors;
mod hazards;
mod heaps;
mod passes;
mod placement;
mod resources;
mod shaders;
mod vk_values;
mod vulkan;
mod work;

use super::diag::{Diagnostic, Diagnostics, JsonPath, suggest};
use super::format::*;
use super::generators::{self, GeneratorSpec};
use super::load::CaptureError;
use super::model::*;
use super::shaders::{Shader, ShaderId};
use crate::capture::dxgi::{self, FormatInfo};

/// Hardware limits checked before anything is allocated (D3D12 feature level 12 values).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_texture_1d: u32,
    pub max_texture_2d: u32,
    pub max_texture_3d: u32,
    pub max_array_layers: u32,
    pub max_buffer_bytes: u64,
    /// Sum of every resource's bytes.
    pub max_total_bytes: u64,
    pub max_dispatch_groups: u32,
    pub max_cbv_srv_uav_descriptors: u32,
    pub max_sampler_descriptors: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_texture_1d: 16384,
            max_texture_2d: 16384,
            max_texture_3d: 2048,
            max_array_layers: 2048,
            max_buffer_bytes: 1 << 32,
            max_total_bytes: 32 << 30,
            max_dispatch_groups: 65535,
            max_cbv_srv_uav_descriptors: 1_000_000,
            max_sampler_descriptors: 2048,
        }
    }
}

/// How to resolve and check a capture.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Multiplies the output resolution; relative sizes follow it.
    pub scale: f64,
    pub limits: Limits,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            scale: 1.0,
            limits: Limits::default(),
        }
    }
}

/// A valid capture and the warnings found on the way.
#[derive(Debug)]
pub struct Validated {
    pub capture: Capture,
    pub warnings: Vec<Diagnostic>,
}

/// Validates a parsed capture; `path` locates side files and names the file in messages.
pub fn validate(
    raw: &RawCapture,
    path: &Path,
    options: &Options,
) -> Result<Validated, CaptureError> {
    // Side files lie beside the capture file itself, which a link may lead elsewhere (where an
    // import through the link put them).
    let real = crate::atomic::destination(path).map_or_else(|_| path.to_path_buf(), |d| d.path);
    let base_dir = real.parent().map(Path::to_path_buf).unwrap_or_default();
    let base_dir = if base_dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        base_dir
    };
    crate::capture::diag::reset_suggestion_budget();
    let mut v = Validator::new(raw, base_dir, options);
    let capture = v.run(path);
    let diagnostics = v.diags.into_vec();
    match capture {
        Some(capture)
            if !diagnostics
                .iter()
                .any(|d| d.severity == super::diag::Severity::Error) =>
        {
            Ok(Validated {
                capture,
                warnings: diagnostics,
            })
        }
        _ => Err(CaptureError::Invalid {
            path: path.to_owned(),
            diagnostics,
        }),
    }
}

/// Name -> index tables for one kind of object, with the names for suggestions.
#[derive(Default)]
struct Names<'a> {
    map: HashMap<&'a str, u32>,
    order: Vec<&'a str>,
}

impl<'a> Names<'a> {
    fn get(&self, name: &str) -> Option<u32> {
        self.map.get(name).copied()
    }
}

struct Validator<'a> {
    raw: &'a RawCapture,
    base_dir: PathBuf,
    options: &'a Options,
    diags: Diagnostics,
    root: JsonPath,
    resources: Names<'a>,
    heaps: Names<'a>,
    queues: Names<'a>,
    meshes: Names<'a>,
    samplers: Names<'a>,
    fences: Names<'a>,
    /// Resolved output size.
    width: u32,
    height: u32,
    /// Side files already found inside the capture's folder, by the path the capture gives:
    /// thousands of passes naming one shader resolve it once.
    side_files: HashMap<String, PathBuf>,
    /// Shaders read so far, and the id (or failure) of each file by resolved path.
    shaders: Vec<Shader>,
    shader_ids: HashMap<PathBuf, Option<ShaderId>>,
    /// Resources some pass so far has written: a read of a `history` resource that none has
    /// sees the previous frame's copy, a different texture from the one rendered to.
    written: std::collections::HashSet<ResourceId>,
    /// The `vulkan` section by index, once it validated.
    vk_model: Option<crate::capture::vk_model::VkModel>,
    vk_names: Option<vulkan::VkNames>,
}

/// Bytes of indirect argument records (D3D12_DRAW_INDEXED_ARGUMENTS, D3D12_DRAW_ARGUMENTS,
/// D3D12_DISPATCH_ARGUMENTS).
const DRAW_INDEXED_ARGS: u64 = 20;
const DRAW_ARGS: u64 = 16;
const DISPATCH_ARGS: u64 = 12;
const PLACEMENT_ALIGNMENT: u64 = 64 << 10;
const MSAA_PLACEMENT_ALIGNMENT: u64 = 4 << 20;

impl<'a> Validator<'a> {
    fn new(raw: &'a RawCapture, base_dir: PathBuf, options: &'a Options) -> Self {
        Self {
            raw,
            base_dir,
            options,
            diags: Diagnostics::default(),
            root: JsonPath::root(),
            resources: Names::default(),
            heaps: Names::default(),
            queues: Names::default(),
            meshes: Names::default(),
            samplers: Names::default(),
            fences: Names::default(),
            width: 1,
            height: 1,
            side_files: HashMap::new(),
            shaders: Vec::new(),
            shader_ids: HashMap::new(),
            written: std::collections::HashSet::new(),
            vk_model: None,
            vk_names: None,
        }
    }

    /// The scale sizes are resolved at: an imported frame keeps the application's sizes, so
    /// its output resolution is the application's whatever `--scale` says (a range check
    /// still refuses a scale that is no scale at all).
    fn scale(&self) -> f64 {
        if self.raw.source.is_some() {
            1.0
        } else {
            self.options.scale
        }
    }

    fn run(&mut self, path: &Path) -> Option<Capture> {
        self.check_top_level();
        if self.diags.has_errors() && !(self.options.scale.is_finite() && self.options.scale > 0.0)
        {
            // Every relative size would be wrong; one message says why.
            return None;
        }
        self.collect_names();
        let heaps = self.check_heaps();
        let resources = self.check_resources(&heaps);
        let descriptor_heaps = self.check_descriptor_heaps();
        self.check_samplers();
        self.check_vulkan();
        self.check_vk_values();
        let queues: Vec<QueueDesc> = self
            .raw
            .queues
            .iter()
            .enumerate()
            .map(|(i, q)| QueueDesc {
                id: QueueId(i as u32),
                name: q.name.clone(),
                queue_type: q.queue_type,
            })
            .collect();
        let meshes = self.check_meshes();
        let passes = self.check_passes(&resources, &heaps, &meshes);
        self.check_fences(&passes);
        let resources = resources?;
        let passes = passes?;
        Some(Capture {
            name: self.raw.name.clone(),
            description: self.raw.description.clone(),
            source: path.to_owned(),
            base_dir: self.base_dir.clone(),
            scale: self.scale(),
            width: self.width,
            height: self.height,
            adapter: self.raw.adapter.clone(),
            camera: self.raw.camera.clone(),
            frame: self.raw.frame.clone(),
            heaps,
            resources,
            descriptor_heaps,
            samplers: self.raw.samplers.clone(),
            queues,
            fences: self.raw.fences.iter().map(|f| f.name.clone()).collect(),
            meshes: meshes?,
            passes,
            shaders: std::mem::take(&mut self.shaders),
            origin: self.raw.source.clone(),
            vulkan: self.vk_model.take(),
        })
    }

    // Top level and names

    fn check_top_level(&mut self) {
        let raw = self.raw;
        let path = self.root.field("resolution");
        let scale = self.options.scale;
        if !(scale.is_finite() && scale > 0.0 && scale <= 16.0) {
            self.diags.error(
                "scale",
                &self.root,
                format!("--scale {scale} must be in (0, 16]"),
            );
        }
        if raw.resolution.width == 0 || raw.resolution.height == 0 {
            self.diags
                .error("resolution", &path, "resolution must be at least 1x1");
        }
        let scale = self.scale();
        let scaled =
            |v: u32| ((f64::from(v) * scale).round() as u64).clamp(1, u64::from(u32::MAX)) as u32;
        self.width = scaled(raw.resolution.width.max(1));
        self.height = scaled(raw.resolution.height.max(1));
        let max2d = self.options.limits.max_texture_2d;
        if self.width > max2d || self.height > max2d {
            self.diags.error(
                "limit",
                &path,
                format!(
                    "output {}x{} at scale {scale} exceeds the maximum 2D texture size {max2d}",
                    self.width, self.height
                ),
            );
        }
        if raw.name.trim().is_empty() {
            self.diags
                .error("name", &self.root.field("name"), "capture name is empty");
        } else if raw.name.chars().any(char::is_control) {
            self.diags.error(
                "name",
                &self.root.field("name"),
                format!(
                    "capture name \"{}\" holds a control character",
                    crate::text::one_line(&raw.name)
                ),
            );
        }
        if !matches!(raw.adapter.resource_heap_tier, 1 | 2) {
            self.diags.error(
                "heap-tier",
                &self.root.field("adapter").field("resource_heap_tier"),
                format!(
                    "resource_heap_tier must be 1 or 2, not {}",
                    raw.adapter.resource_heap_tier
                ),
            );
        }
        let cam = &raw.camera;
        let cpath = self.root.field("camera");
        if !(cam.fov_y_degrees > 0.0 && cam.fov_y_degrees < 180.0) {
            self.diags.error(
                "camera",
                &cpath.field("fov_y_degrees"),
                "fov_y_degrees must be in (0, 180)",
            );
        }
        if !(cam.near > 0.0 && cam.far > cam.near) {
            self.diags.error(
                "camera",
                &cpath.field("far"),
                format!("need 0 < near < far (near {}, far {})", cam.near, cam.far),
            );
        }
        let sc = &raw.frame.shadow_cascades;
        let spath = self.root.field("frame").field("shadow_cascades");
        if !(1..=16384).contains(&sc.resolution) {
            self.diags.error(
                "frame",
                &spath.field("resolution"),
                format!(
                    "shadow map resolution must be in 1..=16384, not {}",
                    sc.resolution
                ),
            );
        }
        if !(0.0..=1.0).contains(&sc.split_lambda) {
            self.diags.error(
                "frame",
                &spath.field("split_lambda"),
                format!("split_lambda must be in [0, 1], not {}", sc.split_lambda),
            );
        }
        if sc.max_distance.is_nan() || sc.max_distance <= cam.near {
            self.diags.error(
                "frame",
                &spath.field("max_distance"),
                format!(
                    "max_distance {} must exceed the camera's near plane {}",
                    sc.max_distance, cam.near
                ),
            );
        }
        if raw.frame.top_view_extent.is_nan() || raw.frame.top_view_extent <= 0.0 {
            self.diags.error(
                "frame",
                &self.root.field("frame").field("top_view_extent"),
                "top_view_extent must be positive",
            );
        }
        if cam.position == cam.target {
            self.diags.error(
                "camera",
                &cpath.field("target"),
                "camera target equals its position",
            );
        }
        if raw.queues.is_empty() {
            self.diags.error(
                "queues",
                &self.root.field("queues"),
                "a capture needs at least one queue",
            );
        }
    }

    fn collect_names(&mut self) {
        fn build<'a, T>(
            diags: &mut Diagnostics,
            root: &JsonPath,
            section: &str,
            items: &'a [T],
            name: impl Fn(&'a T) -> &'a str,
        ) -> Names<'a> {
            let mut names = Names::default();
            for (i, item) in items.iter().enumerate() {
                let n = name(item);
                let path = root.field(section).index(i).field("name");
                if n.trim().is_empty() {
                    diags.error("name", &path, format!("{section}[{i}] has an empty name"));
                    continue;
                }
                // Names are shown in terminals, tables, graphs and file names.
                if n.chars().any(char::is_control) {
                    diags.error(
                        "name",
                        &path,
                        format!(
                            "{section}[{i}] name \"{}\" holds a control character",
                            crate::text::one_line(n)
                        ),
                    );
                }
                if let Some(first) = names.map.insert(n, i as u32) {
                    diags.error(
                        "duplicate-name",
                        &path,
                        format!("duplicate name \"{n}\" (first defined at {section}[{first}])"),
                    );
                    names.map.insert(n, first);
                } else {
                    names.order.push(n);
                }
            }
            names
        }
        let raw = self.raw;
        let d = &mut self.diags;
        let r = &self.root;
        self.resources = build(d, r, "resources", &raw.resources, |x| &x.name);
        self.heaps = build(d, r, "heaps", &raw.heaps, |x| &x.name);
        self.queues = build(d, r, "queues", &raw.queues, |x| &x.name);
        self.meshes = build(d, r, "meshes", &raw.meshes, |x| &x.name);
        self.samplers = build(d, r, "samplers", &raw.samplers, |x| &x.name);
        self.fences = build(d, r, "fences", &raw.fences, |x| &x.name);
        build(d, r, "passes", &raw.passes, |x| &x.name);
        build(d, r, "descriptor_heaps", &raw.descriptor_heaps, |x| &x.name);
    }

    /// Looks a name up, reporting an unknown one with a suggestion.
    fn lookup(&mut self, kind: &'static str, name: &str, path: &JsonPath) -> Option<u32> {
        let names = match kind {
            "resource" => &self.resources,
            "heap" => &self.heaps,
            "queue" => &self.queues,
            "mesh" => &self.meshes,
            "sampler" => &self.samplers,
            _ => &self.fences,
        };
        if let Some(i) = names.get(name) {
            return Some(i);
        }
        let suggestion = suggest(name, names.order.iter().copied());
        let code = match kind {
            "resource" => "unknown-resource",
            "heap" => "unknown-heap",
            "queue" => "unknown-queue",
            "mesh" => "unknown-mesh",
            "sampler" => "unknown-sampler",
            _ => "unknown-fence",
        };
        self.diags.error_with_suggestion(
            code,
            path,
            format!("unknown {kind} \"{name}\""),
            suggestion,
        );
        None
    }

    /// Whether the capture was imported from a Vulkan stream: clears are transfer writes,
    /// placements follow the alignment the driver reported, uniform ranges follow the device.
    fn vulkan(&self) -> bool {
        self.raw
            .source
            .as_ref()
            .is_some_and(crate::capture::format::CaptureSource::is_vulkan)
    }

    /// Whether the capture says it cannot be replayed (an import without shader code).
    fn not_replayable(&self) -> bool {
        self.raw
            .source
            .as_ref()
            .is_some_and(|s| s.not_replayable.is_some())
    }

    fn lookup_format(&mut self, name: &str, path: &JsonPath) -> Option<&'static FormatInfo> {
        if let Some(f) = dxgi::lookup(name) {
            if f.name == "UNKNOWN" {
                self.diags
                    .error("format", path, "format UNKNOWN is not a resource format");
                return None;
            }
            return Some(f);
        }
        let upper = name.to_ascii_uppercase();
        let suggestion = suggest(&upper, dxgi::names());
        self.diags.error_with_suggestion(
            "unknown-format",
            path,
            format!("unknown DXGI format \"{name}\""),
            suggestion,
        );
        None
    }

    /// Resolves a path relative to the capture, refusing anything outside its folder.
    fn side_file(&mut self, rel: &str, path: &JsonPath) -> Option<PathBuf> {
        let p = Path::new(rel);
        if rel.is_empty() {
            self.diags.error("side-file", path, "empty file path");
            return None;
        }
        if p.is_absolute() || p.has_root() {
            self.diags.error(
                "side-file",
                path,
                format!("\"{rel}\" is absolute; side files are paths relative to the capture"),
            );
            return None;
        }
        let mut depth: i32 = 0;
        for c in p.components() {
            match c {
                Component::ParentDir => depth -= 1,
                Component::Normal(_) => depth += 1,
                Component::CurDir => {}
                Component::RootDir | Component::Prefix(_) => depth = -1,
            }
            if depth < 0 {
                self.diags.error(
                    "side-file",
                    path,
                    format!("\"{rel}\" escapes the capture's folder"),
                );
                return None;
            }
        }
        if let Some(full) = self.side_files.get(rel) {
            return Some(full.clone());
        }
        let full = self.base_dir.join(p);
        // Only regular files are read: a FIFO would block, a device never end.
        let problem = match std::fs::metadata(&full) {
            Ok(meta) if meta.is_file() => None,
            Ok(meta) => Some(format!(
                "side file \"{rel}\" is {}, not a regular file ({})",
                crate::files::kind(&meta.file_type()),
                full.display()
            )),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some(format!(
                "side file \"{rel}\" not found (looked at {})",
                full.display()
            )),
            Err(e) => Some(format!(
                "side file \"{rel}\" cannot be read ({}): {e}",
                full.display()
            )),
        };
        if let Some(message) = problem {
            self.diags.error("side-file", path, message);
            return None;
        }
        // A symlink inside the folder may still point outside it.
        match (full.canonicalize(), self.base_dir.canonicalize()) {
            (Ok(f), Ok(b)) if f.starts_with(&b) => {
                self.side_files.insert(rel.to_owned(), full.clone());
                Some(full)
            }
            (Ok(_), Ok(_)) => {
                self.diags.error(
                    "side-file",
                    path,
                    format!("\"{rel}\" resolves outside the capture's folder"),
                );
                None
            }
            (Err(e), _) | (_, Err(e)) => {
                self.diags
                    .error("side-file", path, format!("cannot resolve \"{rel}\": {e}"));
                None
            }
        }
    }

    /// Checks a generator's name and parameters against `table`; `true` when both are known.
    fn check_generator_params(
        &mut self,
        table: &[GeneratorSpec],
        name: &str,
        params: &BTreeMap<String, ParamValue>,
        path: &JsonPath,
    ) -> bool {
        let errors_before = self.diags.error_count();
        let Some(spec) = generators::find(table, name) else {
            let suggestion = suggest(name, table.iter().map(|g| g.name));
            let known: Vec<&str> = table.iter().map(|g| g.name).collect();
            self.diags.error_with_suggestion(
                "unknown-generator",
                &path.field("name"),
                format!("unknown generator \"{name}\" (known: {})", known.join(", ")),
                suggestion,
            );
            return false;
        };
        for (key, value) in params {
            let ppath = path.field("params").field(key);
            if !spec.params.iter().any(|(p, _)| p == key) {
                let suggestion = suggest(key, spec.params.iter().map(|(p, _)| *p));
                self.diags.error_with_suggestion(
                    "unknown-parameter",
                    &ppath,
                    format!("generator \"{name}\" has no parameter \"{key}\""),
                    suggestion,
                );
            } else if let ParamValue::Scalar(x) = value {
                if !x.is_finite() {
                    self.diags
                        .error("parameter", &ppath, "parameter must be finite");
                } else if let Some(max) = generators::param_limit(key)
                    && x.abs() > max
                {
                    self.diags.error(
                        "limit",
                        &ppath,
                        format!(
                            "generator parameter \"{key}\" = {x} is over its limit of {max} (the work it drives grows with it)"
                        ),
                    );
                }
            } else {
                self.diags.error(
                    "parameter",
                    &ppath,
                    format!("generator parameter \"{key}\" takes one number"),
                );
            }
        }
        self.diags.error_count() == errors_before
    }
}

fn describe_allows(a: HeapAllows) -> String {
    let mut parts = Vec::new();
    if a.buffers {
        parts.push("buffers");
    }
    if a.rt_ds_textures {
        parts.push("RT/DS textures");
    }
    if a.other_textures {
        parts.push("non-RT/DS textures");
    }
    if parts.is_empty() {
        "nothing".to_owned()
    } else {
        parts.join(" + ")
    }
}

fn is_depth_family(f: &FormatInfo) -> bool {
    matches!(
        f.name,
        "R16_TYPELESS" | "R32_TYPELESS" | "R24G8_TYPELESS" | "R32G8X24_TYPELESS"
    )
}

fn view_dimension_ok(resource: ResourceKind, view: ResourceKind) -> bool {
    use ResourceKind::*;
    resource == view
        || matches!(
            (resource, view),
            (TextureCube, Texture2DArray)
                | (TextureCube, Texture2D)
                | (Texture2DArray, Texture2D)
                | (Texture2D, Texture2DArray)
                | (Texture2DArray, TextureCube)
        )
}

/// Bytes a mesh side file must hold: per-vertex streams, per-instance streams, then indices.
fn mesh_file_bytes(m: &Mesh) -> Option<u64> {
    let mut total: u64 = 0;
    for s in &m.streams {
        let stride: u64 = s
            .attributes
            .iter()
            .map(|a| u64::from(a.format.size()))
            .sum();
        let count = match s.step {
            StepMode::Vertex => m.vertex_count?,
            StepMode::Instance => m.instance_count?,
        };
        total = total.checked_add(stride.checked_mul(u64::from(count))?)?;
    }
    if let Some(f) = m.index_format {
        total = total.checked_add(u64::from(f.size()).checked_mul(u64::from(m.index_count?))?)?;
    }
    Some(total)
}
