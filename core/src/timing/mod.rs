//! Timing reports: what `framelab replay --timings` writes and what the diff reads. A report is
//! versioned and serialises both ways, names each pass with its queue and marker path (so two
//! frames can be matched without the capture), and keeps every frame's sample. The Chrome trace
//! and the summary statistics are derived from it here, not in the command that prints them.

pub mod counters;
pub mod diff;
pub mod plot;
pub mod render;
pub mod stats;
pub mod trace;
pub mod work_diff;

use serde::{Deserialize, Serialize};

/// The version of the timing report's JSON shape; a reader rejects newer ones.
/// Version 2 added work counters (`counters`, `work`); version 1 reports load unchanged.
pub const FORMAT_VERSION: u32 = 2;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimingReport {
    pub format_version: u32,
    pub adapter: String,
    pub backend: String,
    pub capture: String,
    pub capture_sha256: String,
    pub scale: f64,
    pub frames: u32,
    /// The first frames, run to let clocks and caches settle: kept here, left out of
    /// summaries and diffs.
    #[serde(default)]
    pub warmup: u32,
    /// Nanoseconds per timestamp tick: differences of a few ticks are not measurable.
    #[serde(default)]
    pub timestamp_period_ns: f32,
    /// How pass times were taken. Reports without the field predate chaining: pairs.
    #[serde(default = "StampLayout::before_chaining")]
    pub timestamps: StampLayout,
    pub passes: Vec<PassTiming>,
}

/// How a report's pass times were taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StampLayout {
    /// A pass starts at the previous pass's end stamp: its time includes the barriers before it.
    Chained,
    /// A pass has a start stamp of its own (`--timestamp-pairs`).
    Pairs,
}

impl StampLayout {
    fn before_chaining() -> Self {
        StampLayout::Pairs
    }

    pub fn name(self) -> &'static str {
        match self {
            StampLayout::Chained => "chained",
            StampLayout::Pairs => "pairs",
        }
    }
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PassTiming {
    pub name: String,
    pub queue: String,
    pub marker_path: String,
    /// raster, compute, copy, clear, resolve, generate_mips or present.
    #[serde(default)]
    pub kind: String,
    /// Resources the pass writes (sorted): with the kind and queue, what identifies a pass
    /// whose name changed between two reports.
    #[serde(default)]
    pub writes: Vec<String>,
    /// Bytes of the subresources the pass reads and writes at the replayed scale (its declared
    /// footprint; see `analysis::traffic`): with the GPU time, its achieved bandwidth.
    #[serde(default)]
    pub bytes_read: u64,
    #[serde(default)]
    pub bytes_written: u64,
    /// One per frame; `null` where the adapter could not time the pass.
    pub gpu_ns: Vec<Option<u64>>,
    pub cpu_ns: Vec<u64>,
    /// Why the adapter's timestamps do not measure this pass, when they do not: its samples
    /// are kept but no summary, verdict or frame sum uses them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gpu_untrusted: Option<String>,
    /// Pipeline statistics per frame, when the replay counted them (`replay --counters`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counters: Option<counters::Counters>,
    /// The work the pass submits, from the replayed plan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work: Option<counters::Work>,
}

impl PassTiming {
    /// The GPU samples summaries may use: none when the timestamps are untrusted.
    pub fn trusted_gpu_ns(&self) -> &[Option<u64>] {
        if self.gpu_untrusted.is_some() {
            &[]
        } else {
            &self.gpu_ns
        }
    }

    /// Bytes read and written.
    pub fn bytes_moved(&self) -> u64 {
        self.bytes_read.saturating_add(self.bytes_written)
    }
}

/// Why an adapter's timestamps do not measure passes of `kind`, if they do not.
///
/// Mesa's lavapipe (llvmpipe) writes a compute pass's timestamps while the dispatch is still
/// running on its thread pool: a 256-group dispatch that made every frame 0.43 s longer was
/// timed at 0.09 ms (raster passes and copies are timed as they run).
pub fn untrusted_timestamps(
    adapter_name: &str,
    device_type: wgpu_types::DeviceType,
    kind: crate::capture::format::PassKind,
) -> Option<String> {
    let software = device_type == wgpu_types::DeviceType::Cpu;
    (software && adapter_name.contains("llvmpipe") && kind == crate::capture::format::PassKind::Compute).then(|| {
        "lavapipe timestamps a compute pass before its dispatch has run; time it on a hardware GPU".to_owned()
    })
}

/// Achieved bandwidth in GB/s (10^9 bytes per second) of `bytes` moved in `ns`.
pub fn gigabytes_per_second(bytes: u64, ns: f64) -> Option<f64> {
    (ns > 0.0 && bytes > 0).then(|| bytes as f64 / ns)
}

