//! The synchronization check between submissions and queues: semaphore signals and waits
//! (binary and timeline), image acquires and presents, host waits on fences, semaphores and
//! idle queues, and queue family ownership transfers.

use super::{A, Access, BarrierCmd, HazardKind, Key, Objects, Origin, Read, S, Sync, What, later};

/// Signals kept per semaphore: a wait looks for the one that satisfies it among these.
pub(super) const SIGNALS_KEPT: usize = 64;

impl Sync {
    /// The submission whose signal a wait on `semaphore` waits for: a binary semaphore's
    /// last signal; a timeline semaphore's first signal of at least `value`.
    pub(super) fn signal_for(&self, semaphore: u64, value: Option<u64>) -> Option<u32> {
        let signals = self.signalled.get(&semaphore)?;
        match value {
            None => signals.last().map(|(_, seq)| *seq),
            Some(v) => signals
                .iter()
                .filter(|(sv, _)| sv.is_none_or(|sv| sv >= v))
                .map(|(_, seq)| *seq)
                .min(),
        }
    }

    /// `b`'s dependency and layout transition; `check_old`: whether its old layout must be
    /// the one the subresource is in (a render pass's own transitions are checked at its
    /// start, by `expect_layouts`, under the command that begins it).
    /// An exclusive resource used by the current queue family: reading what another family
    /// left needs that family's release and this one's acquire (a write that keeps nothing
    /// needs neither). The user becomes the owner.
    pub(super) fn own(&mut self, key: Key, write: bool, a: &Access) {
        let Some(family) = self.family else { return };
        let handle = match key {
            Key::Buffer { buffer, .. } => buffer,
            Key::Image { image, .. } => image,
        };
        if self.concurrent.contains(&handle) {
            return;
        }
        let st = self.states.entry(key);
        let previous = st.owner.replace(family);
        if let Some(owner) = previous.filter(|o| *o != family && !write) {
            let by = st
                .write
                .as_ref()
                .map_or(Origin::none(""), |w| w.access.command.clone());
            let prior = Access::event(&by, What::Spelt(format!("owned by queue family {owner}")));
            let mut access = a.clone();
            access.what = What::Spelt(format!("{} on queue family {family}", access.what));
            self.note(
                &a.command,
                key,
                HazardKind::OwnershipTransferMissing,
                access,
                prior,
            );
        }
    }

    /// A queue family ownership transfer's half on this queue: the release (on the source
    /// family) ignores its second scope, the acquire (on the destination) its first, which
    /// the semaphore between the two queues stands in for.
    pub(super) fn transfer_half(
        &mut self,
        objects: &Objects,
        b: &BarrierCmd,
        (src, dst): (u32, u32),
    ) {
        let Some(family) = self.family else { return };
        // Only buffer and image barriers carry queue families.
        let keys = self.barrier_keys(objects, &b.target);
        if family == src {
            let release = BarrierCmd {
                dst_stages: S::EMPTY,
                dst_access: A::EMPTY,
                families: None,
                ..b.clone()
            };
            self.barrier(objects, &release, true);
            for key in keys {
                let st = self.states.entry(key);
                st.released = Some((src, dst));
                // Made available by the release, visible to nothing yet.
                if let Some(w) = st.write.as_mut().filter(|w| w.visible.is_empty()) {
                    w.visible.push((S::EMPTY, A::EMPTY));
                }
            }
        } else if family == dst {
            let later_stages = later(b.dst_stages);
            let walking = self.walking;
            for key in keys {
                let st = self.states.entry(key);
                st.released = None;
                st.owner = Some(dst);
                if let Some(w) = st.write.as_mut().filter(|w| !w.exec.is_empty()) {
                    w.exec |= later_stages;
                    if !w.visible.is_empty() {
                        w.visible.push((later_stages, b.dst_access.expand()));
                    }
                }
                for r in st.reads.iter_mut().filter(|r| !r.exec.is_empty()) {
                    r.exec |= later_stages;
                }
                if let Some((_, to)) = b.layouts {
                    st.layout = Some((to, b.origin.clone()));
                    st.layout_in = walking;
                }
            }
        }
    }

