//! The imported frame as a capture: the resources passes reference (formats through the DXGI
//! table's Vulkan column, usage as resource flags, memory bindings as placements), the memory
//! they are placed in as heaps, the queues, and the fences some pass waits on.

use std::collections::{BTreeMap, BTreeSet};

use super::build::Builder;
use super::state::{BufferInfo, ImageInfo, Objects};
use crate::capture::dxgi;
use crate::capture::format::{
    Access, AdapterModel, Api, Camera, CaptureSource, CpuPageProperty, Extent, FORMAT_VERSION,
    Fence, FrameConstants, Heap, HeapType, InitialContents, MemoryArchitecture, MemoryPool,
    MipLevels, Placement, Queue, RawCapture, Resolution, Resource, ResourceFlag, ResourceKind,
};

const DEVICE_LOCAL: u64 = 0x1;
const HOST_VISIBLE: u64 = 0x2;
const HOST_CACHED: u64 = 0x8;

/// UMA when every device-local memory type is also host-visible (integrated GPUs, lavapipe).
fn architecture(objects: &Objects) -> MemoryArchitecture {
    let local: Vec<u64> = objects
        .memory_type_flags
        .iter()
        .copied()
        .filter(|f| f & DEVICE_LOCAL != 0)
        .collect();
    if !local.is_empty() && local.iter().all(|f| f & HOST_VISIBLE != 0) {
        MemoryArchitecture::Uma
    } else {
        MemoryArchitecture::Numa
    }
}

/// The D3D12 heap a Vulkan memory type behaves as.
fn heap_kind(
    flags: Option<u64>,
    arch: MemoryArchitecture,
) -> (HeapType, CpuPageProperty, MemoryPool) {
    let Some(f) = flags else {
        return (
            HeapType::Default,
            CpuPageProperty::Unknown,
            MemoryPool::Unknown,
        );
    };
    if f & HOST_VISIBLE == 0 {
        return (
            HeapType::Default,
            CpuPageProperty::Unknown,
            MemoryPool::Unknown,
        );
    }
    let page = if f & HOST_CACHED != 0 {
        CpuPageProperty::WriteBack
    } else {
        CpuPageProperty::WriteCombine
    };
    if arch == MemoryArchitecture::Uma || f & DEVICE_LOCAL != 0 {
        // CPU-visible memory the GPU also uses at full speed: D3D12's custom L0 heap.
        return (HeapType::Custom, page, MemoryPool::L0);
    }
    if f & HOST_CACHED != 0 {
        (
            HeapType::Readback,
            CpuPageProperty::Unknown,
            MemoryPool::Unknown,
        )
    } else {
        (
            HeapType::Upload,
            CpuPageProperty::Unknown,
            MemoryPool::Unknown,
        )
    }
}

pub struct Emitted {
    pub capture: RawCapture,
    pub images: usize,
    pub buffers: usize,
    pub notes: Vec<String>,
}

/// An image as a texture resource: its kind from type, cube flag and layers, its usage as
/// flags.
fn image_resource(img: &ImageInfo, name: &str, before_capture: bool) -> Resource {
    let format = dxgi::lookup_vk(&img.format).map(|f| f.name.to_owned());
    let kind = match img.image_type.as_str() {
        "VK_IMAGE_TYPE_1D" | "0" => ResourceKind::Texture1D,
        "VK_IMAGE_TYPE_3D" | "2" => ResourceKind::Texture3D,
        _ if img.create_flags & 0x10 != 0 && img.layers.is_multiple_of(6) && img.layers > 0 => {
            ResourceKind::TextureCube
        }
        _ if img.layers > 1 => ResourceKind::Texture2DArray,
        _ => ResourceKind::Texture2D,
    };
    let mut flags = Vec::new();
    // Usage the image's own format cannot have is for views of another format
    // (`VK_IMAGE_CREATE_EXTENDED_USAGE_BIT`: zink gives its block-compressed textures attachment
    // and storage usage): no flag here, and a use through such a view, a reinterpretation of
    // the format, is judged by the lowering.
    let own = dxgi::lookup_vk(&img.format);
    let compressed = own.is_some_and(|f| f.is_block_compressed());
    let depth = own.is_some_and(|f| f.is_depth_format());
    // Nor for a format that cannot be rendered to (zink gives an E5B9G9R9 texture attachment
    // usage for its views of another format).
    let renders = own.is_some_and(|f| crate::capture::support::Support::of(f).render_target);
    if img.usage & 0x10 != 0 && !compressed && !depth && renders {
        flags.push(ResourceFlag::AllowRenderTarget);
    }
    let colour = own.is_some_and(|f| !f.is_depth_format());
    if img.usage & 0x20 != 0 && !colour {
        flags.push(ResourceFlag::AllowDepthStencil);
        if img.usage & (0x4 | 0x80) == 0 {
            flags.push(ResourceFlag::DenyShaderResource);
        }
    }
    if img.usage & 0x8 != 0 && !compressed && !depth {
        flags.push(ResourceFlag::AllowUnorderedAccess);
    }
    Resource {
        name: name.to_owned(),
        kind,
        format,
        width: Some(Extent::Texels(u64::from(img.extent[0]))),
        height: (kind != ResourceKind::Texture1D)
            .then_some(Extent::Texels(u64::from(img.extent[1]))),
        depth: (kind == ResourceKind::Texture3D).then_some(img.extent[2]),
        array_layers: (img.layers > 1 && kind != ResourceKind::Texture3D).then_some(img.layers),
        mip_levels: (img.mips > 1).then_some(MipLevels::Count(img.mips)),
        samples: (img.samples > 1).then_some(img.samples),
        size: None,
        stride: None,
        buffer_kind: None,
        flags,
        placement: None,
        initial: before_capture.then_some(InitialContents::BeforeCapture {}),
        history: false,
        output: false,
        swapchain: img.swapchain.is_some(),
    }
}

