// Moment soft shadow maps (after Peters et al. 2016) from a summed-area table of the MSM
// moments (raw or quantized): the biased moments over the blocker-search square give the
// blocker share and depth from the Hamburger reconstruction (blocker_msm), the PCSS penumbra
// width follows, and MSM's visibility (vis_msm_of: Hamburger or Hausdorff, bleed reduction) is
// read from the moments over that width. Two table lookups per receiver, both made before the
// result is chosen (lit when the share is below BLOCKER_MIN_SHARE).
// `vis_msm_soft_fixed` reads a fixed-point table (rgba32uint), `vis_msm_soft_float` an f32 one.
// #import shared/light
// #import shared/sat_lookup
// #import shared/blocker
// #import shared/vis_msm

fn msm_soft_blocker(m: vec4<f32>, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_msm(msm_biased(m, l), s.depth - l.bias);
}

// The visibility from the moments `m` at the filter width and the blocker estimate `b`.
fn msm_soft_resolve(m: vec4<f32>, b: vec2<f32>, l: Light, s: LightSample) -> f32 {
    return select(1.0, vis_msm_of(m, l, s), b.y >= BLOCKER_MIN_SHARE);
}

// #fetches vis_msm_soft_fixed: 2 * sat_sample_fixed
fn vis_msm_soft_fixed(map: texture_2d<u32>, l: Light, s: LightSample) -> f32 {
    let b = msm_soft_blocker(sat_sample_fixed(map, l, s.uv, blocker_search_width(l, s)), l, s);
    let m = sat_sample_fixed(map, l, s.uv, blocker_filter_width(l, s, b.x));
    return msm_soft_resolve(m, b, l, s);
}

// #fetches vis_msm_soft_float: 2 * sat_sample_float
fn vis_msm_soft_float(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let b = msm_soft_blocker(sat_sample_float(map, l, s.uv, blocker_search_width(l, s)), l, s);
    let m = sat_sample_float(map, l, s.uv, blocker_filter_width(l, s, b.x));
    return msm_soft_resolve(m, b, l, s);
}
