//! The statistics the timing diff rests on: medians, the two-sided Mann-Whitney U test with
//! tie correction (timestamps are quantised, so ties are common), Holm-Bonferroni adjustment
//! across every row of a diff, and a seeded bootstrap interval for the ratio of medians. The
//! normal distribution comes from `statrs`; what no crate provides for samples like these is
//! written here and checked against published reference values.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use statrs::distribution::{Binomial, ContinuousCDF, DiscreteCDF, Normal};

use super::PassTiming;

/// Mean GPU time in milliseconds over the frames after `warmup` the adapter timed, or `None`
/// when none were.
pub fn mean_gpu_ms(p: &PassTiming, warmup: u32) -> Option<f64> {
    let gpu: Vec<u64> = p
        .trusted_gpu_ns()
        .iter()
        .skip(warmup as usize)
        .flatten()
        .copied()
        .collect();
    if gpu.is_empty() {
        None
    } else {
        Some(gpu.iter().sum::<u64>() as f64 / gpu.len() as f64 / 1e6)
    }
}

/// Median and minimum GPU time in milliseconds over the frames after `warmup` the adapter
/// timed (a summary a slow first frame cannot skew), or `None` when none were.
pub fn gpu_ms_median_min(p: &PassTiming, warmup: u32) -> Option<(f64, f64)> {
    let gpu: Vec<f64> = p
        .trusted_gpu_ns()
        .iter()
        .skip(warmup as usize)
        .flatten()
        .map(|&ns| ns as f64 / 1e6)
        .collect();
    let min = gpu.iter().copied().reduce(f64::min)?;
    Some((median(&gpu), min))
}

/// Mean CPU recording time in milliseconds over the frames after `warmup`.
pub fn mean_cpu_ms(p: &PassTiming, warmup: u32) -> f64 {
    let cpu = p.cpu_ns.get(warmup as usize..).unwrap_or_default();
    cpu.iter().sum::<u64>() as f64 / cpu.len().max(1) as f64 / 1e6
}

/// The median of `xs` (the mean of the middle two for an even count); NaN when empty.
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut v = xs.to_vec();
    median_in_place(&mut v)
}

/// The median, reordering `v` instead of copying it.
fn median_in_place(v: &mut [f64]) -> f64 {
    let n = v.len();
    let (_, &mut hi, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        hi
    } else {
        let lo = v[..n / 2].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo + hi) / 2.0
    }
}

/// The result of a two-sided Mann-Whitney U test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MannWhitney {
    /// U of the first sample: how often one of its values exceeds one of the second's.
    pub u: f64,
    pub p: f64,
}

