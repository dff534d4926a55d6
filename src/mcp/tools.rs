//! The tools `framelab mcp` offers: each takes its arguments as described by a JSON Schema
//! (`schemars`), answers with the same JSON the command line's `--json` prints for the same
//! question (the same core functions make it), and turns every bad argument into a tool
//! error that names it, so a client can correct itself and the session goes on.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

use framelab_core::analysis::report::{self, AnalyzeOptions};
use framelab_core::pipeline::Validated;
use framelab_core::structure::Frame;
use rmcp::handler::server::common::schema_for_type;
use rmcp::model::{CallToolResult, ContentBlock, JsonObject};
use rmcp::service::RoleServer;
use rmcp::{Peer, tool, tool_router};
use schemars::JsonSchema;
use serde::Deserialize;
use serde::de::DeserializeOwned;
use serde_json::{Value, json};

use super::store::{self, Opened, Store, unknown};

/// The most rows one `list_*` call returns.
pub const MAX_ROWS: usize = 1000;
const DEFAULT_ROWS: usize = 100;

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OpenArgs {
    /// A capture file (JSON) inside the client's roots.
    pub path: String,
    /// Output-resolution multiplier the sizes are resolved for (default 1).
    pub scale: Option<f64>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ListArgs {
    /// A capture id from open_capture.
    pub capture: String,
    /// Keep rows whose name contains this text.
    pub filter: Option<String>,
    /// Rows to skip (default 0).
    pub offset: Option<usize>,
    /// Rows to return (default 100, at most 1000).
    pub limit: Option<usize>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PassArgs {
    pub capture: String,
    /// The pass's name.
    pub pass: String,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AnalyzeArgs {
    pub capture: String,
    /// Drop passes whose results never reach an output first.
    pub cull: Option<bool>,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DiffMode {
    /// Passes, resources, formats and barriers added, removed or changed.
    Structure,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiffArgs {
    /// Capture id of the first frame.
    pub a: String,
    /// Capture id of the second frame.
    pub b: String,
    pub mode: DiffMode,
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CloseArgs {
    pub capture: String,
}

/// The server's state: the opened captures, and the directories it may read.
#[derive(Clone)]
pub struct Framelab {
    store: Arc<Mutex<Store>>,
    /// `--root` directories (canonical); empty when none were given.
    roots: Arc<Vec<PathBuf>>,
    tool_router: rmcp::handler::server::router::tool::ToolRouter<Self>,
}

type Answer = Result<CallToolResult, rmcp::ErrorData>;

/// A tool error: the client sees `message` and may try again.
fn refuse(message: impl Into<String>) -> Answer {
    Ok(CallToolResult::error(vec![ContentBlock::text(
        message.into(),
    )]))
}

fn answer(value: impl serde::Serialize) -> Answer {
    match serde_json::to_value(value) {
        Ok(v) => Ok(CallToolResult::structured(v)),
        Err(e) => refuse(format!("the answer does not serialise: {e}")),
    }
}

/// The arguments as `T`, or a message naming what breaks its schema.
fn args<T: DeserializeOwned>(tool: &str, object: JsonObject) -> Result<T, String> {
    serde_json::from_value(Value::Object(object))
        .map_err(|e| format!("{tool}: the arguments do not match its input schema: {e}"))
}

/// `Ok(value)` or an early tool error.
macro_rules! take {
    ($e:expr) => {
        match $e {
            Ok(v) => v,
            Err(message) => return refuse(message),
        }
    };
}

impl Framelab {
    pub fn new(roots: Vec<PathBuf>) -> Framelab {
        Framelab {
            store: Arc::default(),
            roots: Arc::new(roots),
            tool_router: Self::tool_router(),
        }
    }

    pub fn router(&self) -> &rmcp::handler::server::router::tool::ToolRouter<Self> {
        &self.tool_router
    }

    fn store(&self) -> MutexGuard<'_, Store> {
        // A panic while holding the lock cannot leave a half-made entry (inserts are whole),
        // so a poisoned lock is still good to read.
        self.store
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The canonical `path` if it lies inside every root that applies: the `--root`
    /// directories when given, and the client's roots when it declares any (the working
    /// directory when it declares none).
    // Roots are deprecated by a protocol revision newer than the clients framelab is used
    // with, which still send them; until they stop, they are what bounds the files read.
    #[allow(deprecated)]
    async fn allowed(&self, peer: &Peer<RoleServer>, path: &str) -> Result<PathBuf, String> {
        let file = Path::new(path)
            .canonicalize()
            .map_err(|e| format!("cannot open {path}: {e}"))?;
        let inside = |roots: &[PathBuf]| roots.iter().any(|r| file.starts_with(r));
        if !self.roots.is_empty() && !inside(&self.roots) {
            return Err(format!(
                "{} is outside the server's --root ({})",
                file.display(),
                list(&self.roots)
            ));
        }
        let declares_roots = peer
            .peer_info()
            .is_some_and(|info| info.capabilities.roots.is_some());
        let client: Vec<PathBuf> = if declares_roots {
            let listed = peer
                .list_roots()
                .await
                .map_err(|e| format!("cannot list the client's roots: {e}"))?;
            listed
                .roots
                .iter()
                .filter_map(|r| r.uri.strip_prefix("file://"))
                .filter_map(|p| Path::new(p).canonicalize().ok())
                .collect()
        } else {
            std::env::current_dir().into_iter().collect()
        };
        if !inside(&client) {
            return Err(format!(
                "{} is outside the client's roots ({})",
                file.display(),
                list(&client)
            ));
        }
        Ok(file)
    }
}

fn list(paths: &[PathBuf]) -> String {
    if paths.is_empty() {
        return "none".to_owned();
    }
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// `rows` filtered by name and paginated, with the total that matched.
fn page<T: serde::Serialize>(
    rows: &[T],
    name: impl Fn(&T) -> &str,
    a: &ListArgs,
) -> Result<Value, String> {
    let limit = a.limit.unwrap_or(DEFAULT_ROWS);
    if limit > MAX_ROWS {
        return Err(format!(
            "limit {limit} is over the {MAX_ROWS} rows one call returns; page with offset"
        ));
    }
    let matching: Vec<&T> = rows
        .iter()
        .filter(|r| a.filter.as_deref().is_none_or(|f| name(r).contains(f)))
        .collect();
    let offset = a.offset.unwrap_or(0);
    let shown: Vec<&T> = matching.iter().skip(offset).take(limit).copied().collect();
    Ok(json!({
        "total": matching.len(),
        "offset": offset,
        "rows": shown,
    }))
}

fn pass_details(o: &Opened, pass: &str) -> Result<Value, String> {
    let Some(info) = o.info.passes.iter().find(|p| p.name == pass) else {
        return Err(unknown(
            "pass",
            pass,
            o.info.passes.iter().map(|p| p.name.as_str()),
            "list_passes names them",
        ));
    };
    let r = &o.report;
    let position = r.order.iter().position(|p| p == pass);
    let barriers: Vec<_> = r.barriers.iter().filter(|b| b.pass == pass).collect();
    let lints: Vec<_> = r
        .lints
        .iter()
        .filter(|l| l.pass.as_deref() == Some(pass))
        .collect();
    let before: Vec<_> = o.graph.edges.iter().filter(|e| e.to == pass).collect();
    let after: Vec<_> = o.graph.edges.iter().filter(|e| e.from == pass).collect();
    Ok(json!({
        "pass": info,
        "position": position,
        "culled": r.culled.iter().any(|c| c == pass),
        "recorded": o.recorded.get(pass),
        "derived_barriers": barriers,
        "lints": lints,
        "dag": {"before": before, "after": after},
    }))
}

#[tool_router]
impl Framelab {
    #[tool(
        description = "Open a framelab capture (JSON): validate and analyse it, and return its id with a summary (queues, passes, resources, warnings).",
        input_schema = schema_for_type::<OpenArgs>()
    )]
    async fn open_capture(&self, peer: Peer<RoleServer>, object: JsonObject) -> Answer {
        let a: OpenArgs = take!(args("open_capture", object));
        let scale = a.scale.unwrap_or(1.0);
        if !(scale.is_finite() && (0.01..=8.0).contains(&scale)) {
            return refuse(format!("scale {scale} is outside 0.01..=8"));
        }
        let file = take!(self.allowed(&peer, &a.path).await);
        take!(self.store().room());
        // Loading takes a while on a large frame: off the protocol's threads, without the lock.
        let loaded = tokio::task::spawn_blocking(move || store::load(&file, scale)).await;
        let opened = take!(take!(loaded.map_err(|e| format!("loading stopped: {e}"))));
        let mut store = self.store();
        let (id, o) = take!(store.insert(opened));
        answer(json!({
            "capture": id,
            "path": o.path,
            "name": o.analysed.capture.name,
            "scale": o.scale,
            "width": o.analysed.capture.width,
            "height": o.analysed.capture.height,
            "queues": o.info.queues,
            "passes": o.info.passes.len(),
            "resources": o.info.resources.len(),
            "lints": o.report.lints.len(),
        }))
    }

    #[tool(
        description = "The passes of an opened capture: the rows of `framelab info --json`, filtered by name and paginated.",
        input_schema = schema_for_type::<ListArgs>()
    )]
    fn list_passes(&self, object: JsonObject) -> Answer {
        let a: ListArgs = take!(args("list_passes", object));
        let store = self.store();
        let o = take!(store.get(&a.capture));
        answer(take!(page(&o.info.passes, |p| &p.name, &a)))
    }

    #[tool(
        description = "The resources of an opened capture: the rows of `framelab info --json`, filtered by name and paginated.",
        input_schema = schema_for_type::<ListArgs>()
    )]
    fn list_resources(&self, object: JsonObject) -> Answer {
        let a: ListArgs = take!(args("list_resources", object));
        let store = self.store();
        let o = take!(store.get(&a.capture));
        answer(take!(page(&o.info.resources, |r| &r.name, &a)))
    }

    #[tool(
        description = "One pass: its queue, markers, draws, dispatches and copies, bindings and attachments as recorded, the barriers framelab derives before it, the lints that name it and its DAG neighbours.",
        input_schema = schema_for_type::<PassArgs>()
    )]
    fn pass_details(&self, object: JsonObject) -> Answer {
        let a: PassArgs = take!(args("pass_details", object));
        let store = self.store();
        let o = take!(store.get(&a.capture));
        answer(take!(pass_details(o, &a.pass)))
    }

    #[tool(
        description = "The analysis of an opened capture, as `framelab analyze --json`: order, culled passes, derived barriers, fences, queue transfers, memory and aliasing, lints, critical path, async-compute overlap.",
        input_schema = schema_for_type::<AnalyzeArgs>()
    )]
    fn analyze(&self, object: JsonObject) -> Answer {
        let a: AnalyzeArgs = take!(args("analyze", object));
        let store = self.store();
        let o = take!(store.get(&a.capture));
        if !a.cull.unwrap_or(false) {
            return answer(&o.report);
        }
        let validated = Validated {
            path: o.analysed.path.clone(),
            sha256: o.analysed.sha256.clone(),
            capture: o.analysed.capture.clone(),
            warnings: Vec::new(),
        };
        let culled = take!(
            validated
                .analyse(AnalyzeOptions { cull: true })
                .map_err(|e| e.to_string())
        );
        answer(report::report(&culled.capture, &culled.analysis))
    }

    #[tool(
        description = "Compare two opened captures, as `framelab diff --json`; mode `structure`: passes, resources and barriers added, removed or changed.",
        input_schema = schema_for_type::<DiffArgs>()
    )]
    fn diff(&self, object: JsonObject) -> Answer {
        let a: DiffArgs = take!(args("diff", object));
        let store = self.store();
        let (x, y) = (take!(store.get(&a.a)), take!(store.get(&a.b)));
        match a.mode {
            DiffMode::Structure => answer(framelab_core::structure::diff(
                Frame {
                    capture: &x.analysed.capture,
                    analysis: &x.analysed.analysis,
                },
                Frame {
                    capture: &y.analysed.capture,
                    analysis: &y.analysed.analysis,
                },
            )),
        }
    }

    #[tool(
        description = "Close an opened capture and free what it holds.",
        input_schema = schema_for_type::<CloseArgs>()
    )]
    fn close_capture(&self, object: JsonObject) -> Answer {
        let a: CloseArgs = take!(args("close_capture", object));
        let closed = take!(self.store().close(&a.capture));
        answer(json!({"closed": a.capture, "path": closed.path}))
    }
}
