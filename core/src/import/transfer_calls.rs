//! The transfer commands a command buffer records, read from their calls: image clears,
//! copies (with their regions) and blits (one region per layer), each as the `TransferCmd` the
//! build turns into a pass.

use super::calls::CopyKind;
use super::commands::{
    AttachmentClearCmd, BlitRegionCmd, ClearColorValue, Cmd, Region, TransferCmd, clear_color_of,
};
use super::state::Objects;
use super::subresources::{extent3, layer_count, offset3, range, subresource};
use super::value::{ASPECTS, Arg, Got, Skip};
use crate::capture::vulkan::ImageLayout;

/// `vkCmdClearColorImage` or `vkCmdClearDepthStencilImage`; a colour read through the
/// image's format (integers for an integer image).
pub(super) fn clear_image(name: &str, args: &Arg<'_>, objects: &Objects) -> Got<Cmd> {
    let target = args.get("image")?.handle()?;
    let format = objects.images.get(&target).map(|i| i.format.as_str());
    let (value, stencil) = match args.opt("pColor") {
        Some(c) => (clear_color_of(&c, format), 0),
        None => {
            let ds = args.get("pDepthStencil")?;
            (
                [ds.get("depth")?.f64()?, 0.0, 0.0, 0.0],
                ds.get("stencil")?.u32()?,
            )
        }
    };
    Ok(Cmd::Transfer(Box::new(TransferCmd::Clear {
        depth_stencil: name.contains("Depth"),
        layout: args
            .opt("imageLayout")
            .and_then(|l| ImageLayout::from_name(&l.symbol().ok()?)),
        target,
        value,
        stencil,
        ranges: args
            .list("pRanges")?
            .iter()
            .map(range)
            .collect::<Got<_>>()?,
    })))
}

/// `vkCmdClearAttachments`: each attachment by its aspect (a colour attachment by its index
/// in the subpass), and each rectangle with its layers.
pub(super) fn clear_attachments(args: &Arg<'_>) -> Got<Cmd> {
    let mut clear = AttachmentClearCmd::default();
    for a in args.list("pAttachments")? {
        let aspects = a.get("aspectMask")?.flags(ASPECTS)?;
        let value = a.get("clearValue")?;
        if aspects & 0x1 != 0 {
            let slot = a.get("colorAttachment")?.u32()?;
            clear.colors.push((slot, ClearColorValue::read(&value)));
        }
        let ds = value.opt("depthStencil");
        if aspects & 0x2 != 0 {
            let ds = ds.ok_or_else(|| Skip("a depth clear without `depthStencil`".to_owned()))?;
            clear.depth = Some(ds.get("depth")?.f64()? as f32);
        }
        if aspects & 0x4 != 0 {
            let ds = ds.ok_or_else(|| Skip("a stencil clear without `depthStencil`".to_owned()))?;
            clear.stencil = Some(ds.get("stencil")?.u32()?);
        }
    }
    for r in args.list("pRects")? {
        let rect = r.get("rect")?;
        let (offset, extent) = (rect.get("offset")?, rect.get("extent")?);
        clear.rects.push((
            [
                offset.get("x")?.i64()?,
                offset.get("y")?.i64()?,
                extent.get("width")?.i64()?,
                extent.get("height")?.i64()?,
            ],
            r.get("baseArrayLayer")?.u32()?,
            r.get("layerCount")?.u32()?,
        ));
    }
    Ok(Cmd::ClearAttachments(Box::new(clear)))
}

pub(super) fn copy(kind: CopyKind, name: &str, args: &Arg<'_>) -> Got<Cmd> {
    let (src_key, dst_key) = kind.keys();
    let src = args.get(src_key)?.handle()?;
    let dst = args.get(dst_key)?.handle()?;
    let mut regions = Vec::new();
    for r in args.list("pRegions")? {
        let region = match kind {
            CopyKind::BufferToBuffer => Region {
                src_mip: 0,
                src_layer: 0,
                src_origin: [0; 3],
                src_offset: r.get("srcOffset")?.u64()?,
                dst_mip: 0,
                dst_layer: 0,
                dst_origin: [0; 3],
                dst_offset: r.get("dstOffset")?.u64()?,
                size: Some(r.get("size")?.u64()?),
                extent: None,
                row_texels: 0,
                image_rows: 0,
                layers: 1,
            },
            CopyKind::ImageToImage => {
                let (sm, sl) = subresource(&r.get("srcSubresource")?)?;
                let (dm, dl) = subresource(&r.get("dstSubresource")?)?;
                Region {
                    src_mip: sm,
                    src_layer: sl,
                    src_origin: offset3(&r.get("srcOffset")?)?,
                    src_offset: 0,
                    dst_mip: dm,
                    dst_layer: dl,
                    dst_origin: offset3(&r.get("dstOffset")?)?,
                    dst_offset: 0,
                    size: None,
                    extent: Some(extent3(&r.get("extent")?)?),
                    row_texels: 0,
                    image_rows: 0,
                    layers: layer_count(&r.get("dstSubresource")?),
                }
            }
            CopyKind::BufferToImage | CopyKind::ImageToBuffer => {
                let (m, l) = subresource(&r.get("imageSubresource")?)?;
                let origin = offset3(&r.get("imageOffset")?)?;
                let offset = r.get("bufferOffset")?.u64()?;
                let to_image = kind == CopyKind::BufferToImage;
                Region {
                    src_mip: if to_image { 0 } else { m },
                    src_layer: if to_image { 0 } else { l },
                    src_origin: if to_image { [0; 3] } else { origin },
                    src_offset: if to_image { offset } else { 0 },
                    dst_mip: if to_image { m } else { 0 },
                    dst_layer: if to_image { l } else { 0 },
                    dst_origin: if to_image { origin } else { [0; 3] },
                    dst_offset: if to_image { 0 } else { offset },
                    size: None,
                    extent: Some(extent3(&r.get("imageExtent")?)?),
                    row_texels: r.get("bufferRowLength")?.u32()?,
                    image_rows: r.opt("bufferImageHeight").map_or(Ok(0), |h| h.u32())?,
                    layers: layer_count(&r.get("imageSubresource")?),
                }
            }
        };
        regions.push(region);
    }
    let layout = |key: &str| {
        args.opt(key)
            .and_then(|l| ImageLayout::from_name(&l.symbol().ok()?))
    };
    Ok(Cmd::Transfer(Box::new(TransferCmd::Copy {
        name: copy_pass_name(name),
        src,
        dst,
        regions,
        layouts: (layout("srcImageLayout"), layout("dstImageLayout")),
    })))
}

