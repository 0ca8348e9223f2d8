// Moment shadow maps (Peters & Klein 2015), four moments b = (z, z², z³, z⁴) of the filtered
// depth distribution. The moments are biased toward those of a fixed three-point distribution
// (b' = (1 − α) b + α b₀) so the Hankel matrix stays positive definite, then:
// Hamburger: solve B c = (1, d, d²) by Cholesky, the roots z₂ ≤ z₃ of c₃x² + c₂x + c₁ are the
// other support points of the distribution through d that matches b', and the fraction of it
// in front of d is the shadow intensity (three cases by where d lies). Hausdorff: the same when
// z₂, z₃ lie in [0, 1], else the four-point solution supported on [0, 1].
// Degenerate moments (bias 0 on a flat map) fall back to the two-moment Chebyshev bound or the
// step at the mean instead of dividing by zero.
// #import shared/light
// #import shared/sampling
// #import shared/msm_quantize

// Moments of {0, ½, 1} with weights (3/16, 10/16, 3/16): Peters' b₀ = (0, 0.375, 0, 0.375)
// on [−1, 1], mapped to depth in [0, 1].
const MSM_B0: vec4<f32> = vec4<f32>(0.5, 0.34375, 0.265625, 0.2265625);

// The Hamburger reconstruction through d: (z₂, z₃, case) where z₂ ≤ z₃ are the other support
// points of the three-point distribution that matches the biased moments b and has a point at
// d (solve B c = (1, d, d²) by Cholesky, roots of c₃x² + c₂x + c₁). case 0: regular; 1: the
// variance is (numerically) 0, a single point at b.x; 2: rank-deficient, two support points
// (z₂, z₃ then meaningless).
fn msm_roots(b: vec4<f32>, d: f32) -> vec3<f32> {
    let var1 = b.y - b.x * b.x;
    if !(var1 > 1e-12) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let l32 = (b.z - b.x * b.y) / var1;
    let d3 = b.w - b.y * b.y - l32 * l32 * var1;
    if !(d3 > 0.0) {
        return vec3<f32>(0.0, 0.0, 2.0);
    }
    // Forward substitution, scaling by the diagonal, back substitution.
    let y2 = d - b.x;
    let y3 = d * d - b.y - l32 * y2;
    let c3 = y3 / d3;
    let c2 = y2 / var1 - l32 * c3;
    let c1 = 1.0 - b.x * c2 - b.y * c3;
    let p = c2 / c3;
    let q = c1 / c3;
    let r = sqrt(max(0.25 * p * p - q, 0.0));
    return vec3<f32>(-0.5 * p - r, -0.5 * p + r, 0.0);
}

// Shadow intensity (share of the depth distribution in front of d) from biased moments b.
fn msm_intensity(b: vec4<f32>, d: f32, hausdorff: bool) -> f32 {
    let roots = msm_roots(b, d);
    if roots.z == 1.0 {
        return select(0.0, 1.0, d > b.x);
    }
    if roots.z == 2.0 {
        // Rank-deficient: two support points; Chebyshev's bound is the best statement left.
        if d <= b.x {
            return 0.0;
        }
        let t = d - b.x;
        return t * t / (b.y - b.x * b.x + t * t);
    }
    let z2 = roots.x;
    let z3 = roots.y;
    if hausdorff && (z2 < 0.0 || z3 > 1.0) {
        let free = ((b.z - b.y) * d + b.z - b.w) / ((b.y - b.x) * d + b.y - b.z);
        let w1 = select(0.0, 1.0, d > free);
        return (b.y - b.x + (b.z - b.x - (free + 1.0) * (b.y - b.x)) * (free - w1 - d)
            / (d * (d - free))) / (free - w1) + 1.0 - b.x;
    }
    if d <= z2 {
        return 0.0;
    }
    if d <= z3 {
        return (d * z3 - b.x * (d + z3) + b.y) / ((z3 - z2) * (d - z2));
    }
    return 1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / ((d - z2) * (d - z3));
}

// #fetches vis_msm: sample_map
fn vis_msm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    return vis_msm_of(sample_map(map, l, s), l, s);
}

// Filtered (possibly quantized) moments `m` dequantized and biased toward MSM_B0.
fn msm_biased(m: vec4<f32>, l: Light) -> vec4<f32> {
    var b = m;
    if (l.msm_flags & 2u) != 0u {
        b = msm_dequantize(b);
    }
    return mix(b, MSM_B0, l.moment_bias);
}

// Visibility from filtered (possibly quantized) moments `m` however they were filtered.
fn vis_msm_of(m: vec4<f32>, l: Light, s: LightSample) -> f32 {
    let b = msm_biased(m, l);
    let intensity = msm_intensity(b, s.depth - l.bias, (l.msm_flags & 1u) != 0u);
    let v = 1.0 - clamp(intensity, 0.0, 1.0);
    // NaN compares false both ways: a non-finite intensity reads as fully lit.
    return linstep(l.bleed, 1.0, select(1.0, v, v == v));
}
