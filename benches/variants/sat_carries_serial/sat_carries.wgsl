// BENCHMARK VARIANT (benches/variants/sat_carries_serial, run by benches/gpu_check.sh through
// `shadowgraph bench --kernel-dirs`; not shipped): the carries kernel as it was before its
// loads ran BATCH ahead of its sums (commit 31b7881's), each line's edge texels loaded one at a
// time as its serial sum reaches them. The same carries bit for bit (tests/kernel_dir.rs).
// Summed-area table, pass 2 of 3: the carries between tiles, serially along each line
// (⌈side / TILE⌉ tiles; nothing waits on another workgroup). Workgroup row 0 (Dispatch::Lines)
// gives each column x an invocation:
//   col_carry(x, ty) = Σ_{ty' < ty} col_part(x, ty')
//                    = the map above tile row ty, over the tile's columns up to x;
// workgroup row 1 gives each row y an invocation, the workgroup ROWS = WG_SIZE / TILE tile
// rows:
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
// once. Not counted: the row workgroups' re-reads of the tiles' totals above them (a
// workgroup reads at most tiles_x · tiles_y, all of them tiles_x · tiles_y² / (2 · ROWS)
// texels: at 8192² 1/16 of the map's texels, from cache; a GPU spreads them over 64 lanes a
// workgroup and 128 workgroups).
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
// src/sat/mod.rs. A row workgroup covers ROWS whole tile rows (WG_SIZE = 2 · TILE).
const ROWS: u32 = 2u; // WG_SIZE / TILE

// V of up to CHUNK tiles at a time (a 8192-texel row has 256 tiles), for each of the
// workgroup's tile rows: at [r · CHUNK + k], tile first + k for tile row ROWS · wg.x + r.
const CHUNK: u32 = 256u;
var<workgroup> sh_above: array<vec4<u32>, 512>; // ROWS · CHUNK

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

// Rows of tile rows ROWS·g .. ROWS·g + ROWS − 1, invocation li on row g·WG_SIZE + li. Every
// invocation of the workgroup calls it (it has barriers).
fn row_carries(g: u32, layer: u32, li: u32, fs: bool) {
    let tiles = band_tiles(textureDimensions(row_part).x);
    let first_col = layer * tiles;
    let first_row = layer * band_tiles(textureDimensions(col_part).y);
    let height = textureDimensions(row_part).y;
    let width = textureDimensions(col_part).x;
    let ty = g * ROWS;
    if ty * TILE >= height {
        return; // a workgroup past the map's rows (workgroup-uniform: no barrier is skipped)
    }
    let y = g * WG_SIZE + li;
    let own = (li / TILE) * CHUNK;
    var carry = vec4<u32>(0u);
    for (var first = 0u; first < tiles; first += CHUNK) {
        for (var k = li; k < CHUNK && first + k < tiles; k += WG_SIZE) {
            let last = min((first + k) * TILE + TILE - 1u, width - 1u);
            var above = vec4<u32>(0u);
            for (var t = 0u; t < ty; t++) {
                above = sat_sum(above, textureLoad(col_part, vec2<u32>(last, first_row + t), 0), fs);
            }
            sh_above[k] = above;
            // The next tile rows' V adds the tile above them (only those holding map rows).
            for (var r = 1u; r < ROWS && (ty + r) * TILE < height; r++) {
                let total = textureLoad(col_part, vec2<u32>(last, first_row + ty + r - 1u), 0);
                above = sat_sum(above, total, fs);
                sh_above[r * CHUNK + k] = above;
            }
        }
        workgroupBarrier();
        if y < height {
            for (var k = 0u; k < CHUNK && first + k < tiles; k++) {
                let p = vec2<u32>(first_col + first + k, y);
                let part = sat_sum(textureLoad(row_part, p, 0), sh_above[own + k], fs);
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
