// The HDR post chain after TAA, up to the tonemap: low clouds over the sky (drawn after TAA
// so they do not ghost), the post-TAA downscale (1/2 and 1/4) and the sharpen back at full
// resolution, bloom over six half-size levels, and the lens flare built from them.

struct FrameConstants {
    inv_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    moon_direction: vec4<f32>,
    moon_color: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    // Low cloud deck height (m) and how much the city lights it from below at night.
    cloud_height: f32,
    city_glow: f32,
}

// Sharpen strength of the post-TAA pass, before the adaptive fall-off.
const SHARPEN: f32 = 0.6;

// hdr_params as tonemap.wgsl writes it: [0] exposure, log2 average luminance, log2
// adaptation luminance; [1] bloom threshold, bloom intensity, flare intensity.
struct HdrParams {
    values: array<vec4<f32>, 16>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var taa_output: texture_2d<f32>;
@group(0) @binding(3) var depth_r32: texture_2d<f32>;
@group(0) @binding(4) var cloud_distribution: texture_2d<f32>;
@group(0) @binding(5) var linear_wrap: sampler;
@group(0) @binding(6) var linear_clamp: sampler;
@group(0) @binding(7) var composite_post: texture_2d<f32>;
@group(0) @binding(8) var post_half_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(9) var post_quarter_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(10) var post_half: texture_2d<f32>;
@group(0) @binding(11) var post_sharpened_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(12) var post_sharpened: texture_2d<f32>;
@group(0) @binding(13) var<storage, read> hdr_params: HdrParams;
@group(0) @binding(14) var bloom_out: texture_storage_2d<rg11b10ufloat, write>;
@group(0) @binding(15) var bloom_source: texture_2d<f32>;
@group(0) @binding(16) var bloom_chain: texture_2d<f32>;

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

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Low clouds: a deck at `cloud_height` textured by the cloud distribution map (coverage and
// density), lit by the sun or moon from above and, at night, by the city from below (the
// orange underside of clouds over a lit city). Coverage fades towards the horizon.
@fragment
fn fs_clouds(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = vec2<i32>(in.clip.xy);
    let scene = textureLoad(taa_output, c, 0);
    if (textureLoad(depth_r32, c, 0).r < 1.0) {
        return scene;
    }
    let ndc = vec4<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0, 1.0, 1.0);
    let w = frame.inv_view_proj * ndc;
    let dir = normalize(w.xyz / w.w - frame.camera_position.xyz);
    if (dir.y <= 0.02) {
        return scene;
    }
    let hit = frame.camera_position.xz + dir.xz * (params.cloud_height - frame.camera_position.y) / dir.y;
    let drift = vec2<f32>(frame.time.x * 0.004, frame.time.x * 0.0015);
    let cl = textureSampleLevel(cloud_distribution, linear_wrap, hit / 4000.0 + drift, 0.0);
    let detail = textureSampleLevel(cloud_distribution, linear_wrap, hit / 900.0 - drift * 2.0, 0.0).g;
    let coverage = smoothstep(0.1, 0.8, cl.r * (0.7 + 0.6 * detail)) * smoothstep(0.02, 0.25, dir.y);
    let sun = normalize(frame.sun_direction.xyz);
    let day = clamp(sun.y * 4.0 + 0.3, 0.0, 1.0);
    let light = select(frame.moon_color.rgb, frame.sun_color.rgb, sun.y > 0.0);
    let above = light * 0.09 * (1.0 - cl.g * 0.5);
    let below = vec3<f32>(0.9, 0.45, 0.6) * params.city_glow * (1.0 - day) * (0.5 + cl.g);
    let cloud = above + below;
    return vec4<f32>(mix(scene.rgb, cloud, coverage * 0.85), 1.0);
}

// One thread per quarter-resolution texel: four bilinear taps give its 2x2 half-resolution
// texels (each the mean of 2x2 pixels) and their mean.
@compute @workgroup_size(8, 8, 1)
fn cs_post_downscale(@builtin(global_invocation_id) id: vec3<u32>) {
    let quarter = textureDimensions(post_quarter_out);
    if (any(id.xy >= quarter)) {
        return;
    }
    let full = vec2<f32>(textureDimensions(composite_post));
    let half_size = textureDimensions(post_half_out);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let p = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        let uv = (vec2<f32>(p * 2u) + 1.0) / full;
        let c = textureSampleLevel(composite_post, linear_clamp, uv, 0.0);
        if (all(p < half_size)) {
            textureStore(post_half_out, p, c);
        }
        sum += c;
    }
    textureStore(post_quarter_out, id.xy, sum * 0.25);
}

// Unsharp mask against the half-resolution image, adaptive like AMD's CAS: the amount falls
// where local contrast is already high, so edges do not ring.
@compute @workgroup_size(8, 8, 1)
fn cs_post_sharpen(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(post_sharpened_out);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let c = textureLoad(composite_post, id.xy, 0).rgb;
    let blurred = textureSampleLevel(post_half, linear_clamp, uv, 0.0).rgb;
    let detail = c - blurred;
    let contrast = abs(luminance(detail)) / (luminance(blurred) + 0.05);
    let amount = SHARPEN * (1.0 - smoothstep(0.0, 1.0, contrast));
    textureStore(post_sharpened_out, id.xy, vec4<f32>(max(c + detail * amount, vec3<f32>(0.0)), 1.0));
}

