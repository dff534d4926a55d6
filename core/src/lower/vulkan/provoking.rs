//! Triangles wgpu cannot draw as Vulkan recorded them, redrawn as an indexed triangle list:
//! flat inputs from the last vertex (`VK_PROVOKING_VERTEX_MODE_LAST_VERTEX_EXT`, GL's
//! convention, which ANGLE and zink keep; wgpu always takes the first vertex's), and
//! triangle fans (wgpu has none). Each triangle keeps its vertices in Vulkan's order for
//! the topology (the specification's "Primitive Topologies"), rotated cyclically when the
//! last vertex provokes so that it comes first: a rotation keeps the winding, so culling
//! and front faces are unchanged. A draw of vertices gets generated indices; an indexed draw
//! gets its own indices rearranged where the capture holds them as the draw reads them.
//! Lines, points and indirect draws are refused by name.

use std::collections::BTreeMap;

use wgpu_types as wgpu;

use super::VkProblem;
use crate::capture::format::Access;
use crate::capture::model::{Capture, ResourceId};
use crate::plan::BufferSpec;

/// How a draw whose flat inputs come from the last vertex is drawn with the first's.
#[derive(Debug, PartialEq)]
pub(super) struct Listed {
    /// The rotated indices: (plan buffer, byte offset, format).
    pub index: (usize, u64, wgpu::IndexFormat),
    pub first: u32,
    pub count: u32,
    pub base_vertex: i32,
}

/// The draw as the capture records it.
pub(super) struct Draw<'a> {
    pub topology: &'a str,
    pub primitive_restart: bool,
    pub count: u32,
    pub first: u32,
    pub base_vertex: i32,
    pub indirect: bool,
    /// (its bytes as the frame starts, byte offset, 32-bit), for an indexed draw.
    pub indices: Option<(Option<&'a [u8]>, u64, bool)>,
}

fn refuse(what: String) -> VkProblem {
    VkProblem::Unsupported {
        feature: format!(
            "flat inputs from the last vertex (VK_PROVOKING_VERTEX_MODE_LAST_VERTEX_EXT) {what}: wgpu takes the first's"
        ),
    }
}

/// The triangles of `d` as a list, each starting at its provoking vertex, as 32-bit indices
/// to draw from index 0 with the returned base vertex.
pub(super) fn list_indices(d: &Draw, last: bool) -> Result<(Vec<u32>, i32), VkProblem> {
    let topology = d.topology.trim_start_matches("VK_PRIMITIVE_TOPOLOGY_");
    let shape = match topology {
        "TRIANGLE_LIST" => Shape::List,
        "TRIANGLE_STRIP" => Shape::Strip,
        "TRIANGLE_FAN" => Shape::Fan,
        _ => return Err(refuse(format!("in a draw of {topology}"))),
    };
    if d.indirect {
        return Err(refuse(
            "in an indirect draw (its count is read on the GPU)".to_owned(),
        ));
    }
    let source: Vec<u32> = match d.indices {
        None => (0..d.count).collect(),
        Some((bytes, offset, wide)) => {
            let bytes = bytes.ok_or_else(|| {
                refuse(
                    "in an indexed draw whose indices the capture does not hold as the draw reads them (never captured, or written during the frame)"
                        .to_owned(),
                )
            })?;
            read_indices(bytes, offset, d.first, d.count, wide)?
        }
    };
    // Restart ends a strip or fan where the index is all ones; in a list it needs an
    // extension and is refused.
    let restart = match d.indices {
        Some((_, _, true)) => u32::MAX,
        _ => u32::from(u16::MAX),
    };
    let restarts = d.primitive_restart && d.indices.is_some();
    if restarts && shape == Shape::List && source.contains(&restart) {
        return Err(refuse("in a triangle list that restarts".to_owned()));
    }
    let mut out = Vec::with_capacity(source.len() * 3);
    let segments: Vec<&[u32]> = if restarts {
        source.split(|&i| i == restart).collect()
    } else {
        vec![&source]
    };
    for v in segments {
        triangles(shape, v, last, &mut out);
    }
    // A draw of vertices numbers them from `first`: as a base vertex, indices start at 0.
    let base = match d.indices {
        None => i32::try_from(d.first)
            .map_err(|_| VkProblem::Missing(format!("first vertex {} past i32", d.first)))?,
        Some(_) => d.base_vertex,
    };
    Ok((out, base))
}

#[derive(Clone, Copy, PartialEq)]
enum Shape {
    List,
    Strip,
    Fan,
}

