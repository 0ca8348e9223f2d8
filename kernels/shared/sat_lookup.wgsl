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

// The mean over `sat_rect(l, uv, width)` with its edges rounded to the nearest texel edges
// (`sat_nearest`, then `sat_box_*`): the soft techniques' filter in four loads. Their box
// changes width and centre per pixel; moving its edges by at most half a texel moved the mean
// error against the area-light truth by under 1% (5% in one of 27 configurations) on
// sphere_on_plane, pole and stacked, where the exact integral (`sat_sample_*`) reads 16.
// #fetches sat_filter_fixed: 4
fn sat_filter_fixed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_box_fixed(map, sat_nearest(sat_rect(l, uv, width)), l.sat_offset, l.sat_scale);
}

// `sat_filter_fixed`'s integer window over tables of `size`, for several tables of one size
// read over one square (`sat_layer_window` each): CSSM's five.
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

// `sat_search_fixed` of the table `layer` of `map`.
// #fetches sat_search_layer: 4
fn sat_search_layer(map: texture_2d<u32>, layer: SatLayer, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_layer_box(map, layer, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}

// #fetches sat_search_float: 4
fn sat_search_float(map: texture_2d<f32>, l: Light, uv: vec2<f32>, width: f32) -> vec4<f32> {
    return sat_box_float(map, sat_rect(l, uv, width), l.sat_offset, l.sat_scale);
}
