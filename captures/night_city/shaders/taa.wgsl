// Temporal anti-aliasing and its blur chain. TAA reprojects last frame's output by the motion
// vectors (Catmull-Rom history fetch, so the history does not blur frame after frame), clamps
// it to the current 3x3 neighbourhood in YCoCg (variance clipping, Salvi 2016), and blends.
// The motion stencil lowers the history weight on moving objects, foliage and characters
// (anti-ghosting), the reflection mask on reflective pixels (reflections do not move with the
// surface's motion vectors). The blur chain builds the 1/2, 1/4 and 1/8 downscales in one
// dispatch, then blurs each mip horizontally and vertically (9-tap Gaussian): SSR reads it
// next frame as its pre-filtered reflection source.

struct FrameConstants {
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    mip: u32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var composite: texture_2d<f32>;
@group(0) @binding(3) var history: texture_2d<f32>;
@group(0) @binding(4) var motion_vectors: texture_2d<f32>;
@group(0) @binding(5) var motion_stencil: texture_2d<u32>;
@group(0) @binding(6) var reflection_mask: texture_2d<f32>;
@group(0) @binding(7) var linear_clamp: sampler;
@group(0) @binding(8) var taa_output: texture_2d<f32>;
@group(0) @binding(9) var down_0: texture_storage_2d<rgba16float, write>;
@group(0) @binding(10) var down_1: texture_storage_2d<rgba16float, write>;
@group(0) @binding(11) var down_2: texture_storage_2d<rgba16float, write>;
@group(0) @binding(12) var blur_source: texture_2d<f32>;

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

fn to_ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

fn from_ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// HDR values are tone-compressed before blending so one bright sample does not flicker.
fn compress(c: vec3<f32>) -> vec3<f32> {
    return c / (1.0 + max(max(c.r, c.g), c.b));
}

fn expand(c: vec3<f32>) -> vec3<f32> {
    return c / max(1.0 - max(max(c.r, c.g), c.b), 1e-4);
}

// Catmull-Rom history fetch with 5 bilinear taps (Jimenez's approximation).
fn history_catmull_rom(uv: vec2<f32>) -> vec3<f32> {
    let size = vec2<f32>(textureDimensions(history));
    let pos = uv * size;
    let centre = floor(pos - 0.5) + 0.5;
    let f = pos - centre;
    let w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    let w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    let w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    let w3 = f * f * (-0.5 + 0.5 * f);
    let w12 = w1 + w2;
    let tc0 = (centre - 1.0) / size;
    let tc3 = (centre + 2.0) / size;
    let tc12 = (centre + w2 / w12) / size;
    var c = textureSampleLevel(history, linear_clamp, vec2<f32>(tc12.x, tc0.y), 0.0).rgb * (w12.x * w0.y);
    c += textureSampleLevel(history, linear_clamp, vec2<f32>(tc0.x, tc12.y), 0.0).rgb * (w0.x * w12.y);
    c += textureSampleLevel(history, linear_clamp, tc12, 0.0).rgb * (w12.x * w12.y);
    c += textureSampleLevel(history, linear_clamp, vec2<f32>(tc3.x, tc12.y), 0.0).rgb * (w3.x * w12.y);
    c += textureSampleLevel(history, linear_clamp, vec2<f32>(tc12.x, tc3.y), 0.0).rgb * (w12.x * w3.y);
    let total = w12.x * w0.y + w0.x * w12.y + w12.x * w12.y + w3.x * w12.y + w12.x * w3.y;
    return max(c / total, vec3<f32>(0.0));
}

@fragment
fn fs_taa(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = vec2<i32>(in.clip.xy);
    let size = vec2<i32>(textureDimensions(composite)) - 1;
    let current = compress(textureLoad(composite, c, 0).rgb);
    // Neighbourhood mean and deviation in YCoCg; the closest motion vector of the 3x3 (so
    // edges of moving objects reproject with the object, not the background behind them).
    var m1 = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    var motion = vec2<f32>(0.0);
    var fastest = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let q = clamp(c + vec2<i32>(x, y), vec2<i32>(0), size);
            let s = to_ycocg(compress(textureLoad(composite, q, 0).rgb));
            m1 += s;
            m2 += s * s;
            let mv = textureLoad(motion_vectors, q, 0).xy;
            let speed = dot(mv, mv);
            if (speed >= fastest) {
                fastest = speed;
                motion = mv;
            }
        }
    }
    let mean = m1 / 9.0;
    let sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3<f32>(0.0)));
    let prev_uv = in.uv - motion;
    let outside = any(prev_uv < vec2<f32>(0.0)) || any(prev_uv > vec2<f32>(1.0));
    if (frame.time.z < 0.5 || outside) {
        return vec4<f32>(expand(current), 1.0);
    }
    let bits = textureLoad(motion_stencil, c, 0).r;
    var gamma = 1.25;
    var history_weight = 0.9;
    if ((bits & 1u) != 0u) {
        gamma = 0.75;
        history_weight = 0.8;
    }
    if ((bits & 6u) != 0u) {
        history_weight = min(history_weight, 0.75);
    }
    history_weight *= 1.0 - 0.4 * textureLoad(reflection_mask, c, 0).r;
    let lo = mean - gamma * sigma;
    let hi = mean + gamma * sigma;
    let h = clamp(to_ycocg(compress(history_catmull_rom(prev_uv))), lo, hi);
    let blended = mix(current, from_ycocg(h), history_weight);
    return vec4<f32>(expand(max(blended, vec3<f32>(0.0))), 1.0);
}

