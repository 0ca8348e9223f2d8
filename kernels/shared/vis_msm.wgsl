// Moment shadow maps (Peters & Klein 2015), four moments b = (z, z², z³, z⁴) of the filtered
// depth distribution. The moments are biased toward those of a fixed three-point distribution
// (b' = (1 − α) b + α b₀) so the Hankel matrix stays positive definite, then:
// Hamburger: solve B c = (1, d, d²) by Cholesky, the roots z₂ ≤ z₃ of c₃x² + c₂x + c₁ are the
// other support points of the distribution through d that matches b', and the fraction of it
// in front of d is the shadow intensity (three cases by where d lies). Hausdorff: the same when
// z₂, z₃ lie in [0, 1], else the four-point solution supported on [0, 1].
//
// f32: the Cholesky pivots are the covariances of (z, z²) under b' (Var z, and Var z² less
// its regression on z). Formed from b' they cancel ~1-sized terms down to ~α-sized ones, and
// the mix's own roundings land in them too. Here the covariances of the stored moments are
// formed once (raw f32 moments projected onto valid ones first), the bias is added as a
// mixture's covariance, a sum of non-negative terms, and each pivot is floored at α times
// b₀'s, which no distribution's biased moments go below. Measured behind flat occluders at
// α = 10⁻⁴ (README, "MSM moment bias"): the largest error against exact arithmetic 0.016
// where the mix-then-Cholesky form gave 0.053 (raw f32 moments).
// Degenerate moments (bias 0 on a flat map) fall back to the two-moment Chebyshev bound or the
// step at the mean instead of dividing by zero.
// #import shared/light
// #import shared/sampling
// #import shared/msm_quantize

// Moments of {0, ½, 1} with weights (3/16, 10/16, 3/16): Peters' b₀ = (0, 0.375, 0, 0.375)
// on [−1, 1], mapped to depth in [0, 1].
const MSM_B0: vec4<f32> = vec4<f32>(0.5, 0.34375, 0.265625, 0.2265625);
// Its covariances (Var z, Cov(z, z²), Var z²) and the Schur complement
// Var z² − Cov(z, z²)²/Var z, exact in f32.
const MSM_B0_COV: vec3<f32> = vec3<f32>(0.09375, 0.09375, 0.1083984375);
const MSM_B0_SCHUR: f32 = 0.0146484375;

// Biased moments as the reconstruction reads them: the raw moments (for Hausdorff's closed
// form) and the mean, second moment and covariances of (z, z²).
struct MsmMoments {
    // (1 − α)·m + α·b₀.
    b: vec4<f32>,
    // Var z, Cov(z, z²), Var z² of the biased distribution.
    cov: vec3<f32>,
    // b'.yzw − b'.xyz and 1 − b'.x (Hausdorff), mixed from the data's and b₀'s differences
    // rather than differenced after the mix (near z = 1 they are α-sized).
    diff: vec3<f32>,
    below_one: f32,
    // The bias α.
    alpha: f32,
}

// Data moments `m` (dequantized) biased by `alpha` toward MSM_B0, see the header. `project`:
// raw moments, whose roundings are independent per channel, are first projected onto valid
// ones (Var z, Var z² ≥ 0, |Cov(z, z²)| ≤ √(Var z·Var z²)); quantized ones are not: their
// errors come through the dequantization's matrix, whose design keeps them out of the
// near-null directions, and a clamp per entry would undo that.
fn msm_moments(m: vec4<f32>, alpha: f32, project: bool) -> MsmMoments {
    var c = vec3<f32>(m.y - m.x * m.x, m.z - m.x * m.y, m.w - m.y * m.y);
    if project {
        c.x = max(c.x, 0.0);
        c.z = max(c.z, 0.0);
        let limit = sqrt(c.x * c.z);
        c.y = clamp(c.y, -limit, limit);
    }
    // A mixture's covariance: the parts' covariances plus that of their means,
    // (1 − α)·C(m) + α·C(b₀) + α(1 − α)·e eᵀ, e the difference of the means of (z, z²).
    let w = 1.0 - alpha;
    let e = m.xy - MSM_B0.xy;
    var out: MsmMoments;
    out.b = w * m + alpha * MSM_B0;
    out.cov = w * c + alpha * MSM_B0_COV + (alpha * w) * vec3<f32>(e.x * e.x, e.x * e.y, e.y * e.y);
    out.alpha = alpha;
    out.diff = w * (m.yzw - m.xyz) + alpha * (MSM_B0.yzw - MSM_B0.xyz);
    out.below_one = w * (1.0 - m.x) + alpha * (1.0 - MSM_B0.x);
    return out;
}

