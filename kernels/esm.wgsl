// Rasterized depth → exponential shadow map in log form: L = c·z, the logarithm of the moment
// exp(c z) (Annen et al. 2008). Filtering happens in log space (log-sum-exp in `blur`), so
// exp(c z) is never formed and no exponent overflows, whatever c. With `params.linear` (the
// `sat` filter) it stores exp(c (z − 1)) instead.

// #import shared/exp_params
// #import shared/linear_depth

// Traffic (the cost model, src/graph/cost): one texel in, one out.
// #traffic src: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<r32float, write>;
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
    let z = depth.z;
    // For a summed-area table (which sums linearly) the moment itself, scaled by exp(−c) so it
    // stays in [e^{−c}, 1].
    let v = select(params.exp_pos * z, exp(params.exp_pos * (z - 1.0)), params.linear == 1u);
    textureStore(dst, id.xy, vec4<f32>(v, 0.0, 0.0, 0.0));
}
