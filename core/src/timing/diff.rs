//! Comparing two timing reports pass by pass: which passes match (queue, marker path, name and
//! occurrence; a pass whose name changed but whose kind, queue and written resources did not is
//! a rename), then for every matched pass, every queue, every marker group and the frame total,
//! the ratio of medians B/A with a bootstrap interval, a Mann-Whitney test, and a verdict that
//! needs significance, an interval wholly beyond the threshold, and a difference the timestamps
//! can resolve. The frame total is the primary outcome and is tested on its own; the
//! Holm-Bonferroni adjustment runs within each family of secondary rows (the queues and marker
//! groups, the passes), so a frame that halved its cost is not held back by 150 pass rows.

use std::collections::BTreeMap;

use serde::Serialize;

pub use crate::matching::Matching;
use crate::matching::match_items;

use super::stats::{holm, mann_whitney, median, rank_test_floor, ratio_interval, samples_needed};
use super::{PassTiming, TimingReport};

/// The version of the diff's JSON shape.
pub const DIFF_FORMAT_VERSION: u32 = 1;

/// Significance level of the family of comparisons.
const ALPHA: f64 = 0.05;
/// Share of the frame total a pass must take for its regression to fail the gate.
pub const GATE_SHARE: f64 = 0.01;
/// Timestamp ticks a difference must exceed to count as measured.
const RESOLUTION_TICKS: f64 = 4.0;

#[derive(Clone, Copy, Debug)]
pub struct DiffOptions {
    /// A row moves only when its whole interval lies beyond this change, in percent.
    pub threshold_pct: f64,
    /// Regressions beyond this change, in percent, fail the gate (default: `threshold_pct`).
    pub fail_on_regression_pct: Option<f64>,
    pub resamples: usize,
    pub seed: u64,
}

impl Default for DiffOptions {
    fn default() -> Self {
        DiffOptions {
            threshold_pct: 3.0,
            fail_on_regression_pct: None,
            resamples: 2000,
            seed: 0x5eed,
        }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DiffError {
    #[error("the reports were replayed at different scales ({a} and {b}): compare like with like")]
    Scale { a: f64, b: f64 },
    #[error(
        "the reports time passes differently ({a} and {b} timestamps): replay both with or both without --timestamp-pairs"
    )]
    Timestamps { a: &'static str, b: &'static str },
    #[error("the reports come from different adapters (\"{a}\" and \"{b}\")")]
    Adapter { a: String, b: String },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RowKind {
    Total,
    Queue,
    Marker,
    Pass,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "verdict")]
pub enum Verdict {
    Regression,
    Improvement,
    Unchanged,
    /// Too few samples to tell; `needed` per side would resolve the observed change.
    Inconclusive {
        needed: Option<usize>,
    },
    /// The adapter did not time it.
    Untimed,
}

