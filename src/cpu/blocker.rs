//! Reference of `kernels/shared/blocker.wgsl`: the search and filter widths of the soft
//! techniques and their blocker estimates from filtered means. The MSM estimate is computed
//! independently of the shader's steps: the Hankel system by `cpu::vis_msm`'s Cholesky of the
//! raw moments, the weights of the three-point distribution by Lagrange's formula.

use std::f64::consts::PI;

use super::light::{LightSample, linear_to_z, map_width};
use crate::wgsl_mirrors::LightGpu;

/// `BLOCKER_MIN_SHARE`: a search square with a smaller blocker share reads as lit.
pub const MIN_SHARE: f64 = 0.01;

/// A blocker estimate: the average depth (linear) of the texels in front of the receiver and
/// their share of the search square.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocker {
    /// Average blocker depth z_avg, linear, in `[0, max(d, 0)]`.
    pub depth: f64,
    /// Estimated share of blockers.
    pub share: f64,
}

impl Blocker {
    /// Whether the search square holds blockers (share ≥ [`MIN_SHARE`]).
    pub fn found(&self) -> bool {
        self.share >= MIN_SHARE
    }

    /// Depth `z` clamped to `[0, max(d, 0)]` with `share` (`blocker_result`).
    pub fn new(z: f64, share: f64, d: f64) -> Self {
        Self {
            depth: z.clamp(0.0, d.max(0.0)),
            share,
        }
    }
}

/// `SEARCH_CELLS` of `kernels/shared/sat_lookup.wgsl`: the blocker search reads its square
/// in `SEARCH_CELLS × SEARCH_CELLS` cells, each estimated on its own ([`combine`]).
pub const SEARCH_CELLS: u32 = 2;

/// `blocker_total` after `blocker_add` of each cell's estimate and area (texels): the share
/// weighted by area, the depth by blockers (area · share); a cell of area 0 weighs nothing.
pub fn combine(cells: impl IntoIterator<Item = (Blocker, f64)>, d: f64) -> Blocker {
    let (mut z, mut share, mut area) = (0.0, 0.0, 0.0);
    for (b, a) in cells {
        if a > 0.0 {
            let blockers = a * b.share.max(0.0);
            z += blockers * b.depth;
            share += blockers;
            area += a;
        }
    }
    Blocker::new(z / share.max(1e-30), share / area.max(1.0), d)
}

/// `blocker_width`: at least 1 texel, at most `l.max_width`.
fn width(texels: f64, l: &LightGpu) -> f64 {
    let w = if texels > 1.0 { texels } else { 1.0 };
    w.min(f64::from(l.max_width))
}

/// `blocker_search_width`: the light cone at the near plane, in texels.
pub fn search_width(l: &LightGpu, s: &LightSample) -> f64 {
    let near = f64::from(l.near);
    let world = f64::from(l.size) * (s.view_z - near) / s.view_z;
    width(world / map_width(l, near) * face_texels(l), l)
}

/// `blocker_filter_width`: the PCSS penumbra at the receiver for blockers at `z_avg`.
pub fn filter_width(l: &LightGpu, s: &LightSample, z_avg: f64) -> f64 {
    let z_b = linear_to_z(l, z_avg);
    let penumbra = f64::from(l.size) * (s.view_z - z_b) / z_b;
    width(penumbra / map_width(l, s.view_z) * face_texels(l), l)
}

/// `blocker_vsm`: Chebyshev's share p of texels at or behind `d`, the rest averaging
/// `(μ − p·d)/(1 − p)`.
pub fn vsm(m: &[f64], d: f64, floor: f64) -> Blocker {
    let variance = (m[1] - m[0] * m[0]).max(floor);
    let t = d - m[0];
    let p = if t > 0.0 {
        variance / (variance + t * t)
    } else {
        1.0
    };
    let share = 1.0 - p;
    Blocker::new((m[0] - p * d) / share.max(MIN_SHARE), share, d)
}

