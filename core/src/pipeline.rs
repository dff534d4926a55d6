//! The one journey from a capture file to a frame ready for a device, as typed stages each built
//! by value from the one before and holding what it derived:
//!
//! `Loaded` (the file read once, hashed, parsed) -> `Validated` (typed ids, sizes resolved for
//! one scale, shaders reflected) -> `Analysed` (the pass DAG, order, culling, barriers, memory,
//! lints, schedule) -> `Lowered` (the replay plan for one device's features).
//!
//! Every command, the inspector, the benchmarks and the tests walk these; none writes its own
//! copy of the sequence. The replay crate adds the one stage that needs a device (`Replaying`).
//! A stage that fails returns a `StageError` that says which stage and carries the error it
//! met; the command line turns it into the messages users read.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use sha2::Digest;
use wgpu_types::Features;

use crate::analysis::graph::CycleError;
use crate::analysis::report::{Analysis, AnalyzeOptions};
use crate::capture::format::RawCapture;
use crate::capture::model::{Capture, InitialDesc, PassId, ResourceId};
use crate::capture::{CaptureError, Diagnostic, Options};
use crate::lower::{self, LowerError};
use crate::plan::Plan;

/// Why a stage could not be built.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    /// Reading, parsing or validating the capture (`Loaded::read`, `Loaded::validate`).
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// The pass graph has a cycle (`Validated::analyse`). The message is the cycle's own,
    /// so it is not also given as a source (a chain of causes would print it twice).
    #[error("{}: {cycle}", path.display())]
    Cycle { path: PathBuf, cycle: CycleError },
    /// The capture cannot be replayed at all (an import without shaders or contents).
    #[error("{why}")]
    NotReplayable { path: PathBuf, why: String },
    /// The capture does not lower for this device (`Analysed::lower`).
    #[error(transparent)]
    Lower(#[from] LowerError),
}

impl StageError {
    /// The problems as diagnostics: every validation error, or the one thing that stopped it.
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        match self {
            StageError::Capture(e) => e.diagnostics(),
            e => vec![Diagnostic {
                severity: crate::capture::Severity::Error,
                code: "stage",
                path: "$".into(),
                message: e.to_string(),
                suggestion: None,
            }],
        }
    }
}

/// The capture's bytes, read through `files` (a regular file within the capture limit); a
/// file system error keeps the words it always had.
fn read_file(path: &Path) -> Result<Vec<u8>, StageError> {
    crate::files::read(path, crate::files::CAPTURE).map_err(|e| {
        StageError::Capture(match e {
            crate::files::FileError::Io { path, error } => CaptureError::Read {
                path,
                source: error,
            },
            e => CaptureError::File(e),
        })
    })
}

/// The capture file read once and parsed into the serde form; for a replay, its bytes hashed too
/// (timing reports name the capture they timed by this hash).
#[derive(Debug)]
pub struct Loaded {
    pub path: PathBuf,
    /// SHA-256 of the file's bytes, when read with `read_hashed`.
    pub sha256: Option<String>,
    pub raw: RawCapture,
}

impl Loaded {
    /// Reads and parses a capture file.
    pub fn read(path: &Path) -> Result<Loaded, StageError> {
        Self::from_bytes(path, &read_file(path)?)
    }

    /// Reads and parses a capture file and hashes its bytes, for a replay's timing report. Only
    /// replays pay for the hash (about 5% of loading and validating a large capture).
    pub fn read_hashed(path: &Path) -> Result<Loaded, StageError> {
        let bytes = read_file(path)?;
        let mut loaded = Self::from_bytes(path, &bytes)?;
        loaded.sha256 = Some(format!("{:x}", sha2::Sha256::digest(&bytes)));
        Ok(loaded)
    }

    /// Parses a capture already in memory; `path` names it and locates its side files.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Loaded, StageError> {
        Ok(Loaded {
            path: path.to_owned(),
            sha256: None,
            raw: crate::capture::load::parse(path, bytes)?,
        })
    }

    /// A capture built in memory (an import), named by `path`.
    pub fn from_raw(path: &Path, raw: RawCapture) -> Loaded {
        Loaded {
            path: path.to_owned(),
            sha256: None,
            raw,
        }
    }

    /// Validates it for `options` (output scale, limits): every error, not the first.
    pub fn validate(self, options: &Options) -> Result<Validated, StageError> {
        let v = crate::capture::validate::validate(&self.raw, &self.path, options)?;
        Ok(Validated {
            path: self.path,
            sha256: self.sha256,
            capture: v.capture,
            warnings: v.warnings,
        })
    }
}

/// A capture with typed ids, sizes resolved for one output scale and every shader reflected.
#[derive(Debug, Clone)]
pub struct Validated {
    pub path: PathBuf,
    pub sha256: Option<String>,
    pub capture: Capture,
    pub warnings: Vec<Diagnostic>,
}

impl Validated {
    /// Reads, parses and validates a capture file: the first two stages in one call.
    pub fn load(path: &Path, options: &Options) -> Result<Validated, StageError> {
        Loaded::read(path)?.validate(options)
    }

