//! Error statistics, and the regions of the truth they are taken over: penumbra, umbra, lit.
//!
//! **Regions** (per light, over its relevant pixels; [`Regions::new`]): a pixel is an *edge*
//! pixel when it and one of its 4-neighbours are both relevant and lie on opposite sides of
//! truth 0.5 (one `< 0.5`, the other `≥ 0.5`); the *penumbra* is every relevant pixel whose
//! truth is strictly between [`PENUMBRA_LOW`] and [`PENUMBRA_HIGH`], or that lies within
//! [`EDGE_BAND`] pixels (Chebyshev distance: a (2·band + 1)² square) of an edge pixel — so a
//! hard shadow (a point light, or a penumbra thinner than a pixel) still has a penumbra: the
//! band where a misplaced edge shows. The *umbra* is every other relevant pixel with truth
//! ≤ [`PENUMBRA_LOW`]: error there is light where there should be none (leaking, lost contact
//! shadows); *lit* is every other relevant pixel (truth ≥ [`PENUMBRA_HIGH`]): error there is
//! shadow where there should be none (acne, over-darkening, ringing). The three partition the
//! relevant pixels.

/// Truth at or below this is umbra (unless in the edge band).
pub const PENUMBRA_LOW: f64 = 0.02;
/// Truth at or above this is lit (unless in the edge band).
pub const PENUMBRA_HIGH: f64 = 0.98;
/// Half-width in pixels of the band around a truth's 0.5 crossing that counts as penumbra.
pub const EDGE_BAND: usize = 2;

/// Error statistics of one image against a reference, over the pixels of a mask.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorStats {
    /// Pixels measured.
    pub pixels: usize,
    /// Mean |v − truth|.
    pub mean_abs: f64,
    /// Root mean square error.
    pub rmse: f64,
    /// 99th percentile of |v − truth|.
    pub p99: f64,
    /// Largest |v − truth|.
    pub max: f64,
    /// Share of pixels with |v − truth| > 0.05.
    pub over_005: f64,
    /// Share of pixels with |v − truth| > 0.2.
    pub over_02: f64,
}

impl ErrorStats {
    /// Statistics of `values` against `truth` where `mask` is set (all zero when it is empty).
    pub fn new(values: &[f32], truth: &[f64], mask: &[bool]) -> Self {
        let e: Vec<f64> = values
            .iter()
            .zip(truth)
            .zip(mask)
            .filter(|(_, m)| **m)
            .map(|((&v, &t), _)| (f64::from(v) - t).abs())
            .collect();
        Self::of_errors(e)
    }

    /// Statistics of the absolute errors `e` themselves (e.g. a FLIP error map).
    pub fn of_errors(mut e: Vec<f64>) -> Self {
        let n = e.len();
        if n == 0 {
            return Self::default();
        }
        e.sort_by(f64::total_cmp);
        let share = |x: f64| e.iter().filter(|&&v| v > x).count() as f64 / n as f64;
        Self {
            pixels: n,
            mean_abs: e.iter().sum::<f64>() / n as f64,
            rmse: (e.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt(),
            p99: e[((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1],
            max: e[n - 1],
            over_005: share(0.05),
            over_02: share(0.2),
        }
    }
}

/// The penumbra's high-frequency error: the root mean square of the discrete Laplacian of
/// the error e = values − truth, Δe(x, y) = e(x+1, y) + e(x−1, y) + e(x, y+1) + e(x, y−1) −
/// 4 e(x, y), over the pixels of `penumbra` whose four neighbours are all `relevant` (pixels
/// are indexed `[(y · width + x) · lights + l]`, each light on its own). An error that
/// varies smoothly (an offset, a ramp) scores 0 however large it is; a staircase, banding or
/// noise of the same mean scores by its steps. Returns the value and the pixels it was taken
/// over (0 and 0 when none qualifies).
pub fn laplacian_rms(
    values: &[f32],
    truth: &[f64],
    penumbra: &[bool],
    relevant: &[bool],
    width: usize,
    height: usize,
    lights: usize,
) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0usize);
    for l in 0..lights {
        let at = |x: usize, y: usize| (y * width + x) * lights + l;
        let e = |i: usize| f64::from(values[i]) - truth[i];
        for y in 1..height.saturating_sub(1) {
            for x in 1..width.saturating_sub(1) {
                let i = at(x, y);
                let around = [at(x + 1, y), at(x - 1, y), at(x, y + 1), at(x, y - 1)];
                if !penumbra[i] || !relevant[i] || !around.iter().all(|&j| relevant[j]) {
                    continue;
                }
                let lap: f64 = around.iter().map(|&j| e(j)).sum::<f64>() - 4.0 * e(i);
                sum += lap * lap;
                n += 1;
            }
        }
    }
    if n == 0 {
        (0.0, 0)
    } else {
        ((sum / n as f64).sqrt(), n)
    }
}

/// Where a relevant pixel lies in the truth's shadow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Not a relevant pixel.
    Outside,
    /// Strictly inside (0.02, 0.98) or in the band around a 0.5 crossing.
    Penumbra,
    /// Fully shadowed (≤ 0.02), away from an edge.
    Umbra,
    /// Fully lit (≥ 0.98), away from an edge.
    Lit,
}

