// Variance-shadow-map moments of one linear depth (import-only module of `vsm` and `vsm_blur`):
//   (z, z² + ¼ (∂z/∂x² + ∂z/∂y²))  (Donnelly & Lauritzen 2006).
// The derivative term (GPU Gems 3, ch. 8) is the variance of a planar surface across one
// texel, so a lit plane is not self-shadowed. In compute there is no rasterizer derivative:
// each partial is the smaller in magnitude of the forward and backward difference, so a
// silhouette (a jump on one side only) does not inflate the variance of the surface beside it.

// The one-sided difference of smaller magnitude.
fn vsm_partial(z: f32, before: f32, after: f32) -> f32 {
    let forward = after - z;
    let backward = z - before;
    return select(backward, forward, abs(forward) < abs(backward));
}

// The moments of depth `z` with its four neighbours (clamped at the map's edges).
fn vsm_moments(z: f32, left: f32, right: f32, up: f32, down: f32) -> vec2<f32> {
    let dx = vsm_partial(z, left, right);
    let dy = vsm_partial(z, up, down);
    return vec2<f32>(z, z * z + 0.25 * (dx * dx + dy * dy));
}
