// Clustered lighting (Olsson, Billeter and Assarsson, "Clustered deferred and forward shading"):
// local lights are culled into a 3D grid of view-space clusters (32x32-pixel tiles x 24
// exponential depth slices); each cluster stores, in the 3D index texture, where its light
// indices start in light_list and how many there are. Also the per-frame light buffer update
// and the coarse local-light masks.

struct FrameConstants {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    light_count: u32,
    // The first `shadowed_lights` lights are the street lamps with omni shadow maps.
    shadowed_lights: u32,
}

struct Light {
    position_radius: vec4<f32>,
    color_intensity: vec4<f32>,
    direction_cone: vec4<f32>,
    // x: base intensity, y: flicker rate, z: 1 once placed, w: unused.
    extra: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var<storage, read_write> lights_rw: array<Light>;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<storage, read_write> light_list: array<u32>;
@group(0) @binding(5) var cluster_index_out: texture_storage_3d<r32uint, write>;
@group(0) @binding(6) var depth_half: texture_2d<f32>;
@group(0) @binding(7) var cluster_light_index: texture_3d<u32>;
@group(0) @binding(8) var light_mask_fine: texture_storage_2d<r8unorm, write>;
@group(0) @binding(9) var light_mask_coarse: texture_storage_2d<r8unorm, write>;

// The cluster grid shared by the culling pass and its readers: 24 exponential depth slices
// between 0.5 and 400 m; each cluster owns 32 consecutive slots of light_list.
const CLUSTER_NEAR: f32 = 0.5;
const CLUSTER_FAR: f32 = 400.0;
const CLUSTER_SLICES: u32 = 24u;
const MAX_PER_CLUSTER: u32 = 32u;

fn cluster_slice(view_z: f32) -> u32 {
    let s = log(max(view_z, CLUSTER_NEAR) / CLUSTER_NEAR) / log(CLUSTER_FAR / CLUSTER_NEAR);
    return min(u32(s * f32(CLUSTER_SLICES)), CLUSTER_SLICES - 1u);
}

fn cluster_first_slot(tile: vec2<u32>, slice: u32, grid: vec3<u32>) -> u32 {
    return ((slice * grid.y + tile.y) * grid.x + tile.x) * MAX_PER_CLUSTER;
}

const TILE_PX: f32 = 32.0;
const CITY_MIN: vec2<f32> = vec2<f32>(-104.0, -156.0);
const CITY_MAX: vec2<f32> = vec2<f32>(92.0, 144.0);
const BLOCK_PITCH: f32 = 52.0;
const BLOCK_SIZE: f32 = 40.0;

fn slice_depth(s: f32) -> f32 {
    return CLUSTER_NEAR * pow(CLUSTER_FAR / CLUSTER_NEAR, s / f32(CLUSTER_SLICES));
}

fn hash11(n: f32) -> f32 {
    return fract(sin(n * 12.9898) * 43758.5453);
}

// Light buffer update: lights that fall inside a building move out to its facade (neon signs
// and shop fronts), and every light's intensity flickers or pulses at its own rate.
@compute @workgroup_size(64, 1, 1)
fn cs_update_lights(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.light_count) {
        return;
    }
    var l = lights_rw[i];
    if (l.extra.z == 0.0 && i < params.shadowed_lights) {
        // Street lamps down both sides of the main street: warm, steady, shadowed.
        let side = select(-5.5, 5.5, (i & 1u) == 1u);
        l.position_radius = vec4<f32>(-6.0 + side, 7.0, -30.0 + f32(i) * 22.0, 22.0);
        l.color_intensity = vec4<f32>(1.0, 0.82, 0.6, 400.0);
        l.extra = vec4<f32>(400.0, 0.0, 1.0, 0.0);
    }
    if (l.extra.z == 0.0) {
        l.extra = vec4<f32>(l.color_intensity.w, hash11(f32(i) * 3.3), 1.0, 0.0);
        // Neon is saturated: square the generated colour and renormalise its peak to 1.
        let c = l.color_intensity.rgb * l.color_intensity.rgb;
        l.color_intensity = vec4<f32>(c / max(max(c.r, c.g), max(c.b, 1e-3)), l.color_intensity.w);
        var p = l.position_radius.xyz;
        if (all(p.xz > CITY_MIN) && all(p.xz < CITY_MAX)) {
            let local = fract((p.xz - CITY_MIN) / BLOCK_PITCH) * BLOCK_PITCH;
            if (all(local < vec2<f32>(BLOCK_SIZE))) {
                // Push out through the nearest face, one metre into the street.
                let to_lo = local;
                let to_hi = vec2<f32>(BLOCK_SIZE) - local;
                let m = min(min(to_lo.x, to_hi.x), min(to_lo.y, to_hi.y));
                if (m == to_lo.x) { p.x -= to_lo.x + 1.0; }
                else if (m == to_hi.x) { p.x += to_hi.x + 1.0; }
                else if (m == to_lo.y) { p.z -= to_lo.y + 1.0; }
                else { p.z += to_hi.y + 1.0; }
            }
        }
        l.position_radius = vec4<f32>(p, l.position_radius.w);
    }
    let rate = l.extra.y;
    let t = frame.time.x;
    var k = 1.0;
    if (rate > 0.85) {
        // Failing neon: stutters off now and then.
        k = select(1.0, 0.15, hash11(floor(t * 12.0) + f32(i)) > 0.8);
    } else if (rate > 0.6) {
        k = 0.75 + 0.25 * sin(t * (2.0 + rate * 6.0) + f32(i));
    }
    l.color_intensity.w = l.extra.x * k;
    lights_rw[i] = l;
}

