//! How far around a receiver each technique's lookup reads, from its entry
//! ([`super::TechniqueDef::reach`], [`super::TechniqueDef::texels_past_radius`]), and what rests on it: a point light's face layout (and
//! so its projection, raster views and width) and a cascade's guard band.
//!
//! The [`Light`] methods below are the model's, implemented here because they read the
//! registry: every caller is in this layer or above (`docs/ARCHITECTURE.md`, "Layers").

use glam::Mat4;

use super::of;
use crate::model::cascades::SliceGuard;
use crate::model::point::{self, PointLayout, filter_reach};
use crate::model::{Light, LightKind, Technique};

/// How far around a receiver's texel `technique`'s lookup reads a point light's map, in face
/// texels, counting what its prefilter folded into the texels it reads (`face`: the face's
/// side); an error says why a technique cannot be bounded to one face.
pub fn reach(technique: &Technique, face: u32) -> Result<f32, String> {
    (of(technique).reach)(technique, face)
}

/// The reach of a technique that reads one texel around the receiver (`hard`).
pub(super) fn one_texel(_: &Technique, _: u32) -> Result<f32, String> {
    Ok(1.0)
}

/// The reach of a prefiltered technique: its filter's ([`filter_reach`]: the bilinear tap,
/// plus the blur's radius, the table's half box, or the mip level's texel span).
pub(super) fn filtered(technique: &Technique, face: u32) -> Result<f32, String> {
    filter_reach(
        technique.filter().unwrap_or(crate::model::Filter::None),
        face,
    )
}

/// The reach of PCSS and the soft techniques: the search radius and (on a point light) the
/// filter radius are capped at `max_search`, and so is a soft technique's window (at most
/// `max_width` texels), plus what its lookup reads past that radius
/// ([`super::TechniqueDef::texels_past_radius`]).
pub(super) fn searched(technique: &Technique, face: u32) -> Result<f32, String> {
    let max_search = technique.max_search().unwrap_or(0.0);
    let radius = (2.0 * max_search * face as f32).clamp(1.0, face as f32) * 0.5;
    Ok(radius + of(technique).texels_past_radius.unwrap_or(0.0))
}

/// The texels `technique`'s lookup reads past its search radius (capped at `max_search`):
/// PCSS's taps take the nearest texel (1); a table's window rounds its edges to texels and
/// snaps the blocker window outward (2). `None` for techniques without a search.
pub fn texels_past_radius(technique: &Technique) -> Option<f32> {
    of(technique).texels_past_radius
}

/// The guard band of a cascaded directional `light`'s maps. PCSS and the soft techniques:
/// their reach `R` in world units — the cap on search and filter radius that `max_search`
/// sets on the light's one map (`max_search · 2·extent`), or the widest radius they can
/// read, `0.5 · size · (far − near) / near` (the penumbra of a blocker at the near plane over
/// a receiver at the far one; every search radius is smaller), whichever is less — plus the
/// texels their lookups read past a radius ([`texels_past_radius`], as a point light's faces),
/// one for the snapped centre (half a texel each way) and the normal offset (`normal_bias`
/// texels). The other techniques keep the slice's bounding sphere (their filters read a few
/// texels around receivers that lie inside it).
pub fn cascade_guard(light: &Light) -> SliceGuard {
    let t = &light.shadow.technique;
    let (Some(max_search), Some(taps), LightKind::Directional { extent }) =
        (t.max_search(), texels_past_radius(t), light.kind)
    else {
        return SliceGuard::NONE;
    };
    let widest = if light.near > 0.0 {
        0.5 * light.size * (light.far - light.near) / light.near
    } else {
        f32::INFINITY
    };
    SliceGuard {
        world: (max_search * 2.0 * extent).min(widest),
        texels: taps + 1.0 + light.shadow.normal_bias.max(0.0),
    }
}

impl Light {
    /// A point light's face layout for its technique ([`reach`]); an error for other lights or
    /// a technique that cannot be bounded to a face.
    pub fn point_layout(&self) -> Result<PointLayout, String> {
        if self.kind != LightKind::Point {
            return Err("not a point light".into());
        }
        let reach = reach(&self.shadow.technique, self.shadow_map)?;
        PointLayout::new(self.shadow_map, reach)
    }

    /// Light view → clip (depth in [0, 1]); a point light's: each face's, over its widened
    /// frustum ([`PointLayout::projection`]; a 90° face where its technique has no layout,
    /// which scene validation and the plug-in refuse first).
    pub fn projection(&self) -> Mat4 {
        match self.kind {
            LightKind::Directional { extent } => {
                Mat4::orthographic_rh(-extent, extent, -extent, extent, self.near, self.far)
            }
            LightKind::Spot { fov_degrees } => {
                Mat4::perspective_rh(fov_degrees.to_radians(), 1.0, self.near, self.far)
            }
            LightKind::Point => match self.point_layout() {
                Ok(layout) => layout.projection(self.near, self.far),
                Err(_) => {
                    Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, self.near, self.far)
                }
            },
        }
    }

    /// World → clip of each rasterized view of the light with its viewport in the map
    /// (x, y, width, height in texels): the whole map for one-map lights, the six faces'
    /// tiles for a point light.
    pub fn raster_views(&self) -> Vec<([f32; 16], [u32; 4])> {
        match (self.kind, self.point_layout()) {
            (LightKind::Point, Ok(layout)) => {
                let proj = layout.projection(self.near, self.far);
                (0..point::FACES)
                    .map(|f| {
                        let (x, y) = layout.origin(f);
                        let vp = proj * PointLayout::view(self.position, f);
                        (vp.to_cols_array(), [x, y, layout.face, layout.face])
                    })
                    .collect()
            }
            _ => {
                let (w, h) = self.map_dims();
                let vp = self.projection() * self.view();
                vec![(vp.to_cols_array(), [0, 0, w, h])]
            }
        }
    }

    /// World width covered by the shadow map at view distance 1 (spot; a point light's face)
    /// or at any distance (directional): the map spans `width_at_unit * distance` (spot)
    /// world units.
    pub fn width_at_unit(&self) -> f32 {
        match self.kind {
            LightKind::Directional { extent } => 2.0 * extent,
            LightKind::Spot { fov_degrees } => 2.0 * (0.5 * fov_degrees.to_radians()).tan(),
            LightKind::Point => 2.0 * self.point_layout().map_or(1.0, |l| l.tan_half),
        }
    }

    /// One-line description for plans and reports.
    pub fn label(&self) -> String {
        let kind = match self.kind {
            LightKind::Directional { .. } => "directional",
            LightKind::Spot { .. } => "spot",
            LightKind::Point => "point",
        };
        let map = match self.kind {
            LightKind::Point => match self.point_layout() {
                Ok(l) => format!(
                    "six {}² faces, guard band {} texels (90° cores of {}²)",
                    l.face,
                    l.guard,
                    l.face - 2 * l.guard
                ),
                Err(_) => format!("six {}² faces", self.shadow_map),
            },
            _ => format!("{}² map", self.shadow_map),
        };
        format!("{kind}, {} shadows, {map}", self.shadow.technique.name())
    }
}