/// One compared row: a pass, a queue, a marker group or the frame total.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    pub kind: RowKind,
    pub name: String,
    pub queue: String,
    /// Name in A, where a rename matched it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub renamed_from: Option<String>,
    pub samples: [usize; 2],
    pub median_a_ns: f64,
    pub median_b_ns: f64,
    /// (B - A) / A in percent, of the medians.
    pub change_pct: f64,
    /// 95% bootstrap interval of the change, in percent.
    pub interval_pct: Option<[f64; 2]>,
    pub p: Option<f64>,
    pub p_adjusted: Option<f64>,
    #[serde(flatten)]
    pub verdict: Verdict,
    /// Bytes the row's passes read and write per frame, in A and in B.
    pub bytes_moved: [u64; 2],
    /// Those bytes over the median GPU time, in GB/s, in A and in B.
    pub bandwidth_gbps: [Option<f64>; 2],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Side {
    pub capture: String,
    pub adapter: String,
    pub scale: f64,
    pub frames: u32,
    pub warmup: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DiffReport {
    pub format_version: u32,
    pub a: Side,
    pub b: Side,
    pub threshold_pct: f64,
    /// Sorted: the total first, then by absolute change.
    pub rows: Vec<Row>,
    /// Passes only in B, and only in A (queue / marker path / name).
    pub added: Vec<String>,
    pub removed: Vec<String>,
}

impl DiffReport {
    /// Whether a gate at `fail_pct` fails: a significant regression larger than it in the
    /// frame total or in a pass whose regression adds at least `GATE_SHARE` of the frame (a
    /// 70 us upload 30% slower under a loaded machine moves a 6 ms frame 0.4%). Queue and group
    /// rows, and passes too small to move the frame, explain; they do not gate: their timings
    /// are where timestamp overheads and scheduling noise dominate (on lavapipe a 60 us copy
    /// reads 60 us in one session and 130 us in another of the same capture).
    pub fn fails(&self, fail_pct: f64) -> bool {
        let frame = self
            .rows
            .iter()
            .find(|r| r.kind == RowKind::Total)
            .map_or(0.0, |r| r.median_a_ns.max(r.median_b_ns));
        self.rows.iter().any(|r| {
            let gates = match r.kind {
                RowKind::Total => true,
                RowKind::Pass => r.median_b_ns - r.median_a_ns >= GATE_SHARE * frame,
                _ => false,
            };
            gates && r.verdict == Verdict::Regression && r.change_pct > fail_pct
        })
    }
}

/// Matches passes by queue, marker path, name and occurrence, then unmatched ones by (kind,
/// queue, written resources) when that is unambiguous on both sides. A pass that moved to
/// another queue is another pass here: its timing is not comparable.
pub fn match_passes(a: &[PassTiming], b: &[PassTiming]) -> Matching {
    match_items(
        a,
        b,
        |p| (p.queue.clone(), p.marker_path.clone(), p.name.clone()),
        |p| {
            (!p.kind.is_empty() && !p.writes.is_empty())
                .then(|| (p.kind.clone(), p.queue.clone(), p.writes.clone()))
        },
    )
}

/// GPU samples of measured (post-warm-up) frames.
fn samples(p: &PassTiming, warmup: u32) -> Vec<f64> {
    p.trusted_gpu_ns()
        .iter()
        .skip(warmup as usize)
        .flatten()
        .map(|&ns| ns as f64)
        .collect()
}

/// Per measured frame, the sum of the given passes' GPU times (frames where one is untimed are
/// left out; passes whose timestamps the adapter cannot be trusted for are not summed).
fn frame_sums(report: &TimingReport, passes: &[usize]) -> Vec<f64> {
    let trusted: Vec<usize> = passes
        .iter()
        .copied()
        .filter(|&i| report.passes[i].gpu_untrusted.is_none())
        .collect();
    if trusted.is_empty() {
        return Vec::new();
    }
    (report.warmup as usize..report.frames as usize)
        .filter_map(|f| {
            trusted
                .iter()
                .map(|&i| report.passes[i].gpu_ns.get(f).copied().flatten())
                .sum::<Option<u64>>()
                .map(|ns| ns as f64)
        })
        .collect()
}

struct Pending {
    kind: RowKind,
    name: String,
    queue: String,
    renamed_from: Option<String>,
    a: Vec<f64>,
    b: Vec<f64>,
    bytes: [u64; 2],
}

/// Bytes the given passes move per frame.
fn bytes_of(report: &TimingReport, passes: &[usize]) -> u64 {
    passes
        .iter()
        .map(|&i| report.passes[i].bytes_moved())
        .fold(0, u64::saturating_add)
}

fn side(r: &TimingReport) -> Side {
    Side {
        capture: r.capture.clone(),
        adapter: r.adapter.clone(),
        scale: r.scale,
        frames: r.frames,
        warmup: r.warmup,
    }
}

/// queue/markers/name of a pass (its marker path ends with its name).
fn label(p: &PassTiming) -> String {
    if p.marker_path.is_empty() {
        format!("{}/{}", p.queue, p.name)
    } else {
        format!("{}/{}", p.queue, p.marker_path)
    }
}

/// Rows of groups of passes: each side's queues and marker groups (the markers above each
/// pass), with the passes of that side in them.
fn groups(report: &TimingReport) -> BTreeMap<(RowKind, String), Vec<usize>> {
    let mut groups: BTreeMap<(RowKind, String), Vec<usize>> = BTreeMap::new();
    for (i, p) in report.passes.iter().enumerate() {
        groups
            .entry((RowKind::Queue, p.queue.clone()))
            .or_default()
            .push(i);
        // The marker path ends with the pass's own name: groups are the markers above it.
        let parts: Vec<&str> = p.marker_path.split('/').filter(|s| !s.is_empty()).collect();
        let mut path = String::new();
        for part in &parts[..parts.len().saturating_sub(1)] {
            if !path.is_empty() {
                path.push('/');
            }
            path.push_str(part);
            groups
                .entry((RowKind::Marker, path.clone()))
                .or_default()
                .push(i);
        }
    }
    groups
}

/// The rows to compare: the frame total and each queue and marker group found on both sides
/// (every pass of each side, added and removed ones included), then each matched pass.
fn pending_rows(a: &TimingReport, b: &TimingReport, m: &Matching) -> Vec<Pending> {
    let all = |r: &TimingReport| (0..r.passes.len()).collect::<Vec<_>>();
    let mut rows = vec![Pending {
        kind: RowKind::Total,
        name: "frame total".into(),
        queue: String::new(),
        renamed_from: None,
        a: frame_sums(a, &all(a)),
        b: frame_sums(b, &all(b)),
        bytes: [bytes_of(a, &all(a)), bytes_of(b, &all(b))],
    }];
    let (ga, gb) = (groups(a), groups(b));
    let mut keys: Vec<&(RowKind, String)> = ga.keys().chain(gb.keys()).collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        let (kind, name) = key.clone();
        // A queue or group on one side only has nothing to compare with: its passes are
        // listed as added or removed.
        let (Some(pa), Some(pb)) = (ga.get(key), gb.get(key)) else {
            continue;
        };
        rows.push(Pending {
            kind,
            queue: if kind == RowKind::Queue {
                name.clone()
            } else {
                String::new()
            },
            name,
            renamed_from: None,
            a: frame_sums(a, pa),
            b: frame_sums(b, pb),
            bytes: [bytes_of(a, pa), bytes_of(b, pb)],
        });
    }
    for &(i, j) in &m.pairs {
        let (pa, pb) = (&a.passes[i], &b.passes[j]);
        rows.push(Pending {
            kind: RowKind::Pass,
            name: pb.name.clone(),
            queue: pb.queue.clone(),
            renamed_from: m.renamed.contains(&(i, j)).then(|| pa.name.clone()),
            a: samples(pa, a.warmup),
            b: samples(pb, b.warmup),
            bytes: [pa.bytes_moved(), pb.bytes_moved()],
        });
    }
    rows
}

