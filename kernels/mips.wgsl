// Two levels of a mip chain per dispatch: level `a` from `src`, then level `b` from level `a`
// kept in workgroup memory. The executor chains dispatches down to 1×1; the first copies the
// input into level 0 (a = src size) and reduces it into level 1.
//
// Each texel is the area-weighted mean of the texels it covers, so any size (odd, non-square,
// one texel wide) keeps the map's mean exactly: with level sizes max(1, n >> m), a texel j of an
// n_to-texel level covers [j·n_from/n_to, (j+1)·n_from/n_to) of the n_from-texel level above,
// that is 1, 2 or a fraction of up to 4 texels per axis. Weights are exact integer ratios.
// For logarithmic representations (ESM's c·z) the mean is taken of exp(v), as a log-sum-exp.
// Storage: rgba32float by default; the executor re-declares `dst_a`/`dst_b` for the bound format.

// Keep in sync with `MipParams` in src/filter.rs.
struct Params {
    src_size: vec2<u32>,
    a_size: vec2<u32>,
    b_size: vec2<u32>,   // (0, 0): write level a only
    mode: u32,           // 0 mean; 1 log of the mean of exp
    _pad: u32,
}

// Traffic (the cost model, src/graph/cost): each dispatch reads the level above once and writes
// its two levels.
// #traffic src: all
// #traffic dst_a: all
// #traffic dst_b: all
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst_a: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var dst_b: texture_storage_2d<rgba32float, write>;
@group(0) @binding(3) var<uniform> params: Params;

const TILE: u32 = 8u;
// Level-a texels a tile of level b needs per axis: 8 texels at a ratio of at most 3, plus the
// partly covered texel at either end.
const SPAN: u32 = 26u;

var<workgroup> sh_a: array<vec4<f32>, 676>; // SPAN²

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

// Texel `j` of level a, reduced from `src`.
fn reduce_src(j: vec2<u32>) -> vec4<f32> {
    let rx = covered(j.x, params.src_size.x, params.a_size.x);
    let ry = covered(j.y, params.src_size.y, params.a_size.y);
    var m = vec4<f32>(-3.0e38);
    if params.mode == 1u {
        for (var y = ry.x; y < ry.y; y++) {
            for (var x = rx.x; x < rx.y; x++) {
                m = max(m, textureLoad(src, vec2<u32>(x, y), 0));
            }
        }
    }
    var acc = vec4<f32>(0.0);
    for (var y = ry.x; y < ry.y; y++) {
        let wy = weight(y, j.y, params.src_size.y, params.a_size.y);
        for (var x = rx.x; x < rx.y; x++) {
            let w = wy * weight(x, j.x, params.src_size.x, params.a_size.x);
            let v = textureLoad(src, vec2<u32>(x, y), 0);
            if params.mode == 1u {
                acc += w * exp(v - m);
            } else {
                acc += w * v;
            }
        }
    }
    if params.mode == 1u {
        return m + log(acc);
    }
    return acc;
}

@compute @workgroup_size(TILE, TILE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let a = params.a_size;
    let only_a = params.b_size.x == 0u;
    let b = select(params.b_size, a, only_a);
    let t0 = wg.xy * TILE;
    let t1 = min(t0 + TILE, b);
    // Level-a texels this tile's level-b texels cover.
    let lo = t0 * a / b;
    let hi = (t1 * a + b - 1u) / b;
    let span = hi - lo;
    let count = span.x * span.y;
    let li = lid.y * TILE + lid.x;
    for (var k = li; k < count; k += TILE * TILE) {
        let o = vec2<u32>(k % span.x, k / span.x);
        let j = lo + o;
        let v = reduce_src(j);
        sh_a[o.y * SPAN + o.x] = v;
        // The tile whose level-b texel contains j's first corner writes it, exactly once.
        let owner = j * b / a;
        if all(owner >= t0) && all(owner < t1) {
            textureStore(dst_a, j, v);
        }
    }
    workgroupBarrier();
    let j = t0 + lid.xy;
    if only_a || any(j >= t1) {
        return;
    }
    let rx = covered(j.x, a.x, b.x);
    let ry = covered(j.y, a.y, b.y);
    var m = vec4<f32>(-3.0e38);
    if params.mode == 1u {
        for (var y = ry.x; y < ry.y; y++) {
            for (var x = rx.x; x < rx.y; x++) {
                m = max(m, sh_a[(y - lo.y) * SPAN + (x - lo.x)]);
            }
        }
    }
    var acc = vec4<f32>(0.0);
    for (var y = ry.x; y < ry.y; y++) {
        let wy = weight(y, j.y, a.y, b.y);
        for (var x = rx.x; x < rx.y; x++) {
            let w = wy * weight(x, j.x, a.x, b.x);
            let v = sh_a[(y - lo.y) * SPAN + (x - lo.x)];
            if params.mode == 1u {
                acc += w * exp(v - m);
            } else {
                acc += w * v;
            }
        }
    }
    if params.mode == 1u {
        acc = m + log(acc);
    }
    textureStore(dst_b, j, acc);
}
