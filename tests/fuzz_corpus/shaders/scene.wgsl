// Forward scene pass: a textured ground grid and instanced glowing orbs whose positions come
// from the async-compute particle buffer. Lambert + Blinn-Phong sun, HDR output.

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

struct Params {
    ground_tint: vec4<f32>,
    orb_emissive: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var noise: texture_2d<f32>;
@group(0) @binding(3) var linear_wrap: sampler;
@group(0) @binding(4) var<storage, read> particles: array<Particle>;

struct VertexIn {
    @location(0) position: vec4<f32>,   // snorm16x4, scaled by w
    @location(1) uv: vec2<f32>,         // float16x2
    @location(2) normal: vec4<f32>,     // packed 10:10:10:2, biased to unsigned
    @builtin(instance_index) instance: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) kind: u32,
}

@vertex
fn vs_ground(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let world = v.position.xyz * 64.0;
    out.world = world;
    out.normal = normalize(v.normal.xyz * 2.0 - 1.0);
    out.uv = v.uv * 8.0;
    out.clip = frame.view_proj * vec4<f32>(world, 1.0);
    out.kind = 0u;
    return out;
}

@vertex
fn vs_orb(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let p = particles[v.instance].position_radius;
    let world = p.xyz + v.position.xyz * p.w;
    out.world = world;
    out.normal = normalize(v.normal.xyz * 2.0 - 1.0);
    out.uv = v.uv;
    out.clip = frame.view_proj * vec4<f32>(world, 1.0);
    out.kind = 1u;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    let l = normalize(frame.sun_direction.xyz);
    let v = normalize(frame.camera_position.xyz - in.world);
    let h = normalize(l + v);
    if (in.kind == 1u) {
        let rim = pow(1.0 - max(dot(n, v), 0.0), 2.0);
        return vec4<f32>(params.orb_emissive.rgb * (0.6 + 2.0 * rim), 1.0);
    }
    let tex = textureSample(noise, linear_wrap, in.uv).rgb;
    let albedo = params.ground_tint.rgb * (0.5 + 0.5 * tex);
    let diffuse = albedo * max(dot(n, l), 0.0) * frame.sun_color.rgb;
    let specular = pow(max(dot(n, h), 0.0), 64.0) * 0.2 * frame.sun_color.rgb;
    let ambient = albedo * 0.08;
    return vec4<f32>(ambient + diffuse + specular, 1.0);
}
