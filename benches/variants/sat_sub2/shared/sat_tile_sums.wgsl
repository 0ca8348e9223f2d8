// BENCHMARK VARIANT (benches/variants/sat_sub2, run by benches/gpu_check.sh through
// `shadowgraph bench --kernel-dirs`; not shipped): the summed-area tables' tile passes with
// 2 × 2 sub-blocks, 16 × 16 = 256 invocations a 32² tile (the shipped: 4 × 4, 64), so that a
// SIMD group's loads fall 2 texels apart instead of 4 (16 sectors an instruction for 8-byte
// texels instead of 32) and a tile has four times the invocations; the per-line steps run on
// the first LINES = 2 · TILE of them. Fixed-point tables come out bit for bit the same
// (integer sums in any order; tests/kernel_dir.rs); f32 tables may differ in their last bits.
// The edges of one tile's own table (import-only module of `sat_tile_sums` and
// `sat_tile_sums_f32`, and of the depth-sourced `csm_sat_tile_sums*`, `msm_sat_tile_sums*` and
// `vsm_sat_tile_sums*`,
// pass 1 of 3): the tile's last row and last column, from one read of the tile. Each
// invocation sums its sub-block's rows and columns in registers; the edges across the tile
// come from those partial sums in workgroup memory, two barriers in all.
// #import shared/sat_tile
// #import shared/sat_tile_texel
// The importing kernel declares `src` (shared/sat_tile_texel) and the edges it writes,
// `col_part` and `row_part` (storage textures of u32 words):
// #completed-by-importer

// Row y's partial sums, one per sub-block column a, at [y · GRID + a]; column x's, one per
// sub-block row b, at [(TILE + x) · GRID + b]; then the line's sum at its first entry. Line li
// (invocation li's) is row li for li < TILE, column li − TILE after, for li < LINES = 2 · TILE.
var<workgroup> sh_lines: array<vec4<u32>, 1024>; // LINES · GRID

// Invocation li's entry of the edges of tile `tile` of `src` (read as `s`, coded with `p` in
// the variant `fs`): for li < TILE row li of the tile's last column, else column li − TILE of
// its last row. Every invocation calls it (it has barriers).
fn sat_tile_edges(
    p: SatParams,
    fs: bool,
    s: SatSource,
    tile: vec2<u32>,
    li: u32,
) -> vec4<u32> {
    let a = li % GRID;
    let b = li / GRID;
    let size = textureDimensions(src);
    let origin = sat_sub_origin(tile, li);
    // A literal condition: only the VSM and ESM sources' kernels compile it (the sweep reads
    // the block).
    if sat_blocked(s) {
        sat_block_fill(origin, size, s);
    }
    // Row sums prefixed down the sub-block (its table's last column), and column sums, then
    // prefixed along it (its last row).
    var down = vec4<u32>(0u);
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        var row = vec4<u32>(0u);
        for (var i = 0u; i < SUB; i++) {
            let e = sat_texel(origin + vec2<u32>(i, j), j * SUB + i, size, p, fs, s);
            row = sat_sum(row, e, fs);
            col[i] = sat_sum(col[i], e, fs);
        }
        down = sat_sum(down, row, fs);
        sh_lines[(b * SUB + j) * GRID + a] = down;
    }
    for (var i = 0u; i < SUB; i++) {
        if i > 0u {
            col[i] = sat_sum(col[i - 1u], col[i], fs);
        }
        sh_lines[(TILE + a * SUB + i) * GRID + b] = col[i];
    }
    workgroupBarrier();
    // Line li summed across the sub-blocks (the first LINES invocations, a line each).
    var e = vec4<u32>(0u);
    if li < LINES {
        e = sh_lines[li * GRID];
        for (var k = 1u; k < GRID; k++) {
            e = sat_sum(e, sh_lines[li * GRID + k], fs);
        }
        sh_lines[li * GRID] = e;
    }
    workgroupBarrier();
    // Plus the whole sub-block rows above (columns to the left): their last lines' sums.
    if li < LINES {
        let first = li - li % TILE;
        for (var k = 0u; k < (li % TILE) / SUB; k++) {
            e = sat_sum(e, sh_lines[(first + k * SUB + SUB - 1u) * GRID], fs);
        }
    }
    return e;
}

// Pass 1 for tile `tile`: its edges (`sat_tile_edges`) stored into band `s.band` of the
// importer's `row_part` (invocations li < TILE, one row each) and `col_part` (the rest, one
// column each), inside the map. Every invocation calls it.
fn sat_tile_sums_pass(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32) {
    let e = sat_tile_edges(p, fs, s, tile, li);
    let size = textureDimensions(src);
    let q = tile * TILE + li % TILE;
    if li < TILE {
        if q.y < size.y {
            textureStore(row_part, vec2<u32>(s.band.x + tile.x, q.y), e);
        }
    } else if li < LINES && q.x < size.x {
        textureStore(col_part, vec2<u32>(q.x, s.band.y + tile.y), e);
    }
}
