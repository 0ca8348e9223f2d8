// The edges of one tile's own table (import-only module of `sat_tile_sums` and
// `sat_tile_sums_f32`, and of the layered `csm_sat_tile_sums*`, pass 1 of 3): the tile's last row and last column, from one read of
// the tile. Each invocation sums its sub-block's rows and columns in registers; the edges
// across the tile come from those partial sums in workgroup memory, two barriers in all.
// #import shared/sat_tile
// #import shared/sat_tile_texel
// The importing kernel declares `src` (shared/sat_tile_texel):
// #completed-by-importer

// Row y's partial sums, one per sub-block column a, at [y · GRID + a]; then the row's sum in
// [y · GRID]. sh_bottom likewise per column x and sub-block row b.
var<workgroup> sh_right: array<vec4<u32>, 512>; // TILE · GRID
var<workgroup> sh_bottom: array<vec4<u32>, 512>;

// Row li and column li of tile `tile`'s last column and last row.
struct SatEdges {
    row: vec4<u32>,
    col: vec4<u32>,
}

// Invocation li's entries of the edges of tile `tile` of `src` (read as `s`, coded with `p`
// in the variant `fs`). Every invocation calls it (it has barriers).
fn sat_tile_edges(
    p: SatParams,
    fs: bool,
    s: SatSource,
    tile: vec2<u32>,
    li: u32,
) -> SatEdges {
    let a = li % GRID;
    let b = li / GRID;
    let size = textureDimensions(src);
    let origin = sat_sub_origin(tile, li);
    // Row sums prefixed down the sub-block (its table's last column), and column sums, then
    // prefixed along it (its last row).
    var down = vec4<u32>(0u);
    var col: array<vec4<u32>, SUB>;
    for (var j = 0u; j < SUB; j++) {
        var row = vec4<u32>(0u);
        for (var i = 0u; i < SUB; i++) {
            let e = sat_texel(origin + vec2<u32>(i, j), size, p, fs, s);
            row = sat_sum(row, e, fs);
            col[i] = sat_sum(col[i], e, fs);
        }
        down = sat_sum(down, row, fs);
        sh_right[(b * SUB + j) * GRID + a] = down;
    }
    for (var i = 0u; i < SUB; i++) {
        if i > 0u {
            col[i] = sat_sum(col[i - 1u], col[i], fs);
        }
        sh_bottom[(a * SUB + i) * GRID + b] = col[i];
    }
    workgroupBarrier();
    // Tile row li and tile column li, summed across the sub-blocks.
    var e: SatEdges;
    e.row = sh_right[li * GRID];
    e.col = sh_bottom[li * GRID];
    for (var k = 1u; k < GRID; k++) {
        e.row = sat_sum(e.row, sh_right[li * GRID + k], fs);
        e.col = sat_sum(e.col, sh_bottom[li * GRID + k], fs);
    }
    sh_right[li * GRID] = e.row;
    sh_bottom[li * GRID] = e.col;
    workgroupBarrier();
    // Plus the whole sub-block rows above (columns to the left): their last lines' sums.
    for (var k = 0u; k < li / SUB; k++) {
        e.row = sat_sum(e.row, sh_right[(k * SUB + SUB - 1u) * GRID], fs);
        e.col = sat_sum(e.col, sh_bottom[(k * SUB + SUB - 1u) * GRID], fs);
    }
    return e;
}