/// The region of every pixel and light, indexed like the truth (`[px * lights + l]`).
#[derive(Clone, Debug)]
pub struct Regions {
    /// One region per pixel and light.
    pub region: Vec<Region>,
}

impl Regions {
    /// Regions of a `width × height` truth with `lights` lights (see the module docs).
    pub fn new(truth: &[f32], mask: &[bool], width: usize, height: usize, lights: usize) -> Self {
        let mut region = vec![Region::Outside; truth.len()];
        for l in 0..lights {
            let at = |x: usize, y: usize| (y * width + x) * lights + l;
            let above = |i: usize| f64::from(truth[i]) >= 0.5;
            // Edge pixels: a relevant 4-neighbour on the other side of 0.5.
            let mut edge = vec![false; width * height];
            for y in 0..height {
                for x in 0..width {
                    let i = at(x, y);
                    let crosses = |j: usize| mask[i] && mask[j] && above(i) != above(j);
                    if x + 1 < width && crosses(at(x + 1, y)) {
                        edge[y * width + x] = true;
                        edge[y * width + x + 1] = true;
                    }
                    if y + 1 < height && crosses(at(x, y + 1)) {
                        edge[y * width + x] = true;
                        edge[(y + 1) * width + x] = true;
                    }
                }
            }
            let band = dilate(&edge, width, height, EDGE_BAND);
            for (px, &in_band) in band.iter().enumerate() {
                let i = px * lights + l;
                if !mask[i] {
                    continue;
                }
                let t = f64::from(truth[i]);
                region[i] = if in_band || (t > PENUMBRA_LOW && t < PENUMBRA_HIGH) {
                    Region::Penumbra
                } else if t <= PENUMBRA_LOW {
                    Region::Umbra
                } else {
                    Region::Lit
                };
            }
        }
        Self { region }
    }

    /// The mask of one region.
    pub fn mask(&self, r: Region) -> Vec<bool> {
        self.region.iter().map(|&x| x == r).collect()
    }
}

