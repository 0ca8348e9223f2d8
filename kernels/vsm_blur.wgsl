// Rasterized depth → variance-shadow-map moments (shared/vsm_moments), blurred, in one pass:
// the encoding fused into the separable blur (shared/encode_blur, shared/vsm_blur_kernel). With
// a radius past TILE_RADIUS it is the first of two passes (encode and blur along x; `blur`
// along y) on maps narrower than 1024 texels, `vsm_blur_row` on wider ones.

// #import shared/vsm_blur_kernel

// Traffic (the cost model, src/graph/cost): a tile workgroup loads its TILE² depths with a halo
// of r + 1 each side, a row workgroup three rows of its outputs (ROW, the last of a row the rest) + 2r + 2; each output is stored once.
// #traffic src: select(3 * (dst.width / ceil(dst.width / ROW) + 2 * min(params.blur.radius, MAX_RADIUS) + 2), (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2) * (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2), params.blur.axis == 2) per group
// #traffic dst: all
// #traffic stats: none

// Outputs of a one-row workgroup and the run an invocation sums there (shared/encode_blur):
// the row pass of maps narrower than `vsm_blur_row`'s 1024-texel rows (which would leave half
// its invocations idle). Keep in
// sync with `encode_blur_row` in src/filter/encode_blur.rs.
const ROW: u32 = 512u;
const ROW_RUN: u32 = 2u;
