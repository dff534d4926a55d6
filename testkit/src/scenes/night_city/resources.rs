//! The Night City frame's resources, as NIGHT_CITY_PASSES.md lists them (names, formats, sizes;
//! sizes that follow the output are relative), and the frame's header: camera, sun and moon,
//! adapter, descriptor heaps, samplers and queues. Shared by every variant of the capture.

use serde_json::{Value, json};

/// Top-level fields other than the name, resources, meshes, fences and passes.
pub(super) fn header() -> Value {
    json!({
        "format_version": 1,
        "resolution": {"width": 1920, "height": 1080},
        "adapter": {"architecture": "numa", "resource_heap_tier": 2},
        "camera": {
            "position": [-6.0, 9.0, -40.0],
            "target": [-6.0, 3.0, 160.0],
            "fov_y_degrees": 60.0,
            "near": 0.1,
            "far": 2000.0,
            "velocity": [0.0, 0.0, 0.35],
            "jitter_phases": 8
        },
        "frame": {
            "time_seconds": 52000.0,
            "sun_direction": [0.35, 0.62, 0.45],
            "sun_color": [9.0, 8.4, 7.6],
            "moon_direction": [-0.3, 0.5, -0.6],
            "moon_color": [0.04, 0.05, 0.08],
            "exposure": 0.12,
            "shadow_cascades": {"resolution": 4096, "split_lambda": 0.8, "max_distance": 220}
        },
        "descriptor_heaps": [
            {
                "name": "cbv_srv_uav",
                "type": "CBV_SRV_UAV",
                "capacity": 500000,
                "shader_visible": true
            },
            {"name": "samplers", "type": "SAMPLER", "capacity": 2048, "shader_visible": true},
            {"name": "rtv", "type": "RTV", "capacity": 1024},
            {"name": "dsv", "type": "DSV", "capacity": 256}
        ],
        "samplers": [
            {"name": "linear_clamp"},
            {"name": "linear_wrap", "address_u": "wrap", "address_v": "wrap", "address_w": "wrap"},
            {
                "name": "point_clamp",
                "min_filter": "point",
                "mag_filter": "point",
                "mip_filter": "point"
            },
            {"name": "shadow_compare", "compare": "less_equal"},
            {
                "name": "aniso_wrap",
                "address_u": "wrap",
                "address_v": "wrap",
                "address_w": "wrap",
                "max_anisotropy": 16
            }
        ],
        "queues": [
            {"name": "graphics", "type": "graphics"},
            {"name": "compute", "type": "compute"},
            {"name": "copy", "type": "copy"}
        ]
    })
}

/// Every resource of the frame, in the manifest's order.
pub(super) fn resources() -> Vec<Value> {
    [
        pre_geometry(),
        geometry(),
        masks(),
        shadows_and_sky(),
        lighting(),
        composition(),
        post_chain(),
    ]
    .concat()
}

