//! Reference of `kernels/second_depth.wgsl`.

use super::linearize::linearize_texel;
use crate::wgsl_mirrors::SecondDepthParams;

/// The depth a second-depth map holds at one texel, from its first and second rasterized
/// depths `z1`, `z2` (depth-buffer values): the midpoint of their linear depths (`mode` 0) or
/// the second's (`mode` 1); the far plane, 1.0, in both modes where there is no second surface
/// (`z2` at the cleared far plane, 1.0, or not finite): nothing lies behind the first surface
/// there. Non-finite depths read as 1.0, as in `linearize`.
pub fn second_depth_texel(z1: f32, z2: f32, p: &SecondDepthParams) -> f64 {
    let (perspective, near, far) = (
        p.depth.perspective == 1,
        f64::from(p.depth.near),
        f64::from(p.depth.far),
    );
    let first = linearize_texel(z1, perspective, near, far).unwrap_or(1.0);
    let second = linearize_texel(z2, perspective, near, far).unwrap_or(1.0);
    if second >= 1.0 || p.mode == 1 {
        return second;
    }
    0.5 * (first + second)
}

/// The whole map, from the first and second depth maps (row-major, equal sizes).
pub fn second_depth(first: &[f32], second: &[f32], p: &SecondDepthParams) -> Vec<f64> {
    first
        .iter()
        .zip(second)
        .map(|(&z1, &z2)| second_depth_texel(z1, z2, p))
        .collect()
}
