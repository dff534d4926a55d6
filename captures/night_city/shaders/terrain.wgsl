// Terrain maps in world space (top-down over a 600 m square centred on the district): the two
// layer maps and the material-id map the ground is shaded from, the dead LOD-id pass, and the
// landscape normal and heat maps derived from the layers.

struct FrameConstants {
    camera_position: vec4<f32>,
}

struct Params {
    offset: vec4<f32>,
    scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var voxel_normals: texture_3d<f32>;
@group(0) @binding(3) var terrain_layers: texture_2d_array<f32>;
@group(0) @binding(4) var linear_clamp: sampler;

const CITY_MIN: vec2<f32> = vec2<f32>(-104.0, -156.0);
const CITY_MAX: vec2<f32> = vec2<f32>(92.0, 144.0);
const WATER_LEVEL: f32 = -1.5;
const TERRAIN_MAP_EXTENT: f32 = 600.0;
const VOXEL_MIN: vec3<f32> = vec3<f32>(-160.0, -32.0, -200.0);
const VOXEL_SIZE: vec3<f32> = vec3<f32>(320.0, 160.0, 400.0);

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

fn terrain_height(xz: vec2<f32>) -> f32 {
    let outside = max(max(CITY_MIN - xz, xz - CITY_MAX), vec2<f32>(0.0));
    let d = length(outside);
    let hills = max(fbm2(xz * 0.006) * 70.0 - 22.0, 0.0) + fbm2(xz * 0.05) * 1.5;
    // The river: a band past the riverside park where the hills give way to the riverbed.
    let river = smoothstep(165.0, 200.0, xz.y) * (1.0 - smoothstep(430.0, 480.0, xz.y));
    return hills * smoothstep(10.0, 90.0, d) * (1.0 - river) - river * 9.0;
}

struct MapOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec2<f32>,
}

fn decode_position(p: vec4<f32>) -> vec3<f32> {
    return p.xyz * exp2(round(log2(max(p.w * 4096.0, 1.0))));
}

// Terrain chunk meshes laid flat and seen from above: clip xy is the world xz in the map.
@vertex
fn vs_map(@location(0) position: vec4<f32>) -> MapOut {
    let world = decode_position(position) * params.scale.xyz + params.offset.xyz;
    var out: MapOut;
    let m = world.xz / (TERRAIN_MAP_EXTENT * 0.5);
    out.clip = vec4<f32>(m.x, -m.y, 0.5, 1.0);
    out.world = world.xz;
    return out;
}

struct LayersOut {
    // Layer 0: grass, rock, sand, asphalt weights.
    @location(0) weights: vec4<f32>,
    // Layer 1: height (normalised), slope, wetness, voxel-field occlusion.
    @location(1) shape: vec4<f32>,
    @location(2) id: u32,
}

@fragment
fn fs_layers(in: MapOut) -> LayersOut {
    let xz = in.world;
    let h = terrain_height(xz);
    let e = 1.5;
    let hx = terrain_height(xz + vec2<f32>(e, 0.0)) - terrain_height(xz - vec2<f32>(e, 0.0));
    let hz = terrain_height(xz + vec2<f32>(0.0, e)) - terrain_height(xz - vec2<f32>(0.0, e));
    let slope = clamp(length(vec2<f32>(hx, hz)) / (2.0 * e), 0.0, 1.0);
    let in_city = all(xz >= CITY_MIN) && all(xz <= CITY_MAX);
    let shore = smoothstep(WATER_LEVEL + 2.5, WATER_LEVEL, h);
    let rock = smoothstep(0.35, 0.7, slope) + smoothstep(30.0, 45.0, h) * 0.5;
    let sand = shore * (1.0 - rock);
    let grass = max(1.0 - rock - sand, 0.0) * (0.7 + 0.3 * noise2(xz * 0.1));
    var w = vec4<f32>(grass, rock, sand, 0.0);
    var id = select(0u, 1u, rock > grass);
    if (sand > 0.5) {
        id = 2u;
    }
    if (in_city) {
        w = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        id = 3u;
    }
    let total = max(w.x + w.y + w.z + w.w, 1e-3);
    // How open the sky is over this point, from the voxel field's distance to surfaces.
    let vuv = (vec3<f32>(xz.x, h + 2.0, xz.y) - VOXEL_MIN) / VOXEL_SIZE;
    let field = textureSampleLevel(voxel_normals, linear_clamp, vuv, 0.0);
    let openness = clamp(field.w / 4.0, 0.0, 1.0);
    var out: LayersOut;
    out.weights = w / total;
    out.shape = vec4<f32>(clamp((h + 20.0) / 80.0, 0.0, 1.0), slope, shore, openness);
    out.id = id;
    return out;
}

