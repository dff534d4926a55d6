// Screen-space reflections in two steps. The tile mask (1/8 resolution) keeps the largest
// reflectivity of each 8x8 tile so the trace skips tiles that reflect nothing. The trace
// marches the reflected ray through the half-resolution linear depth (coarse steps that grow
// with distance, then a binary refinement), and at the hit fetches the previous frame's
// downscaled TAA output where that point was one frame ago (motion vectors), at a mip chosen
// by roughness: reflections come from a finished, anti-aliased image at no extra shading cost.
// Confidence fades at the screen border, with the ray's length, for rays towards the camera,
// and where the motion stencil says the history is unreliable; it scales the reflectivity
// written beside the colour, which the composition uses to blend SSR over the probes.

struct FrameConstants {
    view: mat4x4<f32>,
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var reflection_mask: texture_2d<f32>;
@group(0) @binding(2) var ssr_tiles: texture_2d<f32>;
@group(0) @binding(3) var depth_r32: texture_2d<f32>;
@group(0) @binding(4) var depth_half: texture_2d<f32>;
@group(0) @binding(5) var noised_normal: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(7) var motion_vectors: texture_2d<f32>;
@group(0) @binding(8) var motion_stencil: texture_2d<u32>;
@group(0) @binding(9) var taa_downscaled: texture_2d<f32>;
@group(0) @binding(10) var linear_clamp: sampler;

const TILE: i32 = 8;
const MARCH_STEPS: i32 = 40;
const REFINE_STEPS: i32 = 5;

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

// The largest reflectivity among 4x4 samples of the tile's 8x8 pixels.
@fragment
fn fs_ssr_tiles(in: FullscreenOut) -> @location(0) f32 {
    let base = vec2<i32>(in.clip.xy) * TILE;
    let size = vec2<i32>(textureDimensions(reflection_mask)) - 1;
    var m = 0.0;
    for (var y = 0; y < TILE; y += 2) {
        for (var x = 0; x < TILE; x += 2) {
            m = max(m, textureLoad(reflection_mask, min(base + vec2<i32>(x, y), size), 0).r);
        }
    }
    return m;
}

fn world_position(uv: vec2<f32>, d: f32) -> vec3<f32> {
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

fn forward() -> vec3<f32> {
    return -vec3<f32>(frame.view[0][2], frame.view[1][2], frame.view[2][2]);
}

// Screen UV (y down) and view depth of a world point.
fn project(p: vec3<f32>) -> vec3<f32> {
    let c = frame.view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xy / c.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, dot(p - frame.camera_position.xyz, forward()));
}

fn scene_depth(uv: vec2<f32>) -> f32 {
    let size = vec2<f32>(textureDimensions(depth_half));
    let p = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    return textureLoad(depth_half, p, 0).r;
}

struct SsrOut {
    @location(0) color: vec4<f32>,
    @location(1) reflectivity: f32,
}

@fragment
fn fs_ssr(in: FullscreenOut) -> SsrOut {
    var out: SsrOut;
    out.color = vec4<f32>(0.0);
    out.reflectivity = 0.0;
    let pixel = vec2<i32>(in.clip.xy);
    let tile = textureLoad(ssr_tiles, min(pixel / TILE, vec2<i32>(textureDimensions(ssr_tiles)) - 1), 0).r;
    let strength = textureLoad(reflection_mask, pixel, 0).r;
    let d = textureLoad(depth_r32, pixel, 0).r;
    // No history on the first frame; nothing to reflect on the sky or in dull tiles.
    if (tile < 0.02 || strength < 0.02 || d >= 1.0 || frame.time.z < 0.5) {
        return out;
    }
    let p = world_position(in.uv, d);
    let n = normalize(textureLoad(noised_normal, pixel, 0).xyz * 2.0 - 1.0);
    let v = normalize(p - frame.camera_position.xyz);
    let r = reflect(v, n);
    let towards_camera = dot(r, forward());
    if (towards_camera < -0.2) {
        return out;
    }
    let z0 = dot(p - frame.camera_position.xyz, forward());
    // Steps grow geometrically from ~1% of the view depth, so near and far rays both reach.
    var step_len = max(0.02 * z0, 0.05);
    var t = step_len;
    var prev_t = 0.0;
    var hit = -1.0;
    var hit_uv = vec2<f32>(0.0);
    var steps_taken = 0;
    for (var i = 0; i < MARCH_STEPS; i++) {
        let q = project(p + r * t);
        if (any(q.xy < vec2<f32>(0.0)) || any(q.xy > vec2<f32>(1.0)) || q.z <= 0.0) {
            break;
        }
        let scene = scene_depth(q.xy);
        let thickness = 0.3 + 0.04 * q.z;
        if (q.z > scene && q.z < scene + thickness + step_len) {
            hit = t;
            hit_uv = q.xy;
            steps_taken = i;
            break;
        }
        prev_t = t;
        step_len *= 1.12;
        t += step_len;
    }
    if (hit < 0.0) {
        return out;
    }
    // Binary refinement between the last miss and the hit.
    var lo = prev_t;
    var hi = hit;
    for (var k = 0; k < REFINE_STEPS; k++) {
        let mid = 0.5 * (lo + hi);
        let q = project(p + r * mid);
        if (q.z > scene_depth(q.xy)) {
            hi = mid;
            hit_uv = q.xy;
        } else {
            lo = mid;
        }
    }
    // Where the hit point was last frame, and how sharp the reflection is.
    let msize = vec2<i32>(textureDimensions(motion_vectors)) - 1;
    let mv = textureLoad(motion_vectors, clamp(vec2<i32>(hit_uv * frame.resolution.xy), vec2<i32>(0), msize), 0).xy;
    let prev_uv = hit_uv - mv;
    let roughness = textureLoad(gbuffer_material, pixel, 0).g;
    let mips = f32(textureNumLevels(taa_downscaled) - 1u);
    let color = textureSampleLevel(taa_downscaled, linear_clamp, prev_uv, roughness * mips * 2.0).rgb;
    let border = min(min(prev_uv.x, 1.0 - prev_uv.x), min(prev_uv.y, 1.0 - prev_uv.y));
    var confidence = smoothstep(0.0, 0.08, border);
    confidence *= 1.0 - f32(steps_taken) / f32(MARCH_STEPS);
    confidence *= smoothstep(-0.2, 0.1, towards_camera);
    let motion = textureLoad(motion_stencil, pixel, 0).r;
    if ((motion & 1u) != 0u) {
        confidence *= 0.5;
    }
    out.color = vec4<f32>(color, 1.0);
    out.reflectivity = strength * confidence;
    return out;
}