/// One side of a blit region as recorded: mip, first layer, layer count, the corners' x and
/// y, and their z.
type BlitSide = (u32, u32, u32, [[u32; 2]; 2], [u32; 2]);

/// A blit with one region per layer; what a draw cannot reproduce (a cubic filter, a region
/// spanning 3D slices, unequal layer counts) is kept as the reason it is refused.
pub(super) fn blit(info: Arg<'_>) -> Got<Cmd> {
    let filter = info.get("filter")?.symbol()?;
    let mut refused = None;
    let linear = match filter.as_ref() {
        "VK_FILTER_NEAREST" => false,
        "VK_FILTER_LINEAR" => true,
        other => {
            refused = Some(format!(
                "vkCmdBlitImage with {other}: wgpu samples only nearest and linear"
            ));
            false
        }
    };
    let mut regions = Vec::new();
    for r in info.list("pRegions")? {
        let side = |sub: &str, offsets: &str| -> Got<BlitSide> {
            let s = r.get(sub)?;
            let (mip, layer) = subresource(&s)?;
            let corners = r.get(offsets)?.items()?;
            let [a, b] = corners.as_slice() else {
                return Err(Skip(format!(
                    "`{offsets}` holds {} offsets, not 2",
                    corners.len()
                )));
            };
            let (a, b) = (offset3(a)?, offset3(b)?);
            Ok((
                mip,
                layer,
                layer_count(&s),
                [[a[0], a[1]], [b[0], b[1]]],
                [a[2], b[2]],
            ))
        };
        let (sm, sl, sn, sc, sz) = side("srcSubresource", "srcOffsets")?;
        let (dm, dl, dn, dc, dz) = side("dstSubresource", "dstOffsets")?;
        if sn != dn {
            refused.get_or_insert(format!("vkCmdBlitImage of {sn} layers into {dn}"));
        }
        if [sz, dz]
            .iter()
            .any(|z| z[0].abs_diff(z[1]) != 1 || z[0].max(z[1]) != 1)
        {
            refused.get_or_insert(
                "vkCmdBlitImage between 3D regions: blits are drawn one 2D slice at a time"
                    .to_owned(),
            );
        }
        if sn.min(dn) > MAX_BLIT_LAYERS {
            return Err(Skip(format!(
                "a blit region of {sn} layers (over {MAX_BLIT_LAYERS})"
            )));
        }
        for k in 0..sn.min(dn) {
            regions.push(BlitRegionCmd {
                src: (sm, sl.saturating_add(k), sc),
                dst: (dm, dl.saturating_add(k), dc),
            });
        }
    }
    let layout = |key: &str| {
        info.opt(key)
            .and_then(|l| ImageLayout::from_name(&l.symbol().ok()?))
    };
    Ok(Cmd::Transfer(Box::new(TransferCmd::Blit {
        src: info.get("srcImage")?.handle()?,
        dst: info.get("dstImage")?.handle()?,
        regions,
        linear,
        layouts: (layout("srcImageLayout"), layout("dstImageLayout")),
        refused,
    })))
}

/// Layers one blit region may cover (each becomes a draw); an array texture has at most 2048
/// on any device framelab replays on.
const MAX_BLIT_LAYERS: u32 = 2048;

/// The pass a copy call becomes is named after it: `vkCmdCopyBufferToImage2KHR` ->
/// `copy_buffer_to_image`.
fn copy_pass_name(call: &str) -> String {
    let base = call
        .trim_start_matches("vkCmd")
        .trim_end_matches("KHR")
        .trim_end_matches('2');
    let mut out = String::new();
    for (i, c) in base.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}