// One workgroup per 32x32-pixel tile: first the tile's depth bounds from the half-resolution
// depth, then one thread per depth slice tests every light's sphere against the slice's
// view-space box. Slices outside the tile's depth bounds hold no lights.
var<workgroup> tile_min: atomic<u32>;
var<workgroup> tile_max: atomic<u32>;

@compute @workgroup_size(32, 1, 1)
fn cs_cluster(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let grid = textureDimensions(cluster_index_out);
    if (wg.x >= grid.x || wg.y >= grid.y) {
        return;
    }
    if (lid == 0u) {
        atomicStore(&tile_min, 0x7F7FFFFFu);
        atomicStore(&tile_max, 0u);
    }
    workgroupBarrier();
    // Half-resolution texels of this tile: 16x16, 8 per thread.
    let half_size = vec2<i32>(textureDimensions(depth_half));
    let scale = vec2<f32>(half_size) / frame.resolution.xy;
    let origin = vec2<f32>(wg.xy) * TILE_PX * scale;
    let extent = max(vec2<i32>(ceil(TILE_PX * scale)), vec2<i32>(1));
    let texels = extent.x * extent.y;
    for (var k = i32(lid); k < texels; k += 32) {
        let p = vec2<i32>(origin) + vec2<i32>(k % extent.x, k / extent.x);
        if (all(p < half_size)) {
            let z = textureLoad(depth_half, p, 0).r;
            // Positive floats order like their bit patterns.
            atomicMin(&tile_min, bitcast<u32>(z));
            atomicMax(&tile_max, bitcast<u32>(z));
        }
    }
    workgroupBarrier();
    let zmin = bitcast<f32>(atomicLoad(&tile_min));
    let zmax = bitcast<f32>(atomicLoad(&tile_max));
    let s = lid;
    if (s >= CLUSTER_SLICES) {
        return;
    }
    let z0 = slice_depth(f32(s));
    let z1 = slice_depth(f32(s + 1u));
    let base = cluster_first_slot(wg.xy, s, grid);
    var count = 0u;
    if (z1 >= zmin && z0 <= zmax) {
        // The tile's NDC rectangle (y up) and the slice's view-space box.
        let px0 = vec2<f32>(wg.xy) * TILE_PX;
        let px1 = min(px0 + TILE_PX, frame.resolution.xy);
        let ndc0 = vec2<f32>(px0.x, px1.y) / frame.resolution.xy * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
        let ndc1 = vec2<f32>(px1.x, px0.y) / frame.resolution.xy * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
        let sx = 1.0 / frame.proj[0][0];
        let sy = 1.0 / frame.proj[1][1];
        let xs = vec4<f32>(ndc0.x * sx * z0, ndc1.x * sx * z0, ndc0.x * sx * z1, ndc1.x * sx * z1);
        let ys = vec4<f32>(ndc0.y * sy * z0, ndc1.y * sy * z0, ndc0.y * sy * z1, ndc1.y * sy * z1);
        let lo = vec3<f32>(min(min(xs.x, xs.y), min(xs.z, xs.w)), min(min(ys.x, ys.y), min(ys.z, ys.w)), -z1);
        let hi = vec3<f32>(max(max(xs.x, xs.y), max(xs.z, xs.w)), max(max(ys.x, ys.y), max(ys.z, ys.w)), -z0);
        for (var i = 0u; i < params.light_count; i++) {
            let l = lights[i].position_radius;
            let c = (frame.view * vec4<f32>(l.xyz, 1.0)).xyz;
            let nearest = clamp(c, lo, hi);
            let d = c - nearest;
            if (dot(d, d) <= l.w * l.w && count < MAX_PER_CLUSTER) {
                light_list[base + count] = i;
                count++;
            }
        }
    }
    textureStore(cluster_index_out, vec3<u32>(wg.xy, s), vec4<u32>(count, 0u, 0u, 0u));
}

