// Summed-area table, pass 1 of 5: encode the representation (fixed point or f32, see
// shared/sat_scan) and scan each row in blocks of WG_SIZE texels. `dst` gets every block's
// local inclusive prefix, `sums` the block's total (one texel per block: ceil(width / WG_SIZE)
// × height). Blocks never wait for each other: the carries between them are added by later
// dispatches (sat_carry, then sat_cols_reduce and sat_cols).
// #import shared/sat_scan

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var sums: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: SatParams;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = params.float_sums != 0u;
    let x = wg.x * WG_SIZE + li;
    let y = wg.y;
    let inside = x < textureDimensions(src).x;
    var v = vec4<u32>(0u);
    if inside {
        v = sat_encode(textureLoad(src, vec2<u32>(x, y), 0), params);
    }
    let before = sat_scan_exclusive(li, v, fs);
    if inside {
        textureStore(dst, vec2<u32>(x, y), sat_add(before, v, fs));
    }
    if li == 0u {
        textureStore(sums, vec2<u32>(wg.x, y), sh_total);
    }
}
