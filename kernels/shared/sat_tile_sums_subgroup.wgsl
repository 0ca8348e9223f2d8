// The edges of one tile's own table by subgroup scans (import-only module): the redesign of
// shared/sat_tile_sums that `exec::KernelLayout::Redesign` compiles in its place on a device
// with wgpu's SUBGROUP feature (`exec::REDESIGNED_MODULES`), for every tile-sums kernel that
// imports it. The same edges (fixed point bit for bit) from one sweep of the tile by its
// columns (shared/sat_strip): the last column's lane stores the row edge of each row, the last
// row the column edges. The importing kernel declares `src` and `col_part`, `row_part`:
// #completed-by-importer
// #import shared/sat_strip

// Pass 1 adds nothing to a column.
fn sat_strip_column(tile: vec2<u32>, s: SatSource, x: u32, fs: bool) -> vec4<u32> {
    return vec4<u32>(0u);
}

// Texel q's own table value: the tile's last column into `row_part`, its last row into
// `col_part`, where they lie in the map.
fn sat_strip_emit(
    tile: vec2<u32>,
    s: SatSource,
    slot: u32,
    q: vec2<u32>,
    own: vec4<u32>,
    column: vec4<u32>,
    fs: bool,
) {
    let size = textureDimensions(src);
    let at = q - tile * TILE;
    if at.x == TILE - 1u && q.y < size.y {
        textureStore(row_part, vec2<u32>(s.band.x + tile.x, q.y), own);
    }
    if at.y == TILE - 1u && q.x < size.x {
        textureStore(col_part, vec2<u32>(q.x, s.band.y + tile.y), own);
    }
}

// Pass 1 for tile `tile`, as shared/sat_tile_sums's. Every invocation calls it.
fn sat_tile_sums_pass(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32) {
    sat_strip_tile(p, fs, s, tile, li, 0u);
}
