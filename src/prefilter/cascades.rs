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

use super::{LightGpu, LightParams};
use crate::error::StageError;
pub use crate::model::cascades::{CascadeCamera, MAX_CASCADES, split_distances};
use crate::model::cascades::{SliceGuard, fit_slices, light_rotation};

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

/// The cascades of a directional light shining along `direction` (toward the scene) for
/// `camera`.
pub fn fit_cascades(
    camera: &CascadeCamera,
    direction: Vec3,
    layout: &CascadeLayout,
) -> Result<Vec<Cascade>, StageError> {
    if layout.map_size == 0 || !(layout.caster_margin >= 0.0 && layout.caster_margin.is_finite()) {
        return Err(StageError::Config {
            field: "cascade map_size/caster_margin".into(),
            message: format!(
                "need map_size > 0 and a finite margin ≥ 0; got {} and {}",
                layout.map_size, layout.caster_margin
            ),
        });
    }
    let slices = fit_slices(
        camera,
        direction,
        layout.count,
        layout.lambda,
        layout.map_size,
        SliceGuard::NONE,
    )?;
    let dir = direction.normalize();
    let (_, up) = light_rotation(dir);
    let mut out = Vec::with_capacity(slices.len());
    for slice in slices {
        let radius = slice.radius;
        let back = radius + layout.caster_margin;
        let eye = slice.center - dir * back;
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
            near: slice.near,
            far: slice.far,
            radius,
        });
    }
    Ok(out)
}

/// The view distance of world point `p` for `camera` (what selects its cascade).
pub fn view_distance(camera: &CascadeCamera, p: Vec3) -> f32 {
    -(camera.view * p.extend(1.0)).xyz().z
}

/// Fills the cascade fields of `first` (cascade 0's [`LightGpu`], its `PrefilterOutput::light`)
/// that `sg_cascade_pick` in the exported WGSL reads: the camera's eye and forward direction,
/// the cascades' count and far view distances, the first cascade's near distance and the
/// blend band `blend` (a fraction of each cascade's range, as [`super::PrefilterConfig`]'s
/// `cascades.blend`). The pick then matches the renderer's (`kernels/shared/cascade.wgsl`).
pub fn pick_fields(
    first: &mut LightGpu,
    camera: &CascadeCamera,
    cascades: &[Cascade],
    blend: f32,
) -> Result<(), StageError> {
    if cascades.is_empty() || cascades.len() > MAX_CASCADES as usize {
        return Err(StageError::Config {
            field: "cascades".into(),
            message: format!("{} cascades: need 1–{MAX_CASCADES}", cascades.len()),
        });
    }
    let to_world = camera.view.inverse();
    first.cascade_eye = to_world.transform_point3(Vec3::ZERO).to_array();
    first.cascade_forward = to_world
        .transform_vector3(Vec3::NEG_Z)
        .normalize()
        .to_array();
    first.cascade_count = cascades.len() as u32;
    // The renderer's index of cascade 1 among its lights; a host keeps its own.
    first.cascade_first = 1;
    first.cascade_near = cascades[0].near;
    first.cascade_blend = blend;
    first.cascade_far = [[0.0; 4]; 2];
    for (k, c) in cascades.iter().enumerate() {
        first.cascade_far[k / 4][k % 4] = c.far;
    }
    Ok(())
}
