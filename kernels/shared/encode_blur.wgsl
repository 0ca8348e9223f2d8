// Encode and blur fused (import-only module of `vsm_blur`, `evsm_blur`, `msm_blur`): a workgroup
// reads its tile of the rasterized depth, with a halo of r + 1 texels (the blur's r and one
// more for an encoding that differentiates the depth), encodes every texel of the tile and
// halo once (the importing kernel's `encode`), runs the
// separable blur along x and then y in workgroup memory, and writes the filtered moments once
// (Peters, HPG 2017: resolve, two Gaussian passes in shared memory, one write).
//
// `params.blur.axis` picks the shape:
//   2: a TILE × TILE tile blurred along both axes (radius ≤ TILE_RADIUS; the tile and its halo of
//      encoded texels fill workgroup memory at TILE_RADIUS with four channels), TILE ×
//      CPU_TILE_ROWS on a CPU driver (`graph::Dispatch::Tiles`);
//   0: ROW texels of one row blurred along x only (radius ≤ MAX_RADIUS): the fallback for larger
//      radii, followed by `blur`'s vertical pass.
// The sums are those of `blur` (the centre, then the symmetric pairs w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ),
// along x then y), with clamp-to-edge: a halo texel outside the map is the encoding of the border
// texel. Reading the depth at clamped coordinates gives exactly that for `vsm`'s derivatives too:
// a clamped texel's outward difference is 0, as the border texel's is.
// Each workgroup counts the non-finite depths of its own outputs, so each is counted once.
// Each encoding reads its five depths straight from the texture (`depth_direct`), on every
// device: staging the tile's depth through workgroup memory first made the fused tiles
// 1.0–1.28× slower on llvmpipe and 1.13–1.20× slower on an H200 (benches/RESULTS.md,
// 2026-11-27), where the texture cache serves the neighbours' reads.
//
// Two layouts (`exec::KernelLayout`, the override GPU_LAYOUT) blur a tile:
//   a GPU's: WG_SIZE invocations encode the tile with its halo into workgroup memory, one texel
//     each, then blur it along x and along y there (`blur_tile_runs`, `blur_tile_single`);
//   a CPU driver's: CPU_LANES invocations walk the tile in strips (`blur_tile_strips`): each
//     walks an encoded row along x, loading each depth once and encoding it in registers, and
//     keeps the horizontal sums; then each walks a column of those sums and stores. On
//     llvmpipe, which runs every SIMD group of a workgroup through every branch and barrier
//     under masks, this ran 2–3× faster than the GPU's layout (benches/RESULTS.md,
//     2026-11-28); on a GPU its few invocations a tile would leave most of each SM idle.
// The row path is the same in both; a CPU driver's CPU_LANES invocations run its WG_SIZE
// invocations' work CPU_LANES at a time. The redesign layout (`exec::KernelLayout::Redesign`,
// the override REDESIGN, on top of the GPU's) walks a tile's blur down strips of columns
// instead (shared/encode_blur_columns), the row path the GPU's.
//
// It holds the kernels' entry point, `main`. The importing kernel declares `const CHANNELS`
// (2 or 4), `struct Params` (its encoding's fields, then `blur: BlurSpec`), the fields of them
// its encoding reads, `struct Coding` and `fn coding() -> Coding` (read once a workgroup, into
// the Tile: read at each texel, llvmpipe loaded them from the uniform buffer at each, 3–4% of
// the EVSM and MSM strips' instructions), `fn encode(z, left, right, up, down, c: Coding) ->
// vec4<f32>`, the
// texel its channels need in workgroup memory: `alias Texel` (vec2<f32> for two channels,
// vec4<f32> for four), `fn texel_of(v: vec4<f32>) -> Texel` and `fn texel_out(t: Texel) ->
// vec4<f32>` (two channels in vec2s halve the workgroup memory and its traffic), and the tile
// that memory allows, `const TILE` (outputs per side) and `const SH_TEXELS` (texels of
// workgroup memory: at least the encoded tile at TILE_RADIUS, (TILE + 2·TILE_RADIUS)², and
// the fallback's encoded row, ROW + 2·MAX_RADIUS; 16 KiB at most): 24 and 1444 with two channels
// (11.3 KiB), 16 and 900 with four (14.1 KiB); `const RUN`, the outputs an invocation sums in a
// tile's blur passes: 4 with two channels, 1 with four (see `run_sums`); `const
// CPU_TILE_ROWS`, the output rows of a CPU driver's taller tile (`filter::encode_blur_cpu_rows`:
// 40 with two channels, 32 with four; its horizontal sums, TILE × (CPU_TILE_ROWS +
// 2·TILE_RADIUS), fit SH_TEXELS); `const WALK_ROWS`, the
// encoded rows a CPU driver's strip walks at once (`walk_step`): 2 where the encoding reads the
// depths above and below (VSM), else 1; `const NEIGHBOURS`, whether `encode` reads the
// depths beside its texel (VSM: the redesign's columns share them through workgroup memory);
// and the fallback's row, `const ROW` outputs a workgroup in runs of `const ROW_RUN` an invocation (ROW = ROW_RUN ·
// WG_SIZE): 1024 in runs of 4 for `vsm_blur_row` (see `blur_row_quads`),
// 512 in runs of 2 for `vsm_blur` (see `blur_row_pairs`), 256 one an invocation with four
// channels:
// #completed-by-importer
// Storage: rg32float by default; the executor re-declares `dst` for the bound format.

