//! Descriptor update templates read: what a template's data writes, as the writes its
//! entries stand for (`vkUpdateDescriptorSetWithTemplate`,
//! `vkCmdPushDescriptorSetWithTemplateKHR`).

use super::state::{Descriptor, EntryWrites, Holds, Objects, descriptor_kind, descriptors};
use super::value::{Arg, Got, Skip};

/// Most elements one template entry is read for: a hostile count stops here.
const MAX_TEMPLATE_ELEMENTS: u32 = 4096;

impl Objects {
    /// The descriptors a template's data writes. The data lists image infos, buffer infos and
    /// texel buffer views apart (as the binary capture holds them, and `gfxrecon-convert` 1.x
    /// writes them), each list in the template's entry order; each entry takes its count from
    /// the list of its kind, as the write it stands for would hold them.
    pub fn template_writes(
        &self,
        template: u64,
        data: &Arg<'_>,
    ) -> Got<Vec<((u32, u32), Descriptor)>> {
        Ok(self
            .template_entry_writes(template, data)?
            .into_iter()
            .flat_map(|(_, written)| written)
            .collect())
    }

    /// What [`Objects::template_writes`] writes, entry by entry: each entry's index in the
    /// template (the write it stands for) with its descriptors.
    pub fn template_entry_writes(&self, template: u64, data: &Arg<'_>) -> Got<EntryWrites> {
        let Some(t) = self.templates.get(&template) else {
            return Err(Skip(format!(
                "update template {template} was never created in the stream"
            )));
        };
        if data.opt("imageInfos").is_none() && data.opt("bufferInfos").is_none() {
            return Err(Skip(
                "the template's data is not in the stream (gfxrecon-convert 0.9.x writes none; import the .gfxr capture)".to_owned(),
            ));
        }
        // In `Holds` order.
        let lists = [
            (data.list("imageInfos")?, "image infos"),
            (data.list("bufferInfos")?, "buffer infos"),
            (data.list("bufferViews")?, "texel buffer views"),
        ];
        let mut next = [0usize; 3];
        let mut out = Vec::new();
        for (index, e) in t.entries.iter().enumerate() {
            let kind = descriptor_kind(&e.ty);
            let Some(holds) = Holds::of(&kind) else {
                continue;
            };
            let at = holds as usize;
            let (list, what) = &lists[at];
            let n = e.count.min(MAX_TEMPLATE_ELEMENTS) as usize;
            let Some(items) = list.get(next[at]..next[at] + n) else {
                return Err(Skip(format!(
                    "the template's data holds {} {what} but its entries ask for more",
                    list.len()
                )));
            };
            next[at] += n;
            out.push((index, descriptors(e.binding, e.element, &kind, items)?));
        }
        Ok(out)
    }
}
