//! Bytes each pass moves: the size of every subresource it reads and of every one it writes, at
//! the scale the capture was resolved for. It is the footprint the capture declares (a sampled
//! texture counts whole, whatever the shader fetches), so bytes / GPU time is the bandwidth a
//! pass would need to touch all of it: far below the adapter's peak means the pass is not bound
//! by memory traffic.

use std::collections::BTreeSet;

use crate::capture::model::{Capture, PassId, ResourceId, Subresources};

/// What one pass reads and writes, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    pub read: u64,
    pub written: u64,
}

impl Traffic {
    pub fn total(self) -> u64 {
        self.read.saturating_add(self.written)
    }
}

/// Bytes of the subresources `range` covers.
fn range_bytes(capture: &Capture, resource: ResourceId, range: &Subresources) -> u64 {
    let r = capture.resource(resource);
    if !r.is_texture() {
        return if range.byte_size == 0 {
            r.bytes
        } else {
            range.byte_size
        };
    }
    let Some(format) = r.format else {
        return 0;
    };
    (range.mip_base..range.mip_base.saturating_add(range.mip_count))
        .filter(|&mip| mip < r.mip_levels)
        .map(|mip| {
            let (w, h, d) = r.mip_extent(mip);
            format
                .surface_bytes(u64::from(w), u64::from(h))
                .unwrap_or(0)
                .saturating_mul(u64::from(d))
                .saturating_mul(u64::from(range.layer_count))
                .saturating_mul(u64::from(r.samples.max(1)))
        })
        .fold(0u64, u64::saturating_add)
}

/// The pass's traffic; a subresource range used twice (bound and attached, say) counts once
/// per direction.
pub fn pass_traffic(capture: &Capture, pass: PassId) -> Traffic {
    let p = capture.pass(pass);
    let reads: BTreeSet<_> = p
        .accesses
        .iter()
        .filter(|a| a.reads)
        .map(|a| (a.resource, a.range))
        .collect();
    let writes: BTreeSet<_> = p
        .accesses
        .iter()
        .filter(|a| a.writes)
        .map(|a| (a.resource, a.range))
        .collect();
    let sum = |set: &BTreeSet<_>| {
        set.iter()
            .map(|(r, range)| range_bytes(capture, *r, range))
            .fold(0u64, u64::saturating_add)
    };
    Traffic {
        read: sum(&reads),
        written: sum(&writes),
    }
}
