//! What the MCP tools compute from an opened capture, apart from the protocol: pages of rows,
//! one pass's details, the checks of a texture or buffer request before any replay, the
//! summary of what a replay read, and the rows a buffer's bytes hold.

use framelab_core::capture::model::ResourceDesc;
use rmcp::Peer;
use rmcp::service::RoleServer;
use serde_json::{Value, json};

use super::args::{DEFAULT_ROWS, ListArgs, MAX_ROWS};
use super::store::{Opened, unknown};

/// `rows` filtered by name and paginated, with the total that matched.
pub fn page<T: serde::Serialize>(
    rows: &[T],
    name: impl Fn(&T) -> &str,
    a: &ListArgs,
) -> anyhow::Result<Value> {
    let limit = a.limit.unwrap_or(DEFAULT_ROWS);
    if limit > MAX_ROWS {
        return Err(anyhow::anyhow!(
            "limit {limit} is over the {MAX_ROWS} rows one call returns; page with offset"
        ));
    }
    let matching: Vec<&T> = rows
        .iter()
        .filter(|r| a.filter.as_deref().is_none_or(|f| name(r).contains(f)))
        .collect();
    let offset = a.offset.unwrap_or(0);
    let shown: Vec<&T> = matching.iter().skip(offset).take(limit).copied().collect();
    Ok(json!({
        "total": matching.len(),
        "offset": offset,
        "rows": shown,
    }))
}

pub fn pass_details(o: &Opened, pass: &str) -> anyhow::Result<Value> {
    let Some(info) = o.info.passes.iter().find(|p| p.name == pass) else {
        return Err(unknown(
            "pass",
            pass,
            o.info.passes.iter().map(|p| p.name.as_str()),
            "list_passes names them",
        ));
    };
    let r = &o.report;
    let position = r.order.iter().position(|p| p == pass);
    let barriers: Vec<_> = r.barriers.iter().filter(|b| b.pass == pass).collect();
    let lints: Vec<_> = r
        .lints
        .iter()
        .filter(|l| l.pass.as_deref() == Some(pass))
        .collect();
    let before: Vec<_> = o.graph.edges.iter().filter(|e| e.to == pass).collect();
    let after: Vec<_> = o.graph.edges.iter().filter(|e| e.from == pass).collect();
    Ok(json!({
        "pass": info,
        "position": position,
        "culled": r.culled.iter().any(|c| c == pass),
        "recorded": o.recorded.get(pass),
        "derived_barriers": barriers,
        "lints": lints,
        "dag": {"before": before, "after": after},
    }))
}

/// A texture subresource as it stood after a pass.
pub struct Target<'a> {
    pub capture: &'a str,
    pub resource: &'a str,
    pub after_pass: Option<&'a str>,
    /// (mip, layer, slice)
    pub sub: (u32, u32, u32),
}

/// The texture request checked against the capture before any replay: the resource is a
/// texture, the pass exists, the subresource is in range; and what the summary says before
/// the pixels: the format and whether a pass up to `after_pass` writes it.
pub fn texture_checks(o: &Opened, a: &Target<'_>) -> anyhow::Result<Value> {
    let (mip, layer, slice) = a.sub;
    let r = find_resource(o, a.resource)?;
    if r.format.is_none() {
        return Err(anyhow::anyhow!("\"{}\" is a buffer, not a texture", r.name));
    }
    let order = &o.report.order;
    let upto = passes_through(o, a.after_pass)?;
    if mip >= r.mip_levels {
        return Err(anyhow::anyhow!(
            "mip {mip}: \"{}\" has {} mip level(s)",
            r.name,
            r.mip_levels
        ));
    }
    if layer >= r.array_layers {
        return Err(anyhow::anyhow!(
            "layer {layer}: \"{}\" has {} layer(s)",
            r.name,
            r.array_layers
        ));
    }
    let depth = (r.depth >> mip).max(1);
    if slice >= depth {
        return Err(anyhow::anyhow!(
            "slice {slice}: mip {mip} of \"{}\" has {depth} slice(s)",
            r.name
        ));
    }
    let written = order[..upto].iter().any(|p| {
        o.info
            .passes
            .iter()
            .any(|row| &row.name == p && row.writes.contains(&r.name))
    });
    Ok(json!({
        "resource": r.name,
        "format": r.format.map(|f| f.name),
        "after_pass": a.after_pass,
        "mip": mip,
        "layer": layer,
        "slice": slice,
        "written_this_frame": written,
    }))
}

