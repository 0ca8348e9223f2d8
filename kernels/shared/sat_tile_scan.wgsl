// The table of one tile with its carries (import-only module of `sat_tiles` and
// `sat_tiles_f32`, and of the layered `csm_sat_tiles*`, pass 3 of 3); the carries of the
// source's band (`SatSource.band`). A table texel (x, y) of tile (tx, ty) is the sum of three
// disjoint parts of [0, x] × [0, y]:
//   the tile's own inclusive table at (x, y)                       (registers + workgroup),
//   col_carry(x, ty): columns tx·TILE ..= x, every row above the tile      (pass 2),
//   row_carry(tx, y): every column left of the tile, every row up to y     (pass 2).
// The tile's table: each invocation sweeps its sub-block row by row (each row prefixed along
// it, added to running column sums); a texel adds the sums left of its sub-block on its row
// (prefix of the sub-blocks' last columns) and above it on its column (prefix of their last
// rows, each with the sub-row's totals left of the sub-block). The representation is read
// once more here (swept twice, the second time from cache) and the table written once: two
// reads and one write per texel over the three passes.
// #import shared/sat_tile
// #import shared/sat_tile_texel
// The importing kernel declares `src` (shared/sat_tile_texel):
// #completed-by-importer

// Row y: at [y · (GRID − 1) + a − 1], the sum of row y over sub-blocks a' < a (a ≥ 1).
var<workgroup> sh_right: array<vec4<u32>, 448>; // TILE · (GRID − 1)
// Column x: at [x · (GRID − 1) + b − 1], the sum of column x over sub-block rows b' < b with
// everything left of x in those rows of the tile.
var<workgroup> sh_bottom: array<vec4<u32>, 448>;
const SIDE: u32 = 7u; // GRID − 1

// Row j of the sub-block at `origin`: its encoded texels prefixed along the row, added to the
// running column sums `col`, which then hold row j of the sub-block's own inclusive table.
fn sat_sweep_row(
    origin: vec2<u32>,
    j: u32,
    p: SatParams,
    fs: bool,
    s: SatSource,
    col: ptr<function, array<vec4<u32>, SUB>>,
) {
    let size = textureDimensions(src);
    var run = vec4<u32>(0u);
    for (var i = 0u; i < SUB; i++) {
        run = sat_sum(run, sat_texel(origin + vec2<u32>(i, j), size, p, fs, s), fs);
        (*col)[i] = sat_sum((*col)[i], run, fs);
    }
}

// Everything invocation li of tile `tile` adds to its sub-block's own table besides the row
// terms of `sat_row_add`: per column i of the sub-block, into `col_add`, the column carry and
// the tile's sums above the sub-block up to that column. Sweeps the sub-block once
// for its edges. Every invocation calls it (it has barriers).
fn sat_tile_prepare(
    col_carry: texture_2d<u32>,
    p: SatParams,
    fs: bool,
    s: SatSource,
    tile: vec2<u32>,
    li: u32,
    col_add: ptr<function, array<vec4<u32>, SUB>>,
) {
    let a = li % GRID;
    let b = li / GRID;
    let size = textureDimensions(src);
    let origin = sat_sub_origin(tile, li);
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        sat_sweep_row(origin, j, p, fs, s, &col);
        if a < SIDE {
            sh_right[(b * SUB + j) * SIDE + a] = col[SUB - 1u];
        }
    }
    if b < SIDE {
        for (var i = 0u; i < SUB; i++) {
            sh_bottom[(a * SUB + i) * SIDE + b] = col[i];
        }
    }
    workgroupBarrier();
    // Row li: the inclusive prefix of its entries is the exclusive prefix of sub-blocks 1 ..
    // GRID − 1.
    var left = sh_right[li * SIDE];
    for (var k = 1u; k < SIDE; k++) {
        left = sat_sum(left, sh_right[li * SIDE + k], fs);
        sh_right[li * SIDE + k] = left;
    }
    workgroupBarrier();
    // Column li: each sub-block row's last-row sums plus that sub-row's totals left of the
    // column's sub-block (row k·SUB + SUB − 1 of sh_right), prefixed.
    let column_block = li / SUB;
    var run = vec4<u32>(0u);
    for (var k = 0u; k < SIDE; k++) {
        var e = sh_bottom[li * SIDE + k];
        if column_block > 0u {
            e = sat_sum(e, sh_right[(k * SUB + SUB - 1u) * SIDE + column_block - 1u], fs);
        }
        run = select(sat_sum(run, e, fs), e, k == 0u);
        sh_bottom[li * SIDE + k] = run;
    }
    workgroupBarrier();
    for (var i = 0u; i < SUB; i++) {
        let x = min(origin.x + i, size.x - 1u);
        (*col_add)[i] = textureLoad(col_carry, vec2<u32>(x, s.band.y + tile.y), 0);
        if b > 0u {
            (*col_add)[i] = sat_sum((*col_add)[i], sh_bottom[(a * SUB + i) * SIDE + b - 1u], fs);
        }
    }
}

// The row terms of texel row j of invocation li's sub-block: the row carry and the tile's sums
// left of the sub-block on that row (after `sat_tile_prepare`).
fn sat_row_add(
    row_carry: texture_2d<u32>,
    fs: bool,
    s: SatSource,
    tile: vec2<u32>,
    li: u32,
    j: u32,
) -> vec4<u32> {
    let a = li % GRID;
    let b = li / GRID;
    let y = min(sat_sub_origin(tile, li).y + j, textureDimensions(row_carry).y - 1u);
    var add = textureLoad(row_carry, vec2<u32>(s.band.x + tile.x, y), 0);
    if a > 0u {
        add = sat_sum(add, sh_right[(b * SUB + j) * SIDE + a - 1u], fs);
    }
    return add;
}
