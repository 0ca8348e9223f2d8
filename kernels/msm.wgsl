// Rasterized depth → four moments (z, z², z³, z⁴) for moment shadow maps (Peters & Klein 2015),
// unfiltered: the map a summed-area table, a mip chain or no filter reads (a blur reads the depth
// itself: `msm_blur`).
// f32 storage keeps the raw powers; 16-bit storage (rgba16unorm, rgba16float) keeps the
// optimized quantization of the paper's section 4.3: an affine map that spreads the moments of
// any z ∈ [0, 1] over [0, 1] so 16 bits lose the least (shared/msm_quantize).
// Storage: rgba32float by default; the executor re-declares `dst` for the bound format.

// #import shared/msm_moments
// #import shared/linear_depth

// Keep in sync with `MsmParams` in src/wgsl_mirrors.rs.
struct Params {
    depth: DepthParams,
    quantized: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

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
    textureStore(dst, id.xy, msm_moments(depth.z, params.quantized == 1u));
}
