//! Reference of `kernels/vsm.wgsl`.

use super::Texels;

/// Moments `(z, z² + ¼(∂x² + ∂y²))` of a linear depth map, each partial the smaller-magnitude
/// one-sided difference (clamped at the edges).
pub fn vsm(linear: &Texels) -> Texels {
    let z = |x: i64, y: i64| linear.at(x, y)[0];
    let partial = |c: f64, before: f64, after: f64| {
        let (f, b) = (after - c, c - before);
        if f.abs() < b.abs() { f } else { b }
    };
    let mut data = Vec::with_capacity(linear.width * linear.height * 2);
    for y in 0..linear.height as i64 {
        for x in 0..linear.width as i64 {
            let c = z(x, y);
            let dx = partial(c, z(x - 1, y), z(x + 1, y));
            let dy = partial(c, z(x, y - 1), z(x, y + 1));
            data.extend([c, c * c + 0.25 * (dx * dx + dy * dy)]);
        }
    }
    Texels {
        width: linear.width,
        height: linear.height,
        channels: 2,
        data,
    }
}
