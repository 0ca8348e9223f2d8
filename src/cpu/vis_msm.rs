//! Reference of `kernels/shared/vis_msm.wgsl`, written independently of the shader's Cholesky
//! steps: the 3×3 Hankel system is solved by Cramer's rule in f64.

use super::Texels;
use super::light::LightSample;
use crate::technique::{LightGpu, MSM_HAUSDORFF, MSM_QUANTIZED};

/// Moments of {0, ½, 1} with weights (3/16, 10/16, 3/16).
pub const B0: [f64; 4] = [0.5, 0.34375, 0.265625, 0.2265625];

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Shadow intensity from (already biased) moments `b` at receiver depth `d`.
pub fn intensity(b: [f64; 4], d: f64, hausdorff: bool) -> f64 {
    let var1 = b[1] - b[0] * b[0];
    if var1 <= 1e-12 {
        return if d > b[0] { 1.0 } else { 0.0 };
    }
    let h = [[1.0, b[0], b[1]], [b[0], b[1], b[2]], [b[1], b[2], b[3]]];
    let det = det3(h);
    if det <= 0.0 {
        if d <= b[0] {
            return 0.0;
        }
        let t = d - b[0];
        return t * t / (var1 + t * t);
    }
    // Cramer: c_i = det(H with column i replaced by (1, d, d²)) / det(H).
    let rhs = [1.0, d, d * d];
    let c: Vec<f64> = (0..3)
        .map(|i| {
            let mut m = h;
            for (r, row) in m.iter_mut().enumerate() {
                row[i] = rhs[r];
            }
            det3(m) / det
        })
        .collect();
    // Roots of c[2] x² + c[1] x + c[0].
    let disc = (c[1] * c[1] - 4.0 * c[2] * c[0]).max(0.0).sqrt();
    let (r1, r2) = ((-c[1] - disc) / (2.0 * c[2]), (-c[1] + disc) / (2.0 * c[2]));
    let (z2, z3) = (r1.min(r2), r1.max(r2));
    if hausdorff && (z2 < 0.0 || z3 > 1.0) {
        let free = ((b[2] - b[1]) * d + b[2] - b[3]) / ((b[1] - b[0]) * d + b[1] - b[2]);
        let w1 = if d > free { 1.0 } else { 0.0 };
        return (b[1] - b[0]
            + (b[2] - b[0] - (free + 1.0) * (b[1] - b[0])) * (free - w1 - d) / (d * (d - free)))
            / (free - w1)
            + 1.0
            - b[0];
    }
    if d <= z2 {
        0.0
    } else if d <= z3 {
        (d * z3 - b[0] * (d + z3) + b[1]) / ((z3 - z2) * (d - z2))
    } else {
        1.0 - (z2 * z3 - b[0] * (z2 + z3) + b[1]) / ((d - z2) * (d - z3))
    }
}

/// The filtered (possibly quantized) moments at `s`, dequantized and biased.
pub fn biased_moments(levels: &[Texels], l: &LightGpu, s: &LightSample) -> [f64; 4] {
    biased(&super::mips::sample(levels, l, s), l)
}

/// Filtered (possibly quantized) moments `m` dequantized and biased (`msm_biased`).
pub fn biased(m: &[f64], l: &LightGpu) -> [f64; 4] {
    let mut b = [m[0], m[1], m[2], m[3]];
    if l.msm_flags & MSM_QUANTIZED != 0 {
        b = super::msm::dequantize(b);
    }
    let a = f64::from(l.moment_bias);
    std::array::from_fn(|i| (1.0 - a) * b[i] + a * B0[i])
}

/// MSM visibility (Hamburger or Hausdorff by `l.msm_flags`) with bleeding reduction.
pub fn vis_msm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    vis_msm_of(&super::mips::sample(levels, l, s), l, s)
}

/// MSM visibility from filtered moments `m` however they were filtered (`vis_msm_of`).
pub fn vis_msm_of(m: &[f64], l: &LightGpu, s: &LightSample) -> f64 {
    let b = biased(m, l);
    let i = intensity(
        b,
        s.depth - f64::from(l.bias),
        l.msm_flags & MSM_HAUSDORFF != 0,
    );
    let v = 1.0 - i.clamp(0.0, 1.0);
    let v = if v.is_nan() { 1.0 } else { v };
    let bleed = f64::from(l.bleed);
    ((v - bleed) / (1.0 - bleed)).clamp(0.0, 1.0)
}