// The Hamburger reconstruction through d: (z₂, z₃, case) where z₂ ≤ z₃ are the other support
// points of the three-point distribution that matches the biased moments and has a point at
// d (solve B c = (1, d, d²) by B = L·diag(1, Var z, s)·Lᵀ, L = [[1], [μ, 1], [E z², ℓ, 1]],
// ℓ = Cov(z, z²)/Var z, s = Var z² − ℓ·Cov(z, z²); roots of c₃x² + c₂x + c₁). The pivots
// Var z and s are at least α times b₀'s (B ⪰ α·B₀ for the moments of any distribution), and
// are floored there. case 0: regular; 1: the variance is (numerically) 0, a single point at
// the mean; 2: rank-deficient, two support points (z₂, z₃ then meaningless).
fn msm_roots(mm: MsmMoments, d: f32) -> vec3<f32> {
    let var1 = max(mm.cov.x, mm.alpha * MSM_B0_COV.x);
    if !(var1 > 1e-12) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let l32 = mm.cov.y / var1;
    let d3 = max(mm.cov.z - l32 * mm.cov.y, mm.alpha * MSM_B0_SCHUR);
    if !(d3 > 0.0) {
        return vec3<f32>(0.0, 0.0, 2.0);
    }
    // Forward substitution, scaling by the diagonal, back substitution.
    let b = mm.b;
    let y2 = d - b.x;
    let y3 = d * d - b.y - l32 * y2;
    let c3 = y3 / d3;
    let c2 = y2 / var1 - l32 * c3;
    let c1 = 1.0 - b.x * c2 - b.y * c3;
    // The root of larger magnitude without cancellation, the other from Vieta's product
    // c₁/c₃: −p/2 ± √(p²/4 − q) loses the smaller root when the other is far away (c₃ → 0,
    // as behind a flat occluder), and with it the weights, which cancel against it.
    let t = -0.5 * (c2 + select(-1.0, 1.0, c2 >= 0.0) * sqrt(max(c2 * c2 - 4.0 * c3 * c1, 0.0)));
    // Each root held within ±MSM_ROOT_LIMIT: where c₃ (or t) rounds to 0 the far support point
    // is at ±∞ in f32 (huge but finite in exact arithmetic), and the weights' quotients become
    // ∞/∞ = NaN, which read as lit or unshadowed (measured: a receiver in `city_street`'s
    // umbra read lit under `cssm`'s moment search). Held there, the point's weight vanishes as
    // it should: the error is O(1/MSM_ROOT_LIMIT).
    let r1 = clamp(t / c3, -MSM_ROOT_LIMIT, MSM_ROOT_LIMIT);
    let r2 = clamp(c1 / t, -MSM_ROOT_LIMIT, MSM_ROOT_LIMIT);
    return vec3<f32>(min(r1, r2), max(r1, r2), 0.0);
}

// The largest magnitude of a support point msm_roots returns (see there); the weights' products
// of two such distances stay far inside f32's range.
const MSM_ROOT_LIMIT: f32 = 1e8;

// E[(z − x)(z − y)] under the biased moments: (μ − x)(μ − y) + Var z, free of the
// cancellation in E z² − (x + y)·μ + x·y.
fn msm_expect(mm: MsmMoments, x: f32, y: f32) -> f32 {
    return (mm.b.x - x) * (mm.b.x - y) + mm.cov.x;
}

// Shadow intensity (share of the depth distribution in front of d) from biased moments.
fn msm_intensity(mm: MsmMoments, d: f32, hausdorff: bool) -> f32 {
    let b = mm.b;
    let roots = msm_roots(mm, d);
    if roots.z == 1.0 {
        return select(0.0, 1.0, d > b.x);
    }
    if roots.z == 2.0 {
        // Rank-deficient: two support points; Chebyshev's bound is the best statement left.
        if d <= b.x {
            return 0.0;
        }
        let t = d - b.x;
        return t * t / (mm.cov.x + t * t);
    }
    let z2 = roots.x;
    let z3 = roots.y;
    if hausdorff && (z2 < 0.0 || z3 > 1.0) {
        // Peters & Klein's four-point solution on [0, 1], in the differences D = mm.diff:
        // free = ((b₃ − b₂)d + b₃ − b₄)/((b₂ − b₁)d + b₂ − b₃), and b₃ − b₁ − (free + 1)(b₂ − b₁)
        // = D₁ − free·D₀.
        let g = mm.diff;
        let free = (g.y * d - g.z) / (g.x * d - g.y);
        let w1 = select(0.0, 1.0, d > free);
        return (g.x + (g.y - free * g.x) * (free - w1 - d) / (d * (d - free))) / (free - w1)
            + mm.below_one;
    }
    if d <= z2 {
        return 0.0;
    }
    if d <= z3 {
        return msm_expect(mm, d, z3) / ((z3 - z2) * (d - z2));
    }
    return 1.0 - msm_expect(mm, z2, z3) / ((d - z2) * (d - z3));
}

// #fetches vis_msm: sample_map
fn vis_msm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    return vis_msm_of(sample_map(map, l, s), l, s);
}

// Filtered (possibly quantized) moments `m` dequantized and biased toward MSM_B0.
fn msm_biased(m: vec4<f32>, l: Light) -> MsmMoments {
    let quantized = (l.msm_flags & 2u) != 0u;
    var b = m;
    if quantized {
        b = msm_dequantize(b);
    }
    return msm_moments(b, l.moment_bias, !quantized);
}

// Visibility from filtered (possibly quantized) moments `m` however they were filtered.
fn vis_msm_of(m: vec4<f32>, l: Light, s: LightSample) -> f32 {
    let mm = msm_biased(m, l);
    let intensity = msm_intensity(mm, s.depth - l.bias, (l.msm_flags & 1u) != 0u);
    let v = 1.0 - clamp(intensity, 0.0, 1.0);
    // NaN compares false both ways: a non-finite intensity reads as fully lit.
    return linstep(l.bleed, 1.0, select(1.0, v, v == v));
}
