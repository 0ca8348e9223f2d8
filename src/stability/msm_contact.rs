//! Case 8: MSM with the receiver just behind a flat occluder, where the bias alone keeps the
//! Hankel matrix definite and f32 rounding of the stored moments (or 16-bit quantization)
//! competes with it. Flat maps at six depths (0.05 … 0.99, one the depth of the issue that
//! found it) run through the scene's graph (linearize, msm, blur; or the soft technique's
//! summed-area table) at every storage with its default moment bias; the real shading kernel
//! evaluates receivers 10⁻⁵ to 10⁻¹ behind the occluder (light bias 0).
//!
//! Bound: a requirement, not an error model. The stored moments are those of a point mass up
//! to the storage's rounding, so the exact answer is MSM's on the point mass with the same
//! bias; a default is acceptable when the GPU stays within [`bound`] of it: 0.01 for raw f32
//! moments (under three 8-bit output levels: no visible speckle), 0.03 for unorm16 (the
//! quantized moments carry 2⁻¹⁷ of their range, ~100× f32's rounding), 0.05 for soft MSM's
//! fixed-point tables (the step of a table coded for 205-texel squares, 10⁻⁵ of the range,
//! rounds each quantized moment once more), 0.25 for f16 (2⁻¹² of the range: no bias up to
//! 10⁻² brings it under 0.03 without lighting the first 0.09 of depth behind every occluder). The defaults are the
//! smallest biases of the measured sweep (`stability::msm_bias`, docs/STABILITY.md "MSM moment bias")
//! whose error there is at most half these bounds. Reported beside: how far behind the
//! occluder the exact shadow takes to reach 90% at that bias (what the bias costs at contact).

use glam::Vec3;

use super::StabilityRow;
use super::check::Check;
use super::harness::{DIRECTIONAL, light, receiver};
use super::msm_maps::{MsmMaps, leak_depth};
use super::planar::storage_name;
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::SatVariant;
use crate::model::{
    BlurKernel, Filter, Soft, Storage, StorageFilter, Technique, default_moment_bias,
    default_soft_moment_bias,
};
use crate::render::Renderer;

/// Map side of `msm` (a flat map has nothing to resolve), and of `msm_soft`, whose table
/// is coded for squares up to `2·SOFT_MAX_SEARCH·SOFT_MAP` = 205 texels: the step the default
/// search cap gives a 1024² map.
const MAP: u32 = 32;
const SOFT_MAP: u32 = 256;
const SOFT_MAX_SEARCH: f32 = 0.4;
/// Occluder depths: near both ends, the middle, and 0.90475309 (`cpu::vis_msm`'s near-singular
/// case).
const DEPTHS: [f32; 6] = [0.05, 0.3, 0.5, 0.7, 0.904_753_1, 0.99];
/// Receivers `10^(−5 + k/4)` behind the occluder, k = 0..=16.
const STEPS: i32 = 16;

/// What the GPU may differ from MSM's exact answer on the point mass by (see the module
/// documentation).
pub(crate) fn bound(storage: Storage, soft: bool) -> f64 {
    match (storage, soft) {
        (Storage::F16, _) => 0.25,
        (_, true) => 0.05,
        (Storage::F32, false) => 0.01,
        (Storage::Unorm16, false) => 0.03,
    }
}

fn technique(storage: Storage, soft: bool) -> Technique {
    if soft {
        Technique::MsmSoft {
            soft: Soft {
                storage,
                sums: SatVariant::Fixed,
                max_search: SOFT_MAX_SEARCH,
            },
            hausdorff: false,
            moment_bias: default_soft_moment_bias(storage),
            bleed: 0.0,
        }
    } else {
        Technique::Msm {
            prefilter: StorageFilter {
                storage,
                filter: Filter::Blur {
                    radius: 2.0,
                    sigma: 1.0,
                    kernel: BlurKernel::Gaussian,
                },
            },
            hausdorff: false,
            moment_bias: default_moment_bias(storage),
            bleed: 0.0,
        }
    }
}

/// Receivers behind an occluder at `z` (texel-centre UVs away from the edges).
fn receivers(l: &crate::model::Light, z: f64) -> Vec<(Vec3, Vec3)> {
    let mut out = Vec::new();
    for uv in [[0.5, 0.5], [0.3125, 0.6875]] {
        for k in 0..=STEPS {
            let d = z + 10f64.powf(-5.0 + f64::from(k) / 4.0);
            if d < 1.0 {
                out.push(receiver(l, uv, d));
            }
        }
    }
    out
}

/// One technique at one storage: every depth's map, every receiver.
fn check(gpu: &Gpu, storage: Storage, soft: bool) -> Result<(Check, f32)> {
    let t = technique(storage, soft);
    let alpha = match crate::technique::value(&t, "moment_bias") {
        Some(crate::model::ParamValue::Float(alpha)) => alpha,
        _ => 0.0,
    };
    let size = if soft { SOFT_MAP } else { MAP };
    let l = light(DIRECTIONAL, t, size, 0.0);
    let mut exec = Executor::new();
    let mut renderer = Renderer::new(&gpu.device);
    let mut c = Check::new();
    for z in DEPTHS {
        let maps = MsmMaps::new(gpu, &mut exec, &l, &vec![z; (size * size) as usize])?;
        let points = receivers(&l, f64::from(z));
        let vis = maps.gpu(gpu, &mut renderer, alpha, &points)?;
        for (&p, &v) in points.iter().zip(&vis) {
            let s = maps.sample(p);
            let exact = maps.exact(alpha, &s);
            c.compare(f64::from(v), exact, bound(storage, soft), || {
                format!("z {z}, receiver {:.3e} behind", s.depth - f64::from(z))
            });
        }
    }
    Ok((c, alpha))
}

/// Case 8: `msm` (Hamburger) at f32, f16 and unorm16 (when the device has 16-bit normalized
/// textures) and `msm_soft` at f32 and f16, each at its default moment bias.
pub(crate) fn msm_contact_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let unorm16 = gpu
        .device
        .features()
        .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM);
    let mut rows = Vec::new();
    for (storage, soft) in [
        (Storage::F32, false),
        (Storage::F16, false),
        (Storage::Unorm16, false),
        (Storage::F32, true),
        (Storage::F16, true),
        (Storage::Unorm16, true),
    ] {
        let name = if soft { "msm_soft" } else { "msm hamburger" };
        let label = storage_name(storage);
        if storage == Storage::Unorm16 && !unorm16 {
            rows.push(Check::reported(
                8,
                ["not run", name, label],
                f64::NAN,
                f64::NAN,
                0,
                "the device has no TEXTURE_FORMAT_16BIT_NORM".into(),
            ));
            continue;
        }
        let (c, alpha) = check(gpu, storage, soft)?;
        let what = format!("behind a flat occluder, α = {alpha:e}: vs exact");
        rows.push(c.row(8, &what, name, label));
        let leak = DEPTHS
            .iter()
            .filter_map(|&z| leak_depth(f64::from(z), f64::from(alpha), 0.9))
            .fold(0.0, f64::max);
        rows.push(Check::reported(
            8,
            [&format!("depth to 90% shadow, α = {alpha:e}"), name, label],
            leak,
            f64::NAN,
            0,
            "exact MSM behind a lone flat occluder: the contact region the bias lights".into(),
        ));
    }
    Ok(rows)
}
