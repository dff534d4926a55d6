//! Subresource units: each pass's accesses expanded to the (mip, layer) units of textures and
//! the elementary byte intervals of buffers, and merged per unit once, because the graph build,
//! the barrier walk and its steady-state walk all consume them. Kept apart from the model it is
//! computed from, which only describes the frame.

use std::collections::HashMap;

use super::model::{FirstAccess, FrameModel, MPass, MResource, ModelAccess, State, Unit};

/// Subresource units: every (mip, layer) of a texture, and for buffers the elementary byte
/// intervals between the boundaries of all accesses to it. Hazards and states are tracked per
/// unit, so accesses to different mips, layers or byte ranges never conflict.
///
/// Also each pass's uses of units, its accesses merged per unit. The graph, the barrier walk and
/// its steady-state walk all consume these, so they are expanded and merged once.
#[derive(Debug)]
pub struct Units {
    /// First unit of each resource in the flat unit space.
    base: Vec<u32>,
    /// Units of each resource (0 for resources no pass accesses).
    counts: Vec<u32>,
    /// Array layers of each accessed texture (0 for buffers and unaccessed resources): with
    /// `base` it locates a unit's mip and layer without reading the resource.
    layers: Vec<u32>,
    /// Accessed previous-frame copies of `history` resources, as (copy, resource).
    previous_copies: Vec<(MResource, MResource)>,
    /// Per unit, for buffers: the end of its byte interval (the interior boundaries of a buffer
    /// are the ends of all its units but the last).
    unit_end: Vec<u64>,
    pub total: usize,
    /// Uses of pass `p` are `uses[use_start[p]..use_start[p + 1]]`, sorted by unit.
    use_start: Vec<u32>,
    uses: Vec<UnitUse>,
}

/// What one pass needs of one unit: all its accesses to the unit merged. Read states combine; of
/// several write states the first access's wins (the pass orders its own accesses internally).
#[derive(Clone, Copy, Debug)]
pub struct UnitUse {
    pub unit: Unit,
    pub resource: MResource,
    pub state: State,
    pub reads: bool,
    pub writes: bool,
    pub uav: bool,
    /// Index of the pass's first access that reads (writes) the unit: the range a hazard on
    /// this unit is reported with.
    pub first_read: FirstAccess,
    pub first_write: FirstAccess,
}

impl Units {
    pub fn new(model: &FrameModel) -> Self {
        // Only resources some pass accesses get units: per-unit state then scales with the
        // frame's work, not with how many resources it declares.
        let mut accessed = vec![false; model.resources.len()];
        // Interior byte boundaries of buffer accesses, as (resource, offset).
        let mut boundaries: Vec<(MResource, u64)> = Vec::new();
        // Buffers that are the previous-frame copy of another, both ways round.
        let mut twins: HashMap<MResource, MResource> = HashMap::new();
        let mut access_count = 0;
        for pass in &model.passes {
            access_count += pass.accesses.len();
            for a in &pass.accesses {
                accessed[a.resource.index()] = true;
                let r = &model.resources[a.resource.index()];
                if r.is_buffer {
                    if let Some(of) = r.previous_of {
                        twins.insert(a.resource, of);
                        twins.insert(of, a.resource);
                    }
                    let start = a.range.byte_offset;
                    let end = start.saturating_add(a.range.byte_size);
                    for x in [start, end] {
                        if x > 0 && x < r.buffer_bytes {
                            boundaries.push((a.resource, x));
                        }
                    }
                }
            }
        }
        // A copy and its resource share byte intervals, so the frame's end state of one maps
        // unit for unit onto the other.
        if !twins.is_empty() {
            let own = boundaries.len();
            for i in 0..own {
                let (resource, x) = boundaries[i];
                if let Some(&twin) = twins.get(&resource) {
                    boundaries.push((twin, x));
                }
            }
        }
        boundaries.sort_unstable();
        boundaries.dedup();
        let mut base = Vec::with_capacity(model.resources.len());
        let mut counts = Vec::with_capacity(model.resources.len());
        let mut layers = Vec::with_capacity(model.resources.len());
        let mut previous_copies = Vec::new();
        let mut unit_end: Vec<u64> = Vec::new();
        let mut next_boundary = 0;
        for (i, r) in model.resources.iter().enumerate() {
            let resource = MResource::new(i);
            base.push(unit_end.len() as u32);
            if !accessed[i] {
                counts.push(0);
                layers.push(0);
                continue;
            }
            layers.push(if r.is_buffer { 0 } else { r.layers.max(1) });
            if let Some(of) = r.previous_of {
                previous_copies.push((resource, of));
            }
            if r.is_buffer {
                // Boundaries of unaccessed twins are passed over.
                while next_boundary < boundaries.len() && boundaries[next_boundary].0 < resource {
                    next_boundary += 1;
                }
                while next_boundary < boundaries.len() && boundaries[next_boundary].0 == resource {
                    unit_end.push(boundaries[next_boundary].1);
                    next_boundary += 1;
                }
                unit_end.push(r.buffer_bytes);
            } else {
                let count = (r.mips * r.layers) as usize;
                unit_end.resize(unit_end.len() + count, 0);
            }
            counts.push(unit_end.len() as u32 - base[i]);
        }
        let mut units = Self {
            base,
            counts,
            layers,
            previous_copies,
            total: unit_end.len(),
            unit_end,
            use_start: Vec::with_capacity(model.passes.len() + 1),
            uses: Vec::with_capacity(access_count + access_count / 2),
        };
        units.merge_uses(model);
        units
    }

