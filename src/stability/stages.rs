//! A technique's scene graph (linearize → encode → blur or mips) run on a raw depth buffer,
//! every stage read back and compared with the same stage of the f64 pipeline
//! (`cpu::linearize`, the technique's `cpu` encoding, `cpu::blur`, `cpu::mips`) on the same
//! buffer, and every texel of every resource checked for NaN/Inf.
//!
//! Error model per stage, `|gpu − f64| ≤ atol + rtol·|f64|`, accumulated along the chain:
//! - encode: VSM a few roundings (1e-6); EVSM SPIR-V's `exp` at `(3 + 2c)` ULP, doubled by the
//!   square; ESM one rounding of `c·z`; MSM raw powers 4 roundings, the 16-bit quantization
//!   matrix ~3·10⁻⁵ absolute; CSM Vulkan's `sin`/`cos`, 2⁻¹¹ absolute.
//! - every store: f16 2⁻¹⁰ relative (Vulkan may round toward zero) and 2⁻²⁴ absolute
//!   (subnormal spacing); unorm16 2⁻¹⁶ absolute; f32 exact.
//! - a linear blur pass of `n` taps: `(n + 2)·u·Σ wᵢ|vᵢ|`, which is `(n + 2)·u·|f64|` for a
//!   channel of one sign (all but CSM's) and at most `(n + 2)·u` for CSM's basis in [−1, 1];
//!   a log-space pass adds `(3 + 2c)` ULP absolute for its `exp`/`log` and 2u relative.
//! - a mip level: 8 roundings relative (16 weighted taps at most, weights exact), or in log
//!   space `2(3 + 2c)` ULP absolute and 4u relative.

use super::check::{Check, U};
use super::harness::{Ran, run_light};
use crate::cpu::{self, Texels};
use crate::error::Result;
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::model::{Filter, Light, LightKind, Storage, Technique};
use crate::technique::{Encoding, encoding, linear_name};

/// `(atol, rtol)`.
type Tol = (f64, f64);

fn add((a, r): Tol, (b, s): Tol) -> Tol {
    (a + b, r + s)
}

/// How a technique's representation is made, stored and filtered.
struct Model {
    /// The f64 encoding of a linear map (all channels).
    encode: Box<dyn Fn(&Texels) -> Texels>,
    /// The encode kernel's error before its store.
    encode_tol: Tol,
    /// One store's rounding.
    store: Tol,
    /// Channels of mixed sign (CSM): blur errors are absolute, not relative.
    mixed_sign: bool,
    /// Filtered in log space (ESM), with this exponent.
    log: Option<f64>,
}

fn model(t: &Technique) -> Option<Model> {
    let ulp = 2.0 * U;
    let storage = t.prefilter().map_or(Storage::F32, |p| p.storage);
    let store = match storage {
        Storage::F32 => (0.0, 0.0),
        Storage::F16 => (U, 2f64.powi(-10)),
        Storage::Unorm16 => (2f64.powi(-16), 0.0),
    };
    let m = |encode: Box<dyn Fn(&Texels) -> Texels>, encode_tol, mixed_sign, log| Model {
        encode,
        encode_tol,
        store,
        mixed_sign,
        log,
    };
    // The encoding the technique's entry declares, with its f64 reference and error model.
    Some(match encoding(t)? {
        Encoding::Vsm => m(Box::new(cpu::vsm::vsm), (1e-6, 1e-6), false, None),
        Encoding::Evsm { exp_pos, exp_neg } => {
            let c = f64::from(exp_pos.max(exp_neg));
            let f = move |z: &Texels| cpu::evsm::evsm(z, exp_pos.into(), exp_neg.into());
            let rtol = 2.0 * (3.0 + 2.0 * c) * ulp + 4.0 * U;
            m(Box::new(f), (0.0, rtol), false, None)
        }
        Encoding::Esm { exponent } => {
            let f = move |z: &Texels| cpu::esm::esm(z, exponent.into());
            m(Box::new(f), (0.0, 2.0 * U), false, Some(exponent.into()))
        }
        Encoding::Msm { quantized: q } => {
            let f = move |z: &Texels| cpu::msm::msm(z, q);
            let tol = if q { (3e-5, 0.0) } else { (1e-7, 4.0 * U) };
            m(Box::new(f), tol, false, None)
        }
        Encoding::Csm { terms } => {
            let f = move |z: &Texels| cpu::csm::csm(z, terms);
            m(Box::new(f), (2f64.powi(-11), 0.0), true, None)
        }
    })
}

