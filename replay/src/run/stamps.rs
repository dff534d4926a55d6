//! Pass timestamps: which queries a frame writes, and reading them back.
//!
//! wgpu writes every timestamp, a pass's first included, at the bottom of the pipe: it is
//! taken when all earlier work has finished. So a pass's start stamp marks the same moment as
//! the previous pass's end stamp, plus the barriers recorded between the two. Every stamp costs
//! a query reset and a point where the GPU drains its work (on lavapipe a flush of the
//! rasterizer), so passes that follow a stamped pass in the same submission reuse that pass's
//! end stamp as their start: n+1 stamps for n passes instead of 2n, and every pass still gets
//! its own time (it includes the barriers that lead into it). The resolved values are copied
//! to a mappable buffer in the frame's own submission, so reading them costs no second submit.
//! A query set holds at most `wgpu::QUERY_SET_MAX_QUERIES`, so long frames use several; a
//! pass's own start and its end always share a set (a query is skipped to keep them together).

use super::*;

/// The timestamp queries of a session, when the adapter has them.
pub(super) struct Timestamps {
    /// Query `q` of a frame is query `q % PER_SET` of set `q / PER_SET`.
    sets: Vec<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    staging: wgpu::Buffer,
    /// Whether timestamps can be written on an encoder between passes (copies, clears...).
    pub inside_encoders: bool,
    /// Every pass writes its own start stamp (2n queries): the layout chaining replaced, kept
    /// so the benchmark can measure what chaining saves.
    pub pairs: bool,
}

/// Queries per query set.
const PER_SET: u32 = wgpu::QUERY_SET_MAX_QUERIES;

/// The stamps one pass writes: the query set, the start index in it when the pass writes its
/// own start (`None` when it reuses the previous pass's end), and the end index in it.
pub(super) type Stamps<'q> = Option<(&'q wgpu::QuerySet, Option<u32>, u32)>;

/// One stamped pass's queries: its start (its own, or the previous pass's end) and its end.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    pub start: u32,
    pub end: u32,
    pub own_start: bool,
}

/// Where each pass's start and end times are in the resolved queries, and how many queries a
/// frame writes.
#[derive(Clone, Debug, Default)]
pub(super) struct StampPlan {
    pub slots: Vec<Option<Slot>>,
    pub count: u32,
}

impl StampPlan {
    /// The stamps pass `i` writes, in `t`'s query sets.
    pub fn stamps<'q>(&self, t: &'q Timestamps, i: usize) -> Stamps<'q> {
        let slot = self.slots.get(i).copied().flatten()?;
        let set = t.sets.get((slot.end / PER_SET) as usize)?;
        let start = slot.own_start.then_some(slot.start % PER_SET);
        Some((set, start, slot.end % PER_SET))
    }
}

impl Timestamps {
    /// The query sets (room for a pair per pass), their resolve buffer and a mappable copy.
    pub fn create(device: &wgpu::Device, passes: usize) -> Option<Self> {
        let features = device.features();
        if !features.contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        // A pair per pass, and a skipped query per set at most.
        let pairs = (passes as u32).saturating_mul(2).max(2);
        let set_count = pairs.div_ceil(PER_SET - 1);
        let sets = (0..set_count)
            .map(|_| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: PER_SET.min(pairs + set_count),
                })
            })
            .collect();
        let size = u64::from(set_count) * u64::from(PER_SET) * 8;
        let (resolve, staging) = query_buffers(device, size, "timestamp");
        Some(Timestamps {
            sets,
            resolve,
            staging,
            inside_encoders: features.contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
            pairs: false,
        })
    }

    /// Assigns queries to passes `0..=last`.
    pub fn plan(&self, passes: &[PassSpec], last: usize) -> StampPlan {
        let kinds: Vec<bool> = passes
            .iter()
            .take(last.saturating_add(1))
            .map(|p| matches!(p.op, PassOp::Raster(_) | PassOp::Compute(_)))
            .collect();
        plan(&kinds, self.inside_encoders, self.pairs)
    }

    /// Resolves the frame's queries and copies them to the mappable buffer.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, plan: &StampPlan) {
        for (k, set) in self.sets.iter().enumerate() {
            let first = k as u32 * PER_SET;
            if first >= plan.count {
                break;
            }
            let count = (plan.count - first).min(PER_SET);
            // Each set's slice starts at a multiple of 32 KiB: aligned as resolves require.
            encoder.resolve_query_set(set, 0..count, &self.resolve, u64::from(first) * 8);
        }
        if plan.count > 0 {
            let bytes = u64::from(plan.count) * 8;
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.staging, 0, bytes);
        }
    }

    /// Waits for the submitted frame and reads its resolved ticks.
    pub fn read(&self, device: &wgpu::Device, plan: &StampPlan) -> Result<Vec<u64>, ReplayError> {
        if plan.count == 0 {
            return Ok(Vec::new());
        }
        let bytes = crate::readback::map_read(
            device,
            &self.staging,
            u64::from(plan.count) * 8,
            "timestamps",
        )?;
        Ok(u64s(&bytes))
    }
}

/// The buffer a query set resolves into and the mappable copy read back, `size` bytes each.
pub(super) fn query_buffers(
    device: &wgpu::Device,
    size: u64,
    what: &str,
) -> (wgpu::Buffer, wgpu::Buffer) {
    let buffer = |label: String, usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&label),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    (
        buffer(
            format!("{what} resolve"),
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        ),
        buffer(
            format!("{what} readback"),
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        ),
    )
}

