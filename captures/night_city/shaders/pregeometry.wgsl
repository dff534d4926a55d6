// Pre-geometry 2D passes: the in-game screens composed into the billboard atlas from the
// glyph sheets copied out of the mega texture, and the cyber GUI elements drawn into their
// own atlas (later copied into the mega texture).

struct FrameConstants {
    time: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameConstants;
@group(0) @binding(1) var billboard_src_0: texture_2d<f32>;
@group(0) @binding(2) var billboard_src_1: texture_2d<f32>;
@group(0) @binding(3) var billboard_src_2: texture_2d<f32>;
@group(0) @binding(4) var linear_wrap: sampler;

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

fn hash21(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(123.34, 456.21));
    let r = q + dot(q, q + 45.32);
    return fract(r.x * r.y);
}

fn palette(t: f32) -> vec3<f32> {
    return 0.5 + 0.5 * cos(6.2831 * (t + vec3<f32>(0.0, 0.33, 0.67)));
}

// The atlas is a 4x4 grid of screens; each screen scrolls one of the three glyph sheets with
// its own palette, scanlines and a frame.
fn screen(cell: vec2<f32>, local: vec2<f32>, glyph: f32) -> vec4<f32> {
    let t = frame.time.x;
    let base = palette(hash21(cell + 3.0) + t * 0.02);
    let accent = palette(hash21(cell + 7.0) + 0.5);
    let scan = 0.8 + 0.2 * sin(local.y * 180.0);
    let border = step(local.x, 0.03) + step(0.97, local.x) + step(local.y, 0.03) + step(0.97, local.y);
    let gradient = mix(base * 0.25, base, local.y);
    var c = mix(gradient, accent, glyph) * scan;
    c = mix(c, vec3<f32>(1.0), min(border, 1.0) * 0.8);
    return vec4<f32>(c, 1.0);
}

fn scroll(cell: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(frame.time.x * 0.05 * (1.0 + hash21(cell)), 0.0);
}

@fragment
fn fs_billboards(in: FullscreenOut) -> @location(0) vec4<f32> {
    let cell = floor(in.uv * 4.0);
    let local = fract(in.uv * 4.0);
    let id = cell.x + cell.y * 4.0;
    let s = scroll(cell);
    let sheet = u32(id) % 3u;
    var glyph = 0.0;
    if (sheet == 0u) {
        glyph = textureSample(billboard_src_0, linear_wrap, local * vec2<f32>(1.0, 0.6) + s).r;
    } else if (sheet == 1u) {
        glyph = textureSample(billboard_src_1, linear_wrap, local + s).r;
    } else {
        glyph = textureSample(billboard_src_2, linear_wrap, local * 1.5 + s).r;
    }
    return screen(cell, local, glyph);
}

// Without the glyph sheets (the night frame copies none out of the mega texture) the screens
// run their idle loop: blocks of pseudo-text generated in place.
@fragment
fn fs_billboards_idle(in: FullscreenOut) -> @location(0) vec4<f32> {
    let cell = floor(in.uv * 4.0);
    let local = fract(in.uv * 4.0);
    let p = (local + scroll(cell)) * vec2<f32>(24.0, 12.0);
    let row_on = step(0.35, fract(p.y)) * step(fract(p.y), 0.85);
    let glyph = step(0.55, hash21(floor(p) + cell * 17.0)) * row_on;
    return screen(cell, local, glyph);
}

// GUI elements: health bar, radar rings, hexagon grid and glyph rows in cyan and red.
@fragment
fn fs_gui(in: FullscreenOut) -> @location(0) vec4<f32> {
    let uv = in.uv * vec2<f32>(2.0, 1.0);
    let cyan = vec3<f32>(0.33, 0.96, 0.93);
    let red = vec3<f32>(1.0, 0.28, 0.27);
    var c = vec3<f32>(0.0);
    var a = 0.0;
    // Radar rings in the left square.
    let r = length(uv - vec2<f32>(0.5, 0.5));
    let ring = smoothstep(0.008, 0.0, abs(fract(r * 8.0) - 0.5) / 8.0) * step(r, 0.45);
    let sweep = smoothstep(0.3, 0.0, fract(atan2(uv.y - 0.5, uv.x - 0.5) / 6.2831 - frame.time.x * 0.2)) * step(r, 0.45);
    c += cyan * (ring + sweep * 0.5);
    a = max(a, max(ring, sweep * 0.5));
    // Hexagon grid in the right square.
    let q = (uv - vec2<f32>(1.0, 0.0)) * 12.0;
    let hx = vec2<f32>(q.x + q.y * 0.5, q.y * 0.866);
    let f = abs(fract(hx) - 0.5);
    let edge = smoothstep(0.06, 0.0, min(f.x, f.y)) * step(1.0, uv.x);
    c += red * edge;
    a = max(a, edge);
    // Health bar and glyph row along the bottom.
    let bar = step(0.05, in.uv.x) * step(in.uv.x, 0.05 + 0.6 * (0.7 + 0.3 * sin(frame.time.x))) * step(0.9, in.uv.y) * step(in.uv.y, 0.94);
    c = mix(c, red, bar);
    a = max(a, bar);
    let glyph = step(0.5, hash21(floor(in.uv * vec2<f32>(64.0, 40.0)))) * step(0.8, in.uv.y) * step(in.uv.y, 0.86);
    c = mix(c, cyan, glyph);
    a = max(a, glyph);
    return vec4<f32>(c, a);
}
