//! What changes per frame: a light's matrices and depth range as the host rasterized them.

use glam::{Mat4, Vec3, Vec4};

use super::{PrefilterConfig, StageError};
use crate::model::{Light, LightKind, Shadow};
use crate::wgsl_mirrors::LightGpu;

/// What changes per frame: the matrices the host rasterized the depth texture with, and how
/// its depth maps to distance. The projection follows wgpu's conventions: right-handed view
/// space looking down −Z, depth 0 at `near` and 1 at `far` (glam's `*_rh` projections; not
/// reversed Z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightParams {
    /// World → light view.
    pub view: Mat4,
    /// Light view → clip: the projection the depth texture was rasterized with.
    pub projection: Mat4,
    /// Perspective (spot) rather than orthographic (directional) depth.
    pub perspective: bool,
    /// A point light ([`LightParams::point`]): six faces in one `3N × 2N` atlas the host
    /// rasterizes with [`crate::prefilter::Prefilter::point_views`]; `view` gives its position,
    /// `projection` is not used (each face's is the stage's, widened by its guard band).
    pub point: bool,
    /// Near plane (view-space distance).
    pub near: f32,
    /// Far plane.
    pub far: f32,
    /// Distance from the light's position to its target along the view axis (world units):
    /// where a directional light's area emitter sits, so its angular size is
    /// `light_size / target_distance` (what `smrt`'s parallel rays follow, as the renderer's
    /// truth does). The constructors set 1; [`LightParams::from_light`] the scene's.
    pub target_distance: f32,
    /// This map's cap on PCSS's and the soft techniques' search and filter half-widths
    /// (shadow-map UV), in place of the config's `max_search`, with PCSS's filter capped there
    /// as its search is: one cascade's share of its light's world reach, which
    /// [`crate::prefilter::Prefilter::fit_light_cascades`] sets so that every cascade estimates
    /// the same penumbra. `None` (what the constructors set): the config's. Refused on a point
    /// light, whose faces' guard bands follow the config's, and on a technique without a
    /// search.
    pub max_search: Option<f32>,
}

impl LightParams {
    /// An orthographic light of half-width `half_width` (world units), `view` from the host.
    pub fn orthographic(view: Mat4, half_width: f32, near: f32, far: f32) -> Self {
        let e = half_width;
        Self {
            view,
            projection: Mat4::orthographic_rh(-e, e, -e, e, near, far),
            perspective: false,
            point: false,
            near,
            far,
            target_distance: 1.0,
            max_search: None,
        }
    }

    /// A square perspective light with full field of view `fov_y_radians`.
    pub fn perspective(view: Mat4, fov_y_radians: f32, near: f32, far: f32) -> Self {
        Self {
            view,
            projection: Mat4::perspective_rh(fov_y_radians, 1.0, near, far),
            perspective: true,
            point: false,
            near,
            far,
            target_distance: 1.0,
            max_search: None,
        }
    }

