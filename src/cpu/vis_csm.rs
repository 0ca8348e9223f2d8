//! Reference of `kernels/shared/vis_csm.wgsl`.

use std::f64::consts::PI;

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// The truncated, attenuated Fourier series of the step minus ½, at receiver depth `d`,
/// for filtered basis values `basis` (`2M` channels: sin, cos per term).
pub fn series(basis: &[f64], l: &LightGpu, d: f64) -> f64 {
    let m = f64::from(l.csm_terms);
    (1..=l.csm_terms as usize)
        .map(|k| {
            let c = PI * (2 * k - 1) as f64;
            let kf = k as f64 / m;
            let w = 2.0 / c * (-f64::from(l.csm_attenuation) * kf * kf).exp();
            w * ((c * d).cos() * basis[2 * k - 2] - (c * d).sin() * basis[2 * k - 1])
        })
        .sum()
}

/// CSM visibility: offset, scaled about ½, clamped (`levels`: the 2M-channel basis, or its
/// mip chain).
pub fn vis_csm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let basis = super::mips::sample(levels, l, s);
    resolve(series(&basis, l, shifted_depth(l, s)), l)
}

/// The receiver depth the series is evaluated at: `d − bias − offset`.
pub fn shifted_depth(l: &LightGpu, s: &LightSample) -> f64 {
    s.depth - f64::from(l.bias) - f64::from(l.csm_offset)
}

/// The series `sum` scaled about ½ and clamped (`csm_resolve`).
pub fn resolve(sum: f64, l: &LightGpu) -> f64 {
    (f64::from(l.csm_scale) * sum + 0.5).clamp(0.0, 1.0)
}

/// The attenuated weight of term k, `(2 / c_k)·exp(−α (k/M)²)` (`csm_weight`).
pub fn weight(k: u32, l: &LightGpu) -> f64 {
    let kf = f64::from(k) / f64::from(l.csm_terms);
    2.0 / (PI * f64::from(2 * k - 1)) * (-f64::from(l.csm_attenuation) * kf * kf).exp()
}