/// `blocker_msm` from biased moments `m`: the support points in front of `d` of the
/// three-point distribution through `d` that matches them, each clamped to `[0, d]`, weighted.
pub fn msm(m: &super::vis_msm::Biased, d: f64) -> Blocker {
    use super::vis_msm::{Roots, expect, roots};
    let b = m.b;
    let (z2, z3) = match roots(m, d) {
        Roots::Point => return Blocker::new(b[0], if d > b[0] { 1.0 } else { 0.0 }, d),
        Roots::RankDeficient => return vsm(&b, d, 0.0),
        Roots::Regular(z2, z3) => (z2, z3),
    };
    // Lagrange: w_i = E[Π_{j≠i} (z − z_j)] / Π_{j≠i} (z_i − z_j).
    let w2 = expect(b, d, z3) / ((z2 - d) * (z2 - z3));
    let w3 = expect(b, d, z2) / ((z3 - d) * (z3 - z2));
    if d <= z2 {
        Blocker::new(d, 0.0, d)
    } else if d <= z3 {
        Blocker::new(z2, w2, d)
    } else {
        let share = w2 + w3;
        let clamped = |z: f64| z.clamp(0.0, d);
        Blocker::new(
            (w2 * clamped(z2) + w3 * clamped(z3)) / share.max(MIN_SHARE),
            share,
            d,
        )
    }
}

/// The CSM-Z series `E[f̄(d, z)·z]` from the filtered CSM-Z channels `zb` (`2M + 1`) at the
/// shifted receiver depth `d` (the sum of `csm_z_chunk_of` over the maps).
pub fn csm_z_series(zb: &[f64], l: &LightGpu, d: f64) -> f64 {
    0.5 * zb[0]
        - (1..=l.csm_terms)
            .map(|k| {
                let c = PI * f64::from(2 * k - 1);
                let i = 2 * k as usize - 1;
                super::vis_csm::weight(k, l) * ((c * d).cos() * zb[i] - (c * d).sin() * zb[i + 1])
            })
            .sum::<f64>()
}

/// `blocker_csm_z`: share `½ − below` (`below` = the CSM series = E\[f\] − ½), depth
/// `zsum / share`.
pub fn csm_z(below: f64, zsum: f64, d: f64) -> Blocker {
    let share = 0.5 - below;
    Blocker::new(zsum / share.max(MIN_SHARE), share, d)
}

/// Texels across one face of the map (`map_size · face_uv`: the map's own width but for a
/// point light's atlas).
fn face_texels(l: &LightGpu) -> f64 {
    f64::from(l.map_size[0]) * f64::from(l.face_uv[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_cells_match_the_kernel() {
        // The kernel reads 2 × 2 cells by name (no loop), meeting at lo + ⌊(hi − lo)/2⌋.
        let wgsl = include_str!("../../kernels/shared/sat_lookup.wgsl");
        assert_eq!(SEARCH_CELLS, 2, "sat_search_cells_* read 2 × 2 cells");
        assert!(wgsl.contains("return b.xy + (b.zw - b.xy) / 2;"));
    }

    #[test]
    fn cells_combine_by_area_and_blockers() {
        // Two cells of 6 and 2 texels: blockers at 0.2 over half of the first, at 0.4 over all
        // of the second; an empty cell whatever its estimate. Share (3 + 2)/8, depth
        // (3·0.2 + 2·0.4)/5 = 0.28.
        let b = |depth, share| Blocker { depth, share };
        let got = combine(
            [(b(0.2, 0.5), 6.0), (b(0.4, 1.0), 2.0), (b(0.9, 1.0), 0.0)],
            0.8,
        );
        assert!((got.share - 5.0 / 8.0).abs() < 1e-12, "{got:?}");
        assert!((got.depth - 0.28).abs() < 1e-12, "{got:?}");
        // No blockers anywhere: share 0, depth clamped into [0, d].
        let none = combine([(b(0.5, 0.0), 4.0)], 0.8);
        assert_eq!((none.share, none.depth), (0.0, 0.0));
    }
}
