//! Brute-force percentage-closer filtering over a linear depth map, in f64: the filtered hard
//! shadow that the prefiltered techniques (VSM, EVSM, ESM, MSM, CSM) approximate when their
//! representation is box-filtered.
//!
//! The map is piecewise constant (texel `(i, j)` covers `[i, i + 1) × [j, j + 1)` in texel
//! units, clamped to the edge outside the map, as `load_depth` reads it). The box of width `w`
//! texels is centred at `uv · size`; each texel it touches is weighted by the exact area of
//! its overlap with the box, so fractional edges are exact: this equals the comparison
//! `d ≤ z + bias` integrated over the box, divided by `w²`.

use crate::cpu::Map;

/// A receiver as the light sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    /// Shadow-map UV (y down), as `LightSample::uv`.
    pub uv: [f64; 2],
    /// Linear light-space depth, as `LightSample::depth`.
    pub depth: f64,
}

/// Overlap of texel `[i, i + 1)` with `[lo, hi)`.
fn overlap(i: i64, lo: f64, hi: f64) -> f64 {
    (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0)
}

/// PCF with a box of `width` texels (> 0) centred at the receiver's UV: the lit fraction of the
/// box, comparisons `depth ≤ z + bias`.
pub fn pcf_box(map: &Map, r: &Receiver, width: f64, bias: f64) -> f64 {
    let n = map.size as f64;
    let half = 0.5 * width;
    let (cx, cy) = (r.uv[0] * n, r.uv[1] * n);
    let (x0, x1, y0, y1) = (cx - half, cx + half, cy - half, cy + half);
    let mut lit = 0.0;
    for j in y0.floor() as i64..y1.ceil() as i64 {
        let wy = overlap(j, y0, y1);
        if wy == 0.0 {
            continue;
        }
        for i in x0.floor() as i64..x1.ceil() as i64 {
            if r.depth <= map.load(i, j) + bias {
                lit += overlap(i, x0, x1) * wy;
            }
        }
    }
    lit / (width * width)
}

/// [`pcf_box`] at every receiver.
pub fn pcf_truth(map: &Map, receivers: &[Receiver], width: f64, bias: f64) -> Vec<f64> {
    receivers
        .iter()
        .map(|r| pcf_box(map, r, width, bias))
        .collect()
}