/// Two-sided Mann-Whitney U test by the normal approximation with tie and continuity
/// corrections (what scipy's `mannwhitneyu(x, y, method="asymptotic")` computes). `None` when
/// either sample is empty.
pub fn mann_whitney(x: &[f64], y: &[f64]) -> Option<MannWhitney> {
    let (n1, n2) = (x.len(), y.len());
    if n1 == 0 || n2 == 0 {
        return None;
    }
    let mut all: Vec<(f64, bool)> = x
        .iter()
        .map(|&v| (v, true))
        .chain(y.iter().map(|&v| (v, false)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Midranks, and the tie term sum(t^3 - t) over groups of equal values.
    let n = all.len();
    let (mut rank_sum_x, mut ties) = (0.0f64, 0.0f64);
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && all[j + 1].0 == all[i].0 {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        let t = (j - i + 1) as f64;
        ties += t * t * t - t;
        rank_sum_x += all[i..=j].iter().filter(|e| e.1).count() as f64 * rank;
        i = j + 1;
    }
    let (n1f, n2f, nf) = (n1 as f64, n2 as f64, n as f64);
    let u = rank_sum_x - n1f * (n1f + 1.0) / 2.0;
    let mu = n1f * n2f / 2.0;
    let variance = n1f * n2f / 12.0 * ((nf + 1.0) - ties / (nf * (nf - 1.0)));
    if variance <= 0.0 {
        // Every value is the same: no evidence of a difference.
        return Some(MannWhitney { u, p: 1.0 });
    }
    let z = ((u - mu).abs() - 0.5).max(0.0) / variance.sqrt();
    let normal = Normal::standard();
    let p = (2.0 * normal.sf(z)).min(1.0);
    Some(MannWhitney { u, p })
}

/// Holm-Bonferroni adjusted p-values, in the order given: the family-wise error rate over all
/// of them stays at the level a single test would have.
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut adjusted = vec![1.0; m];
    let mut running = 0.0f64;
    for (k, &i) in order.iter().enumerate() {
        let value = ((m - k) as f64 * p[i]).min(1.0);
        running = running.max(value);
        adjusted[i] = running;
    }
    adjusted
}

/// Samples at which the bootstrap median is drawn from its exact distribution instead of by
/// resampling (below it the two middle values of an even sample matter).
const DIRECT_MEDIAN_FROM: usize = 64;

/// The bootstrap distribution of a large sample's median, without resampling: the median of n
/// draws with replacement from the sorted sample x is x[K], K the m-th smallest of n uniform
/// indices, and P(K <= k) = P(Binomial(n, (k + 1) / n) >= m). The cumulative distribution is
/// kept where it is neither 0 nor 1 (twelve standard deviations of K either side), so a
/// resample costs a binary search, not n draws.
struct MedianDistribution {
    sorted: Vec<f64>,
    first: usize,
    cdf: Vec<f64>,
}

impl MedianDistribution {
    fn new(sample: &[f64]) -> Option<MedianDistribution> {
        let mut sorted = sample.to_vec();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let m = n.div_ceil(2) as u64;
        let centre = n.div_ceil(2) - 1;
        let width = (6.0 * (n as f64).sqrt()).ceil() as usize + 2;
        let (first, last) = (centre.saturating_sub(width), (centre + width).min(n - 1));
        let mut cdf = Vec::with_capacity(last - first + 1);
        for k in first..=last {
            let p = ((k + 1) as f64 / n as f64).min(1.0);
            let at_least_m = Binomial::new(p, n as u64).ok()?.sf(m - 1);
            cdf.push(at_least_m);
        }
        if let Some(end) = cdf.last_mut() {
            *end = 1.0;
        }
        Some(MedianDistribution { sorted, first, cdf })
    }

    /// The median of one bootstrap resample, for a uniform draw `u` in [0, 1).
    fn sample(&self, u: f64) -> f64 {
        let k = self.cdf.partition_point(|&f| f < u);
        self.sorted[self.first + k.min(self.cdf.len() - 1)]
    }
}

/// A 95% percentile-bootstrap interval for median(b) / median(a), from `resamples` seeded
/// resamples of each sample. `None` when either sample is empty or a median is zero.
pub fn ratio_interval(a: &[f64], b: &[f64], resamples: usize, seed: u64) -> Option<(f64, f64)> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let mut rng = StdRng::seed_from_u64(seed);
    if a.len() >= DIRECT_MEDIAN_FROM && b.len() >= DIRECT_MEDIAN_FROM {
        let (da, db) = (MedianDistribution::new(a)?, MedianDistribution::new(b)?);
        let mut ratios: Vec<f64> = (0..resamples)
            .filter_map(|_| {
                let (ma, mb) = (da.sample(rng.random()), db.sample(rng.random()));
                (ma > 0.0).then(|| mb / ma)
            })
            .collect();
        return percentiles(&mut ratios);
    }
    let mut scratch_a = vec![0.0; a.len()];
    let mut scratch_b = vec![0.0; b.len()];
    let mut ratios = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        for s in scratch_a.iter_mut() {
            *s = a[rng.random_range(0..a.len())];
        }
        for s in scratch_b.iter_mut() {
            *s = b[rng.random_range(0..b.len())];
        }
        let (ma, mb) = (
            median_in_place(&mut scratch_a),
            median_in_place(&mut scratch_b),
        );
        if ma > 0.0 {
            ratios.push(mb / ma);
        }
    }
    percentiles(&mut ratios)
}

/// The 2.5th and 97.5th percentiles.
fn percentiles(ratios: &mut [f64]) -> Option<(f64, f64)> {
    if ratios.is_empty() {
        return None;
    }
    ratios.sort_by(f64::total_cmp);
    let at = |q: f64| ratios[((ratios.len() - 1) as f64 * q).round() as usize];
    Some((at(0.025), at(0.975)))
}