/// Compares report B against report A.
pub fn diff(a: &TimingReport, b: &TimingReport, o: &DiffOptions) -> Result<DiffReport, DiffError> {
    if a.scale != b.scale {
        return Err(DiffError::Scale {
            a: a.scale,
            b: b.scale,
        });
    }
    if a.adapter != b.adapter {
        return Err(DiffError::Adapter {
            a: a.adapter.clone(),
            b: b.adapter.clone(),
        });
    }
    if a.timestamps != b.timestamps {
        return Err(DiffError::Timestamps {
            a: a.timestamps.name(),
            b: b.timestamps.name(),
        });
    }
    let m = match_passes(&a.passes, &b.passes);
    let pending = pending_rows(a, b, &m);
    let tests: Vec<Option<f64>> = pending
        .iter()
        .map(|r| mann_whitney(&r.a, &r.b).map(|t| t.p))
        .collect();
    let (adjusted, family_sizes) = adjust_by_family(&pending, &tests);
    let tick = f64::from(a.timestamp_period_ns.max(b.timestamp_period_ns)).max(1.0);
    let mut rows: Vec<Row> = pending
        .into_iter()
        .zip(tests)
        .zip(adjusted.into_iter().zip(family_sizes))
        .enumerate()
        .map(|(k, ((r, p), (p_adjusted, m)))| {
            // The row's share of the family's error rate at worst (Holm's first step).
            let alpha = ALPHA / m.max(1) as f64;
            row(r, p, p_adjusted, alpha, tick, o, k as u64)
        })
        .collect();
    rows.sort_by(|x, y| {
        (x.kind != RowKind::Total)
            .cmp(&(y.kind != RowKind::Total))
            .then(y.change_pct.abs().total_cmp(&x.change_pct.abs()))
            .then(x.kind.cmp(&y.kind))
            .then(x.name.cmp(&y.name))
    });
    Ok(DiffReport {
        format_version: DIFF_FORMAT_VERSION,
        a: side(a),
        b: side(b),
        threshold_pct: o.threshold_pct,
        rows,
        added: m.added.iter().map(|&j| label(&b.passes[j])).collect(),
        removed: m.removed.iter().map(|&i| label(&a.passes[i])).collect(),
    })
}

