// EVSM's moments (`shared/evsm_moments`: two or four channels, as the table's) summed into a
// table computed from the depth, pass 3 of 3, f32 variant (shared/moment_sat_tiles_f32).
// #import shared/moment_sat_tiles_f32
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth (clamped
// at the map's edge; the second sweep hits its cache), TILE carries of either kind, and writes
// its tile of the table.
// #traffic src: TILE * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst0: all

const SAT_KIND: u32 = SAT_EVSM;
