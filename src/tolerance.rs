//! Error models of the shading kernel's f32 visibility functions against their f64
//! references, evaluated on the same filtered maps: how far apart the two may be. One module,
//! used by the numerical-stability suite (`crate::stability`) and by the GPU tests
//! (`tests/common`), so the bounds a test asserts are the bounds the suite reports.
//!
//! Where the two former copies of these models differed, every term either copy needed is
//! kept: the variance floor's own error (EVSM forms it from the squared filtered mean, 2e), the
//! `exp` of the squared moment's exponent (`3 + 4c` ULP rather than `3 + 2c`), and the f32
//! dequantization of 16-bit MSM moments.

use std::f64::consts::PI;

use crate::cpu::Texels;
use crate::cpu::light::LightSample;
use crate::cpu::vis_msm::{bias_for, branch_spread, dequantized, intensity};
use crate::wgsl_mirrors::{LightGpu, MSM_HAUSDORFF, MSM_QUANTIZED};

/// The unit roundoff of f32, 2⁻²⁴.
pub const U: f64 = 1.0 / (1u64 << 24) as f64;

/// First-order bound on the f32 error of the one-tailed Chebyshev bound
/// `p = σ² / (σ² + t²)`, `σ² = max(E[x²] − E[x]², floor)`, `t = r − E[x]`, when every input
/// carries relative error `e` and both means an absolute error `abs` besides (a table read with
/// filtered fetches, [`filtered_table_error`]; 0 otherwise): the cancellation in σ² amplifies
/// the relative error by `E[x²] / σ²`. The floor carries 2e (EVSM forms it from the squared
/// filtered mean). At most 1, which no visibility's error exceeds.
pub fn chebyshev(mean: f64, mean_sq: f64, receiver: f64, floor: f64, e: f64, abs: f64) -> f64 {
    // p = 1 at and below the mean (continuous at the boundary, σ² / σ²).
    if receiver <= mean - abs {
        return 0.0;
    }
    let var = (mean_sq - mean * mean).max(floor);
    let t = (receiver - mean).max(0.0);
    let dvar =
        e * (mean_sq.abs() + 2.0 * mean * mean) + 2.0 * e * floor + abs * (1.0 + 2.0 * mean.abs());
    let dt = e * (receiver.abs() + mean.abs()) + abs;
    let first = (t * t * dvar + 2.0 * t.abs() * var * dt) / (var + t * t).powi(2);
    // A receiver within `abs` of the mean may read either side of it: 1 against the bound at
    // t + abs.
    let near = if receiver <= mean + abs {
        1.0 - var / (var + (t + abs).powi(2))
    } else {
        0.0
    };
    (first + near).min(1.0)
}

/// The absolute error of a mean read at `s` from a table of f32 sums with filtered fetches
/// (`l.sat_filtered`; 0 for other maps), with the `sat` filter's square: each of the four
/// corners is a bilinear mix of table texels, two lerps in x and one in y (three roundings
/// each, relative to the sums there, bounded by `⌈x⌉·⌈y⌉·amplitude`), and the window three
/// subtractions, over the clamped square's area (the table's own texels are the reference's).
pub fn filtered_table_error(l: &LightGpu, s: &LightSample) -> f64 {
    if l.sat_filtered == 0 {
        return 0.0;
    }
    let (w, h) = (l.map_size[0] as usize, l.map_size[1] as usize);
    let (cx, cy) = (
        s.uv[0] as f32 * l.map_size[0],
        s.uv[1] as f32 * l.map_size[1],
    );
    let half = 0.5 * l.filter_width;
    let r = crate::cpu::sat::grid_rect([cx - half, cy - half, cx + half, cy + half], w, h)
        .map(f64::from);
    filtered_rect_error(l, r)
}

/// [`filtered_table_error`] for the rectangle `r` (texel units, on the grid).
pub fn filtered_rect_error(l: &LightGpu, r: [f64; 4]) -> f64 {
    let area = (r[2] - r[0]) * (r[3] - r[1]);
    let corners: f64 = [(r[0], r[1]), (r[2], r[1]), (r[0], r[3]), (r[2], r[3])]
        .iter()
        .map(|&(x, y)| x.ceil() * y.ceil())
        .sum();
    12.0 * U * corners * f64::from(l.sat_amplitude) / area
}