/// A buffer as a buffer resource; `written`: the frame copies into it.
fn buffer_resource(
    buf: &BufferInfo,
    name: &str,
    objects: &Objects,
    before_capture: bool,
    (copied_into, storage_written): (bool, bool),
) -> Resource {
    let mut flags = Vec::new();
    if buf.usage & (0x20 | 0x8) != 0 {
        flags.push(ResourceFlag::AllowUnorderedAccess);
    }
    let mapped = buf.bound.is_some_and(|(m, _)| objects.mapped.contains(&m));
    let host = buf
        .bound
        .and_then(|(m, _)| objects.memories.get(&m))
        .and_then(|m| objects.memory_type_flags.get(m.type_index as usize))
        .is_some_and(|f| f & HOST_VISIBLE != 0);
    Resource {
        flags,
        initial: (mapped || before_capture).then_some(InitialContents::BeforeCapture {}),
        // The CPU reads what the frame copies into host-visible memory, and what its shaders
        // write to memory the application maps (a compute program's results).
        output: host && (copied_into || (storage_written && mapped)),
        ..plain_buffer(name, buf.size)
    }
}

/// The buffer holding bytes the host wrote during the frame, read by its `host_write` pass:
/// `size` bytes at `offset` of the contents file `path`.
pub fn upload_buffer(name: &str, size: u64, (path, offset): (&str, u64)) -> Resource {
    Resource {
        flags: Vec::new(),
        initial: Some(InitialContents::File {
            path: path.to_owned(),
            offset: Some(offset),
        }),
        output: false,
        ..plain_buffer(name, size)
    }
}

/// A buffer resource with nothing but its name and size.
fn plain_buffer(name: &str, size: u64) -> Resource {
    Resource {
        name: name.to_owned(),
        kind: ResourceKind::Buffer,
        format: None,
        width: None,
        height: None,
        depth: None,
        array_layers: None,
        mip_levels: None,
        samples: None,
        size: Some(size),
        stride: None,
        buffer_kind: None,
        flags: Vec::new(),
        placement: None,
        initial: None,
        history: false,
        output: false,
        swapchain: false,
    }
}

/// Memory objects as heaps, gathered as resources are placed in them.
struct Heaps<'a> {
    objects: &'a Objects,
    arch: MemoryArchitecture,
    by_memory: BTreeMap<u64, Heap>,
    guessed_alignment: bool,
    /// Whether a memory's type was not among those the stream gave (noted once).
    unknown_types: bool,
    notes: Vec<String>,
}

