//! Cascaded shadow maps for a directional light, fitted for a host: the camera's view range is
//! split among 1–8 cascades (the practical split, a blend of logarithmic and uniform), and each
//! cascade gets an orthographic [`LightParams`] that covers its slice of the camera's frustum
//! and does not shimmer as the camera moves or turns:
//!
//! - its half-width is the radius of the slice's bounding sphere, which depends only on the
//!   slice's shape (distances, field of view, aspect), not on where the camera looks;
//! - its centre is snapped to the cascade's texel grid in the light's (fixed) orientation, so
//!   a world point keeps its position within a texel while the camera translates.
//!
//! Each cascade is one layer of the host's depth array, filtered by one light slot of a
//! [`super::Prefilter`] (`record_light(k, …, DepthLayer::new(&array, k), &cascade.light)`);
//! the host picks the cascade by the pixel's view depth against [`Cascade::far`]
//! (`examples/host_lights.rs`).

use glam::{Mat4, Vec3, Vec4Swizzles};

use super::LightParams;
use crate::error::StageError;

/// Cascades one light may have.
pub const MAX_CASCADES: u32 = 8;

/// The camera the cascades cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeCamera {
    /// World → camera view (right-handed, looking down −Z).
    pub view: Mat4,
    /// Full vertical field of view, radians.
    pub fov_y: f32,
    /// Width / height.
    pub aspect: f32,
    /// The view distance the first cascade starts at.
    pub near: f32,
    /// The view distance the last cascade ends at (the shadow distance).
    pub far: f32,
}

/// How the cascades are laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeLayout {
    /// Number of cascades, 1–[`MAX_CASCADES`].
    pub count: u32,
    /// 0: uniform split, 1: logarithmic; the practical split blends the two (0.5–0.9 is usual).
    pub lambda: f32,
    /// Each cascade's map side (texels).
    pub map_size: u32,
    /// How far toward the light, beyond a slice's bounding sphere, casters are kept (world
    /// units): casters outside the camera's view still cast into it.
    pub caster_margin: f32,
}

/// One cascade.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cascade {
    /// Its light: orthographic, texel-snapped.
    pub light: LightParams,
    /// The view distance it starts at.
    pub near: f32,
    /// The view distance it ends at: a pixel at view distance `d` uses the first cascade with
    /// `d ≤ far`.
    pub far: f32,
    /// The half-width of its map (world units): its texel is `2 · radius / map_size`.
    pub radius: f32,
}

/// The far distance of each cascade, the practical split (Zhang et al. 2006):
/// `d_i = λ · n · (f / n)^(i / N) + (1 − λ) · (n + (f − n) · i / N)`, `i = 1 … N`; the last is `far`.
pub fn split_distances(
    near: f32,
    far: f32,
    count: u32,
    lambda: f32,
) -> Result<Vec<f32>, StageError> {
    let bad = |field: &'static str, message: String| StageError::Config {
        field: field.into(),
        message,
    };
    if !(1..=MAX_CASCADES).contains(&count) {
        return Err(bad(
            "cascades",
            format!("{count} is outside 1..={MAX_CASCADES}"),
        ));
    }
    if !(0.0..=1.0).contains(&lambda) {
        return Err(bad("cascade_lambda", format!("{lambda} is outside [0, 1]")));
    }
    if !(near.is_finite() && far.is_finite() && near > 0.0 && far > near) {
        return Err(bad(
            "cascade near/far",
            format!("need 0 < near < far, finite; got near {near}, far {far}"),
        ));
    }
    let (n, f) = (f64::from(near), f64::from(far));
    Ok((1..=count)
        .map(|i| {
            let t = f64::from(i) / f64::from(count);
            let log = n * (f / n).powf(t);
            let uniform = n + (f - n) * t;
            (f64::from(lambda) * log + (1.0 - f64::from(lambda)) * uniform) as f32
        })
        .collect())
}

