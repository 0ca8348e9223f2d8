// Workgroup scans of the five-pass summed-area-table kernels (import-only module; the
// `sat_rows` … `sat_cols` baseline that `shadowgraph bench` times against the tiled kernels).
//
// A workgroup scans a block of BLOCK = WG_SIZE · ITEMS texels of a line: each invocation scans
// its ITEMS consecutive texels in registers, the invocations' totals are scanned with
// Blelloch's (1990) work-efficient tree in workgroup memory (an up-sweep of WG_SIZE − 1 adds
// builds partial sums in place, a down-sweep of as many turns them into the exclusive prefix;
// 2·log2(WG_SIZE) barriers), and each invocation adds its prefix to its texels: O(BLOCK) adds
// in all. No atomics and nothing waits on another workgroup: blocks meet only across
// dispatches (no forward-progress assumption).

// #import shared/sat_params

// Keep in sync with `SAT_BLOCK` in src/sat.rs (BLOCK) and the kernels' dispatches.
const WG_SIZE: u32 = 256u;
const ITEMS: u32 = 4u;
const BLOCK: u32 = 1024u; // WG_SIZE · ITEMS

var<workgroup> sh_scan: array<vec4<u32>, WG_SIZE>;
var<workgroup> sh_total: vec4<u32>;

// a + b in the variant's arithmetic (`float_sums` is uniform: a branch, not a select, so fixed
// point never adds its codes as floats, whose bit patterns may be denormals or NaNs).
fn sat_add(a: vec4<u32>, b: vec4<u32>, float_sums: bool) -> vec4<u32> {
    if float_sums {
        return bitcast<vec4<u32>>(bitcast<vec4<f32>>(a) + bitcast<vec4<f32>>(b));
    }
    return a + b;
}

// Up-sweep over the invocations' values `x`: leaves the tree's partial sums in sh_scan, the
// workgroup's total in its last element. Every invocation must call it (it has barriers).
fn sat_up_sweep(li: u32, x: vec4<u32>, float_sums: bool) {
    workgroupBarrier(); // the previous use of sh_scan is finished
    sh_scan[li] = x;
    for (var d = 1u; d < WG_SIZE; d <<= 1u) {
        workgroupBarrier();
        let i = (li + 1u) * 2u * d - 1u;
        if i < WG_SIZE {
            sh_scan[i] = sat_add(sh_scan[i - d], sh_scan[i], float_sums);
        }
    }
    workgroupBarrier();
}

// Exclusive prefix of `x` over the invocations (in invocation order); the workgroup's total is
// left in sh_total until the next scan.
fn sat_scan_invocations(li: u32, x: vec4<u32>, float_sums: bool) -> vec4<u32> {
    sat_up_sweep(li, x, float_sums);
    if li == WG_SIZE - 1u {
        sh_total = sh_scan[li];
        sh_scan[li] = vec4<u32>(0u);
    }
    for (var d = WG_SIZE / 2u; d > 0u; d >>= 1u) {
        workgroupBarrier();
        let i = (li + 1u) * 2u * d - 1u;
        if i < WG_SIZE {
            let left = sh_scan[i - d];
            sh_scan[i - d] = sh_scan[i];
            sh_scan[i] = sat_add(sh_scan[i], left, float_sums);
        }
    }
    workgroupBarrier();
    return sh_scan[li];
}

// Inclusive scan of a block held as ITEMS consecutive texels per invocation (invocation li
// holds texels li·ITEMS .. li·ITEMS + ITEMS − 1 of the block); the block's total is left in
// sh_total.
fn sat_scan_block(li: u32, items: array<vec4<u32>, ITEMS>, float_sums: bool) -> array<vec4<u32>, ITEMS> {
    var v = items;
    for (var k = 1u; k < ITEMS; k++) {
        v[k] = sat_add(v[k - 1u], v[k], float_sums);
    }
    let before = sat_scan_invocations(li, v[ITEMS - 1u], float_sums);
    for (var k = 0u; k < ITEMS; k++) {
        v[k] = sat_add(before, v[k], float_sums);
    }
    return v;
}

// Total of a block held as in sat_scan_block (the up-sweep half of the tree suffices).
fn sat_reduce_block(li: u32, items: array<vec4<u32>, ITEMS>, float_sums: bool) -> vec4<u32> {
    var t = items[0];
    for (var k = 1u; k < ITEMS; k++) {
        t = sat_add(t, items[k], float_sums);
    }
    sat_up_sweep(li, t, float_sums);
    return sh_scan[WG_SIZE - 1u];
}

// Texel `a` along `axis` on line `b`.
fn sat_texel(a: u32, b: u32, axis: u32) -> vec2<u32> {
    return select(vec2<u32>(a, b), vec2<u32>(b, a), axis == 1u);
}

// Row of the `k`-th texel that invocation `li` holds in column block `block`.
fn sat_column_row(block: u32, li: u32, k: u32) -> u32 {
    return block * BLOCK + li * ITEMS + k;
}

// The full row prefix R(x, y) = rows(x, y) + row_carry(x / BLOCK, y) of ITEMS texels of
// column `x` (0 below the map): `rows` holds each row block's local inclusive scan,
// `row_carry` the exclusive prefix of the row blocks' totals.
fn sat_row_prefix(
    rows: texture_2d<u32>,
    row_carry: texture_2d<u32>,
    fs: bool,
    li: u32,
    block: u32,
    x: u32,
) -> array<vec4<u32>, ITEMS> {
    var v: array<vec4<u32>, ITEMS>;
    let height = textureDimensions(rows).y;
    for (var k = 0u; k < ITEMS; k++) {
        let y = sat_column_row(block, li, k);
        if y < height {
            let r = textureLoad(rows, vec2<u32>(x, y), 0);
            v[k] = sat_add(r, textureLoad(row_carry, vec2<u32>(x / BLOCK, y), 0), fs);
        }
    }
    return v;
}

// The column pass of a SAT for ITEMS texels of column `x` in column block `block`: the
// inclusive scan of the full row prefix down the block plus the block's column carry
// (`col_carry`: the exclusive prefix of the column blocks' totals).
fn sat_column(
    rows: texture_2d<u32>,
    row_carry: texture_2d<u32>,
    col_carry: texture_2d<u32>,
    p: SatParams,
    li: u32,
    block: u32,
    x: u32,
) -> array<vec4<u32>, ITEMS> {
    let fs = p.float_sums != 0u;
    var v = sat_scan_block(li, sat_row_prefix(rows, row_carry, fs, li, block, x), fs);
    let carry = textureLoad(col_carry, vec2<u32>(x, block), 0);
    for (var k = 0u; k < ITEMS; k++) {
        v[k] = sat_add(carry, v[k], fs);
    }
    return v;
}