/// Channels `first..first + n` of `t`.
fn channels(t: &Texels, first: usize, n: usize) -> Texels {
    Texels {
        width: t.width,
        height: t.height,
        channels: n,
        data: t
            .data
            .chunks(t.channels)
            .flat_map(|c| c[first..first + n].to_vec())
            .collect(),
    }
}

/// The comparisons of one run, stage by stage.
pub(crate) struct Stages {
    /// `linearize` against `cpu::linearize`.
    pub linear: Check,
    /// The encoding kernel(s).
    pub encode: Check,
    /// The filter: both blur passes, or every mip level (empty without a filter).
    pub filter: Check,
    /// `blur`, `mips` or `none`.
    pub filter_name: &'static str,
    /// NaN/Inf texels in any resource the graph wrote (the raw depth buffer excluded).
    pub nonfinite: u64,
    /// Texels `linearize` reported replacing.
    pub replaced: u32,
    /// Texels `cpu::linearize` replaces.
    pub expected_replaced: u32,
    /// The run (its textures stay valid until the executor runs again).
    pub ran: Ran,
    /// The encoded maps: resource name, first channel in the f64 encoding, GPU texels.
    pub encoded: Vec<(String, usize, Texels)>,
}

/// Runs `l`'s graph on `raw` and compares every stage (see the module documentation).
pub(crate) fn run_stages(
    gpu: &Gpu,
    exec: &mut Executor,
    l: &Light,
    raw: &[f32],
) -> Result<Option<Stages>> {
    let Some(m) = model(&l.shadow.technique) else {
        return Ok(None);
    };
    let (ran, maps) = run_light(gpu, exec, l, raw)?;
    let n = l.shadow_map as usize;
    let perspective = matches!(l.kind, LightKind::Spot { .. });
    let (lin_ref, expected_replaced) =
        cpu::linearize::linearize(raw, perspective, l.near.into(), l.far.into());
    let mut s = Stages {
        linear: Check::new(),
        encode: Check::new(),
        filter: Check::new(),
        filter_name: "none",
        nonfinite: 0,
        replaced: ran.replaced,
        expected_replaced,
        encoded: Vec::new(),
        ran,
    };
    let linear = s.ran.texels(gpu, &linear_name(0), 0)?;
    // Orthographic depth passes through exactly; perspective is 5 roundings (case 7).
    let lin_tol = if perspective { 5.0 * U } else { 0.0 };
    for (i, (&g, &r)) in linear.data.iter().zip(&lin_ref).enumerate() {
        s.linear.compare(g, r, lin_tol * r, || {
            format!("texel ({}, {})", i % n, i / n)
        });
    }
    // The f64 pipeline starts from the GPU's linear map: each stage is judged on its own.
    let reference = (m.encode)(&linear);
    let enc_tol = add(m.encode_tol, m.store);
    let filter = l.shadow.technique.filter().unwrap_or(Filter::None);
    for map in &maps {
        // `light0.<name>[.blur/.blur_h/.blur_v/.mips]`: the encoding is the first two name parts.
        let encoded_name: String = map.split('.').take(2).collect::<Vec<_>>().join(".");
        let chunk: usize = encoded_name
            .strip_prefix("light0.csm")
            .and_then(|k| k.parse().ok())
            .unwrap_or(0);
        let first = 4 * chunk;
        let got = s.ran.texels(gpu, &encoded_name, 0)?;
        let k = got.channels.min(reference.channels - first);
        let want = channels(&reference, first, k);
        let got = channels(&got, 0, k);
        compare(&mut s.encode, &got, &want, enc_tol, &encoded_name);
        s.encoded.push((encoded_name.clone(), first, got.clone()));
        match filter {
            Filter::Blur {
                radius,
                sigma,
                kernel,
            } => {
                s.filter_name = "blur";
                let w = cpu::blur::weights(radius.into(), sigma.into(), kernel);
                let pass_tol = pass_tolerance(&m, w.len());
                let pass = |t: &Texels, axis| match m.log {
                    Some(_) => log_blur_pass(t, &w, axis),
                    None => cpu::blur::blur_pass(t, &w, axis),
                };
                let h = pass(&want, 0);
                let v = pass(&h, 1);
                let tol_h = add(add(enc_tol, pass_tol), m.store);
                let tol_v = add(add(tol_h, pass_tol), m.store);
                // The unfused passes `.blur_h`, `.blur_v`; the fused `.blur` (with `.blur_h`
                // past the one-dispatch radius), judged at the unfused chain's tolerance.
                let passes = [
                    ("blur_h", &h, tol_h),
                    ("blur_v", &v, tol_v),
                    ("blur", &v, tol_v),
                ];
                for (pass, reference, tol) in passes {
                    let name = format!("{encoded_name}.{pass}");
                    if s.ran.plan.resource(&name).is_none() {
                        continue;
                    }
                    let got = channels(&s.ran.texels(gpu, &name, 0)?, 0, k);
                    compare(&mut s.filter, &got, reference, tol, &name);
                }
            }
            Filter::Mips { .. } => {
                s.filter_name = "mips";
                let chain = cpu::mips::mip_chain(&want, m.log.is_some());
                let name = format!("{encoded_name}.mips");
                let levels = s.ran.levels(gpu, &name)?;
                let mut tol = add(enc_tol, m.store);
                for (level, (got, reference)) in levels.iter().zip(&chain).enumerate() {
                    let got = channels(got, 0, k);
                    compare(
                        &mut s.filter,
                        &got,
                        reference,
                        tol,
                        &format!("{name} level {level}"),
                    );
                    tol = add(add(tol, level_tolerance(&m)), m.store);
                }
                if levels.len() != chain.len() {
                    s.filter.problem(format!(
                        "{} mip levels, the f64 chain has {}",
                        levels.len(),
                        chain.len()
                    ));
                }
            }
            _ => {}
        }
    }
    s.nonfinite = count_nonfinite(gpu, &s.ran)?;
    Ok(Some(s))
}

