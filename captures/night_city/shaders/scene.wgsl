// The district's geometry, shared by every pass that rasterises the scene: the top-view sky
// visibility depth, the depth pre-pass, the base material (G-buffer) pass, the four shadow
// cascades, the CSM proxy, the omni-light shadow maps, the environment probe and the
// transparent pass (holograms and the water surface). Each pass picks its camera with
// `params.view`; the vertex functions are the same in every pass so the pre-pass depth and
// the base pass depth agree exactly (the base pass tests with less_equal).
//
// Vertex layout (structure of arrays, as the frame's engine uses): VB0 POSITION snorm16x4 (xyz
// scaled by the power of two in w * 4096), VB1 TEXCOORD0 float16x2, VB2 NORMAL and TANGENT
// packed 10:10:10:2, VB3 COLOR0 unorm8x4 + TEXCOORD1 float16x2. Dynamic objects (cars, people,
// holographic signs) come from `instance_data`, written by the instance_prep compute pass.

struct FrameConstants {
    view_proj: mat4x4<f32>,
    prev_view_proj: mat4x4<f32>,
    csm_view_proj_0: mat4x4<f32>,
    csm_view_proj_1: mat4x4<f32>,
    csm_view_proj_2: mat4x4<f32>,
    csm_view_proj_3: mat4x4<f32>,
    top_view_proj: mat4x4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    jitter: vec4<f32>,
    time: vec4<f32>,
    camera_position: vec4<f32>,
    resolution: vec4<f32>,
    view: mat4x4<f32>,
}

struct Params {
    // 0 camera, 1-4 shadow cascade 0-3, 5 top view, 6 omni light (paraboloid), 7 CSM proxy.
    view: u32,
    // Which material the fragment stage writes (see fs_gbuffer).
    material: u32,
    // Light index for omni shadow views.
    light: u32,
    // First instance_data record of this draw's instances (the compacted list of its kind).
    instance_base: u32,
    // Static meshes: world = local * scale + offset.
    offset: vec4<f32>,
    scale: vec4<f32>,
    // Object mask written to the albedo alpha (2 bits).
    object_mask: f32,
    // Environment capture: probe position and cube face (view 8).
    probe: vec4<f32>,
    face: u32,
}

struct Instance {
    row0: vec4<f32>,
    row1: vec4<f32>,
    row2: vec4<f32>,
    // xyz: previous frame translation; w: kind * 16 + variant.
    prev: vec4<f32>,
}

struct Light {
    position_radius: vec4<f32>,
    color_intensity: vec4<f32>,
    direction_cone: vec4<f32>,
    extra: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var<storage, read> instance_data: array<Instance>;
@group(0) @binding(3) var voxel_normals: texture_3d<f32>;
@group(0) @binding(4) var billboard_atlas: texture_2d<f32>;
@group(0) @binding(5) var terrain_layers: texture_2d_array<f32>;
@group(0) @binding(6) var ocean_height: texture_2d<f32>;
@group(0) @binding(7) var blue_noise: texture_2d<f32>;
@group(0) @binding(9) var linear_clamp: sampler;
@group(0) @binding(10) var<storage, read> lights: array<Light>;
@group(0) @binding(11) var transparent_lut: texture_2d<f32>;
@group(0) @binding(12) var water_reflection: texture_2d<f32>;

// World extents shared with the terrain-map, voxel and lighting passes.
const CITY_MIN: vec2<f32> = vec2<f32>(-104.0, -156.0);
const CITY_MAX: vec2<f32> = vec2<f32>(92.0, 144.0);
const BLOCK_PITCH: f32 = 52.0;
const BLOCK_SIZE: f32 = 40.0;
const WATER_LEVEL: f32 = -1.5;
const TERRAIN_MAP_EXTENT: f32 = 600.0;
const VOXEL_MIN: vec3<f32> = vec3<f32>(-160.0, -32.0, -200.0);
const VOXEL_SIZE: vec3<f32> = vec3<f32>(320.0, 160.0, 400.0);

struct VertexIn {
    @location(0) position: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) normal: vec4<f32>,
    @location(3) tangent: vec4<f32>,
    @location(4) color: vec4<f32>,
    @location(5) uv1: vec2<f32>,
    @builtin(instance_index) instance: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) color: vec4<f32>,
    @location(4) prev_clip: vec4<f32>,
    @location(5) cur_clip: vec4<f32>,
    @location(6) @interpolate(flat) variant: u32,
}

