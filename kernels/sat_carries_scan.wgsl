// Summed-area table, pass 2 of 3, redesigned: the carries of `sat_carries` (the same
// col_carry and row_carry; fixed point bit for bit), each line's tiles shared among
// SCAN_PARTS lanes instead of walked by one. The `redesign` kernel layout compiles this file
// for the `sat_carries` nodes (exec::REDESIGNED_KERNELS); their dispatch there is
// `Dispatch::Lines { per_group: SCAN_LINES }` (src/sat/mod.rs, `carries_dispatch`): workgroup
// row 0 over the columns, row 1 over the rows, SCAN_LINES lines a workgroup, z the table.
//
// After the reduce-then-scan of b0nes164/GPUPrefixSums (`ReduceThenScan.cuh`: Reduce, Scan,
// DownSweepExclusive), inside one workgroup: a line's tiles go in segments of SCAN_SPAN, lane
// `part` of the line keeping SCAN_BATCH consecutive tiles of a segment in registers; it sums
// them, the SCAN_PARTS sums of each line are scanned in workgroup memory (an exclusive prefix,
// in part order, after the sum of the line's earlier segments), and each lane stores its
// tiles' carries from its registers. Lanes on neighbouring lines (line = li % SCAN_LINES)
// load neighbouring texels of col_part, and neighbouring rows of row_part. Workgroup memory,
// not subgroup operations: the scan is of 8 sums a line, and it runs on every device alike.
//
// A row workgroup is one tile row (SCAN_LINES = TILE): before each segment it sums V, the
// totals of the segment's tiles above its tile row, once for all its rows, SCAN_QUARTERS lanes
// a tile each summing a quarter of the tiles above. The totals come from row_part's last row
// of each tile row (the tile's total, as col_part's last column: the same in fixed point; in
// f32 the tile pass's other order), lanes on neighbouring tiles reading neighbouring texels.
// Layered (params.layers = L > 1, src/sat/layers.rs): workgroup z carries table z within its
// bands, as sat_carries does.
// #import shared/sat_tile
// Traffic (the cost model, src/graph/cost, reads sat_carries' declarations; these are the
// same): every edge texel read once and every carry written once. Not counted, as in
// sat_carries: the row workgroups' reads of the totals above them (tiles_x · tiles_y² / 2
// texels, at 8192² 1/8 of the map's texels, from cache).
// #traffic col_part: all
// #traffic row_part: all
// #traffic col_carry: all
// #traffic row_carry: all

@group(0) @binding(0) var col_part: texture_2d<u32>;
@group(0) @binding(1) var row_part: texture_2d<u32>;
@group(0) @binding(2) var col_carry: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var row_carry: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: SatParams;

// Keep in sync with `SAT_SCAN_LINES` in src/sat/mod.rs.
const SCAN_LINES: u32 = 32u; // lines a workgroup (= TILE: a row workgroup's tile row)
const SCAN_PARTS: u32 = 8u; // lanes a line
const SCAN_BATCH: u32 = 8u; // tiles a lane holds
const SCAN_SPAN: u32 = 64u; // tiles of a line a segment: SCAN_PARTS · SCAN_BATCH
const SCAN_GROUP: u32 = 256u; // SCAN_LINES · SCAN_PARTS
const SCAN_QUARTERS: u32 = 4u; // SCAN_GROUP / SCAN_SPAN: lanes summing one tile's totals above

// The SCAN_PARTS sums of each line's chunks at [part · SCAN_LINES + line]; before them, in a row
// workgroup, V's partial sums at [quarter · SCAN_SPAN + k].
var<workgroup> sh_sums: array<vec4<u32>, 256>; // SCAN_GROUP
// V of the segment's tiles (a row workgroup).
var<workgroup> sh_above: array<vec4<u32>, 64>; // SCAN_SPAN

// Tiles of one table's band (the edges of `layers` tables stacked).
fn band_tiles(stacked: u32) -> u32 {
    return stacked / max(params.layers, 1u);
}

// SCAN_BATCH texels (named values, not an array: llvmpipe indexed an array's copy lane by lane).
struct Batch {
    v0: vec4<u32>,
    v1: vec4<u32>,
    v2: vec4<u32>,
    v3: vec4<u32>,
    v4: vec4<u32>,
    v5: vec4<u32>,
    v6: vec4<u32>,
    v7: vec4<u32>,
}

// Texel `p` of `row_part` (`row`) or `col_part` where `ok`, else 0 (the identity of both
// variants' sums). The bindings are named, never passed: the executor may rewrite each
// binding's loads (`exec::buffers`).
fn load_edge(row: bool, p: vec2<u32>, ok: bool) -> vec4<u32> {
    if !ok {
        return vec4<u32>(0u);
    }
    if row {
        return textureLoad(row_part, p, 0);
    }
    return textureLoad(col_part, p, 0);
}

