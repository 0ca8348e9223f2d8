//! Case 6: NaN, +Inf and −Inf in the depth buffer (degenerate geometry, a host's bad data).
//! `linearize` replaces each with 1.0 ("no occluder") and counts it, the count the renderer
//! reports (`Frame::sanitized`, a `warning:` line from `render`). Downstream, nothing may
//! spread: every texel of every resource each technique's graph writes must be finite, and
//! equal (within the stage error model of `stages`) to the f64 pipeline run on the sanitized
//! map, the replaced texels' finite neighbours included. Summed-area tables of the linear map
//! and of VSM moments likewise.
//!
//! The buffer is 61² (not a multiple of any workgroup): blocky random depths with non-finite
//! values at the four corners, along the edges, in a 3×3 cluster and at 2% of random texels.

use super::StabilityRow;
use super::check::{Check, Rng};
use super::exponents::{range, sat_check, sat_coding_for};
use super::harness::{DIRECTIONAL, SPOT, light, mips, registered};
use super::stages::run_stages;
use crate::cpu::Texels;
use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::ParamValue;
use crate::model::{BlurKernel, Filter, LightKind, Storage, Technique, exponent_limit};
use crate::technique::linear_name;

const MAP: u32 = 61;

/// The depth buffer (orthographic values: linear depth) with its non-finite texels.
fn depth_buffer(rng: &mut Rng) -> (Vec<f32>, usize) {
    let n = MAP as usize;
    let mut raw: Vec<f32> = (0..n * n).map(|_| rng.range(0.85, 0.95) as f32).collect();
    for _ in 0..10 {
        let (x0, y0) = (rng.below(n), rng.below(n));
        let (w, h) = (2 + rng.below(n / 3), 2 + rng.below(n / 3));
        let z = rng.range(0.15, 0.7) as f32;
        for y in y0..(y0 + h).min(n) {
            raw[y * n + x0..y * n + (x0 + w).min(n)].fill(z);
        }
    }
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut at: Vec<usize> = vec![
        0,
        n - 1,
        n * (n - 1),
        n * n - 1,
        n / 2,
        n * (n / 2),
        7 * n + n - 1,
    ];
    for y in 20..23 {
        at.extend(20 + y * n..23 + y * n);
    }
    at.extend((0..n * n / 50).map(|_| rng.below(n * n)));
    at.sort_unstable();
    at.dedup();
    for (k, &i) in at.iter().enumerate() {
        raw[i] = bad[k % 3];
    }
    (raw, at.len())
}

fn blur() -> Filter {
    Filter::Blur {
        radius: 3.0,
        sigma: 1.5,
        kernel: BlurKernel::Gaussian,
    }
}

/// The techniques and filters run on the buffer, with the light kind (the scene defaults
/// but where given).
fn configurations() -> Vec<(String, &'static str, LightKind, Technique)> {
    let vsm = |filter| registered("vsm", Some(Storage::F32), filter, &[]);
    let c16 = exponent_limit(Storage::F16);
    let c = ParamValue::Float(c16);
    let evsm4 = [("exponent_pos", c), ("exponent_neg", c)];
    vec![
        ("vsm → blur".into(), "f32", DIRECTIONAL, vsm(blur())),
        ("vsm → mips".into(), "f32", DIRECTIONAL, vsm(mips(2.0))),
        ("vsm → blur (spot)".into(), "f32", SPOT, vsm(blur())),
        (
            format!("evsm4 c={c16} → blur"),
            "f16",
            DIRECTIONAL,
            registered("evsm4", Some(Storage::F16), blur(), &evsm4),
        ),
        (
            "esm c=80 → blur (log)".into(),
            "f32",
            DIRECTIONAL,
            registered("esm", None, blur(), &[]),
        ),
        (
            "esm c=80 → mips (log)".into(),
            "f32",
            DIRECTIONAL,
            registered("esm", None, mips(2.0), &[]),
        ),
        (
            "msm → blur".into(),
            "f16",
            DIRECTIONAL,
            registered("msm", Some(Storage::F16), blur(), &[]),
        ),
        (
            "csm M=3 → blur".into(),
            "f32",
            DIRECTIONAL,
            registered(
                "csm",
                Some(Storage::F32),
                blur(),
                &[("terms", ParamValue::Int(3))],
            ),
        ),
    ]
}

/// Case 6.
pub(crate) fn non_finite_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let mut rng = Rng::new(0x6A6);
    let (raw, injected) = depth_buffer(&mut rng);
    let mut exec = Executor::new();
    let mut rows = Vec::new();
    let mut counted = Check::new();
    for (name, storage, kind, technique) in configurations() {
        let l = light(kind, technique, MAP, 0.002);
        let s = run_stages(gpu, &mut exec, &l, &raw)?
            .ok_or_else(|| Error::Invalid(format!("{name} has no prefiltered map")))?;
        counted.compare(f64::from(s.replaced), injected as f64, 0.0, || {
            format!("{name}: linearize counted {}", s.replaced)
        });
        if s.expected_replaced as usize != injected {
            counted.problem(format!(
                "the f64 reference replaced {}, {injected} were injected",
                s.expected_replaced
            ));
        }
        let mut all = s.linear;
        all.merge(s.encode);
        all.merge(s.filter);
        if s.nonfinite > 0 {
            all.problem(format!("{} NaN/Inf texels downstream", s.nonfinite));
        }
        let mut row = all.row(6, "every stage vs f64 of the sanitized map", &name, storage);
        row.nonfinite += s.nonfinite;
        rows.push(row);
        if name == "vsm → blur" {
            // Tables of the linear map and of the moments, codings chosen from their ranges.
            let linear = s.ran.texels(gpu, &linear_name(0), 0)?;
            let linear_tex = s.ran.outputs.textures[&linear_name(0)].clone();
            let (moments_name, _, moments) = &s.encoded[0];
            let moments_tex = s.ran.outputs.textures[moments_name].clone();
            for (what, texture, texels) in [
                ("sat of the linear map", linear_tex, linear),
                ("sat of the vsm moments", moments_tex, moments.clone()),
            ] {
                rows.push(sat_row(gpu, &texture, &texels, what)?);
            }
        }
    }
    let mut count = counted.row(
        6,
        "non-finite texels replaced and counted at linearize",
        "linearize",
        "r32float",
    );
    count.note = format!("{injected} injected (NaN, +Inf, −Inf); {}", count.note);
    rows.insert(0, count);
    Ok(rows)
}

/// A summed-area table over sanitized data: finite, windows within the coding's model.
fn sat_row(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    texels: &Texels,
    what: &str,
) -> Result<StabilityRow> {
    let (lo, hi) = range(texels);
    let area = (texels.width * texels.height) as u64;
    let coding = sat_coding_for(lo, hi, area, area)?;
    let (check, nonfinite) = sat_check(gpu, texture, texels, &coding, (lo, hi))?;
    let mut check = check;
    if nonfinite > 0 {
        check.problem(format!("{nonfinite} NaN/Inf texels in the table"));
    }
    let storage = format!("{:?}", coding.variant).to_lowercase();
    let mut row = check.row(
        6,
        &format!("{what}: window means / range vs f64"),
        "sat",
        &storage,
    );
    row.nonfinite += nonfinite;
    Ok(row)
}
