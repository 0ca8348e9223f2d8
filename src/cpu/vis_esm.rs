//! Reference of `kernels/shared/vis_esm.wgsl`.

use super::Texels;
use super::light::LightSample;
use crate::technique::LightGpu;

/// `clamp(E[exp(c z)] · exp(−c d), 0, 1)` with the bilinear mean of `exp(L)` over the log map.
pub fn vis_esm(log_moments: &Texels, l: &LightGpu, s: &LightSample) -> f64 {
    let fx = s.uv[0] * log_moments.width as f64 - 0.5;
    let fy = s.uv[1] * log_moments.height as f64 - 0.5;
    let (x0, y0) = (fx.floor() as i64, fy.floor() as i64);
    let (ax, ay) = (fx - fx.floor(), fy - fy.floor());
    let c = f64::from(l.exp_pos);
    let d = s.depth - f64::from(l.bias);
    // Σ wᵢ exp(Lᵢ − c d), each term formed in f64 without overflow for the exponents used.
    let term = |dx: i64, dy: i64| (log_moments.at(x0 + dx, y0 + dy)[0] - c * d).exp();
    let v = (1.0 - ay) * ((1.0 - ax) * term(0, 0) + ax * term(1, 0))
        + ay * ((1.0 - ax) * term(0, 1) + ax * term(1, 1));
    v.clamp(0.0, 1.0)
}
