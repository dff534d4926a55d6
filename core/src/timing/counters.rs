//! Work counters: what a pass asked the GPU to do. The GPU's pipeline statistics (vertex,
//! clipper, fragment and compute invocations) are counted per frame; beside them the work the
//! replayed plan submits (draws, dispatches, instances, indices, render area, threads), which
//! needs no GPU. Both are exact on a given driver, so a change in them is a fact: the work diff
//! compares them without statistics.

use serde::{Deserialize, Serialize};

/// The names of the GPU counters, in the order pipeline statistics queries write them.
pub const NAMES: [&str; 5] = [
    "vertex_invocations",
    "clipper_invocations",
    "clipper_primitives_out",
    "fragment_invocations",
    "compute_invocations",
];

/// One frame's pipeline statistics of one pass, in [`NAMES`] order.
pub type Counts = [u64; 5];

/// A pass's pipeline statistics, one value per frame run.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counters {
    pub vertex_invocations: Vec<u64>,
    pub clipper_invocations: Vec<u64>,
    pub clipper_primitives_out: Vec<u64>,
    pub fragment_invocations: Vec<u64>,
    pub compute_invocations: Vec<u64>,
}

impl Counters {
    /// Counters from per-frame counts; `None` when no frame counted the pass.
    pub fn from_frames(frames: &[Option<Counts>]) -> Option<Counters> {
        if frames.iter().all(Option::is_none) {
            return None;
        }
        let column = |k: usize| frames.iter().map(|f| f.map_or(0, |c| c[k])).collect();
        Some(Counters {
            vertex_invocations: column(0),
            clipper_invocations: column(1),
            clipper_primitives_out: column(2),
            fragment_invocations: column(3),
            compute_invocations: column(4),
        })
    }

    /// The per-frame values of counter `k` ([`NAMES`] order).
    pub fn series(&self, k: usize) -> &[u64] {
        match k {
            0 => &self.vertex_invocations,
            1 => &self.clipper_invocations,
            2 => &self.clipper_primitives_out,
            3 => &self.fragment_invocations,
            _ => &self.compute_invocations,
        }
    }

    /// Frame `f`'s counts, when the frame was counted.
    pub fn frame(&self, f: usize) -> Option<Counts> {
        let mut c = [0; 5];
        for (k, v) in c.iter_mut().enumerate() {
            *v = *self.series(k).get(f)?;
        }
        Some(c)
    }

    /// The counts of the last frame (the one a diff compares), and whether every frame counted
    /// the same (counts are exact: a frame that differs is a replay that did different work).
    pub fn last(&self) -> Option<(Counts, bool)> {
        let frames = self.vertex_invocations.len();
        let last = self.frame(frames.checked_sub(1)?)?;
        let steady = (0..frames).all(|f| self.frame(f) == Some(last));
        Some((last, steady))
    }
}

/// The work a pass submits, derived from the replayed plan (at the replayed scale).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Work {
    pub draws: u64,
    pub dispatches: u64,
    /// Draws and dispatches whose counts come from a GPU buffer (not in the sums below).
    #[serde(default)]
    pub indirect: u64,
    /// Instances over all direct draws.
    pub instances: u64,
    /// Indices drawn (index count times instances) over indexed direct draws.
    pub indices: u64,
    /// Vertices drawn (vertex count times instances) over non-indexed direct draws.
    pub vertices: u64,
    /// Pixels of the render area: the largest attachment's width times height (0 without).
    pub render_area: u64,
    /// Threads dispatched (workgroups times workgroup size) over direct dispatches whose
    /// workgroup size is known.
    pub threads: u64,
}

impl Work {
    /// Adds one draw: `count` vertices or indices per instance, or an indirect one (its counts
    /// are in a GPU buffer, so it is counted as a draw only).
    pub fn add_draw(&mut self, indirect: bool, instances: u32, count: u32, indexed: bool) {
        self.draws += 1;
        if indirect {
            self.indirect += 1;
            return;
        }
        self.instances += u64::from(instances);
        let drawn = u64::from(count) * u64::from(instances);
        if indexed {
            self.indices += drawn;
        } else {
            self.vertices += drawn;
        }
    }
}

/// Ratios read directly off a pass's counters and work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Ratios {
    /// Fragment invocations per pixel of the render area.
    pub overdraw: Option<f64>,
    /// Vertex invocations per primitive the clipper was given.
    pub vertices_per_primitive: Option<f64>,
    /// Fragment invocations per primitive that reached the rasterizer.
    pub fragments_per_primitive: Option<f64>,
    /// Compute invocations per thread dispatched.
    pub invocations_per_thread: Option<f64>,
}

impl Ratios {
    pub fn of(c: &Counts, w: &Work) -> Ratios {
        let ratio = |a: u64, b: u64| (b > 0 && a > 0).then(|| a as f64 / b as f64);
        Ratios {
            overdraw: ratio(c[3], w.render_area),
            vertices_per_primitive: ratio(c[0], c[1]),
            fragments_per_primitive: ratio(c[3], c[2]),
            invocations_per_thread: ratio(c[4], w.threads),
        }
    }
}

/// A count shown short: 1234 -> "1234", 12345678 -> "12.3M".
pub fn short(n: u64) -> String {
    match n {
        0..10_000 => n.to_string(),
        10_000..10_000_000 => format!("{:.1}k", n as f64 / 1e3),
        _ => format!("{:.1}M", n as f64 / 1e6),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_keep_frames_and_say_when_they_vary() {
        let c = Counters::from_frames(&[Some([1, 2, 3, 4, 5]), Some([1, 2, 3, 4, 5])]).unwrap();
        assert_eq!(c.fragment_invocations, [4, 4]);
        assert_eq!(c.last(), Some(([1, 2, 3, 4, 5], true)));
        let varied = Counters::from_frames(&[Some([1, 2, 3, 4, 5]), Some([1, 2, 3, 9, 5])]);
        assert_eq!(varied.unwrap().last(), Some(([1, 2, 3, 9, 5], false)));
        assert_eq!(Counters::from_frames(&[None, None]), None);
    }

    #[test]
    fn ratios_divide_by_what_the_pass_covered() {
        let w = Work {
            render_area: 100,
            threads: 64,
            ..Work::default()
        };
        let r = Ratios::of(&[300, 100, 50, 250, 64], &w);
        assert_eq!(r.overdraw, Some(2.5));
        assert_eq!(r.vertices_per_primitive, Some(3.0));
        assert_eq!(r.fragments_per_primitive, Some(5.0));
        assert_eq!(r.invocations_per_thread, Some(1.0));
        assert_eq!(Ratios::of(&[0; 5], &Work::default()), Ratios::default());
    }
}
