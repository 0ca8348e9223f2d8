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
//
// An f32 table can also be read with bilinear-filtered fetches (`sat_mean_linear`): the
// hardware's bilinear mix of four SAT texels at a fractional corner is the same F as above,
// so four filtered fetches give the exact integral that the sixteen loads give. Filtering
// hardware keeps 8 fractional bits of the weights (the minimum Vulkan and D3D require, and
// what NVIDIA and AMD keep), so the corners are put on the 2⁻⁸-texel grid first: a weight
// there is exact on every device, and the mean is exact for a rectangle whose edges moved by
// at most 2⁻⁹ texel (`sat_grid`). Off the grid, the truncated weights would move each edge
// by up to 2⁻⁸ texel while the mean is divided by the unmoved area: a relative error of the
// mean's distance to `offset` of 2⁻⁷ / width, which the variance of two moments turns into
// light leaks (4·10⁻³ of variance at width 1).

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

// `rect` ordered, clamped to the map and widened to SAT_MIN_EXTENT inside it: (lo, hi).
fn sat_clamp(rect: vec4<f32>, size: vec2<u32>) -> vec4<f32> {
    let s = vec2<f32>(size);
    let lo0 = clamp(min(rect.xy, rect.zw), vec2<f32>(0.0), s);
    let hi0 = clamp(max(rect.xy, rect.zw), vec2<f32>(0.0), s);
    let lo = min(lo0, s - SAT_MIN_EXTENT);
    return vec4<f32>(lo, max(hi0, lo + SAT_MIN_EXTENT));
}

