//! f64 CPU references, one per kernel or WGSL module and named after it, written in the
//! shader's shape so the two read side by side. Tests compare the GPU against these.

pub mod blocker;
pub mod blur;
pub mod cascade;
pub mod csm;
pub mod csm_z;
pub mod esm;
pub mod evsm;
pub mod evsm_blur;
pub mod light;
pub mod linearize;
pub mod mips;
pub mod msm;
pub mod msm_blur;
pub mod sat;
pub mod second_depth;
pub mod shade;
pub mod vis_csm;
pub mod vis_cssm;
pub mod vis_esm;
pub mod vis_evsm;
pub mod vis_hard;
pub mod vis_msm;
pub mod vis_msm_soft;
pub mod vis_pcf;
pub mod vis_pcss;
pub mod vis_smrt;
pub mod vis_vsm;
pub mod vis_vssm;
pub mod vsm;
pub mod vsm_blur;

/// A linear depth map on the CPU.
#[derive(Clone, Debug)]
pub struct Map<'a> {
    /// Width (the side of a square map; a point light's atlas is 3 faces wide, 2 high).
    pub size: usize,
    /// Row-major texels: `size` a row, as many rows as they fill.
    pub texels: &'a [f32],
}

impl Map<'_> {
    /// Rows: `texels.len() / size`.
    pub fn height(&self) -> usize {
        self.texels.len() / self.size.max(1)
    }

    /// Depth at texel (x, y), clamped to the edge (`load_depth` in `shared/sampling.wgsl`).
    pub fn load(&self, x: i64, y: i64) -> f64 {
        let cx = x.clamp(0, self.size as i64 - 1) as usize;
        let cy = y.clamp(0, self.height() as i64 - 1) as usize;
        f64::from(self.texels[cy * self.size + cx])
    }

    /// The texel containing `uv` (`texel_of`).
    pub fn texel_of(&self, uv: [f64; 2]) -> (i64, i64) {
        let c = |v: f64, n: usize| ((v * n as f64).floor() as i64).clamp(0, n as i64 - 1);
        (c(uv[0], self.size), c(uv[1], self.height()))
    }
}

/// Tap `i` of `n` on the Vogel disc (`vogel_disc` in `shared/sampling.wgsl`).
pub fn vogel_disc(i: u32, n: u32) -> [f64; 2] {
    const GOLDEN_ANGLE: f64 = 2.399963229728653;
    let r = ((f64::from(i) + 0.5) / f64::from(n)).sqrt();
    let t = f64::from(i) * GOLDEN_ANGLE;
    [r * t.cos(), r * t.sin()]
}

/// A multi-channel image in f64 (row-major, `channels` values per texel).
#[derive(Clone, Debug, PartialEq)]
pub struct Texels {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Values per texel.
    pub channels: usize,
    /// `width · height · channels` values.
    pub data: Vec<f64>,
}

impl Texels {
    /// From f32 data as read back from a texture.
    pub fn from_f32(width: usize, height: usize, channels: usize, data: &[f32]) -> Self {
        Self {
            width,
            height,
            channels,
            data: data.iter().map(|&v| f64::from(v)).collect(),
        }
    }

    /// Texel (x, y), clamped to the edge.
    pub fn at(&self, x: i64, y: i64) -> &[f64] {
        let cx = x.clamp(0, self.width as i64 - 1) as usize;
        let cy = y.clamp(0, self.height as i64 - 1) as usize;
        let i = (cy * self.width + cx) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// Bilinear interpolation at `uv`, clamp-to-edge (`sample_bilinear` in `shared/sampling.wgsl`).
    pub fn bilinear(&self, uv: [f64; 2]) -> Vec<f64> {
        let fx = uv[0] * self.width as f64 - 0.5;
        let fy = uv[1] * self.height as f64 - 0.5;
        let (x0, y0) = (fx.floor() as i64, fy.floor() as i64);
        let (ax, ay) = (fx - fx.floor(), fy - fy.floor());
        (0..self.channels)
            .map(|c| {
                let t = |dx: i64, dy: i64| self.at(x0 + dx, y0 + dy)[c];
                (1.0 - ay) * ((1.0 - ax) * t(0, 0) + ax * t(1, 0))
                    + ay * ((1.0 - ax) * t(0, 1) + ax * t(1, 1))
            })
            .collect()
    }
}