    /// A point light at `position`: its shadow map is six perspective faces (+X, −X, +Y, −Y,
    /// +Z, −Z) in one atlas, three faces wide and two high, each face's frustum widened by the
    /// technique's guard band; the host draws its depth pass once per face with the matrices
    /// and viewports of [`crate::prefilter::Prefilter::point_views`].
    pub fn point(position: Vec3, near: f32, far: f32) -> Self {
        Self {
            view: Mat4::from_translation(-position),
            projection: Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, near, far),
            perspective: true,
            point: true,
            near,
            far,
            target_distance: 1.0,
            max_search: None,
        }
    }

    /// A scene light's matrices and planes (what shadowgraph's renderer rasterizes with).
    pub fn from_light(light: &Light) -> Self {
        if light.kind == LightKind::Point {
            return Self::point(light.position, light.near, light.far)
                .with_target_distance((light.target - light.position).length());
        }
        Self {
            view: light.view(),
            projection: light.projection(),
            perspective: matches!(light.kind, LightKind::Spot { .. }),
            point: false,
            near: light.near,
            far: light.far,
            target_distance: (light.target - light.position).length(),
            max_search: None,
        }
    }

    /// These parameters with the emitter `distance` from the light's position
    /// ([`LightParams::target_distance`]).
    pub fn with_target_distance(mut self, distance: f32) -> Self {
        self.target_distance = distance;
        self
    }

    /// Checks the planes (as a scene does) and that the projection maps the near plane to
    /// depth 0 and the far plane to 1 with the stated kind of `w`.
    pub fn validate(&self) -> Result<(), StageError> {
        let err = |field, message: String| StageError::LightParams { field, message };
        for (field, m) in [("view", self.view), ("projection", self.projection)] {
            if !m.is_finite() {
                return Err(err(field, "has a non-finite element".into()));
            }
        }
        if self.view.determinant().abs() < 1e-12 {
            return Err(err("view", "is not invertible".into()));
        }
        for (field, v) in [("near", self.near), ("far", self.far)] {
            if !v.is_finite() || !(1e-6..=1e7).contains(&v) {
                return Err(err(field, format!("{v} is outside [1e-6, 1e7]")));
            }
        }
        if !(self.target_distance.is_finite() && self.target_distance > 0.0) {
            return Err(err(
                "target_distance",
                format!("{} must be finite and positive", self.target_distance),
            ));
        }
        if let Some(m) = self.max_search
            && !(m.is_finite() && m > 0.0 && m <= 1.0)
        {
            return Err(err(
                "max_search",
                format!("{m} is outside (0, 1] (shadow-map UV)"),
            ));
        }
        // A point light's faces are widened for the config's reach (`point_views`): a cap of
        // its own would read past their guard bands.
        if self.point && self.max_search.is_some() {
            return Err(err(
                "max_search",
                "a point light's faces are banded for the config's max_search; leave it None"
                    .into(),
            ));
        }
        if self.far <= self.near {
            return Err(err(
                "far",
                format!("{} must exceed near ({})", self.far, self.near),
            ));
        }
        // A point light's faces are the stage's own projections.
        if self.point {
            return Ok(());
        }
        // Depth must be 0 at the near plane and 1 at the far one, as `linearize` assumes; w is
        // the distance (perspective) or 1 (orthographic).
        for (plane, z, depth) in [("near", self.near, 0.0), ("far", self.far, 1.0)] {
            let clip = self.projection * Vec4::new(0.0, 0.0, -z, 1.0);
            let w = if self.perspective { z } else { 1.0 };
            let d = clip.z / clip.w;
            if (clip.w - w).abs() > 1e-4 * w || (d - depth).abs() > 1e-4 {
                let kind = if self.perspective {
                    "a perspective"
                } else {
                    "an orthographic"
                };
                return Err(err(
                    "projection",
                    format!(
                        "maps the {plane} plane (z = −{z}) to depth {d} with w = {}, where \
                         {kind} projection with depth 0 at near and 1 at far (not reversed Z) \
                         gives depth {depth} with w = {w}",
                        clip.w
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The scene light these parameters and `config` describe on `size`² maps (a point
    /// light's: six `size`² faces; how the stage reuses [`crate::technique::add_light_nodes`]).
    pub fn scene_light(&self, config: &PrefilterConfig, size: u32) -> Light {
        let to_world = self.view.inverse();
        let position = to_world.transform_point3(Vec3::ZERO);
        let forward = to_world.transform_vector3(Vec3::NEG_Z);
        // Symmetric frusta: x_clip = m00·x (orthographic: over w = 1; perspective: over −z).
        let m00 = self.projection.x_axis.x;
        let kind = if self.point {
            LightKind::Point
        } else if self.perspective {
            LightKind::Spot {
                fov_degrees: (2.0 * (1.0 / m00).atan()).to_degrees(),
            }
        } else {
            LightKind::Directional { extent: 1.0 / m00 }
        };
        Light {
            kind,
            position,
            target: position + forward * self.target_distance,
            near: self.near,
            far: self.far,
            size: config.light_size,
            radiance: Vec3::ONE,
            shadow_map: size,
            shadow: Shadow {
                technique: match self.max_search {
                    Some(uv) => config.technique.with_max_search(uv),
                    None => config.technique,
                },
                bias: config.bias,
                // Slope-scaled bias is rasterization state: the host's depth pass owns it.
                slope_bias: 0.0,
                normal_bias: config.normal_bias,
                receiver_plane: config.receiver_plane,
                cascades: crate::model::Cascades::SINGLE,
            },
        }
    }

    /// The WGSL `struct Light` for these matrices, `config`'s technique and `size`² maps:
    /// the host's `view` and `projection` exactly as given (not rebuilt from a look-at), the
    /// light at the view's origin looking down its −Z, map width from the projection's x
    /// scale, radiance 1 and no spot cone (`cos_outer` = −1: the host shades its own cone).
    pub fn light_gpu(&self, config: &PrefilterConfig, size: u32) -> LightGpu {
        let light = self.scene_light(config, size);
        let mut g = LightGpu::new(&light);
        // A cascade's own cap bounds PCSS's filter too, as its guard band allows.
        g.capped_filter |= u32::from(self.max_search.is_some());
        if self.point {
            // The faces' matrices are the stage's (`point_views`); the light is its position.
            return g;
        }
        g.view = self.view.to_cols_array_2d();
        g.view_proj = (self.projection * self.view).to_cols_array_2d();
        g.position = light.position.to_array();
        g.direction = (light.target - light.position).normalize().to_array();
        g.width_at_unit = 2.0 / self.projection.x_axis.x;
        g.map_size = [size as f32; 2];
        g.cos_outer = -1.0;
        g
    }
}
