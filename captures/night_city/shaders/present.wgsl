// The last steps to the presented image: the GUI overlay drawn from the GUI element atlas
// (minimap over the landscape's heat map, hex panel, health bar and text row, crosshair), its glow from its own mips, the
// film-grain noise generated each frame, the grain pass that adds grain, encodes through the
// gamma LUT and lays the GUI on top, and the copy to the sRGB swapchain.

struct FrameConstants {
    camera_position: vec4<f32>,
    resolution: vec4<f32>,
    time: vec4<f32>,
}

struct Params {
    // Gamma LUT row of the brightness setting, and the grain's strength.
    brightness_row: u32,
    grain: f32,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var gui_elements: texture_2d<f32>;
@group(0) @binding(3) var linear_clamp: sampler;
@group(0) @binding(4) var gui_overlay: texture_2d<f32>;
@group(0) @binding(5) var gui_glow_out: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(6) var grain_lut_out: texture_storage_2d<r8unorm, write>;
@group(0) @binding(7) var ldr: texture_2d<f32>;
@group(0) @binding(8) var gamma_lut: texture_2d<f32>;
@group(0) @binding(9) var grain_lut: texture_2d<f32>;
@group(0) @binding(10) var gui_glow: texture_2d<f32>;
@group(0) @binding(11) var final_out: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(12) var final_image: texture_2d<f32>;
@group(0) @binding(13) var landscape_heat: texture_2d<f32>;
@group(0) @binding(14) var landscape_normal: texture_2d<f32>;

// The landscape maps cover 600 m around the origin; the minimap shows 160 m around the camera.
const MAP_EXTENT: f32 = 600.0;
const MINIMAP_SPAN: f32 = 160.0;

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

// `rect` (x, y, w, h in units of the screen height, x from the left) of the atlas region
// `region` (u0, v0, u1, v1), premultiplied.
fn panel(p: vec2<f32>, rect: vec4<f32>, region: vec4<f32>) -> vec4<f32> {
    let local = (p - rect.xy) / rect.zw;
    if (any(local < vec2<f32>(0.0)) || any(local > vec2<f32>(1.0))) {
        return vec4<f32>(0.0);
    }
    let t = textureSampleLevel(gui_elements, linear_clamp, mix(region.xy, region.zw, local), 0.0);
    return vec4<f32>(t.rgb * t.a, t.a);
}

fn over(top: vec4<f32>, below: vec4<f32>) -> vec4<f32> {
    return top + below * (1.0 - top.a);
}

// Layout in units of the screen height so the HUD keeps its proportions at any scale.
@fragment
fn fs_gui_overlay(in: FullscreenOut) -> @location(0) vec4<f32> {
    let aspect = frame.resolution.x / frame.resolution.y;
    let p = vec2<f32>(in.uv.x * aspect, in.uv.y);
    var c = vec4<f32>(0.0);
    // Minimap in the top-right corner, in a circle: the landscape heat map around the camera,
    // hill-shaded by the landscape normal map, under the atlas's radar rings.
    let map = vec4<f32>(aspect - 0.27, 0.04, 0.23, 0.23);
    if (length(p - map.xy - map.zw * 0.5) < map.z * 0.5) {
        let local = (p - map.xy) / map.zw - 0.5;
        let muv = frame.camera_position.xz / MAP_EXTENT + 0.5 + local * (MINIMAP_SPAN / MAP_EXTENT);
        let heat = textureSampleLevel(landscape_heat, linear_clamp, muv, 0.0).rgb;
        let n = textureSampleLevel(landscape_normal, linear_clamp, muv, 0.0).xyz * 2.0 - 1.0;
        let shade = clamp(dot(normalize(n), normalize(vec3<f32>(-0.5, -0.5, 1.0))), 0.2, 1.0);
        let ground = vec4<f32>(heat * shade * 0.45, 0.55);
        c = over(panel(p, map, vec4<f32>(0.0, 0.0, 0.5, 1.0)), ground);
    }
    // Hex panel (quest tracker) under it, dimmed.
    c = over(panel(p, vec4<f32>(aspect - 0.27, 0.3, 0.23, 0.1), vec4<f32>(0.5, 0.3, 1.0, 0.5)) * 0.6, c);
    // Health bar and the glyph row at the bottom left.
    c = over(panel(p, vec4<f32>(0.04, 0.86, 0.6, 0.1), vec4<f32>(0.0, 0.78, 0.5, 0.95)), c);
    // Crosshair: four short ticks around the centre.
    let d = abs(p - vec2<f32>(aspect * 0.5, 0.5));
    let tick = (step(d.x, 0.0012) * step(0.006, d.y) * step(d.y, 0.016))
        + (step(d.y, 0.0012) * step(0.006, d.x) * step(d.x, 0.016));
    c = over(vec4<f32>(vec3<f32>(0.33, 0.96, 0.93), 1.0) * min(tick, 1.0) * 0.9, c);
    return c;
}

// The GUI's glow: its 1/4, 1/8 and 1/16 mips summed at quarter resolution.
@compute @workgroup_size(8, 8, 1)
fn cs_gui_glow(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gui_glow_out);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    var glow = vec4<f32>(0.0);
    for (var m = 2; m <= 4; m++) {
        glow += textureSampleLevel(gui_overlay, linear_clamp, uv, f32(m)) * (0.5 / f32(m - 1));
    }
    textureStore(gui_glow_out, id.xy, min(glow, vec4<f32>(1.0)));
}

