//! What a draw's or dispatch's descriptors become in its pass's binding table: a binding per
//! resource view it can reach, with the access its kind allows and, for storage descriptors,
//! the access the bound pipeline's code makes (where the capture holds the code), so analysis
//! orders and culls on what the shaders really do.

use super::build::Builder;
use super::commands::Use;
use super::pipelines::{Pipelines, StorageUse};
use super::state::{Descriptor, Objects, storage_descriptor};
use crate::capture::format::{Access, Binding, ByteRange, Range};

impl Builder {
    /// The access of the descriptor `u` of type `ty`: `otherwise` for all but storage
    /// descriptors; for those, what the code of the pipeline `code` names does with the
    /// binding, where the capture holds that code (a binary capture); read-write, and a note,
    /// where it does not.
    fn access(
        &mut self,
        code: Option<(&Pipelines, u64)>,
        u: &Use,
        ty: &str,
        otherwise: Access,
    ) -> Access {
        if !storage_descriptor(ty) {
            return otherwise;
        }
        match code.and_then(|(p, pipeline)| p.storage_use(pipeline, u.set, u.binding)) {
            Some(StorageUse {
                writes: true,
                reads: true,
            }) => Access::StorageReadWrite,
            Some(StorageUse { writes: true, .. }) => Access::StorageWrite,
            // Read, or bound and never touched: no write to order.
            Some(_) => Access::StorageRead,
            None => {
                self.note("storage descriptors counted as read-write (the stream holds no shader code to tell)");
                Access::StorageReadWrite
            }
        }
    }

    /// Bindings from the descriptors a draw or dispatch with pipeline `code` can reach.
    pub(super) fn bind(
        &mut self,
        objects: &Objects,
        pass: usize,
        uses: &[Use],
        code: Option<(&Pipelines, u64)>,
    ) {
        for u in uses {
            // Only a descriptor the pipeline's code names is accessed (Vulkan's static use):
            // one left in a bound set is no read, no write and no feedback loop.
            if let Some((p, pipeline)) = code
                && p.used_stages(pipeline, u.set, u.binding) == Some(0)
            {
                continue;
            }
            let (handle, access, bytes, mips, layers) = match &u.descriptor {
                // A null descriptor reaches no resource.
                Descriptor::Sampler { .. } | Descriptor::Null { .. } => continue,
                Descriptor::Image { view, ty, .. } => {
                    let Some(v) = objects.views.get(view) else {
                        self.note(
                            "descriptors naming image views the stream never created: skipped",
                        );
                        continue;
                    };
                    let access = self.access(code, u, ty, Access::Sampled);
                    let img = objects.images.get(&v.image);
                    let total = img.map_or((1, 1), |i| (i.mips, i.layers));
                    let range = |base: u32, count: Option<u32>, all: u32| {
                        (base != 0 || count.is_some_and(|c| c != all))
                            .then_some(Range { base, count })
                    };
                    (
                        v.image,
                        access,
                        None,
                        range(v.base_mip, v.mip_count, total.0),
                        range(v.base_layer, v.layer_count, total.1),
                    )
                }
                Descriptor::Buffer {
                    buffer,
                    offset,
                    range,
                    ty,
                } => {
                    let access = self.access(code, u, ty, Access::Uniform);
                    let Some(b) = objects.buffers.get(buffer) else {
                        self.note("descriptors naming buffers the stream never created: skipped");
                        continue;
                    };
                    if *offset >= b.size {
                        self.note(
                            "buffer descriptors starting past the end of their buffer: skipped",
                        );
                        continue;
                    }
                    let size = (*range).min(b.size - offset);
                    let bytes = (*offset != 0 || size != b.size).then_some(ByteRange {
                        offset: *offset,
                        size,
                    });
                    (*buffer, access, bytes, None, None)
                }
                Descriptor::TexelBuffer { view, ty } => {
                    let Some(&(buffer, offset, range)) = objects.buffer_views.get(view) else {
                        self.note(
                            "descriptors naming buffer views the stream never created: skipped",
                        );
                        continue;
                    };
                    let access = self.access(code, u, ty, Access::StorageRead);
                    let size = objects.buffers.get(&buffer).map_or(0, |b| b.size);
                    if offset >= size {
                        continue;
                    }
                    let len = range.min(size - offset);
                    let bytes =
                        (offset != 0 || len != size).then_some(ByteRange { offset, size: len });
                    (buffer, access, bytes, None, None)
                }
            };
            let Some(name) = self.resource(objects, handle) else {
                continue;
            };
            let binding = Binding {
                resource: Some(name),
                sampler: None,
                access: Some(access),
                mips,
                layers,
                format: None,
                dimension: None,
                bytes,
            };
            let stem = if u.element > 0 {
                format!("set{}_binding{}_{}", u.set, u.binding, u.element)
            } else {
                format!("set{}_binding{}", u.set, u.binding)
            };
            // A resource's name stands for its handle, so the handle tells bindings apart.
            let identity = (pass, handle, access, mips, layers, bytes);
            if !self.binding_seen.insert(identity) {
                continue;
            }
            let bindings = &mut self.passes[pass].bindings;
            let mut key = stem.clone();
            while bindings.contains_key(&key) {
                let k = self.binding_next.entry((pass, stem.clone())).or_insert(2);
                key = format!("{stem}_v{k}");
                *k += 1;
            }
            bindings.insert(key, binding);
        }
    }
}
