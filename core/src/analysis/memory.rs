//! Memory: each resource's lifetime in the pass order, and a placement plan that lets resources
//! whose lifetimes do not overlap share memory (D3D12 placed resources aliasing in one heap),
//! with the aliasing barriers that sharing needs.
//!
//! Resources are planned per heap type, and on resource-heap tier 1 also per category (buffers,
//! RT/DS textures, other textures can't share a heap). Per pool the plan is compared with the
//! lower bound, the largest sum of simultaneously live bytes. Two placements are tried, keeping
//! the smaller: greedy by size (each resource at the lowest aligned offset free for its whole
//! lifetime; quadratic, so only for pools up to a few thousand resources) and a time-ordered
//! best-fit allocator with coalescing free lists (n log n, for any size).

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

use super::model::{FrameModel, MPass, MResource};
use crate::capture::format::HeapType;
use crate::capture::model::ResourceCategory;

/// Positions in the order of a resource's first and last use (inclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Lifetime {
    pub first: u32,
    pub last: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct Placed {
    pub resource: MResource,
    /// Index into `MemoryPlan::pools`.
    pub pool: u32,
    pub offset: u64,
    pub bytes: u64,
    pub lifetime: Option<Lifetime>,
    /// Lives across frames (history, initial contents, outputs): never shares memory.
    pub persistent: bool,
}

#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct Totals {
    pub unaliased_bytes: u64,
    pub aliased_bytes: u64,
    pub lower_bound_bytes: u64,
}

/// An aliasing barrier: `after` starts using memory `before` used.
#[derive(Clone, Debug, Serialize, PartialEq, Eq, PartialOrd, Ord)]
pub struct AliasingBarrier {
    pub before_pass: MPass,
    pub resource_before: MResource,
    pub resource_after: MResource,
}

#[derive(Clone, Debug, Serialize)]
pub struct MemoryPlan {
    /// Per heap type name (DEFAULT, UPLOAD, ...).
    pub per_heap_type: BTreeMap<String, Totals>,
    pub total: Totals,
    pub resources: Vec<Placed>,
    /// Pool names by index (`DEFAULT`, or `DEFAULT/buffers` on resource heap tier 1).
    pub pools: Vec<String>,
    pub aliasing_barriers: Vec<AliasingBarrier>,
}

pub fn lifetimes(model: &FrameModel, order: &[MPass]) -> Vec<Option<Lifetime>> {
    let mut out: Vec<Option<Lifetime>> = vec![None; model.resources.len()];
    for (pos, &p) in order.iter().enumerate() {
        let pos = pos as u32;
        for a in &model.passes[p.index()].accesses {
            let l = out[a.resource.index()].get_or_insert(Lifetime {
                first: pos,
                last: pos,
            });
            l.first = l.first.min(pos);
            l.last = l.last.max(pos);
        }
    }
    out
}

/// One item to place: the resource it is, size, alignment, live interval.
#[derive(Clone, Copy, Debug)]
pub struct Item {
    pub id: MResource,
    pub bytes: u64,
    pub alignment: u64,
    pub first: u32,
    pub last: u32,
}

fn overlaps_in_time(a: &Item, b: &Item) -> bool {
    a.first <= b.last && b.first <= a.last
}

/// Largest sum of bytes live at one position.
pub fn lower_bound(items: &[Item]) -> u64 {
    let Some(end) = items.iter().map(|it| it.last as usize + 1).max() else {
        return 0;
    };
    // Bytes born minus bytes freed at each position; the running sum is what is live there.
    let mut delta: Vec<i128> = vec![0; end + 1];
    for it in items {
        delta[it.first as usize] += i128::from(it.bytes);
        delta[it.last as usize + 1] -= i128::from(it.bytes);
    }
    let (mut live, mut peak) = (0i128, 0i128);
    for d in delta {
        live += d;
        peak = peak.max(live);
    }
    peak as u64
}

fn align_up(v: u64, a: u64) -> u64 {
    v.div_ceil(a.max(1)) * a.max(1)
}

