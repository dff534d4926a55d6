// The texture viewer's display pass: one texel of the viewed subresource per output pixel
// (every `stride`-th texel for a thumbnail),
// channels masked, black and white points and exposure applied, encoded for egui (which
// expects gamma-encoded, non-sRGB textures), NaN / Inf / negative values overlaid.
// SOURCE_DECL and LOAD_EXPR are filled in per texture sampling type.

struct View {
    mask: vec4<f32>,
    black: f32,
    white: f32,
    exposure: f32,
    flags: u32,
    slice: u32,
    stencil_bits: u32,
    // Texels per output pixel along each axis: 1 for the viewer, more for a thumbnail.
    stride: u32,
    pad2: u32,
};

const FLAG_SRGB: u32 = 1u;
const FLAG_INVERT: u32 = 2u;
const FLAG_OVERLAY: u32 = 4u;

SOURCE_DECL
@group(0) @binding(1) var<uniform> view: View;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn load(p: vec2<i32>) -> vec4<f32> {
    return LOAD_EXPR;
}

fn encode(c: vec3<f32>) -> vec3<f32> {
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, c < vec3<f32>(0.0031308));
}

fn is_nan(x: f32) -> bool {
    // NaN is the one value unequal to itself; the bit test keeps a compiler from folding it.
    let bits = bitcast<u32>(x);
    return (bits & 0x7f800000u) == 0x7f800000u && (bits & 0x007fffffu) != 0u;
}

fn is_inf(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) == 0x7f800000u;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let raw = load(vec2<i32>(pos.xy) * i32(max(view.stride, 1u)));
    if (view.flags & FLAG_OVERLAY) != 0u {
        var nan = false;
        var inf = false;
        var negative = false;
        for (var k = 0; k < 4; k++) {
            if view.mask[k] > 0.0 {
                nan = nan || is_nan(raw[k]);
                inf = inf || is_inf(raw[k]);
                negative = negative || raw[k] < 0.0;
            }
        }
        if nan {
            return vec4<f32>(1.0, 0.0, 1.0, 1.0);
        }
        if inf {
            return vec4<f32>(0.0, 1.0, 1.0, 1.0);
        }
        if negative {
            return vec4<f32>(0.2, 0.2, 1.0, 1.0);
        }
    }
    let v = raw * exp2(view.exposure);
    let shown = dot(view.mask, vec4<f32>(1.0));
    var c: vec3<f32>;
    if shown == 1.0 {
        c = vec3<f32>(dot(v, view.mask));
    } else {
        c = v.rgb * view.mask.rgb;
    }
    c = clamp((c - view.black) / max(view.white - view.black, 1e-20), vec3<f32>(0.0), vec3<f32>(1.0));
    if (view.flags & FLAG_INVERT) != 0u {
        c = 1.0 - c;
    }
    if (view.flags & FLAG_SRGB) != 0u {
        c = encode(c);
    }
    return vec4<f32>(c, 1.0);
}
