//! The frame as the analyses see it: passes on queues with resource accesses expressed as D3D12
//! states over subresource units, and resources with their sizes and placement class.
//!
//! Analyses run on this model rather than on `Capture` so that property tests and benchmarks can
//! generate frames directly, and so that the graph, barrier and memory code never needs to know
//! how a capture spells things. `from_capture` is the one bridge.

use std::collections::BTreeSet;
use std::fmt;

use serde::Serialize;

use crate::capture::format::{Access, HeapType, PassKind, QueueType, ResourceKind};
use crate::capture::model::{
    AccessSource, Capture, InitialDesc, PassDesc, PassId, ResourceCategory, ResourceId,
    Subresources,
};

/// Dense indices of the model. The model numbers its passes, resources, queues and subresource
/// units from zero so that analyses keep per-item state in plain vectors; these newtypes keep
/// the four spaces apart (and apart from the capture's ids) at no cost: each is a `u32` in
/// memory, and serializes and formats as the bare number reports have always shown.
macro_rules! dense_index {
    ($($(#[$doc:meta])* $name:ident),* $(,)?) => {$(
        $(#[$doc])*
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Serialize)]
        #[serde(transparent)]
        #[repr(transparent)]
        pub struct $name(pub u32);

        impl $name {
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }
            /// From a position in the model's vectors (which never hold more than `u32::MAX`
            /// items).
            #[inline]
            pub fn new(index: usize) -> Self {
                Self(index as u32)
            }
            /// `0..count` as indices.
            #[inline]
            pub fn range(
                count: usize,
            ) -> impl DoubleEndedIterator<Item = Self> + ExactSizeIterator + Clone {
                (0..count as u32).map(Self)
            }
        }

        // Messages and debug dumps print the bare number, as they did before these types.
        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Debug::fmt(&self.0, f)
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(&self.0, f)
            }
        }
    )*};
}

dense_index!(
    /// A pass of the model: an index into `FrameModel::passes`.
    MPass,
    /// A resource of the model: an index into `FrameModel::resources` (previous-frame copies
    /// included, so not always a capture resource).
    MResource,
    /// A queue of the model: an index into `FrameModel::queues`.
    MQueue,
    /// A subresource unit: an index into the flat unit space of `Units`.
    Unit,
);

/// A pass or none, in four bytes. `Option<MPass>` takes eight; the graph build and the barrier
/// walk keep one of these per unit (and per unit and queue), and those vectors are the hot
/// loops' working set, so they keep the compact form with a named sentinel instead.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
#[repr(transparent)]
pub struct OptPass(u32);

impl OptPass {
    pub const NONE: OptPass = OptPass(u32::MAX);

    #[inline]
    pub fn some(p: MPass) -> Self {
        OptPass(p.0)
    }
    #[inline]
    pub fn get(self) -> Option<MPass> {
        (self != Self::NONE).then_some(MPass(self.0))
    }
    #[inline]
    pub fn is_none(self) -> bool {
        self == Self::NONE
    }
}

impl fmt::Debug for OptPass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.get(), f)
    }
}

/// The index of a pass's first access with some property, or none, in four bytes: `UnitUse`
/// carries two, and uses are the most numerous records of the analysis, so `Option<u32>`'s
/// extra bytes would grow every walk over them. None orders after every index, so merging two
/// uses keeps the earlier access with `min`.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct FirstAccess(u32);

impl FirstAccess {
    pub const NONE: FirstAccess = FirstAccess(u32::MAX);

    #[inline]
    pub fn some(access: u32) -> Self {
        FirstAccess(access)
    }
    #[inline]
    pub fn get(self) -> Option<u32> {
        (self != Self::NONE).then_some(self.0)
    }
}

impl fmt::Debug for FirstAccess {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.get(), f)
    }
}

/// A D3D12 resource state, as bit flags so read states can be combined. The values are
/// D3D12's, except PRESENT, which D3D12 aliases to COMMON and which gets its own bit here so
/// reports can name it.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct State(pub u32);

