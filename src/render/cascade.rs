//! Cascaded shadow maps in the renderer. A directional light with `cascades = N > 1` is drawn
//! as N lights: cascade 0 in the scene light's own place, cascades 1… after every scene light.
//! Each is the scene light moved across its direction onto a slice's bounding sphere (the
//! fitting of `model::cascades`: the practical split of the camera's view range, texel-snapped
//! centres) with that sphere's radius as its half-width, so its depth axis, near and far
//! planes — hence its biases and every technique's depth units — are the scene light's. Each
//! gets its own raster pass, graph nodes (the light's technique, filtered per cascade) and
//! visibility function; the shading picks one per pixel (`kernels/shared/cascade.wgsl`).
//!
//! PCSS and the soft techniques size their search and penumbra in world units from those
//! depths, so every cascade estimates the same shadow at its own resolution. What differs is
//! each map's coverage: a cascade's map is widened by a guard band ([`guard`]) as wide
//! as the technique's reach, the same in world units in every cascade, and its `max_search`
//! (UV of its own map) caps search and filter at that reach, so no lookup of a receiver in the
//! slice reads past the map's edge and no cap changes from one cascade to the next.

use glam::{Mat4, Vec3};

use crate::error::{Error, Result};
use crate::model::cascades::{CascadeCamera, CascadeSlice, SliceGuard, cascade_light, fit_slices};
use crate::model::{Cascades, Light, LightKind};
use crate::scene::Scene;
use crate::{technique::CascadeGroup, wgsl_mirrors::LightGpu};

/// The camera's near plane (`model::Camera::view_proj`): the closest a cascade range starts.
const CAMERA_NEAR: f32 = 0.05;

/// The shallowest view-distance range the cascades split, as a fraction of its near distance:
/// far enough from f32's resolution (2⁻²³) that every split is distinct.
pub const MIN_RANGE: f64 = 1.0 / 1024.0;

/// The farthest view distance cascades cover (`model::cascades::split_distances`' limit):
/// geometry beyond it reads the last cascade.
pub const MAX_VIEW_DISTANCE: f32 = crate::model::cascades::MAX_VIEW_DISTANCE;

/// The lights a frame draws: the scene's, a cascaded one as its cascade 0, then the further
/// cascades of each cascaded light.
#[derive(Clone, Debug)]
pub struct DrawnLights {
    /// Every drawn light (cascades carry [`Cascades::SINGLE`]).
    pub lights: Vec<Light>,
    /// Their GPU descriptions; a cascaded light's entry holds its cascade fields.
    pub gpu: Vec<LightGpu>,
    /// The cascaded lights.
    pub groups: Vec<CascadeGroup>,
    /// The scene's light count (the visibility channels).
    pub visible: usize,
}

impl DrawnLights {
    /// The scene light and cascade of drawn light `k`.
    pub fn owner(&self, k: usize) -> (usize, usize) {
        for g in &self.groups {
            if (g.first..g.first + g.extra()).contains(&k) {
                return (g.light, k - g.first + 1);
            }
        }
        (k, 0)
    }
}

