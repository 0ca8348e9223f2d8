//! Case 3: MSM where its Hankel matrix degenerates: flat maps (every texel's moments equal, so
//! the filtered distribution is one point and the matrix is singular but for the moment bias)
//! at depths 0, 0.37 and exactly 1, and a map of exactly 0 beside exactly 1 (two-point
//! distributions along the seam after the blur: rank deficient).
//!
//! The depth buffer runs through the scene's graph (linearize, msm, blur) at each storage; the
//! moments are read back and checked against the f64 encoding and blur of the GPU's linear
//! map (storage roundings), then the real shading kernel sweeps the receiver depth from 0 to 1
//! in steps of 1/1024 at fixed map positions. Bounds: the visibility matches the f64 function
//! on the same moments within its sensitivity to f32 perturbations of the moments
//! (`tolerance::msm`), and it is non-increasing in the receiver depth up to the sum of the two
//! neighbours' tolerances (the f64 function itself is checked to be non-increasing).

use glam::Vec3;

use super::StabilityRow;
use super::check::Check;
use super::harness::{DIRECTIONAL, light, receiver, run_light, sample, shade};
use super::planar::storage_name;
use crate::cpu;
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::{
    BlurKernel, Filter, Light, Storage, StorageFilter, Technique, default_moment_bias,
};
use crate::render::Renderer;
use crate::{technique::linear_name, wgsl_mirrors::LightGpu};

const MAP: u32 = 32;
/// Receiver depths `i / STEPS` (0 < i < STEPS), and 2⁻²⁰ inside either end: a receiver
/// exactly on the near or far plane is inside the map or not by a rounding.
const STEPS: usize = 1024;

fn depths() -> Vec<f64> {
    let end = 2f64.powi(-20);
    std::iter::once(end)
        .chain((1..STEPS).map(|i| i as f64 / STEPS as f64))
        .chain(std::iter::once(1.0 - end))
        .collect()
}

/// What the f64 function may rise by between neighbours: the moments read back are rounded,
/// so not exactly those of any distribution, and on the 0 | 1 seam (a rank-deficient Hankel
/// matrix, made definite only by the bias α) its solve loses most of f64's digits; measured
/// rises there reach 9·10⁻⁸.
const REFERENCE_RISE: f64 = 1e-6;

