// Compute work before the geometry passes: the 64^3 voxel normal volume of the district and
// the instance preparation that animates, culls and compacts the dynamic objects (cars,
// pedestrians, holographic signs) and writes the indirect arguments the base pass draws with.

struct FrameConstants {
    view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    // Index counts of the car/sign box, the character capsule and the box again.
    index_counts: vec4<u32>,
    // Candidate slots per kind: cars, pedestrians, signs.
    kind_counts: vec4<u32>,
    // Where each kind's compacted instances start after the candidates: a fixed layout (the
    // day's capacities) so the draws' instance bases hold whatever this frame's counts are.
    kind_bases: vec4<u32>,
}

struct Instance {
    row0: vec4<f32>,
    row1: vec4<f32>,
    row2: vec4<f32>,
    prev: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var voxel_normals: texture_storage_3d<rgba16float, write>;
@group(0) @binding(3) var<storage, read_write> instance_data: array<Instance>;
@group(0) @binding(4) var<storage, read_write> draw_args: array<atomic<u32>>;

const CITY_MIN: vec2<f32> = vec2<f32>(-104.0, -156.0);
const CITY_MAX: vec2<f32> = vec2<f32>(92.0, 144.0);
const BLOCK_PITCH: f32 = 52.0;
const BLOCK_SIZE: f32 = 40.0;
const VOXEL_MIN: vec3<f32> = vec3<f32>(-160.0, -32.0, -200.0);
const VOXEL_SIZE: vec3<f32> = vec3<f32>(320.0, 160.0, 400.0);
// Compacted visible instances start after the candidates.
const CANDIDATES: u32 = 2016u;

fn hash21(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(123.34, 456.21));
    let r = q + dot(q, q + 45.32);
    return fract(r.x * r.y);
}

fn hash11(n: f32) -> f32 {
    return fract(sin(n * 12.9898) * 43758.5453);
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

fn terrain_height(xz: vec2<f32>) -> f32 {
    let outside = max(max(CITY_MIN - xz, xz - CITY_MAX), vec2<f32>(0.0));
    let d = length(outside);
    let hills = max(fbm2(xz * 0.006) * 70.0 - 22.0, 0.0) + fbm2(xz * 0.05) * 1.5;
    // The river: a band past the riverside park where the hills give way to the riverbed.
    let river = smoothstep(165.0, 200.0, xz.y) * (1.0 - smoothstep(430.0, 480.0, xz.y));
    return hills * smoothstep(10.0, 90.0, d) * (1.0 - river) - river * 9.0;
}

fn voxel_world(id: vec3<u32>) -> vec3<f32> {
    return VOXEL_MIN + (vec3<f32>(id) + 0.5) / 64.0 * VOXEL_SIZE;
}

// Dispatch 1 (2x2x64 groups of 32x32): the terrain as a signed height field. Each voxel stores
// the outward surface normal of the nearest ground and, in alpha, the signed distance to it
// (positive above ground) in voxel units.
@compute @workgroup_size(32, 32, 1)
fn cs_voxel_terrain(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(64u))) {
        return;
    }
    let p = voxel_world(id);
    let e = VOXEL_SIZE.x / 64.0;
    let h = terrain_height(p.xz);
    let hx = terrain_height(p.xz + vec2<f32>(e, 0.0)) - terrain_height(p.xz - vec2<f32>(e, 0.0));
    let hz = terrain_height(p.xz + vec2<f32>(0.0, e)) - terrain_height(p.xz - vec2<f32>(0.0, e));
    let n = normalize(vec3<f32>(-hx, 2.0 * e, -hz));
    let d = (p.y - h) * n.y / (VOXEL_SIZE.y / 64.0);
    textureStore(voxel_normals, id, vec4<f32>(n, d));
}

