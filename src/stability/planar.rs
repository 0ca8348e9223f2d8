//! Case 2: VSM, EVSM2 and EVSM4 over a planar occluder, the variance-based techniques' corner
//! of zero variance: the occluder map is constant, so σ² is only the floor (and rounding).
//!
//! The depth buffer goes through the scene's graph (linearize, encode, blur) on the GPU; the
//! filtered map is read back and the real shading kernel evaluates receivers at the
//! occluder's depth, in front of it (down to 10⁻⁶ in front) and behind it. In front and at the
//! occluder (the light's bias, 0.002, is far above every rounding) the visibility must be
//! exactly 1: the kernels return 1 on `d ≤ E[x]` without arithmetic. Behind, it is compared
//! with the f64 function on the same filtered texels, within the first-order propagation of
//! the f32 roundings through the Chebyshev bound (`tolerance::vsm`, `tolerance::evsm`).

use super::StabilityRow;
use super::check::{Check, Rng};
use super::harness::{DIRECTIONAL, SPOT, light, receiver, run_light, sample, shade};
use crate::cpu;
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::{
    BlurKernel, Filter, LightKind, Storage, StorageFilter, Technique, exponent_limit,
};
use crate::render::Renderer;
use crate::{
    technique::{Encoding, encoding, linear_name},
    wgsl_mirrors::LightGpu,
};

/// Map side: small, a constant map has nothing to resolve.
const MAP: u32 = 32;
/// The light's constant bias (the scene default).
const BIAS: f32 = 0.002;

fn prefilter(storage: Storage) -> StorageFilter {
    StorageFilter {
        storage,
        filter: Filter::Blur {
            radius: 2.0,
            sigma: 1.0,
            kernel: BlurKernel::Gaussian,
        },
    }
}

/// The three techniques at `storage`; EVSM at the storage's exponent limit (its worst case).
fn techniques(storage: Storage) -> [(&'static str, Technique); 3] {
    let c = exponent_limit(storage);
    let evsm = |four| Technique::Evsm {
        prefilter: prefilter(storage),
        four,
        exp_pos: c,
        exp_neg: c,
        bleed: 0.0,
        min_variance: 1e-4,
    };
    [
        (
            "vsm",
            Technique::Vsm {
                prefilter: prefilter(storage),
                bleed: 0.2,
                min_variance: 1e-5,
            },
        ),
        ("evsm2", evsm(false)),
        ("evsm4", evsm(true)),
    ]
}

/// The raw depth-buffer value of linear depth `z` for light kind `kind` (orthographic depth is
/// linear; perspective through the projection).
fn raw_depth(kind: LightKind, technique: Technique, z: f64) -> f32 {
    let l = LightGpu::new(&light(kind, technique, MAP, BIAS));
    cpu::light::linear_to_ndc(&l, z) as f32
}

/// Receivers at `d` for each depth in `depths`, at `per` random map positions each.
fn receivers(
    l: &crate::model::Light,
    rng: &mut Rng,
    depths: &[f64],
    per: usize,
) -> Vec<(glam::Vec3, glam::Vec3)> {
    let mut out = Vec::new();
    for &d in depths {
        for _ in 0..per {
            let uv = [rng.range(0.1, 0.9), rng.range(0.1, 0.9)];
            out.push(receiver(l, uv, d));
        }
    }
    out
}

/// One technique at one storage: both light kinds, occluders at 0.35 and at 1.0 (the far
/// plane, where EVSM's moments are largest).
fn check_technique(
    gpu: &Gpu,
    rng: &mut Rng,
    name: &str,
    technique: Technique,
    storage: Storage,
) -> Result<[StabilityRow; 2]> {
    let mut exec = Executor::new();
    let mut renderer = Renderer::new(&gpu.device);
    let (mut front, mut behind) = (Check::new(), Check::new());
    let mut outside = 0usize;
    for kind in [DIRECTIONAL, SPOT] {
        let l = light(kind, technique, MAP, BIAS);
        let lg = LightGpu::new(&l);
        for z0 in [0.35, 1.0] {
            let raw = vec![raw_depth(kind, technique, z0); (MAP * MAP) as usize];
            let (ran, maps) = run_light(gpu, &mut exec, &l, &raw)?;
            // The occluder's depth as the GPU linearized it (the map is constant).
            let z = ran.texels(gpu, &linear_name(0), 0)?.data[0];
            let levels = ran.levels(gpu, &maps[0])?;
            let kind_name = if lg.kind == 0 { "directional" } else { "spot" };
            let ahead: Vec<f64> = [0.0, 1e-6, 1e-5, 1e-4, 1e-3, 0.01, 0.1, 0.5 * z, z - 1e-3]
                .iter()
                .map(|&dz| z - dz)
                .filter(|&d| d > 1e-3)
                .collect();
            let after: Vec<f64> = [1e-6, 1e-5, 1e-4, 1e-3, 2e-3, 3e-3, 0.01, 0.05, 0.2, 0.5]
                .iter()
                .map(|&dz| z + dz)
                .filter(|&d| d < 1.0)
                .collect();
            let pa = receivers(&l, rng, &ahead, 16);
            let pb = receivers(&l, rng, &after, 16);
            let all: Vec<_> = pa.iter().chain(&pb).copied().collect();
            let vis = shade(gpu, &mut renderer, &l, std::slice::from_ref(&levels), &all)?;
            outside += vis.iter().filter(|v| !(0.0..=1.0).contains(*v)).count();
            for (i, &v) in vis.iter().enumerate() {
                let s = sample(&l, all[i]);
                let at = || format!("{kind_name}, occluder {z0}, receiver {:+.1e}", s.depth - z);
                if i < pa.len() {
                    front.compare(f64::from(v), 1.0, 0.0, at);
                    continue;
                }
                let (reference, tol) = if !s.inside {
                    (1.0, 0.0)
                } else if lg.technique == 3 {
                    (
                        cpu::vis_vsm::vis_vsm(&levels, &lg, &s),
                        crate::tolerance::vsm(&levels, &lg, &s),
                    )
                } else {
                    (
                        cpu::vis_evsm::vis_evsm(&levels, &lg, &s),
                        crate::tolerance::evsm(&levels, &lg, &s),
                    )
                };
                behind.compare(f64::from(v), reference, tol, at);
            }
        }
    }
    if outside > 0 {
        behind.problem(format!("{outside} visibilities outside [0, 1]"));
    }
    let storage = storage_name(storage);
    Ok([
        front.row(
            2,
            "zero variance, at and in front: exactly 1",
            name,
            storage,
        ),
        behind.row(2, "zero variance, behind: vs f64", name, storage),
    ])
}

/// A storage's name in the table.
pub(crate) fn storage_name(storage: Storage) -> &'static str {
    match storage {
        Storage::F32 => "f32",
        Storage::F16 => "f16",
        Storage::Unorm16 => "unorm16",
    }
}

/// Case 2: every variance technique at f32 and f16.
pub(crate) fn planar_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let mut rng = Rng::new(0x91A7);
    let mut rows = Vec::new();
    for storage in [Storage::F32, Storage::F16] {
        for (name, technique) in techniques(storage) {
            let label = match encoding(&technique) {
                Some(Encoding::Evsm { exp_pos, .. }) => format!("{name} c={exp_pos}"),
                _ => name.to_string(),
            };
            rows.extend(check_technique(gpu, &mut rng, &label, technique, storage)?);
        }
    }
    Ok(rows)
}