/// One log-space blur pass, `m + ln Σ wᵢ exp(vᵢ − m)` with `m` the largest tap: the
/// reference for logarithms past f64's `exp` range (`cpu::blur` exponentiates directly, which
/// overflows beyond 709, e.g. ESM at c = 10⁴).
fn log_blur_pass(src: &Texels, w: &[f64], axis: u32) -> Texels {
    let r = w.len() as i64 - 1;
    let mut data = Vec::with_capacity(src.data.len());
    for y in 0..src.height as i64 {
        for x in 0..src.width as i64 {
            for c in 0..src.channels {
                let tap = |i: i64| {
                    let (sx, sy) = if axis == 0 { (x + i, y) } else { (x, y + i) };
                    (w[i.unsigned_abs() as usize], src.at(sx, sy)[c])
                };
                let m = (-r..=r).map(|i| tap(i).1).fold(f64::NEG_INFINITY, f64::max);
                let sum: f64 = (-r..=r).map(tap).map(|(wi, v)| wi * (v - m).exp()).sum();
                data.push(m + sum.ln());
            }
        }
    }
    Texels {
        data,
        ..src.clone()
    }
}

/// One blur pass of `taps` one-sided weights (2·taps − 1 taps in all).
fn pass_tolerance(m: &Model, taps: usize) -> Tol {
    let n = (2 * taps - 1) as f64;
    match m.log {
        Some(c) => ((3.0 + 2.0 * c) * 2.0 * U, 2.0 * U),
        None if m.mixed_sign => ((n + 2.0) * U, 0.0),
        None => (0.0, (n + 2.0) * U),
    }
}

/// One mip level.
fn level_tolerance(m: &Model) -> Tol {
    match m.log {
        Some(c) => (2.0 * (3.0 + 2.0 * c) * 2.0 * U, 4.0 * U),
        None if m.mixed_sign => (8.0 * U, 0.0),
        None => (0.0, 8.0 * U),
    }
}

fn compare(check: &mut Check, got: &Texels, want: &Texels, (atol, rtol): Tol, name: &str) {
    let c = got.channels;
    for (i, (&g, &r)) in got.data.iter().zip(&want.data).enumerate() {
        check.compare(g, r, atol + rtol * r.abs(), || {
            format!(
                "{name} ({}, {}) channel {}",
                (i / c) % got.width,
                (i / c) / got.width,
                i % c
            )
        });
    }
}

/// NaN/Inf texels in every level of every resource the graph wrote.
fn count_nonfinite(gpu: &Gpu, ran: &Ran) -> Result<u64> {
    let mut n = 0;
    for r in ran.plan.resources.iter().filter(|r| r.slot.is_some()) {
        for t in ran.levels(gpu, &r.resource.name)? {
            n += t.data.iter().filter(|v| !v.is_finite()).count() as u64;
        }
    }
    Ok(n)
}
