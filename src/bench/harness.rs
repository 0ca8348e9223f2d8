//! The timing harness of the benchmarks: plans a graph, fills its imports, records it under a
//! [`GpuTimer`] and keeps the median over timed runs.

use std::collections::HashMap;
use std::time::Instant;

use super::WARMUP;
use crate::error::{Error, Result};
use crate::gpu::{scoped, submit_and_wait, write_texture};
use crate::graph::{self, Graph, Plan};
use crate::{exec::Executor, timer::GpuTimer};

/// A timer for `spans` spans, or the error saying this device cannot time.
pub(super) fn timer(device: &wgpu::Device, queue: &wgpu::Queue, spans: u32) -> Result<GpuTimer> {
    GpuTimer::new(device, queue, spans.max(1)).ok_or_else(|| {
        Error::Invalid(
            "this device cannot time kernels: it lacks TIMESTAMP_QUERY or \
             TIMESTAMP_QUERY_INSIDE_ENCODERS"
                .to_string(),
        )
    })
}

/// Effective bandwidth, GB/s (10⁹ bytes per second).
pub(super) fn gb_per_s(bytes: f64, ms: f64) -> f64 {
    bytes / (ms * 1e6)
}

/// A run's time by the GPU's timestamps and by the wall clock, ms (medians over runs).
#[derive(Clone, Debug, PartialEq)]
pub struct Timed {
    /// The summed span times.
    pub ms: f64,
    /// Submission to completion: the cross-check of `ms` (on a CPU device the two agree within
    /// the submission's fraction of a millisecond; on a GPU the submission can dominate).
    pub wall_ms: f64,
    /// The shortest timed run's spans as a share of the median wall time: the timer's check
    /// run by run (a median can hide a fault that hits some runs). On a CPU device a true timer
    /// reads near 1; a boundary stamped late shortens a run's spans and reads far below. Over
    /// the median wall time, not the run's own: a run whose wait alone was stretched (the
    /// thread descheduled on busy cores) keeps true spans and must not read as a fault.
    pub least_share: f64,
    /// Each span's median on its own (a graph's dispatches by node name, in order): where
    /// the summed time goes (`bench --passes`).
    pub passes: Vec<(String, f64)>,
}

/// Medians of the summed span times and of the wall times of `repeat` runs of `record` (after
/// [`WARMUP`] runs, and on a GPU at least [`crate::timer::GPU_WARMUP_MS`] of them), ms.
pub(super) fn median_time(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    timer: &mut GpuTimer,
    repeat: u32,
    mut record: impl FnMut(&mut wgpu::CommandEncoder, &mut GpuTimer) -> Result<()>,
) -> Result<Timed> {
    // One run: its spans and its wall time, submission to completion.
    let mut run = || -> Result<(Vec<(String, f64)>, f64)> {
        timer.reset();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("shadowgraph.bench"),
        });
        record(&mut enc, timer)?;
        timer.resolve(&mut enc);
        let submitted = Instant::now();
        submit_and_wait(device, queue, enc, "bench")?;
        let wall_ms = submitted.elapsed().as_secs_f64() * 1e3;
        Ok((timer.read(device)?, wall_ms))
    };
    crate::timer::warm_up(device, WARMUP, || run().map(|_| ()))?;
    let mut times = Vec::with_capacity(repeat as usize);
    let mut walls = Vec::with_capacity(repeat as usize);
    let mut passes: Vec<(String, Vec<f64>)> = Vec::new();
    for _ in 0..repeat {
        let (spans, wall_ms) = run()?;
        if spans.is_empty() {
            return Err(Error::Gpu {
                stage: "bench".into(),
                message: "no pass was timed".into(),
            });
        }
        times.push(spans.iter().map(|(_, ms)| ms).sum());
        walls.push(wall_ms);
        if passes.is_empty() {
            passes = spans.iter().map(|(l, _)| (l.clone(), Vec::new())).collect();
        }
        for ((_, v), (_, ms)) in passes.iter_mut().zip(&spans) {
            v.push(*ms);
        }
    }
    let shortest = times.iter().copied().fold(f64::INFINITY, f64::min);
    let wall_ms = median(&mut walls);
    Ok(Timed {
        ms: median(&mut times),
        wall_ms,
        least_share: shortest / wall_ms,
        passes: passes
            .into_iter()
            .map(|(l, mut v)| (l, median(&mut v)))
            .collect(),
    })
}

