//! `shadowgraph evaluate`: a sweep over techniques and their accuracy knobs, each rendered with
//! GPU timestamps and measured against ground truth ([`crate::truth`]).
//!
//! **Which ground truth.** Every configuration is compared with the *area-light truth* of the
//! scene's own light (its `size`; a size of 0 makes it the light's hard shadow at the truth's
//! resolution): this is the shadow the scene should show, so it is the error of the scene as
//! seen, for soft and hard techniques alike, and it is what `pareto.svg` plots. Configurations
//! whose filter is a box over the map (PCF with the box kernel, and every prefiltered
//! technique with the box blur or the mip chain) are also compared with the *filtered hard
//! shadow* ([`crate::truth::pcf::pcf_box`] over the configuration's own rasterized linear map
//! with the same box width, at the same receivers and bias): this isolates what the
//! representation costs (light bleeding, ringing, quantization) from the difference between a
//! box filter and a penumbra. Errors are taken over the truth's relevant pixels only.
//!
//! **Times** are medians over the repeats of the renderer's GPU timestamps; a configuration's
//! total is its shadow raster, its graph kernels and its shading pass (the camera G-buffer is
//! the same for every configuration and reported apart). **Memory** is the plan's peak of live
//! textures plus the rasterized depth maps.

mod grid;
mod output;
mod svg;
mod sweep;

use sweep::storage_name;
pub use sweep::{Config, FILTERS, FilterOfWidth, TECHNIQUES, sweep};

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::cpu::Map;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::{FloatMap, Frame, RenderOptions, Renderer, plan_lights};
use crate::scene::{Filter, Scene, Technique};
use crate::technique::LightGpu;
use crate::truth::pcf::{Receiver, pcf_box};
use crate::truth::{Emitter, Truth, TruthOptions, area_light_truth};

/// What the sweep covers and how it is measured.
#[derive(Clone, Debug)]
pub struct EvaluateOptions {
    /// Technique names to keep (`None`: all of [`TECHNIQUES`]).
    pub techniques: Option<Vec<String>>,
    /// A tiny sweep (one map size, one width, one storage per technique; K = 16 at 1024²,
    /// image at most 160 wide, one repeat): seconds on a software GPU.
    pub quick: bool,
    /// Map sizes (default 512, 1024, 2048, 4096; quick: 512).
    pub sizes: Option<Vec<u32>>,
    /// Emitter samples K of the truth (default 256; quick: 16).
    pub samples: Option<u32>,
    /// Truth resolution (default: [`crate::truth::default_resolution`]; quick: 1024).
    pub truth_resolution: Option<u32>,
    /// Timed frames per configuration (the median is reported).
    pub repeat: u32,
    /// Image size to evaluate at (default: the scene's; quick: scaled to ≤ 160 wide).
    pub image: Option<(u32, u32)>,
    /// MSM moment biases: each `msm`/`msm_soft` configuration runs once per bias instead of
    /// at its storage's default (`None`: the defaults).
    pub moment_biases: Option<Vec<f32>>,
}

impl Default for EvaluateOptions {
    fn default() -> Self {
        Self {
            techniques: None,
            quick: false,
            sizes: None,
            samples: None,
            truth_resolution: None,
            repeat: 5,
            image: None,
            moment_biases: None,
        }
    }
}

/// Error statistics of one visibility image against a truth, over the relevant pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorStats {
    /// Pixels measured.
    pub pixels: usize,
    /// Mean |v − truth|.
    pub mean_abs: f64,
    /// Root mean square error.
    pub rmse: f64,
    /// 99th percentile of |v − truth|.
    pub p99: f64,
    /// Largest |v − truth|.
    pub max: f64,
    /// Share of pixels with |v − truth| > 0.05.
    pub over_005: f64,
    /// Share of pixels with |v − truth| > 0.2.
    pub over_02: f64,
}

