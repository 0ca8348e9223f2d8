// The mip chain's redesign after AMD FidelityFX SPD (`ffx_spd.h`, the Single Pass Downsampler,
// and its WebGPU port): import-only module of `mips_spd` and `mips_spd_log`, which the executor
// compiles in place of `mips` and `mips_log` in the `redesign` kernel layout only
// (`exec::KernelLayout::kernel_source`); `gpu` and `cpu` run shared/mip_chain. The dispatches,
// their parameters and bindings are shared/mip_chain's (`filter::mip_chain`): a workgroup owns
// 64 × 64 texels of level s and writes levels s + 1 … s + 6 of them, each texel the same
// reduction of the same four values in the same order, so the chain is bit for bit the same.
//
// What differs is how a workgroup works. shared/mip_chain: 64 invocations, 16 serial steps each
// over level s + 1, which it keeps whole in workgroup memory (21.3 KiB: a third of an H200's
// threads resident). Here, as SPD: 256 invocations, each issuing all 16 loads of its 4 × 4
// texels of level s first, reducing them to its 2 × 2 texels of level s + 1 and its one texel of
// level s + 2 in registers (SPD's quad reduction across four lanes, done in one invocation: no
// subgroup feature, no barrier), and only level s + 2 onwards (16 × 16, then 8 × 8 … 1) through
// workgroup memory, 5.3 KiB. Invocations are laid out as SPD's `ARmpRed8x8`: each 64 of them an
// 8 × 8 square, so a SIMD group's loads cover a compact block of level s.
// Storage: rgba32float by default; the executor re-declares `dst0` … `dst6` for the format.

// Keep in sync with `MipParams` in src/filter.rs (shared/mip_chain's `Params`).
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

const WG: u32 = 16u;     // invocations per axis: one per level s + 2 texel of the tile
const TILE: u32 = 32u;   // level s + 1 texels per workgroup and axis

// Level s + 2 (16 × 16, row-major) at [0, 256), s + 3 at [256, 320), s + 4 at [320, 336),
// s + 5 at [336, 340), s + 6 at [340].
var<workgroup> sh_level: array<vec4<f32>, 341>;

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

// Texel j of level s + 1, reduced from `src` (any ratio): shared/mip_chain's `reduce_src`,
// the same sums in the same order; with `copy`, the texels whose first corner lies in j are
// stored as level 0 on the way (each exactly once).
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

// The four texels of level s whose quad is texel j of level s + 1, in the order a, b, c, d of
// `quad`, from its corner q: each read clamped into the level, so that a side of one texel
// kept repeats its texel, as shared/mip_chain's `halve_src` reads it (its step 0), and a
// texel past an edge only feeds texels past the edges of the levels below, never stored.
struct Quad {
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
}

fn load_quad(q: vec2<u32>, n: vec2<u32>) -> Quad {
    let last = n - 1u;
    return Quad(
        textureLoad(src, min(q, last), 0),
        textureLoad(src, min(q + vec2<u32>(1u, 0u), last), 0),
        textureLoad(src, min(q + vec2<u32>(0u, 1u), last), 0),
        textureLoad(src, min(q + vec2<u32>(1u, 1u), last), 0),
    );
}

// The quad at q stored as level 0 (the first dispatch's copy; texels past the edge skipped).
fn copy_quad(t: Quad, q: vec2<u32>) {
    store(0u, q, t.a);
    store(0u, q + vec2<u32>(1u, 0u), t.b);
    store(0u, q + vec2<u32>(0u, 1u), t.c);
    store(0u, q + vec2<u32>(1u, 1u), t.d);
}

// Texel j of level s + 1 from its quad of level s; 0 outside the level (as shared/mip_chain).
fn level1(t: Quad, j: vec2<u32>, log_mode: bool) -> vec4<f32> {
    if any(j >= level_size(params.first + 1u)) {
        return vec4<f32>(0.0);
    }
    let v = quad(t.a, t.b, t.c, t.d, params.first, log_mode);
    store(1u, j, v);
    return v;
}

// Texel j of level s + 2: its four quads of level s loaded first (16 loads in flight), then
// its 2 × 2 texels of level s + 1, then itself, all stored.
fn level2(j: vec2<u32>, log_mode: bool) -> vec4<f32> {
    let n = level_size(params.first);
    let q = 4u * j;
    let t0 = load_quad(q, n);
    let t1 = load_quad(q + vec2<u32>(2u, 0u), n);
    let t2 = load_quad(q + vec2<u32>(0u, 2u), n);
    let t3 = load_quad(q + vec2<u32>(2u, 2u), n);
    if params.copy == 1u {
        copy_quad(t0, q);
        copy_quad(t1, q + vec2<u32>(2u, 0u));
        copy_quad(t2, q + vec2<u32>(0u, 2u));
        copy_quad(t3, q + vec2<u32>(2u, 2u));
    }
    let o = 2u * j;
    let a = level1(t0, o, log_mode);
    let b = level1(t1, o + vec2<u32>(1u, 0u), log_mode);
    let c = level1(t2, o + vec2<u32>(0u, 1u), log_mode);
    let d = level1(t3, o + vec2<u32>(1u, 1u), log_mode);
    let v = quad(a, b, c, d, params.first + 1u, log_mode);
    store(2u, j, v);
    return v;
}

// Invocation `li` (0 … 255) of the workgroup as SPD lays it out (`ARmpRed8x8`): each 64 an
// 8 × 8 square of the 16 × 16, row-major within it.
fn spd_position(li: u32) -> vec2<u32> {
    let square = li / 64u;
    let at = li % 64u;
    return vec2<u32>(at % 8u + 8u * (square % 2u), at / 8u + 8u * (square / 2u));
}

// Workgroup `wg`, invocation `li` of the dispatch (workgroups of WG × WG).
fn mip_dispatch(wg: vec2<u32>, li: u32, log_mode: bool) {
    let s = params.first;
    if params.count == 0u {
        // A 1×1 map: level 0 is the chain.
        if all(wg == vec2<u32>(0u)) && li == 0u {
            store(0u, vec2<u32>(0u), textureLoad(src, vec2<u32>(0u), 0));
        }
        return;
    }
    let p = spd_position(li);
    if params.general == 1u {
        // An odd level read: level s + 1 alone, four texels an invocation, in a loop (one copy
        // of the general reduction in the code).
        for (var k = 0u; k < 4u; k++) {
            let j = wg * TILE + p * 2u + vec2<u32>(k % 2u, k / 2u);
            if all(j < level_size(s + 1u)) {
                store(1u, j, reduce_src(j, log_mode));
            }
        }
        return;
    }
    sh_level[p.y * WG + p.x] = level2(wg * WG + p, log_mode);
    if params.count <= 2u {
        return; // uniform: every invocation reads the same `params`
    }
    // Levels s + 3 … s + 6 from workgroup memory: 8 × 8, 4 × 4, 2 × 2, 1 texel a workgroup.
    var side = WG;
    var at_level = 0u;
    for (var k = 3u; k <= 6u; k++) {
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
