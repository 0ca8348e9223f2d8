// Exponential shadow maps: visibility = clamp(E[exp(c z)] · exp(−c d), 0, 1), with the filtered
// moment kept as its logarithm L, so the product is exp(L − c d) and never overflows.
// #import shared/light
// #import shared/sampling

fn vis_esm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let log_moment = sample_map_log(map, l, s.uv);
    return clamp(exp(log_moment - l.exp_pos * (s.depth - l.bias)), 0.0, 1.0);
}
