// Tone mapping in compute: scene + bloom (all three mips), ACES fitted curve, written as
// display-referred 8-bit colour with sRGB encoding done in the shader.

struct FrameConstants {
    view_proj: mat4x4<f32>,
    prev_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    resolution: vec4<f32>,
    jitter: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    exposure: f32,
    bloom_strength: f32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var scene: texture_2d<f32>;
@group(0) @binding(3) var bloom: texture_2d<f32>;
@group(0) @binding(4) var linear_clamp: sampler;
@group(0) @binding(5) var ldr: texture_storage_2d<rgba8unorm, write>;

fn aces(x: vec3<f32>) -> vec3<f32> {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(ldr);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let hdr = textureLoad(scene, vec2<i32>(id.xy), 0).rgb;
    var glow = vec3<f32>(0.0);
    for (var m = 0; m < 3; m++) {
        glow += textureSampleLevel(bloom, linear_clamp, uv, f32(m)).rgb;
    }
    let color = aces((hdr + glow * params.bloom_strength) * params.exposure);
    textureStore(ldr, vec2<i32>(id.xy), vec4<f32>(srgb_encode(color), 1.0));
}
