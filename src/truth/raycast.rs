//! The independent CPU ground truth: f64 ray casting, no shadow maps. Primary rays through the
//! pixel centres (the rasterizer's sample points) find the first hit; shadow rays from it to
//! each emitter sample ([`super::emitter`]) count the samples it sees.
//!
//! A shadow ray spans what any shadow map of the light sees: from the receiver to the light's
//! near plane (view distance `near` along its axis); toward a spot sample it aims at the
//! sample point, toward a directional sample it runs parallel to the sample's direction. Its
//! own triangle is skipped (a flat triangle cannot shadow itself) and hits closer than
//! `1e-9 · (1 + |p|)` are ignored; there is no depth bias.

use glam::{DMat4, DVec3, DVec4};

use super::bvh::Bvh;
use super::{axis_distance, emitter, relevant};
use crate::{
    model::{Light, LightKind},
    scene::Scene,
};

/// Ray-cast visibility per pixel and light.
#[derive(Clone, Debug)]
pub struct CpuTruth {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Number of lights.
    pub lights: usize,
    /// Fraction of emitter samples seen, `visibility[px * lights + l]` (1 outside the mask).
    pub visibility: Vec<f64>,
    /// Relevant receivers ([`super::relevant`]) at the ray-cast hits.
    pub mask: Vec<bool>,
    /// First hit per pixel (position, unit normal facing the camera), `None` for background.
    pub hits: Vec<Option<(DVec3, DVec3)>>,
}

/// Ray casts every light of `scene` at the scene's output size, with emitter samples at
/// `offsets` (units of the light's size), using every core.
pub fn ray_cast_truth(scene: &Scene, offsets: &[[f64; 2]]) -> CpuTruth {
    let bvh = Bvh::new(scene);
    let (w, h) = (scene.width as usize, scene.height as usize);
    let lights = scene.lights.len();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(h.max(1));
    let rows_per = h.div_ceil(threads.max(1));
    let mut hits = vec![None; w * h];
    let mut visibility = vec![1.0; w * h * lights];
    let mut mask = vec![false; w * h * lights];
    let camera = CameraRays::new(scene);
    std::thread::scope(|s| {
        let chunks = hits
            .chunks_mut(rows_per * w)
            .zip(visibility.chunks_mut(rows_per * w * lights))
            .zip(mask.chunks_mut(rows_per * w * lights))
            .enumerate();
        for (c, ((hits, vis), mask)) in chunks {
            let (bvh, camera) = (&bvh, &camera);
            s.spawn(move || {
                for (i, hit) in hits.iter_mut().enumerate() {
                    let px = c * rows_per * w + i;
                    let (o, d) = camera.ray(px % w, px / w);
                    let Some(first) = bvh.nearest(o, d, 0.0, f64::INFINITY, None) else {
                        continue;
                    };
                    let (p, n) = surface(bvh, o, d, &first);
                    *hit = Some((p, n));
                    for (li, light) in scene.lights.iter().enumerate() {
                        if relevant(light, p, n) {
                            mask[i * lights + li] = true;
                            vis[i * lights + li] = seen(bvh, light, p, first.triangle, offsets);
                        }
                    }
                }
            });
        }
    });
    CpuTruth {
        width: scene.width,
        height: scene.height,
        lights,
        visibility,
        mask,
        hits,
    }
}

/// Primary rays of the scene camera (the G-buffer's projection, in f64).
struct CameraRays {
    inverse: DMat4,
    size: (f64, f64),
}

impl CameraRays {
    fn new(scene: &Scene) -> Self {
        let c = &scene.camera;
        let aspect = f64::from(scene.width) / f64::from(scene.height);
        let proj =
            DMat4::perspective_rh(f64::from(c.fov_y_degrees).to_radians(), aspect, 0.05, 500.0);
        let view = DMat4::look_at_rh(c.position.as_dvec3(), c.target.as_dvec3(), c.up.as_dvec3());
        Self {
            inverse: (proj * view).inverse(),
            size: (f64::from(scene.width), f64::from(scene.height)),
        }
    }

    /// Origin on the near plane and unit direction through the centre of pixel (x, y).
    fn ray(&self, x: usize, y: usize) -> (DVec3, DVec3) {
        let ndc_x = 2.0 * (x as f64 + 0.5) / self.size.0 - 1.0;
        let ndc_y = 1.0 - 2.0 * (y as f64 + 0.5) / self.size.1;
        let at = |z: f64| {
            let v: DVec4 = self.inverse * DVec4::new(ndc_x, ndc_y, z, 1.0);
            v.truncate() / v.w
        };
        let (near, far) = (at(0.0), at(1.0));
        (near, (far - near).normalize())
    }
}

/// Hit position and interpolated unit normal, turned toward the camera (as the G-buffer's
/// two-sided normal: negated on a triangle seen from its back).
fn surface(bvh: &Bvh, o: DVec3, d: DVec3, hit: &super::bvh::Hit) -> (DVec3, DVec3) {
    let t = &bvh.triangles[hit.triangle];
    let [u, v] = hit.uv;
    let n = ((1.0 - u - v) * t.n[0] + u * t.n[1] + v * t.n[2]).normalize_or_zero();
    let front = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).dot(-d) > 0.0;
    (o + hit.t * d, if front { n } else { -n })
}

/// Fraction of the emitter samples at `offsets` that `p` (on triangle `own`) sees.
fn seen(bvh: &Bvh, light: &Light, p: DVec3, own: usize, offsets: &[[f64; 2]]) -> f64 {
    let near = f64::from(light.near);
    let z = axis_distance(light, p);
    let (_, _, axis) = emitter::frame(light);
    let t_min = 1e-9 * (1.0 + p.length());
    let unoccluded = offsets
        .iter()
        .filter(|&&off| {
            let q = emitter::point(light, off);
            let (dir, t_max) = match light.kind {
                LightKind::Spot { .. } | LightKind::Point => {
                    let to = q - p;
                    let len = to.length();
                    (to / len, len * (1.0 - near / z).max(0.0))
                }
                LightKind::Directional { .. } => {
                    let dk = (light.target.as_dvec3() - q).normalize();
                    (-dk, ((z - near) / dk.dot(axis)).max(0.0))
                }
            };
            !bvh.occluded(p, dir, t_min, t_max, Some(own))
        })
        .count();
    unoccluded as f64 / offsets.len() as f64
}