/// Greedy by decreasing size: the lowest aligned offset not used by any placed item whose
/// lifetime overlaps. Returns offsets (by position in `items`) and the pool size.
pub fn place_greedy(items: &[Item]) -> (Vec<u64>, u64) {
    let mut idx: Vec<usize> = (0..items.len()).collect();
    idx.sort_by_key(|&i| {
        (
            std::cmp::Reverse(items[i].bytes),
            items[i].first,
            items[i].id,
        )
    });
    let mut offsets = vec![0u64; items.len()];
    let mut placed: Vec<usize> = Vec::new();
    let mut size = 0u64;
    let mut busy: Vec<(u64, u64)> = Vec::new();
    for &i in &idx {
        let it = &items[i];
        busy.clear();
        busy.extend(
            placed
                .iter()
                .filter(|&&j| overlaps_in_time(it, &items[j]))
                .map(|&j| (offsets[j], offsets[j] + items[j].bytes)),
        );
        busy.sort_unstable();
        let mut offset = 0u64;
        for &(start, end) in &busy {
            if offset + it.bytes <= start {
                break;
            }
            offset = offset.max(align_up(end, it.alignment));
        }
        offsets[i] = offset;
        size = size.max(offset + it.bytes);
        placed.push(i);
    }
    (offsets, size)
}

/// Time-ordered best fit: walks positions, freeing what died and allocating what is born
/// (largest first) from a coalescing free list, growing the pool when nothing fits.
pub fn place_timeline(items: &[Item]) -> (Vec<u64>, u64) {
    let mut offsets = vec![0u64; items.len()];
    // Sort keys carry what they compare, so sorting never chases indices into `items`.
    let mut births: Vec<(u32, std::cmp::Reverse<u64>, MResource, u32)> = items
        .iter()
        .enumerate()
        .map(|(i, it)| (it.first, std::cmp::Reverse(it.bytes), it.id, i as u32))
        .collect();
    births.sort_unstable();
    let mut deaths: Vec<(u32, u32)> = items
        .iter()
        .enumerate()
        .map(|(i, it)| (it.last, i as u32))
        .collect();
    deaths.sort_unstable();
    // Free blocks by offset and by (size, offset).
    let mut by_offset: BTreeMap<u64, u64> = BTreeMap::new();
    let mut by_size: BTreeSet<(u64, u64)> = BTreeSet::new();
    let mut top = 0u64;
    let mut d = 0;
    let free = |offset: u64,
                bytes: u64,
                by_offset: &mut BTreeMap<u64, u64>,
                by_size: &mut BTreeSet<(u64, u64)>,
                top: &mut u64| {
        let (mut start, mut end) = (offset, offset + bytes);
        if let Some((&o, &s)) = by_offset.range(..start).next_back()
            && o + s == start
        {
            by_offset.remove(&o);
            by_size.remove(&(s, o));
            start = o;
        }
        if let Some(&s) = by_offset.get(&end) {
            by_offset.remove(&end);
            by_size.remove(&(s, end));
            end += s;
        }
        if end == *top {
            *top = start;
        } else {
            by_offset.insert(start, end - start);
            by_size.insert((end - start, start));
        }
    };
    let mut size = 0u64;
    for &(_, _, _, i) in &births {
        let i = i as usize;
        let it = items[i];
        while d < deaths.len() && deaths[d].0 < it.first {
            let j = deaths[d].1 as usize;
            free(
                offsets[j],
                items[j].bytes,
                &mut by_offset,
                &mut by_size,
                &mut top,
            );
            d += 1;
        }
        let fit = by_size
            .range((it.bytes, 0)..)
            .find(|&&(s, o)| align_up(o, it.alignment) + it.bytes <= o + s)
            .copied();
        let offset = match fit {
            Some((s, o)) => {
                by_size.remove(&(s, o));
                by_offset.remove(&o);
                let start = align_up(o, it.alignment);
                if start > o {
                    by_offset.insert(o, start - o);
                    by_size.insert((start - o, o));
                }
                let end = start + it.bytes;
                if end < o + s {
                    by_offset.insert(end, o + s - end);
                    by_size.insert((o + s - end, end));
                }
                start
            }
            None => {
                let start = align_up(top, it.alignment);
                if start > top {
                    by_offset.insert(top, start - top);
                    by_size.insert((start - top, top));
                }
                top = start + it.bytes;
                start
            }
        };
        offsets[i] = offset;
        size = size.max(offset + it.bytes);
    }
    (offsets, size)
}

