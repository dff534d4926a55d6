//! Summary statistics of a pass's samples across frames, for the replay summary table.

use super::PassTiming;

/// Mean GPU time in milliseconds over the frames the adapter timed, or `None` when none were.
pub fn mean_gpu_ms(p: &PassTiming) -> Option<f64> {
    let gpu: Vec<u64> = p.gpu_ns.iter().flatten().copied().collect();
    if gpu.is_empty() {
        None
    } else {
        Some(gpu.iter().sum::<u64>() as f64 / gpu.len() as f64 / 1e6)
    }
}

/// Mean CPU recording time in milliseconds over all frames.
pub fn mean_cpu_ms(p: &PassTiming) -> f64 {
    p.cpu_ns.iter().sum::<u64>() as f64 / p.cpu_ns.len().max(1) as f64 / 1e6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means_skip_untimed_frames() {
        let p = PassTiming {
            name: "p".into(),
            queue: "graphics".into(),
            marker_path: String::new(),
            gpu_ns: vec![Some(1_000_000), None, Some(3_000_000)],
            cpu_ns: vec![500_000, 1_500_000, 1_000_000],
        };
        assert_eq!(mean_gpu_ms(&p), Some(2.0));
        assert_eq!(mean_cpu_ms(&p), 1.0);
        let untimed = PassTiming {
            gpu_ns: vec![None],
            ..p
        };
        assert_eq!(mean_gpu_ms(&untimed), None);
    }
}
