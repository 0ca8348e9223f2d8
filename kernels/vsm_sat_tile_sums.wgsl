// VSM's moments (each texel's derivatives from its four neighbours' depth, a 4 × 4 sub-block at a
// time: `sat_block_fill`) summed into a table computed from the depth, pass 1 of 3, fixed-point
// variant (shared/moment_sat_sums).
// #import shared/moment_sat_sums
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth and a
// one-texel cross-shaped halo for the derivatives, as `vsm` (clamped at the map's edge) and
// writes its edges.
// #traffic src: TILE * TILE + 4 * TILE per group
// #traffic col_part: all
// #traffic row_part: all
// #traffic stats: none

const SAT_KIND: u32 = SAT_VSM;
const FLOAT_SUMS: bool = false;
