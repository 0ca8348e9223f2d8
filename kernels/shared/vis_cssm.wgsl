// Convolution soft shadow maps (Annen et al. 2008; seed 000), every step a summed-area-table
// lookup: over the blocker-search square, the CSM basis gives E[f] and the CSM-Z basis
// E[f̄·z], hence the blocker share and z_avg (blocker_csm_z); the PCSS penumbra width
// w = size·(Z − Z_b)/Z_b sets the square of the CSM lookup; its response is shifted, scaled
// about ½ and clamped to [0, 1] as CSM's (csm_resolve: the clamp cuts the ringing), then
// sharpened selectively, v^p with p = 1 + A·exp(−B (d − z_avg)): near contact (d ≈ z_avg),
// where the smooth Fourier step leaks light and the penumbra is narrow, the darkening is
// strongest; it fades as the receiver leaves its blockers. A square without blockers
// (share < BLOCKER_MIN_SHARE) is lit.
// The shading block (technique::cssm's `visibility`) reads, at the search width snapped
// outward to texel edges (`sat_search_*`, 4 loads a table), either (`blocker_search =
// "moments"`, the default) MSM's quantized moments' table, which gives `cssm_blocker_moments`, or
// (`"csm_z"`, the paper's) sums `csm_z_chunk_of` over the light's CSM-Z tables and
// `csm_chunk_of` over its basis tables, which gives `cssm_blocker`; where that
// finds blockers, a loop of `soft_filter_trips` trips sums the basis tables again at
// `blocker_filter_width(l, s, b.x)`, the square's edges rounded to the nearest texel edges
// (`sat_filter_*`, 4 loads a table), for `cssm_resolve`.
// #import shared/light
// #import shared/sat_lookup
// #import shared/blocker
// #import shared/vis_csm

fn cssm_blocker(below: f32, zsum: f32, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_csm_z(below, zsum, s.depth - l.bias);
}

// `blocker_search = "moments"`: from MSM's quantized moments over the search square,
// dequantized and biased by `l.moment_bias` as `msm_soft`'s (msm_biased: the light's
// `msm_flags` say quantized), msm_soft's three-point estimate (blocker_msm).
fn cssm_blocker_moments(m: vec4<f32>, l: Light, s: LightSample) -> vec2<f32> {
    return blocker_msm(msm_biased(m, l), s.depth - l.bias);
}

// v^p for v in [0, 1], p ≥ 1 (0 at v = 0, where log2 is −∞).
fn cssm_sharpen(v: f32, p: f32) -> f32 {
    return select(0.0, exp2(p * log2(v)), v > 0.0);
}

// The visibility from the basis sum at the filter width and the blocker estimate `b` (which
// found blockers: share ≥ BLOCKER_MIN_SHARE).
fn cssm_resolve(sum: f32, b: vec2<f32>, l: Light, s: LightSample) -> f32 {
    let v = csm_resolve(sum, l);
    let gap = max(s.depth - l.bias - b.x, 0.0);
    let p = 1.0 + l.sharpen * exp(-l.sharpen_falloff * gap);
    return cssm_sharpen(v, p);
}
