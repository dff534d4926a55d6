// Ocean: the tileable wave field (a sum of ~22 directional wave bands, one per dispatch,
// accumulated in place) and the ocean height map rendered from the water plate using the
// previous frame's wave field and the coastline mask.

struct FrameConstants {
    time: vec4<f32>,
}

struct Params {
    // Band index (wave-noise dispatches), and the water plate placement (height-map pass).
    band: u32,
    offset: vec4<f32>,
    scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var wave_field: texture_storage_2d<rgba16float, read_write>;
@group(0) @binding(3) var ocean_wave_noise: texture_2d<f32>;
@group(0) @binding(4) var ocean_mask: texture_2d<f32>;
@group(0) @binding(5) var linear_wrap: sampler;
@group(0) @binding(6) var linear_clamp: sampler;

const TAU: f32 = 6.2831853;
const TILE_METRES: f32 = 64.0;
const GRAVITY: f32 = 9.81;
const TERRAIN_MAP_EXTENT: f32 = 600.0;

fn hash11(n: f32) -> f32 {
    return fract(sin(n * 12.9898) * 43758.5453);
}

// One band: a wave with integer wave numbers across the tile (so the field tiles), direction
// spread around the wind, amplitude from a Phillips-like spectrum and the deep-water
// dispersion relation for its phase speed. Stores height, d/dx, d/dz and a foam term.
@compute @workgroup_size(8, 8, 1)
fn cs_wave_band(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(wave_field);
    if (any(id.xy >= size)) {
        return;
    }
    let b = f32(params.band);
    let wind = vec2<f32>(0.8, 0.6);
    let angle = (hash11(b * 3.1) - 0.5) * 1.6;
    let dir = vec2<f32>(wind.x * cos(angle) - wind.y * sin(angle), wind.x * sin(angle) + wind.y * cos(angle));
    // Wave numbers 1..~40 cycles per tile, longer waves first.
    let cycles = round(1.0 + b * b * 0.08 + hash11(b * 7.7) * 2.0);
    let kvec = round(dir * cycles) * TAU / TILE_METRES;
    let k = max(length(kvec), 1e-3);
    let omega = sqrt(GRAVITY * k);
    let amplitude = 0.35 / (k * 8.0 + 1.0) * pow(max(dot(normalize(kvec), wind), 0.0), 2.0) + 0.01 / k;
    let p = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) * TILE_METRES;
    let phase = dot(kvec, p) - omega * frame.time.x + hash11(b * 1.3) * TAU;
    let h = amplitude * sin(phase);
    let slope = amplitude * cos(phase) * kvec;
    var acc = vec4<f32>(0.0);
    if (params.band > 0u) {
        acc = textureLoad(wave_field, id.xy);
    }
    let sum = acc + vec4<f32>(h, slope.x, slope.y, 0.0);
    // Foam where the accumulated slope is steep (the crest folds).
    let foam = smoothstep(0.35, 0.8, length(sum.yz));
    textureStore(wave_field, id.xy, vec4<f32>(sum.xyz, foam));
}

struct MapOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec2<f32>,
    @location(1) uv: vec2<f32>,
}

fn decode_position(p: vec4<f32>) -> vec3<f32> {
    return p.xyz * exp2(round(log2(max(p.w * 4096.0, 1.0))));
}

// The water plate's grid, seen from above over the 600 m ocean map centred on the plate.
@vertex
fn vs_ocean(@location(0) position: vec4<f32>) -> MapOut {
    let local = decode_position(position) * params.scale.xyz;
    var out: MapOut;
    let m = local.xz / (TERRAIN_MAP_EXTENT * 0.5);
    out.clip = vec4<f32>(m.x, -m.y, 0.5, 1.0);
    out.world = local.xz + params.offset.xz;
    out.uv = m * 0.5 + 0.5;
    return out;
}

// Height in [0, 1] around 0.5: two scales of the wave field, damped in shallow water where
// the coastline mask fades out.
@fragment
fn fs_ocean(in: MapOut) -> @location(0) f32 {
    let big = textureSample(ocean_wave_noise, linear_wrap, in.world / TILE_METRES).x;
    let small = textureSample(ocean_wave_noise, linear_wrap, in.world / (TILE_METRES * 0.23) + 0.37).x;
    // The mask maps texel for texel onto the height map, so each fragment sits on a texel's
    // centre, where filtering returns that texel: fetch it, one BC7 block decoded instead of
    // the four a bilinear footprint decodes.
    let mask_size = vec2<f32>(textureDimensions(ocean_mask));
    let texel = vec2<i32>(vec2<f32>(in.uv.x, 1.0 - in.uv.y) * mask_size);
    let water = textureLoad(ocean_mask, clamp(texel, vec2<i32>(0), vec2<i32>(mask_size) - 1), 0).r;
    let h = (big + small * 0.3) * mix(0.15, 1.0, water);
    return clamp(0.5 + h * 0.6, 0.0, 1.0);
}
