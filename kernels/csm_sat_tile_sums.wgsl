// Layered summed-area tables of the CSM / CSM-Z basis, pass 1 of 3, fixed-point variant
// (src/sat/layers.rs): workgroup z computes layer z's basis map from the depth on the fly
// (`SatSource`, shared/sat_tile) and writes the edges of each tile's own table, as
// `sat_tile_sums` does for a stored map, into band z of the stacked edges (col_part:
// ⌈height / TILE⌉ rows a band; row_part: ⌈width / TILE⌉ columns). Layer 0's workgroups count
// the non-finite depth texels. The depth is read once a layer (4 B), the basis never written.
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

const FLOAT_SUMS: bool = false;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let layer = params.first_map + wg.z;
    let source = csm_sat_source(params, layer, csm_sat_tiles_of(textureDimensions(src)));
    sat_tile_sums_pass(params.sat, FLOAT_SUMS, source, wg.xy, li);
    if layer == 0u && sat_non_finite > 0u {
        atomicAdd(&stats[0], sat_non_finite);
    }
}
