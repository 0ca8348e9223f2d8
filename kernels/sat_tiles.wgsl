// Summed-area table, pass 3 of 3, fixed-point variant: stores the wrapping u32 sums (window
// sums taken from them with wrapping subtraction are exact; see src/sat/mod.rs for the scale).
// Each workgroup reads its tile of the representation again, sweeps it twice (the second
// time from cache) and adds the carries of pass 2 (shared/sat_tile_scan); the inclusive table
// is written once.
// Storage: rgba32uint by default; the executor re-declares `dst` for the table's channels.
// #import shared/sat_tile_scan
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile (clamped at the map's
// edge; the second sweep hits its cache), TILE carries of either kind, and writes the table.
// #traffic src: TILE * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst: all

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_carry: texture_2d<u32>;
@group(0) @binding(2) var row_carry: texture_2d<u32>;
@group(0) @binding(3) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: SatParams;

const FLOAT_SUMS: bool = false;

// Table texel q (shared/sat_tile_scan; one table, `slot` unused).
fn sat_store(slot: u32, q: vec2<u32>, v: vec4<u32>) {
    textureStore(dst, q, v);
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_table(params, FLOAT_SUMS, SAT_STORED, wg.xy, li, 0u);
}
