// Linear depth → four channels of the CSM-Z basis of convolution soft shadow maps (Annen et
// al. 2008): the complementary basis images B̄_i(z)·z, in the order
//   [z, z·sin c₁z, z·cos c₁z, z·sin c₂z, z·cos c₂z, …, z·cos c_M z]   (2M + 1 channels),
// c_k = π (2k − 1), from channel 4·chunk on; channels past the last are written as zeros.
// Filtered linearly (here through a summed-area table) next to the CSM basis, they give
// E[f̄(d, z)·z] over any rectangle, f̄ = 1 − f the complementary test, so the average blocker
// depth E[f̄·z] / E[f̄] (shared/blocker.wgsl) is a lookup. Every value lies in [−1, 1]
// (|z·sin| ≤ z ≤ 1). The argument is reduced to [−π, π] as in `csm`.
// #import shared/csm_basis
// Storage: rgba32float by default; the executor re-declares `dst` for the bound format
// (r32float, rg32float for a last map of one or two channels; rgba16float for f16).

// Keep in sync with `CsmParams` in src/technique.rs (`first_term` is the chunk here).
struct Params {
    chunk: u32,
    terms: u32,
    _pad0: u32,
    _pad1: u32,
}

// Traffic (the cost model, src/graph/cost): one texel in, one out.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var<uniform> params: Params;

const WG_SIZE: u32 = 16u;

// Channel i of the sequence at depth z (0 past channel 2M).
fn csm_z_channel(i: u32, z: f32) -> f32 {
    if i == 0u {
        return z;
    }
    if i > 2u * params.terms {
        return 0.0;
    }
    let sc = csm_sin_cos((i + 1u) / 2u, z);
    return z * select(sc.y, sc.x, (i & 1u) == 1u);
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(src);
    if any(id.xy >= size) {
        return;
    }
    let z = textureLoad(src, id.xy, 0).r;
    let first = 4u * params.chunk;
    let v = vec4<f32>(
        csm_z_channel(first, z),
        csm_z_channel(first + 1u, z),
        csm_z_channel(first + 2u, z),
        csm_z_channel(first + 3u, z),
    );
    textureStore(dst, id.xy, v);
}
