// VSM's moments (each texel's derivatives from its four neighbours' depth, a 4 × 4 sub-block at a
// time: `sat_block_fill`) summed into a table computed from the depth, pass 3 of 3, fixed-point
// variant (shared/moment_sat_tiles).
// #import shared/moment_sat_tiles
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth and a
// one-texel cross-shaped halo for the derivatives, as `vsm` (clamped at the map's edge; the
// second sweep hits its cache), TILE carries of either kind, and writes its tile of the table.
// #traffic src: TILE * TILE + 4 * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst0: all

const SAT_KIND: u32 = SAT_VSM;
