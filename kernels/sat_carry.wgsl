// Summed-area table, passes 2 and 4 of 5: the exclusive prefix of the block totals along
// each line (`params.axis` 0: rows of the row-block totals; 1: columns of the column-block
// totals): the carry each block of the line must add. One workgroup per line walks it in
// chunks of WG_SIZE with a running carry, so any line length works; maps up to 65536 texels
// have at most 256 blocks a line, one chunk. Dispatched as one group per chunk along the line,
// of which only the first works (the others return at once).
// #import shared/sat_scan

@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var<uniform> params: SatParams;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if wg.x != 0u {
        return;
    }
    let fs = params.float_sums != 0u;
    let size = textureDimensions(src);
    let along = select(size.x, size.y, params.axis == 1u);
    var carry = vec4<u32>(0u);
    for (var start = 0u; start < along; start += WG_SIZE) {
        let a = start + li;
        let p = sat_texel(a, wg.y, params.axis);
        var v = vec4<u32>(0u);
        if a < along {
            v = textureLoad(src, p, 0);
        }
        let before = sat_scan_exclusive(li, v, fs);
        if a < along {
            textureStore(dst, p, sat_add(carry, before, fs));
        }
        carry = sat_add(carry, sh_total, fs);
    }
}