/// Samples per side a two-sided Mann-Whitney test needs to detect a shift of `effect` standard
/// deviations with 80% power at `alpha` (the t-test size scaled by the rank test's asymptotic
/// relative efficiency, 3/pi).
pub fn samples_needed(effect: f64, alpha: f64) -> Option<usize> {
    if !(effect.is_finite() && effect > 0.0) {
        return None;
    }
    let normal = Normal::standard();
    let z_alpha = normal.inverse_cdf(1.0 - alpha / 2.0);
    let z_power = normal.inverse_cdf(0.8);
    let t_test = 2.0 * ((z_alpha + z_power) / effect).powi(2);
    Some((t_test / (3.0 / std::f64::consts::PI)).ceil() as usize)
}

/// The fewest samples per side at which the two-sided Mann-Whitney test (as `mann_whitney`
/// computes it) can reach a p below `alpha` at all: with every value of one sample below every
/// value of the other. Five frames a side can reach 0.05, not 0.05 / 130.
pub fn rank_test_floor(alpha: f64) -> usize {
    let normal = Normal::standard();
    (1..=100_000usize)
        .find(|&n| {
            let nf = n as f64;
            let (mu, variance) = (nf * nf / 2.0, nf * nf * (2.0 * nf + 1.0) / 12.0);
            let z = (mu - 0.5).max(0.0) / variance.sqrt();
            2.0 * normal.sf(z) < alpha
        })
        .unwrap_or(100_000)
}

#[cfg(test)]
mod tests {
    #[test]
    fn untrusted_timestamps_give_no_summary() {
        use crate::capture::format::PassKind;
        use wgpu_types::DeviceType;
        let mut p = PassTiming {
            gpu_ns: vec![Some(90_000), Some(88_000)],
            cpu_ns: vec![1, 1],
            kind: "compute".to_owned(),
            ..PassTiming::default()
        };
        assert!(gpu_ms_median_min(&p, 0).is_some());
        p.gpu_untrusted = crate::timing::untrusted_timestamps(
            "llvmpipe (LLVM 15.0.6, 256 bits)",
            DeviceType::Cpu,
            PassKind::Compute,
        );
        assert!(p.gpu_untrusted.is_some());
        assert_eq!(gpu_ms_median_min(&p, 0), None);
        assert_eq!(mean_gpu_ms(&p, 0), None);
        // Raster passes on lavapipe, and compute on hardware, stay trusted.
        assert!(
            crate::timing::untrusted_timestamps("llvmpipe", DeviceType::Cpu, PassKind::Raster)
                .is_none()
        );
        assert!(
            crate::timing::untrusted_timestamps(
                "NVIDIA H100",
                DeviceType::DiscreteGpu,
                PassKind::Compute
            )
            .is_none()
        );
    }

    use super::*;

    #[test]
    fn means_skip_untimed_frames() {
        let p = PassTiming {
            name: "p".into(),
            queue: "graphics".into(),
            marker_path: String::new(),
            gpu_ns: vec![Some(1_000_000), None, Some(3_000_000)],
            cpu_ns: vec![500_000, 1_500_000, 1_000_000],
            ..PassTiming::default()
        };
        assert_eq!(mean_gpu_ms(&p, 0), Some(2.0));
        assert_eq!(mean_cpu_ms(&p, 0), 1.0);
        assert_eq!(mean_gpu_ms(&p, 1), Some(3.0));
        assert_eq!(mean_cpu_ms(&p, 1), 1.25);
        assert_eq!(gpu_ms_median_min(&p, 0), Some((2.0, 1.0)));
        assert_eq!(gpu_ms_median_min(&p, 1), Some((3.0, 3.0)));
        let untimed = PassTiming {
            gpu_ns: vec![None],
            ..p
        };
        assert_eq!(mean_gpu_ms(&untimed, 0), None);
        assert_eq!(gpu_ms_median_min(&untimed, 0), None);
    }

