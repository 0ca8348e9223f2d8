//! The moment-bias sweep behind MSM's defaults (docs/STABILITY.md, "MSM moment bias";
//! `cargo run --release --example msm_bias_sweep`). A larger bias α keeps the Hankel matrix
//! further from singular, so the f32 arithmetic and the storage's rounding matter less, but it
//! lights the region just behind every occluder (the exact shadow behind a flat occluder takes
//! ~0.9·√α of depth to reach 90%). For each technique, storage and α the real graph and
//! shading kernel run on a random blocky map, and the visibility is compared with MSM in exact
//! arithmetic on the exact moments of the same linear map (f64 encode and blur, or integral
//! image), at two families of receivers:
//!
//! - `behind`: at the centres of flat blocks (the filtered moments are a point mass),
//!   10⁻⁵–10⁻¹ behind the block's depth (log-uniform): the contact case;
//! - `random`: anywhere (blurred edges and corners mix up to four depths), half at a random
//!   depth, half within 10⁻⁵–10⁻¹ of a depth nearby, in front or behind.
//!
//! Each row gives the 99th percentile and the largest |GPU − exact|, the share above 0.01,
//! the share where the GPU and the f64 reference on the same stored moments differ by more
//! than 10⁻⁴ (what the tests compare), the 99th percentile of that reference's own distance
//! to the exact answer (what the storage loses before any f32 arithmetic), and the leak depth
//! above.

use glam::Vec3;

use super::check::Rng;
use super::harness::{DIRECTIONAL, light, receiver};
use super::msm_maps::{MsmMaps, leak_depth};
use super::planar::storage_name;
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::SatVariant;
use crate::model::{BlurKernel, Filter, Soft, Storage, StorageFilter, Technique};
use crate::render::Renderer;

/// Map side and block side of the random map: 256 blocks, about half of them flat.
const MAP: usize = 256;
const BLOCK: usize = 16;
/// Soft MSM's search cap: on a 256² map it codes the fixed-point table as the default 0.1
/// codes a 1024² map's (squares up to 205 texels, so the same quantization step).
const SOFT_MAX_SEARCH: f32 = 0.4;

/// What [`msm_bias_sweep`] runs.
#[derive(Clone, Debug)]
pub struct BiasSweep {
    /// Biases α to try.
    pub alphas: Vec<f32>,
    /// Receivers per family.
    pub points: usize,
    /// Seed of the map and the receivers.
    pub seed: u64,
}

impl Default for BiasSweep {
    fn default() -> Self {
        Self {
            alphas: vec![
                3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 6e-5, 1e-4, 2e-4, 5e-4, 1e-3, 3e-3, 1e-2,
            ],
            points: 4000,
            seed: 8,
        }
    }
}

/// One technique, storage, bias and receiver family.
#[derive(Clone, Debug)]
pub struct BiasRow {
    /// `msm` or `msm_soft`.
    pub technique: &'static str,
    /// Storage of the moments.
    pub storage: Storage,
    /// The bias α.
    pub alpha: f32,
    /// `behind` or `random` (see the module documentation).
    pub family: &'static str,
    /// Receivers compared.
    pub points: usize,
    /// 99th percentile of |GPU − exact|.
    pub p99: f64,
    /// Largest |GPU − exact|.
    pub max: f64,
    /// Share of receivers with |GPU − exact| > 0.01.
    pub over: f64,
    /// Share with |GPU − f64 reference on the same stored moments| > 10⁻⁴.
    pub disagree: f64,
    /// 99th percentile of |f64 reference on the stored moments − exact|: what the storage
    /// loses before any f32 arithmetic.
    pub stored_p99: f64,
    /// Depth behind a flat occluder at 0.5 where the exact shadow reaches 90%.
    pub leak: f64,
}

/// A random blocky linear depth map: `BLOCK`² blocks of depths in [0.02, 0.98]; every other
/// block has a 2×2 patch of another depth in its corner. Returns the map and which blocks
/// are flat (no patch).
fn blocky_map(rng: &mut Rng) -> (Vec<f32>, Vec<bool>) {
    let blocks = MAP / BLOCK;
    let mut map = vec![0.0f32; MAP * MAP];
    let mut flat = Vec::new();
    for by in 0..blocks {
        for bx in 0..blocks {
            let z = rng.range(0.02, 0.98) as f32;
            let patch = rng.range(0.02, 0.98) as f32;
            let has_patch = rng.below(2) == 1;
            flat.push(!has_patch);
            for y in 0..BLOCK {
                for x in 0..BLOCK {
                    let corner = has_patch && x < 2 && y < 2;
                    map[(by * BLOCK + y) * MAP + bx * BLOCK + x] = if corner { patch } else { z };
                }
            }
        }
    }
    (map, flat)
}

/// `10^U(−5, −1)`.
fn small(rng: &mut Rng) -> f64 {
    10f64.powf(rng.range(-5.0, -1.0))
}

