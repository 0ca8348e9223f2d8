// One pass of a separable blur (Gaussian or box with fractional edge weights) over every
// channel of any float representation, as a weighted sum or, for logarithmic representations
// (ESM's c·z), as a log-sum-exp. A workgroup filters WG_SIZE texels of one line: it loads
// the line segment and its halo into workgroup memory once (one read per texel plus the halo),
// then each invocation sums 2r + 1 taps from there. Edges clamp (replicate the border texel), so
// the map edge keeps its shadow instead of fading toward zero.
// Storage: rg32float by default; the executor re-declares `dst` for the bound format.

// Keep in sync with `BlurParams` in src/filter.rs.
struct Params {
    axis: u32,                        // 0 horizontal, 1 vertical
    radius: u32,                      // taps each side, ≤ MAX_RADIUS
    mode: u32,                        // 0 weighted sum; 1 log Σ w exp(v) (texels hold logs)
    _pad: u32,
    weights: array<vec4<f32>, 9>,     // weight of offset i at weights[i / 4][i % 4], i = 0..=32
}

// Traffic (the cost model, src/graph/cost): each workgroup loads its line segment and a halo of
// `radius` texels on either side.
// #traffic src: WG_SIZE + 2 * min(params.radius, MAX_RADIUS) per group
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var<uniform> params: Params;

const WG_SIZE: u32 = 128u;
const MAX_RADIUS: u32 = 32u;

var<workgroup> sh_tile: array<vec4<f32>, 192>; // WG_SIZE + 2 · MAX_RADIUS

fn weight(i: u32) -> f32 {
    return params.weights[i / 4u][i % 4u];
}

// Texel `a` along the axis on line `b`, clamped to the map.
fn load(a: i32, b: i32, size: vec2<i32>) -> vec4<f32> {
    var p = vec2<i32>(a, b);
    if params.axis == 1u {
        p = vec2<i32>(b, a);
    }
    return textureLoad(src, clamp(p, vec2<i32>(0), size - 1), 0);
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let size = vec2<i32>(textureDimensions(src));
    let r = i32(min(params.radius, MAX_RADIUS));
    let line = i32(wg.y);
    let start = i32(wg.x * WG_SIZE) - r;
    for (var t = i32(li); t < i32(WG_SIZE) + 2 * r; t += i32(WG_SIZE)) {
        sh_tile[t] = load(start + t, line, size);
    }
    workgroupBarrier();
    let a = i32(wg.x * WG_SIZE + li);
    let along = select(size.x, size.y, params.axis == 1u);
    if a >= along {
        return;
    }
    let c = i32(li) + r;
    var acc: vec4<f32>;
    if params.mode == 1u {
        // log-sum-exp around the largest tap: every exp ≤ 1, nothing overflows at any c.
        var m = sh_tile[c];
        for (var i = 1; i <= r; i++) {
            m = max(m, max(sh_tile[c - i], sh_tile[c + i]));
        }
        var sum = weight(0u) * exp(sh_tile[c] - m);
        for (var i = 1; i <= r; i++) {
            sum += weight(u32(i)) * (exp(sh_tile[c - i] - m) + exp(sh_tile[c + i] - m));
        }
        acc = m + log(sum);
    } else {
        acc = weight(0u) * sh_tile[c];
        for (var i = 1; i <= r; i++) {
            acc += weight(u32(i)) * (sh_tile[c - i] + sh_tile[c + i]);
        }
    }
    var p = vec2<i32>(a, line);
    if params.axis == 1u {
        p = vec2<i32>(line, a);
    }
    textureStore(dst, p, acc);
}
