// A tile pass's texel (import-only module of shared/sat_tile_sums and shared/sat_tile_scan,
// apart from shared/sat_tile because it reads the importing kernel's `src` binding, which the
// carries kernel, importing shared/sat_tile for `SatSource`, does not have). The importing
// kernel declares `src: texture_2d<f32>`:
// #completed-by-importer
// #import shared/sat_tile
// #import shared/csm_maps
// #import shared/msm_quantize
// #import shared/storage_round
// #import shared/linear_depth
// #import shared/vsm_moments
// #import shared/evsm_moments

// Non-finite depth texels this invocation's `sat_texel` replaced (depth sources; the first
// tile pass counts layer 0's).
var<private> sat_non_finite: u32;

// The moments of the sub-block a pass sweeps (SUB × SUB, row-major) for the sources that
// `sat_blocked` names, filled by `sat_block_fill` before its sweeps and read by `sat_texel`;
// under GPU_LAYOUT, for the other depth sources, the sub-block's raw depths (in x).
var<private> sat_block: array<vec2<f32>, 16>; // SUB · SUB

// GPU_LAYOUT's workgroup memory (shared/sat_tile). A depth source's tile passes stage the raw
// depth of the tile and a one-texel border in it, (TILE + 2)² texels at `stage_depth_slot`
// (`sat_stage_depth`), which each invocation copies its sub-block from; a stored source's
// stage texel row j of every sub-block row at a time, the row each sweep reads next, channel
// by channel at `stage_row_slot` (`sat_stage_row`); pass 3 writes its table through it the
// same way (shared/sat_tile_scan).
const STAGE_SIDE: u32 = TILE + 2u;
// Depth row pitch: 42 = 2 (mod 8) with a slot of padding every 4 texels, so that the 32 lanes
// of a SIMD group reading their sub-blocks' texels (4 apart along a row, 4 rows apart down)
// hit 32 distinct banks.
const STAGE_PITCH: u32 = 42u;
// Rows staged at a time (one texel row of each of the GRID sub-block rows) and their pitch:
// 33 words, the same banks-apart property for the sub-blocks' accesses and the row's.
const STAGE_ROWS: u32 = GRID;
const STAGE_ROW_PITCH: u32 = TILE + 1u;
const STAGE_PLANE: u32 = STAGE_ROWS * STAGE_ROW_PITCH;
var<workgroup> sh_stage: array<u32, 1428>; // STAGE_SIDE · STAGE_PITCH ≥ 4 · STAGE_PLANE (1056)
const_assert STAGE_SIDE * STAGE_PITCH == 1428u && 4u * STAGE_PLANE <= 1428u;

// The row stage's slot of channel c of staged row r (tile row r·SUB + j of round j, 0 ≤ r <
// STAGE_ROWS), tile column x.
fn stage_row_slot(c: u32, r: u32, x: u32) -> u32 {
    return c * STAGE_PLANE + r * STAGE_ROW_PITCH + x;
}

// GPU_LAYOUT, a stored source (`s.from_depth` false; a no-op otherwise): stages texel row j of
// every sub-block row of tile `tile` (tile rows r·SUB + j), at clamped coordinates as
// `sat_texel` reads them, neighbouring invocations on neighbouring texels. Every invocation
// calls it where a sweep reads row j (it has barriers: the stage's last readers are done
// before it is written, and it is written before it is read).
fn sat_stage_row(tile: vec2<u32>, j: u32, size: vec2<u32>, s: SatSource, li: u32) {
    if GPU_LAYOUT && !s.from_depth {
        workgroupBarrier();
        for (var k = li; k < STAGE_ROWS * TILE; k += WG_SIZE) {
            let r = k / TILE;
            let x = k % TILE;
            let q = tile * TILE + vec2<u32>(x, r * SUB + j);
            let v = bitcast<vec4<u32>>(textureLoad(src, min(q, size - 1u), 0));
            for (var c = 0u; c < 4u; c++) {
                sh_stage[stage_row_slot(c, r, x)] = v[c];
            }
        }
        workgroupBarrier();
    }
}

// The depth stage's slot of bordered-tile texel (x, y), 0 ≤ x, y < STAGE_SIDE.
fn stage_depth_slot(x: u32, y: u32) -> u32 {
    return y * STAGE_PITCH + x + x / 4u;
}

