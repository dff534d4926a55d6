// Tiled direct lighting in compute over 16x16-pixel tiles (dispatched indirectly: the tile
// counts are written by instance_prep from the render resolution). Physically based, after
// Filament and Karis: GGX normal distribution, height-correlated Smith visibility, Schlick
// Fresnel, Burley's normalised diffuse, an optional clear-coat lobe. The sun uses the
// resolved shadow mask; local lights come from the pixel's cluster, with windowed inverse-
// square falloff, and the first ten are shadowed by their variance shadow maps. Ambient light
// comes from the prefiltered sky cube, occluded by HBAO and by the top-view sky visibility.
// Emissive surfaces add their radiance to the diffuse result.

struct FrameConstants {
    view: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    top_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    moon_direction: vec4<f32>,
    moon_color: vec4<f32>,
    resolution: vec4<f32>,
}

struct Params {
    shadowed_lights: u32,
    emissive_scale: f32,
    ambient_scale: f32,
}

struct Light {
    position_radius: vec4<f32>,
    color_intensity: vec4<f32>,
    direction_cone: vec4<f32>,
    extra: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(5) var depth_r32: texture_2d<f32>;
@group(0) @binding(6) var sun_shadow: texture_2d<f32>;
@group(0) @binding(7) var ao: texture_2d<f32>;
@group(0) @binding(8) var cluster_light_index: texture_3d<u32>;
@group(0) @binding(9) var<storage, read> light_list: array<u32>;
@group(0) @binding(10) var<storage, read> lights: array<Light>;
@group(0) @binding(11) var omni_vsm: texture_2d_array<f32>;
@group(0) @binding(12) var sky_cube: texture_cube<f32>;
@group(0) @binding(13) var top_view_depth: texture_depth_2d;
@group(0) @binding(14) var coat_mask: texture_2d<f32>;
@group(0) @binding(15) var local_light_mask: texture_2d<f32>;
@group(0) @binding(16) var linear_clamp: sampler;
@group(0) @binding(17) var lit_diffuse: texture_storage_2d<rgba16float, write>;
@group(0) @binding(18) var lit_specular: texture_storage_2d<rgba16float, write>;

const PI: f32 = 3.14159265;
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

fn d_ggx(noh: f32, a: f32) -> f32 {
    let a2 = a * a;
    let f = (noh * a2 - noh) * noh + 1.0;
    return a2 / (PI * f * f);
}

fn v_smith_ggx_correlated(nov: f32, nol: f32, a: f32) -> f32 {
    let a2 = a * a;
    let ggxl = nov * sqrt((-nol * a2 + nol) * nol + a2);
    let ggxv = nol * sqrt((-nov * a2 + nov) * nov + a2);
    return 0.5 / max(ggxv + ggxl, 1e-5);
}

fn f_schlick(f0: vec3<f32>, voh: f32) -> vec3<f32> {
    let f = pow(1.0 - voh, 5.0);
    return f + f0 * (1.0 - f);
}

fn f_schlick_scalar(f0: f32, f90: f32, voh: f32) -> f32 {
    return f0 + (f90 - f0) * pow(1.0 - voh, 5.0);
}

// Burley's diffuse, normalised (Disney principled BRDF).
fn fd_burley(nov: f32, nol: f32, loh: f32, roughness: f32) -> f32 {
    let f90 = 0.5 + 2.0 * roughness * loh * loh;
    return f_schlick_scalar(1.0, f90, nol) * f_schlick_scalar(1.0, f90, nov) / PI;
}

struct Surface {
    albedo: vec3<f32>,
    n: vec3<f32>,
    v: vec3<f32>,
    f0: vec3<f32>,
    roughness: f32,
    coat: f32,
}

struct Lit {
    diffuse: vec3<f32>,
    specular: vec3<f32>,
}

// One punctual light of illuminance `e` (colour times intensity times attenuation) from `l`.
fn shade(s: Surface, l: vec3<f32>, e: vec3<f32>) -> Lit {
    var out: Lit;
    let nol = dot(s.n, l);
    if (nol <= 0.0) {
        return out;
    }
    let h = normalize(s.v + l);
    let nov = max(dot(s.n, s.v), 1e-4);
    let noh = clamp(dot(s.n, h), 0.0, 1.0);
    let loh = clamp(dot(l, h), 0.0, 1.0);
    let a = max(s.roughness * s.roughness, 0.002);
    let f = f_schlick(s.f0, loh);
    var spec = d_ggx(noh, a) * v_smith_ggx_correlated(nov, nol, a) * f;
    var diff = s.albedo * fd_burley(nov, nol, loh, s.roughness);
    if (s.coat > 0.0) {
        // Clear coat: a fixed smooth dielectric lobe (IOR 1.5) over the base, which loses the
        // energy the coat reflects.
        let ac = 0.05 * 0.05;
        let fc = f_schlick_scalar(0.04, 1.0, loh) * s.coat;
        let coat = d_ggx(noh, ac) * v_smith_ggx_correlated(nov, nol, ac) * fc;
        diff *= 1.0 - fc;
        spec = spec * (1.0 - fc) + vec3<f32>(coat);
    }
    out.diffuse = diff * e * nol;
    out.specular = spec * e * nol;
    return out;
}

fn light_shadow(index: u32, world: vec3<f32>, r: f32) -> f32 {
    if (index >= params.shadowed_lights) {
        return 1.0;
    }
    let l = lights[index].position_radius;
    let v = world - l.xyz;
    let dist = length(v);
    let dir = v / max(dist, 1e-4);
    if (dir.y > 0.0) {
        return 1.0;
    }
    let p = dir.xz / (1.0 - dir.y);
    let uv = p * vec2<f32>(0.5, -0.5) + 0.5;
    let m = textureSampleLevel(omni_vsm, linear_clamp, uv, i32(index), 0.0).xy;
    let d = dist / (l.w * 2.0) - 0.01;
    if (d <= m.x) {
        return 1.0;
    }
    // Chebyshev's upper bound, with light-bleeding reduction.
    let variance = max(m.y - m.x * m.x, 1e-5);
    let t = d - m.x;
    let p_max = variance / (variance + t * t);
    return clamp((p_max - 0.2) / 0.8, 0.0, 1.0);
}

// Karis' analytic approximation of the split-sum environment BRDF.
fn env_brdf(f0: vec3<f32>, roughness: f32, nov: f32) -> vec3<f32> {
    let c0 = vec4<f32>(-1.0, -0.0275, -0.572, 0.022);
    let c1 = vec4<f32>(1.0, 0.0425, 1.04, -0.04);
    let r = roughness * c0 + c1;
    let a004 = min(r.x * r.x, exp2(-9.28 * nov)) * r.x + r.y;
    let ab = vec2<f32>(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

@compute @workgroup_size(16, 16, 1)
fn cs_tiled_lighting(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(lit_diffuse);
    if (any(id.xy >= size)) {
        return;
    }
    let c = vec2<i32>(id.xy);
    let d = textureLoad(depth_r32, c, 0).r;
    if (d >= 1.0) {
        // Sky: drawn by the sky pass.
        textureStore(lit_diffuse, c, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        textureStore(lit_specular, c, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let w = frame.inv_view_proj * ndc;
    let world = w.xyz / w.w;
    let base = textureLoad(gbuffer_albedo, c, 0);
    let mat = textureLoad(gbuffer_material, c, 0);
    var s: Surface;
    s.n = normalize(textureLoad(gbuffer_normal, c, 0).xyz * 2.0 - 1.0);
    s.v = normalize(frame.camera_position.xyz - world);
    let metal = mat.x;
    s.roughness = clamp(mat.y, 0.045, 1.0);
    s.albedo = base.rgb * (1.0 - metal);
    s.f0 = mix(vec3<f32>(0.04), base.rgb, metal);
    s.coat = textureLoad(coat_mask, c, 0).r;
    var diffuse = vec3<f32>(0.0);
    var specular = vec3<f32>(0.0);

    // Sun, or the moon at night.
    let sun = normalize(frame.sun_direction.xyz);
    let sun_up = sun.y > 0.0;
    let l = select(normalize(frame.moon_direction.xyz), sun, sun_up);
    let e = select(frame.moon_color.rgb, frame.sun_color.rgb, sun_up);
    let shadow = textureLoad(sun_shadow, c, 0).r;
    let direct = shade(s, l, e * shadow);
    diffuse += direct.diffuse;
    specular += direct.specular;

    // Clustered local lights, skipped where the coarse light mask says the tile has none.
    let mask_size = vec2<f32>(textureDimensions(local_light_mask, 1));
    let any_light = textureLoad(local_light_mask, vec2<i32>(uv * mask_size), 1).r > 0.0;
    if (any_light) {
        let grid = textureDimensions(cluster_light_index);
        let tile_px = ceil(frame.resolution.xy / vec2<f32>(grid.xy));
        let tile = vec2<u32>(min(vec2<f32>(id.xy) / tile_px, vec2<f32>(grid.xy - 1u)));
        let view_z = -(frame.view * vec4<f32>(world, 1.0)).z;
        let slice = cluster_slice(view_z);
        let entry = textureLoad(cluster_light_index, vec3<u32>(tile, slice), 0).r;
        let first = cluster_first_slot(tile, slice, grid);
        let n = min(entry, MAX_PER_CLUSTER);
        for (var k = 0u; k < n; k++) {
            let index = light_list[first + k];
            let light = lights[index];
            let to_light = light.position_radius.xyz - world;
            let dist2 = dot(to_light, to_light);
            let r = light.position_radius.w;
            let window = clamp(1.0 - pow(dist2 / (r * r), 2.0), 0.0, 1.0);
            let atten = window * window / (dist2 + 1.0);
            if (atten <= 0.0) {
                continue;
            }
            let vis = light_shadow(index, world, r);
            let lit = shade(s, to_light / sqrt(dist2), light.color_intensity.rgb * light.color_intensity.w * atten * vis);
            diffuse += lit.diffuse;
            specular += lit.specular;
        }
    }

    // Ambient: irradiance from the most blurred sky mip, reflections from the mip matching the
    // roughness, both occluded by AO; the top view tells whether anything is overhead.
    let ao_v = textureSampleLevel(ao, linear_clamp, uv, 0.0).r;
    let top = frame.top_view_proj * vec4<f32>(world, 1.0);
    let top_uv = top.xy * vec2<f32>(0.5, -0.5) + 0.5;
    let top_size = vec2<f32>(textureDimensions(top_view_depth));
    let top_d = textureLoad(top_view_depth, vec2<i32>(clamp(top_uv, vec2<f32>(0.0), vec2<f32>(1.0)) * (top_size - 1.0)), 0);
    let covered = top.z - top_d > 0.002;
    let sky_vis = select(1.0, 0.35, covered);
    let mips = f32(textureNumLevels(sky_cube) - 1u);
    let irradiance = textureSampleLevel(sky_cube, linear_clamp, s.n, mips).rgb;
    let r = reflect(-s.v, s.n);
    let prefiltered = textureSampleLevel(sky_cube, linear_clamp, r, s.roughness * mips).rgb;
    let nov = max(dot(s.n, s.v), 1e-4);
    diffuse += s.albedo * irradiance * ao_v * sky_vis * params.ambient_scale;
    specular += prefiltered * env_brdf(s.f0, s.roughness, nov) * ao_v * sky_vis * params.ambient_scale;

    // Emissive (windows, signs): alpha of the material target.
    diffuse += base.rgb * mat.w * params.emissive_scale;
    textureStore(lit_diffuse, c, vec4<f32>(diffuse, 1.0));
    textureStore(lit_specular, c, vec4<f32>(specular, 1.0));
}
