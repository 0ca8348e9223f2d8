//! Helpers shared by the GPU tests.
#![allow(dead_code, reason = "each test binary uses a subset")]

pub mod evaluate;
pub mod soft;
pub mod soft_maps;

use rand::{Rng, SeedableRng, rngs::SmallRng};
use shadowgraph::gpu::Gpu;

/// The device every GPU test runs on. No adapter is a failure, never a skip.
pub fn gpu() -> Gpu {
    match Gpu::new() {
        Ok(g) => g,
        Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
    }
}

/// A seeded RNG so failures reproduce.
pub fn rng(seed: u64) -> SmallRng {
    SmallRng::seed_from_u64(seed)
}

/// Asserts `|gpu − ref| ≤ atol + rtol·|ref|` everywhere, reporting the worst index, its error
/// and the number of mismatches.
pub fn assert_close(what: &str, gpu: &[f32], reference: &[f64], atol: f64, rtol: f64) {
    let tolerance: Vec<f64> = reference.iter().map(|r| atol + rtol * r.abs()).collect();
    assert_within(what, gpu, reference, &tolerance);
}

/// Asserts `|gpu[i] − ref[i]| ≤ tolerance[i]` (a per-value bound), reporting the worst excess.
pub fn assert_within(what: &str, gpu: &[f32], reference: &[f64], tolerance: &[f64]) {
    assert_eq!(gpu.len(), reference.len(), "{what}: length");
    assert_eq!(gpu.len(), tolerance.len(), "{what}: tolerances");
    let mut worst = (0usize, f64::NEG_INFINITY);
    let mut mismatches = 0;
    for (i, ((&g, &r), &tol)) in gpu.iter().zip(reference).zip(tolerance).enumerate() {
        let excess = if g.is_finite() {
            (f64::from(g) - r).abs() - tol
        } else {
            f64::INFINITY
        };
        if excess > 0.0 {
            mismatches += 1;
        }
        if excess > worst.1 {
            worst = (i, excess);
        }
    }
    let i = worst.0;
    assert!(
        mismatches == 0,
        "{what}: {mismatches} of {} values off; worst at {i}: gpu {} ref {} (error {:e}, allowed {:e})",
        gpu.len(),
        gpu[i],
        reference[i],
        (f64::from(gpu[i]) - reference[i]).abs(),
        tolerance[i]
    );
}

/// First-order bound on the f32 error of the one-tailed Chebyshev bound
/// `p = σ² / (σ² + t²)`, `σ² = max(E[x²] − E[x]², floor)`, `t = r − E[x]`, when every input
/// carries relative error `e`: the cancellation in σ² amplifies it by `E[x²] / σ²`. The floor
/// carries 2e (EVSM forms it from the squared filtered mean).
pub fn chebyshev_tolerance(mean: f64, mean_sq: f64, receiver: f64, floor: f64, e: f64) -> f64 {
    if receiver <= mean {
        // p = 1 here; at the boundary p is continuous (σ² / σ²).
        return 0.0;
    }
    let var = (mean_sq - mean * mean).max(floor);
    let t = receiver - mean;
    let dvar = e * (mean_sq.abs() + 2.0 * mean * mean) + 2.0 * e * floor;
    let dt = e * (receiver.abs() + mean.abs());
    (t * t * dvar + 2.0 * t.abs() * var * dt) / (var + t * t).powi(2)
}

/// Tolerance of VSM visibility at `s`: inputs carry ~8 roundings (bilinear mix, depth).
pub fn vsm_tolerance(
    moments: &[shadowgraph::cpu::Texels],
    l: &shadowgraph::technique::LightGpu,
    s: &shadowgraph::cpu::light::LightSample,
) -> f64 {
    let m = shadowgraph::cpu::mips::sample(moments, l, s);
    let d = s.depth - f64::from(l.bias);
    let dp = chebyshev_tolerance(
        m[0],
        m[1],
        d,
        f64::from(l.min_variance),
        8.0 * 2f64.powi(-24),
    );
    1e-5 + dp / (1.0 - f64::from(l.bleed))
}