/// The smaller of the two placements (greedy only where its quadratic cost is small).
pub fn place(items: &[Item]) -> (Vec<u64>, u64) {
    let timeline = place_timeline(items);
    if items.len() <= 4000 {
        let greedy = place_greedy(items);
        if greedy.1 <= timeline.1 {
            return greedy;
        }
    }
    timeline
}

/// Aliasing barriers of one pool: walking resources by first use, a map from address ranges to
/// their latest occupant says whose memory each resource takes over. Placement guarantees that
/// any earlier occupant of an overlapping range is dead by then.
fn aliasing(items: &[Item], offsets: &[u64], order: &[MPass], out: &mut Vec<AliasingBarrier>) {
    let mut by_birth: Vec<(u32, MResource, u32)> = items
        .iter()
        .enumerate()
        .map(|(i, it)| (it.first, it.id, i as u32))
        .collect();
    by_birth.sort_unstable();
    // start -> (end, occupant); segments never overlap.
    let mut painted: BTreeMap<u64, (u64, MResource)> = BTreeMap::new();
    let mut previous: Vec<MResource> = Vec::new();
    for (first, id, i) in by_birth {
        let start = offsets[i as usize];
        let end = start + items[i as usize].bytes;
        previous.clear();
        // Overlapping segments, from the last one starting before `end` backwards: the parts
        // outside [start, end) stay with their occupant.
        while let Some((&k, &(e, occupant))) = painted.range(..end).next_back() {
            if e <= start {
                break;
            }
            previous.push(occupant);
            if e > end {
                painted.insert(end, (e, occupant));
            }
            if k < start {
                painted.insert(k, (start, occupant));
                break;
            }
            painted.remove(&k);
        }
        painted.insert(start, (end, id));
        previous.sort_unstable();
        previous.dedup();
        out.extend(previous.iter().map(|&before| AliasingBarrier {
            before_pass: order[first as usize],
            resource_before: before,
            resource_after: id,
        }));
    }
}

fn category_name(c: ResourceCategory) -> &'static str {
    match c {
        ResourceCategory::Buffer => "buffers",
        ResourceCategory::RtDsTexture => "rt_ds_textures",
        ResourceCategory::OtherTexture => "textures",
    }
}

