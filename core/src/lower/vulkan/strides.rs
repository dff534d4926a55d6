//! Vertex buffers laid out as wgpu does not take them: WebGPU's vertex strides are multiples
//! of 4 bytes and its 8- and 16-bit formats have one, two or four channels; Vulkan takes any
//! stride (a terminal's one byte of attributes per cell) and three channels (OpenGL's
//! `GL_SHORT` normals through zink). Such a binding reads a copy of its buffer, made from the
//! contents the frame starts with, where each element's attributes are moved apart so that a
//! three-channel attribute becomes its four-channel twin (the fourth channel zero, which a
//! three-component shader input never reads) and the stride is the next multiple of 4.
//! Where a pass of the frame writes those bytes the draw is refused by name, as the copy
//! would not see the writes.

use crate::capture::format::VertexAttributeVk;

/// The stride wgpu takes for `stride`: the next multiple of 4.
pub(super) fn padded(stride: u32) -> u32 {
    stride.div_ceil(4).saturating_mul(4)
}

/// A three-channel 8- or 16-bit format's four-channel twin and the bytes of one channel.
pub(super) fn widened(format: &str) -> Option<(String, u32)> {
    let short = format.strip_prefix("VK_FORMAT_")?;
    if short == "B8G8R8_UNORM" {
        return Some(("VK_FORMAT_B8G8R8A8_UNORM".to_owned(), 1));
    }
    for (three, four, channel) in [
        ("R8G8B8_", "R8G8B8A8_", 1),
        ("R16G16B16_", "R16G16B16A16_", 2),
    ] {
        if let Some(kind) = short.strip_prefix(three) {
            return Some((format!("VK_FORMAT_{four}{kind}"), channel));
        }
    }
    None
}

/// How one binding's elements are copied: each attribute's bytes from its offset to a new
/// one, and the new stride.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) struct Relayout {
    /// (old offset, new offset, bytes) of each run of bytes copied.
    pub moves: Vec<(u32, u32, u32)>,
    pub stride: u32,
    /// Each attribute's new offset and format, in the order given.
    pub attributes: Vec<(u32, String)>,
}

/// The layout a binding of `stride` with `attributes` (with their sizes in bytes) is copied
/// to, or `None` where wgpu takes it as it is.
pub(super) fn relayout(stride: u32, attributes: &[(&VertexAttributeVk, u32)]) -> Option<Relayout> {
    let widen: Vec<Option<(String, u32)>> =
        attributes.iter().map(|(a, _)| widened(&a.format)).collect();
    if stride.is_multiple_of(4) && widen.iter().all(Option::is_none) {
        return None;
    }
    if widen.iter().all(Option::is_none) {
        // Only the stride: each element whole.
        return Some(Relayout {
            moves: vec![(0, 0, stride)],
            stride: padded(stride),
            attributes: attributes
                .iter()
                .map(|(a, _)| (a.offset, a.format.clone()))
                .collect(),
        });
    }
    // Each attribute moves by the channels added before it.
    let extra_before = |offset: u32| -> u32 {
        attributes
            .iter()
            .zip(&widen)
            .filter(|((a, _), w)| w.is_some() && a.offset < offset)
            .map(|(_, w)| w.as_ref().map_or(0, |w| w.1))
            .sum()
    };
    let mut moves = Vec::new();
    let mut out = Vec::new();
    let mut end = 0;
    for ((a, size), w) in attributes.iter().zip(&widen) {
        let at = a.offset + extra_before(a.offset);
        moves.push((a.offset, at, *size));
        let (format, grown) = match w {
            Some((four, channel)) => (four.clone(), size + channel),
            None => (a.format.clone(), *size),
        };
        end = end.max(at + grown);
        out.push((at, format));
    }
    let added: u32 = widen.iter().flatten().map(|w| w.1).sum();
    Some(Relayout {
        moves,
        stride: padded((stride + added).max(end)),
        attributes: out,
    })
}

/// The elements of a `size`-byte buffer holding `bytes` (zeros past them), from `offset` on,
/// `stride` bytes apart, copied as `layout` says; never empty (wgpu buffers are not).
pub(super) fn repack(
    bytes: &[u8],
    size: u64,
    offset: u64,
    stride: u32,
    layout: &Relayout,
) -> Vec<u8> {
    let wide = layout.stride as usize;
    let n = (size.saturating_sub(offset) as usize).div_ceil(stride.max(1) as usize);
    let mut out = vec![0u8; (n * wide).max(4)];
    for i in 0..n {
        let element = (offset as usize).saturating_add(i * stride as usize);
        for &(from, to, len) in &layout.moves {
            let start = element.saturating_add(from as usize);
            let end = start.saturating_add(len as usize).min(bytes.len());
            let Some(run) = bytes.get(start..end) else {
                continue;
            };
            let at = i * wide + to as usize;
            if let Some(dst) = out.get_mut(at..at + run.len()) {
                dst.copy_from_slice(run);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attribute(offset: u32, format: &str) -> VertexAttributeVk {
        VertexAttributeVk {
            location: 0,
            binding: 0,
            format: format.to_owned(),
            offset,
        }
    }

    #[test]
    fn strides_are_padded_and_elements_kept_whole() {
        assert_eq!((padded(1), padded(4), padded(6), padded(0)), (4, 4, 8, 0));
        let a = attribute(0, "VK_FORMAT_R8_UINT");
        let layout = relayout(1, &[(&a, 1)]).unwrap();
        assert_eq!(layout.stride, 4);
        // One byte per element from offset 1: 2, 3, 4 at 0, 4, 8.
        assert_eq!(
            repack(&[1, 2, 3, 4], 4, 1, 1, &layout),
            [2, 0, 0, 0, 3, 0, 0, 0, 4, 0, 0, 0]
        );
        assert_eq!(
            relayout(8, &[(&attribute(0, "VK_FORMAT_R32G32_SFLOAT"), 8)]),
            None
        );
    }

    #[test]
    fn three_channels_become_four_and_later_attributes_move() {
        assert_eq!(
            widened("VK_FORMAT_R16G16B16_SSCALED"),
            Some(("VK_FORMAT_R16G16B16A16_SSCALED".to_owned(), 2))
        );
        assert_eq!(
            widened("VK_FORMAT_R8G8B8_UNORM"),
            Some(("VK_FORMAT_R8G8B8A8_UNORM".to_owned(), 1))
        );
        assert_eq!(widened("VK_FORMAT_R32G32B32_SFLOAT"), None);
        // A 3 x 16-bit position then a 4 x 8-bit colour: 10 bytes become 12.
        let (p, c) = (
            attribute(0, "VK_FORMAT_R16G16B16_SSCALED"),
            attribute(6, "VK_FORMAT_R8G8B8A8_UNORM"),
        );
        let layout = relayout(10, &[(&p, 6), (&c, 4)]).unwrap();
        assert_eq!(layout.stride, 12);
        assert_eq!(
            layout.attributes,
            [
                (0, "VK_FORMAT_R16G16B16A16_SSCALED".to_owned()),
                (8, "VK_FORMAT_R8G8B8A8_UNORM".to_owned())
            ]
        );
        let element: Vec<u8> = (1..=10).collect();
        assert_eq!(
            repack(&element, 10, 0, 10, &layout),
            [1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 10]
        );
    }
}
