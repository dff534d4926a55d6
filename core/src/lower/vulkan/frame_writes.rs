//! Writes of the frame to the bytes the import reads at its start (indices, vertex buffers
//! laid out anew): whether a pass may change them, and vertex buffers copied to a layout wgpu
//! takes where none does.

use wgpu_types as wgpu;

use super::{Fail, VkProblem, provoking, strides};
use crate::capture::model::*;
use crate::lower::Lowering;
use crate::plan::*;

/// `len` bytes of `data` from `at`, where it holds them.
fn bytes_at(data: Option<&[u8]>, at: u64, len: u64) -> Option<&[u8]> {
    let at = usize::try_from(at).ok()?;
    data?.get(at..at.checked_add(usize::try_from(len).ok()?)?)
}

impl<'c> Lowering<'c> {
    /// Whether a pass of the frame may change bytes `start..end` of buffer `r` from what
    /// they start as (`provoking::Written::changes`): copies of the same bytes do not.
    pub(super) fn vk_frame_changes(&mut self, r: ResourceId, start: u64, end: u64) -> bool {
        let written = self
            .vk
            .written
            .get_or_insert_with(|| provoking::written(self.capture));
        let (buffer_of, buffers) = (&self.buffer_of, &self.plan.buffers);
        let initial = |r: ResourceId| {
            buffer_of
                .get(&r)
                .and_then(|&i| buffers[i].initial.as_deref())
        };
        let dst = initial(r);
        written.changes(r, start, end, |src, at, dst_at, len| {
            bytes_at(initial(src), at, len).is_some_and(|s| Some(s) == bytes_at(dst, dst_at, len))
        })
    }

    /// Vertex buffer `buffer` from `offset` copied to the stride wgpu takes for `stride`, once;
    /// refused where a pass of the frame writes those bytes.
    pub(super) fn vk_repacked(
        &mut self,
        p: &'c PassDesc,
        buffer: ResourceId,
        offset: u64,
        stride: u32,
        layout: &strides::Relayout,
    ) -> Result<usize, Fail> {
        let key = (buffer, offset, stride, layout.clone());
        if let Some(&i) = self.vk.repacked.get(&key) {
            return Ok(i);
        }
        let name = self.capture.resource(buffer).name.clone();
        if self.vk_frame_changes(buffer, offset, u64::MAX) {
            return Err(VkProblem::Unsupported {
                feature: format!(
                    "a vertex buffer laid out as wgpu does not take it (a stride of {stride} bytes, or three 8- or 16-bit channels) over \"{name}\", which a pass of the frame writes"
                ),
            }
            .into());
        }
        let plan = self.buf(p, buffer)?;
        let source = &self.plan.buffers[plan];
        let bytes = strides::repack(
            source.initial.as_deref().unwrap_or_default(),
            source.size,
            offset,
            stride,
            layout,
        );
        self.plan.buffers.push(BufferSpec {
            name: format!(
                "{name}: from byte {offset} at a vertex stride of {}",
                layout.stride
            ),
            size: bytes.len() as u64,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            initial: Some(bytes),
            history: false,
        });
        let i = self.plan.buffers.len() - 1;
        self.vk.repacked.insert(key, i);
        Ok(i)
    }
}
