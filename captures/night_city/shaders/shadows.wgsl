// Shadow resolve passes: the full-resolution sun (or moon) shadow mask from the four cascades,
// and the conversion of each omni light's paraboloid depth into a variance shadow map
// (Donnelly and Lauritzen, "Variance shadow maps").

struct FrameConstants {
    inv_view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    csm_view_proj_0: mat4x4<f32>,
    csm_view_proj_1: mat4x4<f32>,
    csm_view_proj_2: mat4x4<f32>,
    csm_view_proj_3: mat4x4<f32>,
    csm_splits: vec4<f32>,
    csm_texel: vec4<f32>,
    shadow_direction: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var depth_r32: texture_2d<f32>;
@group(0) @binding(2) var noised_normal: texture_2d<f32>;
@group(0) @binding(3) var csm: texture_depth_2d_array;
@group(0) @binding(4) var shadow_compare: sampler_comparison;
@group(0) @binding(5) var omni_depth: texture_depth_2d;
@group(0) @binding(6) var point_clamp: sampler;

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

fn cascade_matrix(c: u32) -> mat4x4<f32> {
    switch c {
        case 0u: { return frame.csm_view_proj_0; }
        case 1u: { return frame.csm_view_proj_1; }
        case 2u: { return frame.csm_view_proj_2; }
        default: { return frame.csm_view_proj_3; }
    }
}

// 12-tap Poisson-disc PCF in cascade `c`, radius 1.5 texels, each tap a hardware 2x2 compare.
fn pcf(c: u32, world: vec3<f32>, n: vec3<f32>, rotation: f32) -> f32 {
    let texel = frame.csm_texel[c];
    // Normal offset scaled by the cascade's texel size removes acne without peter-panning.
    let l = normalize(frame.shadow_direction.xyz);
    let slope = 1.0 - max(dot(n, l), 0.0);
    let p = world + n * texel * (1.0 + 2.0 * slope);
    let clip = cascade_matrix(c) * vec4<f32>(p, 1.0);
    let uv = clip.xy * vec2<f32>(0.5, -0.5) + 0.5;
    let reference = clip.z - 0.0005;
    let taps = array<vec2<f32>, 12>(
        vec2<f32>(-0.326, -0.406), vec2<f32>(-0.840, -0.074), vec2<f32>(-0.696, 0.457),
        vec2<f32>(-0.203, 0.621), vec2<f32>(0.962, -0.195), vec2<f32>(0.473, -0.480),
        vec2<f32>(0.519, 0.767), vec2<f32>(0.185, -0.893), vec2<f32>(0.507, 0.064),
        vec2<f32>(0.896, 0.412), vec2<f32>(-0.322, -0.933), vec2<f32>(-0.792, -0.598));
    let size = vec2<f32>(textureDimensions(csm));
    let cs = cos(rotation);
    let sn = sin(rotation);
    var lit = 0.0;
    for (var k = 0; k < 12; k++) {
        let t = taps[k];
        let o = vec2<f32>(t.x * cs - t.y * sn, t.x * sn + t.y * cs) * 1.5 / size;
        lit += textureSampleCompareLevel(csm, shadow_compare, uv + o, i32(c), reference);
    }
    return lit / 12.0;
}

fn in_cascade(c: u32, world: vec3<f32>) -> bool {
    let clip = cascade_matrix(c) * vec4<f32>(world, 1.0);
    return all(abs(clip.xy) < vec2<f32>(0.98)) && clip.z > 0.0 && clip.z < 1.0;
}

// Sun shadow: pick the cascade by view depth against the split distances, filter with PCF and
// blend into the next cascade over the last 15% of each split so the seams do not show.
@fragment
fn fs_sun_shadow(in: FullscreenOut) -> @location(0) f32 {
    let c = vec2<i32>(in.clip.xy);
    let d = textureLoad(depth_r32, c, 0).r;
    if (d >= 1.0) {
        return 1.0;
    }
    let ndc = vec4<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0, d, 1.0);
    let w = frame.inv_view_proj * ndc;
    let world = w.xyz / w.w;
    let n = normalize(textureLoad(noised_normal, c, 0).xyz * 2.0 - 1.0);
    let view_z = -(frame.view * vec4<f32>(world, 1.0)).z;
    if (view_z > frame.csm_splits.w) {
        return 1.0;
    }
    var cascade = 3u;
    for (var k = 0u; k < 4u; k++) {
        if (view_z <= frame.csm_splits[k] && in_cascade(k, world)) {
            cascade = k;
            break;
        }
    }
    let rotation = fract(sin(dot(in.clip.xy, vec2<f32>(12.9898, 78.233))) * 43758.5453) * 6.2831;
    var lit = pcf(cascade, world, n, rotation);
    let start = select(0.0, frame.csm_splits[max(cascade, 1u) - 1u], cascade > 0u);
    let end = frame.csm_splits[cascade];
    let blend = smoothstep(end - (end - start) * 0.15, end, view_z);
    if (cascade < 3u && blend > 0.0) {
        lit = mix(lit, pcf(cascade + 1u, world, n, rotation), blend);
    }
    // Fade to unshadowed at the shadow distance.
    return mix(lit, 1.0, smoothstep(frame.csm_splits.w * 0.9, frame.csm_splits.w, view_z));
}

// Variance shadow map of one omni light: the first two moments of the paraboloid depth,
// pre-filtered with a 5x5 box so the lighting pass can sample it bilinearly. The box is read
// as nine 2x2 gathers over the 6x6 block from -2 to +3 (the last column and row weighted out),
// a third of the 25 loads; the clamping sampler repeats edge texels as clamped loads did.
@fragment
fn fs_omni_vsm(in: FullscreenOut) -> @location(0) vec2<f32> {
    let c = floor(in.clip.xy);
    let texel = 1.0 / vec2<f32>(textureDimensions(omni_depth));
    var m = vec2<f32>(0.0);
    for (var gy = 0; gy < 3; gy++) {
        for (var gx = 0; gx < 3; gx++) {
            // The corner shared by texels (c - 2 + 2g) and (c - 1 + 2g).
            let corner = (c + vec2<f32>(f32(2 * gx - 1), f32(2 * gy - 1))) * texel;
            // x: (left, bottom), y: (right, bottom), z: (right, top), w: (left, top).
            let g = textureGather(omni_depth, point_clamp, corner);
            let right = select(1.0, 0.0, gx == 2);
            let bottom = select(1.0, 0.0, gy == 2);
            let w = vec4<f32>(bottom, right * bottom, right, 1.0);
            m += vec2<f32>(dot(g, w), dot(g * g, w));
        }
    }
    return m / 25.0;
}
