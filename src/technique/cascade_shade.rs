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

/// `light<i>_cascade<c>(…)`, one function per cascade with a plain light's case as its body,
/// and `light<i>_cascaded(…)`, the pick and the blend. Each cascade's function is called once,
/// where the pixel reads it (its picked cascade, and the next one inside the blend band): a
/// GPU branches per warp, as it did for a `switch` on the cascade called once for each of the
/// two, and a CPU driver that runs every branch under a lane mask (llvmpipe) evaluates each
/// cascade once instead of twice. The result is the same `mix` of the same two values.
pub(super) fn cascade_functions(g: &CascadeGroup, lights: &[Light]) -> String {
    let i = g.light;
    let mut out = String::new();
    for c in 0..g.count {
        let k = g.index(c);
        let body = lights.get(k).map_or_else(
            || "\n            return 1.0;".to_string(),
            |l| light_case(k, l),
        );
        let _ = writeln!(
            out,
            "fn light{i}_cascade{c}(p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> f32 {{{body}\n}}"
        );
    }
    out.push_str(&pick_and_blend(
        &format!("light{i}_cascaded(p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>)"),
        &format!("lights[{i}]"),
        g.count,
        |c| format!("light{i}_cascade{c}(p, n, dpdx, dpdy)"),
    ));
    out
}

/// The WGSL of a cascaded light's pick and blend, the renderer's and the plug-in's export's
/// (`prefilter::wgsl::cascades_block`): `fn {signature} -> f32` picks the receiver's cascade
/// with `cascade_pick({first}, p)` and fades to the next one's visibility across the blend
/// band, `call(c)` being cascade `c`'s visibility (an expression). Each cascade's is evaluated
/// at one site, where the receiver reads it (its cascade, or the next inside the band), and
/// the same two values are mixed.
pub(crate) fn pick_and_blend(
    signature: &str,
    first: &str,
    count: usize,
    call: impl Fn(usize) -> String,
) -> String {
    let mut calls = String::new();
    for c in 0..count {
        let _ = write!(
            calls,
            "    if pick.index == {c}u || next == {c}u {{\n        \
             let x = {};\n        \
             v = select(v, x, pick.index == {c}u);\n        \
             w = select(w, x, next == {c}u);\n    }}\n",
            call(c)
        );
    }
    format!(
        "fn {signature} -> f32 {{\n    \
         let pick = cascade_pick({first}, p);\n    \
         // The cascade the blend fades to (none outside the band).\n    \
         let next = select(0xffffffffu, pick.index + 1u, pick.blend > 0.0);\n    \
         var v = 1.0;\n    \
         var w = 1.0;\n\
         {calls}    \
         if pick.blend <= 0.0 {{\n        return v;\n    }}\n    \
         return mix(v, w, pick.blend);\n}}\n"
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
