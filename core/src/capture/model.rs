//! The validated capture: typed ids instead of names, sizes resolved for one output scale,
//! formats looked up in the DXGI table, side files resolved to paths inside the capture's
//! folder, and every pass's resource accesses gathered into one list.
//!
//! Only `validate` builds a `Capture`, so code downstream (graph, analyses, lowering) can rely on
//! every id being in range and every rule of the format holding.

use super::generators::{Content, Seeded, Shape};
use std::collections::BTreeSet;
use std::path::PathBuf;

use serde::Serialize;

use super::format::{
    Access, AdapterModel, BarrierType, Blend, BufferKind, Camera, FrameConstants, HeapFlag,
    HeapType, IndexFormat, LoadOp, ParamValue, PassKind, QueueType, RenderState, ResourceFlag,
    ResourceKind, ResourceState, SplitFlag, StoreOp, VertexStream,
};
use crate::capture::dxgi::FormatInfo;
use crate::capture::vulkan::{AccessFlags, ImageLayout, PipelineStages};

pub use super::ids::*;

/// A validated capture, resolved for one output scale.
#[derive(Clone, Debug)]
pub struct Capture {
    pub name: String,
    pub description: Option<String>,
    /// The capture file, and the folder side files are resolved against.
    pub source: PathBuf,
    pub base_dir: PathBuf,
    /// The `--scale` the sizes were resolved for.
    pub scale: f64,
    /// Output resolution after scaling.
    pub width: u32,
    pub height: u32,
    pub adapter: AdapterModel,
    pub camera: Camera,
    pub frame: FrameConstants,
    pub heaps: Vec<HeapDesc>,
    pub resources: Vec<ResourceDesc>,
    pub descriptor_heaps: Vec<DescriptorHeapDesc>,
    pub samplers: Vec<super::format::Sampler>,
    pub queues: Vec<QueueDesc>,
    pub fences: Vec<String>,
    pub meshes: Vec<MeshDesc>,
    pub passes: Vec<PassDesc>,
    /// Every shader file the passes name, read and reflected once.
    pub shaders: Vec<super::shaders::Shader>,
    /// The tool and stream an imported capture came from.
    pub origin: Option<super::format::CaptureSource>,
    /// An imported frame's Vulkan objects, by index.
    pub vulkan: Option<super::vk_model::VkModel>,
}

impl Capture {
    /// Each declared wait as (the pass signalling the fence, the pass waiting on it), waiting
    /// passes in recorded order; validation lets a fence be signalled once a frame (the first
    /// signaller is taken otherwise).
    pub fn fence_edges(&self) -> Vec<(PassId, PassId)> {
        let mut signaller: std::collections::BTreeMap<FenceId, PassId> = Default::default();
        for p in &self.passes {
            for &f in &p.signal {
                signaller.entry(f).or_insert(p.id);
            }
        }
        self.passes
            .iter()
            .flat_map(|w| w.wait.iter().map(move |f| (f, w.id)))
            .filter_map(|(f, w)| Some((*signaller.get(f)?, w)))
            .collect()
    }

    /// Imported from a Vulkan program (see `CaptureSource::is_vulkan`).
    pub fn from_vulkan_program(&self) -> bool {
        self.origin
            .as_ref()
            .is_some_and(super::format::CaptureSource::is_vulkan)
    }

    /// Why this capture cannot be replayed, as a message naming its origin; `None` when it can.
    pub fn not_replayable(&self) -> Option<String> {
        let origin = self.origin.as_ref()?;
        let reason = origin.not_replayable.as_ref()?;
        // Only a JSON Lines stream lacks what its binary capture has.
        let advice = if origin.file.ends_with(".jsonl") || origin.file.ends_with(".json") {
            "; importing the binary capture (.gfxr) instead brings what replay needs"
        } else {
            ""
        };
        Some(format!(
            "\"{}\" was imported from {}, captured by {}: {reason}. It can be validated, analysed, inspected as a graph and compared with `diff --structure`, but not replayed or timed{advice}",
            self.source.display(),
            origin.file,
            origin.tool
        ))
    }
    pub fn resource(&self, id: ResourceId) -> &ResourceDesc {
        &self.resources[id.index()]
    }
    pub fn pass(&self, id: PassId) -> &PassDesc {
        &self.passes[id.index()]
    }
    pub fn shader(&self, id: super::shaders::ShaderId) -> &super::shaders::Shader {
        &self.shaders[id.index()]
    }
    pub fn queue(&self, id: QueueId) -> &QueueDesc {
        &self.queues[id.index()]
    }
}

