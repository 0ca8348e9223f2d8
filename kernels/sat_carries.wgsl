// Summed-area table, pass 2 of 3: the carries between tiles, serially along each line
// (⌈side / TILE⌉ tiles; nothing waits on another workgroup). Workgroup row 0 (Dispatch::Lines)
// gives each column x an invocation:
//   col_carry(x, ty) = Σ_{ty' < ty} col_part(x, ty')
//                    = the map above tile row ty, over the tile's columns up to x;
// workgroup row 1 gives each row y an invocation, the workgroup one tile row (WG_SIZE = TILE
// rows):
//   row_carry(tx, y) = Σ_{tx' < tx} (row_part(tx', y) + V(tx'))
//                    = the map left of tile column tx, over every row up to y (the table at
//                      the column before the tile),
// with V(tx') = Σ_{ty' < ty} total(tx', ty') the tiles above, from the tiles' totals (their
// last column of col_part), summed by the workgroup into workgroup memory first.
// Layered (params.layers = L > 1, src/sat/layers.rs): the edges of L tables are stacked, each
// table's col_part a band of ⌈height / TILE⌉ rows and its row_part a band of ⌈width / TILE⌉
// columns; workgroup z carries table z within its bands.
// #import shared/sat_tile
// Traffic (the cost model, src/graph/cost): every edge texel read once and every carry written
// once. Not counted: the row workgroups' re-reads of the tiles' totals above them (at most
// tiles_x · tiles_y / 2 texels, under 1/TILE² of the map's).
// #traffic col_part: all
// #traffic row_part: all
// #traffic col_carry: all
// #traffic row_carry: all

@group(0) @binding(0) var col_part: texture_2d<u32>;
@group(0) @binding(1) var row_part: texture_2d<u32>;
@group(0) @binding(2) var col_carry: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var row_carry: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: SatParams;

// WG_SIZE (shared/sat_tile) lines a workgroup: keep in sync with `SAT_LINES_PER_GROUP` in
// src/sat/mod.rs. A row workgroup covers one tile row because WG_SIZE = TILE.

// V of up to CHUNK tiles at a time (a 32768-texel row has 512 tiles).
const CHUNK: u32 = 512u;
var<workgroup> sh_above: array<vec4<u32>, CHUNK>;

// Tile rows of one table's band (the edges of `layers` tables stacked).
fn band_tiles(stacked: u32) -> u32 {
    return stacked / max(params.layers, 1u);
}

fn column_carries(x: u32, layer: u32, fs: bool) {
    let size = textureDimensions(col_part);
    if x >= size.x {
        return;
    }
    let tiles = band_tiles(size.y);
    var carry = vec4<u32>(0u);
    for (var t = layer * tiles; t < (layer + 1u) * tiles; t++) {
        let p = vec2<u32>(x, t);
        let part = textureLoad(col_part, p, 0);
        textureStore(col_carry, p, carry);
        carry = sat_sum(carry, part, fs);
    }
}

// Rows of tile row `ty`, invocation li on row ty·TILE + li. Every invocation of the workgroup
// calls it (it has barriers).
fn row_carries(ty: u32, layer: u32, li: u32, fs: bool) {
    let tiles = band_tiles(textureDimensions(row_part).x);
    let first_col = layer * tiles;
    let first_row = layer * band_tiles(textureDimensions(col_part).y);
    let height = textureDimensions(row_part).y;
    let width = textureDimensions(col_part).x;
    if ty * TILE >= height {
        return; // a workgroup past the map's rows (workgroup-uniform: no barrier is skipped)
    }
    let y = ty * TILE + li;
    var carry = vec4<u32>(0u);
    for (var first = 0u; first < tiles; first += CHUNK) {
        for (var k = li; k < CHUNK && first + k < tiles; k += WG_SIZE) {
            let last = min((first + k) * TILE + TILE - 1u, width - 1u);
            var above = vec4<u32>(0u);
            for (var t = 0u; t < ty; t++) {
                above = sat_sum(above, textureLoad(col_part, vec2<u32>(last, first_row + t), 0), fs);
            }
            sh_above[k] = above;
        }
        workgroupBarrier();
        if y < height {
            for (var k = 0u; k < CHUNK && first + k < tiles; k++) {
                let p = vec2<u32>(first_col + first + k, y);
                let part = sat_sum(textureLoad(row_part, p, 0), sh_above[k], fs);
                textureStore(row_carry, p, carry);
                carry = sat_sum(carry, part, fs);
            }
        }
        workgroupBarrier();
    }
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = params.float_sums != 0u;
    if wg.y == 0u {
        column_carries(wg.x * WG_SIZE + li, wg.z, fs);
    } else {
        row_carries(wg.x, wg.z, li, fs);
    }
}
