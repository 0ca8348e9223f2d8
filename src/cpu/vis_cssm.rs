//! Reference of `kernels/shared/vis_cssm.wgsl` (with the body `technique::visibility_body`
//! generates around it), in the three steps of [`super::vis_vssm`]: the search's means over
//! the search square (MSM's quantized moments, or the CSM and CSM-Z series), the blocker estimate,
//! the CSM visibility at the penumbra width, sharpened or (`two_depth`) inverted.

use super::blocker::{self, Blocker};
use super::light::LightSample;
use super::sat::Integral;
use crate::model::CssmSearch;
use crate::wgsl_mirrors::LightGpu;

/// A CSSM light's representations, each per texel as its tables sum them.
#[derive(Clone, Copy, Debug)]
pub struct Maps<'a> {
    /// The CSM basis, `2M` channels or more (sin, cos per term; padding zeros after).
    pub basis: &'a Integral,
    /// The blocker search's representation: MSM's quantized moments `(z, z², z³, z⁴)`
    /// ([`CssmSearch::Moments`]) or the CSM-Z basis, `2M + 1` channels or more
    /// (`kernels/shared/csm_maps.wgsl`'s order; [`CssmSearch::CsmZ`]).
    pub search: &'a Integral,
    /// Which of the two `search` holds.
    pub kind: CssmSearch,
}

/// The search's means over the search square snapped outward to texel edges: the four
/// moments, or the two series `[below, zsum]` = \[E\[f\] − ½, E\[f̄·z\]\].
pub fn search(maps: Maps, l: &LightGpu, s: &LightSample) -> Vec<f64> {
    let w = blocker::search_width(l, s);
    let means = maps.search.snapped_square_mean(l.map_size, s.uv, w);
    match maps.kind {
        CssmSearch::Moments => means,
        CssmSearch::CsmZ => {
            let d = super::vis_csm::shifted_depth(l, s);
            let basis = maps.basis.snapped_square_mean(l.map_size, s.uv, w);
            vec![
                super::vis_csm::series(&basis, l, d),
                blocker::csm_z_series(&means, l, d),
            ]
        }
    }
}

/// `cssm_blocker_moments` or `cssm_blocker` from [`search`]'s means.
pub fn blocker_of(kind: CssmSearch, m: &[f64], l: &LightGpu, s: &LightSample) -> Blocker {
    let d = s.depth - f64::from(l.bias);
    match kind {
        CssmSearch::Moments => blocker::msm(&super::vis_msm::biased(m, l), d),
        CssmSearch::CsmZ => blocker::csm_z(m[0], m[1], d),
    }
}

/// The CSM series over the penumbra width of `b`, the square as the table is read
/// ([`Integral::filter_square_mean`]: rounded to texel edges, or on the 2⁻⁸ grid of filtered
/// fetches).
pub fn filtered(maps: Maps, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let w = blocker::filter_width(l, s, b.depth);
    let basis = maps.basis.filter_square_mean(l.map_size, s.uv, w);
    super::vis_csm::series(&basis, l, super::vis_csm::shifted_depth(l, s))
}

/// The sharpening exponent `p = 1 + A·exp(−B·max(d − z_avg, 0))`.
pub fn exponent(l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let gap = (s.depth - f64::from(l.bias) - b.depth).max(0.0);
    1.0 + f64::from(l.sharpen) * (-f64::from(l.sharpen_falloff) * gap).exp()
}

/// `CSSM_MIN_CONTRAST`, `CSSM_FULL_CONTRAST`: the two-depth resolve's blend over the series'
/// contrast `f_r − f_b`.
pub const MIN_CONTRAST: f64 = 0.3;
/// See [`MIN_CONTRAST`].
pub const FULL_CONTRAST: f64 = 0.6;

/// `cssm_two_series` (its first; its second is this at `a = 0`): `Σ w_k sin(c_k x)·sinc(c_k a₀)·
/// sinc(c_k a₁)`, the series `f − ½` at depth offset `x` averaged over a square on a plane whose
/// depth changes by `±a` from the square's centre to its edges. Here each sine directly; the
/// kernel advances them by rotations.
pub fn plane_series(x: f64, a: [f64; 2], l: &LightGpu) -> f64 {
    let sinc = |t: f64| if t.abs() > 1e-4 { t.sin() / t } else { 1.0 };
    (1..=l.csm_terms)
        .map(|k| {
            let c = std::f64::consts::PI * f64::from(2 * k - 1);
            super::vis_csm::weight(k, l) * (c * x).sin() * sinc(c * a[0]) * sinc(c * a[1])
        })
        .sum()
}

/// WGSL's `smoothstep(e0, e1, x)`.
fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// `CSSM_BLOCKER_FLOOR`: the variance floor of [`filter_blockers`].
pub const BLOCKER_FLOOR: f64 = 1e-6;

/// `cssm_filter_blockers`: the blockers' depth over the filter square from the moments' table's
/// mean there `m` (VSSM's estimate from the first two dequantized moments), else `b`'s.
pub fn filter_blockers(m: &[f64], l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let d = s.depth - f64::from(l.bias);
    let f = blocker::vsm(&super::vis_msm::dequantized(m, l), d, BLOCKER_FLOOR);
    if f.found() { f.depth } else { b.depth }
}

/// The blockers' depth the two-depth resolve uses: over the filter square of `width` texels
/// (`l.cssm_two_depth == 2`: the moments' table's mean there) or the search's.
pub fn resolve_depth(maps: Maps, l: &LightGpu, s: &LightSample, b: Blocker, width: f64) -> f64 {
    if l.cssm_two_depth != 2 {
        return b.depth;
    }
    let m = maps.search.filter_square_mean(l.map_size, s.uv, width);
    filter_blockers(&m, l, s, b)
}

/// `cssm_resolve` for the series `sum` at the filter width `width` (texels) of `b`, blockers at
/// depth `z_b` for the two-depth resolve.
pub fn resolve(sum: f64, l: &LightGpu, s: &LightSample, b: Blocker, width: f64, z_b: f64) -> f64 {
    if !b.found() {
        return 1.0;
    }
    let v1 = super::vis_csm::resolve(sum, l);
    let sharpened = v1.powf(exponent(l, s, b));
    if l.cssm_two_depth == 0 {
        return sharpened;
    }
    let d = super::vis_csm::shifted_depth(l, s);
    let half = 0.5 * width;
    let f_r = plane_series(
        s.depth - d,
        [s.depth_slope[0] * half, s.depth_slope[1] * half],
        l,
    );
    let f_b = plane_series(z_b - d, [0.0; 2], l);
    let contrast = f_r - f_b;
    let v2 = (1.0 - (f_r - sum) / contrast.max(MIN_CONTRAST)).clamp(0.0, 1.0);
    let t = smoothstep(MIN_CONTRAST, FULL_CONTRAST, contrast);
    sharpened + (v1.min(v2) - sharpened) * t
}

/// The visibility for blocker estimate `b`.
pub fn finish(maps: Maps, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let width = blocker::filter_width(l, s, b.depth);
    let z_b = resolve_depth(maps, l, s, b, width);
    resolve(filtered(maps, l, s, b), l, s, b, width, z_b)
}

/// CSSM visibility.
pub fn vis_cssm(maps: Maps, l: &LightGpu, s: &LightSample) -> f64 {
    let means = search(maps, l, s);
    finish(maps, l, s, blocker_of(maps.kind, &means, l, s))
}
