// Convolution soft shadow maps (Annen et al. 2008; seed 000), every step a summed-area-table
// lookup: over the blocker-search square, the CSM basis gives E[f] and the CSM-Z basis
// E[f̄·z], hence the blocker share and z_avg (blocker_csm_z); the PCSS penumbra width
// w = size·(Z − Z_b)/Z_b sets the square of the CSM lookup; its response is shifted, scaled
// about ½ and clamped to [0, 1] as CSM's (csm_resolve: the clamp cuts the ringing), then
// sharpened selectively, v^p with p = 1 + A·exp(−B (d − z_avg)): near contact (d ≈ z_avg),
// where the smooth Fourier step leaks light and the penumbra is narrow, the darkening is
// strongest; it fades as the receiver leaves its blockers. By default (`resolve =
// "two_depth"`, this project's) away from contact the series is instead inverted for the share
// of blockers at their depth z_b (cssm_resolve; cssm_filter_blockers). A square without blockers (share < BLOCKER_MIN_SHARE)
// is lit.
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

// The blockers' depth over the filter square for the two-depth resolve (`resolve =
// "two_depth"` with the moment search): from the moments' table's mean there `m`, dequantized,
// VSSM's estimate (blocker_vsm: Chebyshev's share behind d, the rest's mean) from its first two
// moments, variance floored at CSSM_BLOCKER_FLOOR; where it finds no blockers, the search's
// z_avg. The search square is wider than the filter's where the blockers are near the receiver
// and holds other blockers: its z_avg, in front of the filter square's blockers, under-darkens
// their umbra (measured on `point`: umbra error 0.161 against 0.085).
fn cssm_filter_blockers(m: vec4<f32>, look: SoftLookup, l: Light, s: LightSample) -> f32 {
    let b = select(m, msm_dequantize(m), (l.msm_flags & 2u) != 0u);
    let f = blocker_vsm(b, s.depth - l.bias, CSSM_BLOCKER_FLOOR);
    return select(look.blocker.x, f.x, f.y >= BLOCKER_MIN_SHARE);
}

// The variance floor of cssm_filter_blockers (linear depth units²).
const CSSM_BLOCKER_FLOOR: f32 = 1e-6;

// v^p for v in [0, 1], p ≥ 1 (0 at v = 0, where log2 is −∞).
fn cssm_sharpen(v: f32, p: f32) -> f32 {
    return select(0.0, exp2(p * log2(v)), v > 0.0);
}

// The two series of the two-depth resolve in one loop: (Σ_k w_k sin(c_k x_r)·sinc(c_k a.x)·
// sinc(c_k a.y), Σ_k w_k sin(c_k x_b)), i.e. f − ½ at depth offset x_r as the mean over a
// square on a plane whose depth changes by ±a (linear depth units) from the square's centre to
// its edges along u and v (the mean of sin(c(x + a.x·u + a.y·v)) over u, v ∈ [−1, 1] is
// sin(c x)·sinc(c a.x)·sinc(c a.y), sinc(t) = sin(t)/t), and f − ½ at x_b. The sines of
// c_k = π(2k − 1) times the four arguments advance by a rotation of 2π·argument per term (four
// multiply-adds instead of a sine: the loop runs at every shaded pixel with blockers), the
// weights as csm_terms_chunk's.
fn cssm_two_series(x_r: f32, a: vec2<f32>, x_b: f32, l: Light) -> vec2<f32> {
    let v = vec4<f32>(x_r, x_b, a);
    var sn = sin(CSM_PI * v);
    var cs = cos(CSM_PI * v);
    let step_sin = 2.0 * sn * cs;
    let step_cos = cs * cs - sn * sn;
    // The weights' Gaussian factors as csm_terms_start advances them.
    var w = csm_terms_start(0.0, l);
    var sum = vec2<f32>(0.0);
    for (var k = 1u; k <= l.csm_terms; k++) {
        let c = CSM_PI * f32(2u * k - 1u);
        let t = c * a;
        let sinc = select(vec2<f32>(1.0), sn.zw / t, abs(t) > vec2<f32>(1e-4));
        sum += (2.0 / c * w.gauss) * vec2<f32>(sn.x * sinc.x * sinc.y, sn.y);
        csm_terms_advance(&w);
        let next = sn * step_cos + cs * step_sin;
        cs = cs * step_cos - sn * step_sin;
        sn = next;
    }
    return sum;
}

// The visibility from the basis sum at the filter width, the search's lookup `look` (which
// found blockers: share ≥ BLOCKER_MIN_SHARE) and the blockers' depth z_b (look's z_avg, or
// cssm_filter_blockers').
// The paper's resolve: CSM's clamp (csm_resolve, v₁), then v₁^p. The clamp has a dead zone: a
// square whose share of blockers is small reads 1 (lit), as the series leaks light at blockers
// near the receiver (at M = 4 a blocker 0.1 in front reads f = 0.63), and v^p cannot darken 1:
// thin blockers lose their shadow (measured on `pole`).
// `l.cssm_two_depth`: the square modelled as the receiver's plane and blockers at z_b,
// E[f] = (1 − σ)·f_r + σ·f_b with f_r the series' mean over the plane (cssm_two_series, the
// slope from the G-buffer normal) and f_b the series at z_b, gives the blockers' share
// σ = (f_r − E[f]) / (f_r − f_b) and v₂ = 1 − σ, with no dead zone. min(v₁, v₂): where the
// blockers spread in depth (an umbra of several surfaces), v₂ under-darkens and the clamp does
// not. The contrast f_r − f_b is the inversion's divisor: below 0.3 (blockers within about
// 1/(2M) of the receiver, contact) the paper's v₁^p, blended in up to 0.6.
fn cssm_resolve(sum: f32, look: SoftLookup, z_b: f32, l: Light, s: LightSample) -> f32 {
    let v1 = csm_resolve(sum, l);
    let gap = max(s.depth - l.bias - look.blocker.x, 0.0);
    let p = 1.0 + l.sharpen * exp(-l.sharpen_falloff * gap);
    let sharpened = cssm_sharpen(v1, p);
    if l.cssm_two_depth == 0u {
        return sharpened;
    }
    let d = s.depth - l.bias - l.csm_offset;
    let f = cssm_two_series(s.depth - d, s.depth_slope * (0.5 * look.width), z_b - d, l);
    let f_r = f.x;
    let contrast = f.x - f.y;
    let v2 = clamp(1.0 - (f_r - sum) / max(contrast, CSSM_MIN_CONTRAST), 0.0, 1.0);
    return mix(sharpened, min(v1, v2), smoothstep(CSSM_MIN_CONTRAST, CSSM_FULL_CONTRAST, contrast));
}

// The two-depth resolve's blend over the series' contrast f_r − f_b (cssm_resolve).
const CSSM_MIN_CONTRAST: f32 = 0.3;
const CSSM_FULL_CONTRAST: f32 = 0.6;
