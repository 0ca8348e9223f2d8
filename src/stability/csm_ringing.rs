//! Case 5: CSM with M = 16 terms where the truncated Fourier series rings: receivers at their
//! blocker's depth, at depth 0 and 1, and swept through the depth range over flat blockers at
//! 0 (exactly), 0.3, 0.55, 0.8, a random depth and 1 (exactly, the background).
//!
//! The shading computes `clamp(s·Σ w_k sin(c_k t) + ½, 0, 1)` with `t = z − (d − bias −
//! offset)`, `w_k = 2 a_k / (π(2k − 1))`, `a_k = exp(−α (k/M)²)`. Its distance from the step
//! `H(t)` has a bound by summation by parts: with `b_k = (1 − a_k)/(2k − 1)` (`a_k = 0` past M)
//! and `|Σ_{k ≤ n} sin((2k − 1)x)| ≤ 1/|sin x|`,
//! `|½ + Σ w_k sin(c_k t) − H(t)| ≤ E(t) = (2/π)·TV(b)/|sin(πt)|`, `TV(b) = Σ_k |b_k − b_{k+1}|`,
//! so after the scale and the clamp the output differs from the step by at most
//! `max(0, s·E(t) − (s − 1)/2)`: zero once `|sin(πt)| ≥ (4/π)·s·TV(b)/(s − 1)`. The GPU's
//! clamped output over flat blockers is checked against that plus the f32 terms' error, and
//! the unclamped f64 series against `s·E(t)` itself.

use std::f64::consts::PI;

use glam::Vec3;

use super::StabilityRow;
use super::check::{Check, Rng};
use super::harness::{DIRECTIONAL, light, receiver, run_light, sample, shade};
use super::planar::storage_name;
use crate::cpu::{self, Texels};
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::{BlurKernel, Filter, Storage, StorageFilter, Technique};
use crate::render::Renderer;
use crate::tolerance;
use crate::{technique::linear_name, wgsl_mirrors::LightGpu};

const MAP: u32 = 64;
const TERMS: u32 = 16;
const BIAS: f32 = 0.002;