fn technique(storage: Storage, hausdorff: bool) -> Technique {
    Technique::Msm {
        prefilter: StorageFilter {
            storage,
            filter: Filter::Blur {
                radius: 2.0,
                sigma: 1.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        hausdorff,
        moment_bias: default_moment_bias(storage),
        bleed: 0.0,
    }
}

/// A depth map's name, its texels and the map positions swept on it.
type SweptMap = (&'static str, Vec<f32>, Vec<[f64; 2]>);

/// The depth maps (orthographic: raw = linear) and the map positions swept on each.
fn maps() -> Vec<SweptMap> {
    let n = MAP as usize;
    let flat = |z: f32| vec![z; n * n];
    let step: Vec<f32> = (0..n * n)
        .map(|i| if i % n < n / 2 { 0.0 } else { 1.0 })
        .collect();
    let centre = vec![[0.3, 0.6]];
    // On the seam (bilinear between texels 15 and 16) and two texels into the 0 side.
    let seam = vec![[0.5, 0.4], [0.5 - 2.0 / MAP as f64, 0.7]];
    vec![
        ("flat 0", flat(0.0), centre.clone()),
        ("flat 0.37", flat(0.37), centre.clone()),
        ("flat 1", flat(1.0), centre),
        ("0 | 1", step, seam),
    ]
}

/// `(atol, rtol)` of the stored moments against the f64 encoding and blur: raw f32 powers, a
/// few roundings; 16-bit storage after the quantization matrix (entries up to 82 in f32,
/// ~3·10⁻⁵ absolute) plus three stores (encode, blur_h, blur_v) of 2⁻¹⁰ relative each for
/// f16 (Vulkan may round toward zero) or 2⁻¹⁷ absolute for unorm16.
fn moment_tolerance(storage: Storage) -> (f64, f64) {
    match storage {
        Storage::F32 => (1e-7, 1e-6),
        Storage::F16 => (3e-5, 3.0 * 2f64.powi(-10)),
        Storage::Unorm16 => (3e-5 + 3.0 * 2f64.powi(-17), 0.0),
    }
}

struct Checks {
    moments: Check,
    vis: Check,
    monotone: Check,
    outside: usize,
    reference_rises: usize,
}

/// One map: moments against f64, then the sweep.
fn check_map(
    gpu: &Gpu,
    exec: &mut Executor,
    renderer: &mut Renderer,
    l: &Light,
    (name, raw, uvs): &SweptMap,
    c: &mut Checks,
) -> Result<()> {
    let Some(prefilter) = l.shadow.technique.prefilter() else {
        return Ok(());
    };
    let (ran, maps) = run_light(gpu, exec, l, raw)?;
    let linear = ran.texels(gpu, &linear_name(0), 0)?;
    let quantized = prefilter.storage != Storage::F32;
    let expected = cpu::blur::blur(
        &cpu::msm::msm(&linear, quantized),
        2.0,
        1.0,
        BlurKernel::Gaussian,
    );
    let levels = ran.levels(gpu, &maps[0])?;
    let (atol, rtol) = moment_tolerance(prefilter.storage);
    for (i, (&g, &e)) in levels[0].data.iter().zip(&expected.data).enumerate() {
        c.moments.compare(g, e, atol + rtol * e.abs(), || {
            format!("{name}, texel {} channel {}", i / 4, i % 4)
        });
    }
    let lg = LightGpu::new(l);
    for &uv in uvs {
        let points: Vec<(Vec3, Vec3)> = depths().into_iter().map(|d| receiver(l, uv, d)).collect();
        let vis = shade(gpu, renderer, l, std::slice::from_ref(&levels), &points)?;
        c.outside += vis.iter().filter(|v| !(0.0..=1.0).contains(*v)).count();
        let mut last: Option<(f64, f64, f64)> = None;
        for (i, &v) in vis.iter().enumerate() {
            let s = sample(l, points[i]);
            let (reference, tol) = if s.inside {
                (
                    cpu::vis_msm::vis_msm(std::slice::from_ref(&levels[0]), &lg, &s),
                    crate::tolerance::msm(std::slice::from_ref(&levels[0]), &lg, &s),
                )
            } else {
                (1.0, 0.0)
            };
            let at = || format!("{name}, uv {uv:?}, receiver {:.4}", s.depth);
            let v = f64::from(v);
            c.vis.compare(v, reference, tol, at);
            if let Some((v0, r0, t0)) = last {
                // Each point within its tolerance of a non-increasing reference.
                c.monotone
                    .compare((v - v0).max(0.0), 0.0, t0 + tol + REFERENCE_RISE, at);
                if reference > r0 + REFERENCE_RISE {
                    c.reference_rises += 1;
                }
            }
            last = Some((v, reference, tol));
        }
    }
    Ok(())
}

/// Case 3: Hamburger at f32, f16 and unorm16 (when the device has 16-bit normalized
/// textures), Hausdorff at f32.
pub(crate) fn msm_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let unorm16 = gpu
        .device
        .features()
        .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM);
    let mut rows = Vec::new();
    for (storage, hausdorff) in [
        (Storage::F32, false),
        (Storage::F32, true),
        (Storage::F16, false),
        (Storage::Unorm16, false),
    ] {
        let name = if hausdorff {
            "msm hausdorff"
        } else {
            "msm hamburger"
        };
        let storage_label = storage_name(storage);
        if storage == Storage::Unorm16 && !unorm16 {
            rows.push(Check::reported(
                3,
                ["not run", name, storage_label],
                f64::NAN,
                f64::NAN,
                0,
                "the device has no TEXTURE_FORMAT_16BIT_NORM".into(),
            ));
            continue;
        }
        let l = light(DIRECTIONAL, technique(storage, hausdorff), MAP, 0.002);
        let mut exec = Executor::new();
        let mut renderer = Renderer::new(&gpu.device);
        let mut c = Checks {
            moments: Check::new(),
            vis: Check::new(),
            monotone: Check::new(),
            outside: 0,
            reference_rises: 0,
        };
        for map in maps() {
            check_map(gpu, &mut exec, &mut renderer, &l, &map, &mut c)?;
        }
        if c.outside > 0 {
            c.vis
                .problem(format!("{} visibilities outside [0, 1]", c.outside));
        }
        if c.reference_rises > 0 {
            c.monotone.problem(format!(
                "the f64 reference rises {} times",
                c.reference_rises
            ));
        }
        let what = |w: &str| format!("flat, 0 and 1 maps: {w}");
        rows.push(
            c.moments
                .row(3, &what("moments vs f64"), name, storage_label),
        );
        rows.push(
            c.vis
                .row(3, &what("visibility vs f64"), name, storage_label),
        );
        rows.push(
            c.monotone
                .row(3, &what("rise along the depth sweep"), name, storage_label),
        );
    }
    Ok(rows)
}
