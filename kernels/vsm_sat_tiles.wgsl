// VSM's moments summed into a table computed from the depth, pass 3 of 3, fixed-point variant
// (src/sat/layers.rs, technique::add_moment_table: one layer, two channels): each workgroup
// computes its tile of VSM's moments from the depth again (`moment_sat_source`, shared/sat_tile),
// scans it as `sat_tiles` does, adds the carries (pass 2, `sat_carries`) and stores the table.
// The executor re-declares `dst0` for the table's two channels.
// #import shared/sat_tile_scan
// #import shared/csm_sat_params
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth and a
// one-texel cross-shaped halo, as `vsm` (clamped at the map's edge; the second sweep hits its
// cache), TILE carries of either kind, and writes its tile of the table.
// #traffic src: TILE * TILE + 4 * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst0: all

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_carry: texture_2d<u32>;
@group(0) @binding(2) var row_carry: texture_2d<u32>;
@group(0) @binding(3) var dst0: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: CsmSatParams;

const FLOAT_SUMS: bool = false;

// Table texel q (shared/sat_tile_scan; one table, `slot` unused).
fn sat_store(slot: u32, q: vec2<u32>, v: vec4<u32>) {
    textureStore(dst0, q, v);
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_table(params.sat, FLOAT_SUMS, moment_sat_source(params, SAT_VSM), wg.xy, li, 0u);
}