// The first `n` (at most SCAN_BATCH) texels of `row_part` (`row`) or `col_part` from `p`, `step`
// apart, loaded before any is used; the others 0.
fn load_batch(row: bool, p: vec2<u32>, step: vec2<u32>, n: u32) -> Batch {
    return Batch(
        load_edge(row, p, 0u < n),
        load_edge(row, p + step, 1u < n),
        load_edge(row, p + 2u * step, 2u < n),
        load_edge(row, p + 3u * step, 3u < n),
        load_edge(row, p + 4u * step, 4u < n),
        load_edge(row, p + 5u * step, 5u < n),
        load_edge(row, p + 6u * step, 6u < n),
        load_edge(row, p + 7u * step, 7u < n),
    );
}

// The sum of the texels of `b`, added to `s` in order.
fn sum_batch(s: vec4<u32>, b: Batch, fs: bool) -> vec4<u32> {
    var t = sat_sum(s, b.v0, fs);
    t = sat_sum(t, b.v1, fs);
    t = sat_sum(t, b.v2, fs);
    t = sat_sum(t, b.v3, fs);
    t = sat_sum(t, b.v4, fs);
    t = sat_sum(t, b.v5, fs);
    t = sat_sum(t, b.v6, fs);
    return sat_sum(t, b.v7, fs);
}

// The running sum `carry` stored at `p` of `row_carry` (`row`) or `col_carry` where `ok`, then
// `part` added.
fn carry_step(
    row: bool,
    p: vec2<u32>,
    ok: bool,
    part: vec4<u32>,
    carry: ptr<function, vec4<u32>>,
    fs: bool,
) {
    if ok {
        if row {
            textureStore(row_carry, p, *carry);
        } else {
            textureStore(col_carry, p, *carry);
        }
    }
    *carry = sat_sum(*carry, part, fs);
}

// The carries of the first `n` texels of `b`, from `carry`, stored from `p`, `step` apart.
fn carry_batch(
    row: bool,
    p: vec2<u32>,
    step: vec2<u32>,
    n: u32,
    b: Batch,
    carry: vec4<u32>,
    fs: bool,
) {
    var c = carry;
    carry_step(row, p, 0u < n, b.v0, &c, fs);
    carry_step(row, p + step, 1u < n, b.v1, &c, fs);
    carry_step(row, p + 2u * step, 2u < n, b.v2, &c, fs);
    carry_step(row, p + 3u * step, 3u < n, b.v3, &c, fs);
    carry_step(row, p + 4u * step, 4u < n, b.v4, &c, fs);
    carry_step(row, p + 5u * step, 5u < n, b.v5, &c, fs);
    carry_step(row, p + 6u * step, 6u < n, b.v6, &c, fs);
    carry_step(row, p + 7u * step, 7u < n, b.v7, &c, fs);
}

// The tiles of a segment from `first` that lane `part` holds, of `tiles` (0 on a line past
// the map's: `live` false).
fn held(first: u32, part: u32, tiles: u32, live: bool) -> u32 {
    let start = first + part * SCAN_BATCH;
    if !live || start >= tiles {
        return 0u;
    }
    return min(SCAN_BATCH, tiles - start);
}

// One segment's scan: the lane's chunk `b` summed into workgroup memory, then, after the
// line's earlier segments (`carry`) and the chunks of the parts before it, its carries stored
// from `p`, `step` apart; returns the line's sum through the segment. Every invocation calls it
// (it has barriers).
fn scan_segment(
    row: bool,
    line: u32,
    part: u32,
    p: vec2<u32>,
    step: vec2<u32>,
    n: u32,
    b: Batch,
    carry: vec4<u32>,
    fs: bool,
) -> vec4<u32> {
    sh_sums[part * SCAN_LINES + line] = sum_batch(vec4<u32>(0u), b, fs);
    workgroupBarrier();
    var before = carry;
    var total = carry;
    for (var q = 0u; q < SCAN_PARTS; q++) {
        if q == part {
            before = total;
        }
        total = sat_sum(total, sh_sums[q * SCAN_LINES + line], fs);
    }
    carry_batch(row, p, step, n, b, before, fs);
    // The sums are read before the next segment writes them.
    workgroupBarrier();
    return total;
}

