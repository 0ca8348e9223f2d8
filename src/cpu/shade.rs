//! Reference of `pixel_differentials` in `kernels/shade.wgsl`: how far a pixel's receiver moves
//! to the next pixel, from the camera's rays.

use glam::DVec3;

use crate::render::CameraRays;

/// `(dp/dx, dp/dy)` of the receiver `p` (normal `n`) seen through pixel `(x, y)`: ray
/// differentials on the tangent plane, `t·(d_x − d·(d_x·n)/(d·n))` with
/// `t = (p − eye)·n / (d·n)` and `|d·n|` held at ≥ 10⁻³|d|.
pub fn pixel_differentials(
    eye: DVec3,
    rays: &CameraRays,
    x: u32,
    y: u32,
    p: DVec3,
    n: DVec3,
) -> (DVec3, DVec3) {
    let v = |v: glam::Vec3| v.as_dvec3();
    let (r00, rdx, rdy) = (v(rays.ray00), v(rays.ray_dx), v(rays.ray_dy));
    let d = r00 + (f64::from(x) + 0.5) * rdx + (f64::from(y) + 0.5) * rdy;
    let floor = 1e-3 * d.length();
    let dn0 = d.dot(n);
    let dn = if dn0 >= 0.0 {
        dn0.max(floor)
    } else {
        dn0.min(-floor)
    };
    let t = (p - eye).dot(n) / dn;
    (
        t * (rdx - d * (rdx.dot(n) / dn)),
        t * (rdy - d * (rdy.dot(n) / dn)),
    )
}
