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
//     each, then blur it along x and along y there (shared/encode_blur_tile: `blur_tile_runs`,
//     `blur_tile_single`);
//   a CPU driver's: CPU_LANES invocations walk the tile in strips (shared/encode_blur_strips:
//     `blur_tile_strips`): each walks an encoded row along x, loading each depth once and
//     encoding it in registers, and keeps the horizontal sums; then each walks a column of
//     those sums and stores. On llvmpipe, which runs every SIMD group of a workgroup through
//     every branch and barrier under masks, this ran 2–3× faster than the GPU's layout
//     (benches/RESULTS.md, 2026-11-28); on a GPU its few invocations a tile would leave most
//     of each SM idle.
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
// #import shared/encode_blur_tile
// #import shared/encode_blur_strips

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