    fn merge_uses(&mut self, model: &FrameModel) {
        let mut uses = std::mem::take(&mut self.uses);
        let mut by_resource: Vec<(MResource, u32)> = Vec::new();
        for pass in &model.passes {
            let start = uses.len();
            self.use_start.push(start as u32);
            // Accesses by resource: units then come out sorted, as a resource's units are
            // contiguous and each access lists its own in order.
            by_resource.clear();
            by_resource.extend(
                pass.accesses
                    .iter()
                    .enumerate()
                    .map(|(i, a)| (a.resource, i as u32)),
            );
            by_resource.sort_unstable();
            let mut shared = false;
            for (k, &(resource, i)) in by_resource.iter().enumerate() {
                shared |= k > 0 && by_resource[k - 1].0 == resource;
                let a = &pass.accesses[i as usize];
                self.for_each(model, a, |unit| {
                    uses.push(UnitUse {
                        unit,
                        resource: a.resource,
                        state: a.state,
                        reads: a.reads,
                        writes: a.writes,
                        uav: a.uav,
                        first_read: if a.reads {
                            FirstAccess::some(i)
                        } else {
                            FirstAccess::NONE
                        },
                        first_write: if a.writes {
                            FirstAccess::some(i)
                        } else {
                            FirstAccess::NONE
                        },
                    })
                });
            }
            if shared {
                Self::merge_pass(&mut uses, start);
            }
        }
        self.use_start.push(uses.len() as u32);
        self.uses = uses;
    }

    /// Merges a pass's uses of the same unit (several accesses to one resource).
    fn merge_pass(uses: &mut Vec<UnitUse>, start: usize) {
        let pass_uses = &mut uses[start..];
        // Stable, and accesses of one resource were added in access order: the earlier access
        // comes first within a unit.
        pass_uses.sort_by_key(|n| n.unit);
        let mut w = 0;
        for r in 0..pass_uses.len() {
            let n = pass_uses[r];
            if w > 0 && pass_uses[w - 1].unit == n.unit {
                let m = &mut pass_uses[w - 1];
                m.state = match (m.state.is_write(), n.state.is_write()) {
                    (true, _) => m.state,
                    (false, true) => n.state,
                    (false, false) => m.state.union(n.state),
                };
                m.reads |= n.reads;
                m.writes |= n.writes;
                m.uav |= n.uav;
                m.first_read = m.first_read.min(n.first_read);
                m.first_write = m.first_write.min(n.first_write);
            } else {
                pass_uses[w] = n;
                w += 1;
            }
        }
        uses.truncate(start + w);
    }