impl ErrorStats {
    /// Statistics of `values` against `truth` where `mask` is set.
    pub fn new(values: &[f32], truth: &[f64], mask: &[bool]) -> Self {
        let mut e: Vec<f64> = values
            .iter()
            .zip(truth)
            .zip(mask)
            .filter(|(_, m)| **m)
            .map(|((&v, &t), _)| (f64::from(v) - t).abs())
            .collect();
        let n = e.len();
        if n == 0 {
            return Self::default();
        }
        e.sort_by(f64::total_cmp);
        let share = |x: f64| e.iter().filter(|&&v| v > x).count() as f64 / n as f64;
        Self {
            pixels: n,
            mean_abs: e.iter().sum::<f64>() / n as f64,
            rmse: (e.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt(),
            p99: e[((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1],
            max: e[n - 1],
            over_005: share(0.05),
            over_02: share(0.2),
        }
    }
}

/// Measurements of one configuration.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Row {
    /// [`Config::label`].
    pub label: String,
    /// Technique name.
    pub technique: String,
    /// Shadow-map side.
    pub shadow_map: u32,
    /// Storage of the representation (`f32`, `f16`, `unorm16`; empty when none).
    pub storage: String,
    /// Filter name (`blur`, `mips`, `none`; empty when none).
    pub filter: String,
    /// Box width in texels, when the configuration filters with a box.
    pub box_width: Option<f64>,
    /// Median milliseconds per timed pass, in pass order (empty without timestamps).
    pub passes: Vec<(String, f64)>,
    /// Shadow raster, ms.
    pub raster_ms: Option<f64>,
    /// Graph kernels (linearize, encode, filter), ms.
    pub kernels_ms: Option<f64>,
    /// Shading pass, ms.
    pub shade_ms: Option<f64>,
    /// Raster + kernels + shading, ms.
    pub total_ms: Option<f64>,
    /// Camera G-buffer, ms (the same work for every configuration).
    pub gbuffer_ms: Option<f64>,
    /// Peak live texture bytes of the plan plus the depth maps.
    pub memory_bytes: u64,
    /// Error against the area-light truth.
    pub soft: ErrorStats,
    /// Error against the box-PCF truth of the configuration's own map, where it applies.
    pub pcf: Option<ErrorStats>,
}

/// The whole evaluation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Report {
    /// Scene file.
    pub scene: String,
    /// Device description.
    pub device: String,
    /// Whether times come from a CPU driver (lavapipe/llvmpipe), so only ratios mean much.
    pub cpu_driver: bool,
    /// Image size evaluated.
    pub image: (u32, u32),
    /// Emitter samples K of the truth.
    pub truth_samples: usize,
    /// Truth resolution per light.
    pub truth_resolution: Vec<u32>,
    /// Relevant pixels (over all lights).
    pub relevant_pixels: usize,
    /// Configurations skipped, with the reason.
    pub skipped: Vec<(String, String)>,
    /// One row per configuration, in sweep order.
    pub rows: Vec<Row>,
}

/// Light 0's images for the grid: the truth, its mask and every configuration's visibility.
#[derive(Clone, Debug)]
pub struct Images {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Truth visibility of light 0.
    pub truth: Vec<f32>,
    /// Relevant pixels of light 0.
    pub mask: Vec<bool>,
    /// Per row of the report, light 0's rendered visibility.
    pub visibility: Vec<Vec<f32>>,
}

/// The scene as evaluated: `opts.image`, or in quick mode at most 160 pixels wide.
pub fn scene_for(path: &Path, opts: &EvaluateOptions) -> Result<Scene> {
    let mut scene = Scene::load(path)?;
    let size = match opts.image {
        Some(s) => Some(s),
        None if opts.quick && scene.width > 160 => Some((
            160,
            ((scene.height as f64 * 160.0 / scene.width as f64).round() as u32).max(1),
        )),
        None => None,
    };
    if let Some((w, h)) = size {
        if w == 0 || h == 0 {
            return Err(Error::Invalid(format!("image size {w}x{h} is empty")));
        }
        scene.width = w;
        scene.height = h;
    }
    Ok(scene)
}

/// `shadowgraph evaluate`: runs the sweep on the scene at `scene_path` and writes
/// `report.md`, `report.csv`, `report.json`, `pareto.svg`, `grid.png` and `grid.txt` to
/// `out`. Returns a short summary.
pub fn run(gpu: &Gpu, scene_path: &Path, out: &Path, opts: &EvaluateOptions) -> Result<String> {
    check_options(opts)?;
    let scene = scene_for(scene_path, opts)?;
    let configs = sweep(&scene, opts)?;
    let (report, images) = evaluate(gpu, &scene, &configs, opts)?;
    let files = output::write_all(out, &report, &images)?;
    let mut s = format!(
        "evaluated {} configuration(s) of {} at {}x{} against a K = {} area-light truth ({} relevant pixels)\n",
        report.rows.len(),
        report.scene,
        report.image.0,
        report.image.1,
        report.truth_samples,
        report.relevant_pixels
    );
    for (label, why) in &report.skipped {
        s.push_str(&format!("skipped {label}: {why}\n"));
    }
    for f in files {
        s.push_str(&format!("wrote {}\n", f.display()));
    }
    Ok(s)
}

/// The options' counts, named as the command line spells them: `--repeat` in
/// 1..=[`crate::render::MAX_REPEAT`] (`--quick` uses 1), `--truth-resolution` and `--k` at
/// least 1.
pub fn check_options(opts: &EvaluateOptions) -> Result<()> {
    let max = crate::render::MAX_REPEAT;
    if !(1..=max).contains(&opts.repeat) {
        return Err(Error::Invalid(format!(
            "--repeat {} is outside 1..={max}",
            opts.repeat
        )));
    }
    if opts.truth_resolution == Some(0) {
        return Err(Error::Invalid(
            "--truth-resolution 0: the truth's shadow maps need at least 1 texel".into(),
        ));
    }
    if opts.samples == Some(0) {
        return Err(Error::Invalid(
            "--k 0: the truth needs at least one emitter sample".into(),
        ));
    }
    Ok(())
}

/// Renders every configuration of `configs` on `scene` and measures it (see the module docs).
pub fn evaluate(
    gpu: &Gpu,
    scene: &Scene,
    configs: &[Config],
    opts: &EvaluateOptions,
) -> Result<(Report, Images)> {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut renderer = Renderer::new(device);
    let truth_opts = TruthOptions {
        emitter: Emitter::Stratified {
            k: opts.samples.unwrap_or(if opts.quick { 16 } else { 256 }),
            seed: 1,
        },
        resolution: opts
            .truth_resolution
            .or(if opts.quick { Some(1024) } else { None }),
    };
    let bar = progress(configs.len() as u64 + 1);
    bar.set_message("area-light truth");
    let truth = area_light_truth(&mut renderer, device, queue, scene, &truth_opts)?;
    bar.inc(1);
    let relevant = truth.mask.iter().filter(|&&m| m).count();
    if relevant == 0 {
        return Err(Error::Invalid(format!(
            "{}: no pixel is lit by a light (nothing to measure)",
            scene.path.display()
        )));
    }
    let truth64: Vec<f64> = truth.visibility.iter().map(|&v| f64::from(v)).collect();
    let info = gpu.adapter.get_info();
    let mut report = Report {
        scene: scene.path.display().to_string(),
        device: gpu.describe(),
        cpu_driver: info.device_type == wgpu::DeviceType::Cpu,
        image: (scene.width, scene.height),
        truth_samples: truth.samples,
        truth_resolution: truth.resolution.clone(),
        relevant_pixels: relevant,
        skipped: Vec::new(),
        rows: Vec::new(),
    };
    let mut images = Images {
        width: truth.width,
        height: truth.height,
        truth: light0(&truth.visibility, truth.lights),
        mask: light0(&truth.mask, truth.lights),
        visibility: Vec::new(),
    };
    let mut linear = std::collections::HashMap::new();
    for c in configs {
        bar.set_message(c.label.clone());
        let mut s = scene.clone();
        for l in &mut s.lights {
            l.shadow.technique = c.technique;
            l.shadow_map = c.shadow_map;
        }
        let linear = match linear.entry(c.shadow_map) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(linear_maps(&mut renderer, gpu, &s, c.shadow_map)?)
            }
        };
        match measure(
            &mut renderer,
            gpu,
            &s,
            c,
            linear,
            &truth,
            &truth64,
            opts.repeat,
        ) {
            Ok((row, frame)) => {
                images
                    .visibility
                    .push(light0(&frame.visibility, truth.lights));
                report.rows.push(row);
            }
            Err(
                e @ (Error::MissingFeature { .. } | Error::Limit { .. } | Error::SceneLimit { .. }),
            ) => {
                log::warn!("{}: skipped: {e}", c.label);
                report.skipped.push((c.label.clone(), e.to_string()));
            }
            Err(e) => return Err(e),
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok((report, images))
}

/// A progress bar on stderr; indicatif draws nothing when stderr is not a terminal.
fn progress(len: u64) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed_precise} {msg}")
    {
        bar.set_style(style);
    }
    bar
}

