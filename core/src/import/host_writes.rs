//! What the application's CPU writes through a mapping while the imported frames run (vkd3d's
//! vertex data, egui's staging buffers, per-frame constants): each write becomes a
//! `host_write` copy pass at its place in the frame, from a buffer holding the bytes into every
//! buffer bound over the memory written. The copies are marked `host`: the next submission
//! makes host writes visible, so they need no barrier and take none of the queue's.

use super::Importer;
use super::build::Builder;
use super::state::Objects;
use crate::capture::format::{Copy, CopyLocation, PassKind};

impl Importer {
    /// Host writes of `data` at `offset` in `memory`, into every buffer bound over them.
    pub(super) fn host_write(&mut self, memory: u64, offset: u64, data: &[u8]) {
        let end = offset.saturating_add(data.len() as u64);
        let bound = self
            .objects
            .buffers_in
            .get(&memory)
            .map_or(&[][..], Vec::as_slice);
        let mut targets: Vec<(u64, u64, u64)> = bound
            .iter()
            .filter_map(|h| Some((*h, self.objects.buffers.get(h)?)))
            .filter(|(_, b)| b.destroyed_at.is_none())
            .filter_map(|(h, b)| {
                let (m, at) = b.bound?;
                let (from, to) = (offset.max(at), end.min(at.saturating_add(b.size)));
                (m == memory && from < to).then_some((h, from, to))
            })
            .collect();
        targets.sort_unstable();
        targets.dedup();
        for (buffer, from, to) in targets {
            let at = self
                .objects
                .buffers
                .get(&buffer)
                .and_then(|b| b.bound)
                .map_or(0, |(_, a)| a);
            let bytes = data[(from - offset) as usize..(to - offset) as usize].to_vec();
            self.builder.upload(&self.objects, buffer, from - at, bytes);
        }
    }
}

impl Builder {
    /// A host write of `bytes` into `buffer` at `offset` during the imported frames: a copy
    /// pass from a buffer holding the bytes, on the queue of the latest pass.
    pub fn upload(&mut self, objects: &Objects, buffer: u64, offset: u64, bytes: Vec<u8>) {
        let Some(queue) = self
            .last_queue
            .or_else(|| self.queue_names.keys().next().copied())
        else {
            self.note("host writes before any queue was seen: not imported");
            return;
        };
        let Some(dst) = self.resource(objects, buffer) else {
            return;
        };
        // Barriers and waits recorded for the queue belong to its next GPU pass, not to this.
        let barriers = self.pending_barriers.remove(&queue);
        let waits = self.pending_waits.remove(&queue);
        let pass = self.new_pass(objects, queue, PassKind::Copy, "host_write");
        if let Some(b) = barriers {
            self.pending_barriers.insert(queue, b);
        }
        if let Some(w) = waits {
            self.pending_waits.insert(queue, w);
        }
        let Some(pass) = pass else {
            return;
        };
        let mut k = self.uploads.len();
        let mut name = format!("host_write_{k}");
        while !self.taken.insert(name.clone()) {
            k += 1;
            name = format!("host_write_{k}");
        }
        let size = Some(bytes.len() as u64);
        let at = |resource: String, offset: u64| CopyLocation {
            resource,
            mip: 0,
            layer: 0,
            origin: [0; 3],
            offset,
            size,
            bytes_per_row: None,
        };
        self.passes[pass].copies.push(Copy {
            src: at(name.clone(), 0),
            dst: at(dst, offset),
            extent: None,
            host: true,
        });
        self.uploads.push((name, bytes));
    }

    /// Drops the host writes after the imported frames' last GPU work. Nothing the import
    /// holds reads them, and a read-back through a mapping looks the same in a capture (the
    /// capture layer records the mapped memory when it is unmapped): kept, they would stand
    /// as the last writers of the results the CPU reads and hide the work that made them.
    pub fn drop_trailing_host_writes(&mut self) {
        let mut dropped = 0;
        while let Some(p) = self.passes.last() {
            if p.kind != PassKind::Copy || p.copies.is_empty() || !p.copies.iter().all(|c| c.host) {
                break;
            }
            let Some(p) = self.passes.pop() else { break };
            for c in &p.copies {
                self.uploads.retain(|(name, _)| *name != c.src.resource);
                self.taken.remove(&c.src.resource);
            }
            self.pass_names.remove(&p.name);
            dropped += 1;
        }
        let passes = self.passes.len();
        self.last_pass_on.retain(|_, p| *p < passes);
        for _ in 0..dropped {
            self.note("host writes after the frames' last GPU work: left out (nothing in them reads the bytes; a read-back through a mapping is captured the same way)");
        }
    }
}