#[derive(Clone, Debug)]
pub struct HeapDesc {
    pub id: HeapId,
    pub name: String,
    pub heap_type: HeapType,
    pub size: u64,
    pub alignment: u64,
    pub flags: BTreeSet<HeapFlag>,
    pub allows: HeapAllows,
}

/// Which resource categories a heap may hold, after expanding flag aliases.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct HeapAllows {
    pub buffers: bool,
    pub rt_ds_textures: bool,
    pub other_textures: bool,
}

/// The three categories of D3D12's resource heap tier 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ResourceCategory {
    Buffer,
    RtDsTexture,
    OtherTexture,
}

impl ResourceCategory {
    pub fn describe(self) -> &'static str {
        match self {
            ResourceCategory::Buffer => "buffers",
            ResourceCategory::RtDsTexture => "render-target/depth-stencil textures",
            ResourceCategory::OtherTexture => "non-RT/DS textures",
        }
    }
}

impl HeapAllows {
    pub fn allows(self, category: ResourceCategory) -> bool {
        match category {
            ResourceCategory::Buffer => self.buffers,
            ResourceCategory::RtDsTexture => self.rt_ds_textures,
            ResourceCategory::OtherTexture => self.other_textures,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ResourceDesc {
    pub id: ResourceId,
    pub name: String,
    pub kind: ResourceKind,
    /// Texture format, or a typed buffer's element format.
    pub format: Option<&'static FormatInfo>,
    pub width: u32,
    pub height: u32,
    /// Depth of a 3D texture (1 otherwise).
    pub depth: u32,
    /// Array layers, cube faces included (1 for 3D textures and buffers).
    pub array_layers: u32,
    pub mip_levels: u32,
    pub samples: u32,
    /// Buffer properties.
    pub buffer_kind: Option<BufferKind>,
    pub stride: Option<u32>,
    /// Bytes of all subresources (texture) or the buffer size.
    pub bytes: u64,
    /// Bytes the resource occupies in a heap: `bytes` rounded up to its placement alignment.
    pub aligned_bytes: u64,
    /// Required placement alignment (64 KiB, or 4 MiB for MSAA textures).
    pub alignment: u64,
    pub flags: BTreeSet<ResourceFlag>,
    pub placement: PlacementDesc,
    pub initial: InitialDesc,
    pub history: bool,
    pub output: bool,
    /// A swapchain's image, which the frame may leave idle.
    pub swapchain: bool,
}

impl ResourceDesc {
    pub fn is_texture(&self) -> bool {
        self.kind.is_texture()
    }
    pub fn has_flag(&self, flag: ResourceFlag) -> bool {
        self.flags.contains(&flag)
    }
    pub fn category(&self) -> ResourceCategory {
        if !self.is_texture() {
            ResourceCategory::Buffer
        } else if self.has_flag(ResourceFlag::AllowRenderTarget)
            || self.has_flag(ResourceFlag::AllowDepthStencil)
        {
            ResourceCategory::RtDsTexture
        } else {
            ResourceCategory::OtherTexture
        }
    }
    /// The heap type the memory lives in.
    pub fn heap_type(&self, heaps: &[HeapDesc]) -> HeapType {
        match &self.placement {
            PlacementDesc::Committed { heap_type } => *heap_type,
            PlacementDesc::Placed { heap, .. } => heaps[heap.index()].heap_type,
            PlacementDesc::Reserved => HeapType::Default,
        }
    }
    /// Mip dimensions (width, height, depth) of level `mip`.
    pub fn mip_extent(&self, mip: u32) -> (u32, u32, u32) {
        let shrink = |v: u32| (v >> mip).max(1);
        let depth = if self.kind == ResourceKind::Texture3D {
            shrink(self.depth)
        } else {
            1
        };
        (shrink(self.width), shrink(self.height), depth)
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlacementDesc {
    Committed { heap_type: HeapType },
    Placed { heap: HeapId, offset: u64 },
    Reserved,
}

#[derive(Clone, Debug, PartialEq)]
pub enum InitialDesc {
    Undefined,
    /// Contents from before the captured frames (imported captures); not in the capture.
    BeforeCapture,
    /// The resource's bytes in a file, from `offset` (the whole file where `None`).
    File(PathBuf, Option<u64>),
    Generator(Seeded<Content>),
}

#[derive(Clone, Debug)]
pub struct DescriptorHeapDesc {
    pub id: DescriptorHeapId,
    pub name: String,
    pub heap_type: super::format::DescriptorHeapType,
    pub capacity: u32,
    pub shader_visible: bool,
}

#[derive(Clone, Debug)]
pub struct QueueDesc {
    pub id: QueueId,
    pub name: String,
    pub queue_type: QueueType,
}

/// What a queue type can execute, from Vulkan's pipeline-stage/queue-capability table:
/// graphics stages need a graphics queue, compute shaders a compute (or graphics) queue, and
/// transfers run anywhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct QueueCapabilities {
    pub graphics: bool,
    pub compute: bool,
    pub transfer: bool,
}

impl QueueCapabilities {
    pub fn of(queue_type: QueueType) -> Self {
        match queue_type {
            QueueType::Graphics => Self {
                graphics: true,
                compute: true,
                transfer: true,
            },
            QueueType::Compute => Self {
                graphics: false,
                compute: true,
                transfer: true,
            },
            QueueType::Copy => Self {
                graphics: false,
                compute: false,
                transfer: true,
            },
        }
    }
    pub fn names(self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.graphics {
            v.push("graphics");
        }
        if self.compute {
            v.push("compute");
        }
        if self.transfer {
            v.push("transfer");
        }
        v
    }
}

#[derive(Clone, Debug)]
pub struct MeshDesc {
    pub id: MeshId,
    pub name: String,
    pub source: MeshSourceDesc,
    pub streams: Vec<VertexStream>,
    pub index_format: Option<IndexFormat>,
    pub vertex_count: Option<u32>,
    pub index_count: Option<u32>,
    pub instance_count: Option<u32>,
    /// Generator of the per-instance rows: name, seed, parameters.
    pub instances: Option<Seeded<Content>>,
}

impl MeshDesc {
    /// Its vertex count and (for an indexed mesh) index count: as a file mesh states them,
    /// or as its generator builds them.
    pub fn elements(&self) -> (Option<u64>, Option<u64>) {
        let (vertices, indices) = match &self.source {
            MeshSourceDesc::Generator(g) => {
                let (v, i) = g.generator.counts();
                (Some(v), Some(i))
            }
            MeshSourceDesc::File(_) => (
                self.vertex_count.map(u64::from),
                self.index_count.map(u64::from),
            ),
        };
        (vertices, indices.filter(|_| self.index_format.is_some()))
    }

    /// The elements a draw of it reads: its indices when indexed, else its vertices.
    pub fn drawn_elements(&self) -> Option<u64> {
        match self.elements() {
            (_, Some(i)) => Some(i),
            (v, None) if self.index_format.is_none() => v,
            _ => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum MeshSourceDesc {
    File(PathBuf),
    Generator(Seeded<Shape>),
}

/// A subresource range: mips `[mip_base, mip_base + mip_count)` of layers
/// `[layer_base, layer_base + layer_count)`, or a byte range of a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Subresources {
    pub mip_base: u32,
    pub mip_count: u32,
    pub layer_base: u32,
    pub layer_count: u32,
    /// Buffers: byte offset and size.
    pub byte_offset: u64,
    pub byte_size: u64,
}

impl Subresources {
    /// `mips 0..1 layers 0..6` for a texture's range, `bytes 0+256` (offset and size) for a
    /// buffer's, as a pass's details list it.
    pub fn describe(&self, texture: bool) -> String {
        if texture {
            format!(
                "mips {}..{} layers {}..{}",
                self.mip_base,
                self.mip_base + self.mip_count,
                self.layer_base,
                self.layer_base + self.layer_count
            )
        } else {
            format!("bytes {}+{}", self.byte_offset, self.byte_size)
        }
    }

    pub fn whole(resource: &ResourceDesc) -> Self {
        Self {
            mip_base: 0,
            mip_count: if resource.is_texture() {
                resource.mip_levels
            } else {
                1
            },
            layer_base: 0,
            layer_count: if resource.is_texture() {
                resource.array_layers
            } else {
                1
            },
            byte_offset: 0,
            byte_size: if resource.is_texture() {
                0
            } else {
                resource.bytes
            },
        }
    }
    pub fn overlaps(&self, other: &Self) -> bool {
        let mips = self.mip_base < other.mip_base + other.mip_count
            && other.mip_base < self.mip_base + self.mip_count;
        let layers = self.layer_base < other.layer_base + other.layer_count
            && other.layer_base < self.layer_base + self.layer_count;
        let bytes = (self.byte_size == 0 && other.byte_size == 0)
            || self.byte_offset < other.byte_offset + other.byte_size
                && other.byte_offset < self.byte_offset + self.byte_size;
        mips && layers && bytes
    }
}

/// Where in the pass an access comes from, for messages and for the replay lowering.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AccessSource {
    Binding(String),
    ColorAttachment(usize),
    DepthStencil,
    DrawMesh(usize),
    Indirect(usize),
    Copy(usize),
    Blit(usize),
    Clear(usize),
    Resolve,
    GenerateMips,
    Present,
}

/// One declared use of a resource by a pass.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ResourceAccess {
    pub resource: ResourceId,
    pub access: Access,
    pub range: Subresources,
    /// A read that sees the previous contents (a `load`ed attachment, a read-modify-write).
    pub reads: bool,
    pub writes: bool,
    pub source: AccessSource,
}

#[derive(Clone, Debug)]
pub struct ShaderDesc {
    /// The file, read and reflected at validation (`Capture::shader`).
    pub id: super::shaders::ShaderId,
    pub vertex: Option<String>,
    pub fragment: Option<String>,
    pub compute: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum BindingTarget {
    Resource {
        resource: ResourceId,
        view_format: Option<&'static FormatInfo>,
        view_kind: ResourceKind,
    },
    Sampler(SamplerId),
}

#[derive(Clone, Debug, PartialEq)]
pub struct BindingDesc {
    pub variable: String,
    pub target: BindingTarget,
    pub access: Option<Access>,
    pub range: Option<Subresources>,
    /// Reads the previous frame's copy of a `history` resource: a read-only binding of one
    /// that no earlier pass in the capture has written (the pass's own writes come after).
    /// Replay binds the other half of the ping-pong pair; it is no feedback loop.
    pub previous_frame: bool,
}

#[derive(Clone, Debug)]
pub struct ColorAttachmentDesc {
    pub resource: ResourceId,
    pub mip: u32,
    pub layer: u32,
    pub format: &'static FormatInfo,
    pub load: LoadOp,
    pub store: StoreOp,
    pub clear: [f64; 4],
    pub blend: Option<Blend>,
    pub write_mask: Option<String>,
}

#[derive(Clone, Debug)]
pub struct DepthStencilDesc {
    pub resource: ResourceId,
    pub mip: u32,
    pub layer: u32,
    pub format: &'static FormatInfo,
    pub depth_load: LoadOp,
    pub depth_store: StoreOp,
    pub depth_clear: f64,
    pub stencil_load: LoadOp,
    pub stencil_store: StoreOp,
    pub stencil_clear: u32,
    pub read_only: bool,
    pub stencil_read_only: bool,
}

#[derive(Clone, Debug)]
pub struct DrawDesc {
    pub label: Option<String>,
    pub vertex: Option<String>,
    pub fragment: Option<String>,
    pub mesh: Option<MeshId>,
    pub count: Option<u32>,
    pub instances: u32,
    pub first: u32,
    pub first_instance: u32,
    pub base_vertex: i32,
    pub indirect: Option<(ResourceId, u64)>,
    /// The count buffer, offset and most records of an indirect draw whose count the GPU
    /// reads (`IndirectArgs::count`).
    pub draw_count: Option<(ResourceId, u64, u32)>,
    pub stencil_reference: Option<u32>,
    /// Runs no fragment shader (see the format's `Draw::depth_only`).
    pub depth_only: bool,
    pub params: std::collections::BTreeMap<String, ParamValue>,
    /// An imported draw's pipeline and state.
    pub vk: Option<Box<super::vk_model::VkWork>>,
}

#[derive(Clone, Debug)]
pub struct DispatchDesc {
    pub label: Option<String>,
    pub entry: Option<String>,
    pub groups: Option<[u32; 3]>,
    pub indirect: Option<(ResourceId, u64)>,
    pub params: std::collections::BTreeMap<String, ParamValue>,
    /// An imported dispatch's pipeline and state.
    pub vk: Option<Box<super::vk_model::VkWork>>,
}

#[derive(Clone, Debug)]
pub struct CopyLocationDesc {
    pub resource: ResourceId,
    pub mip: u32,
    pub layer: u32,
    pub origin: [u32; 3],
    pub offset: u64,
    pub size: Option<u64>,
    pub bytes_per_row: Option<u32>,
}

#[derive(Clone, Debug)]
pub struct CopyDesc {
    pub src: CopyLocationDesc,
    pub dst: CopyLocationDesc,
    pub extent: Option<[u32; 3]>,
    /// Bytes the CPU wrote during the frame (see the format's `Copy::host`).
    pub host: bool,
}

/// A validated blit: both sides 2D subresources, corners inside their mips.
#[derive(Clone, Debug)]
pub struct BlitDesc {
    pub src: BlitSide,
    pub dst: BlitSide,
    pub linear: bool,
}

#[derive(Clone, Copy, Debug)]
pub struct BlitSide {
    pub resource: ResourceId,
    pub mip: u32,
    pub layer: u32,
    pub corners: [[u32; 2]; 2],
}

/// A validated attachment clear: colour attachments by index into the pass's, with values;
/// rectangles inside the attachments.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachmentClearDesc {
    /// The draw it comes before (the draw count: after the last).
    pub before_draw: usize,
    pub colors: Vec<(usize, [f64; 4])>,
    pub depth: Option<f32>,
    pub stencil: Option<u32>,
    /// `[x, y, width, height]`.
    pub rects: Vec<[u32; 4]>,
}

#[derive(Clone, Debug)]
pub struct ClearDesc {
    pub resource: ResourceId,
    pub value: [f64; 4],
    pub stencil: u32,
    pub range: Subresources,
}

#[derive(Clone, Debug)]
pub struct RecordedBarrierDesc {
    /// Stage and access masks and layouts of a Vulkan barrier, validated.
    pub vulkan: Option<VulkanBarrierDesc>,
    pub barrier_type: BarrierType,
    pub resource: Option<ResourceId>,
    pub resource_before: Option<ResourceId>,
    pub range: Option<Subresources>,
    pub before: Vec<ResourceState>,
    pub after: Vec<ResourceState>,
    pub split: SplitFlag,
}

/// A Vulkan barrier in Vulkan's terms, its names parsed (see `capture::vulkan`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VulkanBarrierDesc {
    pub origin: String,
    pub src_stages: PipelineStages,
    pub src_access: AccessFlags,
    pub dst_stages: PipelineStages,
    pub dst_access: AccessFlags,
    pub old_layout: Option<ImageLayout>,
    pub new_layout: Option<ImageLayout>,
    pub queue_transfer: Option<(u32, u32)>,
}

impl VulkanBarrierDesc {
    /// Layouts, then scopes, then origin: `old -> new; stages/access -> stages/access (origin)`.
    pub fn describe(&self) -> String {
        let layouts = match (self.old_layout, self.new_layout) {
            (Some(a), Some(b)) => format!("{a} -> {b}; "),
            _ => String::new(),
        };
        format!(
            "{layouts}{}/{} -> {}/{} ({})",
            self.src_stages, self.src_access, self.dst_stages, self.dst_access, self.origin
        )
    }
}

#[derive(Clone, Debug)]
pub struct PassDesc {
    pub id: PassId,
    pub name: String,
    pub queue: QueueId,
    pub kind: PassKind,
    pub markers: Vec<String>,
    pub shader: Option<ShaderDesc>,
    pub bindings: Vec<BindingDesc>,
    pub color_attachments: Vec<ColorAttachmentDesc>,
    pub depth_stencil: Option<DepthStencilDesc>,
    pub state: RenderState,
    pub draws: Vec<DrawDesc>,
    pub attachment_clears: Vec<AttachmentClearDesc>,
    pub dispatches: Vec<DispatchDesc>,
    pub copies: Vec<CopyDesc>,
    pub clears: Vec<ClearDesc>,
    pub blits: Vec<BlitDesc>,
    pub resolve: Option<(ResourceId, ResourceId)>,
    pub generate_mips: Option<(ResourceId, Subresources)>,
    pub present: Option<ResourceId>,
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub barriers: Vec<RecordedBarrierDesc>,
    pub signal: Vec<FenceId>,
    pub wait: Vec<FenceId>,
    pub recorded_gpu_ns: Option<u64>,
    /// Every resource use of the pass, from bindings, attachments, draws, copies and so on.
    pub accesses: Vec<ResourceAccess>,
}

impl PassDesc {
    /// The marker path as PIX shows it: `Frame/Geometry/base_material`.
    pub fn marker_path(&self) -> String {
        let mut parts = self.markers.clone();
        parts.push(self.name.clone());
        parts.join("/")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(mips: (u32, u32), layers: (u32, u32), bytes: (u64, u64)) -> Subresources {
        Subresources {
            mip_base: mips.0,
            mip_count: mips.1,
            layer_base: layers.0,
            layer_count: layers.1,
            byte_offset: bytes.0,
            byte_size: bytes.1,
        }
    }

    #[test]
    fn subresource_overlap_needs_both_mips_and_layers() {
        let a = range((0, 2), (0, 1), (0, 0));
        assert!(a.overlaps(&range((1, 1), (0, 1), (0, 0))));
        assert!(!a.overlaps(&range((2, 1), (0, 1), (0, 0))));
        assert!(!a.overlaps(&range((0, 1), (1, 1), (0, 0))));
    }

    #[test]
    fn buffer_ranges_overlap_by_bytes() {
        let a = range((0, 1), (0, 1), (0, 16));
        assert!(a.overlaps(&range((0, 1), (0, 1), (8, 16))));
        assert!(!a.overlaps(&range((0, 1), (0, 1), (16, 16))));
    }

    #[test]
    fn queue_capabilities_follow_the_stage_table() {
        let copy = QueueCapabilities::of(QueueType::Copy);
        assert_eq!(copy.names(), ["transfer"]);
        let compute = QueueCapabilities::of(QueueType::Compute);
        assert!(compute.compute && !compute.graphics);
        assert_eq!(QueueCapabilities::of(QueueType::Graphics).names().len(), 3);
    }
}
