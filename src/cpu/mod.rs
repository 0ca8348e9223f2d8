//! f64 CPU references, one per kernel or WGSL module and named after it, written in the
//! shader's shape so the two read side by side. Tests compare the GPU against these.

pub mod light;
pub mod linearize;
pub mod vis_hard;
pub mod vis_pcf;
pub mod vis_pcss;

/// A linear depth map on the CPU.
#[derive(Clone, Debug)]
pub struct Map<'a> {
    /// Side length.
    pub size: usize,
    /// Row-major texels.
    pub texels: &'a [f32],
}

impl Map<'_> {
    /// Depth at texel (x, y), clamped to the edge (`load_depth` in `shared/sampling.wgsl`).
    pub fn load(&self, x: i64, y: i64) -> f64 {
        let c = |v: i64| v.clamp(0, self.size as i64 - 1) as usize;
        f64::from(self.texels[c(y) * self.size + c(x)])
    }

    /// The texel containing `uv` (`texel_of`).
    pub fn texel_of(&self, uv: [f64; 2]) -> (i64, i64) {
        let s = self.size as f64;
        let c = |v: f64| ((v * s).floor() as i64).clamp(0, self.size as i64 - 1);
        (c(uv[0]), c(uv[1]))
    }
}

/// Tap `i` of `n` on the Vogel disc (`vogel_disc` in `shared/sampling.wgsl`).
pub fn vogel_disc(i: u32, n: u32) -> [f64; 2] {
    const GOLDEN_ANGLE: f64 = 2.399963229728653;
    let r = ((f64::from(i) + 0.5) / f64::from(n)).sqrt();
    let t = f64::from(i) * GOLDEN_ANGLE;
    [r * t.cos(), r * t.sin()]
}
