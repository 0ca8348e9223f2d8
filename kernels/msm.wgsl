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

// The redesign layout (`exec::KernelLayout::Redesign`, REDESIGN true) gives an invocation
// TEXELS_X texels, WG_SIZE apart along x so that neighbouring lanes stay on neighbouring
// texels, and issues every load before the first texel's arithmetic and store (one load in
// flight an invocation left the texture copies at 0.3 of the buffer copy on an H200); each
// texel's arithmetic is the one-texel kernel's, so both give the same map bit for bit. The
// dispatch covers WG_SIZE · TEXELS_X columns a workgroup (`kernels::TEXELS_X_CONSTANT`).
override REDESIGN: bool = false;
override TEXELS_X: u32 = select(1u, 4u, REDESIGN);
const TEXELS_MAX: u32 = 4u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
) {
    if REDESIGN {
        main_texels(wg.xy, lid.xy);
        return;
    }
    let size = textureDimensions(src);
    if any(id.xy >= size) {
        return;
    }
    encode(id.xy, textureLoad(src, id.xy, 0).r);
}

// Texel `xy` of the map from its raw depth.
fn encode(xy: vec2<u32>, raw: f32) {
    if !depth_is_finite(raw) {
        atomicAdd(&stats[0], 1u);
    }
    let z = linear_depth(raw, params.depth);
    textureStore(dst, xy, msm_moments(z, params.quantized == 1u));
}

// TEXELS_X texels an invocation (the redesign layout): every load first, then each texel.
fn main_texels(wg: vec2<u32>, lid: vec2<u32>) {
    let size = textureDimensions(src);
    let y = wg.y * WG_SIZE + lid.y;
    let x0 = wg.x * TEXELS_X * WG_SIZE + lid.x;
    // Past the edge a lane loads the last texel again (cached already) and skips its store:
    // the loads stay unconditional, so none waits on another's branch.
    var raw: array<f32, TEXELS_MAX>;
    for (var k = 0u; k < TEXELS_X; k++) {
        raw[k] = textureLoad(src, min(vec2<u32>(x0 + k * WG_SIZE, y), size - 1u), 0).r;
    }
    if y >= size.y {
        return;
    }
    for (var k = 0u; k < TEXELS_X; k++) {
        let x = x0 + k * WG_SIZE;
        if x < size.x {
            encode(vec2<u32>(x, y), raw[k]);
        }
    }
}
