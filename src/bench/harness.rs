//! The timing harness of the benchmarks: plans a graph, fills its imports, records it under a
//! [`GpuTimer`] and keeps the median over timed runs.

use std::collections::HashMap;
use std::time::Instant;

use super::WARMUP;
use crate::error::{Error, Result};
use crate::exec::{Executor, GpuTimer};
use crate::gpu::{scoped, submit_and_wait, write_texture};
use crate::graph::{self, Graph, Plan};

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
#[derive(Clone, Copy, Debug, PartialEq)]
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
}

/// Medians of the summed span times and of the wall times of `repeat` runs of `record` (after
/// [`WARMUP`] runs), ms.
pub(super) fn median_time(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    timer: &mut GpuTimer,
    repeat: u32,
    mut record: impl FnMut(&mut wgpu::CommandEncoder, &mut GpuTimer) -> Result<()>,
) -> Result<Timed> {
    let mut times = Vec::with_capacity(repeat as usize);
    let mut walls = Vec::with_capacity(repeat as usize);
    for run in 0..WARMUP + repeat {
        timer.reset();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("shadowgraph.bench"),
        });
        record(&mut enc, timer)?;
        timer.resolve(&mut enc);
        let submitted = Instant::now();
        submit_and_wait(device, queue, enc, "bench")?;
        let wall_ms = submitted.elapsed().as_secs_f64() * 1e3;
        let spans = timer.read(device)?;
        if spans.is_empty() {
            return Err(Error::Gpu {
                stage: "bench".into(),
                message: "no pass was timed".into(),
            });
        }
        if run >= WARMUP {
            times.push(spans.iter().map(|(_, ms)| ms).sum());
            walls.push(wall_ms);
        }
    }
    let shortest = times.iter().copied().fold(f64::INFINITY, f64::min);
    let wall_ms = median(&mut walls);
    Ok(Timed {
        ms: median(&mut times),
        wall_ms,
        least_share: shortest / wall_ms,
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

/// Plans `graph` for `outputs`, fills its imports and returns the plan and the median times of
/// running it.
pub(super) fn time_graph(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    executor: &mut Executor,
    graph: &Graph,
    outputs: &[String],
    repeat: u32,
) -> Result<(Plan, Timed)> {
    let outputs: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let plan = graph::plan(graph, &outputs)?;
    executor.prepare(device, &plan)?;
    let imports = random_imports(device, queue, &plan)?;
    let mut timer = timer(device, queue, plan.steps.len() as u32)?;
    let ms = median_time(device, queue, &mut timer, repeat, |enc, t| {
        executor.record(device, enc, &plan, &imports, Some(t))?;
        Ok(())
    })?;
    Ok((plan, ms))
}

/// A texture for every import of `plan`, filled with random values: floats in (0, 1], halves
/// in [⅛, 1), any u32; a depth texture (which the CPU cannot write) is cleared to ½.
pub fn random_imports(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
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
        let data: Option<Vec<u8>> = match format {
            wgpu::TextureFormat::R32Float
            | wgpu::TextureFormat::Rg32Float
            | wgpu::TextureFormat::Rgba32Float => {
                let channels = graph::texel_bytes(format) as usize / 4;
                Some(bytemuck::cast_slice(&random_depths(texels * channels, seed)).to_vec())
            }
            wgpu::TextureFormat::Rgba16Float => {
                let halves: Vec<u16> = random_bits(texels * 4, seed)
                    .into_iter()
                    .map(|b| 0x3000 + (b as u16 % 0x0C00))
                    .collect();
                Some(bytemuck::cast_slice(&halves).to_vec())
            }
            wgpu::TextureFormat::R32Uint
            | wgpu::TextureFormat::Rg32Uint
            | wgpu::TextureFormat::Rgba32Uint => {
                let channels = graph::texel_bytes(format) as usize / 4;
                let words: Vec<u32> = random_bits(texels * channels, seed)
                    .into_iter()
                    .map(|b| b as u32)
                    .collect();
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

    #[test]
    fn median_of_odd_even_and_unsorted() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn random_depths_are_in_zero_one_and_never_zero() {
        let d = random_depths(100_000, 7);
        assert!(d.iter().all(|&v| v > 0.0 && v <= 1.0));
        assert!(d.iter().any(|&v| v < 0.01) && d.iter().any(|&v| v > 0.99));
    }
}
