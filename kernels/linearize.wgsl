// Rasterized depth → linear light-space depth in [0, 1] (shared/linear_depth), with
// non-finite texels replaced by 1.0 and counted in stats[0]. The encodings linearize the depth
// themselves; this map is planned only where something reads the linear depth (hard, PCF and
// PCSS shading, diagnostics).

// #import shared/linear_depth

// Traffic (the cost model, src/graph/cost): one texel in, one out; the counter is one atomic per
// replaced texel.
// #traffic src: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<r32float, write>;
@group(0) @binding(2) var<uniform> params: DepthParams;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(dst);
    if any(id.xy >= size) {
        return;
    }
    let raw = textureLoad(src, id.xy, 0).r;
    if !depth_is_finite(raw) {
        atomicAdd(&stats[0], 1u);
    }
    textureStore(dst, id.xy, vec4<f32>(linear_depth(raw, params), 0.0, 0.0, 0.0));
}
