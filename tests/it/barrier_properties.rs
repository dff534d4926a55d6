//! Property test: on random frames (passes on up to three queues, random accesses to random
//! mips, layers and byte ranges, random declared fences), the derived barriers and fences leave
//! the independent hazard checker nothing to report, and none of them can be removed.

use framelab_core::analysis::model::{
    FrameModel, MPass, MQueue, MResource, ModelAccess, ModelPass, ModelResource, QueueInfo, State,
};
use framelab_core::analysis::units::Units;
use framelab_core::analysis::{barriers, graph, hazards, to_sync};
use framelab_core::capture::format::{HeapType, QueueType};
use framelab_core::capture::model::{ResourceCategory, Subresources};
use proptest::prelude::*;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len() as u64) as usize]
    }
}

/// (state, reads, writes, uav, textures?, buffers?)
type Kind = (State, bool, bool, bool, bool, bool);
const GRAPHICS: &[Kind] = &[
    (State::PIXEL_SHADER_RESOURCE, true, false, false, true, true),
    (
        State::NON_PIXEL_SHADER_RESOURCE,
        true,
        false,
        false,
        true,
        true,
    ),
    (State::RENDER_TARGET, false, true, false, true, false),
    (State::RENDER_TARGET, true, true, false, true, false),
    (State::DEPTH_WRITE, true, true, false, true, false),
    (State::DEPTH_READ, true, false, false, true, false),
    (State::UNORDERED_ACCESS, true, false, true, true, true),
    (State::UNORDERED_ACCESS, false, true, true, true, true),
    (State::UNORDERED_ACCESS, true, true, true, true, true),
    (State::COPY_SOURCE, true, false, false, true, true),
    (State::COPY_DEST, false, true, false, true, true),
    (State::INDIRECT_ARGUMENT, true, false, false, false, true),
    (
        State::VERTEX_AND_CONSTANT_BUFFER,
        true,
        false,
        false,
        false,
        true,
    ),
];
const COMPUTE: &[Kind] = &[
    (
        State::NON_PIXEL_SHADER_RESOURCE,
        true,
        false,
        false,
        true,
        true,
    ),
    (State::UNORDERED_ACCESS, true, false, true, true, true),
    (State::UNORDERED_ACCESS, false, true, true, true, true),
    (State::UNORDERED_ACCESS, true, true, true, true, true),
    (State::COPY_SOURCE, true, false, false, true, true),
    (State::COPY_DEST, false, true, false, true, true),
    (State::INDIRECT_ARGUMENT, true, false, false, false, true),
];
const COPY: &[Kind] = &[
    (State::COPY_SOURCE, true, false, false, true, true),
    (State::COPY_DEST, false, true, false, true, true),
];

fn random_frame(seed: u64) -> FrameModel {
    let mut rng = Rng(seed | 1);
    let queue_types = [QueueType::Graphics, QueueType::Compute, QueueType::Copy];
    let nq = 1 + rng.below(3) as usize;
    let queues = (0..nq)
        .map(|i| QueueInfo {
            name: format!("q{i}"),
            queue_type: queue_types[i],
        })
        .collect();
    let nr = 1 + rng.below(6) as usize;
    let resources: Vec<ModelResource> = (0..nr)
        .map(|i| {
            let buffer = rng.below(3) == 0;
            ModelResource {
                id: framelab_core::capture::model::ResourceId(i as u32),
                name: format!("r{i}"),
                is_buffer: buffer,
                mips: if buffer { 1 } else { 1 + rng.below(3) as u32 },
                layers: if buffer { 1 } else { 1 + rng.below(3) as u32 },
                buffer_bytes: if buffer { 256 } else { 0 },
                aligned_bytes: 65536,
                alignment: 65536,
                heap_type: HeapType::Default,
                category: if buffer {
                    ResourceCategory::Buffer
                } else {
                    ResourceCategory::RtDsTexture
                },
                history: false,
                output: rng.below(4) == 0,
                swapchain: false,
                initialised: rng.below(2) == 0,
                initial_state: State::COMMON,
                previous_of: None,
            }
        })
        .collect();
    let np = 1 + rng.below(12) as usize;
    let mut passes = Vec::new();
    for i in 0..np {
        let queue = rng.below(nq as u64) as u32;
        let kinds = match queue_types[queue as usize] {
            QueueType::Graphics => GRAPHICS,
            QueueType::Compute => COMPUTE,
            QueueType::Copy => COPY,
        };
        let mut accesses = Vec::new();
        let mut used = Vec::new();
        for _ in 0..1 + rng.below(4) {
            let resource = rng.below(nr as u64) as u32;
            if used.contains(&resource) {
                continue;
            }
            let r = &resources[resource as usize];
            let fitting: Vec<Kind> = kinds
                .iter()
                .copied()
                .filter(|k| if r.is_buffer { k.5 } else { k.4 })
                .collect();
            if fitting.is_empty() {
                continue;
            }
            used.push(resource);
            let (state, reads, writes, uav, _, _) = rng.pick(&fitting);
            let range = if r.is_buffer {
                let offset = 16 * rng.below(16);
                let size = 16 * (1 + rng.below((256 - offset) / 16));
                Subresources {
                    mip_base: 0,
                    mip_count: 1,
                    layer_base: 0,
                    layer_count: 1,
                    byte_offset: offset,
                    byte_size: size,
                }
            } else {
                let mip_base = rng.below(r.mips as u64) as u32;
                let layer_base = rng.below(r.layers as u64) as u32;
                let mip_count = 1 + rng.below((r.mips - mip_base) as u64) as u32;
                let layer_count = 1 + rng.below((r.layers - layer_base) as u64) as u32;
                Subresources {
                    mip_base,
                    mip_count,
                    layer_base,
                    layer_count,
                    byte_offset: 0,
                    byte_size: 0,
                }
            };
            accesses.push(ModelAccess {
                resource: MResource(resource),
                range,
                state,
                reads,
                writes,
                uav,
            });
        }
        passes.push(ModelPass {
            id: framelab_core::capture::model::PassId(i as u32),
            name: format!("p{i}"),
            queue: MQueue(queue),
            accesses,
            raster: queue_types[queue as usize] == QueueType::Graphics && rng.below(2) == 0,
            sink: rng.below(8) == 0,
            gpu_ns: Some(1000 + rng.below(100_000)),
            markers: vec![],
        });
    }
    let mut fences = Vec::new();
    for _ in 0..rng.below(3) {
        let (a, b) = (rng.below(np as u64) as u32, rng.below(np as u64) as u32);
        if a < b && passes[a as usize].queue != passes[b as usize].queue {
            fences.push((MPass(a), MPass(b)));
        }
    }
    FrameModel {
        queues,
        resources,
        passes,
        fences,
        heap_tier: 2,
    }
}

