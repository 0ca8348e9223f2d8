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

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::cpu::Map;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::prefilter::PrefilterConfig;
use crate::render::{FloatMap, Frame, RenderOptions, Renderer, plan_lights};
use crate::scene::{BlurKernel, Filter, PcfKernel, Scene, Storage, Technique};
use crate::technique::LightGpu;
use crate::truth::pcf::{Receiver, pcf_box};
use crate::truth::{Emitter, Truth, TruthOptions, area_light_truth};

/// Technique names `--techniques` accepts, in sweep order.
pub const TECHNIQUES: &[&str] = &[
    "hard", "pcf", "pcss", "vsm", "evsm2", "evsm4", "esm", "msm", "csm",
];

/// A filter of a box `width` texels wide.
pub type FilterOfWidth = fn(f32) -> Filter;

/// The filters prefiltered techniques are swept with: a name and the filter of a box `width`
/// texels wide. Adding a filter (e.g. `filter = "sat"`) is one line here.
pub const FILTERS: &[(&str, FilterOfWidth)] = &[
    ("blur", |width| Filter::Blur {
        radius: 0.5 * (width - 1.0),
        sigma: (0.25 * (width - 1.0)).max(0.5),
        kernel: BlurKernel::Box,
    }),
    ("mips", |width| Filter::Mips { width }),
];

/// One configuration of the sweep: a technique with its knobs on a map size.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Short unique label, e.g. `vsm f16 blur5 1024`.
    pub label: String,
    /// Technique and knobs (every light of the scene gets it).
    pub technique: Technique,
    /// Shadow-map side.
    pub shadow_map: u32,
    /// Width in texels of the box the technique filters with, when it has one (the PCF truth
    /// then applies).
    pub box_width: Option<f64>,
}

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

/// Configurations of the sweep for `scene` (every light gets each), filtered by
/// `opts.techniques`. Unknown technique names are an error listing the known ones.
pub fn sweep(scene: &Scene, opts: &EvaluateOptions) -> Result<Vec<Config>> {
    let wanted: Vec<String> = match &opts.techniques {
        None => TECHNIQUES.iter().map(|s| s.to_string()).collect(),
        Some(list) => {
            for t in list {
                if !TECHNIQUES.contains(&t.as_str()) {
                    return Err(Error::Invalid(format!(
                        "unknown technique `{t}` in --techniques (known: {})",
                        TECHNIQUES.join(", ")
                    )));
                }
            }
            list.clone()
        }
    };
    let quick = opts.quick;
    let sizes = opts.sizes.clone().unwrap_or_else(|| {
        if quick {
            vec![512]
        } else {
            vec![512, 1024, 2048, 4096]
        }
    });
    if sizes.is_empty() || sizes.iter().any(|&s| !(1..=65536).contains(&s)) {
        return Err(Error::Invalid(format!(
            "--sizes must be map sides in [1, 65536], got {sizes:?}"
        )));
    }
    let base = if sizes.contains(&1024) {
        1024
    } else {
        sizes[0]
    };
    let widths: &[f32] = if quick { &[5.0] } else { &[3.0, 5.0, 9.0] };
    let storages: &[Storage] = if quick {
        &[Storage::F32]
    } else {
        &[Storage::F32, Storage::F16]
    };
    let mut out = Vec::new();
    let mut push = |label: String, technique: Technique, size: u32, box_width: Option<f64>| {
        out.push(Config {
            label: format!("{label} {size}"),
            technique,
            shadow_map: size,
            box_width,
        });
    };
    let size_sweep = |t: &str| -> Vec<u32> {
        if wanted.iter().any(|w| w == t) {
            sizes.clone()
        } else {
            Vec::new()
        }
    };
    for &size in &size_sweep("hard") {
        push("hard".into(), Technique::Hard, size, None);
    }
    if wanted.iter().any(|w| w == "pcf") {
        for r in if quick { vec![2] } else { vec![1, 2, 4] } {
            let t = Technique::Pcf {
                radius: r,
                kernel: PcfKernel::Box,
            };
            let width = Some(f64::from(2 * r + 1));
            let on: Vec<u32> = if r == 2 { sizes.clone() } else { vec![base] };
            for size in on {
                push(format!("pcf box{}", 2 * r + 1), t, size, width);
            }
        }
    }
    if scene.lights.iter().all(|l| l.size > 0.0) {
        let pcss = scene
            .lights
            .iter()
            .map(|l| l.shadow.technique)
            .find(|t| matches!(t, Technique::Pcss { .. }))
            .unwrap_or(Technique::Pcss {
                blocker_samples: 16,
                filter_samples: 32,
                max_search: 0.1,
            });
        for &size in &size_sweep("pcss") {
            push("pcss".into(), pcss, size, None);
        }
    }
    for name in ["vsm", "evsm2", "evsm4", "esm", "msm", "csm"] {
        if wanted.iter().any(|w| w == name) {
            prefiltered_configs(name, quick, base, &sizes, widths, storages, &mut out)?;
        }
    }
    Ok(out)
}