fn hash21(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(123.34, 456.21));
    let r = q + dot(q, q + 45.32);
    return fract(r.x * r.y);
}

fn noise2(p: vec2<f32>) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let a = hash21(i);
    let b = hash21(i + vec2<f32>(1.0, 0.0));
    let c = hash21(i + vec2<f32>(0.0, 1.0));
    let d = hash21(i + vec2<f32>(1.0, 1.0));
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

fn fbm2(p: vec2<f32>) -> f32 {
    var s = 0.0;
    var a = 0.5;
    var q = p;
    for (var i = 0; i < 5; i++) {
        s += a * noise2(q);
        q = q * 2.03 + vec2<f32>(17.1, 9.7);
        a *= 0.5;
    }
    return s;
}

// Terrain height: rolling hills outside the city, flat streets inside, dropping under the river
// past the riverside park.
fn terrain_height(xz: vec2<f32>) -> f32 {
    let outside = max(max(CITY_MIN - xz, xz - CITY_MAX), vec2<f32>(0.0));
    let d = length(outside);
    let hills = max(fbm2(xz * 0.006) * 70.0 - 22.0, 0.0) + fbm2(xz * 0.05) * 1.5;
    // The river: a band past the riverside park where the hills give way to the riverbed.
    let river = smoothstep(165.0, 200.0, xz.y) * (1.0 - smoothstep(430.0, 480.0, xz.y));
    return hills * smoothstep(10.0, 90.0, d) * (1.0 - river) - river * 9.0;
}

fn decode_position(p: vec4<f32>) -> vec3<f32> {
    return p.xyz * exp2(round(log2(max(p.w * 4096.0, 1.0))));
}

fn view_matrix(view: u32) -> mat4x4<f32> {
    switch view {
        case 1u: { return frame.csm_view_proj_0; }
        case 2u: { return frame.csm_view_proj_1; }
        case 3u: { return frame.csm_view_proj_2; }
        case 4u, 7u: { return frame.csm_view_proj_3; }
        case 5u: { return frame.top_view_proj; }
        case 8u: { return cube_face_view_proj(params.face, params.probe.xyz); }
        default: { return frame.view_proj; }
    }
}

fn look_to(eye: vec3<f32>, dir: vec3<f32>, up: vec3<f32>) -> mat4x4<f32> {
    let f = normalize(dir);
    let s = normalize(cross(f, up));
    let u = cross(s, f);
    return mat4x4<f32>(
        vec4<f32>(s.x, u.x, -f.x, 0.0),
        vec4<f32>(s.y, u.y, -f.y, 0.0),
        vec4<f32>(s.z, u.z, -f.z, 0.0),
        vec4<f32>(-dot(s, eye), -dot(u, eye), dot(f, eye), 1.0));
}

// 90-degree perspective per cube face (D3D/Vulkan face order and orientation; the image's y
// runs down, hence the flipped x in the projection for a right-handed look-at).
fn cube_face_view_proj(face: u32, eye: vec3<f32>) -> mat4x4<f32> {
    var dir = vec3<f32>(1.0, 0.0, 0.0);
    var up = vec3<f32>(0.0, -1.0, 0.0);
    switch face {
        case 0u: { dir = vec3<f32>(1.0, 0.0, 0.0); }
        case 1u: { dir = vec3<f32>(-1.0, 0.0, 0.0); }
        case 2u: { dir = vec3<f32>(0.0, 1.0, 0.0); up = vec3<f32>(0.0, 0.0, 1.0); }
        case 3u: { dir = vec3<f32>(0.0, -1.0, 0.0); up = vec3<f32>(0.0, 0.0, -1.0); }
        case 4u: { dir = vec3<f32>(0.0, 0.0, 1.0); }
        default: { dir = vec3<f32>(0.0, 0.0, -1.0); }
    }
    let near = 0.5;
    let far = 1000.0;
    let proj = mat4x4<f32>(
        vec4<f32>(-1.0, 0.0, 0.0, 0.0),
        vec4<f32>(0.0, -1.0, 0.0, 0.0),
        vec4<f32>(0.0, 0.0, far / (near - far), -1.0),
        vec4<f32>(0.0, 0.0, near * far / (near - far), 0.0));
    return proj * look_to(eye, dir, up);
}

