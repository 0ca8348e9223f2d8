// Exponential variance moments of one linear depth (import-only module of `evsm` and
// `evsm_blur`; Lauritzen): z' = 2z − 1 ∈ [−1, 1],
//   pos = exp(c⁺ z'),  neg = −exp(−c⁻ z'),  (pos, pos², neg, neg²).

fn evsm_moments(z: f32, exp_pos: f32, exp_neg: f32) -> vec4<f32> {
    let w = 2.0 * z - 1.0;
    let pos = exp(exp_pos * w);
    let neg = -exp(-exp_neg * w);
    return vec4<f32>(pos, pos * pos, neg, neg * neg);
}