fn technique(storage: Storage) -> Technique {
    Technique::Csm {
        prefilter: StorageFilter {
            storage,
            filter: Filter::Blur {
                radius: 2.0,
                sigma: 1.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        terms: TERMS,
        attenuation: 1.0,
        offset: 0.5 / TERMS as f32,
        scale: 2.0,
    }
}

/// Flat blockers `[x0, y0, x1, y1)` and their depths; the rest of the map is 1.0.
fn blockers(rng: &mut Rng) -> Vec<([usize; 4], f32)> {
    vec![
        ([4, 4, 20, 20], 0.0),
        ([28, 6, 44, 22], 0.3),
        ([6, 30, 22, 46], 0.55),
        ([30, 30, 46, 46], 0.8),
        ([50, 8, 62, 24], rng.range(0.1, 0.9) as f32),
    ]
}

/// `TV(b)` of the module documentation.
fn total_variation(l: &LightGpu) -> f64 {
    let m = l.csm_terms as usize;
    let b = |k: usize| {
        let a = if k <= m {
            let kf = k as f64 / m as f64;
            (-f64::from(l.csm_attenuation) * kf * kf).exp()
        } else {
            0.0
        };
        (1.0 - a) / (2 * k - 1) as f64
    };
    // Past M the b_k decrease to 0: their variation is b_{M+1}.
    (1..=m).map(|k| (b(k) - b(k + 1)).abs()).sum::<f64>() + b(m + 1)
}

/// `E(t)`: the series' distance from the step (infinite at the jumps t ∈ {0, ±1}).
fn series_bound(tv: f64, t: f64) -> f64 {
    2.0 / PI * tv / (PI * t).sin().abs()
}

/// The |t| from which the scaled, clamped output is exactly the step:
/// `|sin(πt)| ≥ (4/π)·s·TV(b)/(s − 1)` (1 when the scale is 1: the series alone never is).
fn step_exact(l: &LightGpu) -> f64 {
    let s = f64::from(l.csm_scale);
    let x = 4.0 / PI * s * total_variation(l) / (s - 1.0);
    if x >= 1.0 || !x.is_finite() {
        0.5
    } else {
        x.asin() / PI
    }
}

/// The unclamped f64 series against the step on a fine grid of t: the bound `s·E(t)` away
/// from the jumps, and the series' own overshoot (Gibbs) past [0, 1] near them.
fn series_rows(l: &LightGpu) -> [StabilityRow; 2] {
    let w = tolerance::csm_weights(l);
    let s = f64::from(l.csm_scale);
    let tv = total_variation(l);
    let mut check = Check::new();
    let mut overshoot = (0.0f64, 0.0);
    for i in -20_000..=20_000 {
        let t = f64::from(i) / 20_000.0;
        let sum: f64 = w
            .iter()
            .enumerate()
            .map(|(k, wk)| wk * (PI * (2 * k + 1) as f64 * t).sin())
            .sum();
        let v = s * sum + 0.5;
        let o = (sum - 0.5).max(-0.5 - sum);
        if o > overshoot.0 {
            overshoot = (o, t);
        }
        if (0.05..=0.95).contains(&t.abs()) {
            let step = if t > 0.0 { 1.0 } else { 0.0 };
            check.compare(v, s * (step - 0.5) + 0.5, s * series_bound(tv, t), || {
                format!("t = {t:.4}")
            });
        }
    }
    [
        check.row(
            5,
            "unclamped series vs scaled step, 0.05 ≤ |t| ≤ 0.95 (f64)",
            "csm M=16",
            "-",
        ),
        Check::reported(
            5,
            [
                "series overshoot past [0, 1] before scale (Gibbs, f64)",
                "csm M=16",
                "-",
            ],
            overshoot.0,
            f64::NAN,
            0,
            format!(
                "at t = {:.4}; TV(b) = {tv:.4}: scaled by {s} and clamped, the output is the \
                 step for |t| ≥ {:.4}",
                overshoot.1,
                step_exact(l)
            ),
        ),
    ]
}

struct Checks {
    reference: Check,
    /// Where the bound makes the clamped output exactly the step.
    away: Check,
    /// Closer to the jump, where it may ring.
    near: Check,
    contact: (f64, String),
    outside: usize,
}

/// One storage: the GPU's clamped output against the f64 series on the same maps and against
/// the step over flat blockers.
fn check_storage(gpu: &Gpu, rng: &mut Rng, storage: Storage) -> Result<[StabilityRow; 4]> {
    let l = light(DIRECTIONAL, technique(storage), MAP, BIAS);
    let lg = LightGpu::new(&l);
    let n = MAP as usize;
    let blocks = blockers(rng);
    let mut raw = vec![1.0f32; n * n];
    for &([x0, y0, x1, y1], z) in &blocks {
        for y in y0..y1 {
            raw[y * n + x0..y * n + x1].fill(z);
        }
    }
    let mut exec = Executor::new();
    let (ran, maps) = run_light(gpu, &mut exec, &l, &raw)?;
    let linear = ran.texels(gpu, &linear_name(0), 0)?;
    let levels: Vec<Vec<Texels>> = maps
        .iter()
        .map(|m| ran.levels(gpu, m))
        .collect::<Result<_>>()?;
    // The 2M-channel basis the f64 function reads, side by side as the shading binds it.
    let basis = concat(&levels)?;
    // Flat interiors (3 texels from each edge: the 5-tap blur and the bilinear footprint stay
    // inside), and the background far from every blocker.
    let mut flat: Vec<([f64; 2], f64)> = Vec::new();
    for &([x0, y0, x1, y1], _) in &blocks {
        for _ in 0..3 {
            let (x, y) = (
                x0 + 3 + rng.below(x1 - x0 - 6),
                y0 + 3 + rng.below(y1 - y0 - 6),
            );
            flat.push((
                [(x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64],
                linear.at(x as i64, y as i64)[0],
            ));
        }
    }
    flat.push(([36.5 / n as f64, 56.5 / n as f64], linear.at(36, 56)[0]));
    let mut points: Vec<(Vec3, Vec3)> = Vec::new();
    let mut flat_z: Vec<Option<f64>> = Vec::new();
    for &(uv, z) in &flat {
        // At the blocker's depth, then the sweep.
        points.push(receiver(&l, uv, z.clamp(2e-6, 1.0 - 2e-6)));
        flat_z.push(None);
        for i in 1..256 {
            points.push(receiver(&l, uv, f64::from(i) / 256.0));
            flat_z.push(Some(z));
        }
    }
    for _ in 0..64 {
        let uv = [rng.range(0.02, 0.98), rng.range(0.02, 0.98)];
        for d in [2f64.powi(-20), 1.0 - 2f64.powi(-20)] {
            points.push(receiver(&l, uv, d));
            flat_z.push(None);
        }
    }
    let vis = shade(gpu, &mut Renderer::new(&gpu.device), &l, &levels, &points)?;
    let tol = tolerance::csm(&lg);
    let store = if storage == Storage::F16 {
        2f64.powi(-11)
    } else {
        0.0
    };
    // The GPU's basis: Vulkan's sin/cos (2⁻¹¹ absolute) in the encoding, then the store.
    let basis_error: f64 = f64::from(lg.csm_scale)
        * tolerance::csm_weights(&lg).iter().sum::<f64>()
        * 2.0
        * (2f64.powi(-11) + store);
    let tv = total_variation(&lg);
    let s = f64::from(lg.csm_scale);
    let mut c = Checks {
        reference: Check::new(),
        away: Check::new(),
        near: Check::new(),
        contact: (f64::INFINITY, String::new()),
        outside: 0,
    };
    for (i, (&v, point)) in vis.iter().zip(&points).enumerate() {
        let sm = sample(&l, *point);
        let v = f64::from(v);
        c.outside += usize::from(!(0.0..=1.0).contains(&v));
        let reference = if sm.inside {
            cpu::vis_csm::vis_csm(std::slice::from_ref(&basis), &lg, &sm)
        } else {
            1.0
        };
        let at = || {
            format!(
                "uv ({:.3}, {:.3}), receiver {:.4}",
                sm.uv[0], sm.uv[1], sm.depth
            )
        };
        c.reference.compare(v, reference, tol, at);
        match flat_z[i] {
            Some(z) => {
                let t = z - (sm.depth - f64::from(lg.bias) - f64::from(lg.csm_offset));
                if t.abs() < 1e-3 || t.abs() > 1.0 - 1e-3 {
                    continue;
                }
                let step = if t > 0.0 { 1.0 } else { 0.0 };
                let ring = s * series_bound(tv, t) - 0.5 * (s - 1.0);
                let check = if ring <= 0.0 {
                    &mut c.away
                } else {
                    &mut c.near
                };
                check.compare(v, step, ring.max(0.0) + basis_error + tol, || {
                    format!("{}, t = {t:.4}", at())
                });
            }
            None if i % 256 == 0 && i < flat.len() * 256 && v < c.contact.0 => {
                c.contact = (v, at());
            }
            None => {}
        }
    }
    if c.outside > 0 {
        c.reference
            .problem(format!("{} visibilities outside [0, 1]", c.outside));
    }
    let label = storage_name(storage);
    Ok([
        c.reference.row(
            5,
            "at blocker depths, 0, 1 and swept: vs f64 series",
            "csm M=16",
            label,
        ),
        c.away.row(
            5,
            &format!(
                "clamped output = step over flat blockers, |t| ≥ {:.3}",
                step_exact(&lg)
            ),
            "csm M=16",
            label,
        ),
        c.near.row(
            5,
            "clamped output vs step nearer the jump (ringing bound)",
            "csm M=16",
            label,
        ),
        Check::reported(
            5,
            [
                "darkening of receivers at their blocker's depth",
                "csm M=16",
                label,
            ],
            1.0 - c.contact.0,
            f64::NAN,
            0,
            format!(
                "1 − lowest visibility, at {} (offset {} and bias {} put t > 0)",
                c.contact.1, lg.csm_offset, lg.bias
            ),
        ),
    ])
}

/// The maps' channels side by side, level 0 (the technique has no mip filter here).
fn concat(levels: &[Vec<Texels>]) -> Result<Texels> {
    let first = &levels[0][0];
    let channels: usize = levels.iter().map(|l| l[0].channels).sum();
    let mut data = Vec::with_capacity(first.width * first.height * channels);
    for i in 0..first.width * first.height {
        for l in levels {
            let t = &l[0];
            data.extend_from_slice(&t.data[i * t.channels..(i + 1) * t.channels]);
        }
    }
    Ok(Texels {
        width: first.width,
        height: first.height,
        channels,
        data,
    })
}

/// Case 5.
pub(crate) fn csm_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let mut rng = Rng::new(0xC5);
    let mut rows = Vec::new();
    for storage in [Storage::F32, Storage::F16] {
        rows.extend(check_storage(gpu, &mut rng, storage)?);
    }
    rows.extend(series_rows(&LightGpu::new(&light(
        DIRECTIONAL,
        technique(Storage::F32),
        MAP,
        BIAS,
    ))));
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn total_variation_of_the_unattenuated_series_is_its_first_tail_term() {
        // α = 0: b_k = 0 up to M, then 1/(2k − 1): TV = 2·b_{M+1}.
        let mut l = LightGpu::new(&light(DIRECTIONAL, technique(Storage::F32), MAP, BIAS));
        l.csm_attenuation = 0.0;
        let m = f64::from(l.csm_terms);
        assert!((total_variation(&l) - 2.0 / (2.0 * m + 1.0)).abs() < 1e-15);
    }
}
