//! The state of one tracked buffer or image subresource and the rules of a single access:
//! what a read, a write, a memory or execution dependency and a layout transition do to it,
//! and the hazards each finds. The checker (`super`) walks commands and applies these.

use super::Origin;
use super::stages::canonical;
use super::{A, Access, BarrierCmd, HazardKind, S, What, earlier, later};
use crate::capture::vulkan::ImageLayout;

#[derive(Clone, Debug)]
pub(super) struct Write {
    pub(super) access: Access,
    /// The submission it was made in (host waits retire what they waited for).
    pub(super) seq: u32,
    /// The queue it was made on.
    pub(super) queue: u64,
    /// Stages ordered after the write (execution dependencies, chained).
    pub(super) exec: S,
    /// Scopes the write has been made visible to.
    pub(super) visible: Vec<(S, A)>,
}

#[derive(Clone, Debug)]
pub(super) struct Read {
    pub(super) access: Access,
    pub(super) seq: u32,
    /// Stages ordered after the read.
    pub(super) exec: S,
}

#[derive(Clone, Debug, Default)]
pub(super) struct State {
    pub(super) write: Option<Write>,
    pub(super) reads: Vec<Read>,
    /// An image subresource's layout and the command that put it there; `None` where
    /// neither the imported frames nor what stood before them say (`Sync::start`).
    pub(super) layout: Option<(ImageLayout, Origin)>,
    /// The primary command buffer whose commands set `layout` (0: none, before the frames).
    pub(super) layout_in: u64,
    /// The queue family that last used it (an exclusive resource's owner), and a release
    /// to another family not yet acquired.
    pub(super) owner: Option<u32>,
    pub(super) released: Option<(u32, u32)>,
}

/// The first synchronization and access scope of a dependency, and its second. The second
/// synchronization scope (`dst`) reaches logically later stages; its access scope
/// (`dst_visible`, with `dst_access`) only the stages the mask names, as the specification
/// says access scopes are not extended (a barrier to the vertex shader orders a fragment
/// shader's read but does not make the write visible to it).
#[derive(Clone, Copy, Debug)]
pub(super) struct Dep {
    pub(super) src: S,
    pub(super) src_access: A,
    pub(super) dst: S,
    pub(super) dst_visible: S,
    pub(super) dst_access: A,
}

impl Dep {
    pub(super) fn of(b: &BarrierCmd) -> Self {
        Dep {
            src: earlier(b.src_stages),
            src_access: b.src_access.expand(),
            dst: later(b.dst_stages),
            dst_visible: canonical(b.dst_stages),
            dst_access: b.dst_access.expand(),
        }
    }
}

impl State {
    /// `a` reads: after a write it must be visible to it, unless the read is ordered after
    /// another read of the write (the validation layer's rule: that read was checked against
    /// the write, and one missing dependency is one finding).
    pub(super) fn read(&mut self, a: Access, seq: u32) -> Option<(HazardKind, Access)> {
        let after_read = self.reads.iter().any(|r| r.exec.intersects(a.stage));
        let hazard = self.write.as_ref().filter(|_| !after_read).and_then(|w| {
            let seen = w
                .visible
                .iter()
                .any(|(s, x)| s.intersects(a.stage) && x.intersects(a.access));
            (!seen).then(|| (HazardKind::ReadAfterWrite, w.access.clone()))
        });
        match self.reads.iter_mut().find(|r| r.access.stage == a.stage) {
            Some(r) => {
                r.access = a;
                r.exec = S::EMPTY;
                r.seq = seq;
            }
            None => self.reads.push(Read {
                access: a,
                exec: S::EMPTY,
                seq,
            }),
        }
        hazard
    }

    /// `a` writes: reads since the last write must be ordered before it; without such
    /// reads, the last write must be visible to it. (Reads ordered after the last write
    /// carry its ordering; the validation layer checks a write the same way, so one missing
    /// dependency is one finding.)
    pub(super) fn write(&mut self, a: Access, seq: u32, queue: u64) -> Vec<(HazardKind, Access)> {
        let mut hazards: Vec<(HazardKind, Access)> = self
            .reads
            .iter()
            .find(|r| !r.exec.intersects(a.stage))
            .map(|r| (HazardKind::WriteAfterRead, r.access.clone()))
            .into_iter()
            .collect();
        if let Some(w) = &self.write {
            let seen = w
                .visible
                .iter()
                .any(|(s, x)| s.intersects(a.stage) && x.intersects(a.access));
            if !seen && self.reads.is_empty() {
                hazards.push((HazardKind::WriteAfterWrite, w.access.clone()));
            }
        }
        self.write = Some(Write {
            access: a,
            seq,
            queue,
            exec: S::EMPTY,
            visible: Vec::new(),
        });
        self.reads.clear();
        hazards
    }

    /// A memory dependency without a layout transition.
    pub(super) fn depend(&mut self, d: &Dep) {
        if let Some(w) = &mut self.write {
            let in_scope = d.src.intersects(w.access.stage) || w.exec.intersects(d.src);
            if in_scope {
                // The write is made available by this barrier (its access in the first
                // access scope) or was by an earlier one this barrier chains to.
                let available = d.src_access.intersects(w.access.access) || !w.visible.is_empty();
                w.exec |= d.dst;
                if available {
                    w.visible.push((d.dst_visible, d.dst_access));
                }
            }
        }
        for r in &mut self.reads {
            if d.src.intersects(r.access.stage) || r.exec.intersects(d.src) {
                r.exec |= d.dst;
            }
        }
    }

    /// A layout transition: a write ordered after what the first scopes reach, visible to
    /// the second. Like any write it must follow the reads, or without them the last write.
    pub(super) fn transition(
        &mut self,
        d: &Dep,
        a: Access,
        seq: u32,
        queue: u64,
    ) -> Vec<(HazardKind, Access)> {
        let mut hazards: Vec<(HazardKind, Access)> = self
            .reads
            .iter()
            .find(|r| !(d.src.intersects(r.access.stage) || r.exec.intersects(d.src)))
            .map(|r| (HazardKind::WriteAfterRead, r.access.clone()))
            .into_iter()
            .collect();
        if let Some(w) = &self.write {
            let exec = d.src.intersects(w.access.stage) || w.exec.intersects(d.src);
            let available = d.src_access.intersects(w.access.access)
                || w.visible.iter().any(|(s, _)| s.intersects(d.src));
            // Layout transitions on one queue happen in submission order with respect to
            // each other (the validation layer's rule for sequential transitions too): a
            // transition after a transition is a hazard only across queues.
            let sequential = matches!(w.access.what, What::Transition(..)) && w.queue == queue;
            if !(sequential || exec && available) && self.reads.is_empty() {
                hazards.push((HazardKind::WriteAfterWrite, w.access.clone()));
            }
        }
        self.write = Some(Write {
            access: a,
            seq,
            queue,
            exec: d.dst,
            visible: vec![(d.dst_visible, d.dst_access)],
        });
        self.reads.clear();
        hazards
    }
}
