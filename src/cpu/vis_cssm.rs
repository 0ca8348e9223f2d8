//! Reference of `kernels/shared/vis_cssm.wgsl` (with the body `technique::visibility_body`
//! generates around it), in the three steps of [`super::vis_vssm`]: the CSM and CSM-Z series
//! over the search square, the blocker estimate, the sharpened CSM visibility at the penumbra
//! width.

use super::blocker::{self, Blocker};
use super::light::LightSample;
use super::sat::Integral;
use crate::gpu_data::LightGpu;

/// A CSSM light's representations, each per texel as its tables sum them.
#[derive(Clone, Copy, Debug)]
pub struct Maps<'a> {
    /// The CSM basis, `2M` channels or more (sin, cos per term; padding zeros after).
    pub basis: &'a Integral,
    /// The CSM-Z basis, `2M + 1` channels or more (`kernels/csm_z.wgsl`'s order).
    pub z: &'a Integral,
}

/// The two series over the search square snapped outward to texel edges: `(below, zsum)` =
/// (E[f] − ½, E[f̄·z]).
pub fn search(maps: Maps, l: &LightGpu, s: &LightSample) -> (f64, f64) {
    let w = blocker::search_width(l, s);
    let d = super::vis_csm::shifted_depth(l, s);
    let basis = maps.basis.snapped_square_mean(l.map_size, s.uv, w);
    let z = maps.z.snapped_square_mean(l.map_size, s.uv, w);
    (
        super::vis_csm::series(&basis, l, d),
        blocker::csm_z_series(&z, l, d),
    )
}

/// `cssm_blocker`.
pub fn blocker_of(below: f64, zsum: f64, l: &LightGpu, s: &LightSample) -> Blocker {
    blocker::csm_z(below, zsum, s.depth - f64::from(l.bias))
}

/// The CSM series over the penumbra width of `b`, the square's edges rounded to the nearest
/// texel edges.
pub fn filtered(maps: Maps, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let w = blocker::filter_width(l, s, b.depth);
    let basis = maps.basis.nearest_square_mean(l.map_size, s.uv, w);
    super::vis_csm::series(&basis, l, super::vis_csm::shifted_depth(l, s))
}

/// The sharpening exponent `p = 1 + A·exp(−B·max(d − z_avg, 0))`.
pub fn exponent(l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    let gap = (s.depth - f64::from(l.bias) - b.depth).max(0.0);
    1.0 + f64::from(l.sharpen) * (-f64::from(l.sharpen_falloff) * gap).exp()
}

/// `cssm_resolve` for the series `sum` at the filter width.
pub fn resolve(sum: f64, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    if !b.found() {
        return 1.0;
    }
    super::vis_csm::resolve(sum, l).powf(exponent(l, s, b))
}

/// The visibility for blocker estimate `b`.
pub fn finish(maps: Maps, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    resolve(filtered(maps, l, s, b), l, s, b)
}

/// CSSM visibility.
pub fn vis_cssm(maps: Maps, l: &LightGpu, s: &LightSample) -> f64 {
    let (below, zsum) = search(maps, l, s);
    finish(maps, l, s, blocker_of(below, zsum, l, s))
}
