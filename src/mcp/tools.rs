//! The tools `framelab mcp` offers (their arguments are in `args`, what they compute from an
//! opened capture in `answers`): each takes its arguments as described by a JSON Schema
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
use serde::de::DeserializeOwned;
use serde_json::{Value, json};

use super::answers::{
    Target, channel_stats, decode_rows, find_resource, fit, page, pass_details, passes_through,
    progress_sender, texture_checks,
};
use super::args::*;
use super::store::{self, Store};

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
fn args<T: DeserializeOwned>(tool: &str, object: JsonObject) -> anyhow::Result<T> {
    serde_json::from_value(Value::Object(object))
        .map_err(|e| anyhow::anyhow!("{tool}: the arguments do not match its input schema: {e}"))
}

/// `Ok(value)` or an early tool error.
macro_rules! take {
    ($e:expr) => {
        match $e {
            Ok(v) => v,
            Err(message) => return refuse(message.to_string()),
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

    /// Checks `t` against the capture, then has the capture's replay worker (started on the
    /// first request) read the texture; the lock is not held while it replays.
    async fn replay_texture(
        &self,
        t: &Target<'_>,
        peer: &Peer<RoleServer>,
        meta: &rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
    ) -> anyhow::Result<(Value, std::sync::Arc<framelab_replay::decode::DecodedImage>)> {
        let (reply, answer) = tokio::sync::oneshot::channel();
        let summary = {
            let mut store = self.store();
            let o = store.get_mut(t.capture)?;
            let summary = texture_checks(o, t)?;
            let request = super::replay::Request {
                resource: t.resource.to_owned(),
                after: t.after_pass.map(str::to_owned),
                mip: t.sub.0,
                layer: t.sub.1,
                slice: t.sub.2,
                progress: progress_sender(peer, meta),
                cancel,
                reply,
            };
            o.worker().send(super::replay::Job::Texture(request))?;
            summary
        };
        let image = answer
            .await
            .map_err(|_| anyhow::anyhow!("the replay stopped"))??;
        Ok((summary, image))
    }

    /// `frames` frames of a capture replayed and timed by its worker (a session of its own).
    async fn replay_timings(
        &self,
        capture: &str,
        (frames, counters): (u32, bool),
        peer: &Peer<RoleServer>,
        meta: &rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
    ) -> anyhow::Result<framelab_core::timing::TimingReport> {
        let (reply, report) = tokio::sync::oneshot::channel();
        {
            let mut store = self.store();
            let o = store.get_mut(capture)?;
            let job = super::replay::Timings {
                frames,
                counters,
                progress: progress_sender(peer, meta),
                cancel,
                reply,
            };
            o.worker().send(super::replay::Job::Timings(job))?;
        }
        report
            .await
            .map_err(|_| anyhow::anyhow!("the replay stopped"))?
    }

    /// The canonical `path` if it lies inside every root that applies: the `--root`
    /// directories when given, and the client's roots when it declares any (the working
    /// directory when it declares none).
    // Roots are deprecated by a protocol revision newer than the clients framelab is used
    // with, which still send them; until they stop, they are what bounds the files read.
    #[allow(deprecated)]
    async fn allowed(&self, peer: &Peer<RoleServer>, path: &str) -> anyhow::Result<PathBuf> {
        let file = Path::new(path)
            .canonicalize()
            .map_err(|e| anyhow::anyhow!("cannot open {path}: {e}"))?;
        let inside = |roots: &[PathBuf]| roots.iter().any(|r| file.starts_with(r));
        if !self.roots.is_empty() && !inside(&self.roots) {
            return Err(anyhow::anyhow!(
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
                .map_err(|e| anyhow::anyhow!("cannot list the client's roots: {e}"))?;
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
            return Err(anyhow::anyhow!(
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

#[tool_router]
impl Framelab {
    #[tool(
        description = "Open a capture: a framelab capture (JSON), or what `framelab import` reads (a GFXReconstruct .gfxr or JSON Lines stream, a RenderDoc .rdc), imported first. Validate and analyse it, and return its id with a summary (queues, passes, resources, lints).",
        input_schema = schema_for_type::<OpenArgs>()
    )]
    async fn open_capture(&self, peer: Peer<RoleServer>, object: JsonObject) -> Answer {
        let a: OpenArgs = take!(args("open_capture", object));
        let scale = a.scale.unwrap_or(1.0);
        if !(scale.is_finite() && (0.01..=8.0).contains(&scale)) {
            return refuse(format!("scale {scale} is outside 0.01..=8"));
        }
        let file = take!(self.allowed(&peer, &a.path).await);
        let scratch = {
            let mut store = self.store();
            take!(store.room());
            super::imports::scratch().join(store.next_scratch())
        };
        // Loading takes a while on a large frame: off the protocol's threads, without the lock.
        let loaded = tokio::task::spawn_blocking(move || {
            if super::imports::is_import(&file)? {
                let written = super::imports::import_into(&file, &scratch)?;
                let mut opened = store::load(&written, scale)?;
                opened.imported_from = Some((file, scratch));
                Ok(opened)
            } else {
                store::load(&file, scale)
            }
        })
        .await;
        let opened = take!(take!(
            loaded.map_err(|e| anyhow::anyhow!("loading stopped: {e}"))
        ));
        let mut store = self.store();
        let (id, o) = take!(store.insert(opened));
        answer(json!({
            "capture": id,
            "path": o.imported_from.as_ref().map_or(&o.path, |(from, _)| from),
            "imported": o.imported_from.is_some(),
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
        let culled = take!(validated.analyse(AnalyzeOptions { cull: true }));
        answer(report::report(&culled.capture, &culled.analysis))
    }

    #[tool(
        description = "Compare two opened captures, as `framelab diff --json`. Mode `structure`: passes, resources and barriers added, removed or changed. Mode `timing`: both frames replayed here (`frames` each, one capture after the other) and their per-pass GPU times compared with 95% intervals and verdicts, as `framelab diff` compares two timing reports. Mode `work`: one frame of each replayed here with its pipeline statistics counted, and every pass's counters and submitted work compared exactly, as `framelab diff --work` does (no statistics: counts do not scatter).",
        input_schema = schema_for_type::<DiffArgs>()
    )]
    async fn diff(
        &self,
        peer: Peer<RoleServer>,
        meta: rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
        object: JsonObject,
    ) -> Answer {
        let a: DiffArgs = take!(args("diff", object));
        match a.mode {
            DiffMode::Structure => {
                if a.frames.is_some() {
                    return refuse("frames applies to mode timing only");
                }
                let store = self.store();
                let (x, y) = (take!(store.get(&a.a)), take!(store.get(&a.b)));
                answer(framelab_core::structure::diff(
                    Frame {
                        capture: &x.analysed.capture,
                        analysis: &x.analysed.analysis,
                    },
                    Frame {
                        capture: &y.analysed.capture,
                        analysis: &y.analysed.analysis,
                    },
                ))
            }
            DiffMode::Timing => {
                let frames = a.frames.unwrap_or(10);
                if !(2..=MAX_FRAMES).contains(&frames) {
                    return refuse(format!("frames {frames} is outside 2..={MAX_FRAMES}"));
                }
                {
                    let store = self.store();
                    take!(store.get(&a.a));
                    take!(store.get(&a.b));
                }
                let x = take!(
                    self.replay_timings(&a.a, (frames, false), &peer, &meta, cancel.clone())
                        .await
                );
                let y = take!(
                    self.replay_timings(&a.b, (frames, false), &peer, &meta, cancel)
                        .await
                );
                let report = take!(framelab_core::timing::diff::diff(
                    &x,
                    &y,
                    &framelab_core::timing::diff::DiffOptions::default()
                ));
                answer(report)
            }
            DiffMode::Work => {
                if a.frames.is_some() {
                    return refuse(
                        "frames applies to mode timing only: mode work counts one frame",
                    );
                }
                {
                    let store = self.store();
                    take!(store.get(&a.a));
                    take!(store.get(&a.b));
                }
                let x = take!(
                    self.replay_timings(&a.a, (1, true), &peer, &meta, cancel.clone())
                        .await
                );
                let y = take!(
                    self.replay_timings(&a.b, (1, true), &peer, &meta, cancel)
                        .await
                );
                answer(take!(framelab_core::timing::work_diff::work_diff(&x, &y)))
            }
        }
    }

    #[tool(
        description = "A texture as it stood right after a pass of frame 0, replayed on this machine's GPU (lavapipe included): a PNG as `framelab replay --after` exports it (8-bit formats as they are, float ones as the export's preview, integer ones stretched), its longest side at most max_size, with a summary: format, size, per-channel min/max/mean, whether the frame wrote it yet. The replay is kept: a later pass of the same frame continues from the last one asked for. Sends progress (pass i of n) and stops when cancelled.",
        input_schema = schema_for_type::<TextureArgs>()
    )]
    async fn texture(
        &self,
        peer: Peer<RoleServer>,
        meta: rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
        object: JsonObject,
    ) -> Answer {
        let a: TextureArgs = take!(args("texture", object));
        let max_size = a.max_size.unwrap_or(1024);
        if max_size == 0 || max_size > MAX_IMAGE_SIDE {
            return refuse(format!(
                "max_size {max_size} is outside 1..={MAX_IMAGE_SIDE}"
            ));
        }
        let target = Target {
            capture: &a.capture,
            resource: &a.resource,
            after_pass: a.after_pass.as_deref(),
            sub: (
                a.mip.unwrap_or(0),
                a.layer.unwrap_or(0),
                a.slice.unwrap_or(0),
            ),
        };
        let (summary, image) = take!(self.replay_texture(&target, &peer, &meta, cancel).await);
        let (min, max, mean) = channel_stats(&image);
        let display = framelab_replay::export::display_rgba8(&image);
        let shown = fit(display, max_size);
        let mut png = Vec::new();
        take!(
            shown
                .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .map_err(|e| anyhow::anyhow!("encoding the PNG: {e}"))
        );
        let mut summary = summary;
        summary["width"] = json!(image.width);
        summary["height"] = json!(image.height);
        summary["shown"] = json!([shown.width(), shown.height()]);
        summary["channels"] = json!(image.channels);
        summary["min"] = json!(min);
        summary["max"] = json!(max);
        summary["mean"] = json!(mean);
        use base64::Engine as _;
        let data = base64::engine::general_purpose::STANDARD.encode(&png);
        let mut result = CallToolResult::success(vec![
            ContentBlock::text(summary.to_string()),
            ContentBlock::image(data, "image/png"),
        ]);
        result.structured_content = Some(summary);
        Ok(result)
    }

    #[tool(
        description = "Texel values of a texture region as it stood after a pass of frame 0, in the resource's own terms (float, normalised or integer channels as the inspector shows them), row by row; at most 4096 texels a call.",
        input_schema = schema_for_type::<TexelArgs>()
    )]
    async fn read_texels(
        &self,
        peer: Peer<RoleServer>,
        meta: rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
        object: JsonObject,
    ) -> Answer {
        let a: TexelArgs = take!(args("read_texels", object));
        let (w, h) = (a.width.unwrap_or(1), a.height.unwrap_or(1));
        if w == 0 || h == 0 || u64::from(w) * u64::from(h) > MAX_TEXELS {
            return refuse(format!(
                "a {w}x{h} region: read_texels returns 1 to {MAX_TEXELS} texels a call"
            ));
        }
        let target = Target {
            capture: &a.capture,
            resource: &a.resource,
            after_pass: a.after_pass.as_deref(),
            sub: (
                a.mip.unwrap_or(0),
                a.layer.unwrap_or(0),
                a.slice.unwrap_or(0),
            ),
        };
        let (mut summary, image) = take!(self.replay_texture(&target, &peer, &meta, cancel).await);
        let (x1, y1) = (u64::from(a.x) + u64::from(w), u64::from(a.y) + u64::from(h));
        if x1 > u64::from(image.width) || y1 > u64::from(image.height) {
            return refuse(format!(
                "the region {}..{x1} x {}..{y1} is outside the {}x{} subresource",
                a.x, a.y, image.width, image.height
            ));
        }
        let channels = image.channels.clamp(1, 4);
        let rows: Vec<Vec<Vec<f32>>> = (a.y..a.y + h)
            .map(|y| {
                (a.x..a.x + w)
                    .map(|x| {
                        let v = image.values[(y * image.width + x) as usize];
                        v[..channels].to_vec()
                    })
                    .collect()
            })
            .collect();
        summary["width"] = json!(image.width);
        summary["height"] = json!(image.height);
        summary["region"] = json!({"x": a.x, "y": a.y, "width": w, "height": h});
        summary["values"] = json!(rows);
        answer(summary)
    }

    #[tool(
        description = "Bytes of a buffer as they stood after a pass of frame 0: decoded as rows of the WGSL type of the variable that binds it (or of the indirect-argument records it feeds), as the inspector's buffer table shows them, and as hex; at most 65536 bytes a call.",
        input_schema = schema_for_type::<BufferArgs>()
    )]
    async fn read_buffer(
        &self,
        peer: Peer<RoleServer>,
        meta: rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
        object: JsonObject,
    ) -> Answer {
        let a: BufferArgs = take!(args("read_buffer", object));
        let (offset, length) = (a.offset.unwrap_or(0), a.length.unwrap_or(256));
        if length == 0 || length > MAX_BUFFER_BYTES {
            return refuse(format!(
                "length {length}: read_buffer returns 1 to {MAX_BUFFER_BYTES} bytes a call"
            ));
        }
        let (reply, answer_rx) = tokio::sync::oneshot::channel();
        {
            let mut store = self.store();
            let o = take!(store.get_mut(&a.capture));
            let r = take!(find_resource(o, &a.resource));
            if r.format.is_some() {
                return refuse(format!(
                    "\"{}\" is a texture: read it with read_texels",
                    r.name
                ));
            }
            take!(passes_through(o, a.after_pass.as_deref()));
            let request = super::replay::BufferRequest {
                resource: a.resource.clone(),
                after: a.after_pass.clone(),
                offset,
                length,
                progress: progress_sender(&peer, &meta),
                cancel,
                reply,
            };
            take!(o.worker().send(super::replay::Job::Buffer(request)));
        }
        let read = take!(take!(
            answer_rx
                .await
                .map_err(|_| anyhow::anyhow!("the replay stopped"))
        ));
        let rows = read
            .layouts
            .first()
            .map(|choice| decode_rows(choice, offset, &read.bytes));
        let hex = hex::encode(&read.bytes);
        answer(json!({
            "resource": a.resource,
            "after_pass": a.after_pass,
            "size": read.size,
            "offset": offset,
            "length": read.bytes.len(),
            "as": rows,
            "hex": hex,
        }))
    }

    #[tool(
        description = "Replay the frame a number of times on this machine's GPU and time every pass: the timing report `framelab replay --timings` writes (per-pass GPU and CPU times per frame, and the work each pass submits). With `counters`, each pass's pipeline statistics per frame too, as `replay --counters` writes them. Sends progress (frame i of n) and stops when cancelled.",
        input_schema = schema_for_type::<TimingsArgs>()
    )]
    async fn timings(
        &self,
        peer: Peer<RoleServer>,
        meta: rmcp::model::RequestMetaObject,
        cancel: tokio_util::sync::CancellationToken,
        object: JsonObject,
    ) -> Answer {
        let a: TimingsArgs = take!(args("timings", object));
        let frames = a.frames.unwrap_or(3);
        if frames == 0 || frames > MAX_FRAMES {
            return refuse(format!("frames {frames} is outside 1..={MAX_FRAMES}"));
        }
        let report = take!(
            self.replay_timings(
                &a.capture,
                (frames, a.counters.unwrap_or(false)),
                &peer,
                &meta,
                cancel
            )
            .await
        );
        answer(report)
    }

    #[tool(
        description = "What if the frame were changed: apply edits to an opened capture (a lint's fixes, `fix: [\"FL005\"]` or `[\"all\"]`; `cull` passes; `drop_barrier` `PASS:N`; `format` `RESOURCE=FORMAT`; `queue` `PASS=QUEUE`; `scale_resource` `RESOURCE=F`; `merge` `FIRST+SECOND`, two raster passes made one render pass), as `framelab what-if --json` does. The variant is checked first: an error the edits introduce (a missing barrier, a hazard, a read of what nothing wrote) is answered with `safe: false` and nothing runs. Otherwise both frames replay here interleaved, and the answer holds the timing diff, the work diff, memory, every texture compared after the last frame and after every pass (the first pass whose outputs differ), and one summary line; each changed texture comes back as two PNGs, the variant's image and the FLIP error map. A bad edit is a tool error naming it.",
        input_schema = schema_for_type::<WhatIfArgs>()
    )]
    async fn what_if(&self, object: JsonObject) -> Answer {
        use framelab_core::whatif::Edit;
        let a: WhatIfArgs = take!(args("what_if", object));
        let frames = a.frames.unwrap_or(5);
        if !(2..=MAX_FRAMES).contains(&frames) {
            return refuse(format!("frames {frames} is outside 2..={MAX_FRAMES}"));
        }
        let max_size = a.max_size.unwrap_or(512);
        if max_size == 0 || max_size > MAX_IMAGE_SIDE {
            return refuse(format!(
                "max_size {max_size} is outside 1..={MAX_IMAGE_SIDE}"
            ));
        }
        let parsed: Result<Vec<Edit>, _> = (a.fix.iter().map(|x| Edit::fix(x)))
            .chain(a.cull.iter().map(|x| Edit::cull(x)))
            .chain(a.drop_barrier.iter().map(|x| Edit::drop_barrier(x)))
            .chain(a.format.iter().map(|x| Edit::format(x)))
            .chain(a.queue.iter().map(|x| Edit::queue(x)))
            .chain(a.scale_resource.iter().map(|x| Edit::scale_resource(x)))
            .chain(a.merge.iter().map(|x| Edit::merge(x)))
            .collect();
        let edits = take!(parsed);
        if edits.is_empty() {
            return refuse(
                "what_if needs at least one edit (fix, cull, drop_barrier, format, queue, scale_resource, merge)",
            );
        }
        let (path, scale) = {
            let store = self.store();
            let o = take!(store.get(&a.capture));
            (o.path.clone(), o.scale)
        };
        let options = framelab_replay::what_if::Options {
            frames,
            warmup: 1,
            threshold_pct: 3.0,
            tolerance: 0.01,
            final_only: a.final_only.unwrap_or(false),
        };
        // Loading and replaying take a while: off the protocol's threads, on a device of
        // its own.
        let ran = tokio::task::spawn_blocking(move || {
            super::replay::what_if(&path, scale, &edits, &options)
        })
        .await;
        let report = take!(take!(
            ran.map_err(|e| anyhow::anyhow!("what_if stopped: {e}"))
        ));
        let mut content = vec![ContentBlock::text(report.summary.clone())];
        for c in &report.changed {
            let Some((_, b, map)) = &c.texture.images else {
                continue;
            };
            let mut shown = vec![b.clone()];
            shown.extend(
                map.iter()
                    .map(|m| image::DynamicImage::ImageRgb8(m.clone()).to_rgba8()),
            );
            for img in shown {
                let mut png = Vec::new();
                take!(
                    fit(img, max_size)
                        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                        .map_err(|e| anyhow::anyhow!("encoding the PNG: {e}"))
                );
                use base64::Engine as _;
                let data = base64::engine::general_purpose::STANDARD.encode(&png);
                content.push(ContentBlock::image(data, "image/png"));
            }
        }
        let mut result = CallToolResult::success(content);
        result.structured_content = Some(take!(serde_json::to_value(&report)));
        Ok(result)
    }

    #[tool(
        description = "Run a Vulkan program under GFXReconstruct's capture layer, take frame `frame`, stop the program, import the capture into `dir` (as `framelab capture` does) and open it: returns what open_capture returns.",
        input_schema = schema_for_type::<CaptureArgs>()
    )]
    async fn capture_program(&self, peer: Peer<RoleServer>, object: JsonObject) -> Answer {
        let a: CaptureArgs = take!(args("capture_program", object));
        let timeout = a.timeout.unwrap_or(60);
        if !(1..=600).contains(&timeout) || !(1..=1_000_000).contains(&a.frame) {
            return refuse(format!(
                "frame {} or timeout {timeout}: frame is 1..=1000000, timeout 1..=600 s",
                a.frame
            ));
        }
        let dir = take!(self.allowed(&peer, &a.dir).await);
        if !dir.is_dir() {
            return refuse(format!("{} is not a folder", dir.display()));
        }
        take!(self.store().room());
        let stem = Path::new(&a.program).file_name().map_or_else(
            || "capture".to_owned(),
            |n| n.to_string_lossy().into_owned(),
        );
        let frame = a.frame;
        let loaded = tokio::task::spawn_blocking(move || {
            let mut program = vec![a.program];
            program.extend(a.args);
            let gfxr = dir.join(format!("{stem}_frame{frame}.gfxr"));
            let written = framelab_core::import::program::take(&program, frame, timeout, &gfxr)?;
            std::fs::rename(&written, &gfxr)
                .map_err(|e| anyhow::anyhow!("moving the capture to {}: {e}", gfxr.display()))?;
            let json = gfxr.with_extension("json");
            super::imports::import_to(&gfxr, &json)?;
            store::load(&json, 1.0)
        })
        .await;
        let opened = take!(take!(
            loaded.map_err(|e| anyhow::anyhow!("capturing stopped: {e}"))
        ));
        let mut store = self.store();
        let (id, o) = take!(store.insert(opened));
        answer(json!({
            "capture": id,
            "path": o.path,
            "name": o.analysed.capture.name,
            "passes": o.info.passes.len(),
            "resources": o.info.resources.len(),
            "lints": o.report.lints.len(),
        }))
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
