// A BENCHMARK VARIANT of kernels/shared/mip_chain.wgsl, not shipped: `benches/gpu_check.sh`
// runs it through SHADOWGRAPH_KERNEL_DIR beside the shipped kernel, and `tests/kernel_dir.rs`
// checks that it renders what the shipped one does. What differs: level s + 1 is not kept in
// workgroup memory (16 KiB of the shipped kernel's 21.3, which on an H200 admits 10 workgroups
// of 64 an SM, a third of its threads); each invocation computes its level s + 2 texels from
// their 2 × 2 level s + 1 texels, each from its 2 × 2 of level s (neighbouring invocations four
// level-s texels apart), the same values in the same order.
//
// One dispatch of a mip chain (import-only module of `mips` and `mips_log`, which differ in
// `LOG_MODE`, passed to every function here as `log_mode`: a constant, so each kernel holds
// one path), up to six levels per dispatch (after AMD FidelityFX SPD): the dispatch reads
// level s (`src`) and writes levels s + 1 … s + count (`dst1` … `dst6`); the executor chains
// dispatches down to 1×1 (a 4096² chain in two). The first dispatch also stores the level it
// reads as level 0 (`dst0`), from the same loads.
//
// Each texel is the area-weighted mean of the texels it covers, so any size keeps the map's
// mean exactly: with level sizes max(1, n >> m), texel j of an n_to-texel level covers
// [j·n_from/n_to, (j+1)·n_from/n_to) of the n_from-texel level above: 2 texels, 1 (a side of
// 1), or fractions of up to 4 when n_from is odd. A level with an odd side > 1 is reduced by a
// dispatch of its own (`general`, one level); the others are exact halvings (or a side of 1
// kept), which a workgroup does from its own texels. For logarithmic representations (ESM's
// c·z) every mean is of exp(v), as a log-sum-exp.
//
// A workgroup owns a 32 × 32 tile of level s + 1 (64 × 64 texels of level s when it halves).
// Its 8 × 8 invocations reduce the tile's level s + 1 texels row by row, invocation li taking
// texels li, li + 64, …, so that at each step neighbouring invocations read neighbouring
// texels of level s (coalesced on a GPU; an invocation owning a 4 × 4 block read texels eight
// apart, and ran at a third of a texture copy on an H100); levels s + 1, s + 2 and s + 4 … s + 6
// meet in workgroup memory, each texel reduced from the same four values in the same order as
// before, so the chain is bit-identical.
// Storage: rgba32float by default; the executor re-declares `dst0` … `dst6` for the format.

