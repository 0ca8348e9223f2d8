//! Cascaded shadow maps for a directional light, the math both the renderer and the plug-in's
//! host helper (`prefilter::cascades`) use: the practical split of the camera's view range,
//! and each slice's bounding sphere with its centre snapped to the cascade's texel grid in the
//! light's fixed orientation (so a world point keeps its place within a texel as the camera
//! moves, and the half-width does not change as it turns).

use glam::{Mat4, Vec3};

use crate::error::StageError;

/// Cascades one light may have.
pub const MAX_CASCADES: u32 = 8;

/// The farthest view distance cascades split (a light's planes' range, `LightParams::validate`):
/// the slices' spheres stay far from f32's limits.
pub const MAX_VIEW_DISTANCE: f32 = 1e7;

/// How a directional light's shadow is split into cascades (`[light.shadow]` keys `cascades`,
/// `cascade_lambda`, `cascade_blend`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cascades {
    /// Number of cascades, 1–[`MAX_CASCADES`]; 1 is the light's single map.
    pub count: u32,
    /// 0: uniform split, 1: logarithmic; the practical split blends the two.
    pub lambda: f32,
    /// The blend band at the far end of each cascade but the last, as a fraction of the
    /// cascade's view-distance range: across it the visibility fades to the next cascade's.
    pub blend: f32,
}

impl Cascades {
    /// One map: no cascades.
    pub const SINGLE: Self = Self {
        count: 1,
        lambda: 0.5,
        blend: 0.1,
    };
}

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

/// One cascade's slice of the camera's view and the sphere that bounds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeSlice {
    /// The view distance it starts at.
    pub near: f32,
    /// The view distance it ends at.
    pub far: f32,
    /// The bounding sphere's centre (world), snapped to the cascade's texel grid across the
    /// light's direction.
    pub center: Vec3,
    /// The cascade map's half-width: the bounding sphere's radius, widened by the guard band.
    pub radius: f32,
}

/// A band around each slice that its cascade's map covers too, so that a lookup around any
/// receiver of the slice reads texels of that map rather than its clamped edge: `world` units
/// (a soft technique's reach, the same in every cascade) plus `texels` of the cascade's own
/// map (a filter's taps beyond that reach, the centre's snapping, the normal offset).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SliceGuard {
    /// World units beyond the slice's bounding sphere, across the light's direction.
    pub world: f32,
    /// Texels of the cascade's map beyond that.
    pub texels: f32,
}

impl SliceGuard {
    /// No band: the map is the slice's bounding sphere.
    pub const NONE: Self = Self {
        world: 0.0,
        texels: 0.0,
    };

    /// The half-width of a `map_size`² map that covers a sphere of `radius` and this band:
    /// `(radius + world) / (1 − 2·texels / map_size)`, its texel then `2·half-width / map_size`.
    pub fn half_width(&self, radius: f32, map_size: u32) -> f32 {
        (radius + self.world) / (1.0 - 2.0 * self.texels / map_size as f32)
    }
}

/// `light` moved across its direction so that its axis passes through `slice`'s centre, with
/// the slice's (guarded) radius as its half-width and, for PCSS and the soft techniques, the
/// guard's world reach as `max_search` in its own map's UV.
pub fn cascade_light(
    light: &super::Light,
    slice: &CascadeSlice,
    guard: SliceGuard,
) -> super::Light {
    let dir = light.direction();
    let to_center = slice.center - light.position;
    let across = to_center - dir * to_center.dot(dir);
    let mut l = light.clone();
    l.position += across;
    l.target += across;
    l.kind = super::LightKind::Directional {
        extent: slice.radius,
    };
    l.shadow.cascades = Cascades::SINGLE;
    // A technique without `max_search` (no band) keeps its parameters.
    l.shadow.technique = l
        .shadow
        .technique
        .with_max_search(guard.world / (2.0 * slice.radius));
    l
}

fn bad(field: &'static str, message: String) -> StageError {
    StageError::Config {
        field: field.into(),
        message,
    }
}