/// The prefiltered technique `name` with `storage`, `filter` and (CSM) `terms`, validated
/// like a scene file (EVSM exponents clamped to the storage's limit, MSM's default bias for
/// the storage).
fn prefiltered(name: &str, storage: Storage, filter: Filter, terms: u32) -> Result<Technique> {
    let config = match name {
        "vsm" => PrefilterConfig::vsm(1),
        "evsm2" => PrefilterConfig::evsm2(1),
        "evsm4" => PrefilterConfig::evsm4(1),
        "esm" => PrefilterConfig::esm(1),
        "msm" => PrefilterConfig::msm(1),
        _ => PrefilterConfig::csm(1, terms),
    };
    let config = if name == "esm" {
        config.with_filter(filter)
    } else {
        config.with_storage(storage).with_filter(filter)
    };
    let (mut valid, _) = config.validated()?;
    if let Technique::Msm { moment_bias, .. } = &mut valid.technique {
        *moment_bias = crate::scene::default_moment_bias(storage);
    }
    Ok(valid.technique)
}

fn storage_name(s: Storage) -> &'static str {
    match s {
        Storage::F32 => "f32",
        Storage::F16 => "f16",
        Storage::Unorm16 => "unorm16",
    }
}

fn prefiltered_configs(
    name: &str,
    quick: bool,
    base: u32,
    sizes: &[u32],
    widths: &[f32],
    storages: &[Storage],
    out: &mut Vec<Config>,
) -> Result<()> {
    let mut push = |label: String, t: Technique, size: u32, width: f32| {
        out.push(Config {
            label: format!("{label} {size}"),
            technique: t,
            shadow_map: size,
            box_width: Some(f64::from(width)),
        });
    };
    let mid = widths[widths.len() / 2];
    // CSM: the knobs are swept at M = 8 (4 when quick); the other M with the first filter.
    let (default_m, other_m): (u32, &[u32]) = match (name, quick) {
        ("csm", true) => (4, &[]),
        ("csm", false) => (8, &[2, 4, 16]),
        _ => (0, &[]),
    };
    let prefix = |m: u32| {
        if m > 0 {
            format!("{name} M{m}")
        } else {
            name.to_string()
        }
    };
    let mut storages = storages.to_vec();
    if name == "esm" {
        storages = vec![Storage::F32];
    } else if name == "msm" && !quick {
        storages.push(Storage::Unorm16);
    }
    for &storage in &storages {
        for (fname, filter) in FILTERS {
            // Widths are swept for f32; other storages at the middle width.
            let ws: &[f32] = if storage == Storage::F32 {
                widths
            } else {
                &[mid]
            };
            for &w in ws {
                let t = prefiltered(name, storage, filter(w), default_m)?;
                let label = format!("{} {} {fname}{w}", prefix(default_m), storage_name(storage));
                push(label, t, base, w);
            }
        }
    }
    let (fname, filter) = FILTERS[0];
    for &m in other_m {
        for &storage in &storages {
            let t = prefiltered(name, storage, filter(mid), m)?;
            let label = format!("{} {} {fname}{mid}", prefix(m), storage_name(storage));
            push(label, t, base, mid);
        }
    }
    // Map sizes for the default configuration.
    let t = prefiltered(name, Storage::F32, filter(mid), default_m)?;
    for &size in sizes.iter().filter(|&&s| s != base) {
        push(
            format!("{} f32 {fname}{mid}", prefix(default_m)),
            t,
            size,
            mid,
        );
    }
    Ok(())
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
            Err(e @ (Error::MissingFeature { .. } | Error::Limit { .. })) => {
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