// Omni lights hang above the street and light downwards: one paraboloid covering the lower
// hemisphere of light `params.light` (Brabec et al., "Shadow mapping for hemispherical and
// omnidirectional light sources").
fn paraboloid(world: vec3<f32>) -> vec4<f32> {
    let l = lights[params.light].position_radius;
    let v = world - l.xyz;
    let dist = length(v);
    let dir = v / max(dist, 1e-4);
    // Looking down -Y: the paraboloid maps the hemisphere dir.y <= 0.
    let xy = dir.xz / (1.0 - dir.y);
    let range = l.w * 2.0;
    return vec4<f32>(xy, clamp(dist / range, 0.0, 1.0), 1.0);
}

fn finish(out_in: VertexOut, world: vec3<f32>, prev_world: vec3<f32>) -> VertexOut {
    var out = out_in;
    out.world = world;
    out.clip = view_matrix(params.view) * vec4<f32>(world, 1.0);
    out.cur_clip = frame.view_proj * vec4<f32>(world, 1.0);
    out.prev_clip = frame.prev_view_proj * vec4<f32>(prev_world, 1.0);
    return out;
}

// Omni shadow views re-project a vertex into the light's paraboloid.
fn to_paraboloid(in: VertexOut) -> VertexOut {
    var out = in;
    out.clip = paraboloid(in.world);
    // Geometry above the light is behind the paraboloid: push it outside the clip volume.
    if (in.world.y > lights[params.light].position_radius.y + 0.5) {
        out.clip = vec4<f32>(0.0, 0.0, 2.0, 1.0);
    }
    return out;
}

fn base_out(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.normal = normalize(v.normal.xyz * 2.0 - 1.0);
    out.uv = v.uv;
    out.color = v.color;
    out.variant = 0u;
    return out;
}

// Buildings, foliage cards, decals: static meshes placed by the draw's offset and scale.
@vertex
fn vs_static(v: VertexIn) -> VertexOut {
    return static_vertex(v);
}

@vertex
fn vs_omni_static(v: VertexIn) -> VertexOut {
    return to_paraboloid(static_vertex(v));
}

fn static_vertex(v: VertexIn) -> VertexOut {
    let out = base_out(v);
    var world = decode_position(v.position) * params.scale.xyz + params.offset.xyz;
    if (params.material == 7u) {
        // Decals float just above the street they lie on.
        world.y = terrain_height(world.xz) + 0.03;
    }
    return finish(out, world, world);
}

// Foliage cards sway in the wind; the bend also follows the voxel normal field, so cards near
// walls lean away from them and cards on slopes lean downhill. Every pass that draws foliage
// uses this function, so their depths agree.
@vertex
fn vs_foliage(v: VertexIn) -> VertexOut {
    let out = base_out(v);
    var local = decode_position(v.position) * params.scale.xyz;
    let vuv = (local + params.offset.xyz - VOXEL_MIN) / VOXEL_SIZE;
    let g = textureSampleLevel(voxel_normals, linear_clamp, vuv, 0.0).xyz;
    let sway = sin(frame.time.x * 1.7 + local.x * 0.3 + local.z * 0.2) * 0.15;
    let bend = (vec3<f32>(sway, 0.0, sway * 0.5) + vec3<f32>(g.x, 0.0, g.z) * 0.2) * max(local.y, 0.0) / 4.0;
    let prev_sway = sin((frame.time.x - frame.time.y) * 1.7 + local.x * 0.3 + local.z * 0.2) * 0.15;
    let prev_bend = (vec3<f32>(prev_sway, 0.0, prev_sway * 0.5) + vec3<f32>(g.x, 0.0, g.z) * 0.2) * max(local.y, 0.0) / 4.0;
    let world = local + bend + params.offset.xyz;
    return finish(out, world, local + prev_bend + params.offset.xyz);
}

// Buildings: a unit box per lot, placed and sized by the VB7 instance rows (three float4 rows
// of an affine transform, the seed's per-instance layout).
struct BuildingIn {
    @location(0) position: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) normal: vec4<f32>,
    @location(4) color: vec4<f32>,
    @location(6) row0: vec4<f32>,
    @location(7) row1: vec4<f32>,
    @location(8) row2: vec4<f32>,
}

fn building_vertex(v: BuildingIn) -> VertexOut {
    var out: VertexOut;
    let p = vec4<f32>(decode_position(v.position), 1.0);
    let world = vec3<f32>(dot(v.row0, p), dot(v.row1, p), dot(v.row2, p));
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    out.normal = normalize(vec3<f32>(n.x * sign(v.row0.x), n.y, n.z * sign(v.row2.z)));
    out.uv = v.uv;
    // A per-building tint and window seed from the lot position.
    let lot = vec2<f32>(v.row0.w, v.row2.w);
    out.color = vec4<f32>(hash21(lot * 0.013), hash21(lot * 0.029 + 3.1), hash21(lot * 0.047 + 7.3), 1.0);
    out.variant = 0u;
    return finish(out, world, world);
}

