// Variance soft shadow maps (Yang et al. 2010) from a summed-area table of the VSM moments:
// the moments over the blocker-search square give the blocker share and depth (blocker_vsm),
// the PCSS penumbra width follows, and the VSM bound (vis_vsm_of: variance floor, bleed
// reduction) is read from the moments over that width. Two table lookups per receiver; both
// are made before the result is chosen (lit when the share is below BLOCKER_MIN_SHARE).
// `vis_vssm_fixed` reads a fixed-point table (rgba32uint), `vis_vssm_float` an f32 one.
// #import shared/light
// #import shared/sat_lookup
// #import shared/blocker
// #import shared/vis_vsm

fn vssm_blocker(m: vec4<f32>, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_vsm(m, s.depth - l.bias, l.min_variance);
}

// The visibility from the moments `m` at the filter width and the blocker estimate `b`.
fn vssm_resolve(m: vec4<f32>, b: vec2<f32>, l: Light, s: LightSample) -> f32 {
    return select(1.0, vis_vsm_of(m, l, s), b.y >= BLOCKER_MIN_SHARE);
}

// #fetches vis_vssm_fixed: 2 * sat_sample_fixed
fn vis_vssm_fixed(map: texture_2d<u32>, l: Light, s: LightSample) -> f32 {
    let b = vssm_blocker(sat_sample_fixed(map, l, s.uv, blocker_search_width(l, s)), l, s);
    let m = sat_sample_fixed(map, l, s.uv, blocker_filter_width(l, s, b.x));
    return vssm_resolve(m, b, l, s);
}

// #fetches vis_vssm_float: 2 * sat_sample_float
fn vis_vssm_float(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let b = vssm_blocker(sat_sample_float(map, l, s.uv, blocker_search_width(l, s)), l, s);
    let m = sat_sample_float(map, l, s.uv, blocker_filter_width(l, s, b.x));
    return vssm_resolve(m, b, l, s);
}
