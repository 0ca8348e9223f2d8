// Variance shadow maps: one-tailed Chebyshev (Cantelli) bound from the filtered moments,
//   σ² = max(E[z²] − μ², min_variance),  p_max = σ² / (σ² + (d − μ)²) for d > μ, else 1,
// then the light-bleeding reduction linstep(bleed, 1, p_max).
// #import shared/light
// #import shared/sampling

// #fetches vis_vsm: sample_map
fn vis_vsm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    return vis_vsm_of(sample_map(map, l, s), l, s);
}

// The bound from filtered moments `m` however they were filtered (the `sat` filter calls this
// with its rectangle mean).
fn vis_vsm_of(m: vec4<f32>, l: Light, s: LightSample) -> f32 {
    let d = s.depth - l.bias;
    if d <= m.x {
        return 1.0;
    }
    let variance = max(m.y - m.x * m.x, l.min_variance);
    let t = d - m.x;
    return linstep(l.bleed, 1.0, variance / (variance + t * t));
}
