//! Reference of `kernels/shared/vis_esm.wgsl`.

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// `clamp(E[exp(c z)] · exp(−c d), 0, 1)` with the (bi/tri)linear mean of `exp(L)` over the
/// log map (`levels`: the map, or its mip chain).
pub fn vis_esm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let c = f64::from(l.exp_pos);
    let d = s.depth - f64::from(l.bias);
    if l.filter_width > 0.0 {
        // `vis_esm_of_sat`: the table holds m = exp(c (z − 1)); visibility m · exp(c (1 − d)).
        let m = super::mips::sample(levels, l, s)[0];
        return (m.max(1e-37).ln() + c - c * d).exp().clamp(0.0, 1.0);
    }
    // Σ wᵢ exp(Lᵢ − c d), each term formed in f64 without overflow for the exponents used.
    let v: f64 = super::mips::taps(levels, l, s)
        .iter()
        .map(|(w, t)| w * (t[0] - c * d).exp())
        .sum();
    v.clamp(0.0, 1.0)
}