/// The family a row's test is corrected within: the frame total alone (the primary outcome),
/// the queues and marker groups, the passes.
fn family(kind: RowKind) -> usize {
    match kind {
        RowKind::Total => 0,
        RowKind::Queue | RowKind::Marker => 1,
        RowKind::Pass => 2,
    }
}

/// Holm-adjusted p-values within each row's family, and the number of tests in that family.
fn adjust_by_family(pending: &[Pending], tests: &[Option<f64>]) -> (Vec<Option<f64>>, Vec<usize>) {
    let mut adjusted = vec![None; tests.len()];
    let mut sizes = vec![0; tests.len()];
    for f in 0..3 {
        let members: Vec<usize> = (0..tests.len())
            .filter(|&i| family(pending[i].kind) == f && tests[i].is_some())
            .collect();
        let ps: Vec<f64> = members.iter().filter_map(|&i| tests[i]).collect();
        for (&i, q) in members.iter().zip(holm(&ps)) {
            adjusted[i] = Some(q);
        }
        for i in (0..tests.len()).filter(|&i| family(pending[i].kind) == f) {
            sizes[i] = members.len();
        }
    }
    (adjusted, sizes)
}

/// The statistics and verdict of one row; `alpha` is the level its test must reach within
/// its family, which the frames it needs are counted for.
fn row(
    r: Pending,
    p: Option<f64>,
    p_adjusted: Option<f64>,
    alpha: f64,
    tick: f64,
    o: &DiffOptions,
    k: u64,
) -> Row {
    let (ma, mb) = (median(&r.a), median(&r.b));
    let change_pct = if ma > 0.0 {
        (mb / ma - 1.0) * 100.0
    } else {
        0.0
    };
    let interval = ratio_interval(&r.a, &r.b, o.resamples, o.seed.wrapping_add(k))
        .map(|(lo, hi)| [(lo - 1.0) * 100.0, (hi - 1.0) * 100.0]);
    let verdict = match (p_adjusted, interval) {
        _ if r.a.is_empty() || r.b.is_empty() => Verdict::Untimed,
        (Some(q), Some([lo, hi])) => {
            let resolved = (mb - ma).abs() > RESOLUTION_TICKS * tick;
            if q < ALPHA && lo > o.threshold_pct && resolved {
                Verdict::Regression
            } else if q < ALPHA && hi < -o.threshold_pct && resolved {
                Verdict::Improvement
            } else if lo >= -o.threshold_pct && hi <= o.threshold_pct {
                Verdict::Unchanged
            } else {
                Verdict::Inconclusive {
                    needed: needed(&r.a, &r.b, ma, mb, o.threshold_pct, alpha),
                }
            }
        }
        _ => Verdict::Inconclusive { needed: None },
    };
    Row {
        kind: r.kind,
        name: r.name,
        queue: r.queue,
        renamed_from: r.renamed_from,
        samples: [r.a.len(), r.b.len()],
        median_a_ns: ma,
        median_b_ns: mb,
        change_pct,
        interval_pct: interval,
        p,
        p_adjusted,
        verdict,
        bytes_moved: r.bytes,
        bandwidth_gbps: [
            super::gigabytes_per_second(r.bytes[0], ma),
            super::gigabytes_per_second(r.bytes[1], mb),
        ],
    }
}

