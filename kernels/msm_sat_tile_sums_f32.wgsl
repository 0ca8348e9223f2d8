// MSM's moments summed into a table computed from the depth, pass 1 of 3, f32 variant
// (src/sat/layers.rs, technique::add_moment_table: one layer): each workgroup computes its tile
// of MSM's quantized moments from the depth on the fly (`moment_sat_source`, shared/sat_tile),
// rounded as the map's storage would hold them, and writes the edges of its tile's own table,
// as `sat_tile_sums` does for a stored map. Counts the non-finite depth texels. The depth is
// read once (4 B), the moments never written.
// #import shared/sat_tile_sums
// #import shared/csm_sat_params
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth
// (clamped at the map's edge) and writes its edges.
// #traffic src: TILE * TILE per group
// #traffic col_part: all
// #traffic row_part: all
// #traffic stats: none

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var row_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: CsmSatParams;
@group(0) @binding(4) var<storage, read_write> stats: array<atomic<u32>>;

const FLOAT_SUMS: bool = true;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_sums_pass(params.sat, FLOAT_SUMS, moment_sat_source(params, SAT_MSM), wg.xy, li);
    if sat_non_finite > 0u {
        atomicAdd(&stats[0], sat_non_finite);
    }
}
