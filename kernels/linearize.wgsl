// Rasterized depth → linear light-space depth in [0, 1], with non-finite texels replaced.
//
// Orthographic depth is already linear. Perspective (wgpu/glam, depth 0 at near, 1 at far):
//   d_ndc = far (Z − near) / ((far − near) Z)  ⇒  d = near·d_ndc / (far (1 − d_ndc) + near·d_ndc),
// written with (1 − d_ndc), exact in fp32 for d_ndc ≥ 0.5, to avoid cancellation near the far plane.
// NaN and ±Inf (degenerate geometry, a host's bad data) become 1.0 — "no occluder" — and are
// counted in stats[0], so the caller can report them instead of spreading them through filters.

// Keep in sync with `LinearizeParams` in src/technique.rs.
struct Params {
    perspective: u32,
    near: f32,
    far: f32,
    _pad: u32,
}

// Traffic (the cost model, src/graph/cost): one texel in, one out; the counter is one atomic per
// replaced texel.
// #traffic src: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<r32float, write>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

// WGSL lets implementations assume finite floats, so test the exponent bits instead.
fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(dst);
    if any(id.xy >= size) {
        return;
    }
    let raw = textureLoad(src, id.xy, 0).r;
    var z = 1.0;
    if is_finite(raw) {
        let d = clamp(raw, 0.0, 1.0);
        z = d;
        if params.perspective == 1u {
            z = params.near * d / (params.far * (1.0 - d) + params.near * d);
        }
        z = clamp(z, 0.0, 1.0);
    } else {
        atomicAdd(&stats[0], 1u);
    }
    textureStore(dst, id.xy, vec4<f32>(z, 0.0, 0.0, 0.0));
}
