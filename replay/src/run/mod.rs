//! Running a plan: a `Session` owns the GPU resources, shader modules, pipelines and bind
//! groups of a plan, and `run_frame` encodes every pass (each in its own command encoder and
//! error scope, so a validation error names its pass) with timestamps where the adapter can
//! (see `stamps`), submits, and returns per-pass GPU and CPU times.
//!
//! Pipelines use automatic layouts (wgpu derives them from naga's reflection of the entry
//! points), and bind groups are filled by WGSL variable name: `frame` gets the frame constants,
//! `params` the pass's packed parameters, every other variable the capture's binding.
//! Resources marked `history` have two copies that swap every frame.

mod bindings;
mod blit;
mod clear_rects;
mod counters;
mod create;
mod depth_copy;
mod depth_upload;
mod drawn_copies;
mod encode;
mod fetch;
mod frame;
mod pipelines;
mod stamps;
mod unpack;
mod vulkan;
mod work;

use std::collections::BTreeMap;

use crate::device::GpuContext;
use framelab_core::plan::*;
use framelab_core::shader::{ShaderError, ValidatedShader};
use framelab_core::uniforms::UniformError;

#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("{0}")]
    Shader(#[from] Box<ShaderError>),
    #[error("pass \"{pass}\": {message}")]
    Pass { pass: String, message: String },
    #[error("pass \"{pass}\": parameters")]
    Params {
        pass: String,
        #[source]
        source: UniformError,
    },
    #[error("pass \"{pass}\": the GPU reported: {message}")]
    Gpu { pass: String, message: String },
    #[error("creating {what}: the GPU reported: {message}")]
    Setup { what: String, message: String },
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    #[error("reading timestamps back: {0}")]
    Readback(#[from] crate::readback::ReadbackError),
}

/// Times of one pass in one frame.
#[derive(Clone, Debug, Default)]
pub struct PassTime {
    /// GPU time from the pass's timestamps (see `stamps`), when the adapter can time this pass.
    pub gpu_ns: Option<u64>,
    /// Time spent encoding the pass on the CPU.
    pub cpu_ns: u64,
    /// GPU start relative to the frame's first timestamp (for traces).
    pub gpu_start_ns: Option<u64>,
    /// Pipeline statistics, when the frame was counted and the pass draws or dispatches.
    pub counters: Option<framelab_core::timing::counters::Counts>,
}

struct Module {
    module: wgpu::ShaderModule,
    reflection: std::sync::Arc<ValidatedShader>,
    frame_buffer: Option<(wgpu::Buffer, u64)>,
}

struct GpuMesh {
    streams: Vec<(u32, wgpu::Buffer)>,
    index: Option<(wgpu::Buffer, wgpu::IndexFormat, u32)>,
    vertex_count: u32,
    instance_count: u32,
}

/// Bind groups of one pipeline for frame parity 0 and 1 (history copies swap).
type Groups = [Vec<(u32, wgpu::BindGroup)>; 2];

enum Prepared {
    Raster {
        pipelines: BTreeMap<pipelines::Stages, wgpu::RenderPipeline>,
        /// Bind groups per pipeline, per draw (draws with their own parameters get their own
        /// groups; index 0 is the pass's).
        groups: BTreeMap<pipelines::Stages, Vec<Groups>>,
        draw_groups: Vec<usize>,
    },
    Compute {
        pipelines: BTreeMap<String, wgpu::ComputePipeline>,
        groups: BTreeMap<String, Vec<Groups>>,
        dispatch_groups: Vec<usize>,
    },
    /// An imported pass: the bind groups of each draw or dispatch.
    VkWork(vulkan::WorkGroups),
    /// A blit pass: each blit's mapping.
    Blit(Vec<blit::PreparedBlit>),
    Other,
}

/// Views and blit bind groups made once and reused every frame: (texture, copy, mip, layer,
/// view format).
type ViewKey = (usize, usize, u32, u32, Option<wgpu::TextureFormat>);

pub struct Session {
    faults: crate::device::Faults,
    views: std::cell::RefCell<std::collections::HashMap<ViewKey, wgpu::TextureView>>,
    mip_groups: std::cell::RefCell<std::collections::HashMap<ViewKey, wgpu::BindGroup>>,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub plan: Plan,
    textures: Vec<[wgpu::Texture; 2]>,
    buffers: Vec<[wgpu::Buffer; 2]>,
    samplers: Vec<wgpu::Sampler>,
    meshes: Vec<GpuMesh>,
    modules: Vec<Module>,
    prepared: Vec<Prepared>,
    mip_pipelines: BTreeMap<String, (wgpu::RenderPipeline, wgpu::Sampler)>,
    blits: blit::BlitPipelines,
    unpacks: unpack::UnpackPipeline,
    depth_copies: depth_upload::DepthPipelines,
    clear_rects: clear_rects::ClearPipelines,
    timestamps: Option<stamps::Timestamps>,
    /// The queries the last submitted frame writes.
    stamp_plan: stamps::StampPlan,
    timestamp_period: f32,
    statistics: Option<counters::Statistics>,
    /// Whether frames count pipeline statistics ([`Session::set_counting`]).
    counting: bool,
    /// The statistics queries the last submitted frame writes.
    count_plan: counters::CountPlan,
    frames_run: u64,
    vk: vulkan::VkObjects,
    vk_layouts: Vec<wgpu::BindGroupLayout>,
    /// While set, a pass encodes only its draws or dispatches up to this index (see
    /// [`Session::submit_pass_until`]).
    step_limit: std::cell::Cell<Option<usize>>,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("passes", &self.plan.passes.len())
            .field("frames_run", &self.frames_run)
            .finish()
    }
}

