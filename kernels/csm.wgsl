// Linear depth → two terms of the Fourier basis of convolution shadow maps (Annen et al.
// 2007): (sin c_k z, cos c_k z, sin c_{k+1} z, cos c_{k+1} z), c_k = π (2k − 1), k = first_term.
// A scene with M terms runs ⌈M/2⌉ of these; a pair past M is written as zeros. The values lie
// in [−1, 1], so f16 storage keeps them to 2⁻¹¹. The argument is reduced exactly to [−π, π]
// first (sin and cos have period 2 in (2k − 1)·z), where GPU sin/cos are specified.
// #import shared/csm_basis
// Storage: rgba32float by default; the executor re-declares `dst` for the bound format.

// Keep in sync with `CsmParams` in src/technique.rs.
struct Params {
    first_term: u32,
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

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(src);
    if any(id.xy >= size) {
        return;
    }
    let z = textureLoad(src, id.xy, 0).r;
    let k = params.first_term;
    var v = vec4<f32>(csm_sin_cos(k, z), csm_sin_cos(k + 1u, z));
    if k + 1u > params.terms {
        v = vec4<f32>(v.xy, 0.0, 0.0);
    }
    textureStore(dst, id.xy, v);
}
