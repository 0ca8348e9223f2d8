//! The perceptual error: each configuration's shaded image against the *truth-shaded* image
//! (the renderer's shading with the area-light truth's visibility per light in place of the
//! technique's), by NVIDIA's FLIP (Andersson et al., HPG 2020; the `nv-flip` crate binds its
//! C++ reference).
//!
//! Both images are shaded by [`crate::cpu::shade::shade`], the f64 port of
//! `kernels/shade.wgsl`, over the configuration's own G-buffer (the camera's, the same for
//! every configuration), and stored as 8-bit sRGB as the renderer stores them: they differ
//! exactly where the visibilities differ, so a technique that reproduces the truth has a FLIP
//! of exactly 0. (The port agrees with the GPU's image within one 8-bit step: `tests/evaluate/`.)
//! FLIP is taken over the whole image at its default 67 pixels per degree (a 0.7 m wide
//! 3840-pixel monitor seen from 0.7 m); its statistics are those of the per-pixel error map.

use super::stats::ErrorStats;
use crate::cpu::shade::{Shading, shade};
use crate::scene::Scene;
use crate::wgsl_mirrors::FrameGpu;
use crate::wgsl_mirrors::LightGpu;

/// The scene's shading inputs, made once per evaluation.
pub struct Shader {
    frame: FrameGpu,
    lights: Vec<LightGpu>,
    materials: Vec<[f32; 3]>,
}

impl Shader {
    /// The shading kernel's inputs for `scene` at its output size.
    pub fn new(scene: &Scene) -> Self {
        Self {
            frame: FrameGpu::new(scene, scene.width, scene.height),
            lights: scene.lights.iter().map(LightGpu::new).collect(),
            materials: scene.objects.iter().map(|o| o.color.to_array()).collect(),
        }
    }

    /// The RGB8 image of the G-buffer `position`/`normal` (RGBA32F each) shaded with
    /// `visibility` (`[px * lights + l]`).
    pub fn image(&self, position: &[f32], normal: &[f32], visibility: &[f32]) -> Vec<u8> {
        let s = Shading {
            frame: &self.frame,
            lights: &self.lights,
            materials: &self.materials,
        };
        let n = self.lights.len();
        let px = position.len() / 4;
        let mut out = Vec::with_capacity(3 * px);
        for i in 0..px {
            let quad = |d: &[f32]| [d[4 * i], d[4 * i + 1], d[4 * i + 2], d[4 * i + 3]];
            let c = shade(
                &s,
                quad(position),
                quad(normal),
                &visibility[i * n..(i + 1) * n],
            );
            out.extend(c.map(to_unorm8));
        }
        out
    }
}

/// A [0, 1] value as an 8-bit unsigned normalized store writes it (round to nearest).
pub fn to_unorm8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// FLIP's per-pixel error map of `test` against `reference` (RGB8, sRGB, `w × h`).
pub fn flip_map(reference: &[u8], test: &[u8], w: u32, h: u32) -> Vec<f32> {
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference);
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test);
    nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec()
}

/// Statistics of a FLIP error map over every pixel (`mean_abs` is FLIP's mean).
pub fn flip_stats(map: &[f32]) -> ErrorStats {
    ErrorStats::of_errors(map.iter().map(|&v| f64::from(v)).collect())
}

/// FLIP's error map coloured by its magma scale (RGB8), as its tools show it.
pub fn magma(map: &[f32], w: u32, h: u32) -> Vec<u8> {
    nv_flip::FlipImageFloat::with_data(w, h, map)
        .apply_color_lut(&nv_flip::magma_lut())
        .to_vec()
}
