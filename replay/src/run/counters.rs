//! Pipeline statistics per pass: one query around each pass that draws or dispatches (its
//! render or compute pass object), numbered densely in the frame so every resolved query was
//! written, resolved and copied to a mappable buffer in the frame's own submission. Counting
//! is asked for per frame: a query costs the driver a flush around the pass.

use framelab_core::plan::{PassOp, PassSpec};
use framelab_core::timing::counters::Counts;

use super::ReplayError;

/// The five statistics, written per query in this (wgpu's bit) order: see `counters::NAMES`.
const TYPES: wgpu::PipelineStatisticsTypes =
    wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
        .union(wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS)
        .union(wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT)
        .union(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS)
        .union(wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS);

/// Bytes one query resolves to.
const QUERY_BYTES: u64 = 5 * 8;
/// Queries per query set; a set's first query lands at a multiple of 256 bytes (4096 * 40).
const PER_SET: u32 = wgpu::QUERY_SET_MAX_QUERIES;

/// The statistics query sets of a session, when the adapter has them.
pub(super) struct Statistics {
    sets: Vec<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    staging: wgpu::Buffer,
}

/// Which queries each plan pass writes in a frame (the first and how many), and how many the
/// frame writes.
#[derive(Clone, Debug, Default)]
pub(super) struct CountPlan {
    pub slots: Vec<Option<(u32, u32)>>,
    pub count: u32,
}

/// The queries of one pass: one per render or compute pass object it is replayed as (an
/// imported render pass whose draws read its own attachment is several), summed when read.
#[derive(Clone, Copy)]
pub(super) struct PassQueries<'q> {
    sets: &'q [wgpu::QuerySet],
    first: u32,
    count: u32,
}

impl<'q> PassQueries<'q> {
    /// The set and index of the pass's `k`th query.
    pub fn get(&self, k: u32) -> Option<(&'q wgpu::QuerySet, u32)> {
        if k >= self.count {
            return None;
        }
        let q = self.first + k;
        Some((self.sets.get((q / PER_SET) as usize)?, q % PER_SET))
    }
}

/// Whether a pass has a render or compute pass object of its own that draws or dispatches.
pub(super) fn counted(pass: &PassSpec) -> bool {
    matches!(
        pass.op,
        PassOp::Raster(_) | PassOp::Compute(_) | PassOp::VkRaster(_) | PassOp::VkCompute(_)
    )
}

/// How many queries a pass writes: one per pass object it is replayed as.
fn queries(pass: &PassSpec) -> u32 {
    match &pass.op {
        PassOp::VkRaster(r) => r.segments().len() as u32,
        _ => u32::from(counted(pass)),
    }
}

impl Statistics {
    pub fn create(device: &wgpu::Device, passes: &[PassSpec]) -> Option<Self> {
        if !device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        {
            return None;
        }
        let queries = passes.iter().map(queries).sum::<u32>().max(1);
        let set_count = queries.div_ceil(PER_SET);
        let sets = (0..set_count)
            .map(|k| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass statistics"),
                    ty: wgpu::QueryType::PipelineStatistics(TYPES),
                    count: (queries - k * PER_SET).min(PER_SET),
                })
            })
            .collect();
        let (resolve, staging) =
            super::stamps::query_buffers(device, u64::from(queries) * QUERY_BYTES, "statistics");
        Some(Statistics {
            sets,
            resolve,
            staging,
        })
    }

    /// Numbers the counted passes among `0..=last`.
    pub fn plan(passes: &[PassSpec], last: usize) -> CountPlan {
        let mut plan = CountPlan::default();
        for p in passes.iter().take(last.saturating_add(1)) {
            let n = queries(p);
            plan.slots.push((n > 0).then(|| {
                plan.count += n;
                (plan.count - n, n)
            }));
        }
        plan
    }

    /// The queries pass `i` writes.
    pub fn query(&self, plan: &CountPlan, i: usize) -> Option<PassQueries<'_>> {
        let (first, count) = plan.slots.get(i).copied().flatten()?;
        Some(PassQueries {
            sets: &self.sets,
            first,
            count,
        })
    }

    /// Resolves the frame's queries and copies them to the mappable buffer.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, plan: &CountPlan) {
        for (k, set) in self.sets.iter().enumerate() {
            let first = k as u32 * PER_SET;
            if first >= plan.count {
                break;
            }
            let count = (plan.count - first).min(PER_SET);
            encoder.resolve_query_set(set, 0..count, &self.resolve, u64::from(first) * QUERY_BYTES);
        }
        if plan.count > 0 {
            let bytes = u64::from(plan.count) * QUERY_BYTES;
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.staging, 0, bytes);
        }
    }

    /// Waits for the submitted frame and reads each counted pass's statistics.
    pub fn read(
        &self,
        device: &wgpu::Device,
        plan: &CountPlan,
    ) -> Result<Vec<Option<Counts>>, ReplayError> {
        if plan.count == 0 {
            return Ok(vec![None; plan.slots.len()]);
        }
        let bytes = crate::readback::map_read(
            device,
            &self.staging,
            u64::from(plan.count) * QUERY_BYTES,
            "pipeline statistics",
        )?;
        let values = super::stamps::u64s(&bytes);
        Ok(plan
            .slots
            .iter()
            .map(|slot| {
                let (first, n) = (*slot)?;
                let mut c = [0u64; 5];
                for q in first..first + n {
                    let at = q as usize * 5;
                    for (sum, v) in c.iter_mut().zip(values.get(at..at + 5)?) {
                        *sum = sum.saturating_add(*v);
                    }
                }
                Some(c)
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_starts_on_a_resolve_alignment() {
        assert_eq!(
            (u64::from(PER_SET) * QUERY_BYTES) % wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT,
            0
        );
    }
}
