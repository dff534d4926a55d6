// Async-compute particle update: advances 256 orbiting particles and writes the indirect
// draw arguments the scene pass consumes (one instance per live particle).

struct FrameConstants {
    view_proj: mat4x4<f32>,
    prev_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    resolution: vec4<f32>,
    jitter: vec4<f32>,
    time: vec4<f32>,
}

struct Particle {
    position_radius: vec4<f32>,
}

struct DrawIndexedArgs {
    index_count: u32,
    instance_count: atomic<u32>,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

struct Params {
    // Index count of the instanced mesh (the orb), for the indirect draw.
    index_count: u32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(3) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> particles: array<Particle>;
@group(0) @binding(2) var<storage, read_write> draw_args: DrawIndexedArgs;

fn hash(n: u32) -> f32 {
    var x = n * 747796405u + 2891336453u;
    x = ((x >> ((x >> 28u) + 4u)) ^ x) * 277803737u;
    return f32((x >> 22u) ^ x) / 4294967295.0;
}

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i == 0u) {
        draw_args.index_count = params.index_count;
        draw_args.first_index = 0u;
        draw_args.base_vertex = 0;
        draw_args.first_instance = 0u;
    }
    if (i >= arrayLength(&particles)) {
        return;
    }
    let t = frame.time.x;
    let ring = 4.0 + 10.0 * hash(i);
    let speed = 0.2 + 0.6 * hash(i + 7919u);
    let angle = 6.2831853 * hash(i + 104729u) + t * speed;
    let height = 0.5 + 3.0 * hash(i + 1299709u) + 0.3 * sin(t * 2.0 + f32(i));
    let radius = 0.08 + 0.12 * hash(i + 15485863u);
    particles[i].position_radius = vec4<f32>(cos(angle) * ring, height, sin(angle) * ring, radius);
    // Particles below the ground plane are culled from the indirect draw.
    if (height > 0.0) {
        atomicAdd(&draw_args.instance_count, 1u);
    }
}