/// Appends the triangles of one run of vertices `v` to `out`, provoking vertex first.
fn triangles(shape: Shape, v: &[u32], last: bool, out: &mut Vec<u32>) {
    let n = match shape {
        Shape::List => v.len() / 3,
        Shape::Strip | Shape::Fan => v.len().saturating_sub(2),
    };
    for i in 0..n {
        // Vulkan's vertex order for triangle i, and which of the three provokes.
        let (t, first_provoking, last_provoking) = match shape {
            Shape::List => ([v[3 * i], v[3 * i + 1], v[3 * i + 2]], 0, 2),
            Shape::Strip if i % 2 == 0 => ([v[i], v[i + 1], v[i + 2]], 0, 2),
            // Odd triangles of a strip are wound the other way: (i, i + 2, i + 1).
            Shape::Strip => ([v[i], v[i + 2], v[i + 1]], 0, 1),
            Shape::Fan => ([v[i + 1], v[i + 2], v[0]], 0, 1),
        };
        let k = if last {
            last_provoking
        } else {
            first_provoking
        };
        out.extend([t[k], t[(k + 1) % 3], t[(k + 2) % 3]]);
    }
}

/// The bytes `count` indices from index `first` take in an index buffer bound at `offset`.
pub(super) fn index_bytes(offset: u64, first: u32, count: u32, wide: bool) -> (u64, u64) {
    let size = if wide { 4 } else { 2 };
    let start = offset.saturating_add(u64::from(first) * size);
    (start, start.saturating_add(u64::from(count) * size))
}

/// `count` indices from index `first` at byte `offset` of `bytes`.
fn read_indices(
    bytes: &[u8],
    offset: u64,
    first: u32,
    count: u32,
    wide: bool,
) -> Result<Vec<u32>, VkProblem> {
    let (start, end) = index_bytes(offset, first, count, wide);
    let range = usize::try_from(start)
        .ok()
        .zip(usize::try_from(end).ok())
        .and_then(|(s, e)| bytes.get(s..e))
        .ok_or_else(|| {
            VkProblem::Missing(format!(
                "indices at bytes {start}..{end} of an index buffer of {} bytes",
                bytes.len()
            ))
        })?;
    Ok(if wide {
        range
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    } else {
        range
            .chunks_exact(2)
            .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
            .collect()
    })
}

/// Listed `indices` as a new plan buffer, drawn from index 0 with `base_vertex`.
pub(super) fn index_buffer(
    buffers: &mut Vec<BufferSpec>,
    name: String,
    indices: &[u32],
    base_vertex: i32,
) -> Listed {
    let mut bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    // wgpu buffers are never empty.
    bytes.resize(bytes.len().max(4), 0);
    buffers.push(BufferSpec {
        name,
        size: bytes.len() as u64,
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
        initial: Some(bytes),
        history: false,
    });
    Listed {
        index: (buffers.len() - 1, 0, wgpu::IndexFormat::Uint32),
        first: 0,
        count: indices.len() as u32,
        base_vertex,
    }
}

/// The byte ranges of each resource that some pass of the frame writes: indices there may
/// differ when a draw reads them from what the frame starts with. A buffer copy writes its
/// destination range, from its source's range; any other write, the whole resource.
pub(super) fn written(capture: &Capture) -> Written {
    let mut w = Written::default();
    for p in &capture.passes {
        for a in p.accesses.iter().filter(|a| a.access.writes()) {
            let copied: Vec<WriteRange> = p
                .copies
                .iter()
                .filter(|c| c.dst.resource == a.resource)
                .map(|c| match c.dst.size {
                    Some(size) => WriteRange {
                        start: c.dst.offset,
                        end: c.dst.offset.saturating_add(size),
                        from: Some((c.src.resource, c.src.offset)),
                    },
                    None => WriteRange::whole(),
                })
                .collect();
            let only_copies = a.access == Access::CopyDst
                && !copied.is_empty()
                && !p.clears.iter().any(|c| c.resource == a.resource);
            let ranges = w.0.entry(a.resource).or_default();
            if only_copies {
                ranges.extend(copied);
            } else {
                ranges.push(WriteRange::whole());
            }
        }
    }
    w
}

/// Bytes `start..end` of a resource a pass writes, and where a buffer copy writes them from:
/// its source and the offset there of `start`.
#[derive(Debug, Clone, Copy)]
pub(super) struct WriteRange {
    start: u64,
    end: u64,
    from: Option<(ResourceId, u64)>,
}

impl WriteRange {
    fn whole() -> Self {
        WriteRange {
            start: 0,
            end: u64::MAX,
            from: None,
        }
    }
}

/// Byte ranges written during the frame, by resource (`written`).
#[derive(Debug, Default)]
pub(super) struct Written(BTreeMap<ResourceId, Vec<WriteRange>>);

