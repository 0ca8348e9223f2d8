//! Reference of `kernels/shared/vis_vssm.wgsl`, in three steps so tests can perturb each:
//! the moments over the search square, the blocker estimate, the visibility at the penumbra
//! width. `moments` is the integral image of the per-texel representation the table sums (the
//! shader's lookups integrate the same values exactly).

use super::blocker::{self, Blocker};
use super::light::LightSample;
use super::sat::Integral;
use crate::wgsl_mirrors::LightGpu;

/// The blocker search's cells (`sat_search_cells_*`): each cell's mean moments and area.
pub fn search(moments: &Integral, l: &LightGpu, s: &LightSample) -> Vec<(Vec<f64>, f64)> {
    moments.search_cells(
        l.map_size,
        s.uv,
        blocker::search_width(l, s),
        blocker::SEARCH_CELLS,
    )
}

/// `vssm_blocker` of one cell's mean moments `m`.
pub fn cell_blocker(m: &[f64], l: &LightGpu, s: &LightSample) -> Blocker {
    blocker::vsm(m, s.depth - f64::from(l.bias), f64::from(l.min_variance))
}

/// `vssm_search`: the cells' estimates combined ([`blocker::combine`]).
pub fn blocker_of(cells: &[(Vec<f64>, f64)], l: &LightGpu, s: &LightSample) -> Blocker {
    let each = cells
        .iter()
        .filter(|(_, area)| *area > 0.0)
        .map(|(m, area)| (cell_blocker(m, l, s), *area));
    blocker::combine(each, s.depth - f64::from(l.bias))
}

/// The mean moments over the penumbra width of `b`, the square as the table is read
/// ([`Integral::exact_filter_square_mean`]: exact, or on the 2⁻⁸ grid of filtered fetches).
pub fn filtered(moments: &Integral, l: &LightGpu, s: &LightSample, b: Blocker) -> Vec<f64> {
    moments.exact_filter_square_mean(l.map_size, s.uv, blocker::filter_width(l, s, b.depth))
}

/// The visibility for blocker estimate `b` (`vssm_resolve` after the second lookup).
pub fn finish(moments: &Integral, l: &LightGpu, s: &LightSample, b: Blocker) -> f64 {
    if !b.found() {
        return 1.0;
    }
    super::vis_vsm::vis_vsm_of(&filtered(moments, l, s, b), l, s)
}

/// Soft VSM visibility.
pub fn vis_vssm(moments: &Integral, l: &LightGpu, s: &LightSample) -> f64 {
    finish(moments, l, s, blocker_of(&search(moments, l, s), l, s))
}