/// Resolved query values: little-endian u64s.
pub(super) fn u64s(bytes: &[u8]) -> Vec<u64> {
    bytes
        .chunks_exact(8)
        .map(|c| {
            let mut le = [0u8; 8];
            le.copy_from_slice(c);
            u64::from_le_bytes(le)
        })
        .collect()
}

/// Assigns queries to passes, given for each whether it has a pass object (raster, compute)
/// that can carry timestamps; other passes are stamped on the encoder when the adapter allows.
/// A stamped pass starts at the previous pass's end when that pass was stamped (unless
/// `pairs`), else at a query of its own.
fn plan(has_pass_object: &[bool], inside_encoders: bool, pairs: bool) -> StampPlan {
    let mut plan = StampPlan::default();
    let mut previous_end: Option<u32> = None;
    for &has_pass_object in has_pass_object {
        let stamped = has_pass_object || inside_encoders;
        if !stamped {
            plan.slots.push(None);
            previous_end = None;
            continue;
        }
        let (start, own_start) = match previous_end.filter(|_| !pairs) {
            Some(end) => (end, false),
            None => {
                // An own start and its end go to one pass descriptor, so one query set.
                if plan.count % PER_SET == PER_SET - 1 {
                    plan.count += 1;
                }
                plan.count += 1;
                (plan.count - 1, true)
            }
        };
        let end = plan.count;
        plan.count += 1;
        plan.slots.push(Some(Slot {
            start,
            end,
            own_start,
        }));
        previous_end = Some(end);
    }
    plan
}

/// Per-pass GPU times and starts (relative to the frame's first stamp) from resolved ticks.
pub(super) fn times_from_ticks(
    plan: &StampPlan,
    ticks: &[u64],
    period_ns: f64,
    times: &mut [PassTime],
) {
    let tick = |q: u32| ticks.get(q as usize).copied().filter(|&t| t != 0);
    let origin = plan
        .slots
        .iter()
        .flatten()
        .filter_map(|slot| tick(slot.start))
        .min();
    for (t, slot) in times.iter_mut().zip(&plan.slots) {
        let Some(slot) = slot else { continue };
        if let (Some(a), Some(b), Some(origin)) = (tick(slot.start), tick(slot.end), origin)
            && b >= a
        {
            t.gpu_ns = Some(((b - a) as f64 * period_ns) as u64);
            t.gpu_start_ns = Some((a.saturating_sub(origin) as f64 * period_ns) as u64);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(plan: &StampPlan) -> Vec<Option<(u32, u32, bool)>> {
        plan.slots
            .iter()
            .map(|s| s.map(|s| (s.start, s.end, s.own_start)))
            .collect()
    }

    #[test]
    fn chained_passes_share_a_stamp_and_a_gap_restarts_the_chain() {
        // raster, compute, copy (no encoder stamps), raster, compute
        let kinds = [true, true, false, true, true];
        let chained = plan(&kinds, false, false);
        assert_eq!(
            layout(&chained),
            [
                Some((0, 1, true)),
                Some((1, 2, false)),
                None,
                Some((3, 4, true)),
                Some((4, 5, false)),
            ]
        );
        assert_eq!(chained.count, 6);
        // With encoder stamps every pass is timed: n + 1 queries.
        let all = plan(&kinds, true, false);
        assert_eq!(all.count, 6);
        assert!(all.slots.iter().all(Option::is_some));
        assert_eq!(
            all.slots.iter().flatten().filter(|s| s.own_start).count(),
            1
        );
        // Pairs: 2n queries, every pass its own start.
        let pairs = plan(&kinds, true, true);
        assert_eq!(pairs.count, 10);
        assert!(pairs.slots.iter().flatten().all(|s| s.own_start));
    }

    #[test]
    fn an_own_start_and_its_end_share_a_query_set() {
        // Two chained passes, then passes each after an untimed one (own starts at odd
        // queries): the own start that would be the last query of a set moves to the next.
        let mut kinds = vec![true, true];
        for _ in 0..3000 {
            kinds.extend([false, true]);
        }
        let p = plan(&kinds, false, false);
        let own: Vec<Slot> = p
            .slots
            .iter()
            .flatten()
            .filter(|s| s.own_start)
            .copied()
            .collect();
        assert_eq!(own.len(), 3001);
        for slot in &own {
            assert_eq!(slot.end, slot.start + 1);
            assert_eq!(slot.start / PER_SET, slot.end / PER_SET, "{slot:?}");
        }
        // 3 + 2 * 3000 queries, and query 4095 skipped.
        assert_eq!(p.count, 6004);
        assert!(own.iter().all(|s| s.start != PER_SET - 1));
    }

    #[test]
    fn times_come_from_each_slot_and_missing_stamps_give_none() {
        let p = plan(&[true, true, false, true], false, false);
        // Queries: 0 start, 1 end of pass 0 = start of pass 1, 2 end of pass 1, 3 start of
        // pass 3, 4 its end (never written: 0).
        let ticks = [100, 150, 400, 500, 0];
        let mut times = vec![PassTime::default(); 4];
        times_from_ticks(&p, &ticks, 2.0, &mut times);
        assert_eq!(times[0].gpu_ns, Some(100));
        assert_eq!(times[0].gpu_start_ns, Some(0));
        assert_eq!(times[1].gpu_ns, Some(500));
        assert_eq!(times[1].gpu_start_ns, Some(100));
        assert_eq!(times[2].gpu_ns, None);
        assert_eq!(times[3].gpu_ns, None);
    }
}