fn light0<T: Copy>(v: &[T], lights: usize) -> Vec<T> {
    v.iter().step_by(lights.max(1)).copied().collect()
}

/// Renders one configuration (`repeat` timed frames) and measures it.
#[expect(clippy::too_many_arguments, reason = "one measurement's inputs")]
fn measure(
    renderer: &mut Renderer,
    gpu: &Gpu,
    scene: &Scene,
    c: &Config,
    linear: &[FloatMap],
    truth: &Truth,
    truth64: &[f64],
    repeat: u32,
) -> Result<(Row, Frame)> {
    let frame = renderer.render(
        &gpu.device,
        &gpu.queue,
        scene,
        RenderOptions {
            aux: true,
            // One more frame than timed: the first also pays for first-use work (software
            // drivers compile shaders at their first dispatch), so its times are dropped.
            repeat: repeat.max(1) + 1,
            dump: false,
        },
    )?;
    if frame.visibility.len() != truth.visibility.len() {
        return Err(Error::Invalid("truth and render differ in size".into()));
    }
    let soft = ErrorStats::new(&frame.visibility, truth64, &truth.mask);
    let pcf = match c.box_width {
        Some(w) => Some(pcf_stats(scene, &frame, linear, truth, w)?),
        None => None,
    };
    let passes = median_passes(frame.timings.get(1..).unwrap_or_default());
    let sum = |f: &dyn Fn(&str) -> bool| -> Option<f64> {
        (!passes.is_empty()).then(|| passes.iter().filter(|(l, _)| f(l)).map(|p| p.1).sum())
    };
    let raster_ms = sum(&|l| l.ends_with(".shadow_raster"));
    let gbuffer_ms = sum(&|l| l == "gbuffer");
    let shade_ms = sum(&|l| l == "shade");
    let kernels_ms = sum(&|l| !l.ends_with(".shadow_raster") && l != "gbuffer" && l != "shade");
    let total_ms = match (raster_ms, kernels_ms, shade_ms) {
        (Some(a), Some(b), Some(c)) => Some(a + b + c),
        _ => None,
    };
    let plan = plan_lights(&scene.lights)?;
    let depth: u64 = scene
        .lights
        .iter()
        .map(|l| u64::from(l.shadow_map).pow(2) * 4)
        .sum();
    let (storage, filter) = match c.technique {
        Technique::Vsm { prefilter, .. }
        | Technique::Evsm { prefilter, .. }
        | Technique::Msm { prefilter, .. }
        | Technique::Csm { prefilter, .. } => (
            storage_name(prefilter.storage).to_string(),
            filter_name(prefilter.filter),
        ),
        Technique::Esm { filter, .. } => ("f32".to_string(), filter_name(filter)),
        _ => (String::new(), String::new()),
    };
    let row = Row {
        label: c.label.clone(),
        technique: c.technique.name().to_string(),
        shadow_map: c.shadow_map,
        storage,
        filter,
        box_width: c.box_width,
        passes,
        raster_ms,
        kernels_ms,
        shade_ms,
        total_ms,
        gbuffer_ms,
        memory_bytes: plan.plan.peak_live_bytes() + depth,
        soft,
        pcf,
    };
    Ok((row, frame))
}

