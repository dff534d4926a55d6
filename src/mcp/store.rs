//! The captures an MCP session has opened, by id, with what every question about them reads:
//! the validated and analysed frame, its `info` and `analyze` reports and its DAG. Names a
//! client sends (captures, passes, resources) are resolved here, with a did-you-mean.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use framelab_core::analysis::report::{self, AnalyzeOptions, GraphReport, Report};
use framelab_core::capture::Options;
use framelab_core::info::InfoReport;
use framelab_core::pipeline::{Analysed, Loaded};
use serde_json::Value;

/// One opened capture.
pub struct Opened {
    pub path: PathBuf,
    pub scale: f64,
    pub analysed: Analysed,
    pub info: InfoReport,
    pub report: Report,
    pub graph: GraphReport,
    /// Each pass as the file records it (bindings, attachments, draws, recorded barriers).
    pub recorded: BTreeMap<String, Value>,
    /// The replay behind `texture`, started on its first request.
    pub worker: Option<super::replay::Worker>,
    /// For an import: the file imported, and the scratch folder holding what it became.
    pub imported_from: Option<(PathBuf, PathBuf)>,
}

impl Drop for Opened {
    /// An import's scratch folder goes with it (after its replay worker has stopped).
    fn drop(&mut self) {
        self.worker = None;
        if let Some((_, scratch)) = &self.imported_from {
            let _ = std::fs::remove_dir_all(scratch);
        }
    }
}

/// Every opened capture of the session.
#[derive(Default)]
pub struct Store {
    next: u32,
    scratch: u32,
    open: BTreeMap<String, Opened>,
}

/// The most captures one session keeps open (each holds its analysis in memory).
pub const MAX_OPEN: usize = 16;

impl Store {
    /// A fresh name for an import's scratch folder.
    pub fn next_scratch(&mut self) -> String {
        self.scratch += 1;
        format!("import-{}", self.scratch)
    }

    /// Refuses another capture once `MAX_OPEN` are open (checked before loading one).
    pub fn room(&self) -> anyhow::Result<()> {
        if self.open.len() >= MAX_OPEN {
            return Err(anyhow::anyhow!(
                "{MAX_OPEN} captures are open: close one (close_capture) before opening another"
            ));
        }
        Ok(())
    }

    pub fn insert(&mut self, opened: Opened) -> anyhow::Result<(String, &Opened)> {
        self.room()?;
        self.next += 1;
        let id = format!("c{}", self.next);
        let entry = self.open.entry(id.clone()).or_insert(opened);
        Ok((id, entry))
    }

    pub fn get(&self, id: &str) -> anyhow::Result<&Opened> {
        self.open.get(id).ok_or_else(|| {
            unknown(
                "capture id",
                id,
                self.open.keys().map(String::as_str),
                "open_capture returns one",
            )
        })
    }

    pub fn get_mut(&mut self, id: &str) -> anyhow::Result<&mut Opened> {
        self.get(id)?;
        self.open
            .get_mut(id)
            .ok_or_else(|| anyhow::anyhow!("no capture \"{id}\""))
    }

    pub fn close(&mut self, id: &str) -> anyhow::Result<Opened> {
        self.get(id)?;
        self.open
            .remove(id)
            .ok_or_else(|| anyhow::anyhow!("no capture \"{id}\""))
    }
}

impl Opened {
    /// The capture's replay worker, started on first use.
    pub fn worker(&mut self) -> &super::replay::Worker {
        let (path, scale) = (&self.path, self.scale);
        self.worker
            .get_or_insert_with(|| super::replay::Worker::start(path.clone(), scale))
    }
}

/// Loads, validates and analyses a capture file as every command does; the error is the
/// command line's message (the file's diagnostics listed).
pub fn load(path: &Path, scale: f64) -> anyhow::Result<Opened> {
    let loaded = Loaded::read(path).map_err(|e| anyhow::anyhow!(stage_error(&e)))?;
    let recorded = loaded
        .raw
        .passes
        .iter()
        .filter_map(|p| Some((p.name.clone(), serde_json::to_value(p).ok()?)))
        .collect();
    let options = Options {
        scale,
        ..Options::default()
    };
    let validated = loaded
        .validate(&options)
        .map_err(|e| anyhow::anyhow!(stage_error(&e)))?;
    let analysed = validated
        .analyse(AnalyzeOptions { cull: false })
        .map_err(|e| anyhow::anyhow!(stage_error(&e)))?;
    let info = framelab_core::info::report(&analysed.capture);
    let report = report::report(&analysed.capture, &analysed.analysis);
    let graph = report::graph_report(&analysed.analysis);
    Ok(Opened {
        path: path.to_path_buf(),
        scale,
        analysed,
        info,
        report,
        graph,
        recorded,
        worker: None,
        imported_from: None,
    })
}

/// A stage error with every diagnostic it carries, one per line.
fn stage_error(e: &framelab_core::pipeline::StageError) -> String {
    let mut text = e.to_string();
    if !matches!(e, framelab_core::pipeline::StageError::Capture(_)) {
        return text;
    }
    for d in e.diagnostics().iter().take(50) {
        text.push('\n');
        text.push_str(&d.to_string());
    }
    text
}

/// "no <what> "<name>"", with the closest known names.
pub fn unknown<'a>(
    what: &str,
    name: &str,
    known: impl Iterator<Item = &'a str>,
    hint: &str,
) -> anyhow::Error {
    let mut scored: Vec<(f64, &str)> = known
        .map(|k| (strsim::jaro_winkler(name, k), k))
        .filter(|(s, _)| *s > 0.8)
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(b.1)));
    match scored.first() {
        Some((_, best)) => anyhow::anyhow!("no {what} \"{name}\": did you mean \"{best}\"?"),
        None => anyhow::anyhow!("no {what} \"{name}\" ({hint})"),
    }
}
