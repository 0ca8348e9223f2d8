// MSM's moments summed into a table computed from the depth, pass 3 of 3, f32 variant
// (src/sat/layers.rs, technique::add_msm_table: one layer): each workgroup computes its tile
// of MSM's quantized moments from the depth again (`msm_sat_source`, shared/sat_tile), scans
// it as `sat_tiles` does, adds the carries (pass 2, `sat_carries`) and stores the table.
// #import shared/sat_tile_scan
// #import shared/csm_sat_params
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth
// (clamped at the map's edge; the second sweep hits its cache), TILE carries of either kind,
// and writes its tile of the table.
// #traffic src: TILE * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst0: all

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_carry: texture_2d<u32>;
@group(0) @binding(2) var row_carry: texture_2d<u32>;
@group(0) @binding(3) var dst0: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var<uniform> params: CsmSatParams;

const FLOAT_SUMS: bool = true;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = FLOAT_SUMS;
    let size = textureDimensions(src);
    let source = msm_sat_source(params);
    var col_add: array<vec4<u32>, SUB>;
    sat_tile_prepare(col_carry, row_carry, params.sat, fs, source, wg.xy, li, &col_add);
    let origin = sat_sub_origin(wg.xy, li);
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        sat_sweep_row(origin, j, params.sat, fs, source, &col);
        let row_add = sat_row_add(fs, li, j);
        for (var i = 0u; i < SUB; i++) {
            let q = origin + vec2<u32>(i, j);
            let sum = sat_sum(sat_sum(col[i], row_add, fs), col_add[i], fs);
            if all(q < size) {
                textureStore(dst0, q, bitcast<vec4<f32>>(sum));
            }
        }
    }
}