fn filter_name(f: Filter) -> String {
    match f {
        Filter::None => "none",
        Filter::Blur { .. } => "blur",
        Filter::Mips { .. } => "mips",
        Filter::Sat { .. } => "sat",
    }
    .to_string()
}

/// Median of each pass over the frames (passes in the first frame's order).
fn median_passes(frames: &[Vec<(String, f64)>]) -> Vec<(String, f64)> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    first
        .iter()
        .enumerate()
        .map(|(i, (label, _))| {
            let mut v: Vec<f64> = frames
                .iter()
                .filter_map(|f| f.get(i).map(|x| x.1))
                .collect();
            v.sort_by(f64::total_cmp);
            (label.clone(), v[v.len() / 2])
        })
        .collect()
}

/// Each light's linear depth map at `size`: the shade map of a `hard` render (the plan's
/// output, so no later kernel reused its texture). Rasterization does not depend on the
/// technique, so this is the map every configuration of that size rasterized.
fn linear_maps(
    renderer: &mut Renderer,
    gpu: &Gpu,
    scene: &Scene,
    size: u32,
) -> Result<Vec<FloatMap>> {
    let mut s = scene.clone();
    for l in &mut s.lights {
        l.shadow.technique = Technique::Hard;
        l.shadow_map = size;
    }
    let opts = RenderOptions {
        aux: true,
        repeat: 1,
        dump: false,
    };
    Ok(renderer
        .render(&gpu.device, &gpu.queue, &s, opts)?
        .shade_maps)
}