// GPU_LAYOUT: stages the raw depth of tile `tile` and its one-texel border, at clamped
// coordinates, neighbouring invocations on neighbouring texels, and counts the non-finite
// depths of the tile's own texels inside the map (`sat_non_finite`, each texel once: the
// straight layout counts them where it loads them, `sat_raw_own` or `sat_texel`). Every
// invocation calls it (it has a barrier).
fn sat_stage_depth(tile: vec2<u32>, size: vec2<u32>, li: u32) {
    let corner = vec2<i32>(tile * TILE) - 1;
    for (var k = li; k < STAGE_SIDE * STAGE_SIDE; k += WG_SIZE) {
        let x = k % STAGE_SIDE;
        let y = k / STAGE_SIDE;
        let p = corner + vec2<i32>(i32(x), i32(y));
        let q = clamp(p, vec2<i32>(0), vec2<i32>(size) - 1);
        let raw = textureLoad(src, q, 0).r;
        sh_stage[stage_depth_slot(x, y)] = bitcast<u32>(raw);
        let own = all(p == q) && x >= 1u && y >= 1u && x <= TILE && y <= TILE;
        if own && !depth_is_finite(raw) {
            sat_non_finite += 1u;
        }
    }
    workgroupBarrier();
}

// The staged raw depth at map texel p (within one texel of tile `tile`).
fn sat_staged_depth(p: vec2<i32>, tile: vec2<u32>) -> f32 {
    let l = vec2<u32>(p - vec2<i32>(tile * TILE) + 1);
    return bitcast<f32>(sh_stage[stage_depth_slot(l.x, l.y)]);
}

// What a tile pass does before sweeping the sub-block at `origin` of tile `tile`: the
// sub-block's values that `sat_texel` reads from `sat_block` (the blocked sources'; under
// GPU_LAYOUT every depth source's, from the staged tile). Every invocation calls it (under
// GPU_LAYOUT it has a barrier).
fn sat_tile_begin(tile: vec2<u32>, origin: vec2<u32>, size: vec2<u32>, s: SatSource, li: u32) {
    if GPU_LAYOUT {
        if s.from_depth {
            sat_stage_depth(tile, size, li);
        }
        if sat_blocked(s) {
            sat_block_fill(origin, size, s);
        } else if s.from_depth {
            for (var k = 0u; k < SUB * SUB; k++) {
                let p = vec2<i32>(origin) + vec2<i32>(i32(k % SUB), i32(k / SUB));
                sat_block[k] = vec2<f32>(sat_staged_depth(p, tile), 0.0);
            }
        }
    } else if sat_blocked(s) {
        sat_block_fill(origin, size, s);
    }
}

// Whether `s` (literal fields) is computed a sub-block at a time: VSM, whose texels share
// their neighbours' depth, and ESM, whose exp pass 3's two sweeps then share. One- and
// two-channel sources only (a four-channel block would hold 64 values an invocation).
fn sat_blocked(s: SatSource) -> bool {
    return s.from_depth && (s.kind == SAT_VSM || s.kind == SAT_ESM);
}

// The sub-block at `origin`'s moments. VSM's as `vsm` computes them (shared/vsm_moments):
// each texel's derivatives take its four neighbours' depths, clamped to the map; the linear
// depth of the sub-block and its one-texel border is read once, (SUB + 2)² loads, where each
// texel's own five would be 5·SUB² (80 against 36 at SUB = 4; on llvmpipe the table built with
// them per texel ran 1.1× slower than the stored map's, `benches/RESULTS.md`, 2026-11-27).
// ESM's exp(c (z − 1)), one exp a texel a pass instead of one a sweep. Texels past the map's
// edge (ragged tiles) get values that `sat_texel` discards. The sub-block's own non-finite
// depths are counted here (`sat_raw_own`): the sweeps load no depth.
fn sat_block_fill(origin: vec2<u32>, size: vec2<u32>, s: SatSource) {
    if s.kind == SAT_ESM {
        for (var k = 0u; k < SUB * SUB; k++) {
            let at = vec2<i32>(origin) + vec2<i32>(i32(k % SUB), i32(k / SUB));
            let z = linear_depth(sat_raw_own(at, origin, size), s.depth);
            sat_block[k] = vec2<f32>(exp(s.exp_pos * (z - 1.0)), 0.0);
        }
        return;
    }
    const BORDERED: u32 = SUB + 2u;
    var z: array<f32, 36>; // BORDERED²
    for (var k = 0u; k < BORDERED * BORDERED; k++) {
        let at = vec2<i32>(origin) + vec2<i32>(i32(k % BORDERED), i32(k / BORDERED)) - 1;
        z[k] = linear_depth(sat_raw_own(at, origin, size), s.depth);
    }
    for (var k = 0u; k < SUB * SUB; k++) {
        let c = (k / SUB + 1u) * BORDERED + k % SUB + 1u;
        sat_block[k] = vsm_moments(z[c], z[c - 1u], z[c + 1u], z[c - BORDERED], z[c + BORDERED]);
    }
}

