// A tile's own summed-area table by subgroup scans (import-only module of
// shared/sat_tile_sums_subgroup and shared/sat_tile_scan_subgroup, the redesign of the tile
// passes that `exec::KernelLayout::Redesign` compiles in place of shared/sat_tile_sums and
// shared/sat_tile_scan on a device with wgpu's SUBGROUP feature; elsewhere the shipped ones).
// The workgroup's WG_SIZE = 2 · TILE invocations are two halves of TILE lanes; half h sweeps
// rows h · HALF .. h · HALF + HALF − 1 of the tile, lane i column i, so that neighbouring lanes
// load and store neighbouring texels (the shipped modules' lanes own 4 × 4 sub-blocks 4 texels
// apart). Per texel row a lane adds its texel to its column's running sum (registers), and the
// row's inclusive prefix across the lanes is one subgroup scan: the tile's own table in one
// sweep, no second sweep and no workgroup memory but the upper half's TILE column sums, which
// the lower half adds after one barrier (it keeps its HALF running sums until then).
// After a warp per 32-column strip scanning with subgroupInclusiveAdd (the design
// b0nes164/GPUPrefixSums and vello's scans build on; docs/COST.md).
//
// Lanes: a subgroup of s ≥ TILE lanes holds whole halves (s = 64: both); the row prefix is a
// Hillis–Steele scan of subgroupShuffleUp within each TILE lanes. A subgroup of s < TILE lanes
// (lavapipe: 8) cannot scan a row alone: the first subgroup of each half does the half's work,
// lane l owning columns k · s + l (pieces k < TILE / s), pieces chained by their totals, and
// sweeps the half twice (the second time for the table: correct, not fast). Invocation li is
// taken as lane li mod s of subgroup ⌊li / s⌋, as vello's and GPUPrefixSums' scans take it.
//
// Wrapping u32 sums are exact in any order, so fixed-point tables are bit for bit the shipped
// ones (and subgroupInclusiveAdd may add in the driver's order); f32 sums keep a summation
// tree no deeper than the shipped tile's (`sat::float_sum_depth`): a column's running sum in
// chunks of CHUNK_ROWS (≤ 8 roundings a value), the upper half's sum (1), the row scan (log₂ 32
// = 5 with s ≥ 32; log₂ s + TILE / s with pieces: ≤ 10 at s = 4): ≤ 20, as the shipped edges.
// The importer declares `src` (shared/sat_tile_texel) and
//   fn sat_strip_column(tile: vec2<u32>, s: SatSource, x: u32, fs: bool) -> vec4<u32>
//     (what column x adds to every texel of it: pass 3's column carry), and
//   fn sat_strip_emit(tile: vec2<u32>, s: SatSource, slot: u32, q: vec2<u32>, own: vec4<u32>,
//     column: vec4<u32>, fs: bool)
//     (texel q's own table value `own`, its column's `column`: pass 1 keeps the edges, pass 3
//     stores the table):
// #completed-by-importer
// #import shared/sat_tile
// #import shared/sat_tile_texel

const HALF: u32 = 16u; // TILE / 2: rows a half sweeps
const CHUNK_ROWS: u32 = 8u; // rows a running sum adds before it is folded into the chunks above
const MAX_PIECES: u32 = 8u; // TILE / 4: WebGPU's smallest subgroup is 4 lanes

// The upper half's column sums (its HALF rows), read by the lower half.
var<workgroup> sh_half: array<vec4<u32>, 32>; // TILE

// The raw depth at p clamped to the map (a neighbour of `sat_strip_texel`'s texel: not
// counted, its own texel counts it).
fn sat_strip_raw(p: vec2<i32>, size: vec2<u32>) -> f32 {
    return textureLoad(src, clamp(p, vec2<i32>(0), vec2<i32>(size) - 1), 0).r;
}

// Texel q of the source, encoded, as `sat_texel` gives it, but for one texel alone where the
// shipped passes compute a sub-block at a time (`sat_blocked`: VSM's moments from the
// neighbours' depth, ESM's exp): the same functions of the same loads, so the same values.
fn sat_strip_texel(q: vec2<u32>, size: vec2<u32>, p: SatParams, fs: bool, s: SatSource) -> vec4<u32> {
    if !sat_blocked(s) {
        return sat_texel(q, 0u, size, p, fs, s);
    }
    let c = vec2<i32>(q);
    let z = linear_depth(sat_raw_own(c, q, size), s.depth);
    var v: vec4<f32>;
    if s.kind == SAT_ESM {
        v = vec4<f32>(exp(s.exp_pos * (z - 1.0)), 0.0, 0.0, 0.0);
    } else {
        let left = linear_depth(sat_strip_raw(c - vec2<i32>(1, 0), size), s.depth);
        let right = linear_depth(sat_strip_raw(c + vec2<i32>(1, 0), size), s.depth);
        let up = linear_depth(sat_strip_raw(c - vec2<i32>(0, 1), size), s.depth);
        let down = linear_depth(sat_strip_raw(c + vec2<i32>(0, 1), size), s.depth);
        v = vec4<f32>(vsm_moments(z, left, right, up, down), 0.0, 0.0);
    }
    v = select(v, round_f16(v), s.f16);
    v = select(v, round_unorm16(v), s.unorm16);
    return select(vec4<u32>(0u), sat_encode_as(v, p, fs), all(q < size));
}

// Running column sum after adding `e` on row j of a half: `run` the sum since the last chunk,
// `done` the chunks before (CHUNK_ROWS rows each); returns the column's sum so far.
fn sat_strip_add(e: vec4<u32>, j: u32, run: ptr<function, vec4<u32>>, done: ptr<function, vec4<u32>>, fs: bool) -> vec4<u32> {
    *run = sat_sum(*run, e, fs);
    var sum = *run;
    if j >= CHUNK_ROWS {
        sum = sat_sum(*done, *run, fs);
    }
    if j % CHUNK_ROWS == CHUNK_ROWS - 1u {
        *done = sum;
        *run = vec4<u32>(0u);
    }
    return sum;
}