/// The cascades of a directional light shining along `direction` (toward the scene) for
/// `camera`.
pub fn fit_cascades(
    camera: &CascadeCamera,
    direction: Vec3,
    layout: &CascadeLayout,
) -> Result<Vec<Cascade>, StageError> {
    let bad = |field: &'static str, message: String| StageError::Config {
        field: field.into(),
        message,
    };
    if !direction.is_finite() || direction.length_squared() < 1e-12 {
        return Err(bad("direction", format!("{direction} is not a direction")));
    }
    if !(camera.fov_y > 0.0
        && camera.fov_y < 3.1
        && camera.aspect > 0.0
        && camera.aspect.is_finite())
    {
        return Err(bad(
            "camera",
            format!(
                "fov_y {} and aspect {} must be positive (fov below π)",
                camera.fov_y, camera.aspect
            ),
        ));
    }
    if layout.map_size == 0 || !(layout.caster_margin >= 0.0 && layout.caster_margin.is_finite()) {
        return Err(bad(
            "cascade map_size/caster_margin",
            format!(
                "need map_size > 0 and a finite margin ≥ 0; got {} and {}",
                layout.map_size, layout.caster_margin
            ),
        ));
    }
    let fars = split_distances(camera.near, camera.far, layout.count, layout.lambda)?;
    let to_world = camera.view.inverse();
    let dir = direction.normalize();
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    // The light's orientation, fixed: only its position follows the camera.
    let rotation = Mat4::look_to_rh(Vec3::ZERO, dir, up);
    let mut near = camera.near;
    let mut out = Vec::with_capacity(fars.len());
    for far in fars {
        let (center, radius) = slice_sphere(camera, near, far);
        let world_center = to_world.transform_point3(center);
        let texel = 2.0 * radius / layout.map_size as f32;
        let c = rotation.transform_point3(world_center);
        let snapped = Vec3::new(
            (c.x / texel).round() * texel,
            (c.y / texel).round() * texel,
            c.z,
        );
        let snapped_world = rotation.inverse().transform_point3(snapped);
        let back = radius + layout.caster_margin;
        let eye = snapped_world - dir * back;
        let light_near = 1e-3 * back.max(1.0);
        let light = LightParams::orthographic(
            Mat4::look_to_rh(eye, dir, up),
            radius,
            light_near,
            back + radius + light_near,
        );
        light.validate()?;
        out.push(Cascade {
            light,
            near,
            far,
            radius,
        });
        near = far;
    }
    Ok(out)
}

/// The bounding sphere of the frustum slice between view distances `near` and `far`, in view
/// space: centred on the view axis, through the far corners and (where they are farther) the
/// near ones. It depends only on the slice's shape, so turning the camera does not change the
/// radius. Rounded up to 1/64 of itself's binary order so float noise cannot change it.
fn slice_sphere(camera: &CascadeCamera, near: f32, far: f32) -> (Vec3, f32) {
    let t = (0.5 * camera.fov_y).tan();
    // Squared half-diagonal of a slice rectangle per unit distance.
    let k = t * t * (1.0 + camera.aspect * camera.aspect);
    // Centre at distance z on the axis, equidistant from a near and a far corner:
    // (z − n)² + k n² = (f − z)² + k f²  ⇒  z = (f + n)(1 + k) / 2.
    let z = (0.5 * (far + near) * (1.0 + k)).min(far);
    let r2 = ((far - z).powi(2) + k * far * far).max((z - near).powi(2) + k * near * near);
    let radius = quantize_up(r2.sqrt());
    (Vec3::new(0.0, 0.0, -z), radius)
}

/// `r` rounded up to a multiple of 2^(⌊log2 r⌋ − 6).
fn quantize_up(r: f32) -> f32 {
    let quantum = 2f32.powi(r.log2().floor() as i32 - 6);
    (r / quantum).ceil() * quantum
}

/// The view distance of world point `p` for `camera` (what selects its cascade).
pub fn view_distance(camera: &CascadeCamera, p: Vec3) -> f32 {
    -(camera.view * p.extend(1.0)).xyz().z
}
