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
//! box filter and a penumbra. Errors are taken over the truth's relevant pixels only, as a
//! whole and split into the truth's penumbra, umbra and lit regions ([`Regions`]: where
//! techniques differ, light leaking, false shadow).
//!
//! **Perceptual error**: FLIP of the shaded image against the *truth-shaded* image (the same
//! shading with the truth's visibility), over the whole image (the `flip` module).
//!
//! **Pareto fronts** ([`front`]) of total time against each [`Metric`]: the mean error, the
//! penumbra's mean error and FLIP.
//!
//! **Times** come from the renderer's GPU timestamps under the time protocol
//! ([`protocol`]): after every configuration's error is measured, the configurations are timed
//! interleaved, round-robin over the repeats, with the camera G-buffer (the same work in
//! every configuration) as the clock check, and a configuration whose check is more than 10%
//! off the run's median measured again. A configuration's total is its shadow raster, its
//! graph kernels and its shading pass (the G-buffer is reported apart), median over its frames
//! with the quartiles and range ([`Spread`]). **Memory** is the plan's peak of live
//! textures plus the rasterized depth maps.

pub mod agreement;
mod crops;
pub mod crossover;
mod crossover_run;
mod crossover_svg;
mod flip;
mod grid;
mod html;
mod marks;
mod measure;
mod options;
mod output;
mod points;
pub mod protocol;
mod stats;
pub mod summary;
mod svg;
mod sweep;
pub mod temporal;
mod timing;
pub mod verdict;

pub use flip::{Shader, flip_map, flip_stats, to_unorm8};
pub use options::{EvaluateOptions, GPU_IMAGE, check_options, check_sides, scene_for};
pub use output::{
    WALL_TOLERANCE, csv, markdown, protocol_text, untrusted_times, wall_check, wall_ratios,
};
pub use protocol::{Protocol, Spread};
pub use stats::{
    EDGE_BAND, ErrorStats, PENUMBRA_HIGH, PENUMBRA_LOW, Region, Regions, laplacian_rms,
};
pub use svg::{Metric, PALETTE, colour as colour_of, front, pareto, pareto_front};
use sweep::storage_name;
pub use sweep::{Config, FILTERS, FilterOfWidth, sweep};

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::Renderer;
use crate::scene::Scene;
use crate::truth::{Emitter, TruthOptions, area_light_truth};

/// Measurements of one configuration.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Measurement {
    /// [`Config::label`].
    pub label: String,
    /// Technique name.
    pub technique: String,
    /// Its family ([`verdict::Family::name`]): the plots' marker shape.
    #[serde(default)]
    pub family: String,
    /// Shadow-map side.
    pub shadow_map: u32,
    /// Storage of the representation (`f32`, `f16`, `unorm16`; empty when none).
    pub storage: String,
    /// Filter name (`blur`, `mips`, `none`; empty when none).
    pub filter: String,
    /// Box width in texels, when the configuration filters with a box.
    pub box_width: Option<f64>,
    /// Median milliseconds per timed pass over the kept frames, in pass order (empty without
    /// timestamps).
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
    /// A frame's wall time from submission to completion (every pass, the G-buffer
    /// included), median over the timed frames, ms: what the timestamps are checked against.
    #[serde(default)]
    pub wall_ms: Option<f64>,
    /// The total's spread over the kept frames (median, quartiles, range), ms.
    #[serde(default)]
    pub total_spread: Option<Spread>,
    /// Times the configuration was measured again because its clock check was off.
    #[serde(default)]
    pub retries: u32,
    /// Whether its clock check is still more than 10% off the run's after the retries: its
    /// times ran at another clock.
    #[serde(default)]
    pub clock_off: bool,
    /// Its G-buffer's median over the run's median G-buffer (1: the same clock).
    #[serde(default)]
    pub check_ratio: Option<f64>,
    /// Peak live texture bytes of the plan plus the depth maps.
    pub memory_bytes: u64,
    /// What `shadowgraph plan` says light 0's map costs.
    #[serde(default)]
    pub cost: PlanCost,
    /// Error against the area-light truth.
    pub soft: ErrorStats,
    /// The same over the truth's penumbra (see [`Regions`]).
    pub penumbra: ErrorStats,
    /// The penumbra's high-frequency error: RMS of the discrete Laplacian of (visibility −
    /// truth) over the penumbra ([`laplacian_rms`]).
    #[serde(default)]
    pub penumbra_hf: f64,
    /// The same over the truth's umbra: light where there should be none.
    pub umbra: ErrorStats,
    /// The same over the truth's lit pixels: shadow where there should be none.
    pub lit: ErrorStats,
    /// FLIP of the shaded image against the truth-shaded image, over every pixel (`mean_abs`
    /// is FLIP's mean; see the `flip` module).
    pub flip: ErrorStats,
    /// Error against the box-PCF truth of the configuration's own map, where it applies.
    pub pcf: Option<ErrorStats>,
    /// The flicker it adds over the scene's animation, which the truth does not have
    /// ([`temporal::temporal_error`]); `None` for a scene without an `[animation]`.
    #[serde(default)]
    pub temporal: Option<temporal::TemporalError>,
}

