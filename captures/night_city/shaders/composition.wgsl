// From lit surfaces to the composed HDR image: local indirect light from the environment
// probes picked by the GI probe indices, the composition of direct, indirect and reflected
// light into two targets (total on RT0, specular alone on RT1 so the skin pass can blur the
// diffuse part only), the LUT of holographic and transparent materials, screen-space skin
// irradiance and eyes, GI/AO shadowing, the volumetric fog applied by depth, and the water's
// reflection at half resolution.

struct FrameConstants {
    proj: mat4x4<f32>,
    view: mat4x4<f32>,
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    camera_position: vec4<f32>,
    sun_direction: vec4<f32>,
    sun_color: vec4<f32>,
    moon_direction: vec4<f32>,
    moon_color: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    // Street probe position (xyz) and the radius it is trusted within (w).
    street_probe: vec4<f32>,
    // Multiplier of the indirect bounce (night scenes lean on it more).
    indirect_scale: f32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(5) var depth_r32: texture_2d<f32>;
@group(0) @binding(6) var env_dual_paraboloid: texture_2d_array<f32>;
@group(0) @binding(7) var sky_cube: texture_cube<f32>;
@group(0) @binding(8) var gi_probe_indices: texture_3d<u32>;
@group(0) @binding(9) var ao: texture_2d<f32>;
@group(0) @binding(10) var linear_clamp: sampler;
@group(0) @binding(11) var indirect_out: texture_storage_2d<rg11b10ufloat, write>;
@group(0) @binding(12) var lit_diffuse: texture_2d<f32>;
@group(0) @binding(13) var lit_specular: texture_2d<f32>;
@group(0) @binding(14) var indirect: texture_2d<f32>;
@group(0) @binding(15) var ssr: texture_2d<f32>;
@group(0) @binding(16) var ssr_reflectivity: texture_2d<f32>;
@group(0) @binding(17) var transparent_lut_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(18) var composite: texture_2d<f32>;
@group(0) @binding(19) var composite_specular: texture_2d<f32>;
@group(0) @binding(20) var stencil: texture_2d<u32>;
@group(0) @binding(21) var skin_irradiance: texture_2d<f32>;
@group(0) @binding(22) var fog_volume: texture_3d<f32>;
@group(0) @binding(23) var ocean_height: texture_2d<f32>;
@group(0) @binding(24) var linear_wrap: sampler;
@group(0) @binding(25) var head_mask: texture_2d<f32>;
@group(0) @binding(26) var stencil_half: texture_2d<u32>;

const PI: f32 = 3.14159265;
const VOXEL_MIN: vec3<f32> = vec3<f32>(-160.0, -32.0, -200.0);
const VOXEL_SIZE: vec3<f32> = vec3<f32>(320.0, 160.0, 400.0);
const PROBES_PER_AXIS: u32 = 16u;
const WATER_LEVEL: f32 = -1.5;
const WATER_OFFSET: vec2<f32> = vec2<f32>(0.0, 380.0);
const TERRAIN_MAP_EXTENT: f32 = 600.0;
// The froxel volume's depth range (fog.wgsl).
const FOG_NEAR: f32 = 0.5;
const FOG_FAR: f32 = 150.0;
// Stencil values of the base pass: character body and face.
const STENCIL_BODY: u32 = 0x15u;
const STENCIL_FACE: u32 = 0x35u;

fn world_position(uv: vec2<f32>, d: f32) -> vec3<f32> {
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

fn linear_depth(d: f32) -> f32 {
    let a = frame.proj[2][2];
    let b = frame.proj[3][2];
    return b / (d + a);
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Texel of the dual-paraboloid layout (env.wgsl's paraboloid_direction inverted): the +z
// hemisphere on the left half, the -z one on the right.
fn paraboloid_uv(d: vec3<f32>) -> vec2<f32> {
    if (d.z >= 0.0) {
        let l = vec2<f32>(d.x, -d.y) / (1.0 + d.z);
        return vec2<f32>((l.x * 0.5 + 0.5) * 0.5, l.y * 0.5 + 0.5);
    }
    let l = vec2<f32>(-d.x, -d.y) / (1.0 - d.z);
    return vec2<f32>((l.x * 0.5 + 0.5) * 0.5 + 0.5, l.y * 0.5 + 0.5);
}

fn probe_radiance(layer: u32, dir: vec3<f32>, mip: f32) -> vec3<f32> {
    return textureSampleLevel(env_dual_paraboloid, linear_clamp, paraboloid_uv(dir), layer, mip).rgb;
}

// Schlick-style split-sum approximation of the environment BRDF (Karis, mobile).
fn env_brdf(f0: vec3<f32>, roughness: f32, nov: f32) -> vec3<f32> {
    let c0 = vec4<f32>(-1.0, -0.0275, -0.572, 0.022);
    let c1 = vec4<f32>(1.0, 0.0425, 1.04, -0.04);
    let r = roughness * c0 + c1;
    let a004 = min(r.x * r.x, exp2(-9.28 * nov)) * r.x + r.y;
    let ab = vec2<f32>(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

// Local indirect light: what the probe sees beyond the sky (lit windows, neon, the street),
// as diffuse bounce and glossy reflection. The sky's own share is already in the direct
// lighting's ambient term, so it is subtracted here rather than counted twice.
@compute @workgroup_size(8, 8, 1)
fn cs_indirect(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(indirect_out);
    if (any(id.xy >= size)) {
        return;
    }
    let c = vec2<i32>(id.xy);
    let d = textureLoad(depth_r32, c, 0).r;
    if (d >= 1.0) {
        textureStore(indirect_out, c, vec4<f32>(0.0));
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    let p = world_position(uv, d);
    let n = normalize(textureLoad(gbuffer_normal, c, 0).xyz * 2.0 - 1.0);
    let base = textureLoad(gbuffer_albedo, c, 0).rgb;
    let mat = textureLoad(gbuffer_material, c, 0);
    let metal = mat.x;
    let roughness = clamp(mat.y, 0.045, 1.0);
    let v = normalize(frame.camera_position.xyz - p);
    // The GI cell of this point, its chosen probe and how many of its 8 neighbours are open.
    let cell = vec3<u32>(clamp((p - VOXEL_MIN) / VOXEL_SIZE, vec3<f32>(0.0), vec3<f32>(0.9999)) * 64.0);
    let probe = textureLoad(gi_probe_indices, cell, 0).rg;
    let open = f32(countOneBits(probe.g)) / 8.0;
    let probe_count = PROBES_PER_AXIS * PROBES_PER_AXIS * PROBES_PER_AXIS;
    var layer = 1u + probe.r % (textureNumLayers(env_dual_paraboloid) - 1u);
    let near_street = distance(p, params.street_probe.xyz) < params.street_probe.w;
    if (near_street) {
        layer = 0u;
    }
    if (probe.r >= probe_count) {
        textureStore(indirect_out, c, vec4<f32>(0.0));
        return;
    }
    let mips = f32(textureNumLevels(env_dual_paraboloid) - 1u);
    let sky_mips = f32(textureNumLevels(sky_cube) - 1u);
    let diffuse_in = max(probe_radiance(layer, n, mips) - textureSampleLevel(sky_cube, linear_clamp, n, sky_mips).rgb, vec3<f32>(0.0));
    let r = reflect(-v, n);
    let spec_in = max(probe_radiance(layer, r, roughness * mips) - textureSampleLevel(sky_cube, linear_clamp, r, roughness * sky_mips).rgb, vec3<f32>(0.0));
    let f0 = mix(vec3<f32>(0.04), base, metal);
    let occlusion = textureSampleLevel(ao, linear_clamp, uv, 0.0).r * open;
    let result = (base * (1.0 - metal) * diffuse_in + spec_in * env_brdf(f0, roughness, max(dot(n, v), 1e-4)))
        * occlusion * params.indirect_scale;
    textureStore(indirect_out, c, vec4<f32>(result, 1.0));
}

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

struct Composed {
    @location(0) total: vec4<f32>,
    @location(1) specular: vec4<f32>,
}

// RT0: everything; RT1: the specular part. SSR replaces the probe's reflection where it is
// confident and adds to the direct highlights.
@fragment
fn fs_compose(in: FullscreenOut) -> Composed {
    let c = vec2<i32>(in.clip.xy);
    let refl = textureLoad(ssr_reflectivity, c, 0).r;
    let specular = textureLoad(lit_specular, c, 0).rgb + textureLoad(ssr, c, 0).rgb * refl;
    let diffuse = textureLoad(lit_diffuse, c, 0).rgb + textureLoad(indirect, c, 0).rgb * (1.0 - refl);
    var out: Composed;
    out.total = vec4<f32>(diffuse + specular, 1.0);
    out.specular = vec4<f32>(specular, 1.0);
    return out;
}

fn hue(h: f32) -> vec3<f32> {
    let k = vec3<f32>(0.0, 2.0 / 3.0, 1.0 / 3.0);
    return clamp(abs(fract(h + k) * 6.0 - 3.0) - 1.0, vec3<f32>(0.0), vec3<f32>(1.0));
}

// Transparent LUT: one row per neon material (64 hues across magenta, cyan, amber, green),
// across the row the emission by edge factor (fresnel-like, 0 face-on to 1 grazing): a dim
// core that brightens and shifts towards white at the rim; alpha is the coverage.
@compute @workgroup_size(16, 4, 1)
fn cs_transparent_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(transparent_lut_out);
    if (any(id.xy >= size)) {
        return;
    }
    let edge = (f32(id.x) + 0.5) / f32(size.x);
    let row = (f32(id.y) + 0.5) / f32(size.y);
    let palette = array<f32, 4>(0.88, 0.52, 0.09, 0.36);
    let base_hue = palette[id.y % 4u] + (row - 0.5) * 0.06;
    let tint = hue(base_hue);
    let rim = pow(edge, 3.0);
    let emission = mix(tint * 0.6, mix(tint, vec3<f32>(1.0), 0.35) * 3.0, rim);
    let coverage = 0.15 + 0.75 * rim;
    textureStore(transparent_lut_out, id.xy, vec4<f32>(emission, coverage));
}

fn is_skin(s: u32) -> bool {
    return s == STENCIL_BODY || s == STENCIL_FACE;
}

// Screen-space subsurface scattering (after Jimenez et al.): the diffuse light of skin pixels
// (total minus specular) spread by a sum-of-Gaussians profile whose red lobe reaches farthest,
// sized in world units (a few millimetres) by the pixel's depth, and only across skin of
// similar depth. Specular light stays sharp on top. Eyes (inside the head mask, where the
// normal looks back at the camera) are not scattering tissue: they keep their sharp diffuse
// and get a wet cornea reflection of the sky.
@fragment
fn fs_skin(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = vec2<i32>(in.clip.xy);
    let s = textureLoad(stencil, c, 0).r;
    if (!is_skin(s)) {
        return vec4<f32>(0.0);
    }
    let size = vec2<i32>(textureDimensions(composite)) - 1;
    let d = textureLoad(depth_r32, c, 0).r;
    let z = linear_depth(d);
    let spec = textureLoad(composite_specular, c, 0).rgb;
    let centre = textureLoad(composite, c, 0).rgb - spec;
    // 8 mm of scattering in pixels at this depth.
    let pixels_per_metre = frame.proj[1][1] * frame.resolution.y * 0.5 / z;
    let radius = clamp(0.008 * pixels_per_metre, 1.0, 24.0);
    // Per-channel Gaussian widths relative to the radius (red scatters furthest).
    let widths = vec3<f32>(1.0, 0.45, 0.25);
    var sum = centre;
    var weight = vec3<f32>(1.0);
    for (var k = 0; k < 16; k++) {
        let a = f32(k) * 2.39996;
        let rr = sqrt((f32(k) + 0.5) / 16.0);
        let o = vec2<f32>(cos(a), sin(a)) * rr * radius;
        let q = clamp(c + vec2<i32>(round(o)), vec2<i32>(0), size);
        if (!is_skin(textureLoad(stencil, q, 0).r)) {
            continue;
        }
        let dz = abs(linear_depth(textureLoad(depth_r32, q, 0).r) - z);
        let depth_w = exp(-dz * 300.0);
        let w = exp(-(rr * rr) / (2.0 * widths * widths)) * depth_w;
        sum += (textureLoad(composite, q, 0).rgb - textureLoad(composite_specular, q, 0).rgb) * w;
        weight += w;
    }
    var diffuse = sum / weight;
    if (s == STENCIL_FACE) {
        let p = world_position(in.uv, d);
        let n = normalize(textureLoad(gbuffer_normal, c, 0).xyz * 2.0 - 1.0);
        let v = normalize(frame.camera_position.xyz - p);
        // Eyes sit where the head mask is solid (inside the face, not at its feathered rim)
        // and the surface looks back at the camera.
        let inside = smoothstep(0.8, 1.0, textureLoad(head_mask, c, 0).r);
        let eye = smoothstep(0.88, 0.95, dot(n, v)) * inside;
        let r = reflect(-v, n);
        let cornea = textureSampleLevel(sky_cube, linear_clamp, r, 0.0).rgb * 0.04;
        diffuse = mix(diffuse, centre, eye) + cornea * eye;
    }
    return vec4<f32>(diffuse + spec, 1.0);
}

// Multi-bounce ambient occlusion (Jimenez et al. 2016): occlusion as seen after light has
// bounced on surfaces of this albedo, so bright surfaces darken less in their creases.
fn multi_bounce(x: f32, albedo: vec3<f32>) -> vec3<f32> {
    let a = 2.0404 * albedo - 0.3324;
    let b = -4.7951 * albedo + 0.6417;
    let c = 2.7552 * albedo + 0.6903;
    return max(vec3<f32>(x), ((x * a + b) * x + c) * x);
}

// GI/AO shadowing, blended premultiplied over the composite (src + dst * (1 - src.a)): skin
// pixels are replaced by their scattered irradiance, everything else is darkened in its
// creases by multi-bounce AO (half strength: the ambient term was occluded already).
@fragment
fn fs_gi_shadow(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = vec2<i32>(in.clip.xy);
    let occlusion = textureSampleLevel(ao, linear_clamp, in.uv, 0.0).r;
    let albedo = textureLoad(gbuffer_albedo, c, 0).rgb;
    let factor = luminance(mix(vec3<f32>(1.0), multi_bounce(occlusion, albedo), 0.5));
    if (is_skin(textureLoad(stencil, c, 0).r)) {
        return vec4<f32>(textureLoad(skin_irradiance, c, 0).rgb * factor, 1.0);
    }
    return vec4<f32>(0.0, 0.0, 0.0, 1.0 - factor);
}

// The froxel volume applied by depth, premultiplied: in-scattered light plus the scene times
// the transmittance at that depth. Sky pixels take the whole volume.
@fragment
fn fs_fog_apply(in: FullscreenOut) -> @location(0) vec4<f32> {
    let d = textureLoad(depth_r32, vec2<i32>(in.clip.xy), 0).r;
    let z = select(linear_depth(d), FOG_FAR, d >= 1.0);
    let slices = f32(textureDimensions(fog_volume).z);
    let s = log(max(z, FOG_NEAR) / FOG_NEAR) / log(FOG_FAR / FOG_NEAR);
    // Froxel k holds the integral up to its far edge: sample between slice centres.
    let w = clamp(s - 0.5 / slices, 0.5 / slices, 1.0 - 0.5 / slices);
    let fog = textureSampleLevel(fog_volume, linear_clamp, vec3<f32>(in.uv, w), 0.0);
    return vec4<f32>(fog.rgb, 1.0 - fog.a);
}

// Water reflection at half resolution: water pixels trace the ray mirrored by the wave
// normal (from the ocean height map) through the full-resolution depth and take the composed
// image where it hits, the sky cube where it leaves the screen.
@fragment
fn fs_water_reflection(in: FullscreenOut) -> @location(0) vec4<f32> {
    let full = vec2<f32>(textureDimensions(depth_r32));
    let c = vec2<i32>(in.uv * full);
    let d = textureLoad(depth_r32, c, 0).r;
    if (d >= 1.0) {
        return vec4<f32>(0.0);
    }
    // Characters and foliage standing in the shallows are not water (half-resolution stencil).
    let s = textureLoad(stencil_half, vec2<i32>(in.clip.xy), 0).r;
    if (s != 0u) {
        return vec4<f32>(0.0);
    }
    let p = world_position(in.uv, d);
    let n_g = normalize(textureLoad(gbuffer_normal, c, 0).xyz * 2.0 - 1.0);
    if (abs(p.y - WATER_LEVEL) > 1.0 || n_g.y < 0.8) {
        return vec4<f32>(0.0);
    }
    let h_uv = (p.xz - WATER_OFFSET) / TERRAIN_MAP_EXTENT + 0.5;
    let texel = 1.0 / vec2<f32>(textureDimensions(ocean_height));
    let h = textureSampleLevel(ocean_height, linear_wrap, h_uv, 0.0).r;
    let hx = textureSampleLevel(ocean_height, linear_wrap, h_uv + vec2<f32>(texel.x, 0.0), 0.0).r - h;
    let hz = textureSampleLevel(ocean_height, linear_wrap, h_uv + vec2<f32>(0.0, texel.y), 0.0).r - h;
    let n = normalize(vec3<f32>(-hx * 6.0, TERRAIN_MAP_EXTENT * texel.x, -hz * 6.0));
    let v = normalize(p - frame.camera_position.xyz);
    let r = reflect(v, n);
    let forward = -vec3<f32>(frame.view[0][2], frame.view[1][2], frame.view[2][2]);
    var t = 0.5;
    for (var i = 0; i < 32; i++) {
        let q = p + r * t;
        let clip = frame.view_proj * vec4<f32>(q, 1.0);
        let ndc = clip.xy / clip.w;
        let quv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if (clip.w <= 0.0 || any(quv < vec2<f32>(0.0)) || any(quv > vec2<f32>(1.0))) {
            break;
        }
        let scene = linear_depth(textureLoad(depth_r32, vec2<i32>(quv * full), 0).r);
        let qz = dot(q - frame.camera_position.xyz, forward);
        if (qz > scene && qz < scene + 1.0 + 0.1 * t) {
            let fade = smoothstep(0.0, 0.1, min(min(quv.x, 1.0 - quv.x), min(quv.y, 1.0 - quv.y)));
            let hit = textureSampleLevel(composite, linear_clamp, quv, 0.0).rgb;
            let sky = textureSampleLevel(sky_cube, linear_clamp, r, 1.0).rgb;
            return vec4<f32>(mix(sky, hit, fade), 1.0);
        }
        t *= 1.18;
    }
    return vec4<f32>(textureSampleLevel(sky_cube, linear_clamp, r, 1.0).rgb, 1.0);
}
