// Horizon-based ambient occlusion (Bavoil, Sainz and Dimitrov, "Image-space horizon-based
// ambient occlusion") at half resolution: for each pixel, march in four screen directions
// rotated per pixel by blue noise, find the highest horizon angle above the tangent plane
// within a world-space radius, and integrate the occlusion with distance falloff.

struct FrameConstants {
    proj: mat4x4<f32>,
    view: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var depth_half: texture_2d<f32>;
@group(0) @binding(2) var noised_normal: texture_2d<f32>;
@group(0) @binding(3) var blue_noise: texture_2d<f32>;
@group(0) @binding(4) var ao: texture_storage_2d<r8unorm, write>;

const RADIUS: f32 = 1.5;
const DIRECTIONS: i32 = 4;
const STEPS: i32 = 6;

// View-space position of a half-resolution texel from its linear depth.
fn view_position(p: vec2<f32>, size: vec2<f32>) -> vec3<f32> {
    let z = textureLoad(depth_half, vec2<i32>(clamp(p, vec2<f32>(0.0), size - 1.0)), 0).r;
    let ndc = (p + 0.5) / size * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    return vec3<f32>(ndc.x * z / frame.proj[0][0], ndc.y * z / frame.proj[1][1], -z);
}

@compute @workgroup_size(8, 8, 1)
fn cs_hbao(@builtin(global_invocation_id) id: vec3<u32>) {
    let size_u = textureDimensions(ao);
    if (any(id.xy >= size_u)) {
        return;
    }
    let size = vec2<f32>(size_u);
    let pixel = vec2<f32>(id.xy);
    let p = view_position(pixel, size);
    if (-p.z > 1500.0) {
        textureStore(ao, id.xy, vec4<f32>(1.0));
        return;
    }
    // World normal to view space.
    let nsize = vec2<f32>(textureDimensions(noised_normal));
    let nw = textureLoad(noised_normal, vec2<i32>((pixel + 0.5) / size * nsize), 0).xyz * 2.0 - 1.0;
    let n = normalize((frame.view * vec4<f32>(nw, 0.0)).xyz);
    let noise = textureLoad(blue_noise, id.xy % textureDimensions(blue_noise), 0).xy;
    // Radius in pixels at this depth.
    let radius_px = clamp(RADIUS * frame.proj[1][1] * size.y * 0.5 / -p.z, 2.0, 64.0);
    var occlusion = 0.0;
    for (var d = 0; d < DIRECTIONS; d++) {
        let angle = (f32(d) + noise.x) * 6.2831853 / f32(DIRECTIONS);
        let dir = vec2<f32>(cos(angle), sin(angle));
        // Tangent angle from the normal: the horizon starts at the surface's tangent plane.
        let tangent_dir = vec3<f32>(dir.x, -dir.y, 0.0);
        let t = tangent_dir - n * dot(tangent_dir, n);
        let tangent_angle = atan2(t.z, length(t.xy) + 1e-4);
        var horizon = tangent_angle;
        var ao_dir = 0.0;
        var last_sin = sin(tangent_angle);
        for (var s = 1; s <= STEPS; s++) {
            let offset = dir * radius_px * (f32(s) - 0.5 + noise.y) / f32(STEPS);
            let q = view_position(pixel + offset, size);
            let v = q - p;
            let dist = length(v);
            if (dist > RADIUS * 2.0 || dist < 1e-3) {
                continue;
            }
            let elevation = atan2(v.z, length(v.xy));
            if (elevation > horizon) {
                horizon = elevation;
                let s_h = sin(horizon);
                let falloff = 1.0 - (dist * dist) / (4.0 * RADIUS * RADIUS);
                ao_dir += (s_h - last_sin) * falloff;
                last_sin = s_h;
            }
        }
        occlusion += ao_dir;
    }
    let visibility = clamp(1.0 - occlusion / f32(DIRECTIONS) * 1.6, 0.0, 1.0);
    textureStore(ao, id.xy, vec4<f32>(visibility));
}