@vertex
fn vs_building(v: BuildingIn) -> VertexOut {
    return building_vertex(v);
}

@vertex
fn vs_omni_building(v: BuildingIn) -> VertexOut {
    return to_paraboloid(building_vertex(v));
}

// Terrain: a flat grid displaced by terrain_height, so every pass agrees on the ground.
@vertex
fn vs_terrain(v: VertexIn) -> VertexOut {
    return terrain_vertex(v);
}

// Shadow views of the ground: its shape without the normal, whose four more heights (eight
// fbm evaluations) nothing in a depth-only or distance-only view reads.
@vertex
fn vs_terrain_depth(v: VertexIn) -> VertexOut {
    let world = terrain_world(v);
    return finish(base_out(v), world, world);
}

@vertex
fn vs_omni_terrain(v: VertexIn) -> VertexOut {
    let world = terrain_world(v);
    return to_paraboloid(finish(base_out(v), world, world));
}

fn terrain_world(v: VertexIn) -> vec3<f32> {
    let local = decode_position(v.position) * params.scale.xyz + params.offset.xyz;
    return vec3<f32>(local.x, terrain_height(local.xz), local.z);
}

fn terrain_vertex(v: VertexIn) -> VertexOut {
    var out = base_out(v);
    let local = decode_position(v.position) * params.scale.xyz + params.offset.xyz;
    let h = terrain_height(local.xz);
    let world = vec3<f32>(local.x, h, local.z);
    let e = 1.0;
    let hx = terrain_height(local.xz + vec2<f32>(e, 0.0)) - terrain_height(local.xz - vec2<f32>(e, 0.0));
    let hz = terrain_height(local.xz + vec2<f32>(0.0, e)) - terrain_height(local.xz - vec2<f32>(0.0, e));
    out.normal = normalize(vec3<f32>(-hx, 2.0 * e, -hz));
    out.uv = local.xz;
    return finish(out, world, world);
}

// Water: a plate displaced by the ocean height map written by the ocean_wave pass.
@vertex
fn vs_water(v: VertexIn) -> VertexOut {
    var out = base_out(v);
    let local = decode_position(v.position) * params.scale.xyz + params.offset.xyz;
    let uv = (local.xz - params.offset.xz) / TERRAIN_MAP_EXTENT + 0.5;
    let texel = 1.0 / vec2<f32>(textureDimensions(ocean_height));
    let h = textureSampleLevel(ocean_height, linear_clamp, uv, 0.0).r;
    let hx = textureSampleLevel(ocean_height, linear_clamp, uv + vec2<f32>(texel.x, 0.0), 0.0).r - h;
    let hz = textureSampleLevel(ocean_height, linear_clamp, uv + vec2<f32>(0.0, texel.y), 0.0).r - h;
    let amplitude = 1.2;
    let world = vec3<f32>(local.x, WATER_LEVEL + (h - 0.5) * amplitude, local.z);
    let step = TERRAIN_MAP_EXTENT * texel.x;
    out.normal = normalize(vec3<f32>(-hx * amplitude, step, -hz * amplitude));
    out.uv = local.xz;
    return finish(out, world, world);
}

fn instance_world(inst: Instance, p: vec3<f32>) -> vec3<f32> {
    let q = vec4<f32>(p, 1.0);
    return vec3<f32>(dot(inst.row0, q), dot(inst.row1, q), dot(inst.row2, q));
}

fn instance_normal(inst: Instance, n: vec3<f32>) -> vec3<f32> {
    return normalize(vec3<f32>(dot(inst.row0.xyz, n), dot(inst.row1.xyz, n), dot(inst.row2.xyz, n)));
}

fn instanced(v: VertexIn, local: vec3<f32>, n: vec3<f32>) -> VertexOut {
    var out = base_out(v);
    let inst = instance_data[params.instance_base + v.instance];
    let world = instance_world(inst, local);
    let translation = vec3<f32>(inst.row0.w, inst.row1.w, inst.row2.w);
    let prev_world = world - translation + inst.prev.xyz;
    out.normal = instance_normal(inst, n);
    out.variant = u32(inst.prev.w);
    return finish(out, world, prev_world);
}

