// Summed-area table, pass 3 of 5: the total of each block of BLOCK rows of each column of the
// full row prefix R(x, y) = rows(x, y) + row_carry(x / BLOCK, y), one workgroup and one texel
// per block: width × ⌈height / BLOCK⌉. Only the up-sweep half of the scan tree is needed.
// #import shared/sat_scan

// Traffic (the cost model, src/graph/cost): reads the row scans (their first read) and, for each
// texel, its row block's carry.
// #traffic src: all
// #traffic row_carry: 1 per texel of src
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var row_carry: texture_2d<u32>;
@group(0) @binding(2) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: SatParams;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = params.float_sums != 0u;
    let x = wg.x;
    let total = sat_reduce_block(li, sat_row_prefix(src, row_carry, fs, li, wg.y, x), fs);
    if li == 0u {
        textureStore(dst, vec2<u32>(x, wg.y), total);
    }
}