fn check_frame(seed: u64) -> Result<(), String> {
    let model = random_frame(seed);
    let units = Units::new(&model);
    let g = graph::build(&model, &units);
    let order = graph::order(&model, &g).map_err(|e| format!("random frames are acyclic: {e}"))?;
    let plan = barriers::derive(&model, &units, &g, &order);
    let sync: Vec<_> = plan.barriers.iter().filter_map(to_sync).collect();
    let fences: Vec<(MPass, MPass)> = plan
        .fences
        .iter()
        .map(|f| (f.signal_after, f.wait_before))
        .collect();
    let report = hazards::check(&model, &units, &order, &sync, &fences, &plan.initial_states);
    if !report.is_clean() {
        return Err(format!(
            "seed {seed}: {report:#?}\nmodel: {model:#?}\nbarriers: {:#?}\nfences: {fences:?}",
            plan.barriers
        ));
    }
    let redundant =
        hazards::redundant(&model, &units, &order, &sync, &fences, &plan.initial_states);
    if !redundant.is_empty() {
        return Err(format!(
            "seed {seed}: redundant barriers {redundant:?}: {:#?}\nmodel: {model:#?}",
            redundant.iter().map(|&i| &sync[i]).collect::<Vec<_>>()
        ));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() })]
    #[test]
    fn derived_barriers_leave_no_hazard_and_none_is_redundant(seed in any::<u64>()) {
        if let Err(e) = check_frame(seed) {
            prop_assert!(false, "{}", e);
        }
    }
}

/// The checker is not vacuous: dropping a needed barrier, or a derived fence, is caught.
#[test]
fn checker_catches_missing_synchronisation() {
    let mut caught_barrier = 0;
    let mut caught_fence = 0;
    for seed in 1..400u64 {
        let model = random_frame(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let order = graph::order(&model, &g).unwrap();
        let plan = barriers::derive(&model, &units, &g, &order);
        let sync: Vec<_> = plan.barriers.iter().filter_map(to_sync).collect();
        let fences: Vec<(MPass, MPass)> = plan
            .fences
            .iter()
            .map(|f| (f.signal_after, f.wait_before))
            .collect();
        if !sync.is_empty() {
            let fewer = &sync[1..];
            assert!(
                !hazards::check(&model, &units, &order, fewer, &fences, &plan.initial_states)
                    .is_clean()
            );
            caught_barrier += 1;
        }
        if let Some(i) = plan.fences.iter().position(|f| !f.declared) {
            let mut fewer = fences.clone();
            fewer.remove(i);
            assert!(
                !hazards::check(&model, &units, &order, &sync, &fewer, &plan.initial_states)
                    .is_clean(),
                "seed {seed}"
            );
            caught_fence += 1;
        }
    }
    assert!(
        caught_barrier > 100 && caught_fence > 10,
        "{caught_barrier} {caught_fence}"
    );
}