/// One pass of one frame as measured: where its GPU work started (relative to the frame), how
/// long it took on the GPU, and how long recording it took on the CPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    pub gpu_start_ns: Option<u64>,
    pub gpu_ns: Option<u64>,
    pub cpu_ns: u64,
}

/// Why a timing report could not be read.
/// Where a timing report disagrees with itself.
#[derive(Debug, thiserror::Error)]
pub enum Inconsistency {
    #[error("${0} holds a control character")]
    ControlCharacter(String),
    #[error("{0} frames, more than the {MAX_FRAMES} a replay or a diff times")]
    TooManyFrames(u32),
    #[error("warmup {warmup} is more than its {frames} frames")]
    Warmup { warmup: u32, frames: u32 },
    #[error(
        "passes[{pass}] ({name}) has {samples} {what} samples, but the report says {frames} frames"
    )]
    Samples {
        pass: usize,
        name: String,
        samples: usize,
        what: &'static str,
        frames: u32,
    },
}

#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("{path}: not a timing report: {source}")]
    Parse {
        path: String,
        #[source]
        source: serde_json::Error,
    },
    #[error("{path}: {problem}")]
    Inconsistent {
        path: String,
        problem: Inconsistency,
    },
    #[error(
        "{path}: timing report format_version {found} is newer than this framelab reads ({supported})"
    )]
    Version {
        path: String,
        found: u32,
        supported: u32,
    },
}

/// The JSON path (below `$`) of the first string or member name under `v` holding a
/// control character; spelt only once one is found, so a report of many samples costs a scan.
fn hidden_text(v: &serde_json::Value) -> Option<String> {
    use serde_json::Value;
    let bad = |s: &str| s.chars().any(char::is_control);
    match v {
        Value::String(s) => bad(s).then(String::new),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, x)| Some(format!("[{i}]{}", hidden_text(x)?))),
        Value::Object(map) => map.iter().find_map(|(k, x)| {
            let below = if bad(k) {
                String::new()
            } else {
                hidden_text(x)?
            };
            Some(format!(".{}{below}", crate::text::printable(k)))
        }),
        _ => None,
    }
}

/// The most frames a report may hold: more than `replay --frames` or `diff --frames` ever
/// time, and a bound on what reading and comparing one costs.
pub const MAX_FRAMES: u32 = 100_000;

impl TimingReport {
    /// Parses a report written by `framelab replay --timings`; `path` names it in errors.
    pub fn from_json(path: &str, text: &str) -> Result<TimingReport, ReadError> {
        let value = serde_json::from_str(text).map_err(|source| ReadError::Parse {
            path: path.to_owned(),
            source,
        })?;
        TimingReport::from_value(path, value)
    }

    /// A report from JSON already parsed (a caller that looked at it first need not parse
    /// it again).
    pub fn from_value(path: &str, value: serde_json::Value) -> Result<TimingReport, ReadError> {
        // Its names are printed, coloured, to terminals: none may carry a control character.
        if let Some(at) = hidden_text(&value) {
            return Err(ReadError::Inconsistent {
                path: path.to_owned(),
                problem: Inconsistency::ControlCharacter(at),
            });
        }
        let report: TimingReport =
            serde_json::from_value(value).map_err(|source| ReadError::Parse {
                path: path.to_owned(),
                source,
            })?;
        if report.format_version > FORMAT_VERSION {
            return Err(ReadError::Version {
                path: path.to_owned(),
                found: report.format_version,
                supported: FORMAT_VERSION,
            });
        }
        report
            .consistent()
            .map_err(|problem| ReadError::Inconsistent {
                path: path.to_owned(),
                problem,
            })?;
        Ok(report)
    }

    /// Whether the declared frame counts agree with the samples: every per-frame list holds
    /// one sample a frame, so no reader walks frames the report does not have.
    fn consistent(&self) -> Result<(), Inconsistency> {
        let frames = self.frames;
        if frames > MAX_FRAMES {
            return Err(Inconsistency::TooManyFrames(frames));
        }
        if self.warmup > frames {
            let warmup = self.warmup;
            return Err(Inconsistency::Warmup { warmup, frames });
        }
        for (i, p) in self.passes.iter().enumerate() {
            for (what, n) in [("gpu_ns", p.gpu_ns.len()), ("cpu_ns", p.cpu_ns.len())] {
                if n as u64 != u64::from(frames) {
                    return Err(Inconsistency::Samples {
                        pass: i,
                        name: p.name.clone(),
                        samples: n,
                        what,
                        frames,
                    });
                }
            }
        }
        Ok(())
    }

    /// Pretty JSON with a trailing newline, as written to disk.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default() + "\n"
    }
}
