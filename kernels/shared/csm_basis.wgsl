// The CSM Fourier basis (import-only module): (sin c_k x, cos c_k x), c_k = π (2k − 1).

const CSM_PI: f32 = 3.141592653589793;

// (sin, cos) of π (2k − 1) x, with (2k − 1) x reduced to [−1, 1] (period 2) before the
// multiplication by π, so the trigonometric argument stays in [−π, π].
fn csm_sin_cos(k: u32, x: f32) -> vec2<f32> {
    let y = f32(2u * k - 1u) * x;
    let t = CSM_PI * (y - 2.0 * round(0.5 * y));
    return vec2<f32>(sin(t), cos(t));
}