// #import shared/linear_depth
// #import shared/encode_blur_columns

// Keep in sync with `BlurParams` in src/filter.rs (the same bytes; `axis` 2 means both).
struct BlurSpec {
    axis: u32,                    // 2: both axes in one tile; 0: along x only
    radius: u32,                  // taps each side
    mode: u32,                    // 0 (weighted sum): the only mode fused
    _pad: u32,
    weights: array<vec4<f32>, 9>, // weight of offset i at weights[i / 4][i % 4], i = 0..=32
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

// Keep in sync with `ENCODE_BLUR_*` in src/filter.rs.
const WG_SIZE: u32 = 256u;
// The layout the executor compiles (`exec::KernelLayout`): true on a GPU.
override GPU_LAYOUT: bool = false;
// The redesign layout (with GPU_LAYOUT): a tile's blur down strips of columns
// (shared/encode_blur_columns), a graph node's `Dispatch::Redesigned` strips.
override REDESIGN: bool = false;
// A CPU driver's workgroup: one of llvmpipe's SIMD groups (8 lanes of AVX2's 256-bit vectors).
// Strips of 32 and of 8 lanes ran alike on llvmpipe's wall clock and 8 took 1.2–1.6× less CPU
// time (benches/RESULTS.md, 2026-11-28): each extra SIMD group is one more coroutine
// through the barrier.
const CPU_LANES: u32 = 8u;
// The invocations of a workgroup: WG_SIZE on a GPU, CPU_LANES on a CPU driver.
override LANES: u32 = select(CPU_LANES, WG_SIZE, GPU_LAYOUT);
const TILE_RADIUS: u32 = 7u;
const MAX_RADIUS: u32 = 32u;
// Encoded texels an invocation computes and stores (`encode_tile`, blocks of WG_SIZE): at
// least ⌈(TILE + 2·TILE_RADIUS)² / WG_SIZE⌉ of a tile (6 at TILE = 24) and ⌈(ROW +
// 2·MAX_RADIUS) / WG_SIZE⌉ of a row; the blur's sums held between barriers, a run of RUN (`blur_tile_runs`) or up to four blocks of
// WG_SIZE (`blur_tile_single`, h0 … h3). The blocks past the first four (two) exist only in
// kernels whose tile can need them (`ENC_MAX`, `H_MAX`: a constant
// condition, compiled away for a 16² tile: as a run-time test llvmpipe computed the blocks
// anyway and EVSM4/MSM ran 12–20% slower), and are skipped where the radius leaves them empty
// (`k·WG_SIZE < n`, the same for the whole workgroup). Workgroup memory (SH_TEXELS, a `Texel`
// each, one access a tap) holds in turn the encoded tile ((TILE + 2·TILE_RADIUS)², or
// ROW + 2·MAX_RADIUS) and the horizontal sums.

// The encoded tile, then the horizontal sums over it.
var<workgroup> sh_tile: array<Texel, SH_TEXELS>;

// The most encoded texels a tile holds (at TILE_RADIUS): the blocks of WG_SIZE past the first
// four are compiled only where a kernel's tile needs them.
const ENC_MAX: u32 = (TILE + 2u * TILE_RADIUS) * (TILE + 2u * TILE_RADIUS);

// The most horizontal sums of a tile (at TILE_RADIUS) with one output an invocation: the blocks
// of WG_SIZE past the first two likewise.
const H_MAX: u32 = TILE * (TILE + 2u * TILE_RADIUS);

// A workgroup's outputs and the extents it works over.
struct Tile {
    origin: vec2<i32>, // the first output texel
    outs: vec2<i32>,   // outputs along x and y
    r: vec2<i32>,      // blur radius along x and y (0 along y for a row)
    enc: vec2<i32>,    // encoded extent: outs + 2r
    size: vec2<i32>,   // the map
    // The depth's linearization, read from `params` once a workgroup: read at each texel,
    // llvmpipe loaded it from the uniform buffer at each (4% of the MSM strips' instructions).
    depth: DepthParams,
    coding: Coding,    // the importer's encoding parameters (`coding`), likewise
}

fn tile_of(wg: vec2<u32>) -> Tile {
    var t: Tile;
    t.size = vec2<i32>(textureDimensions(src));
    t.depth = params.depth;
    t.coding = coding();
    if params.blur.axis == 2u {
        let r = i32(min(params.blur.radius, TILE_RADIUS));
        t.origin = vec2<i32>(wg * TILE);
        t.outs = vec2<i32>(i32(TILE));
        if !GPU_LAYOUT {
            // The strips' taller tile (`graph::Dispatch::Tiles`): less halo a texel.
            t.origin.y = i32(wg.y * CPU_TILE_ROWS);
            t.outs.y = i32(CPU_TILE_ROWS);
        }
        t.r = vec2<i32>(r);
        if REDESIGN {
            columns_tile(&t, wg);
        }
    } else {
        t.origin = vec2<i32>(i32(wg.x * ROW), i32(wg.y));
        // Clipped to the map: a row narrower than ROW loads and encodes only its own texels.
        t.outs = vec2<i32>(min(i32(ROW), t.size.x - t.origin.x), 1);
        t.r = vec2<i32>(i32(min(params.blur.radius, MAX_RADIUS)), 0);
    }
    t.enc = t.outs + 2 * t.r;
    return t;
}

// (i / d, i % d) for 0 ≤ i < 2²³ and d ≥ 1, in f32: llvmpipe has no vector integer division
// (a SIMD group's division is eight scalar ones; the tile's shape is not a compile-time
// constant). (i + ½)/d lies at least ½/d from an integer and its f32 quotient is within
// 2⁻²⁴·(i + ½)/d < ½/d of it, so the truncation is ⌊i / d⌋ exactly.
fn div_mod(i: i32, d: i32) -> vec2<i32> {
    let q = i32((f32(i) + 0.5) / f32(d));
    return vec2<i32>(q, i - q * d);
}

// The weight of offset i ≤ radius.
fn blur_weight(i: i32) -> f32 {
    return params.blur.weights[u32(i) / 4u][u32(i) % 4u];
}

fn sh_get(i: i32) -> Texel {
    return sh_tile[i];
}

// The raw depth at map texel p, clamped to the map.
fn raw_depth(t: Tile, p: vec2<i32>) -> f32 {
    return textureLoad(src, clamp(p, vec2<i32>(0), t.size - 1), 0).r;
}

// The linear depth at map texel p, clamped to the map, read straight from the texture
// (`encode_at`).
fn depth_direct(t: Tile, p: vec2<i32>) -> f32 {
    return linear_depth(raw_depth(t, p), t.depth);
}

// Whether map texel p is an output of the tile inside the map: where its own non-finite depth
// is counted (a ragged tile's texels past the map read the border at clamped coordinates).
fn owns(t: Tile, p: vec2<i32>) -> bool {
    return all(p >= t.origin) && all(p < min(t.origin + t.outs, t.size));
}

// The encoding of encoded-tile texel i (clamped to the tile: an invocation past its end computes
// a texel it does not store, so none branches).
fn encode_at(t: Tile, i: i32) -> Texel {
    let e = min(i, t.enc.x * t.enc.y - 1);
    let yx = div_mod(e, t.enc.x);
    // The texel's map position, its own non-finite depth counted here: an output of the tile
    // inside the map (a ragged tile's texels past it read the border at clamped coordinates),
    // and not a clamped copy of the last index (i == e).
    let p = t.origin - t.r + vec2<i32>(yx.y, yx.x);
    let raw = raw_depth(t, p);
    if i == e && owns(t, p) && !depth_is_finite(raw) {
        atomicAdd(&stats[0], 1u);
    }
    return texel_of(encode(
        linear_depth(raw, t.depth),
        depth_direct(t, p - vec2<i32>(1, 0)),
        depth_direct(t, p + vec2<i32>(1, 0)),
        depth_direct(t, p - vec2<i32>(0, 1)),
        depth_direct(t, p + vec2<i32>(0, 1)),
        t.coding
    ));
}

// Stores v at i if i < n.
fn put_below(i: i32, n: i32, v: Texel) {
    if i < n {
        sh_tile[i] = v;
    }
}

// Phase 1: every texel of the tile and its blur halo encoded once, each stored as it is
// computed (nothing else is in workgroup memory yet: one barrier, after the stores).
fn encode_tile(t: Tile, li: u32) {
    encode_blocks(t, li);
    workgroupBarrier();
}

// Invocation li's encoded texels of phase 1: li + k·WG_SIZE.
fn encode_blocks(t: Tile, li: u32) {
    let n = t.enc.x * t.enc.y;
    let i = i32(li);
    let s = i32(WG_SIZE);
    put_below(i, n, encode_at(t, i));
    put_below(i + s, n, encode_at(t, i + s));
    put_below(i + 2 * s, n, encode_at(t, i + 2 * s));
    put_below(i + 3 * s, n, encode_at(t, i + 3 * s));
    // Constant for each kernel: a 16² tile has no such block, and no code for it.
    if ENC_MAX > 4u * WG_SIZE && 4 * s < n {
        put_below(i + 4 * s, n, encode_at(t, i + 4 * s));
        put_below(i + 5 * s, n, encode_at(t, i + 5 * s));
    }
}

fn store(t: Tile, o: vec2<i32>, v: Texel) {
    let p = t.origin + o;
    if all(p < t.size) {
        textureStore(dst, p, texel_out(v));
    }
}

// Runs (RUN = 4): an invocation sums RUN consecutive outputs along a line of the tile (a row,
// then a column): each of the RUN + 2r texels the run covers is read once from workgroup memory
// into RUN running sums, RUN + 2r reads for RUN outputs where one output at a time reads 2r + 1
// (3 against 9 an output at r = 4). The tile's side is a multiple of RUN and its runs fit one
// an invocation: (TILE / RUN) · (TILE + 2·TILE_RADIUS) ≤ WG_SIZE (228 at TILE = 24).
// Which kernels run them, measured (benches/RESULTS.md, 2026-11-27): the two-channel tile (24²)
// keeps 144 of 256 invocations busy in its vertical pass and ran 6% faster on an H200 (1.29–
// 1.33× on llvmpipe); a four-channel tile (16²) keeps 64 busy and ran 17–20% slower on the H200
// (1.07–1.12× faster on llvmpipe), and so does the row path (ROW / RUN = 64 of 256: 12% slower
// there, 1.13–1.19× faster on llvmpipe). The GPU decides: four channels and the row path sum one
// output an invocation (`blur_tile_single`, `sum_x`). RUN is a constant, so each kernel
// compiles one of the two.

// The weight of offset d, 0 past the radius r.
fn run_weight(d: i32, r: i32) -> f32 {
    return select(0.0, blur_weight(min(abs(d), r)), abs(d) <= r);
}

// The RUN sums of a run: texel `first + k·step` of workgroup memory is output k's centre, its
// taps at `first + (k + i)·step`, |i| ≤ r. Tap j of the loop, at offset j − r from output 0's
// centre, carries weight w(j − r − k) in output k: a shift register of RUN weights.
struct Run {
    s0: Texel,
    s1: Texel,
    s2: Texel,
    s3: Texel,
}

fn run_sums(first: i32, step: i32, r: i32) -> Run {
    var o: Run;
    o.s0 = Texel(0.0);
    o.s1 = Texel(0.0);
    o.s2 = Texel(0.0);
    o.s3 = Texel(0.0);
    var w0 = run_weight(-r, r);
    var w1 = run_weight(-r - 1, r);
    var w2 = run_weight(-r - 2, r);
    var w3 = run_weight(-r - 3, r);
    for (var j = 0; j < i32(RUN) + 2 * r; j++) {
        let v = sh_get(first + (j - r) * step);
        o.s0 += w0 * v;
        o.s1 += w1 * v;
        o.s2 += w2 * v;
        o.s3 += w3 * v;
        w3 = w2;
        w2 = w1;
        w1 = w0;
        w0 = run_weight(j + 1 - r, r);
    }
    return o;
}

// Phases 2 and 3 in runs (RUN = 4): along x into workgroup memory (outs.x × enc.y sums, a run an
// invocation), then along y into `dst` (outs.x × outs.y outputs, a run down a column an
// invocation). Invocations past the last run idle through the barriers.
fn blur_tile_runs(t: Tile, li: u32) {
    let i = i32(li);
    let runs_x = t.outs.x / i32(RUN);
    let rx = div_mod(i, runs_x);
    let row = rx.x;
    let x0 = rx.y * i32(RUN);
    let along_x = row < t.enc.y;
    var h: Run;
    if along_x {
        h = run_sums(row * t.enc.x + x0 + t.r.x, 1, t.r.x);
    }
    workgroupBarrier();
    if along_x {
        let c = row * t.outs.x + x0;
        sh_tile[c] = h.s0;
        sh_tile[c + 1] = h.s1;
        sh_tile[c + 2] = h.s2;
        sh_tile[c + 3] = h.s3;
    }
    workgroupBarrier();
    let runs_y = t.outs.y / i32(RUN);
    let yc = div_mod(i, t.outs.x);
    let col = yc.y;
    let y0 = yc.x * i32(RUN);
    if i < t.outs.x * runs_y {
        let v = run_sums((y0 + t.r.y) * t.outs.x + col, t.outs.x, t.r.y);
        store(t, vec2<i32>(col, y0), v.s0);
        store(t, vec2<i32>(col, y0 + 1), v.s1);
        store(t, vec2<i32>(col, y0 + 2), v.s2);
        store(t, vec2<i32>(col, y0 + 3), v.s3);
    }
}

// The horizontal sum at output column x of encoded row y, alone.
fn sum_x(t: Tile, x: i32, y: i32) -> Texel {
    let c = y * t.enc.x + x + t.r.x;
    var s = blur_weight(0) * sh_get(c);
    for (var i = 1; i <= t.r.x; i++) {
        s += blur_weight(i) * (sh_get(c - i) + sh_get(c + i));
    }
    return s;
}

// The vertical sum of output q of the tile, alone, stored.
fn sum_y(t: Tile, q: i32) {
    let o = div_mod(q, t.outs.x).yx;
    let c = (o.y + t.r.y) * t.outs.x + o.x;
    var v = blur_weight(0) * sh_get(c);
    for (var k = 1; k <= t.r.y; k++) {
        v += blur_weight(k) * (sh_get(c - k * t.outs.x) + sh_get(c + k * t.outs.x));
    }
    store(t, o, v);
}

// Phases 2 and 3 one output an invocation (RUN = 1): along x into workgroup memory (outs.x ×
// enc.y sums, in up to four blocks of WG_SIZE), then along y into `dst` (WG_SIZE at a time).
fn blur_tile_single(t: Tile, li: u32) {
    let n = t.outs.x * t.enc.y;
    let i = i32(li);
    let w = i32(WG_SIZE);
    let j1 = min(i + w, n - 1);
    let a0 = div_mod(i, t.outs.x);
    let a1 = div_mod(j1, t.outs.x);
    let h0 = sum_x(t, a0.y, a0.x);
    let h1 = sum_x(t, a1.y, a1.x);
    var h2 = h1;
    var h3 = h1;
    if H_MAX > 2u * WG_SIZE && 2 * w < n {
        let j2 = min(i + 2 * w, n - 1);
        let j3 = min(i + 3 * w, n - 1);
        let a2 = div_mod(j2, t.outs.x);
        let a3 = div_mod(j3, t.outs.x);
        h2 = sum_x(t, a2.y, a2.x);
        h3 = sum_x(t, a3.y, a3.x);
    }
    workgroupBarrier();
    put_below(i, n, h0);
    put_below(i + w, n, h1);
    if H_MAX > 2u * WG_SIZE && 2 * w < n {
        put_below(i + 2 * w, n, h2);
        put_below(i + 3 * w, n, h3);
    }
    workgroupBarrier();
    sum_y(t, i);
    if TILE * TILE > WG_SIZE {
        for (var q = i + w; q < t.outs.x * t.outs.y; q += w) {
            sum_y(t, q);
        }
    }
}

// The CPU layout's tile (GPU_LAYOUT false): strips. A window of the 2·STRIP_RADIUS + 1 latest
// texels of a line, centre a7 (a3 … a11, or a0 … a14): the sum of output k, whose centre is
// a7, is w₀·a7 + Σᵢ wᵢ·(a(7−i) + a(7+i)), i = 1 … STRIP_RADIUS, the centre and then the
// symmetric pairs as `sum_x`'s, with wᵢ = 0 past the radius (exact zeros added to the finite
// sum; every texel the window holds is an encoding or a horizontal sum of the map, or 0).
// Named values, not an array (llvmpipe kept arrays indexed in a loop in memory: see `blur`'s
// runs).
//
// STRIP_RADIUS is a constant of each pipeline, set from the node's radius
// (`exec::KernelCache::node_constants`): 4 up to radius 4, else TILE_RADIUS. A window of 9
// texels in place of 15 took the MSM strips 1.27× less CPU time on llvmpipe, VSM's 1.05–1.1×
// (benches/RESULTS.md, 2026-11-28); as a run-time test llvmpipe would run both.
// #override STRIP_RADIUS: select(TILE_RADIUS, 4, params.blur.radius <= 4)
override STRIP_RADIUS: u32 = TILE_RADIUS;
// The window's outer pairs (a0 … a2, a12 … a14): only where STRIP_RADIUS is TILE_RADIUS.
override STRIP_WIDE: bool = STRIP_RADIUS > 4u;

struct Window {
    a0: Texel,
    a1: Texel,
    a2: Texel,
    a3: Texel,
    a4: Texel,
    a5: Texel,
    a6: Texel,
    a7: Texel,
    a8: Texel,
    a9: Texel,
    a10: Texel,
    a11: Texel,
    a12: Texel,
    a13: Texel,
    a14: Texel,
}

// The window's pairs are TILE_RADIUS's, and the horizontal sums of a tile at TILE_RADIUS fit
// workgroup memory.
const_assert TILE_RADIUS == 7u;
const_assert TILE * (TILE + 2u * TILE_RADIUS) <= SH_TEXELS;
const_assert TILE * (CPU_TILE_ROWS + 2u * TILE_RADIUS) <= SH_TEXELS;
// Rows walked in pairs: the strips' encoded rows, CPU_TILE_ROWS + 2r, pair up.
const_assert WALK_ROWS == 1u || (WALK_ROWS == 2u && CPU_TILE_ROWS % 2u == 0u);

fn empty_window() -> Window {
    let z = Texel(0.0);
    return Window(z, z, z, z, z, z, z, z, z, z, z, z, z, z, z);
}

// The window moved on by one texel, v.
fn window_push(w: ptr<function, Window>, v: Texel) {
    if STRIP_WIDE {
        (*w).a0 = (*w).a1;
        (*w).a1 = (*w).a2;
        (*w).a2 = (*w).a3;
    }
    (*w).a3 = (*w).a4;
    (*w).a4 = (*w).a5;
    (*w).a5 = (*w).a6;
    (*w).a6 = (*w).a7;
    (*w).a7 = (*w).a8;
    (*w).a8 = (*w).a9;
    (*w).a9 = (*w).a10;
    (*w).a10 = (*w).a11;
    if STRIP_WIDE {
        (*w).a11 = (*w).a12;
        (*w).a12 = (*w).a13;
        (*w).a13 = (*w).a14;
        (*w).a14 = v;
    } else {
        (*w).a11 = v;
    }
}

// The weights of offsets 0 … 7, 0 past radius r.
struct PairWeights {
    w0: f32,
    w1: f32,
    w2: f32,
    w3: f32,
    w4: f32,
    w5: f32,
    w6: f32,
    w7: f32,
}

fn pair_weights(r: i32) -> PairWeights {
    return PairWeights(
        run_weight(0, r),
        run_weight(1, r),
        run_weight(2, r),
        run_weight(3, r),
        run_weight(4, r),
        run_weight(5, r),
        run_weight(6, r),
        run_weight(7, r)
    );
}

// The output whose centre is the window's a7.
fn window_sum(w: Window, k: PairWeights) -> Texel {
    var s = k.w0 * w.a7;
    s += k.w1 * (w.a6 + w.a8);
    s += k.w2 * (w.a5 + w.a9);
    s += k.w3 * (w.a4 + w.a10);
    s += k.w4 * (w.a3 + w.a11);
    if STRIP_WIDE {
        s += k.w5 * (w.a2 + w.a12);
        s += k.w6 * (w.a1 + w.a13);
        s += k.w7 * (w.a0 + w.a14);
    }
    return s;
}

// A walk along WALK_ROWS encoded rows, y (and y + 1): the position reached in row y, the linear
// depths before it and the raw depths at it (row y's, then row y + 1's), and the non-finite
// depths of the tile's own outputs met so far. Counted in a register, added to `stats` once an
// invocation (`strip_rows`): an atomic in the walk's step, under a mask, took 7% of the strips'
// instructions on llvmpipe (benches/RESULTS.md, 2026-11-28).
struct Walk {
    p: vec2<i32>,
    before0: f32,
    before1: f32,
    raw0: f32,
    raw1: f32,
    bad: u32,
}

fn walk_start(t: Tile, p: vec2<i32>) -> Walk {
    let q = p + vec2<i32>(0, 1);
    return Walk(
        p,
        depth_direct(t, p - vec2<i32>(1, 0)),
        depth_direct(t, q - vec2<i32>(1, 0)),
        raw_depth(t, p),
        raw_depth(t, q),
        0u
    );
}

// 1 where map texel p is an output of the tile with a non-finite depth (`encode_at`'s count).
fn bad_at(t: Tile, p: vec2<i32>, raw: f32) -> u32 {
    return u32(owns(t, p) && !depth_is_finite(raw));
}

// The encodings at the walk's position in its rows (e1: row y + 1's, where WALK_ROWS is 2).
struct Encoded {
    e0: Texel,
    e1: Texel,
}

// The encodings at the walk's position, the walk moved on by one texel. One row: three depth
// loads (the next texel along the row, and above and below). Two rows: four (the next texel
// along each, above the first and below the second), as each row's texel is the other's
// neighbour below or above; both read their depths at clamped coordinates, so a row's
// neighbour is the other row's texel at the map's edges too.
fn walk_step(t: Tile, w: ptr<function, Walk>) -> Encoded {
    let p = (*w).p;
    let q = p + vec2<i32>(0, 1);
    let dx = vec2<i32>(1, 0);
    let raw0 = (*w).raw0;
    (*w).bad += bad_at(t, p, raw0);
    let z0 = linear_depth(raw0, t.depth);
    let next0 = raw_depth(t, p + dx);
    let up0 = depth_direct(t, p - vec2<i32>(0, 1));
    var e: Encoded;
    // A constant condition: each kernel compiles one of the two.
    if WALK_ROWS == 2u {
        let raw1 = (*w).raw1;
        (*w).bad += bad_at(t, q, raw1);
        let z1 = linear_depth(raw1, t.depth);
        let next1 = raw_depth(t, q + dx);
        e.e0 = texel_of(encode(
            z0,
            (*w).before0,
            linear_depth(next0, t.depth),
            up0,
            z1,
            t.coding
        ));
        e.e1 = texel_of(encode(
            z1,
            (*w).before1,
            linear_depth(next1, t.depth),
            z0,
            depth_direct(t, q + vec2<i32>(0, 1)),
            t.coding
        ));
        (*w).before1 = z1;
        (*w).raw1 = next1;
    } else {
        e.e0 = texel_of(encode(
            z0,
            (*w).before0,
            linear_depth(next0, t.depth),
            up0,
            depth_direct(t, q),
            t.coding
        ));
    }
    (*w).p = p + dx;
    (*w).before0 = z0;
    (*w).raw0 = next0;
    return e;
}

// The walk's texels pushed into the windows of its rows.
fn push_rows(w0: ptr<function, Window>, w1: ptr<function, Window>, e: Encoded) {
    window_push(w0, e.e0);
    if WALK_ROWS == 2u {
        window_push(w1, e.e1);
    }
}

// The rows' sums stored at i in workgroup memory (row y + 1's at i + outs.x).
fn store_rows(t: Tile, i: i32, w0: Window, w1: Window, k: PairWeights) {
    sh_tile[i] = window_sum(w0, k);
    if WALK_ROWS == 2u {
        sh_tile[i + t.outs.x] = window_sum(w1, k);
    }
}

// Strips along x: invocation li walks encoded rows WALK_ROWS at a time, rows WALK_ROWS·li,
// WALK_ROWS·(li + LANES), … (enc.y rows: the tile's with its halo) from the halo's left end,
// and stores each row's outs.x horizontal sums in workgroup memory (row-major, outs.x a row).
// With R = STRIP_RADIUS, output k's sum is complete when the walk has pushed texel k + r + R:
// the window's a7 is then texel k + r, its centre. Three loops, so that no step tests which
// part of the walk it is in (llvmpipe would run both sides): the first r + R texels fill the
// window, the rest of the row sums as it goes, and R − r zeros finish the last outputs past the
// row's end.
fn strip_rows(t: Tile, li: u32, k: PairWeights) {
    let r = t.r.x;
    let rr = i32(STRIP_RADIUS);
    let rows = i32(WALK_ROWS);
    var bad = 0u;
    for (var row = rows * i32(li); row < t.enc.y; row += rows * i32(LANES)) {
        var walk = walk_start(t, t.origin - t.r + vec2<i32>(0, row));
        var win0 = empty_window();
        var win1 = empty_window();
        var j = 0;
        for (; j < r + rr; j++) {
            push_rows(&win0, &win1, walk_step(t, &walk));
        }
        let at = row * t.outs.x - r - rr;
        for (; j < t.enc.x; j++) {
            push_rows(&win0, &win1, walk_step(t, &walk));
            store_rows(t, at + j, win0, win1, k);
        }
        let zeros = Encoded(Texel(0.0), Texel(0.0));
        for (; j < t.enc.x + rr - r; j++) {
            push_rows(&win0, &win1, zeros);
            store_rows(t, at + j, win0, win1, k);
        }
        bad += walk.bad;
    }
    if bad > 0u {
        atomicAdd(&stats[0], bad);
    }
}

// Strips along y: invocation li walks columns li, li + LANES, … of the horizontal sums down,
// in `strip_rows`' three loops, and stores each output.
fn strip_columns(t: Tile, li: u32, k: PairWeights) {
    let r = t.r.y;
    let rr = i32(STRIP_RADIUS);
    for (var c = i32(li); c < t.outs.x; c += i32(LANES)) {
        var win = empty_window();
        var j = 0;
        for (; j < r + rr; j++) {
            window_push(&win, sh_get(j * t.outs.x + c));
        }
        for (; j < t.enc.y; j++) {
            window_push(&win, sh_get(j * t.outs.x + c));
            store(t, vec2<i32>(c, j - r - rr), window_sum(win, k));
        }
        for (; j < t.enc.y + rr - r; j++) {
            window_push(&win, Texel(0.0));
            store(t, vec2<i32>(c, j - r - rr), window_sum(win, k));
        }
    }
}

// The tile in strips (the CPU layout): along x into workgroup memory (outs.x × enc.y sums),
// one barrier, then along y into `dst`. Each pass reads its own weights: llvmpipe keeps what
// lives across a barrier in its coroutine's frame, and the weights held across it took 10% of
// the VSM strips' instructions (benches/instructions.sh; benches/RESULTS.md, 2026-11-28).
fn blur_tile_strips(t: Tile, li: u32) {
    strip_rows(t, li, pair_weights(t.r.x));
    workgroupBarrier();
    strip_columns(t, li, pair_weights(t.r.y));
}

// The row's blur along x in runs of 2 (ROW = 2·WG_SIZE): invocation li's outputs x = 2li and
// 2li + 1, from 2 + 2r texels of the encoded row read once into two sliding windows (v_{k−i},
// v_{k+i} of output k as i grows), each output summed in `sum_x`'s order, so the results are
// those of one output at a time. Every invocation stays busy (where runs over a row of
// WG_SIZE outputs left three quarters idle: 12% slower on an H200).
fn blur_row_pairs(t: Tile, li: u32) {
    let x = 2 * i32(li);
    let c = x + t.r.x;
    let c0 = sh_get(c);
    let c1 = sh_get(c + 1);
    let w0 = blur_weight(0);
    var s0 = w0 * c0;
    var s1 = w0 * c1;
    var l0 = c0;
    var l1 = c0;
    var r0 = c1;
    var r1 = c1;
    if t.r.x > 0 {
        l0 = sh_get(c - 1);
        r1 = sh_get(c + 2);
    }
    // Offset r, which needs no next taps, after the loop (as `blur`'s runs: a test inside the
    // loop ran on llvmpipe as masked selects of the windows at every offset).
    for (var i = 1; i < t.r.x; i++) {
        let w = blur_weight(i);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        l1 = l0;
        l0 = sh_get(c - i - 1);
        r0 = r1;
        r1 = sh_get(c + 1 + i + 1);
    }
    if t.r.x > 0 {
        let w = blur_weight(t.r.x);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
    }
    store(t, vec2<i32>(x, 0), s0);
    store(t, vec2<i32>(x + 1, 0), s1);
}

// The row's blur along x in runs of 4 (ROW = 4·WG_SIZE, `vsm_blur_row`): invocation li's
// outputs x = 4li … 4li + 3, from 2 + 2r texels of the encoded row read once into two sets of
// four sliding windows (output k's taps at c + k ∓ i; from offset i to i + 1 each window takes
// its neighbour's value and one texel is read each side), each output summed in `sum_x`'s
// order, so the results are those of one output at a time. Every invocation stays busy (runs
// over a row of WG_SIZE outputs left three quarters idle: 12% slower on an H200).
fn blur_row_quads(t: Tile, li: u32) {
    let x = 4 * i32(li);
    let c = x + t.r.x;
    let w0 = blur_weight(0);
    let c0 = sh_get(c);
    let c1 = sh_get(c + 1);
    let c2 = sh_get(c + 2);
    let c3 = sh_get(c + 3);
    var s0 = w0 * c0;
    var s1 = w0 * c1;
    var s2 = w0 * c2;
    var s3 = w0 * c3;
    var l0 = c0;
    var l1 = c0;
    var l2 = c1;
    var l3 = c2;
    var r0 = c1;
    var r1 = c2;
    var r2 = c3;
    var r3 = c3;
    if t.r.x > 0 {
        l0 = sh_get(c - 1);
        r3 = sh_get(c + 4);
    }
    // Offset r, which needs no next taps, after the loop (a test inside the loop ran on
    // llvmpipe as masked selects of the windows at every offset).
    for (var i = 1; i < t.r.x; i++) {
        let w = blur_weight(i);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        s2 += w * (l2 + r2);
        s3 += w * (l3 + r3);
        l3 = l2;
        l2 = l1;
        l1 = l0;
        l0 = sh_get(c - i - 1);
        r0 = r1;
        r1 = r2;
        r2 = r3;
        r3 = sh_get(c + 3 + i + 1);
    }
    if t.r.x > 0 {
        let w = blur_weight(t.r.x);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        s2 += w * (l2 + r2);
        s3 += w * (l3 + r3);
    }
    store(t, vec2<i32>(x, 0), s0);
    store(t, vec2<i32>(x + 1, 0), s1);
    store(t, vec2<i32>(x + 2, 0), s2);
    store(t, vec2<i32>(x + 3, 0), s3);
}

// The row's blur along x, invocation li's outputs.
fn blur_row(t: Tile, li: u32) {
    if ROW_RUN == 4u {
        // A constant condition, as RUN's.
        blur_row_quads(t, li);
    } else if ROW_RUN == 2u {
        blur_row_pairs(t, li);
    } else {
        // One output an invocation (ROW = WG_SIZE).
        store(t, vec2<i32>(i32(li), 0), sum_x(t, i32(li), 0));
    }
}

// The importing kernel's `main`: workgroup `wg`, invocation `li`.
fn encode_blur(wg: vec2<u32>, li: u32) {
    let t = tile_of(wg);
    // GPU_LAYOUT and REDESIGN are constants at each pipeline: each layout compiles its own
    // branches.
    if REDESIGN && params.blur.axis == 2u {
        blur_columns(t, li);
    } else if GPU_LAYOUT {
        encode_tile(t, li);
        if params.blur.axis == 2u {
            // A constant condition: each kernel compiles one of the two.
            if RUN == 4u {
                blur_tile_runs(t, li);
            } else {
                blur_tile_single(t, li);
            }
        } else {
            blur_row(t, li);
        }
    } else if params.blur.axis == 2u {
        blur_tile_strips(t, li);
    } else {
        // The row path's WG_SIZE invocations, CPU_LANES at a time.
        for (var v = li; v < WG_SIZE; v += LANES) {
            encode_blocks(t, v);
        }
        workgroupBarrier();
        for (var v = li; v < WG_SIZE; v += LANES) {
            blur_row(t, v);
        }
    }
}

// The entry point of every kernel that imports this module.
@compute @workgroup_size(LANES)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    encode_blur(wg.xy, li);
}
