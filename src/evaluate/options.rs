//! What `evaluate` is asked for: its options, their checks against the command line's bounds
//! and the device, and the scene they make.

use std::path::Path;

use crate::error::{Error, Result};
use crate::scene::Scene;

/// What the sweep covers and how it is measured.
#[derive(Clone, Debug)]
pub struct EvaluateOptions {
    /// Technique names to keep (`None`: every registered technique, `technique::names`).
    pub techniques: Option<Vec<String>>,
    /// A tiny sweep (one map size, one width, one storage per technique; K = 16 at 1024²,
    /// image at most 160 wide; the command line's default `--repeat` is then 3): seconds on a
    /// software GPU.
    pub quick: bool,
    /// Map sizes (default 512, 1024, 2048, 4096; quick: 512).
    pub sizes: Option<Vec<u32>>,
    /// Emitter samples K of the truth (default 256; quick: 16).
    pub samples: Option<u32>,
    /// Truth resolution (default: [`crate::truth::default_resolution`]; quick: 1024).
    pub truth_resolution: Option<u32>,
    /// Timed frames per configuration: rounds of the interleaved time protocol (the median
    /// and spread are reported).
    pub repeat: u32,
    /// Image size to evaluate at (default: [`GPU_IMAGE`] on a GPU, the scene's own on a CPU
    /// driver, set by [`run`](super::run); quick: scaled to ≤ 160 wide).
    pub image: Option<(u32, u32)>,
    /// MSM moment biases: each `msm`/`msm_soft` configuration runs once per bias instead of
    /// at its storage's default (`None`: the defaults).
    pub moment_biases: Option<Vec<f32>>,
    /// The time budget per light of the report's verdict, ms (`None`: 1 ms on a GPU, the
    /// median configuration's on a CPU driver; [`verdict::budget`](super::verdict::budget)).
    pub budget_ms: Option<f64>,
    /// Whether `image` is [`run`](super::run)'s default rather than the user's (errors then say so).
    pub image_default: bool,
    /// How often every light's map is redrawn (`--update`; `None`: each light's own `update`).
    pub update: Option<crate::scene::UpdateRate>,
    /// Further operating points for [`run`](super::run): the same configurations timed again with every
    /// light at each of these rates, each report in `DIR/update-<rate>/` (`--update a,b,…`
    /// past its first; `--quick` without `--update`: static).
    pub more_updates: Vec<crate::scene::UpdateRate>,
    /// The crossover's image sizes (`--crossover-sizes`): all but the last are fitted, the
    /// last checks the fit (`None`: the defaults of
    /// [`crossover_run::sizes`](super::crossover_run::sizes)).
    pub crossover_sizes: Option<Vec<(u32, u32)>>,
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
            budget_ms: None,
            image_default: false,
            update: None,
            more_updates: Vec::new(),
            crossover_sizes: None,
        }
    }
}

/// The image `run` evaluates at on a GPU unless told otherwise: where games render. A CPU
/// driver keeps the scene's own size (the bundled scenes' are at most 480×360), which it
/// renders in seconds rather than minutes.
pub const GPU_IMAGE: (u32, u32) = (1920, 1080);

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
        let by = match opts.image {
            Some(GPU_IMAGE) if opts.image_default => {
                format!("evaluate's image {w}x{h} (the default on a GPU)")
            }
            Some(_) => format!("evaluate --image {w}x{h}"),
            None => format!("evaluate --quick, {w}x{h}"),
        };
        scene.locations.set_by("output.width", by.clone());
        scene.locations.set_by("output.height", by);
    }
    Ok(scene)
}

/// The options' counts, named as the command line spells them: `--repeat` in
/// 1..=[`crate::render::MAX_REPEAT`], `--truth-resolution` and `--k` at
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
    let most = crate::truth::MAX_EMITTER_SAMPLES;
    if let Some(k) = opts.samples.filter(|&k| k as usize > most) {
        return Err(Error::Invalid(format!(
            "--k {k}: the truth takes at most {most} emitter samples (a shadow map each)"
        )));
    }
    check_crossover_sizes(opts.crossover_sizes.as_deref())
}

/// `--crossover-sizes`: at least three sizes, none empty, and the ones fitted (all but the
/// last) of at least two pixel counts.
fn check_crossover_sizes(sizes: Option<&[(u32, u32)]>) -> Result<()> {
    let Some(sizes) = sizes else {
        return Ok(());
    };
    if let Some((w, h)) = sizes.iter().find(|(w, h)| *w == 0 || *h == 0) {
        return Err(Error::Invalid(format!(
            "--crossover-sizes: {w}x{h} is empty"
        )));
    }
    if sizes.len() < 3 {
        return Err(Error::Invalid(format!(
            "--crossover-sizes: give at least three sizes (two or more to fit, the last to check the fit), got {}",
            sizes.len()
        )));
    }
    let mut fitted: Vec<u64> = sizes[..sizes.len() - 1]
        .iter()
        .map(|&(w, h)| u64::from(w) * u64::from(h))
        .collect();
    fitted.sort_unstable();
    fitted.dedup();
    if fitted.len() < 2 {
        return Err(Error::Invalid(
            "--crossover-sizes: the sizes fitted (all but the last) need at least two different pixel counts".into(),
        ));
    }
    Ok(())
}

/// The texture sides the options ask for against the device's largest, `max`, each named by
/// its flag: the image (`--image`) and every light's map at every `--sizes` entry (a point
/// light's atlas is three faces wide). Past the device, the scene's own check would name the
/// scene file's key and line, which the user did not write.
pub fn check_sides(max: u32, scene: &Scene, opts: &EvaluateOptions) -> Result<()> {
    let image = [
        (
            "evaluate --image (width)".to_string(),
            opts.image.map(|(w, _)| w),
        ),
        (
            "evaluate --image (height)".into(),
            opts.image.map(|(_, h)| h),
        ),
    ];
    let crossover = opts.crossover_sizes.iter().flatten().flat_map(|&(w, h)| {
        [
            (
                format!("evaluate --crossover-sizes {w}x{h} (width)"),
                Some(w),
            ),
            (
                format!("evaluate --crossover-sizes {w}x{h} (height)"),
                Some(h),
            ),
        ]
    });
    let maps = opts.sizes.iter().flatten().flat_map(|&size| {
        scene.lights.iter().enumerate().map(move |(i, l)| {
            let mut l = l.clone();
            l.shadow_map = size;
            let (w, h) = l.map_dims();
            let what = if w == size {
                format!("evaluate --sizes {size} (light[{i}]'s map side)")
            } else {
                format!("evaluate --sizes {size} (light[{i}]'s point-light atlas of three faces: its width)")
            };
            (what, Some(w.max(h)))
        })
    });
    crate::limits::flag_sides(max, image.into_iter().chain(crossover).chain(maps))
}
