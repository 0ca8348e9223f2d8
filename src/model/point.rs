//! Point lights: six perspective faces, one per axis direction, tiled into one atlas of 3 × 2
//! faces (`3N × 2N` texels for a face of `N`), rasterized in one pass and prefiltered by the
//! same graph as any one-map light.
//!
//! **Why an atlas with guard bands.** Every kernel of the graph (encodings, blurs, mip chains,
//! summed-area tables) runs unchanged on one 2-D texture, and every visibility function reads
//! it as it reads a spot light's map. A face's frustum is widened beyond its 90° core by a
//! guard band of `g` texels on each side, as wide as the technique's reach around a receiver
//! (its filter's half-width, the bilinear tap, the blur's radius, the search cap) plus one
//! texel: the shading picks the face whose axis is the major axis of the direction from the
//! light, so the receiver lands in that face's core, and every texel its lookup reads — and
//! every texel a prefilter folded into those — lies in the same face's tile, drawn from the same
//! centre of projection. No filter reads across a face edge and nothing seams: a receiver near
//! an edge is filtered over real geometry rendered into the guard band, not over a clamped or
//! wrapped neighbour. The cost is resolution: the core spans `N − 2g` of the face's `N` texels.
//!
//! Face `f` looks along [`face_axes`]`(f).0` (+X, −X, +Y, −Y, +Z, −Z) and sits in the atlas at
//! column `f % 3`, row `f / 3`. Ties between axes go to x, then y (the same comparisons in
//! `kernels/shared/light.wgsl`'s `point_face` and [`face_of`]).

use glam::{DVec3, Mat4, Vec3};

use super::Filter;

/// Faces of a point light's map.
pub const FACES: u32 = 6;
/// Faces along the atlas's width.
pub const COLUMNS: u32 = 3;
/// Faces along the atlas's height.
pub const ROWS: u32 = 2;

/// Face `f`'s forward axis and the up vector its view is built with (`Mat4::look_at_rh`).
pub fn face_axes(f: u32) -> (Vec3, Vec3) {
    match f {
        0 => (Vec3::X, Vec3::Y),
        1 => (Vec3::NEG_X, Vec3::Y),
        2 => (Vec3::Y, Vec3::Z),
        3 => (Vec3::NEG_Y, Vec3::Z),
        4 => (Vec3::Z, Vec3::Y),
        _ => (Vec3::NEG_Z, Vec3::Y),
    }
}

/// The face that sees direction `d` (from the light): its major axis and sign, ties to x then y.
pub fn face_of(d: DVec3) -> u32 {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        u32::from(d.x < 0.0)
    } else if a.y >= a.z {
        2 + u32::from(d.y < 0.0)
    } else {
        4 + u32::from(d.z < 0.0)
    }
}

/// How a point light's faces are laid out: face side, guard band and the widened frustum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLayout {
    /// Texels of a face's side (the scene's `shadow_map`).
    pub face: u32,
    /// Guard band on each side of a face's core, texels.
    pub guard: u32,
    /// `tan` of half the face's full (widened) frustum angle: `face / (face − 2·guard)`, so
    /// that the 90° core (`|x/z| ≤ 1`) spans the inner `face − 2·guard` texels.
    pub tan_half: f32,
}

impl PointLayout {
    /// The layout of a `face`-texel face for a technique that reads up to `reach` texels
    /// around a receiver's texel: a guard band of `⌈reach⌉ + 1`. A band wider than a quarter of
    /// the face (a core below half the face) is refused.
    pub fn new(face: u32, reach: f32) -> Result<Self, String> {
        let guard = reach.max(0.0).ceil() as u32 + 1;
        if face < 4 * guard {
            return Err(format!(
                "a point light's faces need a guard band of {guard} texels for this technique's reach of {reach} texels around a receiver, which leaves less than half of a {face}-texel face: raise `shadow_map` to at least {}, or narrow the filter",
                4 * guard
            ));
        }
        Ok(Self {
            face,
            guard,
            tan_half: face as f32 / (face - 2 * guard) as f32,
        })
    }

    /// The atlas's width and height in texels.
    pub fn atlas(&self) -> (u32, u32) {
        (COLUMNS * self.face, ROWS * self.face)
    }

    /// Face `f`'s tile: its top-left texel in the atlas.
    pub fn origin(&self, f: u32) -> (u32, u32) {
        ((f % COLUMNS) * self.face, (f / COLUMNS) * self.face)
    }

    /// World → face `f`'s view for a light at `position`.
    pub fn view(position: Vec3, f: u32) -> Mat4 {
        let (forward, up) = face_axes(f);
        Mat4::look_at_rh(position, position + forward, up)
    }

    /// Face view → clip: perspective over the widened frustum, depth 0 at `near`, 1 at `far`.
    /// The x and y scales are `1 / tan_half` exactly (not through an angle), as the shading
    /// divides by the same `tan_half`.
    pub fn projection(&self, near: f32, far: f32) -> Mat4 {
        let mut p = Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, near, far);
        p.x_axis.x = 1.0 / self.tan_half;
        p.y_axis.y = 1.0 / self.tan_half;
        p
    }
}

/// How far around a receiver's texel a prefilter's lookup reads a point light's map, in face
/// texels (`face`: the face's side): the bilinear tap, plus the blur's radius, the table's half
/// box, or the mip level's texel span; an error where it cannot be bounded to one face. A
/// technique's whole reach is its registry entry's (`technique::reach`).
pub fn filter_reach(filter: Filter, face: u32) -> Result<f32, String> {
    match filter {
        Filter::None => Ok(1.0),
        Filter::Blur { radius, .. } => Ok(radius.ceil() + 1.0),
        Filter::Sat { width, .. } => Ok(0.5 * width + 1.0),
        Filter::Mips { max_anisotropy, .. } if max_anisotropy > 0 => Err(
            "point lights do not support anisotropic mips (`max_anisotropy` > 0): a pixel's footprint that crosses a face edge is unbounded in the atlas"
                .into(),
        ),
        Filter::Mips { width, .. } => {
            // Trilinear reads level ⌈log2 w⌉, whose texels span 2^L level-0 texels: a tile edge
            // must fall on a texel edge of that level, and its bilinear tap reads one texel
            // further on each side.
            let level = width.max(1.0).log2().ceil() as u32;
            let span = 1u32 << level.min(31);
            if !face.is_multiple_of(span) {
                return Err(format!(
                    "a point light's mip chain at width {width} reads level {level}, whose texels span {span} texels: `shadow_map` ({face}) must be a multiple of {span}"
                ));
            }
            Ok(2.0 * span as f32)
        }
    }
}
