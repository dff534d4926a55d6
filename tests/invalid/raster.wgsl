// The raster shader the invalid captures name: a full-screen triangle reading one texture
// (`src`) or one depth texture (`depth_src`).
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var depth_src: texture_depth_2d;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(src, vec2<i32>(p.xy), 0);
}
@fragment fn fs_depth(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(textureLoad(depth_src, vec2<i32>(p.xy), 0));
}