/// VSM at `s`: the bilinear mix and the receiver's depth carry ~8 roundings, and a table read
/// with filtered fetches its corners' roundings ([`filtered_table_error`]); then the
/// light-bleeding reduction divides by `1 − bleed`. Plus 1e-5 for the final arithmetic.
pub fn vsm(maps: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let m = crate::cpu::mips::sample(maps, l, s);
    let d = s.depth - f64::from(l.bias);
    let abs = filtered_table_error(l, s);
    let dp = chebyshev(m[0], m[1], d, f64::from(l.min_variance), 8.0 * U, abs);
    1e-5 + dp / (1.0 - f64::from(l.bleed))
}

/// EVSM at `s`: besides VSM's roundings, SPIR-V's `exp` is accurate to `(3 + 2|x|)` ULP, taken
/// here at the squared moment's exponent (|x| ≤ 2c), and the receiver's depth error is
/// amplified by `2c` through the warp.
pub fn evsm(maps: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let m = crate::cpu::mips::sample(maps, l, s);
    let [(pos, floor_pos), (neg, floor_neg)] = crate::cpu::vis_evsm::warp(l, s, &m);
    let ulp = 2.0 * U;
    let e = |c: f32| {
        let c = f64::from(c);
        (3.0 + 4.0 * c) * ulp + 8.0 * ulp + 4.0 * c * ulp
    };
    let mut dp = chebyshev(m[0], m[1], pos, floor_pos, e(l.exp_pos), 0.0);
    if l.moments == 4 {
        dp = dp.max(chebyshev(m[2], m[3], neg, floor_neg, e(l.exp_neg), 0.0));
    }
    1e-5 + dp / (1.0 - f64::from(l.bleed))
}

/// ESM visibility `v` at `s` over log map `logs`: the f32 arguments `L − c·d`
/// (a few roundings of magnitudes up to |L| + c·d), the receiver's depth (view transform in
/// f32: ~8 roundings of Z + near, over far − near, amplified by c), the inner exps and log of
/// the log-space bilinear ((3 + 2|x|) ULP each) and the final exp, all relative to `v`.
pub fn esm(
    logs: &[crate::cpu::Texels],
    l: &crate::wgsl_mirrors::LightGpu,
    s: &crate::cpu::light::LightSample,
    v: f64,
) -> f64 {
    let taps: Vec<f64> = crate::cpu::mips::taps(logs, l, s)
        .iter()
        .map(|(_, t)| t[0])
        .collect();
    let (lo, hi) = taps
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &t| (a.min(t), b.max(t)));
    let cd = f64::from(l.exp_pos) * s.depth;
    let ulp = 2f64.powi(-23);
    let arg = (hi - cd).abs();
    let depth = f64::from(l.exp_pos) * 4.0 * ulp * (s.view_z + f64::from(l.near))
        / f64::from(l.far - l.near);
    let rel = 8.0 * ulp * (hi.abs() + cd.abs())
        + depth
        + (3.0 + 2.0 * (hi - lo)) * ulp
        + (3.0 + 2.0 * arg) * ulp
        + 3.0 * ulp;
    1e-6 + v * rel
}

/// ESM through a summed-area table at visibility `v` (`vis_esm_of_sat`): the
/// table mean m in f32 from 16 weighted window sums (32 roundings of 2⁻²⁴ of m, the coding
/// being about 0), SPIR-V's `log` (2⁻²¹ absolute near 1, else 3 ULP of |ln m|), the exponent
/// x = ln m + c − c·d formed in f32 (4 ULP of c + c·d), `exp` to (3 + 2|x|) ULP, and the
/// receiver depth's f32 rounding scaled by c (as in [`esm`]).
pub fn esm_sat(
    moments: &[crate::cpu::Texels],
    l: &crate::wgsl_mirrors::LightGpu,
    s: &crate::cpu::light::LightSample,
    v: f64,
) -> f64 {
    let m = crate::cpu::mips::sample(moments, l, s)[0].max(1e-37);
    let table = filtered_table_error(l, s) / m;
    let c = f64::from(l.exp_pos);
    let ulp = 2f64.powi(-23);
    let x = m.ln() + c - c * s.depth;
    let depth = c * 4.0 * ulp * (s.view_z + f64::from(l.near)) / f64::from(l.far - l.near);
    let rel = 16.0 * ulp
        + 2f64.powi(-21)
        + 3.0 * ulp * m.ln().abs()
        + 4.0 * ulp * (c + c * s.depth)
        + (3.0 + 2.0 * x.abs()) * ulp
        + depth
        + table;
    1e-6 + v * rel
}

