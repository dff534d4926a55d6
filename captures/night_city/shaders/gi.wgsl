// GI probe indices: for each cell of the 64^3 volume, the index of the probe that should light
// it (probes sit every 4 cells; the nearest probe that is not buried in geometry according to
// the voxel field; 4096, one past the last probe, when none is usable) and a mask of which of
// the 8 surrounding probes are usable for blending.

@group(0) @binding(0) var voxel_normals: texture_3d<f32>;
@group(0) @binding(1) var gi_probe_indices: texture_storage_3d<rg32uint, write>;

const PROBE_SPACING: u32 = 4u;

fn probe_usable(p: vec3<u32>) -> bool {
    let cell = min(p * PROBE_SPACING + PROBE_SPACING / 2u, vec3<u32>(63u));
    // Alpha is the signed distance to the nearest surface in cells: buried probes are negative.
    return textureLoad(voxel_normals, cell, 0).w > 0.25;
}

@compute @workgroup_size(4, 4, 4)
fn cs_gi_probe_indices(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(64u))) {
        return;
    }
    let probes = 64u / PROBE_SPACING;
    let f = (vec3<f32>(id) + 0.5) / f32(PROBE_SPACING) - 0.5;
    let base = vec3<u32>(clamp(floor(f), vec3<f32>(0.0), vec3<f32>(f32(probes - 2u))));
    var mask = 0u;
    var best = probes * probes * probes;
    var best_d = 1e9;
    for (var k = 0u; k < 8u; k++) {
        let p = base + vec3<u32>(k & 1u, (k >> 1u) & 1u, k >> 2u);
        if (probe_usable(p)) {
            mask = mask | (1u << k);
            let d = distance(vec3<f32>(p), f);
            if (d < best_d) {
                best_d = d;
                best = (p.z * probes + p.y) * probes + p.x;
            }
        }
    }
    textureStore(gi_probe_indices, id, vec4<u32>(best, mask, 0u, 0u));
}