    /// A semaphore wait at stages `mask`: what was submitted up to the semaphore's signal
    /// is ordered before those stages (and logically later ones), and its writes are
    /// visible to them (a signal makes every write available, a wait visible). A wait on
    /// an image acquire orders the presentation engine's read before them.
    pub(super) fn semaphore_wait(&mut self, semaphore: u64, mask: S, value: Option<u64>) {
        let dst = later(mask);
        if let Some(keys) = self.acquire_semaphores.remove(&semaphore) {
            self.acquires_waited.extend(keys.iter().copied());
            for key in keys {
                if let Some(st) = self.states.get_mut(&key) {
                    for r in &mut st.reads {
                        r.exec |= dst;
                    }
                }
            }
            return;
        }
        let Some(upto) = self.signal_for(semaphore, value) else {
            // Signalled before the imported frames, or by the host: nothing here to order.
            return;
        };
        for st in self.states.values_mut() {
            if let Some(w) = st.write.as_mut().filter(|w| w.seq <= upto) {
                w.exec |= dst;
                w.visible.push((dst, A::from_bits(u64::MAX)));
            }
            for r in st.reads.iter_mut().filter(|r| r.seq <= upto) {
                r.exec |= dst;
            }
        }
    }

    /// A host wait saw submissions up to `upto` complete: their accesses are over (the
    /// validation layer retires them too). The presentation engine's read of an acquired
    /// image is no queue's work: only the acquire's own fence or semaphore orders it.
    pub(super) fn retire(&mut self, upto: u32) {
        for st in self.states.values_mut() {
            if st.write.as_ref().is_some_and(|w| w.seq <= upto) {
                st.write = None;
            }
            st.reads.retain(|r| {
                r.seq > upto || matches!(r.access.what, What::Text(t) if t == super::ACQUIRE_READ)
            });
        }
    }

    /// `vkAcquireNextImageKHR` handed `image` over: the presentation engine read it until
    /// now, and only the acquire's semaphore (waited on) or fence orders that read.
    pub fn acquire(&mut self, objects: &Objects, image: u64, sync: (u64, u64), command: &Origin) {
        if !self.enabled {
            return;
        }
        let keys = Self::image_keys(objects, image, (0, None), (0, None));
        for &key in &keys {
            self.acquires_waited.remove(&key);
            let st = self.states.entry(key);
            st.write = None;
            st.reads = vec![Read {
                access: Access::event(command, What::Text(super::ACQUIRE_READ)),
                seq: self.seq,
                exec: S::EMPTY,
            }];
        }
        let (semaphore, fence) = sync;
        if semaphore != 0 {
            self.acquire_semaphores.insert(semaphore, keys.clone());
        }
        if fence != 0 {
            self.acquire_fences.insert(fence, keys);
        }
    }

    /// `vkQueuePresentKHR` of `images` after waiting on `waits`: the presentation engine
    /// reads each image, which needs the image's last write submitted no later than a
    /// waited semaphore's signal.
    pub fn present(&mut self, objects: &Objects, waits: &[u64], images: &[u64], command: &Origin) {
        if !self.enabled {
            return;
        }
        let covered = waits.iter().filter_map(|s| self.signal_for(*s, None)).max();
        for &image in images {
            for key in Self::image_keys(objects, image, (0, None), (0, None)) {
                let Some(w) = self.states.get(&key).and_then(|s| s.write.clone()) else {
                    continue;
                };
                if covered.is_none_or(|c| w.seq > c) {
                    let a =
                        Access::event(command, What::Text("presentation engine read (present)"));
                    self.note(command, key, HazardKind::PresentAfterWrite, a, w.access);
                }
            }
        }
    }

    /// `vkQueueWaitIdle` or `vkDeviceWaitIdle`: everything submitted so far is over.
    pub fn idle(&mut self) {
        self.retire(self.seq);
    }

    /// A host wait that returned `VK_SUCCESS`: on `fences` (all of them, or the only one),
    /// or on timeline `semaphores` likewise.
    pub fn host_wait(&mut self, fences: &[u64], semaphores: &[(u64, Option<u64>)], all: bool) {
        if !self.enabled {
            return;
        }
        if !all && fences.len() + semaphores.len() > 1 {
            // One of several, unknown which.
            return;
        }
        for f in fences {
            if let Some(keys) = self.acquire_fences.remove(f) {
                self.acquires_waited.extend(keys.iter().copied());
                for key in keys {
                    if let Some(st) = self.states.get_mut(&key) {
                        st.reads.clear();
                    }
                }
            }
            if let Some(&upto) = self.fences.get(f) {
                self.retire(upto);
            }
        }
        for &(s, value) in semaphores {
            if let Some(upto) = self.signal_for(s, value) {
                self.retire(upto);
            }
        }
    }
}
