//! The shading block of a cascaded directional light: each cascade is a light of its own
//! (its maps, its `LightGpu`, its visibility function), and the scene light's case picks the
//! cascade by the pixel's view distance (`kernels/shared/cascade.wgsl`), fading to the next
//! one across the blend band.

use std::fmt::Write;

use crate::model::Light;

use super::shade::light_case;

/// The module with `cascade_pick`.
pub(super) const CASCADE_MODULE: &str = "shared/cascade";

/// A cascaded light as the shading block sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CascadeGroup {
    /// The scene light's index (its entry is cascade 0).
    pub light: usize,
    /// The index of cascade 1 among the drawn lights (the others follow it).
    pub first: usize,
    /// Cascades, 2–8.
    pub count: usize,
}

impl CascadeGroup {
    /// Drawn lights it adds to the scene's: its cascades after the first.
    pub fn extra(&self) -> usize {
        self.count.saturating_sub(1)
    }

    /// The drawn light of cascade `c`.
    pub fn index(&self, c: usize) -> usize {
        if c == 0 {
            self.light
        } else {
            self.first + c - 1
        }
    }
}

/// `light<i>_cascade(c, …)`, one case per cascade as a plain light's, and
/// `light<i>_cascaded(…)`, the pick and the blend.
pub(super) fn cascade_functions(g: &CascadeGroup, lights: &[Light]) -> String {
    let i = g.light;
    let mut cases = String::new();
    for c in 0..g.count {
        let k = g.index(c);
        let body = lights.get(k).map_or_else(
            || "\n            return 1.0;".to_string(),
            |l| light_case(k, l),
        );
        let _ = writeln!(cases, "        case {c}u: {{{body}\n        }}");
    }
    format!(
        "fn light{i}_cascade(c: u32, p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> f32 {{\n    \
         switch c {{\n{cases}        default: {{ return 1.0; }}\n    }}\n}}\n\
         fn light{i}_cascaded(p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> f32 {{\n    \
         let pick = cascade_pick(lights[{i}], p);\n    \
         let v = light{i}_cascade(pick.index, p, n, dpdx, dpdy);\n    \
         if pick.blend <= 0.0 {{\n        return v;\n    }}\n    \
         return mix(v, light{i}_cascade(pick.index + 1u, p, n, dpdx, dpdy), pick.blend);\n}}\n"
    )
}

/// [`super::shade_key`] of the drawn `lights` with these cascades.
pub fn shade_key_cascaded(lights: &[Light], groups: &[CascadeGroup]) -> String {
    let mut key = super::shade_key(lights);
    for g in groups {
        let _ = write!(key, "|cascades {} {} {}", g.light, g.first, g.count);
    }
    key
}
