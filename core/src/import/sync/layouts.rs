//! Image layouts as the synchronization check follows them: where each image stands before
//! the imported frames (its creation, a trimmed capture's snapshot, what earlier submissions
//! left), what the frames' barriers and render passes put it in, and every use held against
//! it, judged at the command where its own command buffer set the layout and otherwise at
//! the submission.

use super::super::commands::Cmd;
use super::{
    Access, HazardKind, ImageLayout, Key, Objects, Origin, Recording, Recordings, RenderInstance,
    Sync, UNKNOWN, What,
};

impl Sync {
    /// `image` stands in `layout` before the imported frames (said by `origin`) unless a
    /// command submitted before them, or in them, puts it in another.
    pub fn start_layout(&mut self, image: u64, layout: ImageLayout, origin: Origin) {
        if self.enabled {
            self.start.insert(image, (layout, origin));
        }
    }

    /// The layouts command buffer `cb`, submitted before the imported frames, leaves its
    /// images in; its accesses are not checked (they are not the frames').
    pub fn submitted_before(&mut self, objects: &Objects, recordings: &Recordings, cb: u64) {
        if let Some(r) = recordings.get(&cb).filter(|_| self.enabled) {
            self.walking = 0;
            self.layouts_of(objects, recordings, r, 0);
        }
    }

    pub(super) fn layouts_of(
        &mut self,
        objects: &Objects,
        recordings: &Recordings,
        r: &Recording,
        depth: u32,
    ) {
        for (i, cmd) in r.cmds.iter().enumerate() {
            let command = r.at.get(i).unwrap_or(&UNKNOWN);
            match cmd {
                Cmd::Barrier(bs) => {
                    for b in bs {
                        let Some((from, to)) = b.layouts else {
                            continue;
                        };
                        if from == to && objects.synchronization2 {
                            continue;
                        }
                        for key in self.barrier_keys(objects, &b.target) {
                            self.set_layout(key, to, &b.origin);
                        }
                    }
                }
                Cmd::BeginRender(ri) => self.leave_layouts(objects, ri, command),
                Cmd::Execute(list) if depth < crate::import::record::MAX_EXECUTE_DEPTH => {
                    for cb in list {
                        if let Some(sub) = recordings.get(cb) {
                            self.layouts_of(objects, recordings, sub, depth + 1);
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// A submission before the frames was not walked: what it did to layouts is unknown, so
    /// no layout is held against a use until the frames set it.
    pub fn layouts_unknown(&mut self) {
        self.start.clear();
        for st in self.states.values_mut() {
            st.layout = None;
        }
    }

    /// `key` is now in `layout`, put there by `origin` in the command buffer being walked.
    pub(super) fn set_layout(&mut self, key: Key, layout: ImageLayout, origin: &Origin) {
        let st = self.states.entry(key);
        st.layout = Some((layout, origin.clone()));
        st.layout_in = self.walking;
    }

    /// A use of `key` in `layout` by `command`: a finding when the subresource is known to
    /// be in another. Where a command of the same command buffer put it there, the finding is
    /// the command's, as recording it shows; otherwise the layout it stands in is known only
    /// when the command buffer is submitted, and the finding is the submission's.
    pub(super) fn expect_layout(
        &mut self,
        key: Key,
        layout: ImageLayout,
        command: &Origin,
        what: What,
    ) {
        let Key::Image { image, .. } = key else {
            return;
        };
        let known = self
            .states
            .get(&key)
            .and_then(|s| s.layout.as_ref().map(|(l, by)| (*l, by, s.layout_in)));
        let (current, by, within) = match known {
            Some((l, by, cb)) => (l, by, cb != 0 && cb == self.walking),
            None => match self.start.get(&image) {
                Some((l, by)) => (*l, by, false),
                None => return,
            },
        };
        if current == layout {
            return;
        }
        let prior = Access::event(by, What::InLayout("layout", current));
        if within {
            let access = Access::event(command, what);
            self.note(command, key, HazardKind::LayoutMismatch, access, prior);
            return;
        }
        let what = match what {
            What::InLayout(what, l) => What::InLayoutAt(what, l, command.clone()),
            other => other,
        };
        let at = self.submission.clone().unwrap_or_else(|| UNKNOWN.clone());
        let access = Access::event(&at, what);
        self.note(&at, key, HazardKind::LayoutMismatch, access, prior);
    }

    /// A render pass's attachments at its start: each in the layout the render pass
    /// declares (`initialLayout`; dynamic rendering: the attachment's own).
    pub(super) fn expect_layouts(
        &mut self,
        objects: &Objects,
        ri: &RenderInstance,
        command: &Origin,
    ) {
        for (view, initial, _) in &ri.layouts {
            let Some(initial) = initial else { continue };
            for key in Self::view_keys(objects, *view) {
                self.expect_layout(
                    key,
                    *initial,
                    command,
                    What::InLayout("attachment in", *initial),
                );
            }
        }
    }

    /// A render pass's attachments at its end, in their final layouts.
    pub(super) fn leave_layouts(
        &mut self,
        objects: &Objects,
        ri: &RenderInstance,
        command: &Origin,
    ) {
        for (view, _, last) in &ri.layouts {
            for key in Self::view_keys(objects, *view) {
                self.set_layout(key, *last, command);
            }
        }
    }
}