impl Heaps<'_> {
    /// Places `r` where its memory binding puts it (committed when unbound).
    fn place(&mut self, r: &mut Resource, bound: Option<(u64, u64)>, alignment: Option<u64>) {
        let Some((memory, offset)) = bound else {
            return;
        };
        let objects = self.objects;
        let Some(mem) = objects.memories.get(&memory) else {
            self.notes.push(format!(
                "\"{}\" is bound to memory {memory} the stream never allocated: treated as committed",
                r.name
            ));
            return;
        };
        let flags = objects
            .memory_type_flags
            .get(mem.type_index as usize)
            .copied();
        if flags.is_none() && !self.unknown_types {
            // A trimmed capture's JSON Lines stream holds no vkGetPhysicalDeviceMemoryProperties.
            self.unknown_types = true;
            self.notes.push(
                "memory types the stream does not give (no memory properties in it): its memory taken as DEFAULT heaps".to_owned(),
            );
        }
        let (heap_type, page, pool) = heap_kind(flags, self.arch);
        // Vulkan gives each placement's alignment in its memory requirements; without them
        // the offset itself is the best evidence.
        let alignment = alignment.or_else(|| {
            (offset % 65536 != 0).then(|| {
                self.guessed_alignment = true;
                1u64 << offset.trailing_zeros()
            })
        });
        let heap_name = objects
            .names
            .get(&memory)
            .cloned()
            .unwrap_or_else(|| format!("memory_{memory}"));
        let heap = self.by_memory.entry(memory).or_insert_with(|| Heap {
            name: heap_name,
            heap_type,
            cpu_page_property: page,
            memory_pool: pool,
            size: mem.size,
            alignment: 65536,
            flags: Vec::new(),
        });
        if alignment.is_some_and(|a| a > 65536) {
            heap.alignment = 4 << 20;
        }
        r.placement = Some(Placement::Placed {
            heap: heap.name.clone(),
            offset,
            alignment,
        });
    }
}

/// The resources passes reference, in name order, with their heaps.
struct Made {
    resources: Vec<Resource>,
    heaps: Vec<Heap>,
    images: usize,
    buffers: usize,
    /// The swapchain's extent, else the largest image's: the capture's resolution.
    resolution: (u32, u32),
    notes: Vec<String>,
}

fn resources(b: &Builder, objects: &Objects, hidden_blocks: bool) -> Made {
    let first_submit = b.first_submit.unwrap_or(u64::MAX);
    let selected_later = b.selection.is_some_and(|(a, _)| a > 0);
    // Contents from before the imported frames: earlier frames, or a snapshot not in the JSON.
    let before = |created_at: u64| created_at < first_submit && (hidden_blocks || selected_later);
    let mut heaps = Heaps {
        objects,
        arch: architecture(objects),
        by_memory: BTreeMap::new(),
        guessed_alignment: false,
        unknown_types: false,
        notes: Vec::new(),
    };
    let mut resources = Vec::new();
    let (mut images, mut buffers) = (0, 0);
    let written: BTreeSet<&str> = b
        .passes
        .iter()
        .flat_map(|p| {
            p.copies
                .iter()
                .filter(|c| !c.host)
                .map(|c| c.dst.resource.as_str())
        })
        .collect();
    let storage_written: BTreeSet<&str> = b
        .passes
        .iter()
        .flat_map(|p| p.bindings.values())
        .filter(|b| {
            matches!(
                b.access,
                Some(Access::StorageWrite | Access::StorageReadWrite)
            )
        })
        .filter_map(|b| b.resource.as_deref())
        .collect();
    let mut largest = (0u32, 0u32);
    let mut swapchain_extent = None;
    // Work before the frames names what it touches; what was destroyed before them is not
    // part of them.
    let gone = |destroyed: Option<u64>| {
        destroyed.is_some_and(|d| b.first_submit.is_some_and(|first| d < first))
    };
    for (&handle, rname) in &b.names {
        if objects
            .images
            .get(&handle)
            .is_some_and(|i| gone(i.destroyed_at))
            || objects
                .buffers
                .get(&handle)
                .is_some_and(|x| gone(x.destroyed_at))
        {
            continue;
        }
        let (mut r, bound, alignment) = if let Some(img) = objects.images.get(&handle) {
            images += 1;
            if img.swapchain.is_some() {
                swapchain_extent.get_or_insert((img.extent[0], img.extent[1]));
            }
            if u64::from(img.extent[0]) * u64::from(img.extent[1])
                > u64::from(largest.0) * u64::from(largest.1)
            {
                largest = (img.extent[0], img.extent[1]);
            }
            let r = image_resource(img, rname, before(img.created_at));
            (r, img.bound, img.alignment)
        } else if let Some(buf) = objects.buffers.get(&handle) {
            buffers += 1;
            let written = (
                written.contains(rname.as_str()),
                storage_written.contains(rname.as_str()),
            );
            let r = buffer_resource(buf, rname, objects, before(buf.created_at), written);
            (r, buf.bound, buf.alignment)
        } else {
            continue;
        };
        heaps.place(&mut r, bound, alignment);
        resources.push(r);
    }
    if heaps.guessed_alignment {
        heaps.notes.push("placements whose memory requirements the stream does not give: aligned to the largest power of two dividing their offset".to_owned());
    }
    Made {
        resources,
        heaps: heaps.by_memory.into_values().collect(),
        images,
        buffers,
        resolution: swapchain_extent.unwrap_or(largest),
        notes: heaps.notes,
    }
}