/// MSM at `s`: the kernel's solve is backward stable in the stored moments (their
/// covariances are formed once, the bias added as non-negative terms), so the GPU computes
/// the exact answer for moments off by a few dozen roundings. The tolerance is twice the
/// largest change of the f64 reference over 16 such perturbations of the dequantized moments
/// before their projection and bias (32·u relative per moment, ±8·u on the depth; with
/// quantized storage also 8·u·Σ|q| absolute per moment, the f32 dequantization `q·M` with
/// entries of `M` below 1), plus 1e-4 for the final rational expression, over `1 − bleed`.
pub fn msm(maps: &[Texels], l: &LightGpu, s: &LightSample) -> f64 {
    let q = crate::cpu::mips::sample(maps, l, s);
    let b = dequantized(&q, l);
    // A table read with filtered fetches adds its corners' roundings to every stored moment,
    // carried through the dequantization (entries of its matrix below 1: four per moment).
    let table = filtered_table_error(l, s);
    let dequantize_error = if l.msm_flags & MSM_QUANTIZED != 0 {
        8.0 * U * q.iter().map(|v| v.abs()).sum::<f64>() + 4.0 * table
    } else {
        table
    };
    let d = s.depth - f64::from(l.bias);
    let hausdorff = l.msm_flags & MSM_HAUSDORFF != 0;
    let vis = |b: [f64; 4], d: f64| {
        let v = 1.0 - intensity(&bias_for(b, l), d, hausdorff).clamp(0.0, 1.0);
        if v.is_nan() { 1.0 } else { v }
    };
    let base = vis(b, d);
    let e = 32.0 * U;
    let mut worst: f64 = 0.0;
    for k in 0..16u32 {
        let sign = |bit: u32| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
        let p: [f64; 4] = std::array::from_fn(|i| {
            b[i] * (1.0 + sign(i as u32) * e) + sign(i as u32) * dequantize_error
        });
        let dd = d + sign(k % 4) * 8.0 * U;
        worst = worst.max((vis(p, dd) - base).abs());
    }
    // Where a root sits at 0 or 1, rounding picks Hamburger's or Hausdorff's formula.
    let spread = branch_spread(&bias_for(b, l), d, hausdorff, 1e-3);
    worst = worst.max(spread);
    (1e-4 + 2.0 * worst) / (1.0 - f64::from(l.bleed))
}

/// CSM's term weights `w_k = (2 / c_k)·exp(−α (k/M)²)`, k = 1..=M.
pub fn csm_weights(l: &LightGpu) -> Vec<f64> {
    let m = f64::from(l.csm_terms);
    (1..=l.csm_terms)
        .map(|k| {
            let kf = f64::from(k) / m;
            2.0 / (PI * f64::from(2 * k - 1)) * (-f64::from(l.csm_attenuation) * kf * kf).exp()
        })
        .collect()
}

/// CSM: Vulkan specifies `sin`/`cos` to 2⁻¹¹ absolute on [−π, π] (the kernels reduce their
/// arguments there), so term k may be off by `w_k·2·2⁻¹¹` in the receiver's factors; the sum
/// is scaled by `scale`. Plus 1e-5 for the f32 sum.
pub fn csm(l: &LightGpu) -> f64 {
    let w: f64 = csm_weights(l).iter().sum();
    // A table read with filtered fetches: each basis mean off by its corners' roundings, at
    // the smallest square the clamp leaves (a quarter of the filter's, in a map corner).
    let table = if l.sat_filtered != 0 {
        let half = f64::from(0.5 * l.filter_width).max(1.0);
        let n = f64::from(l.map_size[0].max(l.map_size[1]));
        filtered_rect_error(l, [n - half, n - half, n, n])
    } else {
        0.0
    };
    1e-5 + f64::from(l.csm_scale) * w * 2.0 * (2f64.powi(-11) + table)
}
