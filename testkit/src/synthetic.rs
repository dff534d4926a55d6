//! Synthetic frames for benchmarks and quality tests: seeded, deterministic frame models and
//! capture files of any size, shaped like real frames (transient targets written then read a
//! few passes later, buffers read-modify-written by compute, a few long-lived resources).

use framelab_core::analysis::model::{
    FrameModel, MQueue, MResource, ModelAccess, ModelPass, ModelResource, QueueInfo, State,
};
use framelab_core::capture::format::{HeapType, QueueType};
use framelab_core::capture::model::ResourceCategory;

/// A small deterministic generator (xorshift64*).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }
}

/// A frame of `passes` passes over `resources` declared resources on graphics, compute and
/// copy queues.
pub fn frame(passes: usize, resources: usize, seed: u64) -> FrameModel {
    let mut rng = Rng::new(seed);
    let queues = vec![
        QueueInfo {
            name: "graphics".into(),
            queue_type: QueueType::Graphics,
        },
        QueueInfo {
            name: "compute".into(),
            queue_type: QueueType::Compute,
        },
        QueueInfo {
            name: "copy".into(),
            queue_type: QueueType::Copy,
        },
    ];
    let res: Vec<ModelResource> = (0..resources)
        .map(|i| {
            let buffer = rng.below(4) == 0;
            let size_class = 1 + rng.below(64);
            let bytes = 65536 * size_class * if buffer { 1 } else { 1 + rng.below(8) };
            ModelResource {
                id: framelab_core::capture::model::ResourceId(i as u32),
                name: format!("r{i}"),
                is_buffer: buffer,
                mips: if buffer { 1 } else { 1 + rng.below(3) as u32 },
                layers: 1,
                buffer_bytes: if buffer { bytes } else { 0 },
                aligned_bytes: bytes,
                alignment: 65536,
                heap_type: HeapType::Default,
                category: if buffer {
                    ResourceCategory::Buffer
                } else {
                    ResourceCategory::RtDsTexture
                },
                history: false,
                output: rng.below(200) == 0,
                swapchain: false,
                initialised: rng.below(100) == 0,
                initial_state: State::COMMON,
                previous_of: None,
            }
        })
        .collect();
    let mut model_passes = Vec::with_capacity(passes);
    // Each pass writes one or two resources, mostly new ones, and reads two to four of the
    // last few dozen written, so lifetimes are short and passes depend on recent work, as in a
    // real frame graph. Declared resources beyond what the passes reach stay unused.
    let mut recent: std::collections::VecDeque<MResource> = std::collections::VecDeque::new();
    let mut next_new = 0usize;
    for p in 0..passes {
        let queue = match rng.below(10) {
            0..=6 => 0,
            7..=8 => 1,
            _ => 2,
        };
        let mut accesses: Vec<ModelAccess> = Vec::new();
        let mut used: Vec<MResource> = Vec::new();
        let writes = 1 + rng.below(2);
        let reads = 2 + rng.below(3);
        for k in 0..writes + reads {
            let write = k < writes;
            let r = if write && (rng.below(4) != 0 || recent.is_empty()) && next_new < resources {
                next_new += 1;
                MResource::new(next_new - 1)
            } else if recent.is_empty() {
                continue;
            } else {
                recent[rng.below(recent.len() as u64) as usize]
            };
            if used.contains(&r) {
                continue;
            }
            used.push(r);
            let resource = &res[r.index()];
            let (state, reads_, writes_, uav) = match (queue, write, resource.is_buffer) {
                (2, true, _) => (State::COPY_DEST, false, true, false),
                (2, false, _) => (State::COPY_SOURCE, true, false, false),
                (1, true, _) => (State::UNORDERED_ACCESS, true, true, true),
                (1, false, _) => (State::NON_PIXEL_SHADER_RESOURCE, true, false, false),
                (_, true, false) => (State::RENDER_TARGET, false, true, false),
                (_, true, true) => (State::UNORDERED_ACCESS, false, true, true),
                (_, false, _) => (State::PIXEL_SHADER_RESOURCE, true, false, false),
            };
            accesses.push(ModelAccess {
                resource: r,
                range: resource.whole(),
                state,
                reads: reads_,
                writes: writes_,
                uav,
            });
            if write {
                recent.push_back(r);
                if recent.len() > 32 {
                    recent.pop_front();
                }
            }
        }
        model_passes.push(ModelPass {
            id: framelab_core::capture::model::PassId(p as u32),
            name: format!("p{p}"),
            queue: MQueue(queue),
            accesses,
            raster: queue == 0,
            sink: p + 1 == passes,
            gpu_ns: Some(10_000 + rng.below(200_000)),
            markers: vec![format!("group{}", p / 50)],
        });
    }
    FrameModel {
        queues,
        resources: res,
        passes: model_passes,
        fences: Vec::new(),
        heap_tier: 2,
    }
}

/// A capture file with `passes` compute and copy passes over `resources` buffers and textures,
/// for load-and-validate throughput measurements.
pub fn capture_json(passes: usize, resources: usize, seed: u64) -> String {
    let mut rng = Rng::new(seed);
    let mut out = String::with_capacity(passes * 400 + resources * 200);
    out.push_str(r#"{"format_version":1,"name":"synthetic","resolution":{"width":1920,"height":1080},"camera":{"position":[0,2,-10],"target":[0,0,0],"fov_y_degrees":60},"queues":[{"name":"gfx","type":"graphics"},{"name":"async","type":"compute"},{"name":"dma","type":"copy"}],"resources":["#);
    for i in 0..resources {
        if i > 0 {
            out.push(',');
        }
        if i % 2 == 0 {
            out.push_str(&format!(r#"{{"name":"buf{i}","kind":"buffer","buffer_kind":"structured","stride":16,"size":{},"flags":["ALLOW_UNORDERED_ACCESS"]}}"#, 16 * (64 + rng.below(4096))));
        } else {
            out.push_str(&format!(r#"{{"name":"tex{i}","kind":"texture_2d","format":"R16G16B16A16_FLOAT","width":"half","height":"half","mip_levels":{},"flags":["ALLOW_RENDER_TARGET"]}}"#, 1 + rng.below(4)));
        }
    }
    out.push_str(r#"],"passes":["#);
    for p in 0..passes {
        if p > 0 {
            out.push(',');
        }
        let a = 2 * (rng.below(resources as u64 / 2) as usize);
        let b = 2 * (rng.below(resources as u64 / 2) as usize);
        if p % 3 == 2 {
            let b = if a == b {
                (b + 2) % (resources - resources % 2).max(2)
            } else {
                b
            };
            out.push_str(&format!(r#"{{"name":"copy{p}","queue":"dma","kind":"copy","markers":["frame","copies"],"copies":[{{"src":{{"resource":"buf{a}","size":256}},"dst":{{"resource":"buf{b}","size":256}}}}]}}"#));
        } else {
            out.push_str(&format!(r#"{{"name":"pass{p}","queue":"async","kind":"compute","markers":["frame","compute"],"shader":{{"file":"compute.wgsl","compute":"cs_main"}},"bindings":{{"particles":{{"resource":"buf{a}","access":"storage_read_write"}},"draw_args":{{"resource":"buf{b}","access":"storage_read_write"}}}},"dispatches":[{{"groups":[{},1,1]}}]}}"#, 1 + rng.below(64)));
        }
    }
    out.push_str("]}\n");
    out
}
