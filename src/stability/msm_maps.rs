//! An MSM light's maps as the shading kernel reads them, run through the scene's graph on the
//! GPU and read back, beside the exact moments they stand for: what cases 3 and 8 and the
//! moment-bias sweep compare. The moment bias α lives in `LightGpu` only (the maps do not
//! depend on it), so one run serves every α.

use glam::Vec3;

use super::harness::{run_light, sample};
use crate::cpu::light::LightSample;
use crate::cpu::sat::Integral;
use crate::cpu::{self, Texels};
use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::gpu::{Gpu, read_texture};
use crate::model::{Filter, Light, Technique};
use crate::render::{MapData, Renderer, visibility_at};
use crate::{
    technique::{linear_name, sat_coding},
    wgsl_mirrors::{LightGpu, MSM_QUANTIZED},
};

/// What the shading reads.
enum Stored {
    /// `msm`: the filtered moment map (every level), as f32 texels.
    Levels(Vec<Texels>),
    /// `msm_soft`: the summed-area table's words (a fixed-point table's u32 bit patterns as
    /// f32) in its format, and the per-texel values it sums, decoded.
    Table {
        words: Vec<f32>,
        format: wgpu::TextureFormat,
        decoded: Integral,
    },
}

/// The exact (f64) data moments the stored maps approximate.
enum Exact {
    /// The f64 moments of the GPU's linear map, blurred in f64 (`msm`).
    Levels(Vec<Texels>),
    /// The integral image of the f64 moments of the GPU's linear map (`msm_soft`).
    Integral(Integral),
}

/// One MSM or soft-MSM light's read-back maps and exact moments.
pub(crate) struct MsmMaps {
    light: Light,
    stored: Stored,
    exact: Exact,
}

/// `technique` with its moment bias set to `alpha`.
fn with_alpha(technique: Technique, alpha: f32) -> Technique {
    let alpha = [("moment_bias", crate::model::ParamValue::Float(alpha))];
    crate::technique::with_values(&technique, &alpha).unwrap_or(technique)
}

impl MsmMaps {
    /// Runs `light`'s graph (an `msm` light filtered by a blur or nothing, or an `msm_soft`
    /// light) on the orthographic depth buffer `raw` and reads back what the shading reads.
    pub(crate) fn new(gpu: &Gpu, exec: &mut Executor, light: &Light, raw: &[f32]) -> Result<Self> {
        let (ran, maps) = run_light(gpu, exec, light, raw)?;
        let linear = ran.texels(gpu, &linear_name(0), 0)?;
        let raw_moments = cpu::msm::msm(&linear, false);
        let t = light.shadow.technique;
        let (stored, exact) = match (t.name(), t.prefilter()) {
            ("msm", Some(prefilter)) => {
                let exact = match prefilter.filter {
                    Filter::Blur {
                        radius,
                        sigma,
                        kernel,
                    } => cpu::blur::blur(&raw_moments, f64::from(radius), f64::from(sigma), kernel),
                    Filter::None => raw_moments,
                    other => {
                        return Err(Error::Invalid(format!(
                            "MsmMaps reads blurred or unfiltered moments, not {other:?}"
                        )));
                    }
                };
                (
                    Stored::Levels(ran.levels(gpu, &maps[0])?),
                    Exact::Levels(vec![exact]),
                )
            }
            ("msm_soft", _) => {
                let coding = sat_coding(light)?
                    .ok_or_else(|| Error::Invalid("soft MSM without a table".into()))?;
                let texture = &ran.outputs.textures[&maps[0]];
                let bytes = read_texture(&gpu.device, &gpu.queue, texture, 0)?;
                let words: Vec<u32> = bytemuck::cast_slice(&bytes).to_vec();
                let n = linear.width;
                let decoded = crate::sat::decode_table(&words, n, linear.height, &coding, 4);
                let decoded = Texels::from_f32(n, linear.height, 4, &decoded);
                (
                    Stored::Table {
                        words: words.into_iter().map(f32::from_bits).collect(),
                        format: texture.format(),
                        decoded: Integral::new(&decoded),
                    },
                    Exact::Integral(Integral::new(&raw_moments)),
                )
            }
            _ => {
                return Err(Error::Invalid(
                    "MsmMaps runs msm and msm_soft lights".into(),
                ));
            }
        };
        Ok(Self {
            light: light.clone(),
            stored,
            exact,
        })
    }