// Keep in sync with `MipParams` in src/filter.rs.
struct Params {
    base: vec2<u32>,     // size of level 0
    first: u32,          // the level read, s
    count: u32,          // levels written after it, 0 … 6 (0: a 1×1 map, level 0 only)
    _mode: u32,          // the mode of the node (the kernel's LOG_MODE decides)
    copy: u32,           // 1: also store level s as level 0 (the first dispatch)
    general: u32,        // 1: level s has an odd side > 1; count is 1 (only level s + 1)
    _pad0: u32,
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst0: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var dst1: texture_storage_2d<rgba32float, write>;
@group(0) @binding(3) var dst2: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var dst3: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var dst4: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var dst5: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var dst6: texture_storage_2d<rgba32float, write>;
@group(0) @binding(8) var<uniform> params: Params;

const WG: u32 = 8u;      // invocations per axis
const BLOCK: u32 = 4u;   // level s + 1 texels per invocation and axis
const TILE: u32 = 32u;   // WG · BLOCK

// Levels s + 3 (8 × 8 per workgroup) at [0, 64), s + 4 at [64, 80), s + 5 at [80, 84), s + 6
// at [84].
var<workgroup> sh_level: array<vec4<f32>, 85>;
// The workgroup's level s + 2 (16 × 16, row-major).
var<workgroup> sh_level2: array<vec4<f32>, 256>;

fn level_size(level: u32) -> vec2<u32> {
    return max(params.base >> vec2<u32>(level), vec2<u32>(1u));
}

// Stores v as texel p of level s + k (k = 0: level s itself, the copy).
fn store(k: u32, p: vec2<u32>, v: vec4<f32>) {
    if k > params.count || any(p >= level_size(params.first + k)) {
        return;
    }
    switch k {
        case 0u: { textureStore(dst0, p, v); }
        case 1u: { textureStore(dst1, p, v); }
        case 2u: { textureStore(dst2, p, v); }
        case 3u: { textureStore(dst3, p, v); }
        case 4u: { textureStore(dst4, p, v); }
        case 5u: { textureStore(dst5, p, v); }
        default: { textureStore(dst6, p, v); }
    }
}

// Weight of texel i of an n_from-texel axis in texel j of its n_to-texel reduction.
fn weight(i: u32, j: u32, n_from: u32, n_to: u32) -> f32 {
    let lo = max(i * n_to, j * n_from);
    let hi = min((i + 1u) * n_to, (j + 1u) * n_from);
    if hi <= lo {
        return 0.0;
    }
    return f32(hi - lo) / f32(n_from);
}

// First texel of the n_from axis that texel j of the n_to axis covers, and one past the last.
fn covered(j: u32, n_from: u32, n_to: u32) -> vec2<u32> {
    return vec2<u32>(j * n_from / n_to, ((j + 1u) * n_from + n_to - 1u) / n_to);
}

// Texel j of level s + 1, reduced from `src` (any ratio); with `copy`, the texels whose first
// corner lies in j are stored as level 0 on the way (each exactly once).
fn reduce_src(j: vec2<u32>, log_mode: bool) -> vec4<f32> {
    let n_from = level_size(params.first);
    let n_to = level_size(params.first + 1u);
    let rx = covered(j.x, n_from.x, n_to.x);
    let ry = covered(j.y, n_from.y, n_to.y);
    var m = vec4<f32>(-3.0e38);
    if log_mode {
        for (var y = ry.x; y < ry.y; y++) {
            for (var x = rx.x; x < rx.y; x++) {
                m = max(m, textureLoad(src, vec2<u32>(x, y), 0));
            }
        }
    }
    var acc = vec4<f32>(0.0);
    for (var y = ry.x; y < ry.y; y++) {
        let wy = weight(y, j.y, n_from.y, n_to.y);
        for (var x = rx.x; x < rx.y; x++) {
            let q = vec2<u32>(x, y);
            let v = textureLoad(src, q, 0);
            if params.copy == 1u && all(q * n_to / n_from == j) {
                store(0u, q, v);
            }
            let w = wy * weight(x, j.x, n_from.x, n_to.x);
            if log_mode {
                acc += w * exp(v - m);
            } else {
                acc += w * v;
            }
        }
    }
    if log_mode {
        return m + log(acc);
    }
    return acc;
}

// Texel j of level s + 1 where the level read halves exactly (or keeps a side of 1): the
// quad of its 2 × 2 texels, each stored as level 0 on the way with `copy`. No division: the
// general path's weights and coverage cost llvmpipe most of the pass.
fn halve_src(j: vec2<u32>, log_mode: bool) -> vec4<f32> {
    let n = level_size(params.first);
    let step = select(vec2<u32>(0u), vec2<u32>(1u), n > vec2<u32>(1u));
    let q = j * (step + 1u);
    let a = textureLoad(src, q, 0);
    let b = textureLoad(src, q + vec2<u32>(step.x, 0u), 0);
    let c = textureLoad(src, q + vec2<u32>(0u, step.y), 0);
    let d = textureLoad(src, q + step, 0);
    if params.copy == 1u {
        store(0u, q, a);
        store(0u, q + vec2<u32>(1u, 0u), b);
        store(0u, q + vec2<u32>(0u, 1u), c);
        store(0u, q + vec2<u32>(1u), d);
    }
    return quad(a, b, c, d, params.first, log_mode);
}

// The mean of a and b (of exp, as a log), or a alone where the axis is not halved (a side of
// one texel, kept).
fn pair(a: vec4<f32>, b: vec4<f32>, halved: bool, log_mode: bool) -> vec4<f32> {
    if !halved {
        return a;
    }
    if log_mode {
        let m = max(a, b);
        return m + log(0.5 * (exp(a - m) + exp(b - m)));
    }
    return 0.5 * (a + b);
}

// The 2 × 2 reduction of four texels of `level` (a, b on one row, c, d on the next).
fn quad(
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
    level: u32,
    log_mode: bool,
) -> vec4<f32> {
    let halved = level_size(level) > vec2<u32>(1u);
    let top = pair(a, b, halved.x, log_mode);
    return pair(top, pair(c, d, halved.x, log_mode), halved.y, log_mode);
}

// Texel j of level s + 1 (0 outside the level) where level s halves, stored.
fn level1(j: vec2<u32>, log_mode: bool) -> vec4<f32> {
    if any(j >= level_size(params.first + 1u)) {
        return vec4<f32>(0.0);
    }
    let v = halve_src(j, log_mode);
    store(1u, j, v);
    return v;
}

// Level s + 2's texel `idx` (row-major) of the workgroup's 16 × 16 tile of it, from its
// 2 × 2 texels of level s + 1, each from its 2 × 2 of level s, all stored, level s + 2 kept in
// workgroup memory; `LEVEL2_STEPS` of them per invocation, WG · WG apart.
const LEVEL2_STEPS: u32 = 4u; // (TILE / 2)² / (WG · WG)

fn level2_quads(wg: vec2<u32>, idx: u32, log_mode: bool) {
    let half = TILE / 2u;
    let j = vec2<u32>(idx % half, idx / half);
    let o = wg * TILE + 2u * j;
    let v = quad(
        level1(o, log_mode),
        level1(o + vec2<u32>(1u, 0u), log_mode),
        level1(o + vec2<u32>(0u, 1u), log_mode),
        level1(o + vec2<u32>(1u, 1u), log_mode),
        params.first + 1u,
        log_mode,
    );
    store(2u, wg * half + j, v);
    sh_level2[idx] = v;
}

// Workgroup `wg`, invocation `lid` of the dispatch (workgroups of WG × WG).
fn mip_dispatch(wg: vec2<u32>, lid: vec2<u32>, log_mode: bool) {
    let s = params.first;
    if params.count == 0u {
        // A 1×1 map: level 0 is the chain.
        if all(wg == vec2<u32>(0u)) && all(lid == vec2<u32>(0u)) {
            store(0u, vec2<u32>(0u), textureLoad(src, vec2<u32>(0u), 0));
        }
        return;
    }
    if params.general == 1u {
        // An odd level read: level s + 1 alone, its texels in a loop (one copy of the general
        // reduction in the code: unrolled sixteen times it made llvmpipe compile for seconds).
        for (var k = 0u; k < 16u; k++) {
            let j = wg * TILE + lid * 4u + vec2<u32>(k % 4u, k / 4u);
            if all(j < level_size(s + 1u)) {
                store(1u, j, reduce_src(j, log_mode));
            }
        }
        return;
    }
    // Levels s + 1 and s + 2 in a loop, level s + 2 through workgroup memory; level s + 3:
    // one texel.
    let li = lid.y * WG + lid.x;
    for (var k = 0u; k < LEVEL2_STEPS; k++) {
        level2_quads(wg, li + k * WG * WG, log_mode);
    }
    workgroupBarrier();
    let at = 2u * lid.y * (TILE / 2u) + 2u * lid.x;
    let v3 = quad(
        sh_level2[at],
        sh_level2[at + 1u],
        sh_level2[at + TILE / 2u],
        sh_level2[at + TILE / 2u + 1u],
        s + 2u,
        log_mode,
    );
    store(3u, wg * WG + lid, v3);
    // Levels s + 4 … s + 6 from workgroup memory: 4 × 4, 2 × 2, 1 texel per workgroup.
    sh_level[li] = v3;
    var side = WG;
    var at_level = 0u;
    for (var k = 4u; k <= 6u; k++) {
        workgroupBarrier();
        let half = side / 2u;
        let to = at_level + side * side;
        if li < half * half {
            let o = vec2<u32>(li % half, li / half) * 2u;
            let at = at_level + o.y * side + o.x;
            let v = quad(
                sh_level[at],
                sh_level[at + 1u],
                sh_level[at + side],
                sh_level[at + side + 1u],
                s + k - 1u,
                log_mode,
            );
            sh_level[to + li] = v;
            store(k, wg * half + o / 2u, v);
        }
        at_level = to;
        side = half;
    }
}