pub fn plan(model: &FrameModel, order: &[MPass]) -> MemoryPlan {
    let lifetimes = lifetimes(model, order);
    let end = order.len().saturating_sub(1) as u32;
    const HEAPS: [HeapType; 4] = [
        HeapType::Default,
        HeapType::Upload,
        HeapType::Readback,
        HeapType::Custom,
    ];
    const CATEGORIES: [ResourceCategory; 3] = [
        ResourceCategory::Buffer,
        ResourceCategory::RtDsTexture,
        ResourceCategory::OtherTexture,
    ];
    // Pools: heap type, and on tier 1 also the resource category (index heap * 3 + category).
    let pool_of = |heap: HeapType, category: ResourceCategory| -> usize {
        let h = HEAPS.iter().position(|x| *x == heap).unwrap_or(0);
        let c = if model.heap_tier == 1 {
            CATEGORIES.iter().position(|x| *x == category).unwrap_or(0)
        } else {
            0
        };
        h * 3 + c
    };
    let pool_names: Vec<String> = (0..12)
        .map(|i| {
            let heap = HEAPS[i / 3].name();
            if model.heap_tier == 1 {
                format!("{heap}/{}", category_name(CATEGORIES[i % 3]))
            } else {
                heap.to_owned()
            }
        })
        .collect();
    let mut pools: Vec<Vec<Item>> = vec![Vec::new(); 12];
    let mut unaliased: [Option<u64>; 4] = [None; 4];
    let mut placed: Vec<Placed> = Vec::with_capacity(model.resources.len());
    for (i, r) in model.resources.iter().enumerate() {
        let persistent =
            r.history || r.previous_of.is_some() || r.initialised || r.output || r.swapchain;
        let pool = pool_of(r.heap_type, r.category);
        *unaliased[pool / 3].get_or_insert(0) += r.aligned_bytes;
        let lifetime = lifetimes[i];
        placed.push(Placed {
            resource: MResource::new(i),
            pool: pool as u32,
            offset: 0,
            bytes: r.aligned_bytes,
            lifetime,
            persistent,
        });
        // Persistent resources hold their memory for the whole frame (and across frames),
        // used or not: an idle swapchain image or an unread buffer of contents still takes
        // its bytes. Transient ones no pass uses take none.
        let (first, last) = match lifetime {
            _ if persistent => (0, end),
            Some(l) => (l.first, l.last),
            None => continue,
        };
        pools[pool].push(Item {
            id: MResource::new(i),
            bytes: r.aligned_bytes,
            alignment: r.alignment,
            first,
            last,
        });
    }
    let mut per_heap_type: BTreeMap<String, Totals> = BTreeMap::new();
    for (h, bytes) in unaliased.iter().enumerate() {
        if let Some(bytes) = bytes {
            per_heap_type.insert(
                HEAPS[h].name().to_owned(),
                Totals {
                    unaliased_bytes: *bytes,
                    ..Totals::default()
                },
            );
        }
    }
    let mut aliasing_barriers = Vec::new();
    for (pool, items) in pools
        .iter()
        .enumerate()
        .filter(|(_, items)| !items.is_empty())
    {
        let (offsets, size) = place(items);
        let totals = per_heap_type
            .entry(HEAPS[pool / 3].name().to_owned())
            .or_default();
        totals.aliased_bytes += size;
        totals.lower_bound_bytes += lower_bound(items);
        for (item, &offset) in items.iter().zip(&offsets) {
            placed[item.id.index()].offset = offset;
        }
        aliasing(items, &offsets, order, &mut aliasing_barriers);
    }
    aliasing_barriers.sort_unstable();
    let mut total = Totals::default();
    for t in per_heap_type.values() {
        total.unaliased_bytes += t.unaliased_bytes;
        total.aliased_bytes += t.aliased_bytes;
        total.lower_bound_bytes += t.lower_bound_bytes;
    }
    MemoryPlan {
        per_heap_type,
        total,
        resources: placed,
        pools: pool_names,
        aliasing_barriers,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(id: u32, kib: u64, first: u32, last: u32) -> Item {
        Item {
            id: MResource(id),
            bytes: kib * 1024,
            alignment: 65536,
            first,
            last,
        }
    }

    fn valid(items: &[Item], offsets: &[u64]) -> bool {
        for i in 0..items.len() {
            if !offsets[i].is_multiple_of(items[i].alignment) {
                return false;
            }
            for j in 0..i {
                let memory = offsets[i] < offsets[j] + items[j].bytes
                    && offsets[j] < offsets[i] + items[i].bytes;
                if memory && overlaps_in_time(&items[i], &items[j]) {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn disjoint_lifetimes_share_memory() {
        let items = [item(0, 1024, 0, 1), item(1, 1024, 2, 3), item(2, 512, 1, 2)];
        for (offsets, size) in [place_greedy(&items), place_timeline(&items)] {
            assert!(valid(&items, &offsets));
            assert_eq!(size, 1536 * 1024);
        }
        assert_eq!(lower_bound(&items), 1536 * 1024);
    }

    #[test]
    fn placements_are_valid_on_many_inputs() {
        let mut x = 12345u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..200 {
            let n = 1 + (next() % 40) as u32;
            let items: Vec<Item> = (0..n)
                .map(|id| {
                    let first = (next() % 30) as u32;
                    item(
                        id,
                        64 * (1 + next() % 64),
                        first,
                        first + (next() % 10) as u32,
                    )
                })
                .collect();
            for (offsets, size) in [place_greedy(&items), place_timeline(&items)] {
                assert!(valid(&items, &offsets));
                assert!(size >= lower_bound(&items));
            }
        }
    }
}