/// Median (mean of the middle two for an even count); NaN for no values.
pub(super) fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// Plans `graph` for `outputs`, fills its imports as `inputs` says and returns the plan and
/// the median times of running it.
pub(super) fn time_graph(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    executor: &mut Executor,
    graph: &Graph,
    outputs: &[String],
    repeat: u32,
    inputs: Inputs,
) -> Result<(Plan, Timed)> {
    let outputs: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let plan = graph::plan(graph, &outputs)?;
    executor.prepare(device, &plan)?;
    let imports = fill_imports(device, queue, &plan, inputs)?;
    let mut timer = timer(device, queue, plan.steps.len() as u32)?;
    let ms = median_time(device, queue, &mut timer, repeat, |enc, t| {
        executor.record(device, enc, &plan, &imports, Some(t))?;
        Ok(())
    })?;
    Ok((plan, ms))
}

/// What the benchmark's imported textures hold (`shadowgraph bench --inputs`).
///
/// A GPU may store a texture compressed, so that a kernel's time would depend on the values it
/// moves and not only on their bytes; timing a kernel and its texture copy on each kind of
/// input shows whether it does. On an H200 the three read the same within 0.5% (kernels) and
/// 8% (copies); the 2-4× that random imports had seemed to cost there was the GPU's clock
/// (`benches/RESULTS.md`, 2026-11-27).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Inputs {
    /// Independent pseudo-random values (incompressible): floats in (0, 1], halves in
    /// [⅛, 1), any u32.
    #[default]
    Random,
    /// A smooth field: every channel a sum of slow sines over the texel's position, as a
    /// shadow map's depths are between edges (floats in (0.1, 0.9), halves and u32 fixed
    /// point of the same).
    Smooth,
    /// Every texel the same (½, or its half or fixed-point form).
    Constant,
}

impl Inputs {
    /// The names `--inputs` takes.
    pub const NAMES: [&'static str; 3] = ["random", "smooth", "constant"];

    /// The mode named `name` (one of [`Inputs::NAMES`]).
    pub fn parse(name: &str) -> Result<Inputs> {
        match name {
            "random" => Ok(Inputs::Random),
            "smooth" => Ok(Inputs::Smooth),
            "constant" => Ok(Inputs::Constant),
            _ => Err(Error::Invalid(format!(
                "bench --inputs `{name}`: expected one of {}",
                Inputs::NAMES.join(", ")
            ))),
        }
    }

    /// The name [`Inputs::parse`] takes.
    pub fn name(self) -> &'static str {
        match self {
            Inputs::Random => "random",
            Inputs::Smooth => "smooth",
            Inputs::Constant => "constant",
        }
    }

    /// `width × height × channels` values in [0, 1), channels interleaved, for the smooth and
    /// constant fields (`None` for random inputs, which each format draws in its own range).
    fn field(self, width: u32, height: u32, channels: usize) -> Option<Vec<f32>> {
        let tau = std::f32::consts::TAU;
        match self {
            Inputs::Random => None,
            Inputs::Constant => Some(vec![0.5; (width * height) as usize * channels]),
            Inputs::Smooth => {
                // Separable: a sine over x plus a cosine over y, tabled once per channel.
                let wave = |len: u32, period: f32, phase: f32, f: fn(f32) -> f32| -> Vec<f32> {
                    (0..len)
                        .map(|i| 0.2 * f(tau * (i as f32 / period + phase)))
                        .collect()
                };
                let xs: Vec<Vec<f32>> = (0..channels)
                    .map(|c| wave(width, 97.0, c as f32 / 7.0, f32::sin))
                    .collect();
                let ys: Vec<Vec<f32>> = (0..channels)
                    .map(|c| wave(height, 61.0, c as f32 / 5.0, f32::cos))
                    .collect();
                let mut values = Vec::with_capacity((width * height) as usize * channels);
                for y in 0..height as usize {
                    for x in 0..width as usize {
                        values.extend(xs.iter().zip(&ys).map(|(xs, ys)| 0.5 + xs[x] + ys[y]));
                    }
                }
                Some(values)
            }
        }
    }
}

