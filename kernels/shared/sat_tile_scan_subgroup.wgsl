// The table of one tile with its carries by subgroup scans (import-only module): the redesign
// of shared/sat_tile_scan that `exec::KernelLayout::Redesign` compiles in its place on a
// device with wgpu's SUBGROUP feature (`exec::REDESIGNED_MODULES`), for every tile kernel that
// imports it. A table texel is its tile's own table (shared/sat_strip: one sweep of the tile
// by its columns) plus the column carry of its column and the row carry of its row (pass 2),
// as in shared/sat_tile_scan: fixed-point tables bit for bit the same. The importing kernel
// declares `src`, `col_carry`, `row_carry` and `fn sat_store(slot, q, v)`:
// #completed-by-importer
// #import shared/sat_strip

// Column x's carry: the map above the tile row, over the tile's columns up to x.
fn sat_strip_column(tile: vec2<u32>, s: SatSource, x: u32, fs: bool) -> vec4<u32> {
    let last = textureDimensions(col_carry).x - 1u;
    return textureLoad(col_carry, vec2<u32>(min(x, last), s.band.y + tile.y), 0);
}

// Table texel q (inside the map): its tile's own table, its column carry and its row carry.
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
    if all(q < size) {
        let row = textureLoad(row_carry, vec2<u32>(s.band.x + tile.x, q.y), 0);
        sat_store(slot, q, sat_sum(sat_sum(own, column, fs), row, fs));
    }
}

// Pass 3 for tile `tile`, as shared/sat_tile_scan's. Every invocation calls it.
fn sat_tile_table(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32, slot: u32) {
    sat_strip_tile(p, fs, s, tile, li, slot);
}
