//! Buffers by byte range: each buffer's bytes split into the ranges its accesses and
//! barriers name, so that accesses to disjoint parts of one buffer need no dependency.

use super::{Key, MAX_RANGES, Objects, Sync};

impl Sync {
    /// The bytes `[offset, offset + size)` of `buffer` (`size` `VK_WHOLE_SIZE` or past its
    /// end: to its end), as the tracked ranges that make them up: ranges that straddle
    /// either end are split in two (each half keeps what happened to the whole), and bytes
    /// no range covers yet get one of their own.
    pub(super) fn buffer_keys(
        &mut self,
        objects: &Objects,
        buffer: u64,
        (offset, size): (u64, u64),
    ) -> Vec<Key> {
        let len = objects
            .buffers
            .get(&buffer)
            .map_or(u64::MAX, |b| b.size.max(1));
        let start = offset.min(len.saturating_sub(1));
        let end = offset.saturating_add(size.max(1)).min(len).max(start + 1);
        let key = |start: u64| Key::Buffer { buffer, start };
        let ranges = self.ranges.entry(buffer).or_default();
        if ranges.len() >= MAX_RANGES {
            return ranges.keys().map(|&s| key(s)).collect();
        }
        for at in [start, end] {
            let Some((&s, &e)) = ranges.range(..at).next_back() else {
                continue;
            };
            if e > at {
                ranges.insert(s, at);
                ranges.insert(at, e);
                self.states.copy(key(s), key(at));
            }
        }
        let mut keys = Vec::new();
        let mut pos = start;
        let within: Vec<(u64, u64)> = ranges.range(start..end).map(|(&s, &e)| (s, e)).collect();
        for (s, e) in within {
            if s > pos {
                ranges.insert(pos, s);
                keys.push(key(pos));
            }
            keys.push(key(s));
            pos = e;
        }
        if pos < end {
            ranges.insert(pos, end);
            keys.push(key(pos));
        }
        keys
    }

    /// What one side (`src` or not) of a copy covers: an image's subresources, or the byte
    /// ranges of a buffer (a buffer-to-buffer region's own bytes; with an image on the other
    /// side, from the region's offset on).
    pub(super) fn copy_keys(
        &mut self,
        objects: &Objects,
        h: u64,
        regions: &[crate::import::commands::Region],
        src: bool,
    ) -> Vec<Key> {
        if objects.images.contains_key(&h) {
            let pick = |r: &crate::import::commands::Region| {
                if src {
                    (r.src_mip, r.src_layer)
                } else {
                    (r.dst_mip, r.dst_layer)
                }
            };
            return Self::subresource_keys(objects, h, regions.iter().map(pick));
        }
        let mut keys = Vec::new();
        for r in regions {
            let offset = if src { r.src_offset } else { r.dst_offset };
            keys.extend(self.buffer_keys(objects, h, (offset, r.size.unwrap_or(u64::MAX))));
        }
        keys.sort_unstable();
        keys.dedup();
        keys
    }
}