/// Validation and out-of-memory error scopes. Fields drop in declaration order, so the
/// validation scope (pushed last) is popped first even when an early return drops the pair.
struct Scopes {
    validation: wgpu::ErrorScopeGuard,
    oom: wgpu::ErrorScopeGuard,
}

fn scope(device: &wgpu::Device) -> Scopes {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    Scopes { validation, oom }
}

fn close(scopes: Scopes) -> Option<String> {
    let Scopes { validation, oom } = scopes;
    let v = pollster::block_on(validation.pop());
    let o = pollster::block_on(oom.pop());
    v.or(o).map(|e| e.to_string())
}

impl Session {
    /// Creates every resource, module, pipeline and bind group of the plan.
    pub fn new(ctx: &GpuContext, plan: Plan) -> Result<Self, ReplayError> {
        let device = ctx.device.clone();
        let queue = ctx.queue.clone();
        let textures = create::textures(&device, &queue, &plan)?;
        let buffers = create::buffers(&device, &queue, &plan)?;
        let samplers = create::samplers(&device, &plan)?;
        let meshes = create::meshes(&device, &queue, &plan);
        let modules = create::modules(&device, &plan)?;
        let timestamps = stamps::Timestamps::create(&device, plan.passes.len());
        let timestamp_period = queue.get_timestamp_period();
        let statistics = counters::Statistics::create(&device, &plan.passes);
        let mut session = Session {
            faults: ctx.faults.clone(),
            views: Default::default(),
            mip_groups: Default::default(),
            device,
            queue,
            plan,
            textures,
            buffers,
            samplers,
            meshes,
            modules,
            prepared: Vec::new(),
            mip_pipelines: BTreeMap::new(),
            blits: Default::default(),
            unpacks: Default::default(),
            depth_copies: depth_copy::pipelines(),
            clear_rects: Default::default(),
            timestamps,
            stamp_plan: Default::default(),
            timestamp_period,
            statistics,
            counting: false,
            count_plan: Default::default(),
            frames_run: 0,
            vk: Default::default(),
            vk_layouts: Vec::new(),
            step_limit: Default::default(),
        };
        session.create_vk()?;
        session.create_clear_pipelines()?;
        for i in 0..session.plan.passes.len() {
            let p = session.prepare(i)?;
            session.prepared.push(p);
        }
        session.check_faults("setting up the replay")?;
        Ok(session)
    }

    /// Turns errors recorded outside error scopes, or a lost device, into an error.
    pub fn check_faults(&self, during: &str) -> Result<(), ReplayError> {
        if let Some(reason) = self.faults.lost() {
            return Err(ReplayError::DeviceLost(reason));
        }
        let errors = self.faults.take_uncaptured();
        if errors.is_empty() {
            Ok(())
        } else {
            Err(ReplayError::Setup {
                what: during.to_owned(),
                message: errors.join("; "),
            })
        }
    }

    /// Writes a start and an end stamp for every pass instead of chaining each pass's start to
    /// the previous pass's end (see `stamps`): twice the queries, for comparing the two.
    pub fn set_timestamp_pairs(&mut self, pairs: bool) {
        if let Some(t) = &mut self.timestamps {
            t.pairs = pairs;
        }
    }

    /// Frames submitted or ended so far, whole or stopped part way.
    pub fn frames_run(&self) -> u64 {
        self.frames_run
    }

    /// Whether every pass writes its own start stamp (`set_timestamp_pairs`).
    pub fn timestamp_pairs(&self) -> bool {
        self.timestamps.as_ref().is_some_and(|t| t.pairs)
    }

    /// Counts every pass's pipeline statistics in the frames [`Session::run_frame`] runs from
    /// now on; false when the adapter has no pipeline statistics queries (nothing is counted).
    pub fn set_counting(&mut self, on: bool) -> bool {
        self.counting = on && self.statistics.is_some();
        self.counting || !on
    }

    /// Whether frames count pipeline statistics.
    pub fn counting(&self) -> bool {
        self.counting
    }

    /// Nanoseconds per timestamp tick on this device.
    pub fn timestamp_period(&self) -> f32 {
        self.timestamp_period
    }

    pub fn texture(&self, index: usize) -> &wgpu::Texture {
        // The copy written by the last frame.
        &self.textures[index][self.parity(self.frames_run.saturating_sub(1))]
    }

    pub fn buffer(&self, index: usize) -> &wgpu::Buffer {
        &self.buffers[index][self.parity(self.frames_run.saturating_sub(1))]
    }

    /// The copy of plan texture `index` the frame begun writes (the same as [`Session::texture`]
    /// except for history resources).
    pub fn texture_in_frame(&self, index: usize) -> &wgpu::Texture {
        &self.textures[index][self.parity(self.frames_run)]
    }

    /// The copy of plan buffer `index` the frame begun writes.
    pub fn buffer_in_frame(&self, index: usize) -> &wgpu::Buffer {
        &self.buffers[index][self.parity(self.frames_run)]
    }

    /// How many draws or dispatches a pass encodes now.
    fn steps(&self) -> usize {
        self.step_limit
            .get()
            .map_or(usize::MAX, |l| l.saturating_add(1))
    }

    fn parity(&self, frame: u64) -> usize {
        (frame % 2) as usize
    }
}
