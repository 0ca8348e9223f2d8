//! Temporal error: the flicker a technique adds when something moves, which the truth does
//! not have. Over consecutive frames `t`, `t + 1` of an animation ([`crate::scene::Animation`]),
//! at every pixel and light relevant in both frames and in either frame's truth penumbra
//! ([`Regions`]: strictly soft, or within [`super::EDGE_BAND`] pixels of a 0.5 crossing, so a
//! hard edge has one), the error is `|Δ visibility − Δ truth|`; [`temporal_error`] gives its
//! mean over every pair of frames (each selected pixel of each pair weighs the same) and its
//! largest value. A still scene's is 0; a technique whose edge jumps from texel to texel as
//! the light moves by less than a texel scores high, a wide filter that slides with it low.

use super::stats::{Region, Regions};
use crate::error::{Error, Result};
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;
use crate::truth::{Truth, TruthOptions, area_light_truth};

/// One frame's visibility and its truth, indexed `[pixel * lights + light]`.
#[derive(Clone, Copy, Debug)]
pub struct TemporalFrame<'a> {
    /// The technique's visibility.
    pub visibility: &'a [f32],
    /// The truth's visibility.
    pub truth: &'a [f32],
    /// The truth's relevant pixels.
    pub mask: &'a [bool],
}

/// The temporal error of an animation.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TemporalError {
    /// Pairs of consecutive frames.
    pub pairs: usize,
    /// Pixel-light values measured over every pair.
    pub pixels: usize,
    /// Mean `|Δ visibility − Δ truth|` (0 when nothing was measured).
    pub mean_abs: f64,
    /// Largest `|Δ visibility − Δ truth|`.
    pub max: f64,
}

/// The temporal error of `frames` (in animation order) of a `width × height` image with
/// `lights` lights; an error when a frame's buffers do not all hold `width · height · lights`
/// values.
pub fn temporal_error(
    frames: &[TemporalFrame],
    width: usize,
    height: usize,
    lights: usize,
) -> Result<TemporalError> {
    let n = width * height * lights;
    for (t, f) in frames.iter().enumerate() {
        let lens = [f.visibility.len(), f.truth.len(), f.mask.len()];
        if lens.iter().any(|&l| l != n) {
            return Err(Error::Invalid(format!(
                "temporal error: frame {t} holds {lens:?} values (visibility, truth, mask), not \
                 the {n} of {width}x{height} pixels and {lights} light(s)"
            )));
        }
    }
    let regions: Vec<Regions> = frames
        .iter()
        .map(|f| Regions::new(f.truth, f.mask, width, height, lights))
        .collect();
    let (mut sum, mut max, mut pixels) = (0.0, 0.0f64, 0usize);
    for t in 1..frames.len() {
        let (a, b) = (&frames[t - 1], &frames[t]);
        let (ra, rb) = (&regions[t - 1].region, &regions[t].region);
        for i in 0..n {
            let penumbra = ra[i] == Region::Penumbra || rb[i] == Region::Penumbra;
            if !(a.mask[i] && b.mask[i] && penumbra) {
                continue;
            }
            let dv = f64::from(b.visibility[i]) - f64::from(a.visibility[i]);
            let dt = f64::from(b.truth[i]) - f64::from(a.truth[i]);
            let e = (dv - dt).abs();
            sum += e;
            max = max.max(e);
            pixels += 1;
        }
    }
    Ok(TemporalError {
        pairs: frames.len().saturating_sub(1),
        pixels,
        mean_abs: if pixels > 0 { sum / pixels as f64 } else { 0.0 },
        max,
    })
}

/// The area-light truth of every frame of `scene`'s animation ([`Scene::at_frame`]).
pub fn animation_truths(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    opts: &TruthOptions,
) -> Result<Vec<Truth>> {
    (0..scene.frames())
        .map(|f| area_light_truth(renderer, device, queue, &scene.at_frame(f)?, opts))
        .collect()
}

/// The renderer's visibility of every frame of `scene`'s animation, rendered in order by one
/// renderer (as a game would: lights whose maps are kept notice what moved).
pub fn animation_visibility(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
) -> Result<Vec<Vec<f32>>> {
    (0..scene.frames())
        .map(|f| {
            renderer
                .render_frame(device, queue, scene, f, RenderOptions::default())
                .map(|frame| frame.visibility)
        })
        .collect()
}