impl State {
    pub const COMMON: State = State(0);
    pub const VERTEX_AND_CONSTANT_BUFFER: State = State(0x1);
    pub const INDEX_BUFFER: State = State(0x2);
    pub const RENDER_TARGET: State = State(0x4);
    pub const UNORDERED_ACCESS: State = State(0x8);
    pub const DEPTH_WRITE: State = State(0x10);
    pub const DEPTH_READ: State = State(0x20);
    pub const NON_PIXEL_SHADER_RESOURCE: State = State(0x40);
    pub const PIXEL_SHADER_RESOURCE: State = State(0x80);
    pub const INDIRECT_ARGUMENT: State = State(0x200);
    pub const COPY_DEST: State = State(0x400);
    pub const COPY_SOURCE: State = State(0x800);
    pub const RESOLVE_DEST: State = State(0x1000);
    pub const RESOLVE_SOURCE: State = State(0x2000);
    pub const PRESENT: State = State(0x10_0000);

    const NAMES: [(State, &'static str); 14] = [
        (
            State::VERTEX_AND_CONSTANT_BUFFER,
            "VERTEX_AND_CONSTANT_BUFFER",
        ),
        (State::INDEX_BUFFER, "INDEX_BUFFER"),
        (State::RENDER_TARGET, "RENDER_TARGET"),
        (State::UNORDERED_ACCESS, "UNORDERED_ACCESS"),
        (State::DEPTH_WRITE, "DEPTH_WRITE"),
        (State::DEPTH_READ, "DEPTH_READ"),
        (
            State::NON_PIXEL_SHADER_RESOURCE,
            "NON_PIXEL_SHADER_RESOURCE",
        ),
        (State::PIXEL_SHADER_RESOURCE, "PIXEL_SHADER_RESOURCE"),
        (State::INDIRECT_ARGUMENT, "INDIRECT_ARGUMENT"),
        (State::COPY_DEST, "COPY_DEST"),
        (State::COPY_SOURCE, "COPY_SOURCE"),
        (State::RESOLVE_DEST, "RESOLVE_DEST"),
        (State::RESOLVE_SOURCE, "RESOLVE_SOURCE"),
        (State::PRESENT, "PRESENT"),
    ];

    /// States in which the GPU writes: they cannot be combined with any other state.
    const WRITE_STATES: u32 = 0x4 | 0x8 | 0x10 | 0x400 | 0x1000;

    pub fn union(self, other: State) -> State {
        State(self.0 | other.0)
    }
    pub fn contains(self, other: State) -> bool {
        self.0 & other.0 == other.0
    }
    pub fn is_write(self) -> bool {
        self.0 & Self::WRITE_STATES != 0
    }
    pub fn is_read_only(self) -> bool {
        !self.is_write() && self != State::COMMON
    }
    /// Every single state in this set.
    pub fn bits(self) -> impl Iterator<Item = State> {
        Self::NAMES
            .iter()
            .map(|(s, _)| *s)
            .filter(move |s| self.contains(*s))
    }
    /// The D3D12 name, with `|` between combined read states.
    pub fn name(self) -> String {
        if self == State::COMMON {
            return "COMMON".to_owned();
        }
        Self::NAMES
            .iter()
            .filter(|(s, _)| self.contains(*s))
            .map(|(_, n)| *n)
            .collect::<Vec<_>>()
            .join("|")
    }
    /// Whether a command list of this queue type may hold a resource in this state
    /// (D3D12: compute lists support shader-resource, UAV, indirect, constant and copy states;
    /// copy lists only COMMON and copy states).
    pub fn allowed_on(self, queue: QueueType) -> bool {
        let allowed = match queue {
            QueueType::Graphics => return true,
            QueueType::Compute => {
                State::VERTEX_AND_CONSTANT_BUFFER.0
                    | State::UNORDERED_ACCESS.0
                    | State::NON_PIXEL_SHADER_RESOURCE.0
                    | State::INDIRECT_ARGUMENT.0
                    | State::COPY_DEST.0
                    | State::COPY_SOURCE.0
            }
            QueueType::Copy => State::COPY_DEST.0 | State::COPY_SOURCE.0,
        };
        self.0 & !allowed == 0
    }
}

impl fmt::Debug for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl Serialize for State {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

/// One access of a pass to a range of a resource, in the state it needs.
#[derive(Clone, Debug)]
pub struct ModelAccess {
    pub resource: MResource,
    pub range: Subresources,
    pub state: State,
    /// Reads the previous contents.
    pub reads: bool,
    pub writes: bool,
    /// Whether the access is an unordered-access view use (needs UAV barriers between passes).
    pub uav: bool,
}

#[derive(Clone, Debug)]
pub struct ModelPass {
    /// The capture pass this is (synthetic frames number their passes in order).
    pub id: PassId,
    pub name: String,
    pub queue: MQueue,
    pub accesses: Vec<ModelAccess>,
    /// Runs graphics pipelines (shader reads are pixel-shader reads, Vulkan stages are graphics
    /// stages); otherwise compute or transfer work.
    pub raster: bool,
    /// A frame output by itself (present).
    pub sink: bool,
    /// Recorded or measured GPU time, for the critical path.
    pub gpu_ns: Option<u64>,
    pub markers: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct ModelResource {
    /// The capture resource this is (a previous-frame copy names the resource it copies).
    pub id: ResourceId,
    pub name: String,
    pub is_buffer: bool,
    pub mips: u32,
    pub layers: u32,
    /// Buffer size (byte ranges of accesses are within it).
    pub buffer_bytes: u64,
    /// Bytes it occupies in a heap, aligned.
    pub aligned_bytes: u64,
    pub alignment: u64,
    pub heap_type: HeapType,
    pub category: ResourceCategory,
    /// Read by the next frame: kept alive to the end, and reads before the first write see the
    /// previous frame.
    pub history: bool,
    pub output: bool,
    /// A swapchain's image: the presentation engine holds its memory across frames.
    pub swapchain: bool,
    /// Has initial contents, so it is live from the start of the frame.
    pub initialised: bool,
    /// State at the start of the frame.
    pub initial_state: State,
    /// For the previous-frame copy of a `history` resource: the resource it is the copy of.
    pub previous_of: Option<MResource>,
}

impl ModelResource {
    /// Every subresource (the whole buffer).
    pub fn whole(&self) -> Subresources {
        Subresources {
            mip_base: 0,
            mip_count: self.mips,
            layer_base: 0,
            layer_count: self.layers,
            byte_offset: 0,
            byte_size: self.buffer_bytes,
        }
    }
}

#[derive(Clone, Debug)]
pub struct FrameModel {
    pub queues: Vec<QueueInfo>,
    pub resources: Vec<ModelResource>,
    pub passes: Vec<ModelPass>,
    /// Declared fences as (signalling pass, waiting pass).
    pub fences: Vec<(MPass, MPass)>,
    /// D3D12 resource heap tier (1 keeps buffers, RT/DS and other textures apart).
    pub heap_tier: u8,
}

#[derive(Clone, Debug)]
pub struct QueueInfo {
    pub name: String,
    pub queue_type: QueueType,
}

impl FrameModel {
    pub fn queue_type(&self, pass: MPass) -> QueueType {
        self.queues[self.passes[pass.index()].queue.index()].queue_type
    }
}

/// Which raster stages read a binding, from shader reflection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stages {
    /// Not a raster pass: compute (or transfer) work.
    Compute,
    /// Raster: read by the vertex stage, the fragment stage, or both.
    Raster { vertex: bool, fragment: bool },
}

/// The state a capture access needs. Shader reads are pixel-shader reads when the fragment
/// stage uses the binding, non-pixel when the vertex stage (or compute) does, both when both do.
pub fn state_for(access: Access, stages: Stages, texture: bool) -> State {
    let shader_read = match stages {
        Stages::Compute => State::NON_PIXEL_SHADER_RESOURCE,
        Stages::Raster { vertex, fragment } => {
            let mut s = State::COMMON;
            if vertex {
                s = s.union(State::NON_PIXEL_SHADER_RESOURCE);
            }
            if fragment || !vertex {
                s = s.union(State::PIXEL_SHADER_RESOURCE);
            }
            s
        }
    };
    match access {
        Access::Sampled | Access::StorageRead if !access.is_unordered(texture) => shader_read,
        Access::Sampled => State::PIXEL_SHADER_RESOURCE,
        Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite => {
            State::UNORDERED_ACCESS
        }
        Access::Uniform | Access::VertexBuffer => State::VERTEX_AND_CONSTANT_BUFFER,
        Access::IndexBuffer => State::INDEX_BUFFER,
        Access::IndirectArgs => State::INDIRECT_ARGUMENT,
        Access::CopySrc => State::COPY_SOURCE,
        Access::CopyDst => State::COPY_DEST,
        Access::ColorAttachment => State::RENDER_TARGET,
        Access::DepthWrite => State::DEPTH_WRITE,
        Access::DepthRead => State::DEPTH_READ,
        Access::ResolveSrc => State::RESOLVE_SOURCE,
        Access::ResolveDst => State::RESOLVE_DEST,
        Access::Present => State::PRESENT,
    }
}

type StageSets = (BTreeSet<String>, BTreeSet<String>);

/// Globals used by the vertex entry points (the pass's and per-draw overrides) and by the
/// fragment entry point of a raster pass, from the interface reflected at validation.
fn stage_usage(capture: &Capture, p: &PassDesc) -> Option<StageSets> {
    let shader = p.shader.as_ref()?;
    let interface = &capture.shader(shader.id).interface;
    let mut vertex = BTreeSet::new();
    let entries = shader
        .vertex
        .iter()
        .chain(p.draws.iter().filter_map(|d| d.vertex.as_ref()));
    for entry in entries {
        vertex.extend(interface.globals_used_by(entry)?.iter().cloned());
    }
    let mut fragment = BTreeSet::new();
    let entries = shader
        .fragment
        .iter()
        .chain(p.draws.iter().filter_map(|d| d.fragment.as_ref()));
    for entry in entries {
        fragment.extend(interface.globals_used_by(entry)?.iter().cloned());
    }
    Some((vertex, fragment))
}

/// Builds the analysis model of a validated capture.
pub fn from_capture(capture: &Capture) -> FrameModel {
    let resources = capture
        .resources
        .iter()
        .map(|r| {
            let heap_type = r.heap_type(&capture.heaps);
            ModelResource {
                id: r.id,
                name: r.name.clone(),
                is_buffer: r.kind == ResourceKind::Buffer,
                mips: if r.is_texture() { r.mip_levels } else { 1 },
                layers: if r.is_texture() { r.array_layers } else { 1 },
                buffer_bytes: if r.is_texture() { 0 } else { r.bytes },
                aligned_bytes: r.aligned_bytes,
                alignment: r.alignment,
                heap_type,
                category: r.category(),
                history: r.history,
                output: r.output,
                swapchain: r.swapchain,
                initialised: r.initial != InitialDesc::Undefined,
                initial_state: match heap_type {
                    HeapType::Upload => State::VERTEX_AND_CONSTANT_BUFFER
                        .union(State::INDEX_BUFFER)
                        .union(State::NON_PIXEL_SHADER_RESOURCE)
                        .union(State::PIXEL_SHADER_RESOURCE)
                        .union(State::INDIRECT_ARGUMENT)
                        .union(State::COPY_SOURCE),
                    HeapType::Readback => State::COPY_DEST,
                    _ => State::COMMON,
                },
                previous_of: None,
            }
        })
        .collect();
    let passes = capture
        .passes
        .iter()
        .map(|p| {
            let raster = p.kind == PassKind::Raster;
            let usage = raster.then(|| stage_usage(capture, p));
            let accesses = p
                .accesses
                .iter()
                .map(|a| {
                    let texture = capture.resource(a.resource).is_texture();
                    let stages = match (&usage, &a.source) {
                        (Some(Some((vs, fs))), AccessSource::Binding(var)) => Stages::Raster {
                            vertex: vs.contains(var),
                            fragment: fs.contains(var),
                        },
                        // Without reflection, assume every stage reads it.
                        (Some(_), _) => Stages::Raster {
                            vertex: true,
                            fragment: true,
                        },
                        // Mip generation samples the previous level in a pixel shader.
                        (None, _) if p.kind == PassKind::GenerateMips => Stages::Raster {
                            vertex: false,
                            fragment: true,
                        },
                        (None, _) => Stages::Compute,
                    };
                    ModelAccess {
                        resource: MResource(a.resource.0),
                        range: a.range,
                        state: state_for(a.access, stages, texture),
                        reads: a.reads,
                        writes: a.writes,
                        uav: a.access.is_unordered(texture),
                    }
                })
                .collect();
            ModelPass {
                id: p.id,
                name: p.name.clone(),
                queue: MQueue(p.queue.0),
                accesses,
                raster: raster || p.kind == PassKind::GenerateMips,
                sink: p.kind == PassKind::Present,
                gpu_ns: p.recorded_gpu_ns,
                markers: p.markers.clone(),
            }
        })
        .collect();
    // Capture passes are numbered in recorded order, as the model's are.
    let fences = capture
        .fence_edges()
        .into_iter()
        .map(|(s, w)| (MPass(s.0), MPass(w.0)))
        .collect();
    let mut model = FrameModel {
        queues: capture
            .queues
            .iter()
            .map(|q| QueueInfo {
                name: q.name.clone(),
                queue_type: q.queue_type,
            })
            .collect(),
        resources,
        passes,
        fences,
        heap_tier: capture.adapter.resource_heap_tier,
    };
    model.split_history();
    model
}

impl FrameModel {
    /// Gives each `history` resource read before the frame writes it a second resource, its
    /// previous-frame copy (the other half of the ping-pong pair), and points those reads at it.
    /// Later analyses then need no special case: the copy is never written in the frame, so
    /// reads of it add no edge, and both halves stay alive for the whole frame.
    pub fn split_history(&mut self) {
        for r in 0..self.resources.len() {
            if !self.resources[r].history || self.resources[r].previous_of.is_some() {
                continue;
            }
            let mut previous: Option<MResource> = None;
            'passes: for p in 0..self.passes.len() {
                let writes_here = self.passes[p]
                    .accesses
                    .iter()
                    .any(|a| a.resource.index() == r && a.writes);
                for a in 0..self.passes[p].accesses.len() {
                    let access = &self.passes[p].accesses[a];
                    if access.resource.index() != r || !access.reads || access.writes {
                        continue;
                    }
                    let id = *previous.get_or_insert_with(|| {
                        let mut copy = self.resources[r].clone();
                        copy.name = format!("{} (previous frame)", copy.name);
                        copy.previous_of = Some(MResource::new(r));
                        copy.initialised = true;
                        copy.output = false;
                        self.resources.push(copy);
                        MResource::new(self.resources.len() - 1)
                    });
                    self.passes[p].accesses[a].resource = id;
                }
                if writes_here {
                    break 'passes;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::units::Units;

    #[test]
    fn state_names_and_sets() {
        let s = State::PIXEL_SHADER_RESOURCE.union(State::NON_PIXEL_SHADER_RESOURCE);
        assert_eq!(s.name(), "NON_PIXEL_SHADER_RESOURCE|PIXEL_SHADER_RESOURCE");
        assert!(s.is_read_only());
        assert!(State::UNORDERED_ACCESS.is_write());
        assert_eq!(State::COMMON.name(), "COMMON");
        assert!(!State::RENDER_TARGET.allowed_on(QueueType::Compute));
        assert!(State::UNORDERED_ACCESS.allowed_on(QueueType::Compute));
        assert!(!State::UNORDERED_ACCESS.allowed_on(QueueType::Copy));
    }

    #[test]
    fn a_previous_frame_copy_shares_its_buffers_byte_intervals() {
        let buffer = ModelResource {
            id: ResourceId(0),
            name: "history".into(),
            is_buffer: true,
            mips: 1,
            layers: 1,
            buffer_bytes: 256,
            aligned_bytes: 65536,
            alignment: 65536,
            heap_type: HeapType::Default,
            category: ResourceCategory::Buffer,
            history: true,
            output: false,
            swapchain: false,
            initialised: false,
            initial_state: State::COMMON,
            previous_of: None,
        };
        let bytes = |offset, size| Subresources {
            mip_base: 0,
            mip_count: 1,
            layer_base: 0,
            layer_count: 1,
            byte_offset: offset,
            byte_size: size,
        };
        let access = |range: Subresources, state: State, writes: bool| ModelAccess {
            resource: MResource(0),
            range,
            state,
            reads: !writes,
            writes,
            uav: false,
        };
        let pass = |name: &str, a: ModelAccess| ModelPass {
            id: PassId(0),
            name: name.into(),
            queue: MQueue(0),
            accesses: vec![a],
            raster: false,
            sink: false,
            gpu_ns: None,
            markers: vec![],
        };
        let mut m = FrameModel {
            queues: vec![QueueInfo {
                name: "gfx".into(),
                queue_type: QueueType::Graphics,
            }],
            resources: vec![buffer],
            passes: vec![
                // Reads the previous frame's bytes 0..64, then the frame writes 64..192.
                pass(
                    "read",
                    access(bytes(0, 64), State::NON_PIXEL_SHADER_RESOURCE, false),
                ),
                pass(
                    "write",
                    access(bytes(64, 128), State::UNORDERED_ACCESS, true),
                ),
            ],
            fences: vec![],
            heap_tier: 2,
        };
        m.split_history();
        assert_eq!(m.resources[1].previous_of, Some(MResource(0)));
        let units = Units::new(&m);
        let intervals = |r: MResource| -> Vec<(u64, u64)> {
            (0..units.count(r) as u32)
                .map(|i| units.buffer_interval(r, i))
                .collect()
        };
        assert_eq!(
            intervals(MResource(0)),
            vec![(0, 64), (64, 192), (192, 256)]
        );
        assert_eq!(intervals(MResource(1)), intervals(MResource(0)));
        assert_eq!(units.previous_copies(), &[(MResource(1), MResource(0))]);
    }

    #[test]
    fn storage_read_of_a_buffer_is_a_shader_resource() {
        let both = Stages::Raster {
            vertex: true,
            fragment: true,
        };
        let fragment = Stages::Raster {
            vertex: false,
            fragment: true,
        };
        let vertex = Stages::Raster {
            vertex: true,
            fragment: false,
        };
        assert_eq!(
            state_for(Access::StorageRead, Stages::Compute, false),
            State::NON_PIXEL_SHADER_RESOURCE
        );
        assert_eq!(
            state_for(Access::StorageRead, Stages::Compute, true),
            State::UNORDERED_ACCESS
        );
        assert_eq!(
            state_for(Access::Sampled, fragment, true),
            State::PIXEL_SHADER_RESOURCE
        );
        assert_eq!(
            state_for(Access::StorageRead, vertex, false),
            State::NON_PIXEL_SHADER_RESOURCE
        );
        assert_eq!(
            state_for(Access::Sampled, both, true).name(),
            "NON_PIXEL_SHADER_RESOURCE|PIXEL_SHADER_RESOURCE"
        );
    }
}
