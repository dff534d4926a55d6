// Screen-space passes that derive masks from the depth/stencil and the G-buffer: depth and
// stencil conversion, the dilated motion stencil, the reflection, coat and head masks, the
// noised normal and the coarse and accurate sky masks.

struct FrameConstants {
    proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    resolution: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var depth: texture_depth_2d;
@group(0) @binding(2) var stencil: texture_2d<u32>;
@group(0) @binding(3) var depth_half: texture_2d<f32>;
@group(0) @binding(4) var motion_vectors: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(7) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(8) var depth_r32: texture_2d<f32>;
@group(0) @binding(9) var blue_noise: texture_2d<f32>;
@group(0) @binding(10) var noised_normal: texture_storage_2d<rgb10a2unorm, write>;
@group(0) @binding(11) var coarse_previous: texture_2d<f32>;
@group(0) @binding(12) var sky_mask_coarse: texture_2d<f32>;

// Stencil bits written by the base pass: characters 0x15 body / 0x35 face / 0x95 hair,
// foliage 0xA0.
const STENCIL_CHARACTER: u32 = 0x15u;
const STENCIL_FACE: u32 = 0x35u;
const STENCIL_FOLIAGE: u32 = 0xA0u;

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

// View-space distance along the view axis from a device depth (perspective_rh, z in [0, 1]).
fn linear_depth(d: f32) -> f32 {
    let a = frame.proj[2][2];
    let b = frame.proj[3][2];
    return b / (d + a);
}

// ds_convert 1: the depth as R32_FLOAT (device depth, full resolution).
@fragment
fn fs_depth_r32(in: FullscreenOut) -> @location(0) f32 {
    return textureLoad(depth, vec2<i32>(in.clip.xy), 0);
}

// ds_convert 2: half-resolution linear depth, the nearest of each 2x2 block (conservative for
// occlusion and sky tests).
@fragment
fn fs_depth_half(in: FullscreenOut) -> @location(0) f32 {
    let base = vec2<i32>(in.clip.xy) * 2;
    let size = vec2<i32>(textureDimensions(depth)) - 1;
    var nearest = 1.0;
    for (var k = 0; k < 4; k++) {
        let p = min(base + vec2<i32>(k & 1, k >> 1), size);
        nearest = min(nearest, textureLoad(depth, p, 0));
    }
    return linear_depth(nearest);
}

// ds_convert 3: half-resolution stencil, the bits of any pixel in the 2x2 block.
@fragment
fn fs_stencil_half(in: FullscreenOut) -> @location(0) u32 {
    let base = vec2<i32>(in.clip.xy) * 2;
    let size = vec2<i32>(textureDimensions(stencil)) - 1;
    var bits = 0u;
    for (var k = 0; k < 4; k++) {
        bits = bits | textureLoad(stencil, min(base + vec2<i32>(k & 1, k >> 1), size), 0).r;
    }
    return bits;
}

// Motion stencil: bit 0 moving (|motion| above a pixel), bit 1 foliage, bit 2 characters and
// fur, dilated over a 5x5 neighbourhood so TAA rejects history around moving edges too.
@fragment
fn fs_motion_stencil(in: FullscreenOut) -> @location(0) u32 {
    let c = vec2<i32>(in.clip.xy);
    let size = vec2<i32>(textureDimensions(motion_vectors)) - 1;
    var bits = 0u;
    for (var y = -2; y <= 2; y++) {
        for (var x = -2; x <= 2; x++) {
            let p = clamp(c + vec2<i32>(x, y), vec2<i32>(0), size);
            let mv = textureLoad(motion_vectors, p, 0).xy * frame.resolution.xy;
            let s = textureLoad(stencil, p, 0).r;
            if (length(mv) > 0.5) {
                bits = bits | 1u;
            }
            if (s == STENCIL_FOLIAGE) {
                bits = bits | 2u;
            }
            if ((s & 0x0Fu) == (STENCIL_CHARACTER & 0x0Fu) && s != 0u && s != STENCIL_FOLIAGE) {
                bits = bits | 4u;
            }
        }
    }
    return bits;
}

fn world_position(uv: vec2<f32>, d: f32) -> vec3<f32> {
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

// Reflection mask: how much a pixel reflects (smooth and metallic surfaces, water, wet
// street), by Schlick's Fresnel at the view angle scaled by smoothness; sky is 0.
@fragment
fn fs_reflection_mask(in: FullscreenOut) -> @location(0) f32 {
    let c = vec2<i32>(in.clip.xy);
    let d = textureLoad(depth_r32, c, 0).r;
    if (d >= 1.0) {
        return 0.0;
    }
    let n = normalize(textureLoad(gbuffer_normal, c, 0).xyz * 2.0 - 1.0);
    let m = textureLoad(gbuffer_material, c, 0);
    let p = world_position(in.uv, d);
    let v = normalize(frame.camera_position.xyz - p);
    let f0 = mix(0.04, 0.9, m.x);
    let fresnel = f0 + (1.0 - f0) * pow(1.0 - max(dot(n, v), 0.0), 5.0);
    let smooth_ = 1.0 - m.y;
    return clamp(fresnel * smooth_ * smooth_ * 1.5, 0.0, 1.0);
}

// Noised normal (compute): the G-buffer normal rotated by a small blue-noise cone, so the
// stochastic passes that sample around it (sun shadow, AO, SSR, sky light) decorrelate.
@compute @workgroup_size(8, 8, 1)
fn cs_noised_normal(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gbuffer_normal);
    if (any(id.xy >= size)) {
        return;
    }
    let n = normalize(textureLoad(gbuffer_normal, id.xy, 0).xyz * 2.0 - 1.0);
    let noise = textureLoad(blue_noise, id.xy % textureDimensions(blue_noise), 0).xy;
    let t = normalize(select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9));
    let tangent = normalize(cross(n, t));
    let bitangent = cross(n, tangent);
    let angle = noise.x * 6.2831853;
    let spread = 0.12 * sqrt(noise.y);
    let out_n = normalize(n + (tangent * cos(angle) + bitangent * sin(angle)) * spread);
    textureStore(noised_normal, id.xy, vec4<f32>(out_n * 0.5 + 0.5, 1.0));
}