// Dispatch 2 (16x16x16 groups of 4x4x4): street furniture and block edges. Voxels within the
// city near block edges and above the street take the normal of the nearest block face, so
// the volume bends foliage and ambient lookups away from walls.
@compute @workgroup_size(4, 4, 4)
fn cs_voxel_structures(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = voxel_world(id);
    if (any(p.xz < CITY_MIN) || any(p.xz > CITY_MAX) || p.y < -2.0 || p.y > 40.0) {
        return;
    }
    let local = fract((p.xz - CITY_MIN) / BLOCK_PITCH) * BLOCK_PITCH;
    // Distance to the block's faces: negative inside the block.
    let to_face = vec2<f32>(min(local.x, BLOCK_SIZE - local.x), min(local.y, BLOCK_SIZE - local.y));
    let inside = all(local < vec2<f32>(BLOCK_SIZE));
    var n = vec3<f32>(0.0, 1.0, 0.0);
    var d = p.y / (VOXEL_SIZE.y / 64.0);
    if (inside) {
        // Inside a block: the nearest face's outward normal, negative distance.
        if (to_face.x < to_face.y) {
            n = vec3<f32>(select(1.0, -1.0, local.x < BLOCK_SIZE * 0.5), 0.0, 0.0);
        } else {
            n = vec3<f32>(0.0, 0.0, select(1.0, -1.0, local.y < BLOCK_SIZE * 0.5));
        }
        d = -min(to_face.x, to_face.y) / (VOXEL_SIZE.x / 64.0);
    } else {
        // Street: blend the ground normal with the nearest wall's.
        let gap = local - vec2<f32>(BLOCK_SIZE);
        let wall = select(vec3<f32>(0.0, 0.0, select(-1.0, 1.0, gap.y < 6.0)),
                          vec3<f32>(select(-1.0, 1.0, gap.x < 6.0), 0.0, 0.0), gap.x > 0.0);
        let w = smoothstep(6.0, 0.0, min(abs(gap.x), abs(gap.y)));
        n = normalize(mix(n, wall, w * 0.5));
        d = min(d, min(abs(gap.x), abs(gap.y)) / (VOXEL_SIZE.x / 64.0));
    }
    textureStore(voxel_normals, id, vec4<f32>(n, d));
}

// Streets run along x at these z centres and along z at these x centres.
fn street_x(i: u32) -> f32 {
    return CITY_MIN.x + BLOCK_SIZE + 6.0 + f32(i % 3u) * BLOCK_PITCH;
}

fn street_z(i: u32) -> f32 {
    return CITY_MIN.y + BLOCK_SIZE + 6.0 + f32(i % 5u) * BLOCK_PITCH;
}

struct Placed {
    position: vec3<f32>,
    prev: vec3<f32>,
    heading: f32,
    scale: vec3<f32>,
    radius: f32,
}

// Where candidate `i` of its kind is at time `t`: cars drive along the streets in lanes,
// pedestrians walk the sidewalks, signs stand on poles at block corners.
fn place(kind: u32, i: u32, t: f32) -> Placed {
    let fi = f32(i);
    let r0 = hash11(fi * 1.37 + f32(kind) * 91.0);
    let r1 = hash11(fi * 2.11 + 7.0 + f32(kind) * 13.0);
    let r2 = hash11(fi * 0.73 + 3.0);
    var out: Placed;
    let along_x = r0 < 0.35;
    let span = select(CITY_MAX.y - CITY_MIN.y, CITY_MAX.x - CITY_MIN.x, along_x);
    if (kind == 0u) {
        let lane = select(-2.2, 2.2, r1 < 0.5);
        let dir = select(-1.0, 1.0, r1 < 0.5);
        let speed = 8.0 + 6.0 * r2;
        let s = fract(r2 * 7.0 + dir * t * speed / span) * span;
        if (along_x) {
            out.position = vec3<f32>(CITY_MIN.x + s, 0.75, street_z(i) + lane);
            out.heading = 1.5708 * dir;
        } else {
            out.position = vec3<f32>(street_x(i) + lane, 0.75, CITY_MIN.y + s);
            out.heading = select(3.1416, 0.0, dir > 0.0);
        }
        let prev_s = fract(r2 * 7.0 + dir * (t - frame.time.y) * speed / span) * span;
        out.prev = out.position;
        if (along_x) { out.prev.x = CITY_MIN.x + prev_s; } else { out.prev.z = CITY_MIN.y + prev_s; }
        out.scale = vec3<f32>(1.9, 1.4, 4.5);
        out.radius = 2.6;
    } else if (kind == 1u) {
        let side = select(-4.5, 4.5, r1 < 0.5);
        let dir = select(-1.0, 1.0, hash11(fi * 5.3) < 0.5);
        let speed = 1.1 + 0.5 * r2;
        let s = fract(r2 * 11.0 + dir * t * speed / span) * span;
        let prev_s = fract(r2 * 11.0 + dir * (t - frame.time.y) * speed / span) * span;
        if (along_x) {
            out.position = vec3<f32>(CITY_MIN.x + s, 0.0, street_z(i) + side);
            out.prev = vec3<f32>(CITY_MIN.x + prev_s, 0.0, out.position.z);
            out.heading = 1.5708 * dir;
        } else {
            out.position = vec3<f32>(street_x(i) + side, 0.0, CITY_MIN.y + s);
            out.prev = vec3<f32>(out.position.x, 0.0, CITY_MIN.y + prev_s);
            out.heading = select(3.1416, 0.0, dir > 0.0);
        }
        out.scale = vec3<f32>(0.9 + 0.2 * r2);
        out.radius = 1.2;
    } else {
        // Signs: on the sidewalk edge facing the street, 5-10 m up, rotating slowly if holographic.
        let corner = CITY_MIN + vec2<f32>(floor(r0 * 4.0), floor(r1 * 6.0)) * BLOCK_PITCH;
        let along = r2 * BLOCK_SIZE;
        let on_x = hash11(fi * 3.7) < 0.5;
        let xz = select(corner + vec2<f32>(BLOCK_SIZE + 1.0, along), corner + vec2<f32>(along, BLOCK_SIZE + 1.0), on_x);
        out.position = vec3<f32>(xz.x, 5.0 + 5.0 * hash11(fi * 9.1), xz.y);
        out.prev = out.position;
        out.heading = select(1.5708, 0.0, on_x) + 0.3 * sin(t * 0.5 + fi);
        out.scale = vec3<f32>(4.0 + 3.0 * r1, 2.4, 0.25);
        out.radius = 5.0;
    }
    return out;
}

