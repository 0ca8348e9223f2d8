// Layered summed-area tables of the CSM / CSM-Z basis, pass 3 of 3, f32 variant
// (src/sat/layers.rs): workgroup z computes layer first_map + z's basis map from the depth on
// the fly again (`SatSource`, shared/sat_tile), scans its tile as `sat_tiles` does, adds the
// carries of its band (pass 2, `sat_carries` over the stacked edges) and stores the table where
// csm_sat_texel puts it: in dst<⌊z / n⌋>, n tables a texture interleaved along x (n = 1: dst<z>);
// up to four textures a dispatch (WebGPU's default limit of storage textures a stage).
// The executor re-declares each `dst<j>` for its bound format and binds the unused ones to
// the last bound one (they are not stored to).
// #import shared/sat_tile_scan
// #import shared/csm_sat_params
// Traffic (the cost model, src/graph/cost): each workgroup loads its tile of the depth
// (clamped at the map's edge; the second sweep hits its cache), TILE carries of either kind,
// and writes its tile of its table.
// #traffic src: TILE * TILE per group
// #traffic col_carry: TILE per group
// #traffic row_carry: TILE per group
// #traffic dst0: all
// #traffic dst1: all
// #traffic dst2: all
// #traffic dst3: all

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_carry: texture_2d<u32>;
@group(0) @binding(2) var row_carry: texture_2d<u32>;
@group(0) @binding(3) var dst0: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var dst1: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var dst2: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var dst3: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var<uniform> params: CsmSatParams;

const FLOAT_SUMS: bool = true;

// Texel q of table `slot` of this dispatch (shared/sat_tile_scan), where csm_sat_texel puts it.
fn sat_store(slot: u32, q: vec2<u32>, v: vec4<u32>) {
    let t = csm_sat_texel(params, slot, q);
    switch t.z {
        case 0u: {
            textureStore(dst0, t.xy, bitcast<vec4<f32>>(v));
        }
        case 1u: {
            textureStore(dst1, t.xy, bitcast<vec4<f32>>(v));
        }
        case 2u: {
            textureStore(dst2, t.xy, bitcast<vec4<f32>>(v));
        }
        default: {
            textureStore(dst3, t.xy, bitcast<vec4<f32>>(v));
        }
    }
}

// Workgroup `wg` computes layer first_map + z of tile (x, y), (x, y, z) = csm_sat_pass3_at(wg).
@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let at = csm_sat_pass3_at(params, wg);
    let tiles = csm_sat_tiles_of(textureDimensions(src));
    let source = csm_sat_source(params, params.first_map + at.z, tiles);
    sat_tile_table(params.sat, FLOAT_SUMS, source, at.xy, li, at.z);
}
