//! Semantic validation: `RawCapture` in, `Capture` out, or every problem found.
//!
//! The rules come from D3D12 and Vulkan: heap property and flag rules per resource-heap tier,
//! placement alignment, resource flag combinations, format versus usage, binding access versus
//! resource flags, and what each queue type may execute (Vulkan's pipeline-stage/queue table).
//! Limits are checked before anything is sized or allocated, with arithmetic that cannot
//! overflow. Unknown names get a did-you-mean suggestion.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Component, Path, PathBuf};

use super::diag::{Diagnostic, Diagnostics, JsonPath, suggest};
use super::format::*;
use super::generators::{self, GeneratorSpec};
use super::load::{self, CaptureError};
use super::model::*;
use crate::dxgi::{self, FormatInfo};

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

/// Reads, parses and validates a capture file.
pub fn load(path: &Path, options: &Options) -> Result<Validated, CaptureError> {
    let raw = load::read(path)?;
    validate(&raw, path, options)
}

/// Validates a parsed capture; `path` locates side files and names the file in messages.
pub fn validate(
    raw: &RawCapture,
    path: &Path,
    options: &Options,
) -> Result<Validated, CaptureError> {
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let base_dir = if base_dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        base_dir
    };
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
            scale: self.options.scale,
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
        })
    }

    // -----------------------------------------------------------------------------------------
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
        if !full.is_file() {
            self.diags.error(
                "side-file",
                path,
                format!(
                    "side file \"{rel}\" not found (looked at {})",
                    full.display()
                ),
            );
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

    fn check_generator_params(
        &mut self,
        table: &[GeneratorSpec],
        name: &str,
        params: &BTreeMap<String, ParamValue>,
        path: &JsonPath,
    ) {
        let Some(spec) = generators::find(table, name) else {
            let suggestion = suggest(name, table.iter().map(|g| g.name));
            let known: Vec<&str> = table.iter().map(|g| g.name).collect();
            self.diags.error_with_suggestion(
                "unknown-generator",
                &path.field("name"),
                format!("unknown generator \"{name}\" (known: {})", known.join(", ")),
                suggestion,
            );
            return;
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
                }
            } else {
                self.diags.error(
                    "parameter",
                    &ppath,
                    format!("generator parameter \"{key}\" takes one number"),
                );
            }
        }
    }

    // -----------------------------------------------------------------------------------------
    // Heaps

    fn check_heaps(&mut self) -> Vec<HeapDesc> {
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
                        h.name, heap_type_name(h.heap_type)
                    ));
                }
                if h.memory_pool != MemoryPool::Unknown {
                    self.diags.error("heap-properties", &path.field("memory_pool"), format!(
                        "heap \"{}\" is {}: memory_pool must be UNKNOWN unless the type is CUSTOM",
                        h.name, heap_type_name(h.heap_type)
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
                        h.name, page_name(h.cpu_page_property)
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

    // -----------------------------------------------------------------------------------------
    // Resources

    fn resolve_extent(&mut self, e: &Extent, output: u32, path: &JsonPath) -> Option<u32> {
        let out = f64::from(output);
        let (value, multiple) = match e {
            Extent::Texels(v) => {
                return match u32::try_from(*v) {
                    Ok(0) | Err(_) => {
                        self.diags.error(
                            "size",
                            path,
                            format!("size {v} must be between 1 and {}", u32::MAX),
                        );
                        None
                    }
                    Ok(v) => Some(v),
                };
            }
            Extent::Named(RelativeSize::Full) => (out, None),
            Extent::Named(RelativeSize::Half) => ((out / 2.0).ceil(), None),
            Extent::Named(RelativeSize::Quarter) => ((out / 4.0).ceil(), None),
            Extent::Scaled { scale, multiple_of } => {
                if !(scale.is_finite() && *scale > 0.0 && *scale <= 16.0) {
                    self.diags.error(
                        "size",
                        path,
                        format!("relative scale {scale} must be in (0, 16]"),
                    );
                    return None;
                }
                if *multiple_of == Some(0) {
                    self.diags.error(
                        "size",
                        &path.field("multiple_of"),
                        "multiple_of must be at least 1",
                    );
                    return None;
                }
                ((out * scale).ceil(), *multiple_of)
            }
        };
        let mut v = value.max(1.0) as u64;
        if let Some(m) = multiple {
            v = v.div_ceil(u64::from(m)) * u64::from(m);
        }
        u32::try_from(v).ok().or_else(|| {
            self.diags.error("size", path, "resolved size overflows");
            None
        })
    }

    fn check_resources(&mut self, heaps: &[HeapDesc]) -> Option<Vec<ResourceDesc>> {
        let raw = self.raw;
        let mut out = Vec::new();
        let mut total: u64 = 0;
        let mut ok = true;
        for (i, r) in raw.resources.iter().enumerate() {
            let path = self.root.field("resources").index(i);
            match self.check_resource(i, r, &path, heaps) {
                Some(desc) => {
                    total = total.saturating_add(desc.bytes);
                    out.push(desc);
                }
                None => ok = false,
            }
        }
        let max = self.options.limits.max_total_bytes;
        if total > max {
            self.diags.error(
                "limit",
                &self.root.field("resources"),
                format!(
                    "resources declare {} in total, over the limit of {}; nothing was allocated",
                    human_bytes(total),
                    human_bytes(max)
                ),
            );
            ok = false;
        }
        ok.then_some(out)
    }

    fn check_resource(
        &mut self,
        index: usize,
        r: &Resource,
        path: &JsonPath,
        heaps: &[HeapDesc],
    ) -> Option<ResourceDesc> {
        let limits = self.options.limits;
        let errors_before = self.diags.error_count();
        let flags: BTreeSet<ResourceFlag> = r.flags.iter().copied().collect();
        let format = r
            .format
            .as_deref()
            .and_then(|f| self.lookup_format(f, &path.field("format")));
        let (mut width, mut height, mut depth, mut layers, mut mips, mut samples) =
            (1u32, 1u32, 1u32, 1u32, 1u32, 1u32);
        let mut bytes: u64 = 0;

        if r.kind == ResourceKind::Buffer {
            for (field, present) in [
                ("width", r.width.is_some()),
                ("height", r.height.is_some()),
                ("depth", r.depth.is_some()),
                ("array_layers", r.array_layers.is_some()),
                ("mip_levels", r.mip_levels.is_some()),
                ("samples", r.samples.is_some()),
            ] {
                if present {
                    self.diags.error(
                        "resource-kind",
                        &path.field(field),
                        format!("buffer \"{}\" cannot have `{field}`", r.name),
                    );
                }
            }
            match r.size {
                None => self.diags.error(
                    "resource-size",
                    path,
                    format!("buffer \"{}\" needs a `size` in bytes", r.name),
                ),
                Some(0) => self.diags.error(
                    "resource-size",
                    &path.field("size"),
                    "buffer size must be non-zero",
                ),
                Some(s) if s > limits.max_buffer_bytes => self.diags.error(
                    "limit",
                    &path.field("size"),
                    format!(
                        "buffer \"{}\" of {} exceeds the maximum buffer size {}",
                        r.name,
                        human_bytes(s),
                        human_bytes(limits.max_buffer_bytes)
                    ),
                ),
                Some(s) => bytes = s,
            }
            let kind = r.buffer_kind.unwrap_or(BufferKind::Raw);
            match (kind, r.stride) {
                (BufferKind::Structured, None) => self.diags.error(
                    "buffer-stride",
                    path,
                    format!("structured buffer \"{}\" needs a `stride`", r.name),
                ),
                (BufferKind::Structured, Some(0)) => self.diags.error(
                    "buffer-stride",
                    &path.field("stride"),
                    "stride must be non-zero",
                ),
                (BufferKind::Structured, Some(s)) if !bytes.is_multiple_of(u64::from(s)) => {
                    self.diags.error("buffer-stride", &path.field("size"), format!(
                            "structured buffer \"{}\": size {bytes} is not a multiple of stride {s}", r.name
                        ));
                }
                (BufferKind::ByteAddress, _) if !bytes.is_multiple_of(4) => self.diags.error(
                    "buffer-stride",
                    &path.field("size"),
                    format!(
                        "byte-address buffer \"{}\": size {bytes} is not a multiple of 4",
                        r.name
                    ),
                ),
                (BufferKind::Typed, _) if format.is_none() => self.diags.error(
                    "buffer-format",
                    path,
                    format!("typed buffer \"{}\" needs a `format`", r.name),
                ),
                (_, Some(_)) if kind != BufferKind::Structured => self.diags.error(
                    "buffer-stride",
                    &path.field("stride"),
                    format!(
                        "`stride` only applies to structured buffers (\"{}\" is {})",
                        r.name,
                        buffer_kind_name(kind)
                    ),
                ),
                _ => {}
            }
            for flag in [
                ResourceFlag::AllowRenderTarget,
                ResourceFlag::AllowDepthStencil,
            ] {
                if flags.contains(&flag) {
                    self.diags.error(
                        "resource-flags",
                        &path.field("flags"),
                        format!("buffer \"{}\" cannot have {}", r.name, flag_name(flag)),
                    );
                }
            }
        } else {
            if r.size.is_some() || r.stride.is_some() || r.buffer_kind.is_some() {
                self.diags.error(
                    "resource-kind",
                    path,
                    format!(
                        "texture \"{}\" cannot have `size`, `stride` or `buffer_kind`",
                        r.name
                    ),
                );
            }
            let Some(format) = format else {
                if r.format.is_none() {
                    self.diags.error(
                        "resource-format",
                        path,
                        format!("texture \"{}\" needs a `format`", r.name),
                    );
                }
                return None;
            };
            if format.is_video_or_palette() {
                self.diags.error("format-usage", &path.field("format"), format!(
                    "{} is a video/palette format; framelab replays only colour, depth and block-compressed textures", format.name
                ));
            }
            width = match &r.width {
                Some(e) => self.resolve_extent(e, self.width, &path.field("width"))?,
                None => {
                    self.diags.error(
                        "resource-size",
                        path,
                        format!("texture \"{}\" needs a `width`", r.name),
                    );
                    return None;
                }
            };
            height = match (&r.height, r.kind) {
                (Some(e), ResourceKind::Texture1D) => {
                    let h = self.resolve_extent(e, self.height, &path.field("height"))?;
                    if h != 1 {
                        self.diags.error(
                            "resource-size",
                            &path.field("height"),
                            "a 1D texture has height 1",
                        );
                    }
                    1
                }
                (None, ResourceKind::Texture1D) => 1,
                (Some(e), _) => self.resolve_extent(e, self.height, &path.field("height"))?,
                (None, _) => {
                    self.diags.error(
                        "resource-size",
                        path,
                        format!("texture \"{}\" needs a `height`", r.name),
                    );
                    return None;
                }
            };
            depth = r.depth.unwrap_or(1);
            if r.kind == ResourceKind::Texture3D {
                if r.depth.is_none() || depth == 0 {
                    self.diags.error(
                        "resource-size",
                        path,
                        format!("3D texture \"{}\" needs a non-zero `depth`", r.name),
                    );
                    return None;
                }
                if r.array_layers.is_some_and(|l| l != 1) {
                    self.diags.error(
                        "resource-kind",
                        &path.field("array_layers"),
                        "3D textures have no array layers",
                    );
                }
            } else if r.depth.is_some_and(|d| d != 1) {
                self.diags.error(
                    "resource-kind",
                    &path.field("depth"),
                    format!(
                        "`depth` applies to 3D textures; \"{}\" is {}",
                        r.name,
                        r.kind.as_str()
                    ),
                );
                depth = 1;
            }
            layers = r
                .array_layers
                .unwrap_or(if r.kind == ResourceKind::TextureCube {
                    6
                } else {
                    1
                });
            if r.kind == ResourceKind::Texture3D {
                layers = 1;
            }
            if layers == 0 {
                self.diags.error(
                    "resource-size",
                    &path.field("array_layers"),
                    "array_layers must be at least 1",
                );
                return None;
            }
            if r.kind == ResourceKind::TextureCube {
                if layers % 6 != 0 {
                    self.diags.error("resource-size", &path.field("array_layers"), format!(
                        "cube texture \"{}\" has {layers} layers; a cube (array) needs a multiple of 6", r.name
                    ));
                }
                if width != height {
                    self.diags.error(
                        "resource-size",
                        &path.field("height"),
                        format!(
                            "cube texture \"{}\" faces must be square, not {width}x{height}",
                            r.name
                        ),
                    );
                }
            }
            if matches!(r.kind, ResourceKind::Texture2D | ResourceKind::Texture1D) && layers != 1 {
                self.diags.error(
                    "resource-kind",
                    &path.field("array_layers"),
                    format!(
                        "\"{}\" has {layers} layers; use kind texture_2d_array",
                        r.name
                    ),
                );
            }
            // Limits before any size arithmetic.
            let (max_dim, dim_name) = match r.kind {
                ResourceKind::Texture1D => (limits.max_texture_1d, "1D"),
                ResourceKind::Texture3D => (limits.max_texture_3d, "3D"),
                _ => (limits.max_texture_2d, "2D"),
            };
            for (field, v) in [("width", width), ("height", height), ("depth", depth)] {
                if v > max_dim {
                    self.diags.error(
                        "limit",
                        &path.field(field),
                        format!(
                            "{dim_name} texture \"{}\" {field} {v} exceeds the limit {max_dim}",
                            r.name
                        ),
                    );
                }
            }
            if layers > limits.max_array_layers {
                self.diags.error(
                    "limit",
                    &path.field("array_layers"),
                    format!(
                        "texture \"{}\" has {layers} array layers, over the limit {}",
                        r.name, limits.max_array_layers
                    ),
                );
            }
            if self.diags.error_count() > errors_before {
                return None;
            }
            let full_chain = 32 - width.max(height).max(depth).leading_zeros();
            mips = match r.mip_levels {
                None => 1,
                Some(MipLevels::Chain(_)) => full_chain,
                Some(MipLevels::Count(0)) => {
                    self.diags.error(
                        "resource-size",
                        &path.field("mip_levels"),
                        "mip_levels must be at least 1",
                    );
                    1
                }
                Some(MipLevels::Count(m)) if m > full_chain => {
                    self.diags.error("resource-size", &path.field("mip_levels"), format!(
                        "texture \"{}\" is {width}x{height}x{depth}: at most {full_chain} mips, not {m}", r.name
                    ));
                    1
                }
                Some(MipLevels::Count(m)) => m,
            };
            samples = r.samples.unwrap_or(1);
            if !matches!(samples, 1 | 2 | 4 | 8 | 16) {
                self.diags.error(
                    "resource-samples",
                    &path.field("samples"),
                    format!("sample count {samples} must be 1, 2, 4, 8 or 16"),
                );
            }
            if samples > 1 {
                if !matches!(
                    r.kind,
                    ResourceKind::Texture2D | ResourceKind::Texture2DArray
                ) {
                    self.diags.error(
                        "resource-samples",
                        &path.field("samples"),
                        "only 2D textures can be multisampled",
                    );
                }
                if mips != 1 {
                    self.diags.error(
                        "resource-samples",
                        &path.field("mip_levels"),
                        "multisampled textures have one mip",
                    );
                }
                if flags.contains(&ResourceFlag::AllowUnorderedAccess) {
                    self.diags.error(
                        "resource-flags",
                        &path.field("flags"),
                        "multisampled textures cannot be unordered-access",
                    );
                }
            }
            if format.is_block_compressed()
                && (width % format.block_width != 0 || height % format.block_height != 0)
                && mips == 1
            {
                self.diags.error("format-usage", &path.field("width"), format!(
                    "{} texture \"{}\" must be a multiple of 4 in width and height ({width}x{height})", format.name, r.name
                ));
            }
            // Format against flags.
            let ds = flags.contains(&ResourceFlag::AllowDepthStencil);
            let rt = flags.contains(&ResourceFlag::AllowRenderTarget);
            let uav = flags.contains(&ResourceFlag::AllowUnorderedAccess);
            let depth_capable = format.is_depth_format() || is_depth_family(format);
            if ds && !depth_capable {
                self.diags.error(
                    "format-usage",
                    &path.field("flags"),
                    format!(
                        "\"{}\" has ALLOW_DEPTH_STENCIL but {} is not a depth format",
                        r.name, format.name
                    ),
                );
            }
            if ds && (rt || uav) {
                self.diags.error("resource-flags", &path.field("flags"), format!(
                    "\"{}\": ALLOW_DEPTH_STENCIL cannot be combined with ALLOW_RENDER_TARGET or ALLOW_UNORDERED_ACCESS", r.name
                ));
            }
            if ds && r.kind == ResourceKind::Texture3D {
                self.diags.error(
                    "resource-flags",
                    &path.field("flags"),
                    "3D textures cannot be depth-stencil",
                );
            }
            if format.is_depth_format() && (rt || uav) {
                self.diags.error(
                    "format-usage",
                    &path.field("flags"),
                    format!(
                        "{} is a depth format: it cannot be a render target or unordered-access",
                        format.name
                    ),
                );
            }
            if format.is_block_compressed() && (rt || uav || ds) {
                self.diags.error("format-usage", &path.field("flags"), format!(
                    "{} is block-compressed: it cannot be a render target, depth-stencil or unordered-access", format.name
                ));
            }
            if format.srgb && uav {
                self.diags.error("format-usage", &path.field("flags"), format!(
                    "{} is sRGB: unordered-access views cannot be sRGB; create it typeless or non-sRGB", format.name
                ));
            }
            if flags.contains(&ResourceFlag::DenyShaderResource) && !ds {
                self.diags.error(
                    "resource-flags",
                    &path.field("flags"),
                    "DENY_SHADER_RESOURCE requires ALLOW_DEPTH_STENCIL",
                );
            }
            // Bytes, with overflow checks.
            let mut sum: Option<u64> = Some(0);
            for m in 0..mips {
                let (w, h) = ((width >> m).max(1), (height >> m).max(1));
                let d = if r.kind == ResourceKind::Texture3D {
                    (depth >> m).max(1)
                } else {
                    1
                };
                let surface = format.surface_bytes(u64::from(w), u64::from(h));
                sum = sum.and_then(|s| {
                    surface?
                        .checked_mul(u64::from(d))?
                        .checked_mul(u64::from(layers))?
                        .checked_mul(u64::from(samples))
                        .and_then(|b| s.checked_add(b))
                });
            }
            match sum {
                Some(b) => bytes = b,
                None => {
                    self.diags.error(
                        "limit",
                        path,
                        format!("texture \"{}\" size overflows 64 bits", r.name),
                    );
                    return None;
                }
            }
        }

        let alignment = if samples > 1 {
            MSAA_PLACEMENT_ALIGNMENT
        } else {
            PLACEMENT_ALIGNMENT
        };
        let aligned_bytes = bytes.div_ceil(alignment).saturating_mul(alignment);
        let placement = self.check_placement(r, path, heaps, bytes, alignment, samples, &flags);
        let initial = match &r.initial {
            None => InitialDesc::Undefined,
            Some(InitialContents::File { path: rel }) => {
                match self.side_file(rel, &path.field("initial").field("file").field("path")) {
                    Some(p) => {
                        if let Ok(meta) = std::fs::metadata(&p)
                            && meta.len() != bytes
                        {
                            self.diags.error(
                                "side-file",
                                &path.field("initial").field("file").field("path"),
                                format!(
                                    "\"{rel}\" has {} bytes; resource \"{}\" needs exactly {bytes}",
                                    meta.len(),
                                    r.name
                                ),
                            );
                        }
                        InitialDesc::File(p)
                    }
                    None => InitialDesc::Undefined,
                }
            }
            Some(InitialContents::Generator { name, seed, params }) => {
                self.check_generator_params(
                    generators::CONTENT_GENERATORS,
                    name,
                    params,
                    &path.field("initial").field("generator"),
                );
                InitialDesc::Generator {
                    name: name.clone(),
                    seed: *seed,
                    params: params.clone(),
                }
            }
        };
        if r.history && r.output {
            self.diags.warning(
                "resource-flags",
                &path.field("output"),
                format!("\"{}\" is both history and output", r.name),
            );
        }
        if self.diags.error_count() > errors_before {
            return None;
        }
        Some(ResourceDesc {
            id: ResourceId(index as u32),
            name: r.name.clone(),
            kind: r.kind,
            format,
            width,
            height,
            depth,
            array_layers: layers,
            mip_levels: mips,
            samples,
            buffer_kind: (r.kind == ResourceKind::Buffer)
                .then(|| r.buffer_kind.unwrap_or(BufferKind::Raw)),
            stride: r.stride,
            bytes,
            aligned_bytes,
            alignment,
            flags,
            placement: placement?,
            initial,
            history: r.history,
            output: r.output,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn check_placement(
        &mut self,
        r: &Resource,
        path: &JsonPath,
        heaps: &[HeapDesc],
        bytes: u64,
        alignment: u64,
        samples: u32,
        flags: &BTreeSet<ResourceFlag>,
    ) -> Option<PlacementDesc> {
        let ppath = path.field("placement");
        let placement = match &r.placement {
            None => PlacementDesc::Committed {
                heap_type: HeapType::Default,
            },
            Some(Placement::Committed { heap_type }) => {
                if *heap_type == HeapType::Custom {
                    self.diags.error("placement", &ppath.field("committed").field("heap_type"), "committed resources use DEFAULT, UPLOAD or READBACK; put CUSTOM resources in a named heap");
                }
                PlacementDesc::Committed {
                    heap_type: *heap_type,
                }
            }
            Some(Placement::Reserved) => {
                if r.kind == ResourceKind::Texture3D && samples > 1 {
                    self.diags.error(
                        "placement",
                        &ppath,
                        "reserved MSAA 3D textures do not exist",
                    );
                }
                PlacementDesc::Reserved
            }
            Some(Placement::Placed { heap, offset }) => {
                let hpath = ppath.field("placed").field("heap");
                let id = self.lookup("heap", heap, &hpath)?;
                let h = &heaps[id as usize];
                let opath = ppath.field("placed").field("offset");
                if offset % alignment != 0 {
                    self.diags.error("placement-alignment", &opath, format!(
                        "\"{}\" is placed at offset {offset}, which is not a multiple of its alignment {alignment}{}",
                        r.name, if samples > 1 { " (multisampled resources need 4 MiB)" } else { "" }
                    ));
                }
                if h.alignment < alignment {
                    self.diags.error(
                        "placement-alignment",
                        &hpath,
                        format!(
                            "heap \"{}\" is aligned to {} but \"{}\" needs {alignment}",
                            h.name, h.alignment, r.name
                        ),
                    );
                }
                let end = offset.checked_add(bytes);
                if end.is_none_or(|e| e > h.size) {
                    self.diags.error(
                        "placement-bounds",
                        &opath,
                        format!(
                            "\"{}\" ({} at offset {offset}) does not fit in heap \"{}\" of {}",
                            r.name,
                            human_bytes(bytes),
                            h.name,
                            human_bytes(h.size)
                        ),
                    );
                }
                let category = if !r.kind.is_texture() {
                    ResourceCategory::Buffer
                } else if flags.contains(&ResourceFlag::AllowRenderTarget)
                    || flags.contains(&ResourceFlag::AllowDepthStencil)
                {
                    ResourceCategory::RtDsTexture
                } else {
                    ResourceCategory::OtherTexture
                };
                if !h.allows.allows(category) {
                    self.diags.error(
                        "placement-heap-flags",
                        &hpath,
                        format!(
                            "heap \"{}\" does not allow {} (its flags allow {}), but \"{}\" is one",
                            h.name,
                            category.describe(),
                            describe_allows(h.allows),
                            r.name
                        ),
                    );
                }
                PlacementDesc::Placed {
                    heap: HeapId(id),
                    offset: *offset,
                }
            }
        };
        let heap_type = match &placement {
            PlacementDesc::Committed { heap_type } => *heap_type,
            PlacementDesc::Placed { heap, .. } => heaps[heap.index()].heap_type,
            PlacementDesc::Reserved => HeapType::Default,
        };
        if matches!(heap_type, HeapType::Upload | HeapType::Readback) {
            if r.kind.is_texture() {
                self.diags.error("placement-heap-type", &ppath, format!(
                    "texture \"{}\" is in an {} heap; UPLOAD and READBACK heaps hold buffers (copy textures through them)", r.name, heap_type_name(heap_type)
                ));
            }
            let bad: Vec<&str> = flags
                .iter()
                .filter(|f| {
                    matches!(
                        f,
                        ResourceFlag::AllowUnorderedAccess
                            | ResourceFlag::AllowRenderTarget
                            | ResourceFlag::AllowDepthStencil
                    )
                })
                .map(|f| flag_name(*f))
                .collect();
            if !bad.is_empty() {
                self.diags.error(
                    "placement-heap-type",
                    &path.field("flags"),
                    format!(
                        "\"{}\" in an {} heap cannot have {}",
                        r.name,
                        heap_type_name(heap_type),
                        bad.join(", ")
                    ),
                );
            }
        }
        Some(placement)
    }

    // -----------------------------------------------------------------------------------------
    // Descriptor heaps, samplers, meshes

    fn check_descriptor_heaps(&mut self) -> Vec<DescriptorHeapDesc> {
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

    fn check_samplers(&mut self) {
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

    fn check_meshes(&mut self) -> Option<Vec<MeshDesc>> {
        let mut out = Vec::new();
        let mut ok = true;
        for (i, m) in self.raw.meshes.iter().enumerate() {
            let path = self.root.field("meshes").index(i);
            let errors_before = self.diags.error_count();
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
                    self.diags.error("mesh", &path, format!(
                        "mesh \"{}\" has a per-instance stream (slot {}) but no `instance_count`", m.name, stream.slot
                    ));
                }
            }
            let source = match &m.source {
                MeshSource::File { path: rel } => {
                    let fpath = path.field("source").field("file").field("path");
                    if m.vertex_count.is_none() {
                        self.diags.error(
                            "mesh",
                            &path,
                            format!("mesh \"{}\" from a file needs `vertex_count`", m.name),
                        );
                    }
                    if m.index_format.is_some() && m.index_count.is_none() {
                        self.diags.error(
                            "mesh",
                            &path,
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
                    self.check_generator_params(
                        generators::MESH_GENERATORS,
                        name,
                        params,
                        &path.field("source").field("generator"),
                    );
                    Some(MeshSourceDesc::Generator {
                        name: name.clone(),
                        seed: *seed,
                        params: params.clone(),
                    })
                }
            };
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
                } else if !matches!(g.name.as_str(), "instances" | "city_lots") {
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
                    instances: m
                        .instances
                        .as_ref()
                        .map(|g| (g.name.clone(), g.seed, g.params.clone())),
                }),
                _ => ok = false,
            }
        }
        ok.then_some(out)
    }

    // -----------------------------------------------------------------------------------------
    // Passes

    fn check_passes(
        &mut self,
        resources: &Option<Vec<ResourceDesc>>,
        heaps: &[HeapDesc],
        meshes: &Option<Vec<MeshDesc>>,
    ) -> Option<Vec<PassDesc>> {
        let mut out = Vec::new();
        let mut ok = true;
        for (i, p) in self.raw.passes.iter().enumerate() {
            let path = self.root.field("passes").index(i);
            match self.check_pass(i, p, &path, resources.as_deref(), heaps, meshes.as_deref()) {
                Some(pass) => out.push(pass),
                None => ok = false,
            }
        }
        (ok && resources.is_some()).then_some(out)
    }

    fn check_pass(
        &mut self,
        index: usize,
        p: &Pass,
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

        // Which fields belong to which kind.
        let present_fields: [(&str, bool); 10] = [
            ("shader", p.shader.is_some()),
            ("color_attachments", !p.color_attachments.is_empty()),
            ("depth_stencil", p.depth_stencil.is_some()),
            ("state", p.state.is_some()),
            ("draws", !p.draws.is_empty()),
            ("dispatches", !p.dispatches.is_empty()),
            ("copies", !p.copies.is_empty()),
            ("clears", !p.clears.is_empty()),
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

        // Queue capabilities (Vulkan's pipeline stage -> required queue capability table).
        if let (Some(caps), Some(qt)) = (caps, queue_type) {
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
                        queue_type_name(qt),
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

        // Shader.
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
            Some(ShaderDesc { path: file, file: s.file.clone(), vertex: s.vertex.clone(), fragment: s.fragment.clone(), compute: s.compute.clone() })
        });
        if matches!(p.kind, PassKind::Raster | PassKind::Compute) && p.shader.is_none() {
            self.diags.error(
                "shader",
                path,
                format!("{} pass \"{name}\" needs a `shader`", p.kind.as_str()),
            );
        }

        let mut accesses: Vec<ResourceAccess> = Vec::new();
        let res = |id: u32| resources.map(|r| &r[id as usize]);

        // Bindings.
        let mut bindings = Vec::new();
        for (var, b) in &p.bindings {
            let bpath = path.field("bindings").field(var);
            if let Some(desc) = self.check_binding(name, var, b, &bpath, resources, &mut accesses) {
                bindings.push(desc);
            }
        }

        // Colour attachments.
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
            if format.is_depth_stencil() || format.is_block_compressed() || format.is_typeless() {
                self.diags.error(
                    "format-usage",
                    &apath,
                    format!(
                        "{} cannot be a colour attachment (\"{}\" in pass \"{name}\")",
                        format.name, r.name
                    ),
                );
            }
            if a.blend
                .as_ref()
                .is_some_and(|b| !matches!(b, Blend::Preset(BlendPreset::Opaque)))
                && format.is_integer()
            {
                self.diags.error(
                    "format-usage",
                    &apath.field("blend"),
                    format!("integer format {} cannot blend", format.name),
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

        // Depth-stencil.
        let state = p.state.clone().unwrap_or_default();
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
            let writes = !d.read_only && (state.depth_write || stencil_writes || d.depth_load == LoadOp::Clear || d.stencil_load == LoadOp::Clear);
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
            if p.draws.is_empty() {
                self.diags.warning(
                    "no-draws",
                    &path.field("draws"),
                    format!("raster pass \"{name}\" issues no draws"),
                );
            }
        }

        // Draws.
        let mut draws = Vec::new();
        for (i, d) in p.draws.iter().enumerate() {
            let dpath = path.field("draws").index(i);
            let mesh = d
                .mesh
                .as_ref()
                .and_then(|m| self.lookup("mesh", m, &dpath.field("mesh")));
            let mesh_desc = mesh.and_then(|m| meshes.map(|ms| &ms[m as usize]));
            if d.mesh.is_none() && d.count.is_none() && d.indirect.is_none() {
                self.diags.error(
                    "draw",
                    &dpath,
                    "a draw without a mesh needs a `count` (vertices generated in the shader)",
                );
            }
            if d.instances == 0 {
                self.diags
                    .warning("draw", &dpath.field("instances"), "draw of zero instances");
            }
            if let (Some(m), Some(count)) = (mesh_desc, d.count) {
                let available = if m.index_format.is_some() {
                    m.index_count
                } else {
                    m.vertex_count
                };
                if let Some(avail) = available
                    && u64::from(d.first) + u64::from(count) > u64::from(avail)
                {
                    self.diags.error(
                        "draw",
                        &dpath.field("count"),
                        format!(
                            "draw reads elements {}..{} of mesh \"{}\", which has {avail}",
                            d.first,
                            u64::from(d.first) + u64::from(count),
                            m.name
                        ),
                    );
                }
            }
            if d.stencil_reference.is_some_and(|r| r > 255) {
                self.diags.error(
                    "draw",
                    &dpath.field("stencil_reference"),
                    "stencil reference is 8 bits (0..255)",
                );
            }
            if d.stencil_reference.is_some() && state.stencil.is_none() {
                self.diags.error(
                    "draw",
                    &dpath.field("stencil_reference"),
                    format!("pass \"{name}\" sets a stencil reference but has no stencil state"),
                );
            }
            let indexed = mesh_desc.is_some_and(|m| m.index_format.is_some());
            let indirect = d.indirect.as_ref().and_then(|ind| {
                let args = if indexed {
                    DRAW_INDEXED_ARGS
                } else {
                    DRAW_ARGS
                };
                self.check_indirect(
                    ind,
                    args,
                    &dpath.field("indirect"),
                    resources,
                    &mut accesses,
                    AccessSource::Indirect(i),
                )
            });
            draws.push(DrawDesc {
                label: d.label.clone(),
                vertex: d.vertex.clone(),
                mesh: mesh.map(MeshId),
                count: d.count,
                instances: d.instances,
                first: d.first,
                first_instance: d.first_instance,
                base_vertex: d.base_vertex,
                indirect,
                stencil_reference: d.stencil_reference,
                params: d.params.clone(),
            });
        }

        // Dispatches.
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
            match (&d.groups, &d.indirect) {
                (Some(_), Some(_)) => {
                    self.diags
                        .error("dispatch", &dpath, "give `groups` or `indirect`, not both")
                }
                (None, None) => self.diags.error(
                    "dispatch",
                    &dpath,
                    "a dispatch needs `groups` or `indirect`",
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
                (None, Some(_)) => {}
            }
            let indirect = d.indirect.as_ref().and_then(|ind| {
                self.check_indirect(
                    ind,
                    DISPATCH_ARGS,
                    &dpath.field("indirect"),
                    resources,
                    &mut accesses,
                    AccessSource::Indirect(i),
                )
            });
            dispatches.push(DispatchDesc {
                label: d.label.clone(),
                entry: d.entry.clone(),
                groups: d.groups,
                indirect,
                params: d.params.clone(),
            });
        }

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

        // Clears.
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
            let access = if r.has_flag(ResourceFlag::AllowDepthStencil) {
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
            if let (Some(caps), true) = (caps, access != Access::StorageWrite)
                && !caps.graphics
            {
                self.diags.error("queue-capability", &path.field("queue"), format!(
                        "clearing render target or depth \"{}\" needs a graphics queue; queue \"{}\" is not one", r.name, p.queue
                    ));
            }
            if let (Some(caps), Access::StorageWrite) = (caps, access)
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

        // Resolve.
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

        // Mip generation.
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

        // Present.
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
            dispatches,
            copies,
            clears,
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

    fn check_binding(
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
                    return None;
                }
                if access.is_unordered(r.is_texture())
                    && !r.has_flag(ResourceFlag::AllowUnorderedAccess)
                {
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
                    if access.is_unordered(r.is_texture())
                        && (f.is_block_compressed() || f.is_depth_stencil() || f.srgb)
                    {
                        self.diags.error(
                            "format-usage",
                            &path.field("access"),
                            format!(
                                "{} cannot be a storage texture (\"{}\" in pass \"{pass}\")",
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
                    }
                    None
                };
                let range = if r.is_texture() {
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
                    range
                };
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
                })
            }
        }
    }

    /// The format a view of `r` uses: the resource's, or a compatible reinterpretation.
    fn view_format(
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
        if !dxgi::view_compatible(resource_format, f) {
            self.diags.error("view-format", path, format!(
                "view format {} is not compatible with \"{}\" ({}); only typeless resources can be viewed in another format of their family",
                f.name, r.name, resource_format.name
            ));
            return None;
        }
        Some(f)
    }

    fn view_range(
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

    fn single_subresource(
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

    fn check_indirect(
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

    fn check_copy(
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
            (false, false) => {
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
            (true, true) => {
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
            }
            (texture_src, _) => {
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
                    .unwrap_or(row_bytes.div_ceil(256) * 256);
                if pitch < row_bytes {
                    self.diags.error("copy", &path.field(bside).field("bytes_per_row"), format!(
                        "bytes_per_row {pitch} is less than a row of {} texels ({row_bytes} bytes)", extent[0]
                    ));
                }
                if pitch % 256 != 0 {
                    self.diags.error("copy", &path.field(bside).field("bytes_per_row"), format!(
                        "bytes_per_row {pitch} must be a multiple of 256 (D3D12_TEXTURE_DATA_PITCH_ALIGNMENT)"
                    ));
                }
                let needed = pitch * rows.saturating_sub(1) * u64::from(extent[2].max(1))
                    + row_bytes
                    + pitch * rows * u64::from(extent[2].max(1).saturating_sub(1));
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
            }
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
        })
    }

    fn check_barrier(
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
        })
    }

    fn check_fences(&mut self, passes: &Option<Vec<PassDesc>>) {
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

pub fn flag_name(flag: ResourceFlag) -> &'static str {
    match flag {
        ResourceFlag::AllowRenderTarget => "ALLOW_RENDER_TARGET",
        ResourceFlag::AllowDepthStencil => "ALLOW_DEPTH_STENCIL",
        ResourceFlag::AllowUnorderedAccess => "ALLOW_UNORDERED_ACCESS",
        ResourceFlag::DenyShaderResource => "DENY_SHADER_RESOURCE",
        ResourceFlag::AllowCrossAdapter => "ALLOW_CROSS_ADAPTER",
        ResourceFlag::AllowSimultaneousAccess => "ALLOW_SIMULTANEOUS_ACCESS",
        ResourceFlag::VideoDecodeReferenceOnly => "VIDEO_DECODE_REFERENCE_ONLY",
        ResourceFlag::RaytracingAccelerationStructure => "RAYTRACING_ACCELERATION_STRUCTURE",
    }
}

pub fn queue_type_name(q: QueueType) -> &'static str {
    match q {
        QueueType::Graphics => "graphics",
        QueueType::Compute => "compute",
        QueueType::Copy => "copy",
    }
}

pub fn heap_type_name(h: HeapType) -> &'static str {
    match h {
        HeapType::Default => "DEFAULT",
        HeapType::Upload => "UPLOAD",
        HeapType::Readback => "READBACK",
        HeapType::Custom => "CUSTOM",
    }
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

pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u < UNITS.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

fn page_name(p: CpuPageProperty) -> &'static str {
    match p {
        CpuPageProperty::Unknown => "UNKNOWN",
        CpuPageProperty::NotAvailable => "NOT_AVAILABLE",
        CpuPageProperty::WriteCombine => "WRITE_COMBINE",
        CpuPageProperty::WriteBack => "WRITE_BACK",
    }
}

pub fn buffer_kind_name(k: BufferKind) -> &'static str {
    match k {
        BufferKind::Structured => "structured",
        BufferKind::ByteAddress => "byte_address",
        BufferKind::Raw => "raw",
        BufferKind::Typed => "typed",
    }
}
