//! Reference of `kernels/shared/vis_msm_soft.wgsl`, in the three steps of
//! [`super::vis_vssm`]: the moments over the search square, the blocker estimate of the
//! biased moments, MSM's visibility at the penumbra width.

use super::blocker::{self, Blocker};
use super::light::LightSample;
use super::sat::Integral;
use crate::gpu_data::LightGpu;

/// The mean (possibly quantized) moments over the blocker-search square snapped outward to
/// texel edges.
pub fn search(moments: &Integral, l: &LightGpu, s: &LightSample) -> Vec<f64> {
    moments.snapped_square_mean(l.map_size, s.uv, blocker::search_width(l, s))
}

/// `msm_soft_blocker`.
pub fn blocker_of(m: &[f64], l: &LightGpu, s: &LightSample) -> Blocker {
    blocker::msm(&super::vis_msm::biased(m, l), s.depth - f64::from(l.bias))
}

/// The mean moments over the penumbra width of `b`, the square as the table is read
/// ([`Integral::filter_square_mean`]: rounded to texel edges, or on the 2⁻⁸ grid of filtered
/// fetches).
pub fn filtered(moments: &Integral, l: &LightGpu, s: &LightSample, b: Blocker) -> Vec<f64> {
    moments.filter_square_mean(l.map_size, s.uv, blocker::filter_width(l, s, b.depth))
}

/// The visibility for blocker estimate `b` (`msm_soft_resolve` after the second lookup).
pub fn finish(moments: &Integral, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    if !b.found() {
        return 1.0;
    }
    super::vis_msm::vis_msm_of(&filtered(moments, l, s, b), l, s)
}

/// Soft MSM visibility.
pub fn vis_msm_soft(moments: &Integral, l: &LightGpu, s: &LightSample) -> f64 {
    finish(moments, l, s, blocker_of(&search(moments, l, s), l, s))
}