// One thread per 1/8-resolution texel: its 4x4 half-resolution texels (each a bilinear
// average of 2x2 full-resolution pixels), the 2x2 quarter-resolution ones, and itself.
@compute @workgroup_size(8, 8, 1)
fn cs_taa_downscale(@builtin(global_invocation_id) id: vec3<u32>) {
    let size2 = textureDimensions(down_2);
    let size0 = textureDimensions(down_0);
    let size1 = textureDimensions(down_1);
    if (any(id.xy >= size2)) {
        return;
    }
    var quarter = array<vec4<f32>, 4>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var y = 0u; y < 4u; y++) {
        for (var x = 0u; x < 4u; x++) {
            let p0 = id.xy * 4u + vec2<u32>(x, y);
            let uv = (vec2<f32>(p0) + 0.5) / vec2<f32>(size0);
            let c = textureSampleLevel(taa_output, linear_clamp, uv, 0.0);
            if (all(p0 < size0)) {
                textureStore(down_0, p0, c);
            }
            quarter[(y / 2u) * 2u + x / 2u] += c * 0.25;
        }
    }
    var eighth = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let p1 = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        if (all(p1 < size1)) {
            textureStore(down_1, p1, quarter[k]);
        }
        eighth += quarter[k] * 0.25;
    }
    textureStore(down_2, id.xy, eighth);
}

fn store_mip(p: vec2<u32>, c: vec4<f32>) {
    switch params.mip {
        case 0u: { textureStore(down_0, p, c); }
        case 1u: { textureStore(down_1, p, c); }
        default: { textureStore(down_2, p, c); }
    }
}

fn blur(id: vec2<u32>, axis: vec2<i32>) {
    let size = textureDimensions(blur_source, params.mip);
    if (any(id >= size)) {
        return;
    }
    let weights = array<f32, 5>(0.227027, 0.1945946, 0.1216216, 0.054054, 0.016216);
    let last = vec2<i32>(size) - 1;
    var sum = textureLoad(blur_source, vec2<i32>(id), i32(params.mip)) * weights[0];
    for (var k = 1; k < 5; k++) {
        let a = clamp(vec2<i32>(id) + axis * k, vec2<i32>(0), last);
        let b = clamp(vec2<i32>(id) - axis * k, vec2<i32>(0), last);
        sum += (textureLoad(blur_source, a, i32(params.mip)) + textureLoad(blur_source, b, i32(params.mip))) * weights[k];
    }
    store_mip(id, sum);
}

@compute @workgroup_size(8, 8, 1)
fn cs_blur_horizontal(@builtin(global_invocation_id) id: vec3<u32>) {
    blur(id.xy, vec2<i32>(1, 0));
}

@compute @workgroup_size(8, 8, 1)
fn cs_blur_vertical(@builtin(global_invocation_id) id: vec3<u32>) {
    blur(id.xy, vec2<i32>(0, 1));
}