    /// Uses of units by all passes.
    pub fn use_count(&self) -> usize {
        self.uses.len()
    }

    /// A pass's uses of units, sorted by unit, one per unit.
    pub fn uses(&self, pass: MPass) -> &[UnitUse] {
        let p = pass.index();
        &self.uses[self.use_start[p] as usize..self.use_start[p + 1] as usize]
    }

    /// The (mip, layer) of a unit of a known resource (buffer interval index in `layer`).
    pub fn cell(&self, resource: MResource, unit: Unit) -> (u32, u32) {
        let offset = unit.0 - self.base[resource.index()];
        match self.layers[resource.index()] {
            0 => (0, offset),
            layers => (offset / layers, offset % layers),
        }
    }

    /// Whether an accessed resource is a buffer (its units are byte intervals).
    pub fn is_buffer(&self, resource: MResource) -> bool {
        self.layers[resource.index()] == 0
    }

    /// Accessed previous-frame copies of `history` resources, as (copy, resource).
    pub fn previous_copies(&self) -> &[(MResource, MResource)] {
        &self.previous_copies
    }

    /// Calls `f` with each unit an access touches.
    pub fn for_each(&self, model: &FrameModel, a: &ModelAccess, mut f: impl FnMut(Unit)) {
        let r = &model.resources[a.resource.index()];
        let base = self.base[a.resource.index()];
        if r.is_buffer {
            let count = self.counts[a.resource.index()] as usize;
            let b = &self.unit_end[base as usize..base as usize + count.saturating_sub(1)];
            let (start, end) = (
                a.range.byte_offset,
                a.range.byte_offset.saturating_add(a.range.byte_size),
            );
            let whole = a.range.byte_size == 0;
            let first = if whole {
                0
            } else {
                b.partition_point(|&x| x <= start)
            };
            let last = if whole {
                b.len()
            } else {
                b.partition_point(|&x| x < end)
            };
            for u in first..=last {
                f(Unit(base + u as u32));
            }
        } else {
            let rg = &a.range;
            for mip in rg.mip_base..(rg.mip_base + rg.mip_count).min(r.mips) {
                for layer in rg.layer_base..(rg.layer_base + rg.layer_count).min(r.layers) {
                    f(Unit(base + mip * r.layers + layer));
                }
            }
        }
    }

    /// The resource and (mip, layer) of a unit, for messages and range merging.
    pub fn locate(&self, model: &FrameModel, unit: Unit) -> (MResource, u32, u32) {
        let resource = self.base.partition_point(|&b| b <= unit.0) - 1;
        let r = &model.resources[resource];
        let offset = unit.0 - self.base[resource];
        let resource = MResource::new(resource);
        if r.is_buffer {
            (resource, 0, offset)
        } else {
            (resource, offset / r.layers, offset % r.layers)
        }
    }

    /// The first unit of a resource.
    pub fn base(&self, resource: MResource) -> Unit {
        Unit(self.base[resource.index()])
    }

    /// Units of a resource; 0 for a resource no pass accesses.
    pub fn count(&self, resource: MResource) -> usize {
        self.counts[resource.index()] as usize
    }

    /// A resource's units as positions in per-unit vectors (empty for one no pass accesses).
    pub fn span(&self, resource: MResource) -> std::ops::Range<usize> {
        let base = self.base[resource.index()] as usize;
        base..base + self.count(resource)
    }

    /// The byte interval of a buffer unit.
    pub fn buffer_interval(&self, resource: MResource, index: u32) -> (u64, u64) {
        let unit = self.base[resource.index()] as usize + index as usize;
        let start = if index == 0 {
            0
        } else {
            self.unit_end[unit - 1]
        };
        (start, self.unit_end[unit])
    }
}
