// Local volumetric fog (Wronski, "Volumetric fog", SIGGRAPH 2014): a froxel volume aligned
// with the camera frustum (exponential depth slices to 150 m). Each thread walks one froxel
// column front to back: height fog density, in-scattering of the sun through the shadow
// cascades and of the clustered local lights (Henyey-Greenstein phase), integrated with
// energy-conserving steps. Each froxel stores the scattered light reaching the eye from in
// front of its far face (rgb) and the transmittance up to it (a). Mip 1, a 2x2x2 average, is
// built by a second pass.

struct FrameConstants {
    view: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    csm_view_proj_0: mat4x4<f32>,
    csm_view_proj_1: mat4x4<f32>,
    csm_view_proj_2: mat4x4<f32>,
    csm_view_proj_3: mat4x4<f32>,
    csm_splits: vec4<f32>,
    camera_position: vec4<f32>,
    shadow_direction: vec4<f32>,
    sun_color: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    density: f32,
    height_falloff: f32,
    anisotropy: f32,
}

struct Light {
    position_radius: vec4<f32>,
    color_intensity: vec4<f32>,
    direction_cone: vec4<f32>,
    extra: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var fog_mip_0: texture_storage_3d<rgba16float, write>;
@group(0) @binding(3) var fog_mip_1: texture_storage_3d<rgba16float, write>;
@group(0) @binding(9) var fog_source: texture_3d<f32>;
@group(0) @binding(4) var csm: texture_depth_2d_array;
@group(0) @binding(5) var shadow_compare: sampler_comparison;
@group(0) @binding(6) var cluster_light_index: texture_3d<u32>;
@group(0) @binding(7) var<storage, read> light_list: array<u32>;
@group(0) @binding(8) var<storage, read> lights: array<Light>;

const FOG_NEAR: f32 = 0.5;
const FOG_FAR: f32 = 150.0;
// The cluster grid shared by the culling pass and its readers: 24 exponential depth slices
// between 0.5 and 400 m; each cluster owns 32 consecutive slots of light_list.
const CLUSTER_NEAR: f32 = 0.5;
const CLUSTER_FAR: f32 = 400.0;
const CLUSTER_SLICES: u32 = 24u;
const MAX_PER_CLUSTER: u32 = 32u;

fn cluster_slice(view_z: f32) -> u32 {
    let s = log(max(view_z, CLUSTER_NEAR) / CLUSTER_NEAR) / log(CLUSTER_FAR / CLUSTER_NEAR);
    return min(u32(s * f32(CLUSTER_SLICES)), CLUSTER_SLICES - 1u);
}

fn cluster_first_slot(tile: vec2<u32>, slice: u32, grid: vec3<u32>) -> u32 {
    return ((slice * grid.y + tile.y) * grid.x + tile.x) * MAX_PER_CLUSTER;
}
const PI: f32 = 3.14159265;

fn froxel_depth(s: f32, count: f32) -> f32 {
    return FOG_NEAR * pow(FOG_FAR / FOG_NEAR, s / count);
}

fn hg(cos_theta: f32, g: f32) -> f32 {
    return (1.0 - g * g) / (4.0 * PI * pow(1.0 + g * g - 2.0 * g * cos_theta, 1.5));
}

fn cascade_matrix(c: u32) -> mat4x4<f32> {
    switch c {
        case 0u: { return frame.csm_view_proj_0; }
        case 1u: { return frame.csm_view_proj_1; }
        case 2u: { return frame.csm_view_proj_2; }
        default: { return frame.csm_view_proj_3; }
    }
}

fn sun_visibility(world: vec3<f32>, view_z: f32) -> f32 {
    var c = 3u;
    for (var k = 0u; k < 4u; k++) {
        if (view_z <= frame.csm_splits[k]) {
            c = k;
            break;
        }
    }
    let clip = cascade_matrix(c) * vec4<f32>(world, 1.0);
    let uv = clip.xy * vec2<f32>(0.5, -0.5) + 0.5;
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0))) {
        return 1.0;
    }
    return textureSampleCompareLevel(csm, shadow_compare, uv, i32(c), clip.z - 0.001);
}

fn density_at(p: vec3<f32>) -> f32 {
    let height = exp(-max(p.y, 0.0) * params.height_falloff);
    let drift = p.xz * 0.05 + vec2<f32>(frame.time.x * 0.2, 0.0);
    let wisps = 0.6 + 0.4 * sin(drift.x * 1.3 + sin(drift.y * 0.7) * 2.0) * sin(drift.y * 1.1 + p.y * 0.2);
    return params.density * height * wisps;
}

@compute @workgroup_size(8, 8, 1)
fn cs_fog_integrate(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(fog_mip_0);
    if (any(id.xy >= size.xy)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size.xy);
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    let far = frame.inv_view_proj * ndc;
    let ray = normalize(far.xyz / far.w - frame.camera_position.xyz);
    let forward = -vec3<f32>(frame.view[0][2], frame.view[1][2], frame.view[2][2]);
    let along = dot(ray, forward);
    let l = normalize(frame.shadow_direction.xyz);
    let sun_phase = hg(dot(ray, l), params.anisotropy);
    let grid = textureDimensions(cluster_light_index);
    let pixel = uv * frame.resolution.xy;
    let tile = vec2<u32>(min(pixel / ceil(frame.resolution.xy / vec2<f32>(grid.xy)), vec2<f32>(grid.xy - 1u)));
    var scattered = vec3<f32>(0.0);
    var transmittance = 1.0;
    let count = f32(size.z);
    for (var z = 0u; z < size.z; z++) {
        let z0 = froxel_depth(f32(z), count);
        let z1 = froxel_depth(f32(z) + 1.0, count);
        let zc = 0.5 * (z0 + z1);
        let p = frame.camera_position.xyz + ray * (zc / along);
        let sigma = density_at(p);
        var inscatter = frame.sun_color.rgb * sun_visibility(p, zc) * sun_phase;
        // Clustered local lights at this depth.
        let slice = cluster_slice(zc);
        let entry = textureLoad(cluster_light_index, vec3<u32>(tile, slice), 0).r;
        let first = cluster_first_slot(tile, slice, grid);
        let n = min(entry, MAX_PER_CLUSTER);
        for (var k = 0u; k < n; k++) {
            let light = lights[light_list[first + k]];
            let d = light.position_radius.xyz - p;
            let dist2 = dot(d, d);
            let r = light.position_radius.w;
            let window = clamp(1.0 - pow(dist2 / (r * r), 2.0), 0.0, 1.0);
            let atten = window * window / (dist2 + 1.0);
            let phase = hg(dot(ray, normalize(d)), params.anisotropy);
            inscatter += light.color_intensity.rgb * light.color_intensity.w * atten * phase;
        }
        // Energy-conserving integration over the slice (Hillaire 2015).
        let thickness = (z1 - z0) / along;
        let extinction = max(sigma, 1e-6);
        let slice_t = exp(-extinction * thickness);
        scattered += transmittance * (inscatter * sigma) * (1.0 - slice_t) / extinction;
        transmittance *= slice_t;
        textureStore(fog_mip_0, vec3<u32>(id.xy, z), vec4<f32>(scattered, transmittance));
    }
}

@compute @workgroup_size(4, 4, 4)
fn cs_fog_downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(fog_mip_1);
    if (any(id >= size)) {
        return;
    }
    let src = textureDimensions(fog_source);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let p = min(id * 2u + vec3<u32>(k & 1u, (k >> 1u) & 1u, k >> 2u), src - 1u);
        sum += textureLoad(fog_source, p, 0);
    }
    textureStore(fog_mip_1, id, sum / 8.0);
}