/// Error against the box-PCF truth over each light's linear map `linear` (1 where the
/// receiver leaves the map, as the shading returns).
fn pcf_stats(
    scene: &Scene,
    frame: &Frame,
    linear: &[FloatMap],
    truth: &Truth,
    width: f64,
) -> Result<ErrorStats> {
    let lights = scene.lights.len();
    let mut reference = vec![1.0; frame.visibility.len()];
    for (li, light) in scene.lights.iter().enumerate() {
        let Some(linear) = linear.get(li) else {
            return Err(Error::Invalid(format!(
                "light {li} has no linear map to take the PCF truth over"
            )));
        };
        let map = Map {
            size: linear.width as usize,
            texels: &linear.data,
        };
        let g = LightGpu::new(light);
        for px in 0..(frame.width * frame.height) as usize {
            let i = px * lights + li;
            if !truth.mask[i] {
                continue;
            }
            let at = |d: &[f32]| {
                DVec3::new(d[4 * px].into(), d[4 * px + 1].into(), d[4 * px + 2].into())
            };
            let (p, n) = (at(&frame.position), at(&frame.normal).normalize_or_zero());
            let s = crate::cpu::light::sample(&g, p, n);
            if s.inside {
                let r = Receiver {
                    uv: s.uv,
                    depth: s.depth,
                };
                reference[i] = pcf_box(&map, &r, width, f64::from(light.shadow.bias));
            }
        }
    }
    Ok(ErrorStats::new(&frame.visibility, &reference, &truth.mask))
}

/// Output folder helper: creates `dir` and names `file` in it.
fn out_path(dir: &Path, file: &str) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|error| Error::Io {
        path: dir.to_path_buf(),
        error,
    })?;
    Ok(dir.join(file))
}
