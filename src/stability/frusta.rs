//! Case 7: very deep (near/far = 10⁻⁴) and very shallow (near/far = 0.999) light frusta,
//! perspective (spot) and orthographic (directional): the linear depth `linearize` computes
//! from the depth buffer against the f64 linearization of the *same* f32 depth values, in
//! linear-depth units, next to the smallest depth difference techniques resolve (the bias).
//!
//! Depth buffers: the f32 depth values of random linear depths and of the frustum's ends,
//! uniformly random f32 depths, the 64 largest f32 values below 1 (where a deep perspective
//! frustum puts most of its range), and a scene rasterized by the renderer (a plane and a
//! sphere inside the frustum). Bound: the kernel evaluates `n·D / (f(1 − D) + n·D)`, five f32
//! roundings at most (`1 − D` is exact for D ≥ ½), so `5u·d`; orthographic depth is exact.
//! Besides, the depth buffer's own resolution: the linear-depth step between the two largest
//! f32 depth values, which no linearization can refine, must stay below the bias.

use std::path::Path;

use super::StabilityRow;
use super::check::{Check, Rng, U};
use super::harness::{light, run_light};
use crate::cpu::{self, linearize::linearize_texel};
use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::{
    model::{LightKind, PcfKernel, Technique},
    scene::Scene,
};
use crate::{
    technique::{depth_name, linear_name},
    wgsl_mirrors::LightGpu,
};

const MAP: u32 = 64;
const BIAS: f32 = 0.002;

/// `(near, far)` of the two frusta.
const FRUSTA: [(f32, f32, &str); 2] = [(0.01, 100.0, "1e-4"), (9.99, 10.0, "0.999")];

/// Depth-buffer values for `l` (see the module documentation), `MAP²` of them.
fn depth_values(l: &crate::model::Light, rng: &mut Rng) -> Vec<f32> {
    let g = LightGpu::new(l);
    let n = (MAP * MAP) as usize;
    let mut v: Vec<f32> = [0.0, 1.0, 1e-7, 1.0 - 1e-7]
        .iter()
        .map(|&d| cpu::light::linear_to_ndc(&g, d) as f32)
        .collect();
    let mut top = 1.0f32;
    for _ in 0..64 {
        top = f32::from_bits(top.to_bits() - 1);
        v.push(top);
    }
    while v.len() < n / 2 {
        v.push(cpu::light::linear_to_ndc(&g, rng.unit()) as f32);
    }
    while v.len() < n {
        v.push(rng.unit() as f32);
    }
    v
}

/// GPU linear depth against the f64 linearization of the same values; returns the largest
/// |Δ| in linear-depth units.
fn compare(
    check: &mut Check,
    raw: &[f32],
    gpu: &[f64],
    l: &crate::model::Light,
    what: &str,
) -> f64 {
    let mut largest = 0.0f64;
    let perspective = matches!(l.kind, LightKind::Spot { .. });
    let bound = if perspective { 5.0 * U } else { 0.0 };
    for (i, (&d, &g)) in raw.iter().zip(gpu).enumerate() {
        let Some(reference) = linearize_texel(d, perspective, l.near.into(), l.far.into()) else {
            check.problem(format!("{what}: non-finite depth {d}"));
            continue;
        };
        largest = largest.max((g - reference).abs());
        check.compare(g, reference, bound * reference + 1e-30, || {
            format!("{what} texel {i}, depth buffer {d:e}")
        });
    }
    largest
}