// The inclusive prefix of `v` over lanes 0 ..= lane of the `width` lanes it spans (width a
// power of two ≤ the subgroup; lanes of other spans of `width` do not mix in). Every lane of
// the subgroup calls it.
// `whole`: the span is the whole subgroup.
fn sat_strip_scan(v: vec4<u32>, lane: u32, width: u32, whole: bool, fs: bool) -> vec4<u32> {
    if !fs && whole {
        // Wrapping u32: any order of additions gives the same sums.
        return subgroupInclusiveAdd(v);
    }
    var x = v;
    for (var d = 1u; d < width; d *= 2u) {
        let t = subgroupShuffleUp(x, d);
        if lane >= d {
            x = sat_sum(t, x, fs);
        }
    }
    return x;
}

// Rows of the half `half` of tile `tile`, s ≥ TILE: lane `col` keeps its column's running sums
// (HALF of them), the upper half hands its last to the lower through `sh_half`, then every row
// is scanned across the lanes and handed to `sat_strip_emit`. Every invocation calls it.
fn sat_strip_wide(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32, slot: u32, whole: bool) {
    let size = textureDimensions(src);
    let col = li % TILE;
    let half = li / TILE;
    let x = tile.x * TILE + col;
    let y0 = tile.y * TILE + half * HALF;
    var held: array<vec4<u32>, 16>; // HALF
    var run = vec4<u32>(0u);
    var done = vec4<u32>(0u);
    for (var j = 0u; j < HALF; j++) {
        let e = sat_strip_texel(vec2<u32>(x, y0 + j), size, p, fs, s);
        held[j] = sat_strip_add(e, j, &run, &done, fs);
    }
    if half == 0u {
        sh_half[col] = held[HALF - 1u];
    }
    workgroupBarrier();
    let above = sh_half[col];
    let column = sat_strip_column(tile, s, x, fs);
    for (var j = 0u; j < HALF; j++) {
        var v = held[j];
        if half == 1u {
            v = sat_sum(above, v, fs);
        }
        let own = sat_strip_scan(v, col, TILE, whole, fs);
        sat_strip_emit(tile, s, slot, vec2<u32>(x, y0 + j), own, column, fs);
    }
}

// `sat_strip_wide` for subgroups of s < TILE lanes: the first subgroup of each half sweeps
// it, lane l owning columns k · s + l; the column sums for the lower half first, then the
// rows again for the table. Every invocation calls it.
fn sat_strip_narrow(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32, slot: u32, width: u32) {
    let size = textureDimensions(src);
    let lane = li % TILE;
    let half = li / TILE;
    let pieces = TILE / width;
    let y0 = tile.y * TILE + half * HALF;
    let working = lane < width;
    if working {
        for (var k = 0u; k < pieces; k++) {
            let x = tile.x * TILE + k * width + lane;
            var run = vec4<u32>(0u);
            var done = vec4<u32>(0u);
            var sum = vec4<u32>(0u);
            for (var j = 0u; j < HALF; j++) {
                let e = sat_strip_texel(vec2<u32>(x, y0 + j), size, p, fs, s);
                sum = sat_strip_add(e, j, &run, &done, fs);
            }
            if half == 0u {
                sh_half[k * width + lane] = sum;
            }
        }
    }
    workgroupBarrier();
    if !working {
        return;
    }
    // The second sweep's texels were counted by the first.
    let counted = sat_non_finite;
    var run: array<vec4<u32>, 8>; // MAX_PIECES
    var done: array<vec4<u32>, 8>;
    for (var j = 0u; j < HALF; j++) {
        var left = vec4<u32>(0u);
        for (var k = 0u; k < pieces; k++) {
            let x = tile.x * TILE + k * width + lane;
            let e = sat_strip_texel(vec2<u32>(x, y0 + j), size, p, fs, s);
            var r = run[k];
            var d = done[k];
            var v = sat_strip_add(e, j, &r, &d, fs);
            run[k] = r;
            done[k] = d;
            if half == 1u {
                v = sat_sum(sh_half[k * width + lane], v, fs);
            }
            let piece = sat_strip_scan(v, lane, width, true, fs);
            var own = piece;
            if k > 0u {
                own = sat_sum(left, piece, fs);
            }
            left = subgroupShuffle(own, width - 1u);
            let column = sat_strip_column(tile, s, x, fs);
            sat_strip_emit(tile, s, slot, vec2<u32>(x, y0 + j), own, column, fs);
        }
    }
    sat_non_finite = counted;
}

// Tile `tile`'s own table, every texel (inside the map or not) handed to `sat_strip_emit`.
// Every invocation calls it (it has a barrier).
fn sat_strip_tile(p: SatParams, fs: bool, s: SatSource, tile: vec2<u32>, li: u32, slot: u32) {
    // Every invocation is active here: the count is the subgroup's size, the same for the
    // whole workgroup, read back as a workgroup-uniform value so the barriers below are in
    // uniform control flow.
    let lanes = subgroupAdd(1u);
    if li == 0u {
        sh_width = lanes;
    }
    let width = workgroupUniformLoad(&sh_width);
    if width >= TILE {
        sat_strip_wide(p, fs, s, tile, li, slot, width == TILE);
    } else {
        sat_strip_narrow(p, fs, s, tile, li, slot, width);
    }
}

// The subgroup's size, as `sat_strip_tile` hands it to the workgroup.
var<workgroup> sh_width: u32;