// Cars and holographic sign panels: a unit box stretched by the instance transform.
@vertex
fn vs_instanced(v: VertexIn) -> VertexOut {
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    return instanced(v, decode_position(v.position), n);
}

@vertex
fn vs_omni_instanced(v: VertexIn) -> VertexOut {
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    return to_paraboloid(instanced(v, decode_position(v.position), n));
}

// Characters: the capsule mesh is the body; the head and hair reuse it, squashed.
fn character_body(v: VertexIn) -> VertexOut {
    let p = decode_position(v.position);
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    return instanced(v, vec3<f32>(p.x, p.y * 0.8 + 0.72, p.z), n);
}

@vertex
fn vs_character_body(v: VertexIn) -> VertexOut {
    return character_body(v);
}

@vertex
fn vs_omni_character(v: VertexIn) -> VertexOut {
    return to_paraboloid(character_body(v));
}

@vertex
fn vs_character_head(v: VertexIn) -> VertexOut {
    let p = decode_position(v.position);
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    return instanced(v, p * vec3<f32>(0.42, 0.14, 0.45) + vec3<f32>(0.0, 1.62, 0.02), n);
}

@vertex
fn vs_character_hair(v: VertexIn) -> VertexOut {
    var p = decode_position(v.position);
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    // Only the top of the squashed capsule: a cap over the head, slightly larger than it.
    p.y = max(p.y, 0.1);
    return instanced(v, p * vec3<f32>(0.47, 0.16, 0.5) + vec3<f32>(0.0, 1.66, 0.0), n);
}

@vertex
fn vs_character_fur(v: VertexIn) -> VertexOut {
    var p = decode_position(v.position);
    let n = normalize(v.normal.xyz * 2.0 - 1.0);
    p.y = max(p.y, 0.0);
    // The fur shell sits outside the hair cap; fs_gbuffer cuts it into strands.
    var out = instanced(v, p * vec3<f32>(0.52, 0.19, 0.55) + vec3<f32>(0.0, 1.66, 0.0), n);
    out.variant = out.variant | 0x1000u;
    return out;
}

// ---------------------------------------------------------------------------------------------
// Fragment stages

fn foliage_alpha(uv: vec2<f32>) -> f32 {
    // A leafy silhouette: a trunk and a noisy crown.
    let trunk = step(abs(uv.x - 0.5), 0.04) * step(uv.y, 0.45);
    let c = uv - vec2<f32>(0.5, 0.62);
    let crown = fbm2(uv * 9.0) * 0.35 + 0.32 - length(c * vec2<f32>(1.0, 1.3));
    return max(trunk, step(0.0, crown));
}

fn fur_alpha(world: vec3<f32>) -> f32 {
    return step(0.45, hash21(floor(world.xz * 140.0)));
}

// Depth-only passes still cut out foliage and fur, or their shadows and depth would be cards.
@fragment
fn fs_depth(in: VertexOut) {
    if (params.material == 6u && foliage_alpha(in.uv) < 0.5) {
        discard;
    }
    if (params.material == 8u && (in.variant & 0x1000u) != 0u && fur_alpha(in.world) < 0.5) {
        discard;
    }
}

// Omni shadow depth also stores linear distance in the colour-less R32 target's depth: the
// fragment depth is the normalised distance, not the paraboloid's z.
@fragment
fn fs_omni_depth(in: VertexOut) -> @builtin(frag_depth) f32 {
    if (params.material == 6u && foliage_alpha(in.uv) < 0.5) {
        discard;
    }
    let l = lights[params.light].position_radius;
    return clamp(length(in.world - l.xyz) / (l.w * 2.0), 0.0, 1.0);
}

struct GBuffer {
    @location(0) albedo: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) material: vec4<f32>,
    @location(3) motion: vec2<f32>,
}

fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn window_pattern(world: vec3<f32>, n: vec3<f32>, seed: f32) -> vec2<f32> {
    // Facade coordinates: along the wall and up.
    let along = select(world.x, world.z, abs(n.x) > 0.5);
    let cell = vec2<f32>(along / 3.2, world.y / 3.6);
    let f = fract(cell);
    let inside = step(0.18, f.x) * step(f.x, 0.82) * step(0.25, f.y) * step(f.y, 0.8);
    // Integer hash of the window cell and the building, so every texel of a window agrees.
    let c = vec2<i32>(floor(cell));
    let h = pcg(u32(c.x + 4096) * 7919u + u32(c.y + 4096) * 104729u + u32(seed * 1000.0));
    let lit = step(0.55, f32(h & 0xFFFFu) / 65535.0);
    let ground_floor = step(world.y, 3.2);
    return vec2<f32>(inside * (1.0 - ground_floor), lit);
}

