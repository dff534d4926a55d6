// Environment probes: the 512x256 dual-paraboloid array (two hemispheres side by side, 32
// probes, 6 mips prefiltered by roughness). Probe 0 is the street probe captured into env_cube
// this frame; the others are distant probes that see only the sky, taken from the sky cube's
// prefiltered mips.

struct Params {
    mip: u32,
    mip_count: u32,
    // Array layers of the probe array (a storage texture's layer count is not queried: naga
    // emits a size-with-LOD query the SPIR-V rules allow on sampled images only).
    layers: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var env_cube: texture_cube<f32>;
@group(0) @binding(2) var sky_cube: texture_cube<f32>;
@group(0) @binding(3) var linear_clamp: sampler;
@group(0) @binding(4) var dp_mip_0: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(5) var dp_mip_1: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(6) var dp_mip_2: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(7) var dp_mip_3: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(8) var dp_mip_4: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(9) var dp_mip_5: texture_storage_2d_array<rg11b10ufloat, write>;

const PI: f32 = 3.14159265;

// Dual-paraboloid texel to direction: left half the +z hemisphere, right half the -z one.
fn paraboloid_direction(uv: vec2<f32>) -> vec3<f32> {
    let back = uv.x >= 0.5;
    let local = vec2<f32>(fract(uv.x * 2.0), uv.y) * 2.0 - 1.0;
    let r2 = dot(local, local);
    let z = (1.0 - r2) * 0.5;
    var d = normalize(vec3<f32>(local.x, -local.y, max(z, 0.0)));
    if (back) {
        d = vec3<f32>(-d.x, d.y, -d.z);
    }
    return d;
}

fn radical_inverse(i: u32) -> f32 {
    var b = (i << 16u) | (i >> 16u);
    b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u);
    b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);
    b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u);
    b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);
    return f32(b) * 2.3283064e-10;
}

// Sample i of count of the GGX lobe of roughness^2 `a` around n, as the reflected direction
// (Hammersley points, Karis 2013).
fn ggx_sample(n: vec3<f32>, a: f32, i: u32, count: u32) -> vec3<f32> {
    let up = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.y) < 0.99);
    let tx = normalize(cross(up, n));
    let ty = cross(n, tx);
    let xi = vec2<f32>(f32(i) / f32(count), radical_inverse(i));
    let phi = 2.0 * PI * xi.x;
    let cos_t = sqrt((1.0 - xi.y) / (1.0 + (a * a - 1.0) * xi.y));
    let sin_t = sqrt(1.0 - cos_t * cos_t);
    let h = tx * cos(phi) * sin_t + ty * sin(phi) * sin_t + n * cos_t;
    return normalize(2.0 * dot(n, h) * h - n);
}

// GGX prefilter of the captured cube around n, sampling a blurrier cube mip as the lobe widens.
fn prefilter_capture(n: vec3<f32>, roughness: f32) -> vec3<f32> {
    if (roughness <= 0.0) {
        return textureSampleLevel(env_cube, linear_clamp, n, 0.0).rgb;
    }
    let a = roughness * roughness;
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    let count = 16u;
    for (var i = 0u; i < count; i++) {
        let l = ggx_sample(n, a, i, count);
        let nl = dot(n, l);
        if (nl > 0.0) {
            sum += textureSampleLevel(env_cube, linear_clamp, l, 0.0).rgb * nl;
            weight += nl;
        }
    }
    return sum / max(weight, 1e-4);
}

fn store_mip(mip: u32, p: vec2<u32>, layer: u32, c: vec4<f32>) {
    switch mip {
        case 0u: { textureStore(dp_mip_0, p, layer, c); }
        case 1u: { textureStore(dp_mip_1, p, layer, c); }
        case 2u: { textureStore(dp_mip_2, p, layer, c); }
        case 3u: { textureStore(dp_mip_3, p, layer, c); }
        case 4u: { textureStore(dp_mip_4, p, layer, c); }
        default: { textureStore(dp_mip_5, p, layer, c); }
    }
}

// One dispatch per mip. z 0 is the captured probe (layer 0); z 1 the distant probes (every
// other layer), which all see the same sky and differ only by a ground term below the
// horizon: each texel samples the sky once and writes it to every distant layer, where one
// invocation per layer sampled the same texel 31 times.
@compute @workgroup_size(8, 8, 1)
fn cs_dual_paraboloid(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(max(512u >> params.mip, 1u), max(256u >> params.mip, 1u));
    if (any(id.xy >= size) || id.z > 1u) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let dir = paraboloid_direction(uv);
    let roughness = f32(params.mip) / f32(max(params.mip_count - 1u, 1u));
    if (id.z == 0u) {
        store_mip(params.mip, id.xy, 0u, vec4<f32>(prefilter_capture(dir, roughness), 1.0));
        return;
    }
    let sky_mips = f32(textureNumLevels(sky_cube) - 1u);
    let c = textureSampleLevel(sky_cube, linear_clamp, dir, roughness * sky_mips).rgb;
    for (var layer = 1u; layer < params.layers; layer++) {
        // Distant probes sit over the hills or the water: darken the lower hemisphere by
        // a ground term that varies per probe.
        let ground = 0.3 + 0.5 * fract(f32(layer) * 0.618);
        store_mip(params.mip, id.xy, layer, vec4<f32>(select(c, c * ground, dir.y < 0.0), 1.0));
    }
}