/// The temporal error of `visibility` (per frame, [`animation_visibility`]) against `truths`
/// ([`animation_truths`]) of the same animation.
pub fn animation_temporal_error(
    truths: &[Truth],
    visibility: &[Vec<f32>],
) -> Result<TemporalError> {
    if truths.len() != visibility.len() {
        return Err(Error::Invalid(format!(
            "temporal error: {} truth frames for {} rendered frames",
            truths.len(),
            visibility.len()
        )));
    }
    let Some(first) = truths.first() else {
        return Ok(TemporalError::default());
    };
    let frames: Vec<TemporalFrame> = truths
        .iter()
        .zip(visibility)
        .map(|(t, v)| TemporalFrame {
            visibility: v,
            truth: &t.visibility,
            mask: &t.mask,
        })
        .collect();
    temporal_error(
        &frames,
        first.width as usize,
        first.height as usize,
        first.lights,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w × h` truth of `lights` lights whose shadow edge (a ramp 1.5 pixels wide, so some
    /// pixels are strictly soft) lies at column `edge` (light `l`'s one column further), with
    /// the last column not relevant.
    fn truth(w: usize, h: usize, lights: usize, edge: f64) -> (Vec<f32>, Vec<bool>) {
        let mut t = vec![0.0; w * h * lights];
        let mut m = vec![true; w * h * lights];
        for y in 0..h {
            for x in 0..w {
                for l in 0..lights {
                    let i = (y * w + x) * lights + l;
                    let d = (x as f64 - edge - l as f64 + 0.1 * y as f64) / 1.5;
                    t[i] = (0.5 + d).clamp(0.0, 1.0) as f32;
                    m[i] = x + 1 < w;
                }
            }
        }
        (t, m)
    }

    /// The regions' penumbra by brute force: soft, or within 2 pixels (Chebyshev) of a pixel
    /// that crosses 0.5 with a relevant 4-neighbour.
    fn penumbra(t: &[f32], m: &[bool], w: usize, h: usize, lights: usize) -> Vec<bool> {
        let at = |x: usize, y: usize, l: usize| (y * w + x) * lights + l;
        let crosses = |i: usize, j: usize| m[i] && m[j] && ((t[i] >= 0.5) != (t[j] >= 0.5));
        let edge = |x: usize, y: usize, l: usize| {
            let i = at(x, y, l);
            let mut n = Vec::new();
            if x > 0 {
                n.push(at(x - 1, y, l));
            }
            if x + 1 < w {
                n.push(at(x + 1, y, l));
            }
            if y > 0 {
                n.push(at(x, y - 1, l));
            }
            if y + 1 < h {
                n.push(at(x, y + 1, l));
            }
            n.into_iter().any(|j| crosses(i, j))
        };
        let mut out = vec![false; t.len()];
        for y in 0..h {
            for x in 0..w {
                for l in 0..lights {
                    let i = at(x, y, l);
                    let soft = t[i] > 0.02 && t[i] < 0.98;
                    let near = (0..h).any(|yy| {
                        (0..w)
                            .any(|xx| x.abs_diff(xx) <= 2 && y.abs_diff(yy) <= 2 && edge(xx, yy, l))
                    });
                    out[i] = m[i] && (soft || near);
                }
            }
        }
        out
    }

    #[test]
    fn matches_a_direct_computation() {
        let (w, h, lights) = (14, 9, 2);
        let mut seed = 0x2545_f491_u64;
        let mut noise = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 1000) as f32 / 1000.0 - 0.5
        };
        let frames: Vec<(Vec<f32>, Vec<bool>, Vec<f32>)> = (0..4)
            .map(|k| {
                let (t, m) = truth(w, h, lights, 4.0 + 0.7 * k as f64);
                let v = t
                    .iter()
                    .map(|&x| (x + 0.2 * noise()).clamp(0.0, 1.0))
                    .collect();
                (t, m, v)
            })
            .collect();
        let view: Vec<TemporalFrame> = frames
            .iter()
            .map(|(t, m, v)| TemporalFrame {
                visibility: v,
                truth: t,
                mask: m,
            })
            .collect();
        let got = temporal_error(&view, w, h, lights).expect("temporal error");
        let (mut sum, mut n, mut max) = (0.0, 0, 0.0f64);
        for k in 1..frames.len() {
            let (ta, ma, va) = &frames[k - 1];
            let (tb, mb, vb) = &frames[k];
            let pa = penumbra(ta, ma, w, h, lights);
            let pb = penumbra(tb, mb, w, h, lights);
            for i in 0..ta.len() {
                if ma[i] && mb[i] && (pa[i] || pb[i]) {
                    let e = ((f64::from(vb[i]) - f64::from(va[i]))
                        - (f64::from(tb[i]) - f64::from(ta[i])))
                    .abs();
                    sum += e;
                    max = max.max(e);
                    n += 1;
                }
            }
        }
        assert!(n > 20, "too few penumbra pixels: {n}");
        assert_eq!((got.pairs, got.pixels), (3, n));
        // The same sums in the same order: equal to f64 rounding.
        assert!(
            (got.mean_abs - sum / n as f64).abs() < 1e-12,
            "{got:?} vs {}",
            sum / n as f64
        );
        assert_eq!(got.max, max);
        assert!(got.mean_abs > 0.01, "the noise should show: {got:?}");
    }

    #[test]
    fn a_still_sequence_and_an_exact_one_score_zero() {
        let (w, h) = (10, 6);
        let (t0, m) = truth(w, h, 1, 3.0);
        let (t1, _) = truth(w, h, 1, 4.0);
        let still = TemporalFrame {
            visibility: &t0,
            truth: &t0,
            mask: &m,
        };
        let moved = TemporalFrame {
            visibility: &t1,
            truth: &t1,
            mask: &m,
        };
        let e = temporal_error(&[still, still, moved], w, h, 1).expect("temporal error");
        assert_eq!(e.mean_abs, 0.0);
        assert!(e.pixels > 0);
        // A visibility that lags one frame behind the truth does not.
        let lag = TemporalFrame {
            visibility: &t0,
            truth: &t1,
            mask: &m,
        };
        let e = temporal_error(&[still, lag], w, h, 1).expect("temporal error");
        assert!(e.mean_abs > 0.05, "{e:?}");
        let short = TemporalFrame {
            visibility: &t0[1..],
            truth: &t0,
            mask: &m,
        };
        assert!(temporal_error(&[still, short], w, h, 1).is_err());
    }
}
