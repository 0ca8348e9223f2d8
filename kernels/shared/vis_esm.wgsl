// Exponential shadow maps: visibility = clamp(E[exp(c z)] · exp(−c d), 0, 1), with the filtered
// moment kept as its logarithm L, so the product is exp(L − c d) and never overflows.
// #import shared/light
// #import shared/sampling

// #fetches vis_esm: sample_map_log
fn vis_esm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    return vis_esm_of_log(sample_map_log(map, l, s), l, s);
}

// The `sat` filter's table sums the moment scaled by exp(−c), m = E[exp(c (z − 1))]: its log
// moment is ln m + c. A mean that quantization left at or below 0 reads as fully shadowed.
fn vis_esm_of_sat(m: vec4<f32>, l: Light, s: LightSample) -> f32 {
    return vis_esm_of_log(log(max(m.x, 1e-37)) + l.exp_pos, l, s);
}

fn vis_esm_of_log(log_moment: f32, l: Light, s: LightSample) -> f32 {
    return clamp(exp(log_moment - l.exp_pos * (s.depth - l.bias)), 0.0, 1.0);
}
