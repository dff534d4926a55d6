//! Vertex buffers at strides wgpu does not take: WebGPU's vertex strides are multiples of 4
//! bytes, Vulkan's any number (a terminal's one byte of attributes per cell). Each element is
//! copied to the next multiple of 4 into a buffer of the replay's own, from the contents the
//! frame starts with; where a pass of the frame writes those bytes the draw is refused by
//! name, as the copy would not see the writes.

/// The stride wgpu takes for `stride`: the next multiple of 4.
pub(super) fn padded(stride: u32) -> u32 {
    stride.div_ceil(4).saturating_mul(4)
}

/// The elements of a `size`-byte buffer holding `bytes` (zeros past them), from `offset` on,
/// `stride` bytes apart, each at `padded(stride)`; never empty (wgpu buffers are not).
pub(super) fn repack(bytes: &[u8], size: u64, offset: u64, stride: u32) -> Vec<u8> {
    let (stride, wide) = (stride as usize, padded(stride) as usize);
    let n = (size.saturating_sub(offset) as usize).div_ceil(stride.max(1));
    let mut out = vec![0u8; (n * wide).max(4)];
    for i in 0..n {
        let start = (offset as usize).saturating_add(i * stride);
        let end = start.saturating_add(stride).min(bytes.len());
        if let Some(element) = bytes.get(start..end) {
            out[i * wide..i * wide + element.len()].copy_from_slice(element);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_move_to_the_padded_stride() {
        assert_eq!((padded(1), padded(4), padded(6), padded(0)), (4, 4, 8, 0));
        // One byte per element from offset 1: 2, 3, 4 at 0, 4, 8.
        assert_eq!(
            repack(&[1, 2, 3, 4], 4, 1, 1),
            [2, 0, 0, 0, 3, 0, 0, 0, 4, 0, 0, 0]
        );
        // Six bytes per element; the buffer's last bytes past what the capture held are zero.
        assert_eq!(
            repack(&[1, 2, 3, 4, 5, 6, 7, 8], 12, 0, 6),
            [1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 0, 0, 0, 0, 0, 0]
        );
        assert_eq!(repack(&[], 0, 0, 3), [0, 0, 0, 0]);
    }
}
