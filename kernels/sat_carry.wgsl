// Summed-area table, passes 2 and 4 of 5: the exclusive prefix of the block totals along
// each line (`params.axis` 0: rows of the row-block totals; 1: columns of the column-block
// totals), i.e. the carry each block of the line must add. One invocation per line scans it
// serially: a line has ⌈side / BLOCK⌉ totals (≤ 32 for a 32768-texel side), so this is the
// work-efficient choice (n − 1 adds, no barriers) and any length works.
// #import shared/sat_scan

// Traffic (the cost model, src/graph/cost): the block totals, read and written once.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var<uniform> params: SatParams;

// Keep in sync with `SAT_CARRY_LINES` in src/sat.rs: lines per workgroup.
const CARRY_WG_SIZE: u32 = 64u;

@compute @workgroup_size(CARRY_WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = params.float_sums != 0u;
    let size = textureDimensions(src);
    let cols = params.axis == 1u;
    let line = select(wg.y, wg.x, cols) * CARRY_WG_SIZE + li;
    if line >= select(size.y, size.x, cols) {
        return;
    }
    let along = select(size.x, size.y, cols);
    var carry = vec4<u32>(0u);
    for (var a = 0u; a < along; a++) {
        let p = sat_texel(a, line, params.axis);
        let total = textureLoad(src, p, 0);
        textureStore(dst, p, carry);
        carry = sat_add(carry, total, fs);
    }
}
