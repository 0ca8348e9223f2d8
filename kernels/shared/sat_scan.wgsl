// Workgroup scans and the parameters of the summed-area-table kernels (import-only module).
//
// Values travel as vec4<u32> in both variants: u32 fixed point, added with two's-complement
// wraparound (WGSL's u32 `+` wraps), or the bits of an f32, added as floats. 0u is the identity
// of both (the bits of +0.0). The scan is Blelloch's (1990) work-efficient tree: an up-sweep of
// WG_SIZE − 1 adds builds partial sums in place, a down-sweep of as many turns them into the
// exclusive prefix; 2·log2(WG_SIZE) barriers, no atomics and nothing that waits on another
// workgroup (no forward-progress assumption: blocks meet only across dispatches).

// Keep in sync with `SatParams` in src/sat.rs.
struct SatParams {
    offset: vec4<f32>,   // subtracted from every value before scaling (centres the range)
    scale: vec4<f32>,    // fixed: units per value unit (a power of two); float: 1
    limit: vec4<f32>,    // |(v − offset)·scale| is clamped to this (keeps window sums in range)
    channels: u32,       // channels of the representation that are used; the others are 0
    float_sums: u32,     // 1: f32 variant (values are f32 bits), 0: u32 fixed point
    axis: u32,           // sat_carry: 0 scans rows of block totals, 1 columns
    _pad: u32,
}

// Keep in sync with `SAT_BLOCK` in src/sat.rs: one workgroup scans one block of a line.
const WG_SIZE: u32 = 256u;

var<workgroup> sh_scan: array<vec4<u32>, WG_SIZE>;
var<workgroup> sh_total: vec4<u32>;

// a + b in the variant's arithmetic.
fn sat_add(a: vec4<u32>, b: vec4<u32>, float_sums: bool) -> vec4<u32> {
    let f = bitcast<vec4<u32>>(bitcast<vec4<f32>>(a) + bitcast<vec4<f32>>(b));
    return select(a + b, f, float_sums);
}

// A representation texel in the variant's domain: (v − offset)·scale, clamped to ±limit,
// rounded to the nearest integer (ties to even) and wrapped into u32 for fixed point, or kept
// as f32 bits; channels past `channels` are 0 (a texture without alpha reads alpha as 1).
fn sat_encode(v: vec4<f32>, p: SatParams) -> vec4<u32> {
    let x = clamp((v - p.offset) * p.scale, -p.limit, p.limit);
    let used = vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(p.channels);
    let fixed = bitcast<vec4<u32>>(vec4<i32>(round(x)));
    let e = select(fixed, bitcast<vec4<u32>>(x), p.float_sums != 0u);
    return select(vec4<u32>(0u), e, used);
}

// Up-sweep: leaves the partial sums of the tree in sh_scan and the block total in its last
// element. Every invocation of the workgroup must call it (it has barriers).
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

// Sum of `x` over the workgroup.
fn sat_reduce(li: u32, x: vec4<u32>, float_sums: bool) -> vec4<u32> {
    sat_up_sweep(li, x, float_sums);
    return sh_scan[WG_SIZE - 1u];
}

// Exclusive prefix sum of `x` over the workgroup (invocation order); the workgroup's total is
// left in sh_total until the next scan.
fn sat_scan_exclusive(li: u32, x: vec4<u32>, float_sums: bool) -> vec4<u32> {
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

// Texel `a` along `axis` on line `b`.
fn sat_texel(a: u32, b: u32, axis: u32) -> vec2<u32> {
    return select(vec2<u32>(a, b), vec2<u32>(b, a), axis == 1u);
}

// The column pass of a SAT, column `x`, block `block` of WG_SIZE rows: the inclusive scan of
// R(x, y) = rows(x, y) + row_carry(x / WG_SIZE, y) down the block, plus the column carry of
// the block. `rows` holds each row block's local inclusive scan, `row_carry` the exclusive
// prefix of the row blocks' totals, so R is the full row prefix; `col_carry` holds the
// exclusive prefix of the column blocks' totals of R. Returns 0 below the map.
fn sat_column(
    rows: texture_2d<u32>,
    row_carry: texture_2d<u32>,
    col_carry: texture_2d<u32>,
    p: SatParams,
    li: u32,
    block: u32,
    x: u32,
) -> vec4<u32> {
    let fs = p.float_sums != 0u;
    let y = block * WG_SIZE + li;
    let inside = y < textureDimensions(rows).y;
    var v = vec4<u32>(0u);
    if inside {
        let r = textureLoad(rows, vec2<u32>(x, y), 0);
        v = sat_add(r, textureLoad(row_carry, vec2<u32>(x / WG_SIZE, y), 0), fs);
    }
    let before = sat_scan_exclusive(li, v, fs);
    return sat_add(textureLoad(col_carry, vec2<u32>(x, block), 0), sat_add(before, v, fs), fs);
}