// Columns g · SCAN_LINES + line of table `layer`, invocation li on column line =
// li % SCAN_LINES and part li / SCAN_LINES of its tiles. Every invocation of the workgroup
// calls it.
fn column_carries(g: u32, layer: u32, li: u32, fs: bool) {
    let size = textureDimensions(col_part);
    if g * SCAN_LINES >= size.x {
        return; // a workgroup past the map's columns (workgroup-uniform: no barrier is skipped)
    }
    let line = li % SCAN_LINES;
    let part = li / SCAN_LINES;
    let x = g * SCAN_LINES + line;
    let tiles = band_tiles(size.y);
    let band = layer * tiles;
    let down = vec2<u32>(0u, 1u);
    var carry = vec4<u32>(0u);
    for (var first = 0u; first < tiles; first += SCAN_SPAN) {
        let n = held(first, part, tiles, x < size.x);
        let p = vec2<u32>(x, band + first + part * SCAN_BATCH);
        let b = load_batch(false, p, down, n);
        carry = scan_segment(false, line, part, p, down, n, b, carry, fs);
    }
}

// V of tiles `first .. first + SCAN_SPAN` above tile row `ty` into sh_above (0 past the
// row's `tiles`): lane li sums quarter li / SCAN_SPAN of the tile rows above tile
// first + li % SCAN_SPAN from row_part's last rows (`cols` the table's band's first column).
// Every invocation calls it.
fn totals_above(first: u32, ty: u32, tiles: u32, cols: u32, li: u32, fs: bool) {
    let k = li % SCAN_SPAN;
    let quarter = li / SCAN_SPAN;
    let each = (ty + SCAN_QUARTERS - 1u) / SCAN_QUARTERS;
    let end = min((quarter + 1u) * each, ty);
    var above = vec4<u32>(0u);
    if first + k < tiles {
        let step = vec2<u32>(0u, TILE);
        for (var t = quarter * each; t < end; t += SCAN_BATCH) {
            let p = vec2<u32>(cols + first + k, t * TILE + TILE - 1u);
            above = sum_batch(above, load_batch(true, p, step, min(SCAN_BATCH, end - t)), fs);
        }
    }
    sh_sums[quarter * SCAN_SPAN + k] = above;
    workgroupBarrier();
    if li < SCAN_SPAN {
        var v = sh_sums[li];
        for (var q = 1u; q < SCAN_QUARTERS; q++) {
            v = sat_sum(v, sh_sums[q * SCAN_SPAN + li], fs);
        }
        sh_above[li] = v;
    }
    workgroupBarrier();
}

// `b`'s texels, the chunk from tile `k` of the segment, with their tiles' V added.
fn with_above(b: Batch, k: u32, fs: bool) -> Batch {
    return Batch(
        sat_sum(b.v0, sh_above[k], fs),
        sat_sum(b.v1, sh_above[k + 1u], fs),
        sat_sum(b.v2, sh_above[k + 2u], fs),
        sat_sum(b.v3, sh_above[k + 3u], fs),
        sat_sum(b.v4, sh_above[k + 4u], fs),
        sat_sum(b.v5, sh_above[k + 5u], fs),
        sat_sum(b.v6, sh_above[k + 6u], fs),
        sat_sum(b.v7, sh_above[k + 7u], fs),
    );
}

// Rows of tile row g of table `layer`, invocation li on row g · SCAN_LINES + li % SCAN_LINES
// and part li / SCAN_LINES of its tiles. Every invocation of the workgroup calls it.
fn row_carries(g: u32, layer: u32, li: u32, fs: bool) {
    let size = textureDimensions(row_part);
    if g * SCAN_LINES >= size.y {
        return; // a workgroup past the map's rows (workgroup-uniform: no barrier is skipped)
    }
    let line = li % SCAN_LINES;
    let part = li / SCAN_LINES;
    let y = g * SCAN_LINES + line;
    let tiles = band_tiles(size.x);
    let cols = layer * tiles;
    let right = vec2<u32>(1u, 0u);
    var carry = vec4<u32>(0u);
    for (var first = 0u; first < tiles; first += SCAN_SPAN) {
        totals_above(first, g, tiles, cols, li, fs);
        let n = held(first, part, tiles, y < size.y);
        let p = vec2<u32>(cols + first + part * SCAN_BATCH, y);
        // Past the row's tiles the loads are 0 and so is V: the chunk's sum is the held tiles'.
        let b = with_above(load_batch(true, p, right, n), part * SCAN_BATCH, fs);
        carry = scan_segment(true, line, part, p, right, n, b, carry, fs);
    }
}

@compute @workgroup_size(SCAN_GROUP)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let fs = params.float_sums != 0u;
    if wg.y == 0u {
        column_carries(wg.x, wg.z, li, fs);
    } else {
        row_carries(wg.x, wg.z, li, fs);
    }
}