// Sky mask, coarse: the fraction of sky texels in each 4x4 block of the half-resolution
// linear depth (sky is at the far plane).
@fragment
fn fs_sky_coarse(in: FullscreenOut) -> @location(0) f32 {
    let base = vec2<i32>(in.clip.xy) * 4;
    let size = vec2<i32>(textureDimensions(depth_half)) - 1;
    var sky = 0.0;
    for (var y = 0; y < 4; y++) {
        for (var x = 0; x < 4; x++) {
            let z = textureLoad(depth_half, min(base + vec2<i32>(x, y), size), 0).r;
            sky += select(0.0, 1.0, z > 1500.0);
        }
    }
    return sky / 16.0;
}

// Sky mask, coarse mips: each built from the one above it, keeping the maximum so a block
// with any sky stays marked (the accurate pass uses it to skip pure-geometry tiles).
@fragment
fn fs_sky_mip(in: FullscreenOut) -> @location(0) f32 {
    let base = vec2<i32>(in.clip.xy) * 2;
    let size = vec2<i32>(textureDimensions(coarse_previous)) - 1;
    var m = 0.0;
    for (var k = 0; k < 4; k++) {
        m = max(m, textureLoad(coarse_previous, min(base + vec2<i32>(k & 1, k >> 1), size), 0).r);
    }
    return m;
}

// Sky mask, accurate: 1 where the full-resolution depth is the far plane, skipping blocks the
// coarse mips mark as having no sky.
@fragment
fn fs_sky_accurate(in: FullscreenOut) -> @location(0) f32 {
    let coarse_size = vec2<f32>(textureDimensions(sky_mask_coarse, 2));
    let cc = vec2<i32>(in.uv * coarse_size);
    if (textureLoad(sky_mask_coarse, cc, 2).r <= 0.0) {
        return 0.0;
    }
    let d = textureLoad(depth, vec2<i32>(in.clip.xy), 0);
    return select(0.0, 1.0, d >= 1.0);
}

// Coat mask: clear coat on painted car bodies (object mask 2 in the albedo alpha), strongest
// where the paint is smooth.
@fragment
fn fs_coat_mask(in: FullscreenOut) -> @location(0) f32 {
    let c = vec2<i32>(in.clip.xy);
    let object = round(textureLoad(gbuffer_albedo, c, 0).a * 3.0);
    let m = textureLoad(gbuffer_material, c, 0);
    return select(0.0, clamp(1.2 - m.y * 2.0, 0.0, 1.0), object == 2.0);
}

// Head mask: faces from the stencil (0x35), feathered over a 5x5 neighbourhood for the skin
// and eye passes.
@fragment
fn fs_head_mask(in: FullscreenOut) -> @location(0) f32 {
    let c = vec2<i32>(in.clip.xy);
    let size = vec2<i32>(textureDimensions(stencil)) - 1;
    var sum = 0.0;
    for (var y = -2; y <= 2; y++) {
        for (var x = -2; x <= 2; x++) {
            let s = textureLoad(stencil, clamp(c + vec2<i32>(x, y), vec2<i32>(0), size), 0).r;
            sum += select(0.0, 1.0, s == STENCIL_FACE);
        }
    }
    return sum / 25.0;
}
