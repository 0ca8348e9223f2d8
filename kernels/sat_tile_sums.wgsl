// Summed-area table, pass 1 of 3, fixed-point variant: for every TILE × TILE tile of the
// representation (coded as in shared/sat_params), the last row and the last column of the tile's
// own inclusive table (shared/sat_tile_sums):
//   col_part(x, ty) = Σ of the tile's rows over columns tx·TILE ..= x,
//   row_part(tx, y) = Σ of the tile's columns over rows ty·TILE ..= y.
// The representation is read once; these two edges (2/TILE of the map) are all it writes.
// Storage: rgba32uint by default; the executor re-declares them for the table's channels.
// #import shared/sat_tile_sums
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile (clamped at the map's
// edge) and writes its edges.
// #traffic src: TILE * TILE per group
// #traffic col_part: all
// #traffic row_part: all

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var row_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: SatParams;

const FLOAT_SUMS: bool = false;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_sums_pass(params, FLOAT_SUMS, SAT_STORED, wg.xy, li);
}