// The raw depth of `src` (the depth buffer) at p clamped to the map of `size`, p within one
// texel of the sub-block at `origin`: under GPU_LAYOUT from the staged tile (counted there),
// else loaded, a non-finite depth counted here (`sat_non_finite`) when p is a texel of the
// sub-block inside the map, so that the blocked sources' sweeps load nothing more.
fn sat_raw_own(p: vec2<i32>, origin: vec2<u32>, size: vec2<u32>) -> f32 {
    if GPU_LAYOUT {
        return sat_staged_depth(p, origin / TILE);
    }
    let q = clamp(p, vec2<i32>(0), vec2<i32>(size) - 1);
    let raw = textureLoad(src, q, 0).r;
    let o = vec2<i32>(origin);
    let own = all(p == q) && all(p >= o) && all(p < o + i32(SUB));
    if own && !depth_is_finite(raw) {
        sat_non_finite += 1u;
    }
    return raw;
}

// The encoded texel `q` of `src` (`size` its size) read as `s` says, 0 outside the map (the
// load is clamped to the map and its value discarded, so no invocation branches).
// `src` is the importing kernel's binding, read here and not passed down: the executor's
// packed variant (src/exec/packed.rs) re-declares it `texture_2d<u32>` and unpacks this load
// when the representation is f16 pairs in r32uint words, which a `texture_2d<f32>` parameter
// would not let it do.
fn sat_texel(
    q: vec2<u32>,
    size: vec2<u32>,
    p: SatParams,
    fs: bool,
    s: SatSource,
) -> vec4<u32> {
    let inside = all(q < size);
    // The sub-block's texel (`sat_block`'s index) for the sources it holds.
    let own = q.y % SUB * SUB + q.x % SUB;
    var v: vec4<f32>;
    if s.from_depth {
        // Unused by the blocked sources below, whose `sat_block_fill` loaded and counted it.
        var raw = 0.0;
        if GPU_LAYOUT {
            // Staged by `sat_tile_begin`, counted there.
            raw = sat_block[own].x;
        } else if !sat_blocked(s) {
            raw = textureLoad(src, min(q, size - 1u), 0).r;
            if inside && !depth_is_finite(raw) {
                sat_non_finite += 1u;
            }
        }
        let z = linear_depth(raw, s.depth);
        if s.kind == SAT_MSM {
            // MSM's moments as shared/msm_moments computes them, quantized (a table's always
            // are).
            let z2 = z * z;
            v = msm_quantize(vec4<f32>(z, z2, z2 * z, z2 * z2));
        } else if sat_blocked(s) {
            // VSM's moments or ESM's exp(c (z − 1)) (`esm`'s moment for a summed-area table)
            // of the invocation's sub-block, computed once a pass (`sat_block_fill`;
            // sub-blocks start at multiples of SUB).
            v = vec4<f32>(sat_block[own], 0.0, 0.0);
        } else if s.kind == SAT_EVSM {
            v = evsm_moments(z, s.exp_pos, s.exp_neg);
        } else {
            v = csm_basis_map(s.layer, s.terms, s.moments, z);
        }
        // The storage's rounding, selected rather than branched on: llvmpipe runs a branch's
        // body for every lane, and both roundings are a few integer operations.
        v = select(v, round_f16(v), s.f16);
        v = select(v, round_unorm16(v), s.unorm16);
    } else if GPU_LAYOUT {
        // Staged by `sat_stage_row` for this row of the sweep.
        let l = q % TILE;
        var w: vec4<u32>;
        for (var c = 0u; c < 4u; c++) {
            w[c] = sh_stage[stage_row_slot(c, l.y / SUB, l.x)];
        }
        v = bitcast<vec4<f32>>(w);
    } else {
        v = textureLoad(src, min(q, size - 1u), 0);
    }
    return select(vec4<u32>(0u), sat_encode_as(v, p, fs), inside);
}