/// The view-distance range the cascades of `scene` cover: from the nearest point of the
/// scene's geometry in front of the camera (at least the camera's near plane) to the farthest,
/// at least [`MIN_RANGE`] of the near distance deep (a scene thin along the view, or far from
/// the camera, still splits) and at most [`MAX_VIEW_DISTANCE`]. With no geometry in front the
/// cascades shade nothing, and cover the first [`MIN_RANGE`] past the near plane. An error
/// (the scene's nearest geometry beyond [`MAX_VIEW_DISTANCE`]) names the first cascaded
/// light's `cascades` key with its line.
pub fn view_range(scene: &Scene) -> Result<(f32, f32)> {
    let eye = scene.camera.position.as_dvec3();
    let forward = (scene.camera.target.as_dvec3() - eye).normalize();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in scene.objects.iter().flat_map(|o| &o.mesh.positions) {
        let d = (p.as_dvec3() - eye).dot(forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let camera_near = f64::from(CAMERA_NEAR);
    let near = if hi > camera_near {
        lo.max(camera_near)
    } else {
        camera_near
    };
    let limit = f64::from(MAX_VIEW_DISTANCE);
    if near * (1.0 + MIN_RANGE) > limit {
        let why = format!(
            "the scene's nearest geometry lies {} units from `camera.position`{}, past the {} that cascades cover; move the camera closer or use one map (`cascades = 1`)",
            crate::scene::fmt_num(near),
            scene.locations.get("camera.position"),
            crate::scene::fmt_num(limit)
        );
        let light = scene
            .lights
            .iter()
            .position(|l| l.shadow.cascades.count > 1);
        return Err(match light {
            Some(i) => cascade_error(scene, i, why),
            None => Error::Scene {
                path: scene.path.clone(),
                location: scene.locations.get("camera.position"),
                message: format!("cascades: {why}"),
            },
        });
    }
    let far = hi.max(near * (1.0 + MIN_RANGE)).min(limit);
    Ok((near as f32, far as f32))
}

/// The camera of `scene` as the cascades see it.
pub fn cascade_camera(scene: &Scene) -> Result<CascadeCamera> {
    let (near, far) = view_range(scene)?;
    let c = &scene.camera;
    Ok(CascadeCamera {
        view: Mat4::look_at_rh(c.position, c.target, c.up),
        fov_y: c.fov_y_degrees.to_radians(),
        aspect: scene.width as f32 / scene.height as f32,
        near,
        far,
    })
}

/// The lights `scene` draws.
pub fn drawn_lights(scene: &Scene) -> Result<DrawnLights> {
    let mut lights: Vec<Light> = scene.lights.clone();
    let mut gpu: Vec<LightGpu> = scene.lights.iter().map(LightGpu::new).collect();
    let mut groups = Vec::new();
    let visible = lights.len();
    for (i, light) in scene.lights.iter().enumerate() {
        let c = light.shadow.cascades;
        if c.count <= 1 || !matches!(light.kind, LightKind::Directional { .. }) {
            continue;
        }
        crate::technique::params::cascade_support(&light.shadow.technique).map_err(|why| {
            cascade_error(
                scene,
                i,
                format!(
                    "does not apply to technique \"{}\": {why}",
                    light.shadow.technique.name()
                ),
            )
        })?;
        let camera = cascade_camera(scene)?;
        let guard = crate::technique::cascade_guard(light);
        let slices = fit_slices(
            &camera,
            light.direction(),
            c.count,
            c.lambda,
            light.shadow_map,
            guard,
        )
        .map_err(|e| cascade_error(scene, i, e.to_string()))?;
        let group = CascadeGroup {
            light: i,
            first: lights.len(),
            count: slices.len(),
        };
        let cascade_lights: Vec<Light> = slices
            .iter()
            .map(|s| cascade_light(light, s, guard))
            .collect();
        let capped = guard != SliceGuard::NONE;
        lights[i] = cascade_lights[0].clone();
        gpu[i] = cascade_gpu(&cascade_lights[0], &group, &camera, c, &slices);
        gpu[i].capped_filter |= u32::from(capped);
        for l in &cascade_lights[1..] {
            let mut g = LightGpu::new(l);
            g.capped_filter |= u32::from(capped);
            gpu.push(g);
            lights.push(l.clone());
        }
        groups.push(group);
    }
    Ok(DrawnLights {
        lights,
        gpu,
        groups,
        visible,
    })
}

/// An error of light `i`'s cascades, naming its `cascades` key with the file and line.
fn cascade_error(scene: &Scene, i: usize, why: String) -> Error {
    let key = format!("light[{i}].shadow.cascades");
    Error::Scene {
        path: scene.path.clone(),
        location: scene.locations.get(&key),
        message: match scene.lights.get(i) {
            Some(l) => format!("`{key}` = {}: {why}", l.shadow.cascades.count),
            None => format!("`{key}`: {why}"),
        },
    }
}

/// Cascade 0's description with the cascade fields the pick reads.
fn cascade_gpu(
    first: &Light,
    group: &CascadeGroup,
    camera: &CascadeCamera,
    c: Cascades,
    slices: &[CascadeSlice],
) -> LightGpu {
    let mut g = LightGpu::new(first);
    let to_world = camera.view.inverse();
    g.cascade_eye = to_world.transform_point3(Vec3::ZERO).to_array();
    g.cascade_forward = to_world.transform_vector3(-Vec3::Z).normalize().to_array();
    g.cascade_count = group.count as u32;
    g.cascade_first = group.first as u32;
    g.cascade_near = camera.near;
    g.cascade_blend = c.blend;
    for (k, s) in slices.iter().enumerate() {
        g.cascade_far[k / 4][k % 4] = s.far;
    }
    g
}
