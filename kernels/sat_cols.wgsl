// Summed-area table, pass 5 of 5, fixed-point variant: scan each column in blocks of BLOCK rows
// with the row and column carries added (shared/sat_scan's `sat_column`), one workgroup per
// block, and store the inclusive SAT as wrapping u32 fixed point. Window sums taken from it with
// wrapping subtraction are exact (see src/sat.rs for the scale).
// #import shared/sat_scan

// Traffic (the cost model, src/graph/cost): reads the row scans again (the table's second read),
// each texel's row carry and one column carry per block, and writes the table.
// #traffic src: all
// #traffic row_carry: 1 per texel of src
// #traffic col_carry: 1 per group
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var row_carry: texture_2d<u32>;
@group(0) @binding(2) var col_carry: texture_2d<u32>;
@group(0) @binding(3) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: SatParams;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let x = wg.x;
    let height = textureDimensions(src).y;
    let sat = sat_column(src, row_carry, col_carry, params, li, wg.y, x);
    for (var k = 0u; k < ITEMS; k++) {
        let y = sat_column_row(wg.y, li, k);
        if y < height {
            textureStore(dst, vec2<u32>(x, y), sat[k]);
        }
    }
}