/// `hidden_blocks`: the stream left blocks out before the first imported submission (state
/// snapshot, memory fills), so what existed then may hold data the JSON does not show.
pub fn emit(
    mut b: Builder,
    objects: &Objects,
    name: &str,
    file: &str,
    tool: &str,
    hidden_blocks: bool,
) -> Emitted {
    let made = resources(&b, objects, hidden_blocks);
    // Fences nobody waits on order nothing.
    let waited = std::mem::take(&mut b.waited);
    for p in &mut b.passes {
        p.signal.retain(|f| waited.contains(f));
    }
    let fences: Vec<Fence> = b
        .fences
        .iter()
        .filter(|f| waited.contains(*f))
        .map(|f| Fence { name: f.clone() })
        .collect();
    let mut queues: Vec<Queue> = b
        .queue_names
        .values()
        .map(|(n, t)| Queue {
            name: n.clone(),
            queue_type: *t,
        })
        .collect();
    queues.sort_by(|a, c| a.name.cmp(&c.name));
    let (width, height) = made.resolution;
    let capture = RawCapture {
        format_version: FORMAT_VERSION,
        name: name.to_owned(),
        description: Some(format!(
            "Imported by framelab import from {file} ({tool}); {} frame(s), {} passes",
            b.frames_seen.max(1),
            b.passes.len()
        )),
        resolution: Resolution { width: width.max(1), height: height.max(1) },
        adapter: AdapterModel { architecture: architecture(objects), resource_heap_tier: 2 },
        camera: Camera {
            position: [0.0, 0.0, 1.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_degrees: 60.0,
            near: 0.1,
            far: 1000.0,
            velocity: [0.0; 3],
            jitter_phases: 0,
        },
        frame: FrameConstants::default(),
        heaps: made.heaps,
        resources: made.resources,
        descriptor_heaps: Vec::new(),
        samplers: Vec::new(),
        queues,
        fences,
        meshes: Vec::new(),
        passes: b.passes,
        vulkan: None,
        source: Some(CaptureSource {
            tool: tool.to_owned(),
            api: Api::Vulkan,
            file: file.to_owned(),
            not_replayable: Some(
                "GFXReconstruct's JSON holds no shader code (only each module's size and a pointer), so the passes have nothing to run".to_owned(),
            ),
            sync_hazards: None,
            valid_usage: None,
        }),
    };
    Emitted {
        capture,
        images: made.images,
        buffers: made.buffers,
        notes: made.notes,
    }
}

/// Gives each resource the flags the frame's use of it implies where its creation did not:
/// a Vulkan image used as a colour or depth attachment, or bound for storage, without that
/// usage (a valid-usage error, reported with its VUID, that drivers run anyway). The capture
/// describes what the frame does, so it still validates and replays.
pub fn flags_from_use(capture: &mut RawCapture) {
    let mut needs: BTreeMap<&str, BTreeSet<ResourceFlag>> = BTreeMap::new();
    let mut sampled: BTreeSet<&str> = BTreeSet::new();
    let textures: BTreeSet<&str> = capture
        .resources
        .iter()
        .filter(|r| r.kind.is_texture())
        .map(|r| r.name.as_str())
        .collect();
    for p in &capture.passes {
        for a in &p.color_attachments {
            needs
                .entry(&a.resource)
                .or_default()
                .insert(ResourceFlag::AllowRenderTarget);
        }
        if let Some(d) = &p.depth_stencil {
            needs
                .entry(&d.resource)
                .or_default()
                .insert(ResourceFlag::AllowDepthStencil);
        }
        for b in p.bindings.values() {
            let (Some(r), Some(access)) = (b.resource.as_deref(), b.access) else {
                continue;
            };
            if access.is_unordered(textures.contains(r)) {
                needs
                    .entry(r)
                    .or_default()
                    .insert(ResourceFlag::AllowUnorderedAccess);
            } else if access == Access::Sampled {
                sampled.insert(r);
            }
        }
    }
    let needs: BTreeMap<String, BTreeSet<ResourceFlag>> =
        needs.into_iter().map(|(k, v)| (k.to_owned(), v)).collect();
    let sampled: BTreeSet<String> = sampled.into_iter().map(str::to_owned).collect();
    for r in &mut capture.resources {
        for &flag in needs.get(&r.name).into_iter().flatten() {
            if !r.flags.contains(&flag) {
                r.flags.push(flag);
            }
        }
        if sampled.contains(&r.name) {
            r.flags.retain(|f| *f != ResourceFlag::DenyShaderResource);
        }
    }
}
