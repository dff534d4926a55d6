//! `framelab info`: a capture as resolved for one scale, as a stable, serialisable report
//! (every resource with its resolved size and heap, every pass with its queue and marker path,
//! descriptor heaps, and byte totals per heap type) and as readable tables.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::capture::format::BufferKind;
use crate::capture::format::{HeapType, ResourceFlag};
use crate::capture::model::{Capture, PlacementDesc, QueueCapabilities};
use crate::text::{human_bytes, table};

#[derive(Debug, Serialize)]
pub struct InfoReport {
    pub capture: String,
    pub scale: f64,
    pub width: u32,
    pub height: u32,
    pub queues: Vec<QueueInfo>,
    pub heaps: Vec<HeapInfo>,
    pub resources: Vec<ResourceInfo>,
    pub descriptor_heaps: Vec<DescriptorHeapInfo>,
    pub passes: Vec<PassInfo>,
    /// Per heap type (DEFAULT, UPLOAD, ...): resource count and bytes.
    pub totals: BTreeMap<String, Total>,
}

#[derive(Debug, Serialize)]
pub struct QueueInfo {
    pub name: String,
    #[serde(rename = "type")]
    pub queue_type: &'static str,
    pub capabilities: Vec<&'static str>,
}

#[derive(Debug, Serialize)]
pub struct HeapInfo {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: &'static str,
    pub size: u64,
    pub alignment: u64,
}

#[derive(Debug, Serialize)]
pub struct ResourceInfo {
    pub name: String,
    pub kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub format: Option<&'static str>,
    pub width: u32,
    pub height: u32,
    pub depth: u32,
    pub array_layers: u32,
    pub mip_levels: u32,
    pub samples: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub buffer_kind: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stride: Option<u32>,
    pub bytes: u64,
    /// The named heap for placed resources, `committed` or `reserved` otherwise.
    pub heap: String,
    pub heap_type: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<u64>,
    pub flags: Vec<&'static str>,
    pub history: bool,
    pub output: bool,
    pub swapchain: bool,
}

#[derive(Debug, Serialize)]
pub struct DescriptorHeapInfo {
    pub name: String,
    #[serde(rename = "type")]
    pub heap_type: &'static str,
    pub capacity: u32,
    pub shader_visible: bool,
}

#[derive(Debug, Serialize)]
pub struct PassInfo {
    pub name: String,
    pub queue: String,
    pub queue_type: &'static str,
    pub kind: &'static str,
    pub marker_path: String,
    pub draws: usize,
    pub dispatches: usize,
    pub copies: usize,
    /// Resources the pass reads / writes, in name order.
    pub reads: Vec<String>,
    pub writes: Vec<String>,
}

#[derive(Debug, Default, Serialize)]
pub struct Total {
    pub resources: usize,
    pub bytes: u64,
}

pub fn report(capture: &Capture) -> InfoReport {
    let queues = capture
        .queues
        .iter()
        .map(|q| QueueInfo {
            name: q.name.clone(),
            queue_type: q.queue_type.name(),
            capabilities: QueueCapabilities::of(q.queue_type).names(),
        })
        .collect();
    let heaps = capture
        .heaps
        .iter()
        .map(|h| HeapInfo {
            name: h.name.clone(),
            heap_type: h.heap_type.name(),
            size: h.size,
            alignment: h.alignment,
        })
        .collect();
    let mut totals: BTreeMap<String, Total> = BTreeMap::new();
    let resources = capture
        .resources
        .iter()
        .map(|r| {
            let heap_type: HeapType = r.heap_type(&capture.heaps);
            let (heap, offset) = match &r.placement {
                PlacementDesc::Committed { .. } => ("committed".to_owned(), None),
                PlacementDesc::Placed { heap, offset } => {
                    (capture.heaps[heap.index()].name.clone(), Some(*offset))
                }
                PlacementDesc::Reserved => ("reserved".to_owned(), None),
            };
            let total = totals.entry(heap_type.name().to_owned()).or_default();
            total.resources += 1;
            total.bytes += r.bytes;
            ResourceInfo {
                name: r.name.clone(),
                kind: r.kind.as_str(),
                format: r.format.map(|f| f.name),
                width: if r.is_texture() { r.width } else { 0 },
                height: if r.is_texture() { r.height } else { 0 },
                depth: r.depth,
                array_layers: r.array_layers,
                mip_levels: r.mip_levels,
                samples: r.samples,
                buffer_kind: r.buffer_kind.map(BufferKind::name),
                stride: r.stride,
                bytes: r.bytes,
                heap,
                heap_type: heap_type.name(),
                offset,
                flags: r.flags.iter().map(|f: &ResourceFlag| f.name()).collect(),
                history: r.history,
                output: r.output,
                swapchain: r.swapchain,
            }
        })
        .collect();
    let descriptor_heaps = capture
        .descriptor_heaps
        .iter()
        .map(|d| DescriptorHeapInfo {
            name: d.name.clone(),
            heap_type: match d.heap_type {
                crate::capture::format::DescriptorHeapType::CbvSrvUav => "CBV_SRV_UAV",
                crate::capture::format::DescriptorHeapType::Sampler => "SAMPLER",
                crate::capture::format::DescriptorHeapType::Rtv => "RTV",
                crate::capture::format::DescriptorHeapType::Dsv => "DSV",
            },
            capacity: d.capacity,
            shader_visible: d.shader_visible,
        })
        .collect();
    let passes = capture
        .passes
        .iter()
        .map(|p| {
            let names = |f: fn(&crate::capture::model::ResourceAccess) -> bool| {
                let mut v: Vec<String> = p
                    .accesses
                    .iter()
                    .filter(|a| f(a))
                    .map(|a| capture.resource(a.resource).name.clone())
                    .collect();
                v.sort();
                v.dedup();
                v
            };
            let queue = capture.queue(p.queue);
            PassInfo {
                name: p.name.clone(),
                queue: queue.name.clone(),
                queue_type: queue.queue_type.name(),
                kind: p.kind.as_str(),
                marker_path: p.marker_path(),
                draws: p.draws.len(),
                dispatches: p.dispatches.len(),
                copies: p.copies.len(),
                reads: names(|a| a.reads),
                writes: names(|a| a.writes),
            }
        })
        .collect();
    InfoReport {
        capture: capture.name.clone(),
        scale: capture.scale,
        width: capture.width,
        height: capture.height,
        queues,
        heaps,
        resources,
        descriptor_heaps,
        passes,
        totals,
    }
}