// Bloom level 0: the exposed image's bright part (soft-knee threshold) at half resolution,
// averaged with Karis weights (1 / (1 + luma)) so single bright pixels do not flicker.
@compute @workgroup_size(8, 8, 1)
fn cs_bloom_prefilter(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(bloom_out);
    if (any(id.xy >= size)) {
        return;
    }
    let full = vec2<f32>(textureDimensions(post_sharpened));
    let exposure = hdr_params.values[0].x;
    let threshold = hdr_params.values[1].x;
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let o = vec2<f32>(f32(k & 1u), f32(k >> 1u)) - 0.5;
        let uv = (vec2<f32>(id.xy) * 2.0 + 1.0 + o) / full;
        let c = textureSampleLevel(post_sharpened, linear_clamp, uv, 0.0).rgb * exposure;
        let l = luminance(c);
        let knee = threshold * 0.5;
        let soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
        let contribution = max(soft * soft / (4.0 * knee + 1e-4), l - threshold) / max(l, 1e-4);
        let w = 1.0 / (1.0 + l);
        sum += c * max(contribution, 0.0) * w;
        weight += w;
    }
    textureStore(bloom_out, id.xy, vec4<f32>(sum / max(weight, 1e-4), 1.0));
}

// Bloom levels 1-5: the 13-tap downsample (Jimenez 2014) of the previous level.
@compute @workgroup_size(8, 8, 1)
fn cs_bloom_downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(bloom_out);
    if (any(id.xy >= size)) {
        return;
    }
    let texel = 1.0 / vec2<f32>(textureDimensions(bloom_source));
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let s = texel;
    let a = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(-2.0, -2.0), 0.0).rgb;
    let b = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(0.0, -2.0), 0.0).rgb;
    let c = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(2.0, -2.0), 0.0).rgb;
    let d = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(-2.0, 0.0), 0.0).rgb;
    let e = textureSampleLevel(bloom_source, linear_clamp, uv, 0.0).rgb;
    let f = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(2.0, 0.0), 0.0).rgb;
    let g = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(-2.0, 2.0), 0.0).rgb;
    let h = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(0.0, 2.0), 0.0).rgb;
    let i = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(2.0, 2.0), 0.0).rgb;
    let j = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(-1.0, -1.0), 0.0).rgb;
    let k = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(1.0, -1.0), 0.0).rgb;
    let l = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(-1.0, 1.0), 0.0).rgb;
    let m = textureSampleLevel(bloom_source, linear_clamp, uv + s * vec2<f32>(1.0, 1.0), 0.0).rgb;
    var r = e * 0.125 + (a + c + g + i) * 0.03125 + (b + d + f + h) * 0.0625 + (j + k + l + m) * 0.125;
    textureStore(bloom_out, id.xy, vec4<f32>(r, 1.0));
}

// Lens flare at half resolution (after Chapman): ghosts are the bright bloom mirrored through
// the image centre at several spacings, a halo ring, both with chromatic separation and a
// tint that changes with distance from the centre, fading towards the edges of the lens.
@fragment
fn fs_lens_flare(in: FullscreenOut) -> @location(0) vec4<f32> {
    let uv = vec2<f32>(1.0) - in.uv;
    let ghost_vec = (vec2<f32>(0.5) - uv) * 0.42;
    let dispersal = vec3<f32>(-0.006, 0.0, 0.006);
    var flare = vec3<f32>(0.0);
    for (var i = 0; i < 6; i++) {
        let o = fract(uv + ghost_vec * f32(i));
        let w = pow(1.0 - length(vec2<f32>(0.5) - o) / 0.7071, 8.0);
        let dir = normalize(ghost_vec + 1e-5);
        let col = vec3<f32>(
            textureSampleLevel(bloom_chain, linear_clamp, o + dir * dispersal.r, 2.0).r,
            textureSampleLevel(bloom_chain, linear_clamp, o, 2.0).g,
            textureSampleLevel(bloom_chain, linear_clamp, o + dir * dispersal.b, 2.0).b,
        );
        let tint = mix(vec3<f32>(1.0, 0.6, 0.3), vec3<f32>(0.3, 0.6, 1.0), f32(i) / 5.0);
        flare += col * w * tint;
    }
    let halo_vec = normalize(ghost_vec + 1e-5) * 0.45;
    let hw = pow(1.0 - length(vec2<f32>(0.5) - fract(uv + halo_vec)) / 0.7071, 5.0);
    flare += textureSampleLevel(bloom_chain, linear_clamp, uv + halo_vec, 3.0).rgb * hw * vec3<f32>(0.8, 0.5, 1.0);
    let edge = smoothstep(0.75, 0.2, length(in.uv - 0.5));
    return vec4<f32>(flare * edge, 1.0);
}
