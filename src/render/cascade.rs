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
use crate::model::cascades::{
    CascadeCamera, CascadeSlice, SliceGuard, cascade_light, fit_slices, guard,
};
use crate::model::{Cascades, Light, LightKind};
use crate::scene::Scene;
use crate::technique::{CascadeGroup, LightGpu};

/// The camera's near plane (`model::Camera::view_proj`): the closest a cascade range starts.
const CAMERA_NEAR: f32 = 0.05;

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
/// scene's geometry in front of the camera (at least the camera's near plane) to the farthest.
pub fn view_range(scene: &Scene) -> Result<(f32, f32)> {
    let eye = scene.camera.position;
    let forward = (scene.camera.target - eye).normalize();
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for p in scene.objects.iter().flat_map(|o| &o.mesh.positions) {
        let d = (*p - eye).dot(forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let near = lo.max(CAMERA_NEAR);
    if hi.is_nan() || hi <= near * 1.001 {
        return Err(Error::Invalid(
            "cascades: no geometry lies in front of the camera".into(),
        ));
    }
    Ok((near, hi))
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
            Error::Invalid(format!(
                "light[{i}]: {} cascades of technique \"{}\": {why}",
                c.count,
                light.shadow.technique.name()
            ))
        })?;
        let camera = cascade_camera(scene)?;
        let guard = guard(light);
        let slices = fit_slices(
            &camera,
            light.direction(),
            c.count,
            c.lambda,
            light.shadow_map,
            guard,
        )
        .map_err(|e| Error::Invalid(format!("light[{i}]: {e}")))?;
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
