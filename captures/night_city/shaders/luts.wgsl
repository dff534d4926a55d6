// Look-up tables and maps computed each frame: the 3D colour-grading LUT (filmic contrast,
// white balance, saturation and split toning applied to the identity cube) and the cloud
// distribution map the sky and cloud passes sample.

struct FrameConstants {
    time: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var grading_lut: texture_storage_3d<rgba16float, write>;
@group(0) @binding(2) var cloud_distribution: texture_storage_2d<rgba8unorm, write>;

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

@compute @workgroup_size(4, 4, 4)
fn cs_grading_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(grading_lut);
    if (any(id >= size)) {
        return;
    }
    var c = vec3<f32>(id) / vec3<f32>(size - 1u);
    // White balance towards a warm afternoon.
    c *= vec3<f32>(1.04, 1.0, 0.94);
    // S-curve contrast around mid grey.
    c = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    c = c * c * (3.0 - 2.0 * c) * 0.35 + c * 0.65;
    // Saturation lift.
    let y = luminance(c);
    c = mix(vec3<f32>(y), c, 1.15);
    // Split toning: teal shadows, amber highlights (the city's signature look).
    let shadows = vec3<f32>(0.0, 0.03, 0.05) * (1.0 - y);
    let highlights = vec3<f32>(0.05, 0.02, -0.02) * y;
    c = clamp(c + shadows + highlights, vec3<f32>(0.0), vec3<f32>(1.0));
    textureStore(grading_lut, id, vec4<f32>(c, 1.0));
}

fn hash21(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(123.34, 456.21));
    let r = q + dot(q, q + 45.32);
    return fract(r.x * r.y);
}

// Tileable value noise with a period of `period` cells.
fn noise_tiled(p: vec2<f32>, period: f32) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let a = hash21((i % period + period) % period);
    let b = hash21(((i + vec2<f32>(1.0, 0.0)) % period + period) % period);
    let c = hash21(((i + vec2<f32>(0.0, 1.0)) % period + period) % period);
    let d = hash21(((i + vec2<f32>(1.0, 1.0)) % period + period) % period);
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// Cloud distribution: R coverage, G density, B height of the cloud base, A type. Fractal noise
// drifting with the wind, tileable so the sky can repeat it.
@compute @workgroup_size(8, 8, 1)
fn cs_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(cloud_distribution);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let drift = vec2<f32>(frame.time.x * 0.002, frame.time.x * 0.0007);
    var n = 0.0;
    var a = 0.5;
    var period = 4.0;
    for (var o = 0; o < 6; o++) {
        n += a * noise_tiled((uv + drift) * period, period);
        period *= 2.0;
        a *= 0.5;
    }
    let coverage = smoothstep(0.45, 0.75, n);
    let density = smoothstep(0.55, 0.9, n);
    let base = noise_tiled(uv * 3.0, 3.0);
    let kind = noise_tiled(uv * 2.0 + 5.0, 2.0);
    textureStore(cloud_distribution, id.xy, vec4<f32>(coverage, density, base, kind));
}