/// The far distance of each cascade, the practical split (Zhang et al. 2006):
/// `d_i = λ · n · (f / n)^(i / N) + (1 − λ) · (n + (f − n) · i / N)`, `i = 1 … N`; the last is `far`.
pub fn split_distances(
    near: f32,
    far: f32,
    count: u32,
    lambda: f32,
) -> Result<Vec<f32>, StageError> {
    if !(1..=MAX_CASCADES).contains(&count) {
        return Err(bad(
            "cascades",
            format!("{count} is outside 1..={MAX_CASCADES}"),
        ));
    }
    if !(0.0..=1.0).contains(&lambda) {
        return Err(bad("cascade_lambda", format!("{lambda} is outside [0, 1]")));
    }
    // A light's planes' range (`LightParams::validate`): the slices' spheres stay far from
    // f32's limits.
    if !(near.is_finite()
        && far.is_finite()
        && near >= 1e-6
        && far > near
        && far <= MAX_VIEW_DISTANCE)
    {
        return Err(bad(
            "cascade near/far",
            format!("need 1e-6 ≤ near < far ≤ 1e7; got near {near}, far {far}"),
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

/// The light's fixed orientation for `direction` (unit): what texel snapping is done in.
pub fn light_rotation(direction: Vec3) -> (Mat4, Vec3) {
    let up = if direction.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    (Mat4::look_to_rh(Vec3::ZERO, direction, up), up)
}

/// The slices of `camera`'s view for `count` cascades split with `lambda`, each with its
/// bounding sphere widened by `guard` and snapped to the grid of a `map_size`² map in the
/// orientation of a light shining along `direction`.
pub fn fit_slices(
    camera: &CascadeCamera,
    direction: Vec3,
    count: u32,
    lambda: f32,
    map_size: u32,
    guard: SliceGuard,
) -> Result<Vec<CascadeSlice>, StageError> {
    if !direction.is_finite() || direction.length_squared() < 1e-12 {
        return Err(bad("direction", format!("{direction} is not a direction")));
    }
    if !camera.view.is_finite() || camera.view.determinant().abs() < 1e-12 {
        return Err(bad(
            "camera",
            "its view matrix is not finite and invertible".into(),
        ));
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
    if map_size == 0 {
        return Err(bad("map_size", "need map_size > 0".into()));
    }
    let finite = |x: f32| x.is_finite() && x >= 0.0;
    if !(finite(guard.world) && finite(guard.texels)) {
        return Err(bad(
            "guard",
            format!(
                "need a finite band ≥ 0; got {} world units and {} texels",
                guard.world, guard.texels
            ),
        ));
    }
    // As a point light's faces: a band past a quarter of the map is refused.
    if 4.0 * guard.texels > map_size as f32 {
        let fits = (4.0 * guard.texels).ceil() as u32;
        return Err(bad(
            "shadow_map",
            format!(
                "a guard band of {} texels is wider than a quarter of a {map_size}² cascade; the smallest map that fits it is {fits}",
                guard.texels
            ),
        ));
    }
    let fars = split_distances(camera.near, camera.far, count, lambda)?;
    let to_world = camera.view.inverse();
    let (rotation, _) = light_rotation(direction.normalize());
    let mut near = camera.near;
    let mut out = Vec::with_capacity(fars.len());
    for far in fars {
        let (center, sphere) = slice_sphere(camera, near, far);
        // Without a band: the sphere's radius, already a multiple of its quantum, so unchanged.
        let radius = quantize_up(guard.half_width(sphere, map_size));
        let texel = 2.0 * radius / map_size as f32;
        let c = rotation.transform_point3(to_world.transform_point3(center));
        let snapped = Vec3::new(
            (c.x / texel).round() * texel,
            (c.y / texel).round() * texel,
            c.z,
        );
        out.push(CascadeSlice {
            near,
            far,
            center: rotation.inverse().transform_point3(snapped),
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
