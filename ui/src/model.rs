//! The inspection model: a replayed frame as plain data (ids, names, numbers, preformatted
//! text), projected by `project` from the pipeline's stages by id. The panels draw only this,
//! so they can be tested on a fixed model; passes and resources keep their capture ids so
//! that anything naming one (the command line, a test) finds it without matching names.

pub use framelab_core::analysis::graph::EdgeKind;
pub use framelab_core::buffer_views::{BufferView, LayoutChoice};
pub use framelab_core::capture::model::{PassId, ResourceId};
pub use framelab_core::layout::{BufferLayout, Field, Scalar};

/// A whole frame to inspect.
#[derive(Clone, Debug, Default)]
pub struct Inspection {
    pub capture: String,
    pub scale: f64,
    pub queues: Vec<String>,
    /// In execution order: the pass at index `i` is the replay plan's pass `i`.
    pub passes: Vec<Pass>,
    pub resources: Vec<Resource>,
    /// Cross-queue waits: the signalling pass and the waiting pass.
    pub fences: Vec<(usize, usize)>,
    /// The pass DAG's edges between model passes.
    pub edges: Vec<Edge>,
    /// The memory aliasing plan: where each placed resource lives and when.
    pub memory: Vec<MemoryBlock>,
    /// Timings from a report given on the command line (`--timings`); a replay's own timings
    /// replace them when it finishes.
    pub timings: Option<Timings>,
    /// A second report to compare with (`--compare`).
    pub compare: Option<Compare>,
    /// The resource the frame presents (the last present pass's), opened first.
    pub presented: Option<usize>,
    /// The frame came from a Vulkan program: barrier tables give Vulkan's layouts, stages and
    /// accesses alone, since its D3D12 states are framelab's translation, not the program's.
    pub vulkan_terms: bool,
}

/// A dependency between two passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    pub from: usize,
    pub to: usize,
    pub kind: EdgeKind,
    /// The resource of a data hazard.
    pub resource: Option<String>,
}

/// One resource in the aliasing plan: its pool (heap type, or heap type and category), its
/// offset and size there, and the passes (model indices) from its first to its last use;
/// persistent resources live the whole frame.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryBlock {
    pub resource: ResourceId,
    pub pool: String,
    pub offset: u64,
    pub bytes: u64,
    pub first: usize,
    pub last: usize,
}

/// Per pass, in the model's order: where its GPU work starts in the frame and how long it
/// takes, in nanoseconds (`None` where it was not timed).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timings {
    pub source: String,
    pub passes: Vec<Option<PassTime>>,
    /// Why some passes have no time although they ran (the adapter's timestamps do not
    /// measure them), shown with the timeline.
    pub note: Option<String>,
    /// Per pass, the work it submits (from the replayed plan), where known.
    pub work: Vec<Option<framelab_core::timing::counters::Work>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassTime {
    pub start_ns: f64,
    pub gpu_ns: f64,
    /// False where the adapter's timestamps do not measure this kind of pass (the timings'
    /// `note` says why): the pass keeps its place on the timeline but shows no time.
    pub measured: bool,
    /// The pass's pipeline statistics in the frame timed, when counted.
    pub counters: Option<framelab_core::timing::counters::Counts>,
}

/// The timing diff against another report: per pass, that side's median and the verdict.
#[derive(Clone, Debug, Default)]
pub struct Compare {
    pub source: String,
    pub passes: Vec<Option<CompareRow>>,
    /// A warning about the comparison itself (reports taken at different scales).
    pub note: Option<String>,
}

#[derive(Clone, Debug)]
pub struct CompareRow {
    pub other_ms: f64,
    pub change_pct: f64,
    /// regression, improvement, unchanged, inconclusive, untimed or moved.
    pub verdict: String,
    /// The pass's name there, where it was renamed.
    pub renamed: Option<String>,
    /// The queue it runs on there, where it moved to another (its times are shown, not
    /// compared).
    pub moved: Option<String>,
}

