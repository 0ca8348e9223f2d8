// Rasterized depth → up to four maps of the convolution basis, from one read of the depth.
//
// The light's maps, in order (map index m):
//   - CSM basis (Annen et al. 2007), ⌈M/2⌉ maps: map m holds (sin c_k z, cos c_k z,
//     sin c_{k+1} z, cos c_{k+1} z), k = 2m + 1, c_k = π (2k − 1); a pair past M is zeros.
//   - CSSM only, the CSM-Z basis (Annen et al. 2008): the complementary basis images B̄_i(z)·z
//     in the order [z, z·sin c₁z, z·cos c₁z, …, z·cos c_M z] (2M + 1 channels), four channels a
//     map from channel 4·(m − ⌈M/2⌉) on, channels past the last zeros. Filtered next to the CSM
//     basis they give E[f̄(d, z)·z] over any rectangle, f̄ = 1 − f, so the average blocker depth
//     E[f̄·z] / E[f̄] (shared/blocker.wgsl) is a lookup.
//   - or, CSSM with `blocker_search = "moments"` (`moments` = 1), one map of MSM's quantized
//     moments (z, z², z³, z⁴), whose means give MSM's blocker estimate.
// This dispatch writes maps first_map … first_map + maps − 1 to dst0 … dst<maps − 1> (the
// executor binds the unused outputs to the last bound one; they are not stored to). Every value
// lies in [−1, 1] (|z·sin| ≤ z ≤ 1), so f16 storage keeps them to 2⁻¹¹. The argument is reduced
// exactly to [−π, π] first (shared/csm_basis). The depth is linearized here (shared/linear_depth).
// Storage: rgba32float by default; the executor re-declares each `dst<j>` for its bound format
// (rg32float or r32float for a last map of fewer channels; rgba16float for f16).

// #import shared/csm_maps
// #import shared/linear_depth

// Keep in sync with `CsmParams` in src/wgsl_mirrors.rs.
struct Params {
    depth: DepthParams,
    first_map: u32,
    maps: u32,
    terms: u32,
    moments: u32,
}

// Traffic (the cost model, src/graph/cost): one texel in, one out per bound map (an unbound
// output is not in the node and costs nothing).
// #traffic src: all
// #traffic dst0: all
// #traffic dst1: all
// #traffic dst2: all
// #traffic dst3: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst0: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var dst1: texture_storage_2d<rgba32float, write>;
@group(0) @binding(3) var dst2: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var dst3: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var<uniform> params: Params;
@group(0) @binding(6) var<storage, read_write> stats: array<atomic<u32>>;

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

// Texel `xy` of every bound map from its raw depth.
fn encode(xy: vec2<u32>, raw: f32) {
    if !depth_is_finite(raw) {
        atomicAdd(&stats[0], 1u);
    }
    let z = linear_depth(raw, params.depth);
    let m = params.first_map;
    let moments = params.moments != 0u;
    textureStore(dst0, xy, csm_basis_map(m, params.terms, moments, z));
    if params.maps > 1u {
        textureStore(dst1, xy, csm_basis_map(m + 1u, params.terms, moments, z));
    }
    if params.maps > 2u {
        textureStore(dst2, xy, csm_basis_map(m + 2u, params.terms, moments, z));
    }
    if params.maps > 3u {
        textureStore(dst3, xy, csm_basis_map(m + 3u, params.terms, moments, z));
    }
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