fn visible(center: vec3<f32>, radius: f32) -> bool {
    // Gribb-Hartmann frustum planes from the view-projection (rows of the matrix).
    let m = transpose(frame.view_proj);
    let planes = array<vec4<f32>, 5>(m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[2]);
    for (var k = 0; k < 5; k++) {
        let p = planes[k];
        if (dot(p.xyz, center) + p.w < -radius * length(p.xyz)) {
            return false;
        }
    }
    return distance(center, frame.camera_position.xyz) < 600.0;
}

fn kind_of(i: u32) -> vec2<u32> {
    let k = params.kind_counts;
    if (i < k.x) {
        return vec2<u32>(0u, i);
    }
    if (i < k.x + k.y) {
        return vec2<u32>(1u, i - k.x);
    }
    return vec2<u32>(2u, i - k.x - k.y);
}

// Dispatch 1 (63 groups): animate every candidate and store its record with a visibility flag
// in the candidate half of instance_data.
@compute @workgroup_size(32, 1, 1)
fn cs_animate(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= CANDIDATES) {
        return;
    }
    let kv = kind_of(i);
    let placed = place(kv.x, kv.y, frame.time.x);
    let c = cos(placed.heading);
    let s = sin(placed.heading);
    let sc = placed.scale;
    var inst: Instance;
    inst.row0 = vec4<f32>(c * sc.x, 0.0, s * sc.z, placed.position.x);
    inst.row1 = vec4<f32>(0.0, sc.y, 0.0, placed.position.y);
    inst.row2 = vec4<f32>(-s * sc.x, 0.0, c * sc.z, placed.position.z);
    let seen = visible(placed.position + vec3<f32>(0.0, sc.y * 0.5, 0.0), placed.radius);
    let variant = u32(hash11(f32(i) * 4.1) * 16.0);
    // w: kind * 16 + variant, negative when culled.
    let tag = f32(kv.x * 16u + variant);
    inst.prev = vec4<f32>(placed.prev, select(-1.0 - tag, tag, seen));
    instance_data[i] = inst;
}

// Dispatch 2 (3 groups): one group per kind writes its DrawIndexedInstanced header with no
// instances yet; group 0 also writes the tiled-lighting dispatch arguments (16x16 tiles).
@compute @workgroup_size(1, 1, 1)
fn cs_args(@builtin(workgroup_id) wg: vec3<u32>) {
    let k = wg.x;
    let base = k * 5u;
    atomicStore(&draw_args[base + 0u], params.index_counts[k]);
    atomicStore(&draw_args[base + 1u], 0u);
    atomicStore(&draw_args[base + 2u], 0u);
    atomicStore(&draw_args[base + 3u], 0u);
    atomicStore(&draw_args[base + 4u], 0u);
    if (k == 0u) {
        atomicStore(&draw_args[16u], u32(ceil(frame.resolution.x / 16.0)));
        atomicStore(&draw_args[17u], u32(ceil(frame.resolution.y / 16.0)));
        atomicStore(&draw_args[18u], 1u);
    }
}

// Dispatch 3 (63 groups): compact the visible candidates of each kind into its range of the
// second half of instance_data and count them into the draw's instance count.
@compute @workgroup_size(32, 1, 1)
fn cs_compact(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= CANDIDATES) {
        return;
    }
    let inst = instance_data[i];
    if (inst.prev.w < 0.0) {
        return;
    }
    let kind = u32(inst.prev.w) / 16u;
    let slot = atomicAdd(&draw_args[kind * 5u + 1u], 1u);
    instance_data[CANDIDATES + params.kind_bases[kind] + slot] = inst;
}
