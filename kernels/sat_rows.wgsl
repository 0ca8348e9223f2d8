// Summed-area table, pass 1 of 5: encode the representation (fixed point or f32, see
// shared/sat_scan) and scan each row in blocks of BLOCK texels, one workgroup per block.
// `dst` gets every block's local inclusive prefix, `sums` the block's total (one texel per
// block: ⌈width / BLOCK⌉ × height). Blocks never wait for each other: the carries between them
// are added by later dispatches (sat_carry, then sat_cols_reduce and sat_cols).
// #import shared/sat_scan

// Traffic (the cost model, src/graph/cost): one read of the representation, one write of the block
// scans and of the block totals.
// #traffic src: all
// #traffic dst: all
// #traffic sums: all
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var sums: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: SatParams;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let width = textureDimensions(src).x;
    let y = wg.y;
    let first = wg.x * BLOCK + li * ITEMS;
    var v: array<vec4<u32>, ITEMS>;
    for (var k = 0u; k < ITEMS; k++) {
        if first + k < width {
            v[k] = sat_encode(textureLoad(src, vec2<u32>(first + k, y), 0), params);
        }
    }
    let scanned = sat_scan_block(li, v, params.float_sums != 0u);
    for (var k = 0u; k < ITEMS; k++) {
        if first + k < width {
            textureStore(dst, vec2<u32>(first + k, y), scanned[k]);
        }
    }
    if li == 0u {
        textureStore(sums, vec2<u32>(wg.x, y), sh_total);
    }
}
