// The bandwidth yardstick for benchmarks: copies a buffer, 16 bytes per invocation.
// Effective bandwidth counts one read and one write of every byte.

// Traffic (the cost model, src/graph/cost): the yardstick: every byte read once and written once.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var<storage, read> src: array<vec4<u32>>;
@group(0) @binding(1) var<storage, read_write> dst: array<vec4<u32>>;

const WG_SIZE: u32 = 256u;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // A 2-D grid of workgroups lifts the 65535-group limit of one dimension.
    let i = id.x + id.y * groups.x * WG_SIZE;
    if i < arrayLength(&dst) {
        dst[i] = src[i];
    }
}
