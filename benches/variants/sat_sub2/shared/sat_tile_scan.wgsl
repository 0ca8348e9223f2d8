// BENCHMARK VARIANT (benches/variants/sat_sub2, run by benches/gpu_check.sh through
// `shadowgraph bench --kernel-dirs`; not shipped): the summed-area tables' tile passes with
// 2 × 2 sub-blocks, 16 × 16 = 256 invocations a 32² tile (the shipped: 4 × 4, 64), so that a
// SIMD group's loads fall 2 texels apart instead of 4 (16 sectors an instruction for 8-byte
// texels instead of 32) and a tile has four times the invocations; the per-line steps run on
// the first LINES = 2 · TILE of them. Fixed-point tables come out bit for bit the same
// (integer sums in any order; tests/kernel_dir.rs); f32 tables may differ in their last bits.
// The table of one tile with its carries (import-only module of `sat_tiles` and
// `sat_tiles_f32`, and of the depth-sourced `csm_sat_tiles*`, `msm_sat_tiles*` and
// `vsm_sat_tiles*`, pass 3 of 3); the carries of the source's band (`SatSource.band`). A table
// texel (x, y) of tile (tx, ty) is the sum of three disjoint parts of [0, x] × [0, y]:
//   the tile's own inclusive table at (x, y)                       (registers + workgroup),
//   col_carry(x, ty): columns tx·TILE ..= x, every row above the tile      (pass 2),
//   row_carry(tx, y): every column left of the tile, every row up to y     (pass 2).
// The tile's table: each invocation sweeps its sub-block row by row (each row prefixed along
// it, added to running column sums); a texel adds the sums left of its sub-block on its row
// (prefix of the sub-blocks' last columns) and above it on its column (prefix of their last
// rows, each with the sub-row's totals left of the sub-block). The representation is read
// once more here (swept twice: the second time from cache on a GPU, from the first sweep's
// encoded texels, `sat_enc`, on a CPU driver) and the table written once: two
// reads and one write per texel over the three passes.
// #import shared/sat_tile
// #import shared/sat_tile_texel
// The importing kernel declares `src` (shared/sat_tile_texel), the carries it reads,
// `col_carry` and `row_carry` (`texture_2d<u32>`), and `fn sat_store(slot: u32, q: vec2<u32>,
// v: vec4<u32>)`, which writes table texel q (`slot`: which of its tables, where it has several):
// #completed-by-importer

// Row y: at [y · (GRID − 1) + a − 1], the sum of row y over sub-blocks a' < a (a ≥ 1).
var<workgroup> sh_right: array<vec4<u32>, 480>; // TILE · (GRID − 1)
// Column x: at [x · (GRID − 1) + b − 1], the sum of column x over sub-block rows b' < b, each
// sub-block's own table's last row (its columns up to x); the sub-blocks wholly left of the
// column's are added apart (`sat_tile_prepare`).
var<workgroup> sh_bottom: array<vec4<u32>, 480>;
const SIDE: u32 = 15u; // GRID − 1
// The tile's carries, one load an invocation (not one per texel row and column of every
// sub-block, eight times over): at [y] row y's row carry, at [TILE + x] column x's column
// carry.
var<workgroup> sh_carry: array<vec4<u32>, 64>; // LINES

// Without GPU_LAYOUT: the sub-block's encoded texels (row-major), kept from the pass's first
// sweep for its second, which then neither loads nor encodes (MSM's tables 1.1×, CSSM's
// 1.2× faster on llvmpipe, benches/RESULTS.md, 2026-11-27). Under it the
// second sweep loads and encodes again, from the texture cache: pass 3 7–13% faster on an
// H200 than with the kept texels, sixteen four-channel values more an invocation
// (2026-11-27).
var<private> sat_enc: array<vec4<u32>, 4>; // SUB · SUB

// Row j of the sub-block at `origin`: its encoded texels prefixed along the
// row, added to the running column sums `col`, which then hold row j of the sub-block's own
// inclusive table; `again`: the pass's second sweep.
fn sat_sweep_row(
    origin: vec2<u32>,
    j: u32,
    p: SatParams,
    fs: bool,
    s: SatSource,
    again: bool,
    col: ptr<function, array<vec4<u32>, SUB>>,
) {
    let size = textureDimensions(src);
    var run = vec4<u32>(0u);
    for (var i = 0u; i < SUB; i++) {
        var e: vec4<u32>;
        if GPU_LAYOUT {
            e = sat_texel(origin + vec2<u32>(i, j), j * SUB + i, size, p, fs, s);
        } else if again {
            e = sat_enc[j * SUB + i];
        } else {
            e = sat_texel(origin + vec2<u32>(i, j), j * SUB + i, size, p, fs, s);
            sat_enc[j * SUB + i] = e;
        }
        run = sat_sum(run, e, fs);
        (*col)[i] = sat_sum((*col)[i], run, fs);
    }
}