/// What `shadowgraph plan` computes of a configuration's first drawn light (its cost model,
/// `docs/COST.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanCost {
    /// Bytes read and written per texel of the map by the graph's kernels.
    pub bytes_per_texel: f64,
    /// Dispatches of the graph's kernels.
    pub dispatches: u32,
    /// Texture fetches per pixel of the visibility function in the shading kernel.
    pub fetches_per_pixel: f64,
}

/// The whole evaluation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Report {
    /// Scene file.
    pub scene: String,
    /// Device description (name, backend, type, driver).
    pub device: String,
    /// The source's commit (`git rev-parse` where the binary was built, `unknown` otherwise).
    #[serde(default)]
    pub commit: String,
    /// Date of the run (UTC), `YYYY-MM-DD`.
    #[serde(default)]
    pub date: String,
    /// Timed frames per configuration (rounds of the time protocol).
    #[serde(default)]
    pub repeats: u32,
    /// The run's median G-buffer time, ms: the clock check's reference.
    #[serde(default)]
    pub check_median_ms: Option<f64>,
    /// Lights of the scene (the operating point's).
    #[serde(default)]
    pub lights: usize,
    /// How often the lights' maps are redrawn, per light as the scene file writes it (`1`,
    /// `k`, `"static"`).
    #[serde(default)]
    pub updates: Vec<String>,
    /// The verdict's time budget per light as given (`--budget`), ms.
    #[serde(default)]
    pub budget_ms: Option<f64>,
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
    /// Of those, pixels in the truth's penumbra, umbra and lit regions ([`Regions`]).
    pub region_pixels: [usize; 3],
    /// Configurations skipped, with the reason.
    pub skipped: Vec<(String, String)>,
    /// One row per configuration, in sweep order.
    pub rows: Vec<Measurement>,
    /// Each front's technique against PCSS as the image grows ([`crossover`]; `None` in a
    /// further operating point's report, whose first report has it).
    #[serde(default)]
    pub crossover: Option<crossover::Crossover>,
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
    /// Light 0's region per pixel.
    pub regions: Vec<Region>,
    /// The image shaded with the truth's visibility (RGB8, every light).
    pub truth_shaded: Vec<u8>,
    /// Per row, the image shaded with its visibility (RGB8), by the same shading.
    pub shaded: Vec<Vec<u8>>,
}

/// Records in `scene`'s locations that every light's `key` (`shadow_map`, `shadow`) was set
/// by `by`, so that a limit or memory error names the sweep's choice rather than the file's
/// line.
fn set_lights_by(scene: &mut Scene, key: &str, by: &str) {
    for i in 0..scene.lights.len() {
        scene.locations.set_by(format!("light[{i}].{key}"), by);
    }
}