pub fn render_text(r: &InfoReport) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "capture {}  output {}x{} (scale {})\n",
        r.capture, r.width, r.height, r.scale
    );
    let queues: Vec<Vec<String>> = r
        .queues
        .iter()
        .map(|q| {
            vec![
                q.name.clone(),
                q.queue_type.to_owned(),
                q.capabilities.join(", "),
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Queues\n{}",
        table(&["name", "type", "can do"], &queues)
    );
    if !r.heaps.is_empty() {
        let heaps: Vec<Vec<String>> = r
            .heaps
            .iter()
            .map(|h| {
                vec![
                    h.name.clone(),
                    h.heap_type.to_owned(),
                    human_bytes(h.size),
                    h.alignment.to_string(),
                ]
            })
            .collect();
        let _ = writeln!(
            out,
            "Heaps\n{}",
            table(&["name", "type", "size", "alignment"], &heaps)
        );
    }
    let resources: Vec<Vec<String>> = r
        .resources
        .iter()
        .map(|x| {
            let size = if x.kind == "buffer" {
                format!("{} B", x.bytes)
            } else if x.kind == "texture_3d" {
                format!("{}x{}x{}", x.width, x.height, x.depth)
            } else {
                format!("{}x{}", x.width, x.height)
            };
            vec![
                x.name.clone(),
                x.kind.to_owned(),
                x.format.unwrap_or("-").to_owned(),
                size,
                x.array_layers.to_string(),
                x.mip_levels.to_string(),
                human_bytes(x.bytes),
                if x.heap == "committed" {
                    format!("committed {}", x.heap_type)
                } else {
                    x.heap.clone()
                },
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Resources ({})\n{}",
        r.resources.len(),
        table(
            &[
                "name", "kind", "format", "size", "layers", "mips", "bytes", "heap"
            ],
            &resources
        )
    );
    if !r.descriptor_heaps.is_empty() {
        let d: Vec<Vec<String>> = r
            .descriptor_heaps
            .iter()
            .map(|d| {
                vec![
                    d.name.clone(),
                    d.heap_type.to_owned(),
                    d.capacity.to_string(),
                    d.shader_visible.to_string(),
                ]
            })
            .collect();
        let _ = writeln!(
            out,
            "Descriptor heaps\n{}",
            table(&["name", "type", "capacity", "shader-visible"], &d)
        );
    }
    let passes: Vec<Vec<String>> = r
        .passes
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let work = match p.kind {
                "raster" => format!("{} draws", p.draws),
                "compute" => format!("{} dispatches", p.dispatches),
                "copy" => format!("{} copies", p.copies),
                _ => String::new(),
            };
            vec![
                (i + 1).to_string(),
                p.marker_path.clone(),
                p.queue.clone(),
                p.kind.to_owned(),
                work,
            ]
        })
        .collect();
    let _ = writeln!(
        out,
        "Passes ({})\n{}",
        r.passes.len(),
        table(&["#", "marker path", "queue", "kind", "work"], &passes)
    );
    let totals: Vec<Vec<String>> = r
        .totals
        .iter()
        .map(|(k, t)| vec![k.clone(), t.resources.to_string(), human_bytes(t.bytes)])
        .collect();
    let _ = write!(
        out,
        "Totals per heap type\n{}",
        table(&["heap type", "resources", "bytes"], &totals)
    );
    out
}
