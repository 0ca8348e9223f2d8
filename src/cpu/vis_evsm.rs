//! Reference of `kernels/shared/vis_evsm.wgsl`.

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// One-tailed Chebyshev bound (`chebyshev_upper`).
pub fn chebyshev_upper(mean: f64, mean_sq: f64, receiver: f64, floor: f64) -> f64 {
    if receiver <= mean {
        return 1.0;
    }
    let variance = (mean_sq - mean * mean).max(floor);
    let t = receiver - mean;
    variance / (variance + t * t)
}

/// The receiver's warped depths `(pos, neg)` and the variance floors for the filtered moments
/// `m`: the floor in depth units² through the warp's derivative at the occluders' mean,
/// `min_variance · (2c·E[warped])²`.
pub fn warp(l: &LightGpu, s: &LightSample, m: &[f64]) -> [(f64, f64); 2] {
    let w = 2.0 * (s.depth - f64::from(l.bias)) - 1.0;
    let (cp, cn) = (f64::from(l.exp_pos), f64::from(l.exp_neg));
    let (pos, neg) = ((cp * w).exp(), -(-cn * w).exp());
    let floor = |c: f64, v: f64| f64::from(l.min_variance) * (2.0 * c * v).powi(2);
    let mean_neg = m.get(2).copied().unwrap_or(0.0);
    [(pos, floor(cp, m[0])), (neg, floor(cn, mean_neg))]
}

/// EVSM2/EVSM4 visibility with bleeding reduction (`levels`: the map, or its mip chain).
pub fn vis_evsm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let m = super::mips::sample(levels, l, s);
    let [(pos, floor_pos), (neg, floor_neg)] = warp(l, s, &m);
    let mut p = chebyshev_upper(m[0], m[1], pos, floor_pos);
    if l.moments == 4 {
        p = p.min(chebyshev_upper(m[2], m[3], neg, floor_neg));
    }
    let bleed = f64::from(l.bleed);
    ((p - bleed) / (1.0 - bleed)).clamp(0.0, 1.0)
}