/// A texture for every import of `plan`, filled with random values: floats in (0, 1], halves
/// in [⅛, 1), any u32; a depth texture (which the CPU cannot write) is cleared to ½.
pub fn random_imports(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
) -> Result<HashMap<String, wgpu::Texture>> {
    fill_imports(device, queue, plan, Inputs::Random)
}

/// A texture for every import of `plan`, filled as `inputs` says; a depth texture (which the
/// CPU cannot write) is cleared to ½ whatever `inputs` is.
pub fn fill_imports(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
    inputs: Inputs,
) -> Result<HashMap<String, wgpu::Texture>> {
    let mut imports = HashMap::new();
    for (i, r) in plan
        .resources
        .iter()
        .filter(|r| r.slot.is_none())
        .enumerate()
    {
        let name = &r.resource.name;
        let format = r.resource.format;
        let texels = r.width as usize * r.height as usize;
        let seed = 0x5EED + i as u64;
        let channels = (graph::texel_bytes(format) as usize / 4).max(1);
        let field = |channels: usize| inputs.field(r.width, r.height, channels);
        let data: Option<Vec<u8>> = match format {
            wgpu::TextureFormat::R32Float
            | wgpu::TextureFormat::Rg32Float
            | wgpu::TextureFormat::Rgba32Float => {
                let values =
                    field(channels).unwrap_or_else(|| random_depths(texels * channels, seed));
                Some(bytemuck::cast_slice(&values).to_vec())
            }
            wgpu::TextureFormat::Rgba16Float => {
                let halves: Vec<u16> = match field(4) {
                    // Halves in [⅛, 1) ordered as the values are.
                    Some(values) => values
                        .iter()
                        .map(|&v| 0x3000 + (v * 0x0C00 as f32) as u16)
                        .collect(),
                    None => random_bits(texels * 4, seed)
                        .into_iter()
                        .map(|b| 0x3000 + (b as u16 % 0x0C00))
                        .collect(),
                };
                Some(bytemuck::cast_slice(&halves).to_vec())
            }
            wgpu::TextureFormat::R32Uint
            | wgpu::TextureFormat::Rg32Uint
            | wgpu::TextureFormat::Rgba32Uint => {
                let words: Vec<u32> = match field(channels) {
                    // 24-bit fixed point, as the summed-area tables' inputs are.
                    Some(values) => values
                        .iter()
                        .map(|&v| (v * (1u32 << 24) as f32) as u32)
                        .collect(),
                    None => random_bits(texels * channels, seed)
                        .into_iter()
                        .map(|b| b as u32)
                        .collect(),
                };
                Some(bytemuck::cast_slice(&words).to_vec())
            }
            wgpu::TextureFormat::Depth32Float => None,
            other => {
                return Err(Error::Invalid(format!(
                    "benchmark import `{name}` is {other:?}, which the harness cannot fill"
                )));
            }
        };
        let mut usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC;
        if data.is_none() {
            usage |= wgpu::TextureUsages::RENDER_ATTACHMENT;
        }
        let texture = scoped(
            device,
            || {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("shadowgraph.bench.import"),
                    size: wgpu::Extent3d {
                        width: r.width,
                        height: r.height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
            },
            |m| Error::Gpu {
                stage: format!("creating benchmark import `{name}`"),
                message: m,
            },
        )?;
        match data {
            Some(bytes) => write_texture(queue, &texture, &bytes),
            None => clear_depth(device, queue, &texture)?,
        }
        imports.insert(name.clone(), texture);
    }
    Ok(imports)
}

/// Clears a depth texture to ½ (its values do not change what the kernels reading it cost).
fn clear_depth(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Result<()> {
    let view = texture.create_view(&Default::default());
    let mut enc = device.create_command_encoder(&Default::default());
    drop(enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("shadowgraph.bench.clear"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.5),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    }));
    submit_and_wait(device, queue, enc, "bench clear")
}

/// `count` pseudo-random 64-bit words (SplitMix64; deterministic per `seed`).
fn random_bits(count: usize, seed: u64) -> Vec<u64> {
    let mut state = seed;
    (0..count)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        })
        .collect()
}

