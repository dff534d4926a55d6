// From HDR to the display: the HDR LUTs and parameters computed each frame, the colour
// grading pass that uses them, and the gamma LUT.
//
// - hdr_lut_a (256x256): local tonemapping gain by (pixel log luminance, neighbourhood log
//   luminance): large-scale contrast is compressed towards mid grey, detail is kept but for
//   the largest steps, which are rolled off against halos.
// - hdr_lut_b (256x64): the Purkinje shift of night vision by (pixel log luminance, adapted log
//   luminance): dim pixels under dark adaptation lose saturation and shift towards blue.
// - hdr_lut_c (256x1): the filmic tone curve (ACES fit) over exposed log2 values.
// - hdr_params: exposure from the log-average luminance of the quarter-resolution image
//   (partial adaptation around the capture's exposure), bloom and flare settings.
// - gamma_lut (456x256): the display transfer per brightness setting (rows), over 456 input
//   levels (columns): the sRGB encoding of the value raised to the setting's gamma.

struct FrameConstants {
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    // Bloom threshold (exposed luminance), bloom and lens flare intensities.
    bloom_threshold: f32,
    bloom_intensity: f32,
    flare_intensity: f32,
    // How far exposure adapts to the image (0 fixed, 1 fully).
    adaptation: f32,
}

struct HdrParams {
    values: array<vec4<f32>, 16>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var hdr_lut_a_out: texture_storage_2d<r16float, write>;
@group(0) @binding(3) var hdr_lut_b_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(4) var hdr_lut_c_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(5) var<storage, read_write> hdr_params_out: HdrParams;
@group(0) @binding(6) var post_quarter: texture_2d<f32>;
@group(0) @binding(7) var<storage, read> hdr_params: HdrParams;
@group(0) @binding(8) var post_sharpened: texture_2d<f32>;
@group(0) @binding(9) var bloom_chain: texture_2d<f32>;
@group(0) @binding(10) var lens_flare: texture_2d<f32>;
@group(0) @binding(11) var grading_lut: texture_3d<f32>;
@group(0) @binding(12) var hdr_lut_a: texture_2d<f32>;
@group(0) @binding(13) var hdr_lut_b: texture_2d<f32>;
@group(0) @binding(14) var hdr_lut_c: texture_2d<f32>;
@group(0) @binding(15) var linear_clamp: sampler;
@group(0) @binding(16) var gamma_lut_out: texture_storage_2d<rgba8unorm, write>;

// Log2 luminance range the LUTs cover.
const LOG_MIN: f32 = -12.0;
const LOG_MAX: f32 = 6.0;
const MID_GREY: f32 = 0.18;

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn to_log(u: f32) -> f32 {
    return mix(LOG_MIN, LOG_MAX, u);
}

fn lut_u(log_value: f32) -> f32 {
    return clamp((log_value - LOG_MIN) / (LOG_MAX - LOG_MIN), 0.0, 1.0);
}

fn cell(id: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(id) + 0.5) / vec2<f32>(size);
}

@compute @workgroup_size(8, 8, 1)
fn cs_hdr_lut_a(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(hdr_lut_a_out);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = cell(id.xy, size);
    let pixel = to_log(uv.x);
    let local = to_log(uv.y);
    let mid = log2(MID_GREY);
    // Base layer compressed to 60% of its range around mid grey; the detail layer kept, with
    // large differences (a bright light against a dark neighbourhood, where halos would
    // appear) rolled off softly.
    let detail = pixel - local;
    let target_log = mid + (local - mid) * 0.6 + detail / (1.0 + abs(detail) * 0.15);
    let gain = clamp(exp2(target_log - pixel), 1.0 / 64.0, 64.0);
    textureStore(hdr_lut_a_out, id.xy, vec4<f32>(gain, 0.0, 0.0, 1.0));
}

@compute @workgroup_size(8, 8, 1)
fn cs_hdr_lut_b(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(hdr_lut_b_out);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = cell(id.xy, size);
    let pixel = to_log(uv.x);
    let adapted = to_log(uv.y);
    // Rods take over under dark adaptation, and only for dim pixels.
    let scotopic = (1.0 - smoothstep(-9.0, -3.0, adapted)) * (1.0 - smoothstep(-7.0, 0.0, pixel));
    let tint = vec3<f32>(0.55, 0.75, 1.25);
    textureStore(hdr_lut_b_out, id.xy, vec4<f32>(tint, scotopic * 0.8));
}

