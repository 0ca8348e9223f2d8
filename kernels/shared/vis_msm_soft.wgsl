// Moment soft shadow maps (after Peters et al. 2016) from a summed-area table of the MSM
// moments (raw or quantized): the biased moments over the blocker-search square give the
// blocker share and depth from the Hamburger reconstruction (blocker_msm), the PCSS penumbra
// width follows, and MSM's visibility (vis_msm_of: Hamburger or Hausdorff, bleed reduction) is
// read from the moments over that width. The search reads the
// square snapped outward to texel edges in 2 × 2 cells (`sat_search_cells_*`: 9 loads; the
// cells' estimates combined, so that the receiver's own texels filling a wide square cannot
// hide its blockers), the filter the exact square (`sat_filter_*`), in a loop of
// `soft_filter_trips` trips: a receiver whose search square holds no blockers (share below
// BLOCKER_MIN_SHARE) is lit after the search.
// `vis_msm_soft_fixed` reads a fixed-point table (rgba32uint), `vis_msm_soft_float` an f32 one.
// #import shared/light
// #import shared/sat_lookup
// #import shared/blocker
// #import shared/vis_msm

fn msm_soft_blocker(m: vec4<f32>, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_msm(msm_biased(m, l), s.depth - l.bias);
}

// The blocker estimate of the search square's cells (`sat_search_cells_*`), combined.
fn msm_soft_search(c: SearchCells, l: Light, s: LightSample) -> vec2<f32> {
    var acc = blocker_add(BlockerSum(0.0, 0.0, 0.0), msm_soft_blocker(c.m00, l, s), c.area.x);
    acc = blocker_add(acc, msm_soft_blocker(c.m10, l, s), c.area.y);
    acc = blocker_add(acc, msm_soft_blocker(c.m01, l, s), c.area.z);
    acc = blocker_add(acc, msm_soft_blocker(c.m11, l, s), c.area.w);
    return blocker_total(acc, s.depth - l.bias);
}

// #fetches vis_msm_soft_fixed: sat_search_cells_fixed + sat_filter_fixed
fn vis_msm_soft_fixed(map: texture_2d<u32>, l: Light, s: LightSample) -> f32 {
    let search = sat_search_cells_fixed(map, l, s.uv, blocker_search_width(l, s));
    let look = soft_blockers(msm_soft_search(search, l, s), l, s);
    var m = vec4<f32>(0.0);
    for (var k = 0u; k < soft_filter_trips(look); k++) {
        m = sat_filter_fixed(map, l, s.uv, look.width);
    }
    if !look.blockers {
        return 1.0;
    }
    return vis_msm_of(m, l, s);
}

// #fetches vis_msm_soft_float: sat_search_cells_float + sat_filter_float
fn vis_msm_soft_float(map: texture_2d<f32>, smp: sampler, l: Light, s: LightSample) -> f32 {
    let search = sat_search_cells_float(map, l, s.uv, blocker_search_width(l, s));
    let look = soft_blockers(msm_soft_search(search, l, s), l, s);
    var m = vec4<f32>(0.0);
    for (var k = 0u; k < soft_filter_trips(look); k++) {
        m = sat_filter_float(map, smp, l, s.uv, look.width);
    }
    if !look.blockers {
        return 1.0;
    }
    return vis_msm_of(m, l, s);
}
