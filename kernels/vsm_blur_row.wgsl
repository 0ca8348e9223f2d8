// Rasterized depth → variance-shadow-map moments blurred along x, the first of two passes past
// the tile's TILE_RADIUS (then `blur` along y): 1024 outputs a workgroup in runs of 4, every
// invocation busy. A kernel of its own: `vsm_blur`'s one-row fallback has 512 outputs a
// workgroup in runs of 2, for maps narrower than 1024 texels.

// #import shared/vsm_blur_kernel

// Traffic (the cost model, src/graph/cost): a row workgroup loads three rows of its outputs (ROW, the
// last of a row the rest) + 2r + 2 depths; each output is stored once.
// #traffic src: select(3 * (dst.width / ceil(dst.width / ROW) + 2 * min(params.blur.radius, MAX_RADIUS) + 2), (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2) * (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2), params.blur.axis == 2) per group
// #traffic dst: all
// #traffic stats: none

// Outputs of a row workgroup and the run an invocation sums (shared/encode_blur). Keep in sync
// with `encode_blur_row` in src/filter/encode_blur.rs.
const ROW: u32 = 1024u;
const ROW_RUN: u32 = 4u;
