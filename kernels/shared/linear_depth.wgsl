// Rasterized depth → linear light-space depth in [0, 1] (import-only module): the one
// linearization every kernel that reads the raw depth buffer shares (`linearize`, and the
// encodings `vsm`, `evsm`, `esm`, `msm`, `csm`, which read the depth themselves instead
// of a linear map another dispatch wrote).
//
// Orthographic depth is already linear. Perspective (wgpu/glam, depth 0 at near, 1 at far):
//   d_ndc = far (Z − near) / ((far − near) Z)  ⇒  d = near·d_ndc / (far (1 − d_ndc) + near·d_ndc),
// written with (1 − d_ndc), exact in fp32 for d_ndc ≥ 0.5, to avoid cancellation near the far plane.
// NaN and ±Inf (degenerate geometry, a host's bad data) become 1.0 — "no occluder"; the kernel
// counts them (`DepthTexel.finite`) so the caller can report them instead of spreading them
// through filters.

// Keep in sync with `LinearizeParams` in src/wgsl_mirrors.rs.
struct DepthParams {
    perspective: u32,
    near: f32,
    far: f32,
    _pad: u32,
}

// WGSL lets implementations assume finite floats, so test the exponent bits instead.
fn depth_is_finite(raw: f32) -> bool {
    return (bitcast<u32>(raw) & 0x7f800000u) != 0x7f800000u;
}

// The linear depth of one depth-buffer value (1.0 where it is not finite). Selects, not
// branches: llvmpipe runs both sides of a branch under masks anyway, and the branches took 2%
// more of the fused VSM blur's instructions there (benches/instructions.sh); a GPU pays one
// division more for an orthographic map.
fn linear_depth(raw: f32, p: DepthParams) -> f32 {
    let d = clamp(raw, 0.0, 1.0);
    let z = select(d, p.near * d / (p.far * (1.0 - d) + p.near * d), p.perspective == 1u);
    return select(1.0, clamp(z, 0.0, 1.0), depth_is_finite(raw));
}

// One texel of a depth buffer, linearized.
struct DepthTexel {
    z: f32,
    // false where the raw value was NaN or ±Inf (and `z` is 1.0): the caller counts it.
    finite: bool,
}

// Texel `p` of the depth buffer `src`, linearized with `p`.
fn load_linear_depth(src: texture_2d<f32>, at: vec2<u32>, p: DepthParams) -> DepthTexel {
    let raw = textureLoad(src, at, 0).r;
    return DepthTexel(linear_depth(raw, p), depth_is_finite(raw));
}
