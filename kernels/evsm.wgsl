// Rasterized depth → exponential variance moments (shared/evsm_moments), unfiltered: the map a
// summed-area table, a mip chain or no filter reads (a blur reads the depth itself: `evsm_blur`).
// EVSM2 binds an rg32float (or rgba16float) output and keeps (pos, pos²); EVSM4 keeps all four.
// The scene clamps c to the storage's limit (42 for f32, 5.54 for f16) so pos² stays finite.

// #import shared/exp_params
// #import shared/linear_depth
// #import shared/evsm_moments

// Traffic (the cost model, src/graph/cost): one texel in, one out.
// #traffic src: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(src);
    if any(id.xy >= size) {
        return;
    }
    let depth = load_linear_depth(src, id.xy, params.depth);
    if !depth.finite {
        atomicAdd(&stats[0], 1u);
    }
    textureStore(dst, id.xy, evsm_moments(depth.z, params.exp_pos, params.exp_neg));
}