    /// The light at moment bias `alpha`.
    pub(crate) fn light(&self, alpha: f32) -> Light {
        let mut l = self.light.clone();
        l.shadow.technique = with_alpha(l.shadow.technique, alpha);
        l
    }

    /// The shading kernel's visibility at `points` with moment bias `alpha`.
    pub(crate) fn gpu(
        &self,
        gpu: &Gpu,
        renderer: &mut Renderer,
        alpha: f32,
        points: &[(Vec3, Vec3)],
    ) -> Result<Vec<f32>> {
        let l = self.light(alpha);
        let size = l.shadow_map;
        let data: Vec<f32>;
        let map = match &self.stored {
            Stored::Levels(levels) => {
                data = levels
                    .iter()
                    .flat_map(|t| t.data.iter().map(|&x| x as f32))
                    .collect();
                MapData {
                    size,
                    format: wgpu::TextureFormat::Rgba32Float,
                    mips: levels.len() as u32,
                    data: &data,
                }
            }
            Stored::Table { words, format, .. } => MapData::new(size, *format, words),
        };
        visibility_at(
            renderer,
            &gpu.device,
            &gpu.queue,
            std::slice::from_ref(&l),
            &[map],
            points,
        )
    }

    /// The light sample of a receiver exactly as the GPU gets it.
    pub(crate) fn sample(&self, point: (Vec3, Vec3)) -> LightSample {
        sample(&self.light, point)
    }

    /// The f64 reference's visibility at `s` on the stored (read-back) maps, with bias
    /// `alpha`: what the tests compare the GPU with.
    pub(crate) fn stored(&self, alpha: f32, s: &LightSample) -> f64 {
        let lg = LightGpu::new(&self.light(alpha));
        if !s.inside {
            return 1.0;
        }
        match &self.stored {
            Stored::Levels(levels) => cpu::vis_msm::vis_msm(levels, &lg, s),
            Stored::Table { decoded, .. } => cpu::vis_msm_soft::vis_msm_soft(decoded, &lg, s),
        }
    }

    /// The visibility at `s` with bias `alpha` in exact arithmetic on the exact moments of the
    /// GPU's linear map (no storage rounding, no quantization).
    pub(crate) fn exact(&self, alpha: f32, s: &LightSample) -> f64 {
        let mut lg = LightGpu::new(&self.light(alpha));
        if !s.inside {
            return 1.0;
        }
        lg.msm_flags &= !MSM_QUANTIZED;
        match &self.exact {
            Exact::Levels(levels) => cpu::vis_msm::vis_msm(levels, &lg, s),
            Exact::Integral(integral) => cpu::vis_msm_soft::vis_msm_soft(integral, &lg, s),
        }
    }
}

/// The depth behind a lone flat occluder at `z` where MSM's exact shadow intensity with bias
/// `alpha` first reaches `level`: the width of the region behind contact that the bias lights
/// (bisection on the f64 reference; `None` when it is not reached before depth 1).
pub(crate) fn leak_depth(z: f64, alpha: f64, level: f64) -> Option<f64> {
    let data = [z, z * z, z * z * z, z * z * z * z];
    let b = cpu::vis_msm::bias(data, alpha, true);
    let at = |t: f64| cpu::vis_msm::intensity(&b, z + t, false);
    let (mut lo, mut hi) = (0.0, 1.0 - z);
    if at(hi).is_nan() || at(hi) < level {
        return None;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if at(mid) >= level {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}