/// A progress callback for the replay, when the client asked for progress.
pub fn progress_sender(
    peer: &Peer<RoleServer>,
    meta: &rmcp::model::RequestMetaObject,
) -> Box<dyn Fn(usize, usize) + Send> {
    let token = meta
        .get("progressToken")
        .cloned()
        .and_then(|t| serde_json::from_value::<rmcp::model::NumberOrString>(t).ok());
    let (Some(token), Ok(runtime)) = (token, tokio::runtime::Handle::try_current()) else {
        return Box::new(|_, _| {});
    };
    let peer = peer.clone();
    Box::new(move |done, total| {
        let peer = peer.clone();
        let param = rmcp::model::ProgressNotificationParam::new(
            rmcp::model::ProgressToken(token.clone()),
            done as f64,
        )
        .with_total(total as f64)
        .with_message(format!("pass {done} of {total}"));
        // The replay workers call this from threads of their own, outside the runtime:
        // there the notification is sent before the call returns, so that every one reaches
        // the client before the tool's answer, which the worker sends after its last. Inside
        // the runtime's context it is only queued.
        if tokio::runtime::Handle::try_current().is_err() {
            let _ = runtime.block_on(peer.notify_progress(param));
        } else {
            runtime.spawn(async move {
                let _ = peer.notify_progress(param).await;
            });
        }
    })
}

/// Per-channel minimum, maximum and mean of the finite values.
pub fn channel_stats(
    image: &framelab_replay::decode::DecodedImage,
) -> (Vec<f32>, Vec<f32>, Vec<f64>) {
    let n = image.channels.clamp(1, 4);
    let mut min = vec![f32::INFINITY; n];
    let mut max = vec![f32::NEG_INFINITY; n];
    let mut sum = vec![0f64; n];
    let mut count = vec![0u64; n];
    for v in &image.values {
        for c in 0..n {
            if v[c].is_finite() {
                min[c] = min[c].min(v[c]);
                max[c] = max[c].max(v[c]);
                sum[c] += f64::from(v[c]);
                count[c] += 1;
            }
        }
    }
    let mean = sum
        .iter()
        .zip(&count)
        .map(|(s, &k)| if k == 0 { 0.0 } else { s / k as f64 })
        .collect();
    (min, max, mean)
}

/// `img` scaled down (triangle filter) so that its longest side is at most `side`.
pub fn fit(img: image::RgbaImage, side: u32) -> image::RgbaImage {
    let longest = img.width().max(img.height());
    if longest <= side {
        return img;
    }
    let scale = f64::from(side) / f64::from(longest);
    let w = ((f64::from(img.width()) * scale).round() as u32).max(1);
    let h = ((f64::from(img.height()) * scale).round() as u32).max(1);
    image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle)
}

/// The capture's resource `name`, or an error with the closest names.
pub fn find_resource<'o>(o: &'o Opened, name: &str) -> anyhow::Result<&'o ResourceDesc> {
    let resources = &o.analysed.capture.resources;
    resources.iter().find(|r| r.name == name).ok_or_else(|| {
        unknown(
            "resource",
            name,
            resources.iter().map(|r| r.name.as_str()),
            "list_resources names them",
        )
    })
}

/// How many passes of the order run up to and including `after` (all of them for `None`), or
/// an error with the closest pass names.
pub fn passes_through(o: &Opened, after: Option<&str>) -> anyhow::Result<usize> {
    let order = &o.report.order;
    let Some(p) = after else {
        return Ok(order.len());
    };
    order
        .iter()
        .position(|x| x == p)
        .map(|i| i + 1)
        .ok_or_else(|| {
            unknown(
                "pass",
                p,
                order.iter().map(String::as_str),
                "list_passes names them",
            )
        })
}

/// The rows of `choice`'s layout that lie wholly in `bytes` (read from byte `offset`), each
/// field decoded as the inspector's buffer table decodes it; at most 256 rows.
pub fn decode_rows(
    choice: &framelab_core::buffer_views::LayoutChoice,
    offset: u64,
    bytes: &[u8],
) -> Value {
    let l = &choice.layout;
    let stride = l.stride.max(1);
    let end = offset + bytes.len() as u64;
    let first = offset.saturating_sub(choice.base).div_ceil(stride);
    let rows: Vec<Value> = (first..)
        .map(|i| (i, choice.base + i * stride))
        .take_while(|&(_, at)| at + stride <= end)
        .take(256)
        .map(|(i, at)| {
            let row = &bytes[(at - offset) as usize..];
            let fields: serde_json::Map<String, Value> = l
                .fields
                .iter()
                .map(|f| (f.name.clone(), json!(f.read(row))))
                .collect();
            json!({"index": i, "offset": at, "fields": fields})
        })
        .collect();
    json!({
        "type": l.type_name,
        "source": choice.source,
        "stride": l.stride,
        "rows": rows,
    })
}