/// Passes 1-9: billboards, GUI, top view, voxels, instances, terrain, ocean.
fn pre_geometry() -> Vec<Value> {
    vec![
        json!({
            "name": "mega_texture",
            "kind": "buffer",
            "buffer_kind": "byte_address",
            "size": 16777216,
            "initial": {"generator": {"name": "atlas", "seed": 11, "params": {"cells": 64}}},
            "history": true
        }),
        json!({
            "name": "billboard_src_0",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": 480,
            "height": 272
        }),
        json!({
            "name": "billboard_src_1",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": 240,
            "height": 136
        }),
        json!({
            "name": "billboard_src_2",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": 240,
            "height": 136
        }),
        json!({
            "name": "billboard_atlas",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 1024,
            "height": 1024,
            "mip_levels": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "gui_elements",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 1024,
            "height": 512,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "top_view_depth",
            "kind": "texture_2d",
            "format": "D16_UNORM",
            "width": 2048,
            "height": 2048,
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
        json!({
            "name": "voxel_normals",
            "kind": "texture_3d",
            "format": "R16G16B16A16_FLOAT",
            "width": 64,
            "height": 64,
            "depth": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "instance_data",
            "kind": "buffer",
            "buffer_kind": "structured",
            "size": 258048,
            "stride": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"],
            "initial": {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
        }),
        json!({
            "name": "draw_args",
            "kind": "buffer",
            "buffer_kind": "byte_address",
            "size": 1280,
            "flags": ["ALLOW_UNORDERED_ACCESS"],
            "initial": {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
        }),
        json!({
            "name": "terrain_layers",
            "kind": "texture_2d_array",
            "format": "R8G8B8A8_UNORM",
            "width": 1024,
            "height": 1024,
            "array_layers": 2,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "terrain_ids",
            "kind": "texture_2d",
            "format": "R16_UINT",
            "width": 1024,
            "height": 1024,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "lod_ids",
            "kind": "texture_2d",
            "format": "R16_UINT",
            "width": 256,
            "height": 256,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "ocean_height",
            "kind": "texture_2d",
            "format": "R16_UNORM",
            "width": 1024,
            "height": 1024,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "ocean_mask",
            "kind": "texture_2d",
            "format": "BC7_UNORM_SRGB",
            "width": 1024,
            "height": 1024,
            "initial": {"generator": {"name": "coastline", "seed": 5}}
        }),
        json!({
            "name": "ocean_wave_noise",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": 256,
            "height": 256,
            "flags": ["ALLOW_UNORDERED_ACCESS"],
            "history": true,
            "initial": {"generator": {"name": "constant", "seed": 0, "params": {"value": 0}}}
        }),
    ]
}

/// Passes 10-13: depth, G-buffer, blue noise, depth/stencil conversions, motion stencil.
fn geometry() -> Vec<Value> {
    vec![
        json!({
            "name": "depth",
            "kind": "texture_2d",
            "format": "R32G8X24_TYPELESS",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
        json!({
            "name": "gbuffer_albedo",
            "kind": "texture_2d",
            "format": "R10G10B10A2_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "gbuffer_normal",
            "kind": "texture_2d",
            "format": "R10G10B10A2_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "gbuffer_material",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "motion_vectors",
            "kind": "texture_2d",
            "format": "R16G16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "blue_noise",
            "kind": "texture_2d",
            "format": "R16G16B16A16_UNORM",
            "width": 64,
            "height": 64,
            "initial": {"generator": {"name": "blue_noise", "seed": 3}}
        }),
        json!({
            "name": "depth_r32",
            "kind": "texture_2d",
            "format": "R32_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "depth_half",
            "kind": "texture_2d",
            "format": "R16_FLOAT",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "stencil_half",
            "kind": "texture_2d",
            "format": "R8_UINT",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "motion_stencil",
            "kind": "texture_2d",
            "format": "R8_UINT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
    ]
}

/// Passes 14-19: reflection mask, noised normal, sky masks, AO, grading LUT.
fn masks() -> Vec<Value> {
    vec![
        json!({
            "name": "reflection_mask",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "noised_normal",
            "kind": "texture_2d",
            "format": "R10G10B10A2_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "sky_mask_coarse",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": {"scale": 0.125},
            "height": {"scale": 0.125, "multiple_of": 8},
            "mip_levels": 4,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "sky_mask",
            "kind": "texture_2d",
            "format": "R32_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "ao",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "grading_lut",
            "kind": "texture_3d",
            "format": "R16G16B16A16_FLOAT",
            "width": 32,
            "height": 32,
            "depth": 32,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
    ]
}

/// Passes 20-25: shadow maps, clouds, the sky cube, the coat mask.
fn shadows_and_sky() -> Vec<Value> {
    vec![
        json!({
            "name": "csm_proxy",
            "kind": "texture_2d",
            "format": "R16_TYPELESS",
            "width": 2048,
            "height": 2048,
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
        json!({
            "name": "csm",
            "kind": "texture_2d_array",
            "format": "R16_TYPELESS",
            "width": 4096,
            "height": 4096,
            "array_layers": 4,
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
        json!({
            "name": "omni_depth",
            "kind": "texture_2d",
            "format": "R32_TYPELESS",
            "width": 1024,
            "height": 1024,
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
        json!({
            "name": "omni_vsm",
            "kind": "texture_2d_array",
            "format": "R16G16_UNORM",
            "width": 1024,
            "height": 1024,
            "array_layers": 10,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "cloud_distribution",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 512,
            "height": 512,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "sky_cube",
            "kind": "texture_cube",
            "format": "R11G11B10_FLOAT",
            "width": 64,
            "height": 64,
            "mip_levels": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "sky_projected",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": 256,
            "height": 256,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "coat_mask",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
    ]
}

/// Passes 26-36: clustered lights, sun shadow, environment, GI, landscape, fog, lighting.
fn lighting() -> Vec<Value> {
    vec![
        json!({
            "name": "cluster_light_index",
            "kind": "texture_3d",
            "format": "R32_UINT",
            "width": {"scale": 0.03125},
            "height": {"scale": 0.03125},
            "depth": 24,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "light_list",
            "kind": "buffer",
            "buffer_kind": "structured",
            "size": 6266880,
            "stride": 4,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "lights",
            "kind": "buffer",
            "buffer_kind": "structured",
            "size": 262144,
            "stride": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"],
            "initial": {
                "generator": {
                    "name": "lights",
                    "seed": 17,
                    "params": {"count": 256, "area": 240, "intensity": 300}
                }
            }
        }),
        json!({
            "name": "sun_shadow",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "local_light_mask",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": {"scale": 0.0625},
            "height": {"scale": 0.0625},
            "mip_levels": 2,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "env_cube",
            "kind": "texture_cube",
            "format": "R11G11B10_FLOAT",
            "width": 128,
            "height": 128,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "env_dual_paraboloid",
            "kind": "texture_2d_array",
            "format": "R11G11B10_FLOAT",
            "width": 512,
            "height": 256,
            "array_layers": 32,
            "mip_levels": 6,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "gi_probe_indices",
            "kind": "texture_3d",
            "format": "R32G32_UINT",
            "width": 64,
            "height": 64,
            "depth": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "landscape_normal",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 1024,
            "height": 1024,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "landscape_heat",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 1024,
            "height": 1024,
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "fog_volume",
            "kind": "texture_3d",
            "format": "R16G16B16A16_FLOAT",
            "width": {"scale": 0.125},
            "height": {"scale": 0.125, "multiple_of": 8},
            "depth": 128,
            "mip_levels": 2,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "head_mask",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "lit_diffuse",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "lit_specular",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
    ]
}

/// Passes 37-45: SSR,
/// indirect light, composition, transparency, skin, water, TAA.
fn composition() -> Vec<Value> {
    vec![
        json!({
            "name": "ssr_tiles",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": {"scale": 0.125},
            "height": {"scale": 0.125, "multiple_of": 8},
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "ssr",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "ssr_reflectivity",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "indirect",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "composite",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "composite_specular",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "transparent_lut",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": 256,
            "height": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "skin_irradiance",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "water_reflection",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "taa_output",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"],
            "history": true
        }),
        json!({
            "name": "taa_downscaled",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "half",
            "height": "half",
            "mip_levels": 3,
            "flags": ["ALLOW_UNORDERED_ACCESS"],
            "history": true
        }),
        json!({
            "name": "taa_blur_temp",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "half",
            "height": "half",
            "mip_levels": 3,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "composite_post",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
    ]
}

/// Passes 46-57: downscales, HDR LUTs, bloom, lens flare, grading, GUI, grain,
/// present; and the environment capture's depth.
fn post_chain() -> Vec<Value> {
    vec![
        json!({
            "name": "post_half",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "post_quarter",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "quarter",
            "height": "quarter",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "post_sharpened",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "hdr_lut_a",
            "kind": "texture_2d",
            "format": "R16_FLOAT",
            "width": 256,
            "height": 256,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "hdr_lut_b",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": 256,
            "height": 64,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "hdr_lut_c",
            "kind": "texture_2d",
            "format": "R16G16B16A16_FLOAT",
            "width": 256,
            "height": 1,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "hdr_params",
            "kind": "buffer",
            "buffer_kind": "structured",
            "size": 256,
            "stride": 16,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "bloom_chain",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "half",
            "height": "half",
            "mip_levels": 6,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "lens_flare",
            "kind": "texture_2d",
            "format": "R11G11B10_FLOAT",
            "width": "half",
            "height": "half",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "ldr",
            "kind": "texture_2d",
            "format": "R10G10B10A2_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"]
        }),
        json!({
            "name": "gamma_lut",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": 456,
            "height": 256,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "gui_overlay",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": "full",
            "height": "full",
            "mip_levels": "full",
            "flags": ["ALLOW_RENDER_TARGET", "ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "gui_glow",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": "quarter",
            "height": "quarter",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "grain_lut",
            "kind": "texture_2d",
            "format": "R8_UNORM",
            "width": 256,
            "height": 256,
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "final",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_UNORDERED_ACCESS"]
        }),
        json!({
            "name": "swapchain",
            "kind": "texture_2d",
            "format": "R8G8B8A8_UNORM_SRGB",
            "width": "full",
            "height": "full",
            "flags": ["ALLOW_RENDER_TARGET"],
            "output": true
        }),
        json!({
            "name": "env_depth",
            "kind": "texture_2d",
            "format": "D32_FLOAT",
            "width": 128,
            "height": 128,
            "flags": ["ALLOW_DEPTH_STENCIL"]
        }),
    ]
}