    /// Whether the pass graph can be ordered (it has no cycle), as `analyse` would find.
    pub fn check_order(&self) -> Result<(), StageError> {
        crate::analysis::check_order(&self.capture).map_err(|cycle| StageError::Cycle {
            path: self.path.clone(),
            cycle,
        })
    }

    /// Builds the pass DAG and everything derived from it.
    pub fn analyse(self, options: AnalyzeOptions) -> Result<Analysed, StageError> {
        let analysis = self.analysis(options)?;
        Ok(Analysed {
            path: self.path,
            sha256: self.sha256,
            capture: self.capture,
            analysis,
        })
    }

    /// The analysis `analyse` derives, leaving this stage as it is (to analyse it again, with
    /// other options or in a benchmark).
    pub fn analysis(&self, options: AnalyzeOptions) -> Result<Analysis, StageError> {
        crate::analysis::report::analyze(&self.capture, options).map_err(|cycle| {
            StageError::Cycle {
                path: self.path.clone(),
                cycle,
            }
        })
    }
}

/// A validated capture and its analysis.
#[derive(Debug)]
pub struct Analysed {
    pub path: PathBuf,
    pub sha256: Option<String>,
    pub capture: Capture,
    pub analysis: Analysis,
}

impl Analysed {
    /// Loads, validates and analyses a capture file.
    pub fn load(
        path: &Path,
        options: &Options,
        analyse: AnalyzeOptions,
    ) -> Result<Analysed, StageError> {
        Validated::load(path, options)?.analyse(analyse)
    }

    /// The journey of every front end that replays (`replay`, `diff`, `inspect`, the MCP
    /// server's worker, the benchmarks): a capture file read with its digest (a replay's
    /// timing report names the capture by it), validated, analysed, and refused here where it
    /// cannot be replayed, before any device opens.
    pub fn for_replay(
        path: &Path,
        options: &Options,
        analyse: AnalyzeOptions,
    ) -> Result<Analysed, StageError> {
        Loaded::read_hashed(path)?
            .validate(options)?
            .analyse(analyse)?
            .replayable()
    }

    /// Why this capture cannot be replayed (an import without shaders or contents), if so:
    /// asked before any device opens.
    pub fn replayable(self) -> Result<Analysed, StageError> {
        match self.capture.not_replayable() {
            Some(why) => Err(StageError::NotReplayable {
                path: self.path,
                why,
            }),
            None => Ok(self),
        }
    }

    /// The replay plan for a device with the `available` features (`adapter` names it in
    /// errors), passes in the analysis's order.
    pub fn lower(self, available: Features, adapter: &str) -> Result<Lowered, StageError> {
        self.lower_with(available, adapter, lower::Texels::Load)
    }

    /// As [`Analysed::lower`], with textures' contents loaded or left out (`texels`: left out
    /// to judge whether the frame replays, as `import` does).
    pub fn lower_with(
        self,
        available: Features,
        adapter: &str,
        texels: lower::Texels,
    ) -> Result<Lowered, StageError> {
        let frame = lower::lower_with(
            &self.capture,
            &self.analysis.order,
            available,
            adapter,
            texels,
        )?;
        let mut notes = frame.notes;
        notes.extend(
            unknown_reads(&self.capture, &frame.pass_ids)
                .into_iter()
                .map(|(resource, pass)| {
                    format!(
                        "\"{resource}\" is read by pass \"{pass}\" before the frame writes it, and the capture holds no contents for it (earlier GPU work, or memory only in the driver's own layout): it starts cleared, so what that pass reads may not be what the program read"
                    )
                }),
        );
        Ok(Lowered {
            analysed: self,
            plan: frame.plan,
            texture_of: frame.texture_of,
            buffer_of: frame.buffer_of,
            pass_ids: frame.pass_ids,
            notes,
        })
    }
}

/// The resources the frame reads before anything in it writes them and whose contents at its
/// start the capture does not hold (an imported frame's `before_capture`), each with the
/// first pass that reads it, in execution order (`order`, capture passes). Swapchain images
/// are left out: an acquired image's contents are undefined to the program too.
pub fn unknown_reads(capture: &Capture, order: &[PassId]) -> Vec<(String, String)> {
    let mut settled = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for &p in order {
        let pass = capture.pass(p);
        for a in &pass.accesses {
            let r = capture.resource(a.resource);
            if r.initial != InitialDesc::BeforeCapture || r.swapchain {
                continue;
            }
            if (a.reads || !a.writes) && settled.insert(a.resource) {
                out.push((r.name.clone(), pass.name.clone()));
            }
            if a.writes {
                settled.insert(a.resource);
            }
        }
    }
    out
}

/// An analysed capture lowered to a replay plan for one device.
#[derive(Debug)]
pub struct Lowered {
    pub analysed: Analysed,
    pub plan: Plan,
    /// The plan texture of each capture texture.
    pub texture_of: BTreeMap<ResourceId, usize>,
    /// The plan buffer of each capture buffer.
    pub buffer_of: BTreeMap<ResourceId, usize>,
    /// The capture pass of each plan pass.
    pub pass_ids: Vec<PassId>,
    /// What the lowering chose on its own (formats substituted and the like).
    pub notes: Vec<String>,
}

impl Lowered {
    pub fn capture(&self) -> &Capture {
        &self.analysed.capture
    }
}