/// `count` pseudo-random values in (0, 1] (deterministic per `seed`).
pub(super) fn random_depths(count: usize, seed: u64) -> Vec<f32> {
    random_bits(count, seed)
        .into_iter()
        .map(|z| ((z >> 40) as f32 + 1.0) / (1u32 << 24) as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timer::GPU_WARMUP_MS;

    #[test]
    fn median_of_odd_even_and_unsorted() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn warm_up_is_warmup_runs_and_on_a_gpu_a_least_time() {
        let keep_warming =
            |runs, elapsed, gpu| crate::timer::keep_warming(runs, WARMUP, elapsed, gpu);
        // A CPU device: WARMUP runs, however short.
        assert!(keep_warming(WARMUP - 1, 1e9, false));
        assert!(!keep_warming(WARMUP, 0.0, false));
        // A GPU: WARMUP runs and GPU_WARMUP_MS, whichever is more, capped at MAX_WARMUP.
        assert!(keep_warming(WARMUP - 1, 1e9, true));
        assert!(keep_warming(WARMUP, GPU_WARMUP_MS - 1.0, true));
        assert!(keep_warming(50, 0.0, true));
        assert!(!keep_warming(WARMUP, GPU_WARMUP_MS, true));
        assert!(!keep_warming(crate::timer::MAX_WARMUP_RUNS, 0.0, true));
    }

    /// The smooth field is the sum of two slow waves (checked in f64 from its formula), moves
    /// little from texel to texel and spans most of (0.1, 0.9); the constant field is ½.
    #[test]
    fn smooth_and_constant_fields_are_what_they_say() {
        let (w, h, channels) = (300u32, 200u32, 3usize);
        let field = Inputs::Smooth.field(w, h, channels).unwrap();
        assert_eq!(field.len(), (w * h) as usize * channels);
        let tau = std::f64::consts::TAU;
        let mut worst = 0.0f64;
        for y in 0..h as usize {
            for x in 0..w as usize {
                for c in 0..channels {
                    let want = 0.5
                        + 0.2 * (tau * (x as f64 / 97.0 + c as f64 / 7.0)).sin()
                        + 0.2 * (tau * (y as f64 / 61.0 + c as f64 / 5.0)).cos();
                    let got = field[(y * w as usize + x) * channels + c] as f64;
                    // f32 sines of arguments up to 2π·3.1: a few ulps of 1.
                    worst = worst.max((got - want).abs());
                    assert!(got > 0.1 - 1e-6 && got < 0.9 + 1e-6, "{got}");
                }
            }
        }
        assert!(worst < 1e-5, "{worst}");
        // Neighbours along x differ by at most 0.2 · 2π / 97 (the wave's steepest slope).
        let step = field
            .chunks(channels)
            .zip(field.chunks(channels).skip(1))
            .enumerate()
            .filter(|(i, _)| (i + 1) % w as usize != 0)
            .flat_map(|(_, (a, b))| a.iter().zip(b).map(|(a, b)| (a - b).abs()))
            .fold(0.0f32, f32::max);
        assert!(
            step > 0.005 && step < 0.2 * std::f32::consts::TAU / 97.0 + 1e-4,
            "{step}"
        );
        let (lo, hi) = field
            .iter()
            .fold((1.0f32, 0.0f32), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(lo < 0.2 && hi > 0.8, "{lo} {hi}");
        let constant = Inputs::Constant.field(7, 5, 2).unwrap();
        assert!(constant.len() == 70 && constant.iter().all(|&v| v == 0.5));
        assert!(Inputs::Random.field(7, 5, 2).is_none());
    }

    #[test]
    fn inputs_parse_their_names_and_name_the_choices_otherwise() {
        for name in Inputs::NAMES {
            assert_eq!(Inputs::parse(name).unwrap().name(), name);
        }
        let e = Inputs::parse("noise").unwrap_err().to_string();
        assert!(
            e.contains("`noise`") && e.contains("random, smooth, constant"),
            "{e}"
        );
    }

    #[test]
    fn random_depths_are_in_zero_one_and_never_zero() {
        let d = random_depths(100_000, 7);
        assert!(d.iter().all(|&v| v > 0.0 && v <= 1.0));
        assert!(d.iter().any(|&v| v < 0.01) && d.iter().any(|&v| v > 0.99));
    }
}