    #[test]
    fn the_rank_test_floor_is_where_complete_separation_first_reaches_alpha() {
        let floor = rank_test_floor(0.05);
        let separated = |n: usize| {
            let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
            let y: Vec<f64> = (0..n).map(|i| (100 + i) as f64).collect();
            mann_whitney(&x, &y).unwrap().p
        };
        assert!(separated(floor) < 0.05 && separated(floor - 1) >= 0.05);
        // 4 a side reach 0.05; a family of 130 asks for more.
        assert_eq!(floor, 4);
        assert!(rank_test_floor(0.05 / 130.0) > 6);
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn mann_whitney_matches_scipy() {
        // scipy.stats.mannwhitneyu documentation: males vs females, method="asymptotic"
        // gives U = 17 and p = 0.11134688653314041 (agreement to 1e-9: statrs's erfc and scipy's
        // ndtr differ in the last digits).
        let males = [19.0, 22.0, 16.0, 29.0, 24.0];
        let females = [20.0, 11.0, 17.0, 12.0];
        let r = mann_whitney(&males, &females).unwrap();
        assert_eq!(r.u, 17.0);
        assert!((r.p - 0.11134688653314041).abs() < 1e-9, "{}", r.p);
    }

    #[test]
    fn mann_whitney_corrects_for_ties() {
        // With ties: scipy.stats.mannwhitneyu([1, 2, 2, 3, 3, 3], [3, 4, 4, 5],
        // method="asymptotic") gives U = 1.5 and p = 0.026826219079541514.
        let r = mann_whitney(&[1.0, 2.0, 2.0, 3.0, 3.0, 3.0], &[3.0, 4.0, 4.0, 5.0]).unwrap();
        assert_eq!(r.u, 1.5);
        assert!((r.p - 0.026826219079541514).abs() < 1e-9, "{}", r.p);
        // Identical samples: no evidence at all.
        assert_eq!(mann_whitney(&[5.0; 4], &[5.0; 6]).unwrap().p, 1.0);
    }

    #[test]
    fn holm_matches_its_definition() {
        // Sorted 0.01, 0.02, 0.04 over m = 3: 0.03, max(0.03, 0.04), max(0.04, 0.04).
        let adjusted = holm(&[0.04, 0.01, 0.02]);
        let expected = [0.04, 0.03, 0.04];
        for (a, e) in adjusted.iter().zip(expected) {
            assert!((a - e).abs() < 1e-12, "{adjusted:?}");
        }
        assert_eq!(holm(&[0.9, 0.8]), vec![1.0, 1.0]);
    }

    #[test]
    fn bootstrap_interval_covers_the_shift_and_is_seeded() {
        let a: Vec<f64> = (0..40).map(|i| 100.0 + (i % 7) as f64).collect();
        let b: Vec<f64> = a.iter().map(|x| x * 1.2).collect();
        let (lo, hi) = ratio_interval(&a, &b, 2000, 7).unwrap();
        assert!(lo <= 1.2 && 1.2 <= hi && lo > 1.1 && hi < 1.3, "{lo} {hi}");
        assert_eq!(ratio_interval(&a, &b, 2000, 7), Some((lo, hi)));
    }

    #[test]
    fn samples_needed_grows_as_effects_shrink() {
        let big = samples_needed(1.0, 0.05).unwrap();
        let small = samples_needed(0.25, 0.05).unwrap();
        // The t test needs 16 per side for d = 1; the rank test about 3/pi as efficiently.
        assert_eq!(big, 17);
        assert!(small > 10 * big);
        assert_eq!(samples_needed(0.0, 0.05), None);
    }

    #[test]
    fn the_median_distribution_agrees_with_resampling() {
        // Odd n: the drawn median has the distribution of resampled medians, so the intervals
        // of the two paths agree to within the bootstrap's own noise.
        let a: Vec<f64> = (0..201).map(|i| 1000.0 + ((i * 37) % 101) as f64).collect();
        let b: Vec<f64> = a.iter().map(|x| x * 1.05).collect();
        let fast = ratio_interval(&a, &b, 4000, 3).unwrap();
        let mut rng = StdRng::seed_from_u64(5);
        let mut ratios = Vec::new();
        for _ in 0..4000 {
            let draw = |xs: &[f64], rng: &mut StdRng| {
                let v: Vec<f64> = (0..xs.len())
                    .map(|_| xs[rng.random_range(0..xs.len())])
                    .collect();
                median(&v)
            };
            let (ma, mb) = (draw(&a, &mut rng), draw(&b, &mut rng));
            ratios.push(mb / ma);
        }
        let slow = percentiles(&mut ratios).unwrap();
        assert!(
            (fast.0 - slow.0).abs() < 0.004 && (fast.1 - slow.1).abs() < 0.004,
            "{fast:?} {slow:?}"
        );
        assert!(fast.0 < 1.05 && 1.05 < fast.1, "{fast:?}");
    }
}
