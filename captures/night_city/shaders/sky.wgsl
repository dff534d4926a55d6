// The sky: an analytic single-scattering-style sky model (Rayleigh gradient, Mie halo, sun
// disk) with clouds from the cloud distribution map, captured into a cube map whose mips are
// GGX-prefiltered by roughness (split-sum, Karis 2013), a stereographic projection of the upper
// hemisphere, and the pass that draws the sky behind the city where the sky mask says.

struct FrameConstants {
    inv_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    moon_direction: vec4<f32>,
    moon_color: vec4<f32>,
}

struct Params {
    mip: u32,
    mip_count: u32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var cloud_distribution: texture_2d<f32>;
@group(0) @binding(3) var linear_wrap: sampler;
@group(0) @binding(4) var linear_clamp: sampler;
@group(0) @binding(5) var sky_mip_0: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(6) var sky_mip_1: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(7) var sky_mip_2: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(8) var sky_mip_3: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(9) var sky_mip_4: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(10) var sky_mip_5: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(11) var sky_mip_6: texture_storage_2d_array<rg11b10ufloat, write>;
@group(0) @binding(12) var sky_projected: texture_storage_2d<rg11b10ufloat, write>;
@group(0) @binding(13) var sky_mask: texture_2d<f32>;
@group(0) @binding(14) var sky_mask_coarse: texture_2d<f32>;
@group(0) @binding(15) var sky_cube: texture_cube<f32>;
@group(0) @binding(16) var sky_projection: texture_2d<f32>;

const PI: f32 = 3.14159265;

// Sky radiance (scene-linear, same units as sun_color) in direction `dir`.
fn sky_radiance(dir: vec3<f32>, with_sun: bool) -> vec3<f32> {
    let sun = normalize(frame.sun_direction.xyz);
    let up = max(dir.y, 0.0);
    let day = clamp(sun.y * 4.0 + 0.3, 0.0, 1.0);
    let zenith = vec3<f32>(0.12, 0.28, 0.65);
    let horizon = vec3<f32>(0.55, 0.62, 0.7);
    let below = vec3<f32>(0.12, 0.11, 0.1);
    // Rayleigh-like: deep blue at the zenith, pale at the horizon (optical depth grows).
    var c = mix(horizon, zenith, pow(up, 0.45));
    let cos_theta = dot(dir, sun);
    let rayleigh_phase = 0.75 * (1.0 + cos_theta * cos_theta);
    c *= rayleigh_phase;
    // Mie halo around the sun (Henyey-Greenstein, g = 0.8).
    let g = 0.8;
    let mie = (1.0 - g * g) / pow(1.0 + g * g - 2.0 * g * cos_theta, 1.5) / (4.0 * PI);
    c += vec3<f32>(1.0, 0.9, 0.75) * mie * 0.6;
    c *= frame.sun_color.rgb * 0.18 * day;
    // Night: moonlit dark blue.
    c += vec3<f32>(0.01, 0.015, 0.03) * (1.0 - day) * (0.5 + up);
    if (dir.y < 0.0) {
        c = mix(c, below * frame.sun_color.rgb * 0.05 * day + 0.005, smoothstep(0.0, -0.15, dir.y));
    }
    // Clouds on a plane 2 km up, lit by the sun from above, darker in dense cores.
    if (dir.y > 0.01) {
        let hit = dir.xz / dir.y * 2.0;
        let cl = textureSampleLevel(cloud_distribution, linear_wrap, hit * 0.08 + 0.5, 0.0);
        let fade = smoothstep(0.01, 0.2, dir.y);
        let lit = frame.sun_color.rgb * 0.1 * (1.0 - cl.g * 0.6) * (0.6 + 0.4 * max(cos_theta, 0.0)) * day;
        c = mix(c, lit + 0.01, cl.r * fade * 0.9);
    }
    if (with_sun && cos_theta > 0.99996) {
        c += frame.sun_color.rgb * 40.0;
    }
    return c;
}

fn cube_direction(face: u32, uv: vec2<f32>) -> vec3<f32> {
    let u = uv.x * 2.0 - 1.0;
    let v = uv.y * 2.0 - 1.0;
    switch face {
        case 0u: { return normalize(vec3<f32>(1.0, -v, -u)); }
        case 1u: { return normalize(vec3<f32>(-1.0, -v, u)); }
        case 2u: { return normalize(vec3<f32>(u, 1.0, v)); }
        case 3u: { return normalize(vec3<f32>(u, -1.0, -v)); }
        case 4u: { return normalize(vec3<f32>(u, -v, 1.0)); }
        default: { return normalize(vec3<f32>(-u, -v, -1.0)); }
    }
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

// GGX-prefiltered radiance around `n` (= v = r, the split-sum assumption) for `roughness`.
fn prefiltered(n: vec3<f32>, roughness: f32) -> vec3<f32> {
    if (roughness <= 0.0) {
        return sky_radiance(n, false);
    }
    let a = roughness * roughness;
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    let count = 48u;
    for (var i = 0u; i < count; i++) {
        let l = ggx_sample(n, a, i, count);
        let nl = dot(n, l);
        if (nl > 0.0) {
            sum += sky_radiance(l, false) * nl;
            weight += nl;
        }
    }
    return sum / max(weight, 1e-4);
}

fn store_mip(mip: u32, p: vec2<u32>, face: u32, c: vec4<f32>) {
    switch mip {
        case 0u: { textureStore(sky_mip_0, p, face, c); }
        case 1u: { textureStore(sky_mip_1, p, face, c); }
        case 2u: { textureStore(sky_mip_2, p, face, c); }
        case 3u: { textureStore(sky_mip_3, p, face, c); }
        case 4u: { textureStore(sky_mip_4, p, face, c); }
        case 5u: { textureStore(sky_mip_5, p, face, c); }
        default: { textureStore(sky_mip_6, p, face, c); }
    }
}

// One dispatch per mip (z = face): mip m holds the sky prefiltered for roughness m / (n - 1).
@compute @workgroup_size(8, 8, 1)
fn cs_sky_cube(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = max(64u >> params.mip, 1u);
    if (any(id.xy >= vec2<u32>(size))) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / f32(size);
    let dir = cube_direction(id.z, uv);
    let roughness = f32(params.mip) / f32(max(params.mip_count - 1u, 1u));
    store_mip(params.mip, id.xy, id.z, vec4<f32>(prefiltered(dir, roughness), 1.0));
}

// Stereographic projection of the upper hemisphere: p = dir.xz / (1 + dir.y).
@compute @workgroup_size(8, 8, 1)
fn cs_sky_projected(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(sky_projected);
    if (any(id.xy >= size)) {
        return;
    }
    let p = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size) * 2.0 - 1.0;
    let r2 = dot(p, p);
    var c = vec3<f32>(0.0);
    if (r2 <= 1.0) {
        let dir = vec3<f32>(2.0 * p.x, 1.0 - r2, 2.0 * p.y) / (1.0 + r2);
        c = sky_radiance(dir, true);
    }
    textureStore(sky_projected, id.xy, vec4<f32>(c, 1.0));
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

// The sky behind the city: only where the sky mask is set (coarse mip first, to skip whole
// blocks of geometry cheaply). Upper hemisphere from the stereographic map, the rest from the
// cube, the sun disk analytically.
@fragment
fn fs_sky(in: FullscreenOut) -> @location(0) vec4<f32> {
    let coarse_size = vec2<f32>(textureDimensions(sky_mask_coarse, 3));
    if (textureLoad(sky_mask_coarse, vec2<i32>(in.uv * coarse_size), 3).r <= 0.0) {
        discard;
    }
    if (textureLoad(sky_mask, vec2<i32>(in.clip.xy), 0).r <= 0.0) {
        discard;
    }
    let ndc = vec4<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0, 1.0, 1.0);
    let w = frame.inv_view_proj * ndc;
    let dir = normalize(w.xyz / w.w - frame.camera_position.xyz);
    var c: vec3<f32>;
    if (dir.y > 0.0) {
        let p = dir.xz / (1.0 + dir.y);
        c = textureSampleLevel(sky_projection, linear_clamp, p * 0.5 + 0.5, 0.0).rgb;
    } else {
        c = textureSampleLevel(sky_cube, linear_clamp, dir, 0.0).rgb;
    }
    let sun = normalize(frame.sun_direction.xyz);
    let d = dot(dir, sun);
    c += frame.sun_color.rgb * 40.0 * smoothstep(0.99995, 0.99998, d);
    // The moon: a disc of about a degree with a faint halo, where the sun is below the horizon.
    if (sun.y < 0.0) {
        let m = dot(dir, normalize(frame.moon_direction.xyz));
        c += frame.moon_color.rgb * (600.0 * smoothstep(0.99984, 0.99988, m) + 4.0 * pow(max(m, 0.0), 400.0));
    }
    return vec4<f32>(c, 1.0);
}