// What the G-buffer holds for a fragment, and whether the material's cut-out (foliage cards,
// decal stripes, fur strands) keeps it.
struct Surface {
    out: GBuffer,
    keep: bool,
}

fn gbuffer_surface(in: VertexOut) -> Surface {
    var keep = true;
    var n = normalize(in.normal);
    var albedo = vec3<f32>(0.5);
    var metal = 0.0;
    var rough = 0.6;
    var emissive = 0.0;
    var mask = params.object_mask;
    switch params.material {
        case 0u: {
            // Buildings: concrete and glass facades, windows lit at random.
            let seed = in.color.r * 7.0 + in.color.g * 3.0;
            let tint = mix(vec3<f32>(0.32, 0.31, 0.3), in.color.rgb * 0.6 + 0.15, 0.45);
            let w = window_pattern(in.world, n, seed);
            let roof = step(0.9, n.y);
            albedo = mix(tint, vec3<f32>(0.05, 0.07, 0.09), w.x * (1.0 - roof));
            metal = w.x * (1.0 - roof) * 0.9;
            rough = mix(0.75, 0.08, w.x * (1.0 - roof));
            emissive = w.x * w.y * (1.0 - roof) * 0.35;
            albedo = mix(albedo, vec3<f32>(1.0, 0.78, 0.5), w.x * w.y * (1.0 - roof) * 0.6);
        }
        case 1u: {
            // Ground: layered materials from the terrain layer maps; streets inside the city.
            let uv = in.world.xz / TERRAIN_MAP_EXTENT + 0.5;
            let layers = textureSample(terrain_layers, linear_clamp, uv, 0);
            let grass = vec3<f32>(0.16, 0.26, 0.08);
            let rock = vec3<f32>(0.35, 0.33, 0.3);
            let sand = vec3<f32>(0.55, 0.5, 0.38);
            let asphalt = vec3<f32>(0.08, 0.08, 0.085);
            let walk = vec3<f32>(0.36, 0.35, 0.34);
            let detail = 0.85 + 0.3 * noise2(in.world.xz * 1.7);
            albedo = (grass * layers.r + rock * layers.g + sand * layers.b + asphalt * layers.a) * detail;
            let total = layers.r + layers.g + layers.b + layers.a;
            albedo = albedo / max(total, 1e-3);
            // Sidewalks: the 3 m band of each block facing the street.
            let inblock = fract((in.world.xz - CITY_MIN) / BLOCK_PITCH) * BLOCK_PITCH;
            let edge = min(min(inblock.x, BLOCK_SIZE - inblock.x), min(inblock.y, BLOCK_SIZE - inblock.y));
            let city = step(CITY_MIN.x, in.world.x) * step(in.world.x, CITY_MAX.x) * step(CITY_MIN.y, in.world.z) * step(in.world.z, CITY_MAX.y);
            let is_walk = city * step(0.0, edge) * step(edge, 3.0) * step(inblock.x, BLOCK_SIZE) * step(inblock.y, BLOCK_SIZE);
            albedo = mix(albedo, walk * detail, is_walk);
            // Lane markings on the asphalt.
            let lane = abs(fract((in.world.x - CITY_MIN.x - BLOCK_SIZE - 6.0) / BLOCK_PITCH + 0.5) - 0.5) * BLOCK_PITCH;
            let dash = step(0.5, fract(in.world.z / 6.0));
            albedo = mix(albedo, vec3<f32>(0.75, 0.7, 0.4), step(lane, 0.12) * dash * layers.a);
            rough = mix(0.85, 0.35, layers.a * (1.0 - is_walk));
        }
        case 2u: {
            // Holographic sign panels: the billboard atlas, emissive.
            let face = step(0.5, abs(n.z));
            let uv = fract(in.uv * vec2<f32>(1.0, 1.0));
            let variant = f32(in.variant & 15u);
            let tile = vec2<f32>(variant % 4.0, floor(variant / 4.0)) / 4.0;
            let screen = textureSample(billboard_atlas, linear_clamp, tile + uv * 0.25).rgb;
            albedo = mix(vec3<f32>(0.05), screen, face);
            emissive = face * 0.8;
            rough = 0.2;
            metal = 1.0 - face;
        }
        case 3u: {
            albedo = vec3<f32>(0.02, 0.05, 0.06);
            rough = 0.05;
        }
        case 4u: {
            // Cars: painted metal, variant picks the colour; tail lights emissive.
            let hue = f32(in.variant & 15u) / 16.0;
            albedo = 0.5 + 0.45 * cos(6.2831 * (hue + vec3<f32>(0.0, 0.33, 0.67)));
            albedo = albedo * albedo;
            metal = 0.8;
            rough = 0.3;
        }
        case 5u: {
            // Characters: cloth bodies and skin heads.
            let hue = f32(in.variant & 15u) / 16.0;
            let cloth = 0.3 + 0.25 * cos(6.2831 * (hue + vec3<f32>(0.1, 0.4, 0.7)));
            let skin = mix(vec3<f32>(0.85, 0.6, 0.45), vec3<f32>(0.35, 0.22, 0.15), hue);
            albedo = select(cloth, skin, in.world.y > 1.45);
            rough = 0.7;
        }
        case 6u: {
            if (foliage_alpha(in.uv) < 0.5) {
                keep = false;
            }
            albedo = in.color.rgb * (0.6 + 0.4 * noise2(in.uv * 20.0));
            albedo = select(albedo, vec3<f32>(0.25, 0.17, 0.1), in.uv.y < 0.45 && abs(in.uv.x - 0.5) < 0.05);
            rough = 0.8;
        }
        case 7u: {
            // Decals: zebra crossings and grime patches on the street.
            let stripe = step(0.5, fract(in.uv.x * 8.0));
            let grime = noise2(in.world.xz * 0.8);
            if (in.variant == 0u && stripe < 0.5 && grime < 0.7) {
                keep = false;
            }
            albedo = vec3<f32>(0.7, 0.7, 0.68) * (0.8 + 0.2 * grime);
            rough = 0.6;
            n = vec3<f32>(0.0, 1.0, 0.0);
        }
        default: {
            // Hair and fur: the fur shell is cut into strands, and its tips thin out with a
            // blue-noise dither (TAA resolves it into soft edges).
            if ((in.variant & 0x1000u) != 0u) {
                let dither = textureLoad(blue_noise, vec2<u32>(in.clip.xy) % textureDimensions(blue_noise), 0).r;
                let tip = clamp((in.world.y - 1.7) * 12.0, 0.0, 1.0);
                if (fur_alpha(in.world) < 0.5 || dither < tip) {
                    keep = false;
                }
            }
            let hue = f32(in.variant & 15u) / 16.0;
            albedo = mix(vec3<f32>(0.05, 0.03, 0.02), vec3<f32>(0.6, 0.1, 0.5), step(0.8, hue));
            rough = 0.5;
        }
    }
    let cur = in.cur_clip.xy / in.cur_clip.w - frame.jitter.xy;
    let prev = in.prev_clip.xy / in.prev_clip.w - frame.jitter.zw;
    var out: GBuffer;
    out.albedo = vec4<f32>(albedo, mask / 3.0);
    out.normal = vec4<f32>(n * 0.5 + 0.5, 0.0);
    out.material = vec4<f32>(metal, rough, 0.0, emissive);
    // Screen-space motion in UV units (y down), current minus previous position.
    out.motion = (cur - prev) * vec2<f32>(0.5, -0.5);
    return Surface(out, keep);
}