impl Written {
    /// Whether any byte of `start..end` of `r` may change during the frame: a write overlaps
    /// it that is not a copy of the same bytes. `same(source, at, dst_at, len)` says whether
    /// `source` (which the frame must not write) holds at `at` the `len` bytes `r` starts
    /// with at `dst_at` (gfxrecon's `unassisted` tracking writes mapped memory back whole,
    /// unchanged, after the draws that read it).
    pub(super) fn changes(
        &self,
        r: ResourceId,
        start: u64,
        end: u64,
        same: impl Fn(ResourceId, u64, u64, u64) -> bool,
    ) -> bool {
        self.0.get(&r).is_some_and(|ranges| {
            ranges.iter().any(|w| {
                let (from, to) = (w.start.max(start), w.end.min(end));
                from < to
                    && !w.from.is_some_and(|(src, at)| {
                        !self.0.contains_key(&src)
                            && same(src, at + (from - w.start), from, to - from)
                    })
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draw(indices: Option<(Option<&[u8]>, u64, bool)>) -> Draw<'_> {
        Draw {
            topology: "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST",
            primitive_restart: false,
            count: 7,
            first: 5,
            base_vertex: -2,
            indirect: false,
            indices,
        }
    }

    /// A copy that writes back the bytes a range starts with changes nothing (gfxrecon's
    /// `unassisted` tracking); one of other bytes, or from a source the frame writes, does.
    #[test]
    fn a_copy_of_the_same_bytes_changes_nothing() {
        let (dst, src, other) = (ResourceId(0), ResourceId(1), ResourceId(2));
        let copy = |from| WriteRange {
            start: 8,
            end: 24,
            from: Some((from, 100)),
        };
        let mut w = Written::default();
        w.0.insert(dst, vec![copy(src)]);
        let same = |s: ResourceId, at: u64, dst_at: u64, len: u64| {
            s == src && at == 100 + (dst_at - 8) && len > 0
        };
        assert!(!w.changes(dst, 0, 16, same));
        assert!(w.changes(dst, 0, 16, |_, _, _, _| false));
        assert!(
            !w.changes(dst, 24, 40, |_, _, _, _| false),
            "outside the copy"
        );
        w.0.insert(src, vec![WriteRange::whole()]);
        assert!(w.changes(dst, 0, 16, same), "a source the frame writes");
        w.0.insert(other, vec![WriteRange::whole()]);
        assert!(w.changes(other, 0, 1, same));
    }

    #[test]
    fn a_draw_of_vertices_starts_each_triangle_at_its_last() {
        let (i, base) = list_indices(&draw(None), true).unwrap();
        assert_eq!(i, [2, 0, 1, 5, 3, 4]);
        assert_eq!(base, 5);
        // With the first vertex provoking a list is drawn as it is.
        assert_eq!(
            list_indices(&draw(None), false).unwrap().0,
            [0, 1, 2, 3, 4, 5]
        );
    }

    #[test]
    fn indices_are_read_at_the_draws_first_and_keep_its_base_vertex() {
        let words: Vec<u8> = (0u16..16).flat_map(|v| (v * 10).to_le_bytes()).collect();
        let (i, base) = list_indices(&draw(Some((Some(&words), 2, false))), true).unwrap();
        // Offset 2 bytes is index 1; first 5 more: values 60, 70, ... in triangles.
        assert_eq!(i, [80, 60, 70, 110, 90, 100]);
        assert_eq!(base, -2);
    }

    #[test]
    fn strips_keep_each_triangles_winding_and_provoking_vertex() {
        let mut strip = draw(None);
        strip.topology = "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP";
        strip.count = 5;
        strip.first = 0;
        // Vulkan's triangles: (0 1 2), (1 3 2), (2 3 4); the last vertex provokes 2, 3, 4.
        let (i, _) = list_indices(&strip, true).unwrap();
        assert_eq!(i, [2, 0, 1, 3, 2, 1, 4, 2, 3]);
        let (i, _) = list_indices(&strip, false).unwrap();
        assert_eq!(i, [0, 1, 2, 1, 3, 2, 2, 3, 4]);
    }

    #[test]
    fn fans_become_lists_and_restart_splits_them() {
        // 0 1 2 3, restart, 4 5 6 as 16-bit indices.
        let v: Vec<u8> = [0u16, 1, 2, 3, 0xffff, 4, 5, 6]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut fan = draw(Some((Some(&v), 0, false)));
        fan.topology = "VK_PRIMITIVE_TOPOLOGY_TRIANGLE_FAN";
        fan.first = 0;
        fan.count = 8;
        fan.primitive_restart = true;
        // Vulkan's fan triangle i is (i + 1, i + 2, 0) of its run.
        let (i, _) = list_indices(&fan, false).unwrap();
        assert_eq!(i, [1, 2, 0, 2, 3, 0, 5, 6, 4]);
        let (i, _) = list_indices(&fan, true).unwrap();
        assert_eq!(i, [2, 0, 1, 3, 0, 2, 6, 4, 5]);
    }

    #[test]
    fn what_cannot_be_rearranged_is_refused_by_name() {
        let mut lines = draw(None);
        lines.topology = "VK_PRIMITIVE_TOPOLOGY_LINE_STRIP";
        let e = list_indices(&lines, true).unwrap_err().to_string();
        assert!(e.contains("LINE_STRIP"), "{e}");
        let e = list_indices(&draw(Some((None, 0, true))), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not hold"), "{e}");
        let short = [0u8; 8];
        assert!(list_indices(&draw(Some((Some(&short), 0, true))), true).is_err());
    }
}
