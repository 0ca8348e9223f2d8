//! Reference of `kernels/blur.wgsl`: both passes of the separable blur, clamp-to-edge.

use super::Texels;
use crate::model::BlurKernel;

/// One-sided weights in f64, normalized so `w0 + 2 Σ wi = 1` (independent of `filter.rs`).
pub fn weights(radius: f64, sigma: f64, kernel: BlurKernel) -> Vec<f64> {
    let taps = radius.ceil().min(32.0) as usize;
    let raw: Vec<f64> = (0..=taps)
        .map(|i| {
            let x = i as f64;
            match kernel {
                BlurKernel::Gaussian => (-x * x / (2.0 * sigma * sigma)).exp(),
                // Full weight inside the radius, the fractional part one texel beyond.
                BlurKernel::Box => (radius - x + 1.0).clamp(0.0, 1.0),
            }
        })
        .collect();
    let total = raw[0] + 2.0 * raw[1..].iter().sum::<f64>();
    raw.into_iter().map(|w| w / total).collect()
}

/// One pass along `axis` (0 = x, 1 = y); with `log_space` the texels are logarithms and the
/// pass computes `log Σ wᵢ exp(vᵢ)`.
pub fn blur_pass_mode(src: &Texels, w: &[f64], axis: u32, log_space: bool) -> Texels {
    if !log_space {
        return blur_pass(src, w, axis);
    }
    let exp = Texels {
        data: src.data.iter().map(|v| v.exp()).collect(),
        ..src.clone()
    };
    let out = blur_pass(&exp, w, axis);
    Texels {
        data: out.data.iter().map(|v| v.ln()).collect(),
        ..out
    }
}

/// Both passes, in log space when `log_space`.
pub fn blur_mode(
    src: &Texels,
    radius: f64,
    sigma: f64,
    kernel: BlurKernel,
    log_space: bool,
) -> Texels {
    let w = weights(radius, sigma, kernel);
    blur_pass_mode(&blur_pass_mode(src, &w, 0, log_space), &w, 1, log_space)
}

/// One pass along `axis` (0 = x, 1 = y).
pub fn blur_pass(src: &Texels, w: &[f64], axis: u32) -> Texels {
    let r = w.len() as i64 - 1;
    let mut data = vec![0.0; src.data.len()];
    for y in 0..src.height as i64 {
        for x in 0..src.width as i64 {
            let out =
                &mut data[(y as usize * src.width + x as usize) * src.channels..][..src.channels];
            for i in -r..=r {
                let (sx, sy) = if axis == 0 { (x + i, y) } else { (x, y + i) };
                let wi = w[i.unsigned_abs() as usize];
                for (o, v) in out.iter_mut().zip(src.at(sx, sy)) {
                    *o += wi * v;
                }
            }
        }
    }
    Texels {
        data,
        ..src.clone()
    }
}

/// The horizontal then the vertical pass.
pub fn blur(src: &Texels, radius: f64, sigma: f64, kernel: BlurKernel) -> Texels {
    let w = weights(radius, sigma, kernel);
    blur_pass(&blur_pass(src, &w, 0), &w, 1)
}