#[derive(Clone, Debug)]
pub struct Pass {
    pub id: PassId,
    pub name: String,
    pub queue: usize,
    /// raster, compute, copy, clear, resolve, generate_mips or present.
    pub kind: String,
    /// Marker groups above the pass, outermost first.
    pub markers: Vec<String>,
    /// Its work reaches no output.
    pub culled: bool,
    /// One line per draw, dispatch, copy or clear, with its arguments.
    pub work: Vec<String>,
    /// How many of the first `work` lines are draws or dispatches (which can be replayed up
    /// to).
    pub steps: usize,
    /// WGSL variable -> resource view.
    pub bindings: Vec<(String, String)>,
    /// Colour and depth attachments with load/store and clear values.
    pub attachments: Vec<Attachment>,
    /// Render state and shader entry points.
    pub state: Vec<(String, String)>,
    pub params: Vec<(String, String)>,
    pub barriers: Vec<Barrier>,
    /// Lints that name this pass: `code severity: message`.
    pub lints: Vec<String>,
    /// Resources (model indices) it reads, and those it writes: colour attachments first, then
    /// depth, then everything else it writes, each once.
    pub inputs: Vec<usize>,
    pub outputs: Vec<usize>,
}

/// A colour or depth attachment of a pass.
#[derive(Clone, Debug, PartialEq)]
pub struct Attachment {
    /// `color N` or `depth`.
    pub slot: String,
    /// The resource (model index).
    pub resource: usize,
    /// Subresource, format, load and store, as one line.
    pub text: String,
}

/// Where a barrier sits relative to its pass, and who asked for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BarrierSide {
    Before,
    After,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BarrierSource {
    /// What the analysis derives the frame needs.
    Derived,
    /// What the capture records.
    Recorded,
}

#[derive(Clone, Debug)]
pub struct Barrier {
    pub side: BarrierSide,
    pub source: BarrierSource,
    /// transition, uav or aliasing.
    pub kind: String,
    pub resource: String,
    pub subresource: String,
    /// D3D12 states, `BEFORE -> AFTER`.
    pub states: String,
    /// The Vulkan layouts, stages and accesses (derived barriers).
    pub vulkan: String,
}

/// How the texture viewer shows a texture's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// Float, normalised and packed formats.
    Float,
    /// The depth aspect of a depth(-stencil) texture.
    Depth,
    Uint,
    Sint,
    /// The stencil aspect of a depth-stencil texture.
    Stencil,
}

#[derive(Clone, Debug)]
pub struct TextureView {
    /// The replay plan's texture index.
    pub plan_index: usize,
    pub sampling: Sampling,
    /// 3D: slices are chosen, not layers.
    pub volume: bool,
    /// Values are linear colour to be encoded for display (sRGB formats, HDR floats).
    pub encode_srgb: bool,
    /// A reason it cannot be shown (multisampled, block-compressed ...), if any.
    pub unviewable: Option<String>,
    /// Has a stencil aspect the viewer can show instead of depth.
    pub stencil: bool,
}

#[derive(Clone, Debug)]
pub struct Resource {
    pub id: ResourceId,
    pub name: String,
    pub kind: String,
    /// The capture's (DXGI) format name; empty for untyped buffers.
    pub format: String,
    pub width: u32,
    pub height: u32,
    pub depth: u32,
    pub mips: u32,
    pub layers: u32,
    pub bytes: u64,
    /// The heap it is placed in, `committed` or `reserved`, with its heap type.
    pub heap: String,
    /// Offset in the aliasing plan's pool.
    pub offset: Option<u64>,
    /// First and last pass (model indices) that use it.
    pub first_pass: Option<usize>,
    pub last_pass: Option<usize>,
    /// Resources that share its memory in the aliasing plan.
    pub aliases: Vec<String>,
    pub texture: Option<TextureView>,
    pub buffer: Option<BufferView>,
}

impl Inspection {
    /// Where a capture pass is among the passes shown, if it is shown.
    pub fn pass_position(&self, id: PassId) -> Option<usize> {
        self.passes.iter().position(|p| p.id == id)
    }
    /// Where a capture resource is among the resources (capture order, so its index, when the
    /// model has it).
    pub fn resource_position(&self, id: ResourceId) -> Option<usize> {
        self.resources
            .get(id.index())
            .filter(|r| r.id == id)
            .map(|_| id.index())
    }
}
