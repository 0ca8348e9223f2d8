// Rasterized depth → four moments (shared/msm_moments, quantized for 16-bit storage), blurred,
// in one pass: the encoding fused into the separable blur (shared/encode_blur). With a radius
// past TILE_RADIUS it is the first of two passes (encode and blur along x; `blur` along y).
// On maps at least 512 wide the row pass is `msm_blur_row`'s.

// #import shared/msm_blur_kernel

// Traffic (the cost model, src/graph/cost): a tile workgroup loads its TILE² depths with a halo
// of r + 1 each side, a row workgroup three rows of its outputs (ROW, the last of a row the rest) + 2r + 2; each output is stored once.
// #traffic src: select(3 * (dst.width / ceil(dst.width / ROW) + 2 * min(params.blur.radius, MAX_RADIUS) + 2), (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2) * (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2), params.blur.axis == 2) per group
// #traffic dst: all
// #traffic stats: none

// The row path's shape (shared/encode_blur): 256 outputs a workgroup, one an invocation, on
// maps narrower than `msm_blur_row`'s 512-texel rows. Keep in sync with `encode_blur_row` in
// src/filter/encode_blur.rs.
const ROW: u32 = 256u;
const ROW_RUN: u32 = 1u;
