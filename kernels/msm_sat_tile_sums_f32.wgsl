// MSM's quantized moments (as `msm` computes them) summed into a table computed from the depth,
// pass 1 of 3, f32 variant (shared/moment_sat_sums).
// #import shared/moment_sat_sums
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth (clamped
// at the map's edge) and writes its edges.
// #traffic src: TILE * TILE per group
// #traffic col_part: all
// #traffic row_part: all
// #traffic stats: none

const SAT_KIND: u32 = SAT_MSM;
const FLOAT_SUMS: bool = true;