fn column_count(cx: u32, cy: u32, z0: f32, z1: f32) -> u32 {
    var total = 0u;
    for (var s = 0u; s < CLUSTER_SLICES; s++) {
        let a = slice_depth(f32(s));
        let b = slice_depth(f32(s + 1u));
        if (b >= z0 && a <= z1) {
            total = max(total, textureLoad(cluster_light_index, vec3<u32>(cx, cy, s), 0).r);
        }
    }
    return total;
}

// Local light mask, fine (mip 0, 16-pixel tiles): the most lights any cluster overlapping the
// tile's own depth range holds, normalised to the per-cluster maximum.
@compute @workgroup_size(8, 8, 1)
fn cs_light_mask_fine(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(light_mask_fine);
    if (any(id.xy >= size)) {
        return;
    }
    let half_size = vec2<i32>(textureDimensions(depth_half));
    let scale = vec2<f32>(half_size) / frame.resolution.xy;
    let origin = vec2<i32>(vec2<f32>(id.xy) * 16.0 * scale);
    let extent = max(vec2<i32>(ceil(16.0 * scale)), vec2<i32>(1));
    var z0 = 1e9;
    var z1 = 0.0;
    for (var y = 0; y < extent.y; y++) {
        for (var x = 0; x < extent.x; x++) {
            let z = textureLoad(depth_half, min(origin + vec2<i32>(x, y), half_size - 1), 0).r;
            z0 = min(z0, z);
            z1 = max(z1, z);
        }
    }
    let grid = textureDimensions(cluster_light_index);
    let c = min(id.xy / 2u, grid.xy - 1u);
    let n = column_count(c.x, c.y, z0, z1);
    // Saturates at 8 lights: the mask says where local lighting is busy.
    textureStore(light_mask_fine, id.xy, vec4<f32>(min(f32(n) / 8.0, 1.0)));
}

// Local light mask, coarse (mip 1, one texel per cluster column): lights over all slices.
@compute @workgroup_size(8, 8, 1)
fn cs_light_mask_coarse(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(light_mask_coarse);
    if (any(id.xy >= size)) {
        return;
    }
    let grid = textureDimensions(cluster_light_index);
    let c = min(id.xy, grid.xy - 1u);
    let n = column_count(c.x, c.y, 0.0, 1e9);
    textureStore(light_mask_coarse, id.xy, vec4<f32>(min(f32(n) / 8.0, 1.0)));
}