// Everything invocation li of tile `tile` adds to its sub-block's own table besides the row
// terms of `sat_row_add`: per column i of the sub-block, into `col_add`, the column carry and
// the tile's sums above the sub-block up to that column. Sweeps the sub-block once
// for its edges. Every invocation calls it (it has barriers).
fn sat_tile_prepare(
    col_carry: texture_2d<u32>,
    row_carry: texture_2d<u32>,
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
    // Invocation li's carry: row li (li < TILE), else column li − TILE, clamped to the map.
    let q = min(tile * TILE + li % TILE, size - 1u);
    if li < TILE {
        sh_carry[li] = textureLoad(row_carry, vec2<u32>(s.band.x + tile.x, q.y), 0);
    } else if li < LINES {
        sh_carry[li] = textureLoad(col_carry, vec2<u32>(q.x, s.band.y + tile.y), 0);
    }
    // A literal condition: only the VSM and ESM sources' kernels compile it (both sweeps read
    // the block).
    if sat_blocked(s) {
        sat_block_fill(origin, size, s);
    }
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        sat_sweep_row(origin, j, p, fs, s, false, &col);
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
    // Line li % TILE (li < LINES = 2 · TILE), each in entries only its invocation touches: row li
    // (li < TILE), whose inclusive prefix is the exclusive prefix of sub-blocks 1 .. GRID − 1;
    // column li − TILE, likewise down the sub-block rows.
    let line = li % TILE;
    if li < TILE {
        var left = sh_right[line * SIDE];
        for (var k = 1u; k < SIDE; k++) {
            left = sat_sum(left, sh_right[line * SIDE + k], fs);
            sh_right[line * SIDE + k] = left;
        }
    } else if li < LINES {
        var up = sh_bottom[line * SIDE];
        for (var k = 1u; k < SIDE; k++) {
            up = sat_sum(up, sh_bottom[line * SIDE + k], fs);
            sh_bottom[line * SIDE + k] = up;
        }
    }
    workgroupBarrier();
    // The sub-blocks above and to the left, whole: per sub-block row k < b, its totals left of
    // sub-block column a (row k·SUB + SUB − 1 of sh_right, prefixed). A separate sum, not a
    // term of the column prefixes, so rows and columns take one phase and two barriers.
    var corner = vec4<u32>(0u);
    for (var k = 0u; k < b; k++) {
        let e = sh_right[(k * SUB + SUB - 1u) * SIDE + max(a, 1u) - 1u];
        corner = sat_sum(corner, select(vec4<u32>(0u), e, a > 0u), fs);
    }
    for (var i = 0u; i < SUB; i++) {
        (*col_add)[i] = sh_carry[TILE + a * SUB + i];
        if b > 0u {
            let above = sat_sum(sh_bottom[(a * SUB + i) * SIDE + b - 1u], corner, fs);
            (*col_add)[i] = sat_sum((*col_add)[i], above, fs);
        }
    }
}

// The row terms of texel row j of invocation li's sub-block: the row carry and the tile's sums
// left of the sub-block on that row (after `sat_tile_prepare`).
fn sat_row_add(fs: bool, li: u32, j: u32) -> vec4<u32> {
    let a = li % GRID;
    let b = li / GRID;
    var add = sh_carry[b * SUB + j];
    if a > 0u {
        add = sat_sum(add, sh_right[(b * SUB + j) * SIDE + a - 1u], fs);
    }
    return add;
}

// Pass 3 for tile `tile`: its table with the carries of band `s.band`, every texel inside the
// map handed to the importer's `sat_store(slot, q, v)`. Every invocation calls it (it has
// barriers).
fn sat_tile_table(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32, slot: u32) {
    var col_add: array<vec4<u32>, SUB>;
    sat_tile_prepare(col_carry, row_carry, p, fs, s, tile, li, &col_add);
    let origin = sat_sub_origin(tile, li);
    let size = textureDimensions(src);
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        sat_sweep_row(origin, j, p, fs, s, true, &col);
        let row_add = sat_row_add(fs, li, j);
        for (var i = 0u; i < SUB; i++) {
            let q = origin + vec2<u32>(i, j);
            if all(q < size) {
                sat_store(slot, q, sat_sum(sat_sum(col[i], row_add, fs), col_add[i], fs));
            }
        }
    }
}