// unknown_color_01: the frame's mystery pass. It draws two LOD-id meshes whose vertices all
// end up outside the clip volume (behind the near plane), so nothing is rasterised and the
// target keeps its clear value; no later pass reads it.
@vertex
fn vs_lod_ids(@location(0) position: vec4<f32>, @builtin(instance_index) instance: u32) -> MapOut {
    let world = decode_position(position) * params.scale.xyz + params.offset.xyz;
    var out: MapOut;
    let m = world.xz / (TERRAIN_MAP_EXTENT * 0.5);
    out.clip = vec4<f32>(m.x, -m.y, -1.0, 1.0);
    out.world = world.xz;
    return out;
}

@fragment
fn fs_lod_ids(in: MapOut) -> @location(0) u32 {
    let d = distance(in.world, frame.camera_position.xz);
    return u32(clamp(log2(max(d, 1.0)) - 4.0, 0.0, 7.0));
}

struct FullscreenOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> FullscreenOut {
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: FullscreenOut;
    out.clip = vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
    out.uv = vec2<f32>(p.x, 1.0 - p.y);
    return out;
}

struct LandscapeOut {
    @location(0) normal: vec4<f32>,
    @location(1) heat: vec4<f32>,
}

// Landscape maps: a tangent-space normal map from the height layer and a heat map (the
// scanner view): asphalt holds the day's heat, water and shade are cold, vegetation is mild.
@fragment
fn fs_landscape(in: FullscreenOut) -> LandscapeOut {
    let texel = 1.0 / vec2<f32>(textureDimensions(terrain_layers).xy);
    let h = textureSampleLevel(terrain_layers, linear_clamp, in.uv, 1, 0.0);
    let hl = textureSampleLevel(terrain_layers, linear_clamp, in.uv - vec2<f32>(texel.x, 0.0), 1, 0.0).r;
    let hr = textureSampleLevel(terrain_layers, linear_clamp, in.uv + vec2<f32>(texel.x, 0.0), 1, 0.0).r;
    let hd = textureSampleLevel(terrain_layers, linear_clamp, in.uv - vec2<f32>(0.0, texel.y), 1, 0.0).r;
    let hu = textureSampleLevel(terrain_layers, linear_clamp, in.uv + vec2<f32>(0.0, texel.y), 1, 0.0).r;
    // Height is normalised over 80 m; one texel is 600/1024 m.
    let scale = 80.0 / (TERRAIN_MAP_EXTENT * texel.x);
    let n = normalize(vec3<f32>((hl - hr) * scale, (hd - hu) * scale, 2.0));
    let w = textureSampleLevel(terrain_layers, linear_clamp, in.uv, 0, 0.0);
    let temperature = clamp(w.a * 0.9 + w.y * 0.6 + w.x * 0.35 + w.z * 0.45 - h.z * 0.5, 0.0, 1.0);
    // Heat palette: blue - magenta - orange - white.
    let heat = clamp(vec3<f32>(temperature * 2.0 - 0.3, temperature * temperature * 1.6 - 0.3, 1.0 - temperature * 1.5 + temperature * temperature), vec3<f32>(0.0), vec3<f32>(1.0));
    var out: LandscapeOut;
    out.normal = vec4<f32>(n * 0.5 + 0.5, 1.0);
    out.heat = vec4<f32>(heat, 1.0);
    return out;
}