@fragment
fn fs_gbuffer(in: VertexOut) -> GBuffer {
    let s = gbuffer_surface(in);
    if (!s.keep) {
        discard;
    }
    return s.out;
}

// Opaque draws: the same surface without a `discard` anywhere in the pipeline, so the GPU
// tests depth before shading and shades each pixel the depth pre-pass left visible once
// instead of every layer of the city behind it.
@fragment
fn fs_gbuffer_opaque(in: VertexOut) -> GBuffer {
    return gbuffer_surface(in).out;
}

// Environment capture: a quick forward shade of the district for the reflection probe (sun
// Lambert without shadows, sky ambient from above, emissive windows and signs).
@fragment
fn fs_env(in: VertexOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    var albedo = vec3<f32>(0.4);
    var emissive = vec3<f32>(0.0);
    switch params.material {
        case 0u: {
            let w = window_pattern(in.world, n, in.color.r * 7.0 + in.color.g * 3.0);
            albedo = mix(vec3<f32>(0.32, 0.31, 0.3), vec3<f32>(0.05, 0.07, 0.09), w.x);
            emissive = vec3<f32>(1.0, 0.78, 0.5) * w.x * w.y * 2.0;
        }
        case 1u: {
            let city = all(in.world.xz > CITY_MIN) && all(in.world.xz < CITY_MAX);
            albedo = select(vec3<f32>(0.16, 0.26, 0.08), vec3<f32>(0.1, 0.1, 0.105), city);
        }
        case 3u: { albedo = vec3<f32>(0.02, 0.05, 0.06); }
        default: {}
    }
    let l = normalize(frame.sun_direction.xyz);
    let sky = vec3<f32>(0.12, 0.2, 0.35) * frame.sun_color.rgb * 0.15 * (0.6 + 0.4 * n.y);
    let c = albedo * (frame.sun_color.rgb * max(dot(n, l), 0.0) / 3.14159 + sky) + emissive;
    return vec4<f32>(c, 1.0);
}

