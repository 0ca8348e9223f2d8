// The first of two passes past the tile's TILE_RADIUS on maps at least 512 texels wide (then
// `blur` along y), msm_blur's encoding fused into the blur along x: 512 outputs a workgroup in
// runs of 2, every invocation busy. A kernel of its own: `msm_blur`'s one-row fallback has
// one output an invocation (256 a workgroup).

// #import shared/msm_blur_kernel

// Traffic (the cost model, src/graph/cost): a tile workgroup loads its TILE² depths with a halo
// of r + 1 each side, a row workgroup three rows of its outputs (ROW, the last of a row the rest) + 2r + 2; each output is stored once.
// #traffic src: select(3 * (dst.width / ceil(dst.width / ROW) + 2 * min(params.blur.radius, MAX_RADIUS) + 2), (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2) * (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2), params.blur.axis == 2) per group
// #traffic dst: all
// #traffic stats: none

// Outputs of a row workgroup and the run an invocation sums (shared/encode_blur). Keep in sync
// with `encode_blur_row` in src/filter/encode_blur.rs.
const ROW: u32 = 512u;
const ROW_RUN: u32 = 2u;