/// `shadowgraph evaluate`: runs the sweep on the scene at `scene_path` and writes
/// `report.md`, `report.csv`, `report.json`, `pareto.svg`, `grid.png` and `grid.txt` to
/// `out`. Returns a short summary.
pub fn run(gpu: &Gpu, scene_path: &Path, out: &Path, opts: &EvaluateOptions) -> Result<String> {
    check_options(opts)?;
    let mut opts = opts.clone();
    if opts.image.is_none() && !opts.quick && crate::timer::is_gpu(&gpu.device) {
        opts.image = Some(GPU_IMAGE);
        opts.image_default = true;
    }
    let opts = &opts;
    let scene = scene_for(scene_path, opts)?;
    check_sides(gpu.device.limits().max_texture_dimension_2d, &scene, opts)?;
    let configs = sweep(&scene, opts)?;
    output::check_dir(out)?;
    let (mut report, images, mut kept) = evaluate_kept(gpu, &scene, &configs, opts)?;
    let others = points::more(gpu, &mut kept, &report, opts)?;
    report.crossover = Some(crossover_run::measure(gpu, &mut kept, &report, opts)?);
    let mut files = output::write_all(out, &report, &images, &others)?;
    for (dir, r) in &others {
        files.extend(output::write_all(&out.join(dir), r, &images, &[])?);
    }
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
    for (label, q) in output::untrusted_times(&report) {
        s.push_str(&format!(
            "times not trusted: {label}'s passes sum to {q:.2}x its wall time (rerun on an idle machine)\n"
        ));
    }
    match &report.crossover {
        Some(c) if c.note.is_none() => {
            s.push_str(&crossover_run::check_line(c));
            s.push('\n');
        }
        Some(c) => s.push_str(&format!(
            "no crossover: {}\n",
            c.note.as_deref().unwrap_or_default()
        )),
        None => {}
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
    evaluate_kept(gpu, scene, configs, opts).map(|(r, i, _)| (r, i))
}

/// What [`evaluate_kept`] keeps to time the configurations again: its renderer, the scene and
/// every measured configuration's lights (row order).
pub(crate) struct Kept {
    renderer: Renderer,
    scene: Scene,
    variants: Vec<timing::Variant>,
}

/// [`evaluate`], keeping what timing the rows again needs.
fn evaluate_kept(
    gpu: &Gpu,
    scene: &Scene,
    configs: &[Config],
    opts: &EvaluateOptions,
) -> Result<(Report, Images, Kept)> {
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
    let bar = progress(configs.len() as u64 * (1 + u64::from(opts.repeat)) + 1);
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
    let reference = measure::Reference::new(scene, truth);
    // An animated scene's truth of every frame, for the temporal error.
    let truths = if scene.frames() > 1 {
        bar.set_message("area-light truth of every animation frame");
        temporal::animation_truths(&mut renderer, device, queue, scene, &truth_opts)?
    } else {
        Vec::new()
    };
    let info = gpu.adapter.get_info();
    let t = &reference.truth;
    let mut report = Report {
        scene: scene.path.display().to_string(),
        device: gpu.describe(),
        commit: timing::commit(),
        date: timing::today(),
        repeats: opts.repeat,
        check_median_ms: None,
        lights: scene.lights.len(),
        updates: (0..scene.lights.len())
            .map(|i| opts.update.unwrap_or(scene.update_rate(i)).name())
            .collect(),
        budget_ms: opts.budget_ms,
        cpu_driver: info.device_type == wgpu::DeviceType::Cpu,
        image: (scene.width, scene.height),
        truth_samples: t.samples,
        truth_resolution: t.resolution.clone(),
        relevant_pixels: relevant,
        region_pixels: reference.region_pixels(),
        skipped: Vec::new(),
        rows: Vec::new(),
        crossover: None,
    };
    let mut images = Images {
        width: t.width,
        height: t.height,
        truth: light0(&t.visibility, t.lights),
        mask: light0(&t.mask, t.lights),
        visibility: Vec::new(),
        regions: light0(&reference.regions.region, t.lights),
        truth_shaded: Vec::new(),
        shaded: Vec::new(),
    };
    let mut linear = std::collections::HashMap::new();
    // The scene of every measured configuration, timed after all are measured.
    let mut variants = Vec::new();
    for c in configs {
        bar.set_message(c.label.clone());
        let mut s = scene.clone();
        if let Some(u) = opts.update {
            s.updates = vec![u; s.lights.len()];
        }
        for l in &mut s.lights {
            l.shadow.technique = c.technique;
            l.shadow_map = c.shadow_map;
            // A technique that refuses cascades (`smrt`) runs on the light's one map.
            if crate::technique::params::cascade_support(&c.technique).is_err() {
                l.shadow.cascades = crate::model::Cascades::SINGLE;
            }
        }
        // (`linear_maps` below renders this scene's maps too: its errors name the same.)
        let by = format!("evaluate's configuration `{}`", c.label);
        set_lights_by(&mut s, "shadow", &by);
        let size_by = match opts.sizes {
            Some(_) => format!("evaluate --sizes (configuration `{}`)", c.label),
            None => by,
        };
        set_lights_by(&mut s, "shadow_map", &size_by);
        let linear = match linear.entry(c.shadow_map) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(measure::linear_maps(&mut renderer, gpu, &s, c.shadow_map)?)
            }
        };
        match measure::measure(&mut renderer, gpu, &s, c, linear, &reference) {
            Ok(mut m) => {
                if !truths.is_empty() {
                    let v = temporal::animation_visibility(&mut renderer, device, queue, &s)?;
                    m.row.temporal = Some(temporal::animation_temporal_error(&truths, &v)?);
                }
                variants.push(timing::Variant::of(&s));
                let lights = reference.truth.lights;
                images.visibility.push(light0(&m.frame.visibility, lights));
                if images.truth_shaded.is_empty() {
                    images.truth_shaded = m.truth_shaded;
                }
                images.shaded.push(m.shaded);
                report.rows.push(m.row);
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
    bar.set_message("timing (interleaved)");
    let protocol = Protocol::new(opts.repeat);
    let run = timing::time_variants(&mut renderer, gpu, scene, &variants, &protocol, &bar)?;
    apply_times(&mut report, &run);
    bar.finish_and_clear();
    let kept = Kept {
        renderer,
        scene: scene.clone(),
        variants,
    };
    Ok((report, images, kept))
}

/// Fills the times of `report`'s rows from the time protocol's `run` (row `i` from
/// configuration `i`): per pass and part the median over the kept frames, the total's spread,
/// the clock check's ratio, retries and flag, and the run's check median.
pub fn apply_times(report: &mut Report, run: &protocol::Run) {
    for (row, t) in report.rows.iter_mut().zip(&run.timed) {
        timing::fill(row, t, run.check_median);
    }
    report.check_median_ms = run.check_median;
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

/// Output folder helper: creates `dir` and names `file` in it.
fn out_path(dir: &Path, file: &str) -> Result<PathBuf> {
    crate::io::make_dir(dir)?;
    Ok(dir.join(file))
}