// The transparent pass: each draw's material picks holograms (2), the water surface (3) or
// the lights' glow (9).
@fragment
fn fs_transparent(in: VertexOut) -> @location(0) vec4<f32> {
    if (params.material == 3u) {
        return water_surface(in);
    }
    if (params.material == 9u) {
        return light_glow(in);
    }
    return holo(in);
}

// Local scattering around every light: a camera-facing quad per light (one instance each,
// read from the light buffer after this frame's update), sized by the light's radius, so
// neon and lamps show as glowing sources in the haze rather than only by what they light.
@vertex
fn vs_light_glow(v: VertexIn) -> VertexOut {
    var out = base_out(v);
    let light = lights[v.instance];
    let corner = decode_position(v.position).xz * 2.0;
    let right = vec3<f32>(frame.view[0][0], frame.view[1][0], frame.view[2][0]);
    let up = vec3<f32>(frame.view[0][1], frame.view[1][1], frame.view[2][1]);
    let size = 1.0 + light.position_radius.w * 0.15;
    let world = light.position_radius.xyz + (right * corner.x + up * corner.y) * size;
    out.uv = corner;
    out.color = light.color_intensity;
    out.normal = normalize(frame.camera_position.xyz - world);
    return finish(out, world, world);
}

// A bright core and a wide halo, additive; the halo is the light scattered by the air near it.
fn light_glow(in: VertexOut) -> vec4<f32> {
    let r2 = dot(in.uv, in.uv);
    let shape = exp(-r2 * 40.0) * 4.0 + exp(-r2 * 5.0) * 0.35;
    let fade = 1.0 - smoothstep(0.6, 1.0, r2);
    return vec4<f32>(in.color.rgb * in.color.w * 0.0015 * shape * fade, 0.0);
}

// Holographic signs, drawn again over their opaque panels in the transparent pass and blended
// additively (premultiplied with zero alpha): the transparent LUT's row for the sign's
// variant, looked up by how grazing the view is, with scanlines rolling upwards and a flicker.
fn holo(in: VertexOut) -> vec4<f32> {
    let n = normalize(in.normal);
    let v = normalize(frame.camera_position.xyz - in.world);
    let edge = 1.0 - abs(dot(n, v));
    let rows = f32(textureDimensions(transparent_lut).y);
    let row = (f32(in.variant % u32(rows)) + 0.5) / rows;
    let lut = textureSampleLevel(transparent_lut, linear_clamp, vec2<f32>(edge, row), 0.0);
    let scan = 0.55 + 0.45 * step(0.5, fract(in.world.y * 5.0 - frame.time.x * 1.5));
    let flicker = 0.85 + 0.15 * sin(frame.time.x * 23.0 + f32(in.variant) * 1.7);
    return vec4<f32>(lut.rgb * lut.a * scan * flicker, 0.0);
}

// The water surface: the half-resolution water reflection over the lit water by Schlick's
// Fresnel (water's F0 is 0.02, raised a little for the wind-roughened surface), blended
// premultiplied so it replaces that share of the water's colour.
fn water_surface(in: VertexOut) -> vec4<f32> {
    let n = normalize(in.normal);
    let v = normalize(frame.camera_position.xyz - in.world);
    let fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(n, v), 0.0), 5.0);
    let uv = in.clip.xy / frame.resolution.xy;
    let reflected = textureSampleLevel(water_reflection, linear_clamp, uv, 0.0).rgb;
    let f = clamp(fresnel * 1.5, 0.0, 1.0);
    return vec4<f32>(reflected * f, f);
}
