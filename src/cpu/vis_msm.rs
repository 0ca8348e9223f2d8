//! Reference of `kernels/shared/vis_msm.wgsl`, written independently of the shader's solve:
//! the biased Hankel matrix is formed from the raw moments and factored by a textbook
//! Cholesky in f64, in loops. (Cramer's rule, used here before, squares the matrix's
//! condition number: near a flat occluder, where the bias alone keeps the matrix definite,
//! it lost five digits; `tests/data/msm_reference.py` gives 60-digit values the tests check.)

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::{LightGpu, MSM_HAUSDORFF, MSM_QUANTIZED};

/// Moments of {0, ½, 1} with weights (3/16, 10/16, 3/16).
pub const B0: [f64; 4] = [0.5, 0.34375, 0.265625, 0.2265625];

/// The Hamburger reconstruction through a receiver depth (`msm_roots`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Roots {
    /// The other two support points `z₂ ≤ z₃`.
    Regular(f64, f64),
    /// The variance is (numerically) zero: one point at the mean.
    Point,
    /// The Hankel matrix is singular: two support points.
    RankDeficient,
}

/// Covariances (Var z, Cov(z, z²), Var z²) of [`B0`]'s distribution, and the Schur
/// complement Var z² − Cov(z, z²)²/Var z.
const B0_COV: [f64; 3] = [0.09375, 0.09375, 0.1083984375];
const B0_SCHUR: f64 = 0.0146484375;

/// Biased moments as the reconstruction reads them (`MsmMoments`): `(1 − α)·m + α·b₀` and α,
/// which bounds the Hankel matrix's pivots from below.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biased {
    /// The biased raw moments.
    pub b: [f64; 4],
    /// The bias α.
    pub alpha: f64,
}

/// `moments` projected onto the moments of some distribution: Var z and Var z² clamped at 0,
/// Cov(z, z²) to Cauchy–Schwarz's bound (rounded or filtered moments may lie just outside,
/// where the bias alone would have to keep the Hankel matrix definite). Valid moments pass
/// unchanged up to rounding.
pub fn project(b: [f64; 4]) -> [f64; 4] {
    let var1 = (b[1] - b[0] * b[0]).max(0.0);
    let var2 = (b[3] - b[1] * b[1]).max(0.0);
    let limit = (var1 * var2).sqrt();
    let cov = (b[2] - b[0] * b[1]).clamp(-limit, limit);
    let second = b[0] * b[0] + var1;
    [b[0], second, b[0] * second + cov, second * second + var2]
}

/// Data moments (dequantized) biased by `alpha` toward [`B0`], projected first when `raw`
/// (f32 moments round each channel on its own; quantized ones are left as they are, see
/// `kernels/shared/vis_msm.wgsl`).
pub fn bias(data: [f64; 4], alpha: f64, raw: bool) -> Biased {
    let p = if raw { project(data) } else { data };
    Biased {
        b: std::array::from_fn(|i| (1.0 - alpha) * p[i] + alpha * B0[i]),
        alpha,
    }
}