/// Pixels within Chebyshev distance `k` of a set pixel: a separable max over rows, then
/// columns.
fn dilate(m: &[bool], w: usize, h: usize, k: usize) -> Vec<bool> {
    let mut rows = vec![false; m.len()];
    for y in 0..h {
        for x in 0..w {
            let (a, b) = (x.saturating_sub(k), (x + k).min(w - 1));
            rows[y * w + x] = (a..=b).any(|xx| m[y * w + xx]);
        }
    }
    let mut out = vec![false; m.len()];
    for y in 0..h {
        for x in 0..w {
            let (a, b) = (y.saturating_sub(k), (y + k).min(h - 1));
            out[y * w + x] = (a..=b).any(|yy| rows[yy * w + x]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Laplacian's RMS, written out directly in f64 over one light.
    fn direct(e: &dyn Fn(usize, usize) -> f64, w: usize, h: usize) -> f64 {
        let (mut sum, mut n) = (0.0, 0.0);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let lap = e(x + 1, y) + e(x - 1, y) + e(x, y + 1) + e(x, y - 1) - 4.0 * e(x, y);
                sum += lap * lap;
                n += 1.0;
            }
        }
        (sum / n).sqrt()
    }

    /// A truth ramp t = 0.1 + g·x (64 × 8, every pixel penumbra and relevant) rendered as a
    /// staircase of 4-texel steps (each step's value the truth at its centre) and as the ramp
    /// offset by g: both have mean |error| g, but the staircase's error is a sawtooth whose
    /// Laplacian is ±4g at the two pixels around each step, so its RMS is sqrt(30 · 6 ·
    /// (4g)² / (62 · 6)) (30 step pixels per interior row) while the offset scores 0. Both
    /// against the written-out sum (1e-12: the same sums in another order). A second light
    /// (interleaved) with the roles swapped scores the same, so lights do not mix; a pixel
    /// that is not relevant, and its four neighbours, are left out.
    #[test]
    fn a_staircase_scores_above_a_smooth_error_of_the_same_mean() {
        let (w, h, g) = (64usize, 8usize, 0.01);
        let truth_at = |x: usize| 0.1 + g * x as f64;
        let stair_at = |x: usize| truth_at(4 * (x / 4)) + 1.5 * g;
        let truth: Vec<f64> = (0..w * h).map(|i| truth_at(i % w)).collect();
        let stair: Vec<f32> = (0..w * h).map(|i| stair_at(i % w) as f32).collect();
        let offset: Vec<f32> = (0..w * h).map(|i| (truth_at(i % w) + g) as f32).collect();
        let all = vec![true; w * h];
        let mean = |v: &[f32]| ErrorStats::new(v, &truth, &all).mean_abs;
        assert!((mean(&stair) - g).abs() < 1e-7 && (mean(&offset) - g).abs() < 1e-7);
        let (hf_stair, n) = laplacian_rms(&stair, &truth, &all, &all, w, h, 1);
        let (hf_offset, _) = laplacian_rms(&offset, &truth, &all, &all, w, h, 1);
        assert_eq!(n, 62 * 6);
        let known = (30.0 * 6.0 * (4.0 * g).powi(2) / (62.0 * 6.0)).sqrt();
        // f32 storage of the values: their errors are within 1e-8, the Laplacian's 1e-7.
        assert!((hf_stair - known).abs() < 1e-6, "{hf_stair} vs {known}");
        assert!(hf_offset < 1e-6, "{hf_offset}");
        let e = |v: &[f32]| {
            let v = v.to_vec();
            let truth = truth.clone();
            move |x: usize, y: usize| f64::from(v[y * w + x]) - truth[y * w + x]
        };
        assert!((hf_stair - direct(&e(&stair), w, h)).abs() < 1e-12);
        assert!((hf_offset - direct(&e(&offset), w, h)).abs() < 1e-12);
        // Two lights interleaved: [stair, offset] per pixel.
        let both: Vec<f32> = (0..w * h).flat_map(|i| [stair[i], offset[i]]).collect();
        let truth2: Vec<f64> = truth.iter().flat_map(|&t| [t, t]).collect();
        let only = |l: usize| -> Vec<bool> { (0..2 * w * h).map(|i| i % 2 == l).collect() };
        let all2 = vec![true; 2 * w * h];
        let (a, na) = laplacian_rms(&both, &truth2, &only(0), &all2, w, h, 2);
        assert!((a - hf_stair).abs() < 1e-12 && na == n);
        let (b, _) = laplacian_rms(&both, &truth2, &only(1), &all2, w, h, 2);
        assert!((b - hf_offset).abs() < 1e-12);
        // A pixel whose neighbour is not relevant is left out.
        let mut relevant = all.clone();
        relevant[3 * w + 10] = false;
        assert_eq!(
            laplacian_rms(&stair, &truth, &all, &relevant, w, h, 1).1,
            n - 5
        );
    }
}
