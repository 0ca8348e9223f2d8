// Summed-area-table lookups for the shading side (import-only module): the mean of the
// representation over any axis-aligned rectangle, from a SAT built by the sat_* kernels.
//
// Coordinates are texel units: texel (i, j) covers [i, i + 1) × [j, j + 1), so a shadow-map
// UV maps to uv · size. SAT texel (i, j) holds the sum over texels [0, i] × [0, j], which is
// F(i + 1, j + 1) with F(x, y) the integral of the piecewise-constant map over [0, x] × [0, y].
// Inside a texel F is bilinear in (x, y), so F at a fractional corner is the bilinear mix of
// four SAT texels and the integral over the rectangle is exact for fractional edges. Each of
// the 16 corner-pair boxes below is an integer-edged window sum: in fixed point it is taken
// with wrapping u32 arithmetic and is exact while its true value fits in an i32 (the scale
// rule of src/sat.rs, with the window one texel larger than the rectangle each way); only
// then is it weighted in f32.
//
// A rectangle is ordered, clamped to the map and, where thinner than SAT_MIN_EXTENT, widened
// to it inside the map (the mean then tends to the point value, never 0/0). Channels the
// representation does not have hold 0 in the table and decode to `offset`.

const SAT_MIN_EXTENT: f32 = 0.00390625; // 2⁻⁸ texel

// The integer corner nodes of a clamped rectangle and their bilinear weights:
// x = (i0, i0 + 1, i1, i1 + 1) with i0 = ⌊x0⌋, i1 = ⌊x1⌋ (clamped to the map),
// wx = (1 − fract(x0), fract(x0), 1 − fract(x1), fract(x1)); the same for y.
struct SatNodes {
    x: vec4<i32>,
    y: vec4<i32>,
    wx: vec4<f32>,
    wy: vec4<f32>,
    area: f32,
}

fn sat_nodes(rect: vec4<f32>, size: vec2<u32>) -> SatNodes {
    let s = vec2<f32>(size);
    let lo0 = clamp(min(rect.xy, rect.zw), vec2<f32>(0.0), s);
    let hi0 = clamp(max(rect.xy, rect.zw), vec2<f32>(0.0), s);
    let lo = min(lo0, s - SAT_MIN_EXTENT);
    let hi = max(hi0, lo + SAT_MIN_EXTENT);
    let i0 = floor(lo);
    let i1 = floor(hi);
    let a0 = lo - i0;
    let a1 = hi - i1;
    let top = vec2<i32>(size);
    var n: SatNodes;
    n.x = min(vec4<i32>(i32(i0.x), i32(i0.x) + 1, i32(i1.x), i32(i1.x) + 1), vec4<i32>(top.x));
    n.y = min(vec4<i32>(i32(i0.y), i32(i0.y) + 1, i32(i1.y), i32(i1.y) + 1), vec4<i32>(top.y));
    n.wx = vec4<f32>(1.0 - a0.x, a0.x, 1.0 - a1.x, a1.x);
    n.wy = vec4<f32>(1.0 - a0.y, a0.y, 1.0 - a1.y, a1.y);
    n.area = (hi.x - lo.x) * (hi.y - lo.y);
    return n;
}

// F(X, Y) at integer nodes: 0 on the top and left edges, else SAT texel (X − 1, Y − 1).
// #fetches sat_node_u32: 1
fn sat_node_u32(sat: texture_2d<u32>, x: i32, y: i32) -> vec4<u32> {
    if x == 0 || y == 0 {
        return vec4<u32>(0u);
    }
    return textureLoad(sat, vec2<i32>(x - 1, y - 1), 0);
}

// #fetches sat_node_f32: 1
fn sat_node_f32(sat: texture_2d<f32>, x: i32, y: i32) -> vec4<f32> {
    if x == 0 || y == 0 {
        return vec4<f32>(0.0);
    }
    return textureLoad(sat, vec2<i32>(x - 1, y - 1), 0);
}

// Mean of the representation over `rect` = (x0, y0, x1, y1), texel units, from a fixed-point
// SAT (rgba32uint) encoded with `offset` and `scale` (SatCoding in src/sat.rs).
// With F at the left edge a mix over r and at the right edge over p (weights summing to 1),
// F(x1) − F(x0) = Σ_r,p wx0_r·wx1_p·(F(X1_p) − F(X0_r)): a weighted sum of integer windows.
// #fetches sat_mean_fixed: 16
fn sat_mean_fixed(sat: texture_2d<u32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let n = sat_nodes(rect, textureDimensions(sat));
    var f: array<vec4<u32>, 16>;
    for (var j = 0; j < 4; j++) {
        for (var i = 0; i < 4; i++) {
            f[j * 4 + i] = sat_node_u32(sat, n.x[i], n.y[j]);
        }
    }
    var sum = vec4<f32>(0.0);
    for (var s = 0; s < 2; s++) {
        for (var q = 2; q < 4; q++) {
            for (var r = 0; r < 2; r++) {
                for (var p = 2; p < 4; p++) {
                    // Wrapping differences: exact whatever the SAT values are.
                    let window = f[q * 4 + p] - f[q * 4 + r] - f[s * 4 + p] + f[s * 4 + r];
                    let w = n.wx[r] * n.wx[p] * n.wy[s] * n.wy[q];
                    sum += w * vec4<f32>(bitcast<vec4<i32>>(window));
                }
            }
        }
    }
    return sum / (scale * n.area) + offset;
}

// The same from an f32 SAT (rgba32float) built with `offset` and `scale` (scale is 1 for the
// f32 variant). Each window is a difference of f32 sums: its error grows with the sums at the
// corners (about 2⁻²⁴ of the sum over [0, X] × [0, Y] each), not with the window.
// #fetches sat_mean_float: 16
fn sat_mean_float(sat: texture_2d<f32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let n = sat_nodes(rect, textureDimensions(sat));
    var f: array<vec4<f32>, 16>;
    for (var j = 0; j < 4; j++) {
        for (var i = 0; i < 4; i++) {
            f[j * 4 + i] = sat_node_f32(sat, n.x[i], n.y[j]);
        }
    }
    var sum = vec4<f32>(0.0);
    for (var s = 0; s < 2; s++) {
        for (var q = 2; q < 4; q++) {
            for (var r = 0; r < 2; r++) {
                for (var p = 2; p < 4; p++) {
                    let window = (f[q * 4 + p] - f[q * 4 + r]) - (f[s * 4 + p] - f[s * 4 + r]);
                    sum += n.wx[r] * n.wx[p] * n.wy[s] * n.wy[q] * window;
                }
            }
        }
    }
    return sum / (scale * n.area) + offset;
}