// ACES filmic fit (Narkowicz 2015).
fn aces(x: f32) -> f32 {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

@compute @workgroup_size(64, 1, 1)
fn cs_hdr_lut_c(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(hdr_lut_c_out);
    if (id.x >= size.x) {
        return;
    }
    let x = exp2(to_log((f32(id.x) + 0.5) / f32(size.x)));
    // Film stocks roll off each layer slightly differently: red keeps its highlights longest.
    let c = vec3<f32>(aces(x * 1.02), aces(x), aces(x * 0.96));
    textureStore(hdr_lut_c_out, vec2<u32>(id.x, 0u), vec4<f32>(c, 1.0));
}

var<workgroup> partial_log: array<f32, 256>;
var<workgroup> partial_weight: array<f32, 256>;

// One workgroup: the centre-weighted log-average luminance of the quarter image, and the
// exposure that adapts `adaptation` of the way from the capture's towards mid grey.
@compute @workgroup_size(16, 16, 1)
fn cs_hdr_params(@builtin(local_invocation_index) li: u32) {
    let size = textureDimensions(post_quarter);
    var sum = 0.0;
    var weight = 0.0;
    for (var y = li / 16u; y < size.y; y += 16u) {
        for (var x = li % 16u; x < size.x; x += 16u) {
            let l = luminance(textureLoad(post_quarter, vec2<u32>(x, y), 0).rgb);
            let uv = cell(vec2<u32>(x, y), size) - 0.5;
            let w = 1.0 - 0.8 * min(dot(uv, uv) * 4.0, 1.0);
            sum += log2(max(l, 1e-6)) * w;
            weight += w;
        }
    }
    partial_log[li] = sum;
    partial_weight[li] = weight;
    workgroupBarrier();
    for (var stride = 128u; stride > 0u; stride >>= 1u) {
        if (li < stride) {
            partial_log[li] += partial_log[li + stride];
            partial_weight[li] += partial_weight[li + stride];
        }
        workgroupBarrier();
    }
    if (li == 0u) {
        let avg_log = partial_log[0] / max(partial_weight[0], 1e-4);
        let base = frame.time.w;
        let wanted = MID_GREY / exp2(avg_log);
        let exposure = base * exp2(clamp(log2(wanted / base) * params.adaptation, -2.0, 2.0));
        hdr_params_out.values[0] = vec4<f32>(exposure, avg_log, avg_log + log2(exposure), 0.0);
        hdr_params_out.values[1] = vec4<f32>(params.bloom_threshold, params.bloom_intensity, params.flare_intensity, 0.0);
        for (var k = 2u; k < 16u; k++) {
            hdr_params_out.values[k] = vec4<f32>(0.0);
        }
    }
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

// Exposure, bloom (the six levels, wider ones weighted less) and flare, local tonemapping,
// the Purkinje shift, the filmic curve per channel, then the 3D grading LUT and a vignette.
// Output is display-linear; the gamma LUT encodes it in the grain pass.
@fragment
fn fs_color_grading(in: FullscreenOut) -> @location(0) vec4<f32> {
    let hdr = hdr_params.values[0];
    let exposure = hdr.x;
    let settings = hdr_params.values[1];
    var c = textureLoad(post_sharpened, vec2<i32>(in.clip.xy), 0).rgb * exposure;
    var bloom = vec3<f32>(0.0);
    var total = 0.0;
    for (var k = 0; k < 6; k++) {
        let w = 1.0 / (1.0 + f32(k) * 0.6);
        bloom += textureSampleLevel(bloom_chain, linear_clamp, in.uv, f32(k)).rgb * w;
        total += w;
    }
    c += bloom / total * settings.y;
    c += textureSampleLevel(lens_flare, linear_clamp, in.uv, 0.0).rgb * settings.z;
    let l = max(luminance(c), 1e-6);
    // The neighbourhood: five wide taps of the quarter-resolution image.
    var around = 0.0;
    for (var k = 0; k < 5; k++) {
        let a = f32(k) * 1.2566;
        let o = select(vec2<f32>(cos(a), sin(a)) * 0.03, vec2<f32>(0.0), k == 0);
        around += luminance(textureSampleLevel(post_quarter, linear_clamp, in.uv + o, 0.0).rgb);
    }
    let local_log = log2(max(around / 5.0 * exposure, 1e-6));
    let gain = textureSampleLevel(hdr_lut_a, linear_clamp, vec2<f32>(lut_u(log2(l)), lut_u(local_log)), 0.0).r;
    c *= gain;
    let shift = textureSampleLevel(hdr_lut_b, linear_clamp, vec2<f32>(lut_u(log2(l)), lut_u(hdr.z)), 0.0);
    c = mix(c, vec3<f32>(luminance(c)) * shift.rgb, shift.a);
    let u = vec3<f32>(lut_u(log2(max(c.r, 1e-6))), lut_u(log2(max(c.g, 1e-6))), lut_u(log2(max(c.b, 1e-6))));
    let mapped = vec3<f32>(
        textureSampleLevel(hdr_lut_c, linear_clamp, vec2<f32>(u.r, 0.5), 0.0).r,
        textureSampleLevel(hdr_lut_c, linear_clamp, vec2<f32>(u.g, 0.5), 0.0).g,
        textureSampleLevel(hdr_lut_c, linear_clamp, vec2<f32>(u.b, 0.5), 0.0).b,
    );
    let n = f32(textureDimensions(grading_lut).x);
    let graded = textureSampleLevel(grading_lut, linear_clamp, mapped * ((n - 1.0) / n) + 0.5 / n, 0.0).rgb;
    let d = in.uv - 0.5;
    let vignette = 1.0 - 0.7 * dot(d, d);
    return vec4<f32>(graded * vignette, 1.0);
}

fn srgb_encode(x: f32) -> f32 {
    if (x <= 0.0031308) {
        return x * 12.92;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(8, 8, 1)
fn cs_gamma_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gamma_lut_out);
    if (any(id.xy >= size)) {
        return;
    }
    let x = f32(id.x) / f32(size.x - 1u);
    // Brightness settings from gamma 1.4 (brightest) to 0.7 (darkest); 1.0 a little above
    // the middle row.
    let setting = f32(id.y) / f32(size.y - 1u);
    let gamma = mix(1.4, 0.7, setting);
    let v = srgb_encode(pow(x, 1.0 / gamma));
    textureStore(gamma_lut_out, id.xy, vec4<f32>(v, v, v, 1.0));
}