fn hash(p: vec3<u32>) -> f32 {
    var v = p.x * 1664525u + p.y * 22695477u + p.z * 2891336453u;
    v ^= v >> 16u;
    v *= 0x7feb352du;
    v ^= v >> 15u;
    v *= 0x846ca68bu;
    v ^= v >> 16u;
    return f32(v) / 4294967295.0;
}

// Grain noise for this frame: approximately Gaussian (sum of four uniforms) at full and half
// frequency, so grains are a little larger than a pixel, as film grain is.
@compute @workgroup_size(8, 8, 1)
fn cs_grain_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(grain_lut_out);
    if (any(id.xy >= size)) {
        return;
    }
    let f = u32(frame.time.z);
    var fine = 0.0;
    var coarse = 0.0;
    for (var k = 0u; k < 4u; k++) {
        fine += hash(vec3<u32>(id.xy, f * 8u + k));
        coarse += hash(vec3<u32>(id.xy / 2u, f * 8u + 4u + k));
    }
    let g = ((fine - 2.0) * 0.6 + (coarse - 2.0) * 0.4) * 0.5 + 0.5;
    textureStore(grain_lut_out, id.xy, vec4<f32>(clamp(g, 0.0, 1.0), 0.0, 0.0, 1.0));
}

fn encode(x: f32, row: i32) -> f32 {
    let width = f32(textureDimensions(gamma_lut).x - 1u);
    let t = clamp(x, 0.0, 1.0) * width;
    let i = i32(floor(t));
    let a = textureLoad(gamma_lut, vec2<i32>(i, row), 0).r;
    let b = textureLoad(gamma_lut, vec2<i32>(min(i + 1, i32(width)), row), 0).r;
    return mix(a, b, fract(t));
}

// Grain (strongest in the mid-tones, as on film), then the gamma LUT, then the GUI and its
// glow over the encoded image (the GUI is authored in display values).
@compute @workgroup_size(8, 8, 1)
fn cs_film_grain(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(final_out);
    if (any(id.xy >= size)) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
    var c = textureLoad(ldr, id.xy, 0).rgb;
    let offset = vec2<u32>(u32(frame.time.z) * 61u, u32(frame.time.z) * 127u);
    let g = textureLoad(grain_lut, (id.xy + offset) % textureDimensions(grain_lut), 0).r - 0.5;
    let l = dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
    let midtones = 4.0 * l * (1.0 - l);
    c = max(c + g * params.grain * (0.3 + midtones), vec3<f32>(0.0));
    let row = i32(params.brightness_row);
    var encoded = vec3<f32>(encode(c.r, row), encode(c.g, row), encode(c.b, row));
    let gui = textureLoad(gui_overlay, id.xy, 0);
    let glow = textureSampleLevel(gui_glow, linear_clamp, uv, 0.0);
    encoded = encoded * (1.0 - gui.a) + gui.rgb;
    encoded = encoded + glow.rgb * (1.0 - gui.a) * 0.6;
    textureStore(final_out, id.xy, vec4<f32>(min(encoded, vec3<f32>(1.0)), 1.0));
}

fn srgb_decode(x: f32) -> f32 {
    if (x <= 0.04045) {
        return x / 12.92;
    }
    return pow((x + 0.055) / 1.055, 2.4);
}

// The final image holds display-encoded values; the sRGB swapchain encodes what it is given,
// so the present pass decodes first and the bytes on screen are the final image's.
@fragment
fn fs_present(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = textureLoad(final_image, vec2<i32>(in.clip.xy), 0).rgb;
    return vec4<f32>(srgb_decode(c.r), srgb_decode(c.g), srgb_decode(c.b), 1.0);
}
