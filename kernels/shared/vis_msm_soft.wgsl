// Moment soft shadow maps (after Peters et al. 2016) from a summed-area table of the MSM
// moments (raw or quantized): the biased moments over the blocker-search square give the
// blocker share and depth from the Hamburger reconstruction (blocker_msm), the PCSS penumbra
// width follows, and MSM's visibility (vis_msm_of: Hamburger or Hausdorff, bleed reduction) is
// read from the moments over that width. The search reads the
// square snapped outward to texel edges (`sat_search_*`: 4 loads; the square grows by less
// than a texel per side, an estimate either way), the filter the square with its edges rounded
// to the nearest texel edges (`sat_filter_*`: 4 loads), in a loop of `soft_filter_trips` trips: a receiver whose search square holds no blockers
// (share below BLOCKER_MIN_SHARE) is lit after the search.
// `vis_msm_soft_fixed` reads a fixed-point table (rgba32uint), `vis_msm_soft_float` an f32 one.
// #import shared/light
// #import shared/sat_lookup
// #import shared/blocker
// #import shared/vis_msm

fn msm_soft_blocker(m: vec4<f32>, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_msm(msm_biased(m, l), s.depth - l.bias);
}

// #fetches vis_msm_soft_fixed: sat_search_fixed + sat_filter_fixed
fn vis_msm_soft_fixed(map: texture_2d<u32>, l: Light, s: LightSample) -> f32 {
    let search = sat_search_fixed(map, l, s.uv, blocker_search_width(l, s));
    let look = soft_blockers(msm_soft_blocker(search, l, s), l, s);
    var m = vec4<f32>(0.0);
    for (var k = 0u; k < soft_filter_trips(look); k++) {
        m = sat_filter_fixed(map, l, s.uv, look.width);
    }
    if !look.blockers {
        return 1.0;
    }
    return vis_msm_of(m, l, s);
}

// #fetches vis_msm_soft_float: sat_search_float + sat_filter_float
fn vis_msm_soft_float(map: texture_2d<f32>, smp: sampler, l: Light, s: LightSample) -> f32 {
    let search = sat_search_float(map, l, s.uv, blocker_search_width(l, s));
    let look = soft_blockers(msm_soft_blocker(search, l, s), l, s);
    var m = vec4<f32>(0.0);
    for (var k = 0u; k < soft_filter_trips(look); k++) {
        m = sat_filter_float(map, smp, l, s.uv, look.width);
    }
    if !look.blockers {
        return 1.0;
    }
    return vis_msm_of(m, l, s);
}