/// A scene with one light of `kind` (near, far) over a plane and a sphere placed inside the
/// frustum, rendered with every resource kept: its depth buffer and linear map.
fn rasterized(
    gpu: &Gpu,
    kind: &str,
    near: f32,
    far: f32,
) -> Result<(Vec<f32>, Vec<f64>, crate::model::Light)> {
    // The light looks down from `h`; the plane sits at distance `mid` inside [near, far].
    let mid = near + 0.5 * (far - near);
    let size = if kind == "spot" { mid } else { 4.0 };
    let shape = if kind == "spot" {
        "fov_degrees = 60.0"
    } else {
        "extent = 5.0"
    };
    let text = format!(
        "[output]\nwidth = 16\nheight = 16\n\n[camera]\nposition = [0.0, 3.0, 6.0]\n\
         target = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n\n[[light]]\nkind = \"{kind}\"\n\
         {shape}\nposition = [0.0, {mid}, 0.001]\ntarget = [0.0, 0.0, 0.0]\nnear = {near}\n\
         far = {far}\nshadow_map = {MAP}\n\n[light.shadow]\ntechnique = \"pcf\"\n\n\
         [[object]]\nshape = \"plane\"\nsize = {size}\n\n[[object]]\nshape = \"sphere\"\n\
         radius = {r}\ntranslate = [0.0, {r}, 0.0]\n",
        r = 0.25 * (far - near).min(size),
    );
    let scene = Scene::parse(Path::new("stability_frustum.toml"), &text)?;
    let frame = Renderer::new(&gpu.device).render(
        &gpu.device,
        &gpu.queue,
        &scene,
        RenderOptions {
            aux: false,
            repeat: 1,
            dump: true,
        },
    )?;
    let find = |name: &str| {
        frame
            .resources
            .iter()
            .find(|r| r.levels[0].resource == name)
            .map(|r| r.levels[0].data.clone())
            .ok_or_else(|| Error::Invalid(format!("the frame has no `{name}`")))
    };
    let depth = find(&depth_name(0))?;
    let linear = find(&linear_name(0))?
        .iter()
        .map(|&v| f64::from(v))
        .collect();
    Ok((depth, linear, scene.lights[0].clone()))
}

/// Case 7.
pub(crate) fn frusta_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let mut rng = Rng::new(0xF7);
    let mut exec = Executor::new();
    let mut rows = Vec::new();
    let pcf = Technique::Pcf {
        radius: 1,
        kernel: PcfKernel::Box,
    };
    for (kind, label) in [
        (super::harness::SPOT, "spot"),
        (super::harness::DIRECTIONAL, "directional"),
    ] {
        for (near, far, ratio) in FRUSTA {
            let mut l = light(kind, pcf, MAP, BIAS);
            (l.near, l.far) = (near, far);
            let raw = depth_values(&l, &mut rng);
            let (ran, maps) = run_light(gpu, &mut exec, &l, &raw)?;
            let gpu_linear = ran.texels(gpu, &maps[0], 0)?.data;
            let mut check = Check::new();
            let a = compare(&mut check, &raw, &gpu_linear, &l, "random");
            let (depth, linear, scene_light) = rasterized(gpu, label, near, far)?;
            let b = compare(&mut check, &depth, &linear, &scene_light, "rasterized");
            let name = format!("{label} near/far {ratio}");
            let mut row = check.row(
                7,
                "linear depth vs f64 of the same buffer",
                &name,
                "r32float",
            );
            row.note = format!(
                "largest |Δ| {:.1e} = {:.1e} × bias; {}",
                a.max(b),
                a.max(b) / f64::from(BIAS),
                row.note
            );
            rows.push(row);
            // One f32 depth step at the top of the buffer, in linear depth (f64).
            let perspective = label == "spot";
            let lin = |d: f32| linearize_texel(d, perspective, near.into(), far.into());
            let below = f32::from_bits(1.0f32.to_bits() - 1);
            let step = match (lin(1.0), lin(below)) {
                (Some(a), Some(b)) => a - b,
                _ => f64::NAN,
            };
            let mut quantum = Check::new();
            quantum.compare(step, 0.0, f64::from(BIAS), || "depth 1 − 2⁻²⁴ to 1".into());
            let mut row = quantum.row(
                7,
                "depth-buffer step at the far plane vs bias (f64)",
                &name,
                "depth32float",
            );
            row.note = format!(
                "one f32 step of the depth buffer = {:.1e} × bias",
                step / f64::from(BIAS)
            );
            rows.push(row);
        }
    }
    Ok(rows)
}
