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
//! the host picks the cascade by the pixel's view depth against [`Cascade::far`], or with the
//! exported `sg_cascade_pick` and the fields [`pick_fields`] fills (`examples/host_lights.rs`).
//!
//! Two fittings: [`fit_cascades`] gives each cascade its own depth range (the slice's sphere
//! and a caster margin: the tightest depth for the techniques that compare depths near the
//! receiver), and [`fit_light_cascades`] moves the host's one directional light across its
//! direction onto each slice, keeping its depth axis and planes, so that PCSS and the soft
//! techniques, whose penumbrae follow depths from the light's plane, estimate the same shadow
//! in every cascade; each of its maps is widened by a guard band as wide as the technique's
//! reach and given that reach as its own `max_search`: the fitting of the renderer's cascades
//! (`model::cascades`), from the host's matrices.

use glam::{Mat4, Vec3, Vec4Swizzles};

use super::{LightGpu, LightParams, PrefilterConfig};
use crate::error::StageError;
pub use crate::model::cascades::{CascadeCamera, MAX_CASCADES, split_distances};
use crate::model::cascades::{SliceGuard, cascade_light, fit_slices, light_rotation};

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

/// The cascades of the host's directional `light` (orthographic: the one map it would draw
/// without cascades; its view's origin is the emitter's plane, its near and far planes the
/// depth range, its half-width what `config`'s `max_search` is a fraction of) for `camera`,
/// laid out by `config`'s `cascades` on `config.size`² maps. Each cascade is `light` moved
/// across its direction onto a slice of the camera's view (oriented as the renderer orients a
/// directional light, so the texel snapping holds; the host's roll is not kept), with the same
/// planes and depth axis. For PCSS and the soft techniques each map is widened by a guard
/// band: the technique's reach `R` in world units (`max_search · 2·half-width`, or the widest
/// penumbra `0.5 · light_size · (far − near) / near`, whichever is less) plus the texels its
/// lookups read past a radius, the snapped centre and `normal_bias`; each cascade's
/// [`LightParams::max_search`] is `R` in its own map's UV, capping PCSS's filter too. A band
/// past a quarter of the map is refused.
pub fn fit_light_cascades(
    camera: &CascadeCamera,
    light: &LightParams,
    config: &PrefilterConfig,
) -> Result<Vec<Cascade>, StageError> {
    light.validate()?;
    if light.perspective || light.point {
        return Err(StageError::LightParams {
            field: "projection",
            message: "cascades need a directional light's orthographic projection".into(),
        });
    }
    let (config, _) = config.validated()?;
    let base = light.scene_light(&config, config.size);
    let band = crate::technique::cascade_guard(&base);
    let c = config.cascades;
    let slices = fit_slices(
        camera,
        base.direction(),
        c.count,
        c.lambda,
        config.size,
        band,
    )?;
    let capped = band != SliceGuard::NONE;
    slices
        .iter()
        .map(|s| {
            let l = cascade_light(&base, s, band);
            let mut params = LightParams::from_light(&l);
            params.max_search = l.shadow.technique.max_search().filter(|_| capped);
            params.validate()?;
            Ok(Cascade {
                light: params,
                near: s.near,
                far: s.far,
                radius: s.radius,
            })
        })
        .collect()
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