/// Solves `h·x = rhs` for a symmetric positive definite `h` by Cholesky (`h = L·Lᵀ`), each
/// squared pivot raised to at least `floor[i]`, or `None` when a pivot is not positive.
fn cholesky_solve(h: [[f64; 3]; 3], rhs: [f64; 3], floor: [f64; 3]) -> Option<[f64; 3]> {
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = h[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                let s = s.max(floor[i]);
                if s.is_nan() || s <= 0.0 {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = (rhs[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        x[i] = (y[i] - (i + 1..3).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    Some(x)
}

/// The Hamburger reconstruction of biased moments `m` through `d`: the roots of
/// `c₃x² + c₂x + c₁`, where `c` solves the Hankel system `B·c = (1, d, d²)`, B's pivots
/// floored at α times b₀'s (`B ⪰ α·B₀` for any distribution's biased moments).
pub fn roots(m: &Biased, d: f64) -> Roots {
    let b = m.b;
    let floor = [0.0, m.alpha * B0_COV[0], m.alpha * B0_SCHUR];
    if (b[1] - b[0] * b[0]).max(floor[1]) <= 1e-12 {
        return Roots::Point;
    }
    let h = [[1.0, b[0], b[1]], [b[0], b[1], b[2]], [b[1], b[2], b[3]]];
    let Some(c) = cholesky_solve(h, [1.0, d, d * d], floor) else {
        return Roots::RankDeficient;
    };
    // The smaller-magnitude root from the larger by Vieta (no cancellation).
    let disc = (c[1] * c[1] - 4.0 * c[2] * c[0]).max(0.0).sqrt();
    let big = -0.5 * (c[1] + disc.copysign(c[1]));
    if big == 0.0 {
        return Roots::Regular(0.0, 0.0);
    }
    // Held within ±ROOT_LIMIT as `msm_roots` holds them (a root at ±∞ where c₃ is 0).
    let (r1, r2) = (
        (big / c[2]).clamp(-ROOT_LIMIT, ROOT_LIMIT),
        (c[0] / big).clamp(-ROOT_LIMIT, ROOT_LIMIT),
    );
    Roots::Regular(r1.min(r2), r1.max(r2))
}

/// `MSM_ROOT_LIMIT` of `kernels/shared/vis_msm.wgsl`: the largest magnitude of a support point.
pub const ROOT_LIMIT: f64 = 1e8;

/// `E[(z − x)(z − y)]` under moments `b`.
pub fn expect(b: [f64; 4], x: f64, y: f64) -> f64 {
    b[1] - (x + y) * b[0] + x * y
}

/// Shadow intensity from biased moments `m` at receiver depth `d`.
pub fn intensity(m: &Biased, d: f64, hausdorff: bool) -> f64 {
    let b = m.b;
    let (z2, z3) = match roots(m, d) {
        Roots::Point => return if d > b[0] { 1.0 } else { 0.0 },
        Roots::RankDeficient => {
            if d <= b[0] {
                return 0.0;
            }
            let t = d - b[0];
            return t * t / (b[1] - b[0] * b[0] + t * t);
        }
        Roots::Regular(z2, z3) => (z2, z3),
    };
    if hausdorff && (z2 < 0.0 || z3 > 1.0) {
        return hausdorff_intensity(b, d);
    }
    if d <= z2 {
        0.0
    } else if d <= z3 {
        expect(b, d, z3) / ((z3 - z2) * (d - z2))
    } else {
        1.0 - expect(b, z2, z3) / ((d - z2) * (d - z3))
    }
}

/// Hausdorff's four-point intensity on [0, 1] (Peters & Klein 2015), which `intensity` takes
/// when the Hamburger roots leave [0, 1].
pub fn hausdorff_intensity(b: [f64; 4], d: f64) -> f64 {
    let free = ((b[2] - b[1]) * d + b[2] - b[3]) / ((b[1] - b[0]) * d + b[1] - b[2]);
    let w1 = if d > free { 1.0 } else { 0.0 };
    (b[1] - b[0]
        + (b[2] - b[0] - (free + 1.0) * (b[1] - b[0])) * (free - w1 - d) / (d * (d - free)))
        / (free - w1)
        + 1.0
        - b[0]
}

/// With Hausdorff reconstruction, how far the answer at `d` may move when a Hamburger root lies
/// within `margin` of 0 or 1, where rounding decides between the two formulas: the distance
/// between them there (0 elsewhere, or without Hausdorff).
pub fn branch_spread(m: &Biased, d: f64, hausdorff: bool, margin: f64) -> f64 {
    let Roots::Regular(z2, z3) = roots(m, d) else {
        return 0.0;
    };
    if !hausdorff || (z2.abs() > margin && (z3 - 1.0).abs() > margin) {
        return 0.0;
    }
    (intensity(m, d, false).clamp(0.0, 1.0) - hausdorff_intensity(m.b, d).clamp(0.0, 1.0)).abs()
}

/// Filtered (possibly quantized) moments `m` dequantized (the data moments).
pub fn dequantized(m: &[f64], l: &LightGpu) -> [f64; 4] {
    let b = [m[0], m[1], m[2], m[3]];
    if l.msm_flags & MSM_QUANTIZED != 0 {
        super::msm::dequantize(b)
    } else {
        b
    }
}

/// Data moments `data` of light `l` biased as the kernel does (`msm_biased`: projected when
/// the light stores raw moments).
pub fn bias_for(data: [f64; 4], l: &LightGpu) -> Biased {
    bias(
        data,
        f64::from(l.moment_bias),
        l.msm_flags & MSM_QUANTIZED == 0,
    )
}

/// Filtered (possibly quantized) moments `m` dequantized and biased (`msm_biased`).
pub fn biased(m: &[f64], l: &LightGpu) -> Biased {
    bias_for(dequantized(m, l), l)
}

/// MSM visibility (Hamburger or Hausdorff by `l.msm_flags`) with bleeding reduction.
pub fn vis_msm(levels: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    vis_msm_of(&super::mips::sample(levels, l, s), l, s)
}

/// MSM visibility from filtered moments `m` however they were filtered (`vis_msm_of`).
pub fn vis_msm_of(m: &[f64], l: &LightGpu, s: &LightSample) -> f64 {
    visibility(&biased(m, l), s.depth - f64::from(l.bias), l)
}

/// The visibility, bleeding reduction included, of biased moments `m` at depth `d`.
pub fn visibility(m: &Biased, d: f64, l: &LightGpu) -> f64 {
    let i = intensity(m, d, l.msm_flags & MSM_HAUSDORFF != 0);
    let v = 1.0 - i.clamp(0.0, 1.0);
    let v = if v.is_nan() { 1.0 } else { v };
    let bleed = f64::from(l.bleed);
    ((v - bleed) / (1.0 - bleed)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::{bias, intensity};

    /// Inputs (exact binary numbers) and the visibility `linstep(bleed, 1, 1 − intensity)`
    /// evaluated with 60 digits by `tests/data/msm_reference.py` (mpmath, an LU solve),
    /// rounded to f64 (20 digits in the comments); the lines are that script's output.
    struct Case {
        moments: [f64; 4],
        d: f64,
        alpha: f64,
        bleed: f64,
        hausdorff: bool,
        visibility: f64,
    }

    #[rustfmt::skip]
    const CASES: [Case; 7] = [
    // flat_behind_bleed: z2, z3 = 0.130668133051, 0.948561867012; visibility 0.90320816710090451248 (the issue: Cramer's rule gave 0.9031859)
    Case { moments: [0.9504754699392566, 0.9034036189562507, 0.8586629792722674, 0.8161380987432505], d: 0.9506347094697088, alpha: 9.999999747378752e-06, bleed: 0.20000000298023224, hausdorff: false, visibility: 0.9032081671009045 },
    // stored_f32_behind_flat: z2, z3 = 0.0995088148825, 0.903847987446; visibility 0.70683224106464799683 (f32 moments outside the valid set: projected)
    Case { moments: [0.9047530889511108, 0.8185781240463257, 0.7406110763549805, 0.6700701713562012], d: 0.905126690864563, alpha: 9.999999747378752e-06, bleed: 0.0, hausdorff: false, visibility: 0.706832241064648 },
    // flat_peters_bias: z2, z3 = 0.24988574291, 0.977268135531; visibility 0.53339356465192269858
    Case { moments: [0.25, 0.0625, 0.015625, 0.00390625], d: 0.2501, alpha: 3e-07, bleed: 0.0, hausdorff: false, visibility: 0.5333935646519227 },
    // two_points: z2, z3 = -6.08755198939, 0.29999399665; visibility 0.49999501332633225609 (singular data matrix)
    Case { moments: [0.5, 0.29, 0.185, 0.1241], d: 0.70001, alpha: 5.999999848427251e-05, bleed: 0.0, hausdorff: false, visibility: 0.4999950133263323 },
    // close_triple: z2, z3 = -0.401561316187, 0.599568896816; visibility 0.77966468264980669048
    Case { moments: [0.6001, 0.360120015, 0.2161080270025, 0.12968643240600045], d: 0.60025, alpha: 1e-06, bleed: 0.0, hausdorff: false, visibility: 0.7796646826498067 },
    // flat_near_zero: z2, z3 = 0.0184467534654, 0.860210361163; visibility 0.14035578163895823108
    Case { moments: [0.02, 0.0004, 8.000000000000001e-06, 1.6e-07], d: 0.03, alpha: 0.0005000000237487257, bleed: 0.0, hausdorff: false, visibility: 0.14035578163895823 },
    // two_points_hausdorff: z2, z3 = -6.08755198939, 0.29999399665; visibility 0.49997210509913455509
    Case { moments: [0.5, 0.29, 0.185, 0.1241], d: 0.70001, alpha: 5.999999848427251e-05, bleed: 0.0, hausdorff: true, visibility: 0.49997210509913453 },
    ];

    /// Tolerance 1e-9: the projection and the mix round each moment (~2⁻⁵³ relative), and
    /// the last Cholesky pivot, about 0.015·α here, amplifies that by ~1/pivot; measured:
    /// 4.1e-10 at α = 3e-7, ≤ 6e-11 for α ≥ 1e-6. Cramer's rule (the solve before) misses
    /// the first case by 2.5e-5.
    #[test]
    fn near_singular_cases_match_60_digits() {
        for (k, c) in CASES.iter().enumerate() {
            let i = intensity(&bias(c.moments, c.alpha, true), c.d, c.hausdorff);
            let v = ((1.0 - i.clamp(0.0, 1.0) - c.bleed) / (1.0 - c.bleed)).clamp(0.0, 1.0);
            let err = (v - c.visibility).abs();
            eprintln!("case {k}: {v} vs {} ({err:.2e})", c.visibility);
            assert!(err <= 1e-9, "case {k}: {v} vs {} ({err:.2e})", c.visibility);
        }
    }
}
