//! References of `kernels/shade.wgsl`: `pixel_differentials` (how far a pixel's receiver moves
//! to the next pixel, from the camera's rays) and the shading itself ([`shade`]: Lambert +
//! ambient with given visibilities, so an image can be shaded with another visibility, e.g. the
//! ground truth's).

use glam::DVec3;

use crate::model::CameraRays;
use crate::wgsl_mirrors::FrameGpu;
use crate::wgsl_mirrors::LightGpu;

/// What [`shade`] needs besides the G-buffer: the frame constants, each light and each
/// material's albedo, as the shading kernel receives them.
pub struct Shading<'a> {
    /// Frame constants (ambient, background).
    pub frame: &'a FrameGpu,
    /// The lights, in scene order.
    pub lights: &'a [LightGpu],
    /// Albedo per material (the G-buffer normal's `w` indexes it).
    pub materials: &'a [[f32; 3]],
}

/// `main` of `kernels/shade.wgsl` for one pixel: the G-buffer's `position` (w = coverage) and
/// `normal` (w = material), and `visibility` per light; returns the sRGB colour in [0, 1]
/// before the 8-bit store.
pub fn shade(s: &Shading, position: [f32; 4], normal: [f32; 4], visibility: &[f32]) -> [f64; 3] {
    let v = |c: [f32; 3]| DVec3::new(c[0].into(), c[1].into(), c[2].into());
    if position[3] == 0.0 {
        return linear_to_srgb(v(s.frame.background));
    }
    let p = DVec3::new(position[0].into(), position[1].into(), position[2].into());
    let gn = DVec3::new(normal[0].into(), normal[1].into(), normal[2].into());
    let n = if gn.length_squared() == 0.0 {
        DVec3::Y
    } else {
        gn.normalize()
    };
    let last = s.materials.len().saturating_sub(1);
    let albedo = s
        .materials
        .get((normal[3].max(0.0) as usize).min(last))
        .map_or(DVec3::ZERO, |&c| v(c));
    let mut radiance = v(s.frame.ambient) * albedo;
    for (l, &vis) in s.lights.iter().zip(visibility) {
        let ndl = n.dot(super::light::to_light(l, p)).max(0.0);
        radiance += albedo * v(l.radiance) * (ndl * f64::from(vis) * cone(l, p));
    }
    linear_to_srgb(radiance)
}

/// `cone`: spot lights light only their cone (soft edge over the outer 10% of the angle).
fn cone(l: &LightGpu, p: DVec3) -> f64 {
    if l.kind != 1 {
        return 1.0;
    }
    let pos = DVec3::new(
        l.position[0].into(),
        l.position[1].into(),
        l.position[2].into(),
    );
    let dir = DVec3::new(
        l.direction[0].into(),
        l.direction[1].into(),
        l.direction[2].into(),
    );
    let c = (p - pos).normalize().dot(dir);
    let e0 = f64::from(l.cos_outer);
    let e1 = e0 + 0.1 * (1.0 - e0);
    let t = ((c - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// `linear_to_srgb`, per channel, after clamping to [0, 1].
fn linear_to_srgb(c: DVec3) -> [f64; 3] {
    c.to_array().map(|x| {
        let x = x.clamp(0.0, 1.0);
        if x <= 0.0031308 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        }
    })
}

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