fn sat_nodes(rect: vec4<f32>, size: vec2<u32>) -> SatNodes {
    let c = sat_clamp(rect, size);
    let lo = c.xy;
    let hi = c.zw;
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

// Where a fixed-point table lies in its texture: `n` tables interleaved along x
// (src/sat/layers.rs), this one at slot `k`, its texel (x, y) at (x·n + k, y). Reading the
// same corner of several interleaved tables reads one run of memory, not a cache line a
// table (CSSM's filter lookups). A table of its own is `sat_alone()`.
struct SatLayer {
    n: i32,
    k: i32,
}

fn sat_alone() -> SatLayer {
    return SatLayer(1, 0);
}

// The size of the table `layer` of `sat`.
fn sat_layer_size(sat: texture_2d<u32>, layer: SatLayer) -> vec2<u32> {
    let d = textureDimensions(sat);
    return vec2<u32>(d.x / u32(layer.n), d.y);
}

// F(X, Y) at integer nodes: 0 on the top and left edges, else SAT texel (X − 1, Y − 1) of the
// table `layer`. The load is made unconditionally (at a clamped texel) and the edge selected
// after: a branch per load costs a CPU driver a divergent branch per node and a GPU nothing
// either way.
// #fetches sat_layer_node: 1
fn sat_layer_node(sat: texture_2d<u32>, layer: SatLayer, x: i32, y: i32) -> vec4<u32> {
    let t = max(vec2<i32>(x - 1, y - 1), vec2<i32>(0));
    let v = textureLoad(sat, vec2<i32>(t.x * layer.n + layer.k, t.y), 0);
    return select(v, vec4<u32>(0u), x == 0 || y == 0);
}

// #fetches sat_node_f32: 1
fn sat_node_f32(sat: texture_2d<f32>, x: i32, y: i32) -> vec4<f32> {
    let v = textureLoad(sat, max(vec2<i32>(x - 1, y - 1), vec2<i32>(0)), 0);
    return select(v, vec4<f32>(0.0), x == 0 || y == 0);
}

// The exact integral as nine integer windows: the nodes X = (i0, i0 + 1, i1, i1 + 1) cut the
// x axis into three spans [X_k, X_k+1), the left texel column (weight 1 − fract(x0)), the
// whole columns between (weight 1) and the right column (weight fract(x1)); the same for y.
// F(x1) − F(x0) = (1 − a0)·C(i0) + Σ_(i0 < i < i1) C(i) + a1·C(i1) is Σ_k w_k·(F(X_k+1) − F(X_k))
// with w = (1 − a0, 1, a1), also for i0 = i1 (the middle span is then [i0 + 1, i0): −C(i0),
// and the weights sum to a1 − a0). Every window lies inside [X0, X3) × [Y0, Y3), so in fixed
// point each is exact under the same scale rule as before; nine conversions and products
// instead of sixteen overlapping windows.
fn sat_span_weights(w: vec4<f32>) -> vec3<f32> {
    return vec3<f32>(w.x, 1.0, w.w);
}

// Mean of the representation over `rect` = (x0, y0, x1, y1), texel units, from a fixed-point
// SAT (rgba32uint) encoded with `offset` and `scale` (SatCoding in src/sat.rs).
// #fetches sat_mean_fixed: 16
fn sat_mean_fixed(sat: texture_2d<u32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    return sat_layer_mean(sat, sat_alone(), rect, offset, scale);
}

// `sat_mean_fixed` of the table `layer` of `sat`.
// #fetches sat_layer_mean: 16
fn sat_layer_mean(sat: texture_2d<u32>, layer: SatLayer, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let n = sat_nodes(rect, sat_layer_size(sat, layer));
    let wx = sat_span_weights(n.wx);
    let wy = sat_span_weights(n.wy);
    // Row differences first: d[j][k] = F(X_k+1, Y_j) − F(X_k, Y_j), wrapping.
    var d: array<vec4<u32>, 12>;
    for (var j = 0; j < 4; j++) {
        let f0 = sat_layer_node(sat, layer, n.x[0], n.y[j]);
        let f1 = sat_layer_node(sat, layer, n.x[1], n.y[j]);
        let f2 = sat_layer_node(sat, layer, n.x[2], n.y[j]);
        let f3 = sat_layer_node(sat, layer, n.x[3], n.y[j]);
        d[j * 3] = f1 - f0;
        d[j * 3 + 1] = f2 - f1;
        d[j * 3 + 2] = f3 - f2;
    }
    var sum = vec4<f32>(0.0);
    for (var m = 0; m < 3; m++) {
        var row = vec4<f32>(0.0);
        for (var k = 0; k < 3; k++) {
            // Wrapping differences: exact whatever the SAT values are.
            let window = d[(m + 1) * 3 + k] - d[m * 3 + k];
            row += wx[k] * vec4<f32>(bitcast<vec4<i32>>(window));
        }
        sum += wy[m] * row;
    }
    return sum / (scale * n.area) + offset;
}

// The same from an f32 SAT (rgba32float) built with `offset` and `scale` (scale is 1 for the
// f32 variant). Each window is a difference of f32 sums: its error grows with the sums at the
// corners (about 2⁻²⁴ of the sum over [0, X] × [0, Y] each), not with the window.
// #fetches sat_mean_float: 16
fn sat_mean_float(sat: texture_2d<f32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let n = sat_nodes(rect, textureDimensions(sat));
    let wx = sat_span_weights(n.wx);
    let wy = sat_span_weights(n.wy);
    var d: array<vec4<f32>, 12>;
    for (var j = 0; j < 4; j++) {
        let f0 = sat_node_f32(sat, n.x[0], n.y[j]);
        let f1 = sat_node_f32(sat, n.x[1], n.y[j]);
        let f2 = sat_node_f32(sat, n.x[2], n.y[j]);
        let f3 = sat_node_f32(sat, n.x[3], n.y[j]);
        d[j * 3] = f1 - f0;
        d[j * 3 + 1] = f2 - f1;
        d[j * 3 + 2] = f3 - f2;
    }
    var sum = vec4<f32>(0.0);
    for (var m = 0; m < 3; m++) {
        var row = vec4<f32>(0.0);
        for (var k = 0; k < 3; k++) {
            row += wx[k] * (d[(m + 1) * 3 + k] - d[m * 3 + k]);
        }
        sum += wy[m] * row;
    }
    return sum / (scale * n.area) + offset;
}

// Mean over the rectangle snapped outward to texel edges, [⌊x0⌋, ⌈x1⌉) × [⌊y0⌋, ⌈y1⌉) after
// the clamp of `sat_nodes`: one integer window, four loads. For estimates (the blocker search)
// where a square up to one texel wider per side reads as well as the exact one.
// #fetches sat_box_fixed: 4
fn sat_box_fixed(sat: texture_2d<u32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    return sat_layer_box(sat, sat_alone(), rect, offset, scale);
}

// `sat_box_fixed` of the table `layer` of `sat`.
// #fetches sat_layer_box: 4
fn sat_layer_box(sat: texture_2d<u32>, layer: SatLayer, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    return sat_layer_window(sat, layer, sat_box(rect, sat_layer_size(sat, layer)), offset, scale);
}

// The mean over the integer window b (x0, y0, x1, y1; `sat_box`'s) of the fixed-point table
// `layer` of `sat`, four loads. Several tables of one size read over one square share the
// window's computation (CSSM's filter lookups).
// #fetches sat_layer_window: 4
fn sat_layer_window(sat: texture_2d<u32>, layer: SatLayer, b: vec4<i32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let window = sat_layer_node(sat, layer, b.z, b.w) - sat_layer_node(sat, layer, b.x, b.w)
        - sat_layer_node(sat, layer, b.z, b.y) + sat_layer_node(sat, layer, b.x, b.y);
    let area = f32((b.z - b.x) * (b.w - b.y));
    return vec4<f32>(bitcast<vec4<i32>>(window)) / (scale * area) + offset;
}

// #fetches sat_box_float: 4
fn sat_box_float(sat: texture_2d<f32>, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let b = sat_box(rect, textureDimensions(sat));
    let window = (sat_node_f32(sat, b.z, b.w) - sat_node_f32(sat, b.x, b.w))
        - (sat_node_f32(sat, b.z, b.y) - sat_node_f32(sat, b.x, b.y));
    let area = f32((b.z - b.x) * (b.w - b.y));
    return window / (scale * area) + offset;
}

// Fractional corners of `sat_mean_linear` are multiples of 1 / SAT_GRID texel.
const SAT_GRID: f32 = 256.0;

// `sat_clamp`'s rectangle with its edges on the 2⁻⁸-texel grid (nearest, ties up) and at
// least one grid step wide, within [0, size] (a clamped edge is on the grid already).
fn sat_grid(rect: vec4<f32>, size: vec2<u32>) -> vec4<f32> {
    let c = sat_clamp(rect, size);
    let lo = floor(c.xy * SAT_GRID + 0.5) / SAT_GRID;
    let hi = floor(c.zw * SAT_GRID + 0.5) / SAT_GRID;
    return vec4<f32>(lo, max(hi, lo + 1.0 / SAT_GRID));
}

// F(x, y), every channel, at a point of [0, width] × [0, height] from one bilinear fetch:
// SAT texel (X − 1, Y − 1) holds F(X, Y) and is centred at (X − ½, Y − ½), so for x, y ≥ 1 F
// is the filtered fetch at (x − ½, y − ½). Below 1 F falls linearly to 0 at the top and left
// edges, where the table has no texels: F(x, y) = min(x, 1)·min(y, 1)·F(max(x, 1), max(y, 1))
// (F is bilinear on [0, 1]² between 0 and the first nodes). `smp` filters linearly and clamps
// to the edge; the level is explicit, so the fetch is defined in non-uniform control flow.
// With `size` a power of two, (x − ½) / size is exact and so is the hardware's weight.
// #fetches sat_corner_linear: 1
fn sat_corner_linear(sat: texture_2d<f32>, smp: sampler, p: vec2<f32>, size: vec2<f32>) -> vec4<f32> {
    let q = max(p, vec2<f32>(1.0));
    let f = textureSampleLevel(sat, smp, (q - 0.5) / size, 0.0);
    let edge = min(p, vec2<f32>(1.0));
    return f * (edge.x * edge.y);
}

// The mean of `sat_mean_float` over `rect` on the 2⁻⁸-texel grid (`sat_grid`) in four
// filtered fetches of an f32 table (rgba32float … r32float, bound filterable), where
// `sat_mean_float` makes sixteen loads. The f32 rounding is the same: each corner is a sum
// over [0, x] × [0, y], rounded relative to it.
// #fetches sat_mean_linear: 4
fn sat_mean_linear(sat: texture_2d<f32>, smp: sampler, rect: vec4<f32>, offset: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    let dims = textureDimensions(sat);
    let size = vec2<f32>(dims);
    let r = sat_grid(rect, dims);
    let window = (sat_corner_linear(sat, smp, r.zw, size) - sat_corner_linear(sat, smp, r.xw, size))
        - (sat_corner_linear(sat, smp, r.zy, size) - sat_corner_linear(sat, smp, r.xy, size));
    let area = (r.z - r.x) * (r.w - r.y);
    return window / (scale * area) + offset;
}

// The integer nodes (X0, Y0, X1, Y1) of `sat_nodes`' rectangle snapped outward: X0 = ⌊x0⌋,
// X1 = ⌈x1⌉ (> X0: the rectangle is at least SAT_MIN_EXTENT wide), within [0, size].
fn sat_box(rect: vec4<f32>, size: vec2<u32>) -> vec4<i32> {
    let c = sat_clamp(rect, size);
    return vec4<i32>(vec2<i32>(floor(c.xy)), min(vec2<i32>(ceil(c.zw)), vec2<i32>(size)));
}