/// Samples per side that would settle the row: the observed change must be told apart from the
/// threshold (beyond it: a regression or an improvement; within it: unchanged), so the effect
/// to resolve is the change's distance from the threshold, against the observed spread, at the
/// level `alpha` the row's test must reach within its family; and never fewer than the rank
/// test needs to reach that level at all. `None` where that distance is nil or the row already
/// has the samples.
fn needed(a: &[f64], b: &[f64], ma: f64, mb: f64, threshold_pct: f64, alpha: f64) -> Option<usize> {
    let spread = |xs: &[f64], m: f64| {
        let dev: Vec<f64> = xs.iter().map(|x| (x - m).abs()).collect();
        1.4826 * median(&dev)
    };
    let sigma = (spread(a, ma) + spread(b, mb)) / 2.0;
    let distance = ((mb - ma).abs() - threshold_pct / 100.0 * ma).abs();
    let by_effect = if sigma > 0.0 {
        samples_needed(distance / sigma, alpha)?
    } else if distance > 0.0 {
        // No spread at all: any sample resolves the change, once the test can reach alpha.
        0
    } else {
        return None;
    };
    Some(by_effect.max(rank_test_floor(alpha))).filter(|&n| n > a.len().min(b.len()))
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    use super::*;
    use crate::timing::FORMAT_VERSION;

    fn pass(name: &str, queue: &str, kind: &str, writes: &[&str], gpu: Vec<u64>) -> PassTiming {
        PassTiming {
            name: name.into(),
            queue: queue.into(),
            marker_path: format!("Frame/{name}"),
            kind: kind.into(),
            writes: writes.iter().map(|w| (*w).to_owned()).collect(),
            cpu_ns: vec![0; gpu.len()],
            gpu_ns: gpu.into_iter().map(Some).collect(),
            ..PassTiming::default()
        }
    }

    fn report(passes: Vec<PassTiming>) -> TimingReport {
        TimingReport {
            format_version: FORMAT_VERSION,
            adapter: "test".into(),
            backend: "vulkan".into(),
            capture: "c".into(),
            capture_sha256: String::new(),
            scale: 1.0,
            frames: passes.first().map_or(0, |p| p.gpu_ns.len() as u32),
            warmup: 0,
            timestamp_period_ns: 1.0,
            timestamps: crate::timing::StampLayout::Chained,
            passes,
        }
    }

    /// Log-normal frame times around `median_ns` with `spread` (a few %), quantised to
    /// 10 ns ticks, with an occasional 3x outlier.
    fn noisy(rng: &mut StdRng, median_ns: f64, spread: f64, frames: usize) -> Vec<u64> {
        (0..frames)
            .map(|_| {
                // Box-Muller from two uniforms.
                let (u1, u2): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random());
                let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                let outlier = if rng.random_range(0..100) == 0 {
                    3.0
                } else {
                    1.0
                };
                ((median_ns * (spread * z).exp() * outlier) / 10.0).round() as u64 * 10
            })
            .collect()
    }

    fn frame(rng: &mut StdRng, scale_pass_7: f64, spread: f64, frames: usize) -> TimingReport {
        report(
            (0..60)
                .map(|i| {
                    let base = 20_000.0 + 5_000.0 * i as f64;
                    let m = if i == 7 { base * scale_pass_7 } else { base };
                    pass(
                        &format!("p{i}"),
                        "gfx",
                        "raster",
                        &[],
                        noisy(rng, m, spread, frames),
                    )
                })
                .collect(),
        )
    }

    fn light() -> DiffOptions {
        // Fewer resamples keep a thousand simulated diffs quick; the verdict rule is the same.
        DiffOptions {
            resamples: 200,
            ..DiffOptions::default()
        }
    }

    #[test]
    fn frames_needed_count_from_the_threshold() {
        // Spread ~1.5 around 100; B is 3.5% slower, 0.5% beyond a 3% threshold.
        let a: Vec<f64> = (0..12).map(|i| 100.0 + f64::from(i % 5) - 2.0).collect();
        let b: Vec<f64> = a.iter().map(|x| x * 1.035).collect();
        let (ma, mb) = (median(&a), median(&b));
        let near = needed(&a, &b, ma, mb, 3.0, ALPHA).unwrap();
        // Against the bare 3.5% shift far fewer frames would seem enough.
        let naive = needed(&a, &b, ma, mb, 0.0, ALPHA);
        assert!(
            near > 12 && naive.is_none_or(|n| n < near),
            "{near} {naive:?}"
        );
        // A change already resolved by the samples at hand asks for no more.
        let far: Vec<f64> = a.iter().map(|x| x * 1.5).collect();
        assert_eq!(needed(&a, &far, ma, median(&far), 3.0, ALPHA), None);
    }

    #[test]
    fn a_a_comparisons_rarely_flag_and_a_real_shift_is_found() {
        let mut rng = StdRng::seed_from_u64(2026);
        let mut false_alarms = 0;
        for _ in 0..1000 {
            let (a, b) = (
                frame(&mut rng, 1.0, 0.03, 30),
                frame(&mut rng, 1.0, 0.03, 30),
            );
            let d = diff(&a, &b, &light()).unwrap();
            false_alarms += usize::from(d.fails(3.0));
        }
        let mut found = 0;
        for _ in 0..200 {
            let (a, b) = (
                frame(&mut rng, 1.0, 0.02, 30),
                frame(&mut rng, 1.10, 0.02, 30),
            );
            let d = diff(&a, &b, &light()).unwrap();
            let p7 = d.rows.iter().find(|r| r.name == "p7").unwrap();
            found += usize::from(p7.verdict == Verdict::Regression);
        }
        println!(
            "A/A: {false_alarms} of 1000 diffs flagged a regression; +10% at 2% noise found in {found} of 200"
        );
        assert!(false_alarms <= 50, "{false_alarms} false alarms in 1000");
        assert!(found >= 190, "found {found} of 200");
    }

    #[test]
    fn a_halved_frame_is_decided_on_five_frames_a_side() {
        // Night City's shape: ~130 passes, every one about half as costly in B, 5 frames each.
        let mut rng = StdRng::seed_from_u64(54);
        let side = |rng: &mut StdRng, scale: f64| {
            report(
                (0..130)
                    .map(|i| {
                        let m = (30_000.0 + 4_000.0 * i as f64) * scale;
                        pass(
                            &format!("p{i}"),
                            "gfx",
                            "raster",
                            &[],
                            noisy(rng, m, 0.02, 5),
                        )
                    })
                    .collect(),
            )
        };
        let (a, b) = (side(&mut rng, 1.0), side(&mut rng, 0.48));
        let d = diff(&a, &b, &light()).unwrap();
        let total = &d.rows[0];
        assert_eq!(total.kind, RowKind::Total);
        // The primary outcome is tested alone: p is not multiplied by the pass rows.
        assert_eq!(total.p, total.p_adjusted);
        assert_eq!(total.verdict, Verdict::Improvement, "{total:?}");
        // A pass row cannot reach 0.05 / 130 with five frames: it says how many would.
        let pass_row = d.rows.iter().find(|r| r.name == "p100").unwrap();
        match pass_row.verdict {
            Verdict::Inconclusive { needed: Some(n) } => assert!(n > 5, "{n}"),
            v => panic!("{v:?}"),
        }
    }

    #[test]
    fn passes_match_by_identity_then_by_what_they_write() {
        let a = vec![
            pass("gbuffer", "gfx", "raster", &["albedo"], vec![1]),
            pass("old_name", "gfx", "compute", &["ao"], vec![1]),
            pass("gone", "gfx", "raster", &["x"], vec![1]),
            pass("moved", "gfx", "compute", &["lights"], vec![1]),
        ];
        let b = vec![
            pass("gbuffer", "gfx", "raster", &["albedo"], vec![1]),
            pass("new_name", "gfx", "compute", &["ao"], vec![1]),
            pass("moved", "async", "compute", &["lights"], vec![1]),
            pass("fresh", "gfx", "raster", &["y"], vec![1]),
        ];
        let m = match_passes(&a, &b);
        assert_eq!(m.pairs, vec![(0, 0), (1, 1)]);
        assert_eq!(m.renamed, vec![(1, 1)]);
        // A pass on another queue is another pass: removed from A's queue, added to B's.
        assert_eq!(m.removed, vec![2, 3]);
        assert_eq!(m.added, vec![2, 3]);
        let d = diff(&report(a), &report(b), &light()).unwrap();
        assert_eq!(d.added, ["async/Frame/moved", "gfx/Frame/fresh"]);
        assert_eq!(d.removed, ["gfx/Frame/gone", "gfx/Frame/moved"]);
        let renamed = d.rows.iter().find(|r| r.name == "new_name").unwrap();
        assert_eq!(renamed.renamed_from.as_deref(), Some("old_name"));
    }

    #[test]
    fn repeated_names_match_by_occurrence() {
        let a = vec![
            pass("blur", "gfx", "compute", &["t0"], vec![1]),
            pass("blur", "gfx", "compute", &["t1"], vec![1]),
        ];
        let m = match_passes(&a, &a.clone());
        assert_eq!(m.pairs, vec![(0, 0), (1, 1)]);
        assert!(m.added.is_empty() && m.removed.is_empty());
    }

    #[test]
    fn reports_at_other_scales_on_other_adapters_or_timed_otherwise_are_refused() {
        let a = report(vec![pass("p", "gfx", "raster", &[], vec![1, 2])]);
        let mut b = a.clone();
        b.scale = 0.5;
        assert_eq!(
            diff(&a, &b, &light()),
            Err(DiffError::Scale { a: 1.0, b: 0.5 })
        );
        let mut c = a.clone();
        c.adapter = "other".into();
        assert!(matches!(
            diff(&a, &c, &light()),
            Err(DiffError::Adapter { .. })
        ));
        // Chained pass times include the barriers before each pass; pairs do not.
        let mut d = a.clone();
        d.timestamps = crate::timing::StampLayout::Pairs;
        assert!(matches!(
            diff(&a, &d, &light()),
            Err(DiffError::Timestamps { .. })
        ));
    }

    #[test]
    fn warm_up_frames_are_left_out() {
        let mut a = report(vec![pass(
            "p",
            "gfx",
            "raster",
            &[],
            vec![900_000, 100, 100, 100],
        )]);
        a.warmup = 1;
        let d = diff(&a, &a.clone(), &light()).unwrap();
        let p = d.rows.iter().find(|r| r.name == "p").unwrap();
        assert_eq!(p.samples, [3, 3]);
        assert_eq!(p.median_a_ns, 100.0);
    }

    #[test]
    fn differences_below_the_timestamp_resolution_are_not_regressions() {
        // +50% of 4 ticks is 2 ticks: significant, beyond the threshold, but not measurable.
        let a = report(vec![pass("tiny", "gfx", "raster", &[], vec![40; 40])]);
        let b = report(vec![pass("tiny", "gfx", "raster", &[], vec![60; 40])]);
        let mut a10 = a.clone();
        a10.timestamp_period_ns = 10.0;
        let mut b10 = b.clone();
        b10.timestamp_period_ns = 10.0;
        let coarse = diff(&a10, &b10, &light()).unwrap();
        let row = coarse.rows.iter().find(|r| r.name == "tiny").unwrap();
        assert_ne!(row.verdict, Verdict::Regression);
        let fine = diff(&a, &b, &light()).unwrap();
        let row = fine.rows.iter().find(|r| r.name == "tiny").unwrap();
        assert_eq!(row.verdict, Verdict::Regression);
    }

    #[test]
    fn passes_too_small_to_move_the_frame_do_not_gate() {
        let frame = |big: u64, tiny: u64| {
            report(vec![
                pass("big", "gfx", "raster", &[], vec![big; 30]),
                pass("tiny", "gfx", "copy", &[], vec![tiny; 30]),
            ])
        };
        let a = frame(1_000_000, 5_000);
        // The tiny pass doubles: a regression in its row, 0.5% of the frame, no gate.
        let d = diff(&a, &frame(1_000_000, 10_000), &light()).unwrap();
        let tiny = d.rows.iter().find(|r| r.name == "tiny").unwrap();
        assert_eq!(tiny.verdict, Verdict::Regression);
        assert!(!d.fails(3.0));
        // A pass of 1.5% of the frame 30% slower adds 0.45%: no gate; twice as slow adds 1.5%
        // of the frame: the pass fails the gate though the frame total moves less than 3%.
        let a = frame(1_000_000, 15_000);
        assert!(
            !diff(&a, &frame(1_000_000, 19_500), &light())
                .unwrap()
                .fails(3.0)
        );
        assert!(
            diff(&a, &frame(1_000_000, 30_000), &light())
                .unwrap()
                .fails(3.0)
        );
        // The big pass grows by 20%: it and the frame fail the gate.
        assert!(
            diff(&a, &frame(1_200_000, 5_000), &light())
                .unwrap()
                .fails(3.0)
        );
    }
}