/// The two receiver families on `map`, as map positions and depths.
fn families(rng: &mut Rng, map: &[f32], flat: &[bool], n: usize) -> [Vec<([f64; 2], f64)>; 2] {
    let blocks = MAP / BLOCK;
    let flat_blocks: Vec<usize> = (0..flat.len()).filter(|&b| flat[b]).collect();
    let mut behind = Vec::new();
    while behind.len() < n {
        let b = flat_blocks[rng.below(flat_blocks.len())];
        let (bx, by) = (b % blocks, b / blocks);
        let z = f64::from(map[(by * BLOCK + BLOCK / 2) * MAP + bx * BLOCK + BLOCK / 2]);
        let d = z + small(rng);
        let uv = [bx, by].map(|c| (c * BLOCK + BLOCK / 2) as f64 / MAP as f64);
        if d < 1.0 {
            behind.push((uv, d));
        }
    }
    let mut random = Vec::new();
    while random.len() < n {
        let uv = [rng.range(0.02, 0.98), rng.range(0.02, 0.98)];
        let d = if rng.below(2) == 0 {
            rng.range(0.01, 0.99)
        } else {
            let last = MAP as i64 - 1;
            let mut t = |c: f64| ((c * MAP as f64) as i64 + rng.below(7) as i64 - 3).clamp(0, last);
            let (x, y) = (t(uv[0]), t(uv[1]));
            let z = f64::from(map[y as usize * MAP + x as usize]);
            let sign = if rng.below(2) == 0 { -1.0 } else { 1.0 };
            z + sign * small(rng)
        };
        if d > 0.0 && d < 1.0 {
            random.push((uv, d));
        }
    }
    [behind, random]
}

/// The techniques swept: `msm` (Gaussian blur, radius 2) and `msm_soft` (fixed-point table
/// coded for [`SOFT_MAX_SEARCH`], light 1 unit wide) at every storage.
fn techniques() -> Vec<(&'static str, Storage, Technique)> {
    let mut out = Vec::new();
    for storage in [Storage::F32, Storage::F16, Storage::Unorm16] {
        let msm = Technique::Msm {
            prefilter: StorageFilter {
                storage,
                filter: Filter::Blur {
                    radius: 2.0,
                    sigma: 1.0,
                    kernel: BlurKernel::Gaussian,
                },
            },
            hausdorff: false,
            moment_bias: 0.0,
            bleed: 0.0,
        };
        out.push(("msm", storage, msm));
    }
    for storage in [Storage::F32, Storage::F16, Storage::Unorm16] {
        let soft = Technique::MsmSoft {
            soft: Soft {
                storage,
                sums: SatVariant::Fixed,
                max_search: SOFT_MAX_SEARCH,
            },
            hausdorff: false,
            moment_bias: 0.0,
            bleed: 0.0,
        };
        out.push(("msm_soft", storage, soft));
    }
    out
}

/// The share of `errors` above `limit`, their 99th percentile and largest value.
fn stats(errors: &mut [f64], limit: f64) -> (f64, f64, f64) {
    errors.sort_by(f64::total_cmp);
    let n = errors.len();
    let over = errors.iter().filter(|&&e| e > limit).count() as f64 / n as f64;
    (over, errors[(n - 1) * 99 / 100], errors[n - 1])
}

/// Runs the sweep; `progress(technique, storage)` is called before each map's run. Storages
/// the device cannot hold (unorm16 without `TEXTURE_FORMAT_16BIT_NORM`) are left out.
pub fn msm_bias_sweep(
    gpu: &Gpu,
    sweep: &BiasSweep,
    progress: &mut dyn FnMut(&str, Storage),
) -> Result<Vec<BiasRow>> {
    let unorm16 = gpu
        .device
        .features()
        .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM);
    let mut rng = Rng::new(sweep.seed);
    let (map, flat) = blocky_map(&mut rng);
    let fams = families(&mut rng, &map, &flat, sweep.points);
    let mut rows = Vec::new();
    for (name, storage, t) in techniques() {
        if storage == Storage::Unorm16 && !unorm16 {
            continue;
        }
        progress(name, storage);
        let mut l = light(DIRECTIONAL, t, MAP as u32, 0.0);
        l.size = 1.0;
        let mut exec = Executor::new();
        let mut renderer = Renderer::new(&gpu.device);
        let maps = MsmMaps::new(gpu, &mut exec, &l, &map)?;
        for &alpha in &sweep.alphas {
            for (family, set) in ["behind", "random"].into_iter().zip(&fams) {
                let points: Vec<(Vec3, Vec3)> =
                    set.iter().map(|&(uv, d)| receiver(&l, uv, d)).collect();
                let vis = maps.gpu(gpu, &mut renderer, alpha, &points)?;
                let (mut exact, mut same, mut kept) = (Vec::new(), Vec::new(), Vec::new());
                for (&p, &v) in points.iter().zip(&vis) {
                    let s = maps.sample(p);
                    let (v, e, r) = (f64::from(v), maps.exact(alpha, &s), maps.stored(alpha, &s));
                    exact.push((v - e).abs());
                    same.push((v - r).abs());
                    kept.push((r - e).abs());
                }
                let (over, p99, max) = stats(&mut exact, 0.01);
                let (disagree, _, _) = stats(&mut same, 1e-4);
                let (_, stored_p99, _) = stats(&mut kept, 0.01);
                rows.push(BiasRow {
                    technique: name,
                    storage,
                    alpha,
                    family,
                    points: points.len(),
                    p99,
                    max,
                    over,
                    disagree,
                    stored_p99,
                    leak: leak_depth(0.5, f64::from(alpha), 0.9).unwrap_or(f64::NAN),
                });
            }
        }
    }
    Ok(rows)
}

/// The rows as a Markdown table.
pub fn bias_table(rows: &[BiasRow]) -> String {
    let mut s = String::from(
        "| technique | storage | α | receivers | p99 \\|Δ\\| | max \\|Δ\\| | > 0.01 | \
         ≠ f64 (> 1e-4) | storage p99 | 90% depth |\n\
         | --- | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {:e} | {} | {:.4} | {:.4} | {:.1}% | {:.1}% | {:.4} | {:.4} |\n",
            r.technique,
            storage_name(r.storage),
            r.alpha,
            r.family,
            r.p99,
            r.max,
            100.0 * r.over,
            100.0 * r.disagree,
            r.stored_p99,
            r.leak
        );
    }
    s
}
