// Fixture compute shader: copies one storage buffer's words into another (the view-hazard
// test binds both to one buffer).
@group(0) @binding(0) var<storage, read> src: array<u32>;
@group(0) @binding(1) var<storage, read_write> dst: array<u32>;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < arrayLength(&dst) && id.x < arrayLength(&src)) {
        dst[id.x] = src[id.x] + 1u;
    }
}
