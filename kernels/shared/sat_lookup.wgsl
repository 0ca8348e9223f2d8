// The `sat` filter's lookups for the shading side (import-only module): a light's filtered
// representation at a receiver as the mean over a square of `width` shadow-map texels centred
// on it, from the light's summed-area table, four lookups per channel (sixteen with the
// sub-texel edges) whatever the width. Any other rectangle, e.g. a per-pixel penumbra width,
// goes through `sat_rect` with that width.
// #import shared/light
// #import shared/sat

// The square of `width` texels centred on uv, in texel units (x0, y0, x1, y1).
fn sat_rect(l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    let c = uv * l.map_size;
    let h = vec2<f32>(0.5 * width);
    return vec4<f32>(c - h, c + h);
}

// The mean over `sat_rect(l, uv, width)` from a fixed-point table (rgba32uint).
// #fetches sat_sample_fixed: 16
fn sat_sample_fixed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_mean_fixed(map, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// `sat_sample_fixed` of the table `layer` of `map` (shared/sat's SatLayer).
// #fetches sat_sample_layer: 16
fn sat_sample_layer(map: texture_2d<u32>, layer: SatLayer, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_layer_mean(map, layer, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// The mean over `sat_rect(l, uv, width)` from an f32 table (rgba32float). Sixteen loads, not
// four filtered fetches: the loads' window sums are differences of neighbouring table texels,
// exact to the table, where a filtered fetch rounds each corner relative to the whole corner
// sum; at the `sat` filter's few-texel widths that rounding reached the moments (MSM at width
// 3 on a 512² map read shadow in 6% of lit pixels).
// #fetches sat_sample_float: 16
fn sat_sample_float(map: texture_2d<f32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_mean_float(map, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// The square `sat_rect(l, uv, width)` with its edges rounded to the nearest texel edges (ties
// to even, as `round`), at least one texel wide.
fn sat_nearest(r: vec4<f32>) -> vec4<f32> {
    let lo = round(r.xy);
    return vec4<f32>(lo, max(round(r.zw), lo + 1.0));
}

// The soft techniques' filter from a fixed-point table: the exact mean over
// `sat_rect(l, uv, width)` (`sat_sample_fixed`, 16 loads). Their box changes width and centre
// per pixel, so edges rounded to the nearest texel edges (4 loads) move it by up to half a
// texel at the map's texel pitch: a mean error that cannot be seen in the mean against the
// area-light truth, and a staircase of the texel grid across every penumbra that can (the
// mean |Laplacian| of the penumbra several times the exact square's).
// #fetches sat_filter_fixed: sat_sample_fixed
fn sat_filter_fixed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_sample_fixed(map, l, uv, width);
}

// CSSM's filter window over tables of `size`: the square `sat_rect(l, uv, width)` with its
// edges rounded to the nearest texel edges (`sat_nearest`), one integer window that several
// tables of one size are read over (`sat_layer_window` each, 4 loads a table: CSSM's five).
fn sat_filter_window(l: Light, uv: vec2<f32>, width: f32, size: vec2<u32>) -> vec4<i32> {
    return sat_box(sat_nearest(sat_rect(l, uv, width)), size);
}

// From an f32 table the soft filter needs no rounding: four filtered fetches give the mean
// over the square itself, its edges on the 2⁻⁸-texel grid (`sat_mean_linear`; `smp` filters
// linearly). Each corner is rounded relative to its sum, which the penumbra's wide squares
// divide by their area (against the area-light truth at 1024² no change from the fixed-point
// table's rounded squares).
// #fetches sat_filter_float: sat_mean_linear
fn sat_filter_float(map: texture_2d<f32>, smp: sampler, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_mean_linear(map, smp, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// The mean over `sat_rect(l, uv, width)` snapped outward to texel edges (`sat_box_*`): the
// blocker search's estimate in four loads.
// #fetches sat_search_fixed: 4
fn sat_search_fixed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_box_fixed(map, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// The blocker search in cells (Yang et al. 2010, "Variance Soft Shadow Mapping", §4.3: a
// kernel that is not planar is subdivided): the search square snapped outward to texel edges,
// as `sat_search_*` reads it, cut at texel edges into 2 × 2 cells, each cell's mean from the
// table. One estimate over a wide square fails where the receiver's own texels fill it: a plane
// seen by a spot light stores a linear depth whose mean over a square lies behind its centre
// (1/z, not z, is affine across the map), and a few blockers in front cannot pull the mean in
// front of the receiver, so the estimate reads no blockers and a long shadow's far end is cut
// off along an arc. A cell holds a quarter of the plane's spread in depth and its blockers at
// up to four times their share. The cells meet at X0 + ⌊(X1 − X0)/2⌋ (and the same along y):
// a square one texel wide has an empty column of cells (area 0), which weighs nothing. Each of
// the 3 × 3 corners is loaded once; no arrays and no loops (private arrays indexed in a loop
// live in memory on a GPU and on llvmpipe alike).
struct SearchCells {
    m00: vec4<f32>,    // each cell's mean: (left, top), (right, top), (left, bottom), (right, bottom)
    m10: vec4<f32>,
    m01: vec4<f32>,
    m11: vec4<f32>,
    area: vec4<f32>,   // the four cells' texels in that order (0: an empty cell)
}

// The cells' integer window (`sat_box` of the search square, x0, y0, x1, y1) and where they
// meet (the x and y of the middle edges).
fn search_window(l: Light, uv: vec2<f32>, width: f32, size: vec2<u32>) -> vec4<i32> {
    return sat_box(sat_rect(l, uv, width), size);
}

fn search_middle(b: vec4<i32>) -> vec2<i32> {
    return b.xy + (b.zw - b.xy) / 2;
}

// The four cells' texels.
fn search_areas(b: vec4<i32>, mid: vec2<i32>) -> vec4<f32> {
    let w = vec2<f32>(vec2<i32>(mid.x - b.x, b.z - mid.x));
    let h = vec2<f32>(vec2<i32>(mid.y - b.y, b.w - mid.y));
    return vec4<f32>(w.x * h.x, w.y * h.x, w.x * h.y, w.y * h.y);
}

// The cells of the search square from a fixed-point table (rgba32uint): nine corners, four
// wrapping integer windows.
// #fetches sat_search_cells_fixed: 9
fn sat_search_cells_fixed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, width: f32) -> SearchCells {
    let layer = sat_alone();
    let b = search_window(l, uv, width, sat_layer_size(map, layer));
    let mid = search_middle(b);
    let f00 = sat_layer_node(map, layer, b.x, b.y);
    let f10 = sat_layer_node(map, layer, mid.x, b.y);
    let f20 = sat_layer_node(map, layer, b.z, b.y);
    let f01 = sat_layer_node(map, layer, b.x, mid.y);
    let f11 = sat_layer_node(map, layer, mid.x, mid.y);
    let f21 = sat_layer_node(map, layer, b.z, mid.y);
    let f02 = sat_layer_node(map, layer, b.x, b.w);
    let f12 = sat_layer_node(map, layer, mid.x, b.w);
    let f22 = sat_layer_node(map, layer, b.z, b.w);
    let area = search_areas(b, mid);
    let a = max(area, vec4<f32>(1.0));
    var c: SearchCells;
    c.m00 = vec4<f32>(bitcast<vec4<i32>>((f11 - f01) - (f10 - f00))) / (l.sat_scale * a.x) + l.sat_offset;
    c.m10 = vec4<f32>(bitcast<vec4<i32>>((f21 - f11) - (f20 - f10))) / (l.sat_scale * a.y) + l.sat_offset;
    c.m01 = vec4<f32>(bitcast<vec4<i32>>((f12 - f02) - (f11 - f01))) / (l.sat_scale * a.z) + l.sat_offset;
    c.m11 = vec4<f32>(bitcast<vec4<i32>>((f22 - f12) - (f21 - f11))) / (l.sat_scale * a.w) + l.sat_offset;
    c.area = area;
    return c;
}

// The cells of the search square from an f32 table (rgba32float).
// #fetches sat_search_cells_float: 9
fn sat_search_cells_float(map: texture_2d<f32>, l: Light, uv: vec2<f32>, width: f32) -> SearchCells {
    let b = search_window(l, uv, width, textureDimensions(map));
    let mid = search_middle(b);
    let f00 = sat_node_f32(map, b.x, b.y);
    let f10 = sat_node_f32(map, mid.x, b.y);
    let f20 = sat_node_f32(map, b.z, b.y);
    let f01 = sat_node_f32(map, b.x, mid.y);
    let f11 = sat_node_f32(map, mid.x, mid.y);
    let f21 = sat_node_f32(map, b.z, mid.y);
    let f02 = sat_node_f32(map, b.x, b.w);
    let f12 = sat_node_f32(map, mid.x, b.w);
    let f22 = sat_node_f32(map, b.z, b.w);
    let area = search_areas(b, mid);
    let a = max(area, vec4<f32>(1.0));
    var c: SearchCells;
    c.m00 = ((f11 - f01) - (f10 - f00)) / (l.sat_scale * a.x) + l.sat_offset;
    c.m10 = ((f21 - f11) - (f20 - f10)) / (l.sat_scale * a.y) + l.sat_offset;
    c.m01 = ((f12 - f02) - (f11 - f01)) / (l.sat_scale * a.z) + l.sat_offset;
    c.m11 = ((f22 - f12) - (f21 - f11)) / (l.sat_scale * a.w) + l.sat_offset;
    c.area = area;
    return c;
}

// `sat_search_fixed` of the table `layer` of `map`.
// #fetches sat_search_layer: 4
fn sat_search_layer(map: texture_2d<u32>, layer: SatLayer, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_layer_box(map, layer, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// #fetches sat_search_float: 4
fn sat_search_float(map: texture_2d<f32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_box_float(map, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}
