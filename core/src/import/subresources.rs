//! How calls name the parts of an image they touch: subresource ranges and layers, texel
//! offsets and extents, as the commands and barriers that the recording and the transfer calls
//! read give them.

use super::commands::LevelRange;
use super::value::{ASPECTS, Arg, Got};

/// A `VkImageSubresourceRange`: mip and layer ranges (`None` counts: to the last).
pub(super) fn range(r: &Arg<'_>) -> Got<(LevelRange, LevelRange)> {
    let count = |a: Arg<'_>| -> Got<Option<u32>> {
        let v = a.u64()?;
        Ok((v < u64::from(u32::MAX)).then_some(v as u32))
    };
    let _ = r.get("aspectMask")?.flags(ASPECTS)?;
    Ok((
        (r.get("baseMipLevel")?.u32()?, count(r.get("levelCount")?)?),
        (
            r.get("baseArrayLayer")?.u32()?,
            count(r.get("layerCount")?)?,
        ),
    ))
}

/// A `VkOffset3D`.
pub(super) fn offset3(a: &Arg<'_>) -> Got<[u32; 3]> {
    Ok([a.get("x")?.u32()?, a.get("y")?.u32()?, a.get("z")?.u32()?])
}

/// A `VkExtent3D`.
pub(super) fn extent3(a: &Arg<'_>) -> Got<[u32; 3]> {
    Ok([
        a.get("width")?.u32()?,
        a.get("height")?.u32()?,
        a.get("depth")?.u32()?,
    ])
}

/// A `VkImageSubresourceLayers`' mip level and first layer.
pub(super) fn subresource(a: &Arg<'_>) -> Got<(u32, u32)> {
    Ok((a.get("mipLevel")?.u32()?, a.get("baseArrayLayer")?.u32()?))
}

/// A `VkImageSubresourceLayers`' layer count (1 where it has none).
pub(super) fn layer_count(a: &Arg<'_>) -> u32 {
    a.opt("layerCount").and_then(|c| c.u32().ok()).unwrap_or(1)
}
