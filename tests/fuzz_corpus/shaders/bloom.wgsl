// Bloom bright-pass: a 13-tap downsample of the HDR scene into the half-resolution bloom
// target, keeping only energy above a soft threshold.

struct Params {
    threshold: f32,
    knee: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var scene: texture_2d<f32>;
@group(0) @binding(2) var linear_clamp: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> VertexOut {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: VertexOut;
    out.clip = vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
    out.uv = uv;
    return out;
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

@fragment
fn fs_bright(in: VertexOut) -> @location(0) vec4<f32> {
    let texel = 1.0 / vec2<f32>(textureDimensions(scene));
    var c = textureSample(scene, linear_clamp, in.uv).rgb * 0.125;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(-1.0, -1.0)).rgb * 0.125;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(1.0, -1.0)).rgb * 0.125;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(-1.0, 1.0)).rgb * 0.125;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(1.0, 1.0)).rgb * 0.125;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(-2.0, 0.0)).rgb * 0.0625;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(2.0, 0.0)).rgb * 0.0625;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(0.0, -2.0)).rgb * 0.0625;
    c += textureSample(scene, linear_clamp, in.uv + texel * vec2<f32>(0.0, 2.0)).rgb * 0.0625;
    let l = luminance(c);
    let soft = clamp(l - params.threshold + params.knee, 0.0, 2.0 * params.knee);
    let weight = max(soft * soft / (4.0 * params.knee + 1e-4), l - params.threshold) / max(l, 1e-4);
    return vec4<f32>(c * weight, 1.0);
}