/// Tolerance of EVSM visibility at `s`: besides the roundings of VSM, SPIR-V's `exp` is
/// accurate to (3 + 2|x|) ULP, and the receiver's depth error is amplified by 2c.
pub fn evsm_tolerance(
    moments: &[shadowgraph::cpu::Texels],
    l: &shadowgraph::technique::LightGpu,
    s: &shadowgraph::cpu::light::LightSample,
) -> f64 {
    let m = shadowgraph::cpu::mips::sample(moments, l, s);
    let [(pos, floor_pos), (neg, floor_neg)] = shadowgraph::cpu::vis_evsm::warp(l, s, &m);
    let ulp = 2f64.powi(-23);
    let e = |c: f32| (3.0 + 4.0 * f64::from(c)) * ulp + 8.0 * ulp + 4.0 * f64::from(c) * ulp;
    let mut dp = chebyshev_tolerance(m[0], m[1], pos, floor_pos, e(l.exp_pos));
    if l.moments == 4 {
        dp = dp.max(chebyshev_tolerance(
            m[2],
            m[3],
            neg,
            floor_neg,
            e(l.exp_neg),
        ));
    }
    1e-5 + dp / (1.0 - f64::from(l.bleed))
}

/// Tolerance of ESM visibility `v` at `s` over log map `logs`: the f32 arguments `L − c·d`
/// (a few roundings of magnitudes up to |L| + c·d), the receiver's depth (view transform in
/// f32: ~8 roundings of Z + near, over far − near, amplified by c), the inner exps and log of
/// the log-space bilinear ((3 + 2|x|) ULP each) and the final exp, all relative to `v`.
pub fn esm_tolerance(
    logs: &[shadowgraph::cpu::Texels],
    l: &shadowgraph::technique::LightGpu,
    s: &shadowgraph::cpu::light::LightSample,
    v: f64,
) -> f64 {
    let taps: Vec<f64> = shadowgraph::cpu::mips::taps(logs, l, s)
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

/// Tolerance of ESM through a summed-area table at visibility `v` (`vis_esm_of_sat`): the
/// table mean m in f32 from 16 weighted window sums (32 roundings of 2⁻²⁴ of m, the coding
/// being about 0), SPIR-V's `log` (2⁻²¹ absolute near 1, else 3 ULP of |ln m|), the exponent
/// x = ln m + c − c·d formed in f32 (4 ULP of c + c·d), `exp` to (3 + 2|x|) ULP, and the
/// receiver depth's f32 rounding scaled by c (as in [`esm_tolerance`]).
pub fn esm_sat_tolerance(
    moments: &[shadowgraph::cpu::Texels],
    l: &shadowgraph::technique::LightGpu,
    s: &shadowgraph::cpu::light::LightSample,
    v: f64,
) -> f64 {
    let m = shadowgraph::cpu::mips::sample(moments, l, s)[0].max(1e-37);
    let c = f64::from(l.exp_pos);
    let ulp = 2f64.powi(-23);
    let x = m.ln() + c - c * s.depth;
    let depth = c * 4.0 * ulp * (s.view_z + f64::from(l.near)) / f64::from(l.far - l.near);
    let rel = 16.0 * ulp
        + 2f64.powi(-21)
        + 3.0 * ulp * m.ln().abs()
        + 4.0 * ulp * (c + c * s.depth)
        + (3.0 + 2.0 * x.abs()) * ulp
        + depth;
    1e-6 + v * rel
}

/// A linear depth map with structure: a background and overlapping random rectangles, so
/// windows see mixes of occluders (never all zeros).
pub fn blocky_map(rng: &mut SmallRng, size: usize) -> Vec<f32> {
    let mut m: Vec<f32> = (0..size * size)
        .map(|_| rng.random_range(0.85..0.95))
        .collect();
    for _ in 0..12 {
        let (x0, y0) = (rng.random_range(0..size), rng.random_range(0..size));
        let (w, h) = (rng.random_range(2..size / 3), rng.random_range(2..size / 3));
        let z: f32 = rng.random_range(0.15..0.7);
        for y in y0..(y0 + h).min(size) {
            for x in x0..(x0 + w).min(size) {
                m[y * size + x] = z + rng.random_range(0.0..0.02);
            }
        }
    }
    m
}

/// The f64 reference `f` at sample `s`, or `None` where nudging the receiver by ±1e-4 texel in
/// UV or ±2e-6 in depth makes it jump by more than 1e-3 (a texel boundary or a comparison tie,
/// where f32 and f64 may legitimately disagree). Continuous changes (bilinear weights) stay
/// below that threshold; a single tap flipping moves every tested kernel by more.
pub fn robust(
    s: &shadowgraph::cpu::light::LightSample,
    map_size: usize,
    f: impl Fn(&shadowgraph::cpu::light::LightSample) -> f64,
) -> Option<f64> {
    let v = f(s);
    let du = 1e-4 / map_size as f64;
    let nudges = [
        (du, 0.0, 0.0),
        (-du, 0.0, 0.0),
        (0.0, du, 0.0),
        (0.0, -du, 0.0),
        (0.0, 0.0, 2e-6),
        (0.0, 0.0, -2e-6),
    ];
    for (dx, dy, dz) in nudges {
        let mut t = *s;
        t.uv = [s.uv[0] + dx, s.uv[1] + dy];
        t.depth += dz;
        if (f(&t) - v).abs() > 1e-3 {
            return None;
        }
    }
    Some(v)
}

/// Tolerance of MSM visibility at `s`: the kernel's solve is backward stable in the stored
/// moments (their covariances are formed once, the bias added as non-negative terms), so the
/// GPU computes the exact answer for moments off by a few dozen roundings; the tolerance is
/// twice the largest change of the f64 reference over 16 such perturbations of the
/// (dequantized) moments before their projection and bias (relative 32·2⁻²⁴ per moment,
/// ±8·2⁻²⁴ on the receiver depth), plus 1e-4 for the final rational expression.
pub fn msm_tolerance(
    moments: &[shadowgraph::cpu::Texels],
    l: &shadowgraph::technique::LightGpu,
    s: &shadowgraph::cpu::light::LightSample,
) -> f64 {
    use shadowgraph::cpu::vis_msm::{bias_for, branch_spread, dequantized, intensity};
    use shadowgraph::technique::MSM_HAUSDORFF;
    let b = dequantized(&shadowgraph::cpu::mips::sample(moments, l, s), l);
    let d = s.depth - f64::from(l.bias);
    let hausdorff = l.msm_flags & MSM_HAUSDORFF != 0;
    let vis = |b: [f64; 4], d: f64| {
        let v = 1.0 - intensity(&bias_for(b, l), d, hausdorff).clamp(0.0, 1.0);
        if v.is_nan() { 1.0 } else { v }
    };
    let base = vis(b, d);
    let e = 32.0 * 2f64.powi(-24);
    let mut worst: f64 = 0.0;
    for k in 0..16u32 {
        let sign = |bit: u32| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
        let p: [f64; 4] = std::array::from_fn(|i| b[i] * (1.0 + sign(i as u32) * e));
        let dd = d + sign(k % 4) * 8.0 * 2f64.powi(-24);
        worst = worst.max((vis(p, dd) - base).abs());
    }
    // Where a root sits at 0 or 1, rounding picks Hamburger's or Hausdorff's formula.
    let spread = branch_spread(&bias_for(b, l), d, hausdorff, 1e-3);
    worst = worst.max(spread);
    let bleed = f64::from(l.bleed);
    (1e-4 + 2.0 * worst) / (1.0 - bleed)
}

/// Tolerance of CSM visibility: Vulkan specifies `sin`/`cos` to 2⁻¹¹ absolute on [−π, π]
/// (the kernels reduce their arguments there), so term k may be off by w_k · 2 · 2⁻¹¹ in the
/// receiver's factors; the sum is scaled by `scale`. Plus 1e-5 for the f32 sum.
pub fn csm_tolerance(l: &shadowgraph::technique::LightGpu) -> f64 {
    let m = f64::from(l.csm_terms);
    let weights: f64 = (1..=l.csm_terms)
        .map(|k| {
            let kf = f64::from(k) / m;
            2.0 / (std::f64::consts::PI * f64::from(2 * k - 1))
                * (-f64::from(l.csm_attenuation) * kf * kf).exp()
        })
        .sum();
    1e-5 + f64::from(l.csm_scale) * weights * 2.0 * 2f64.powi(-11)
}
