//! Reference of `kernels/shared/vis_vsm.wgsl`.

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// Chebyshev upper bound from the filtered moments (`levels`: the map, or its mip chain),
/// with bleeding reduction.
pub fn vis_vsm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    vis_vsm_of(&super::mips::sample(levels, l, s), l, s)
}

/// The bound from filtered moments `m` however they were filtered (`vis_vsm_of`).
pub fn vis_vsm_of(m: &[f64], l: &LightGpu, s: &LightSample) -> f64 {
    let d = s.depth - f64::from(l.bias);
    if d <= m[0] {
        return 1.0;
    }
    let variance = (m[1] - m[0] * m[0]).max(f64::from(l.min_variance));
    let t = d - m[0];
    let p = variance / (variance + t * t);
    let bleed = f64::from(l.bleed);
    ((p - bleed) / (1.0 - bleed)).clamp(0.0, 1.0)
}
