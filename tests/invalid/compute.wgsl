// The shader the invalid captures name: validation reads and reflects it, so bindings must name its variables.
@group(0) @binding(0) var<storage, read_write> particles: array<u32>;
@compute @workgroup_size(1) fn cs_main() { particles[0] = 1u; }
