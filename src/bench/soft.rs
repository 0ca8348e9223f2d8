//! The soft techniques' shading cost against PCSS as the penumbra widens: one scene, one map,
//! one image, only the technique and the light's size changed.

use std::fmt::Write;

use super::harness::median;
use super::{GPU_WARMUP_MS, WARMUP};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;

/// The scene the soft-shadow benchmark shades: `scenes/techniques/cssm.toml` (a spot light over
/// a floating sphere and a box on a plane; its depth range is fitted for CSSM), embedded so the
/// benchmark runs from anywhere.
const SOFT_SCENE: &str = include_str!("../../scenes/techniques/cssm.toml");

/// Default light sizes of [`soft_cost`], world units (the scene's own is 0.5): the penumbra
/// widens with the size.
pub const SOFT_LIGHT_SIZES: &[f32] = &[0.25, 0.5, 1.0, 2.0];

/// The configurations compared, in row order: a name and the scene's `[light.shadow]` table
/// (the scene file's defaults apply to every other key). The first PCSS row is the yardstick.
pub const SOFT_TECHNIQUES: &[(&str, &str)] = &[
    ("hard", "technique = \"hard\""),
    (
        "pcss 16+32",
        "technique = \"pcss\"\nblocker_samples = 16\nfilter_samples = 32",
    ),
    (
        "pcss 64+64",
        "technique = \"pcss\"\nblocker_samples = 64\nfilter_samples = 64",
    ),
    ("vssm", "technique = \"vssm\""),
    ("vssm float", "technique = \"vssm\"\nsat_sums = \"float\""),
    ("msm_soft", "technique = \"msm_soft\""),
    (
        "msm_soft float",
        "technique = \"msm_soft\"\nsat_sums = \"float\"",
    ),
    ("cssm M=8", "technique = \"cssm\"\nterms = 8"),
    (
        "cssm M=8 csm_z",
        "technique = \"cssm\"\nterms = 8\nblocker_search = \"csm_z\"",
    ),
    ("smrt 7x8", "technique = \"smrt\"\nrays = 7\nsteps = 8"),
];

/// Index of the yardstick in [`SOFT_TECHNIQUES`]: PCSS with 16 blocker and 32 filter taps.
const YARDSTICK: usize = 1;

/// One technique of the soft-shadow benchmark.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftRow {
    /// Its name in [`SOFT_TECHNIQUES`].
    pub technique: String,
    /// Its shading fetches per pixel (the declared count of a pixel that takes every lookup).
    pub fetches: f64,
    /// Per light size (in the order asked for), the shading pass's median GPU time, ms.
    pub shade_ms: Vec<f64>,
    /// The prefilter's median GPU time (every pass of the light after its raster: encodings,
    /// blurs, tables, mips), ms, at the first light size (the light's size changes no
    /// prefilter pass).
    pub prefilter_ms: f64,
    /// The same, pass by pass (each pass's median, in the frame's order): where the prefilter's
    /// time goes in a frame, against the kernel benchmark's standalone chain.
    pub prefilter_passes: Vec<(String, f64)>,
    /// The whole frame's median GPU time (every timed pass), ms, at the first light size.
    pub frame_ms: f64,
    /// The same frames' median wall time from submission to completion, ms: the cross-check
    /// of the timestamps (it adds the submission's latency).
    pub wall_ms: f64,
    /// The image it was shaded at, width × height.
    pub image: (u32, u32),
    /// The light's shadow-map size, texels a side.
    pub map: u32,
}

/// Frames a configuration renders back to back in each round; the last one is timed. The first
/// frame after a change of configuration reads cold caches and, on a GPU, runs at whatever
/// clock the idle gap before it left: on an H100 at 1920×1080, PCSS 16+32's shading pass read
/// 0.64 ms as single interleaved frames, 0.23 ms as the last of three and 0.15 ms over twenty
/// consecutive frames, the ratios between techniques within 15% of the twenty's from three on.
/// Three keep the benchmark's time on a CPU driver within reason.
pub const STEADY_FRAMES: u32 = 3;

/// Whether a timed pass is part of a light's prefilter: a light's pass (`light<i>.…`) other
/// than its raster.
fn is_prefilter(pass: &str) -> bool {
    pass.starts_with("light") && !pass.ends_with(".shadow_raster")
}

/// The technique scene with `shadow` as its light's `[light.shadow]` table.
fn scene_with(shadow: &str) -> Result<Scene> {
    let start = SOFT_SCENE
        .find("[light.shadow]")
        .ok_or_else(|| Error::Invalid("the soft benchmark scene has no [light.shadow]".into()))?;
    let end = SOFT_SCENE[start..]
        .find("\n\n")
        .map_or(SOFT_SCENE.len(), |e| start + e);
    let text = format!(
        "{}[light.shadow]\n{shadow}{}",
        &SOFT_SCENE[..start],
        &SOFT_SCENE[end..]
    );
    Scene::parse(std::path::Path::new("scenes/techniques/cssm.toml"), &text)
}

/// The declared shading fetches per pixel of the scene's one light.
fn shading_fetches(scene: &Scene) -> Result<f64> {
    let block = crate::technique::shading_block(&scene.lights);
    let wgsl = crate::kernels::resolve("shade", Some(&block))?;
    let light = crate::wgsl_mirrors::LightGpu::new(&scene.lights[0]);
    crate::graph::cost::fetches::Fetches::new("shade", &wgsl, bytemuck::bytes_of(&light))?
        .count("light0_visibility")
}

/// The checks [`soft_cost`] makes of its arguments before any work: light sizes (at least one,
/// each a positive world width in a scene's `light.size` range), `repeat` ≥ 1, and an `only`
/// that names at least one configuration of [`SOFT_TECHNIQUES`]. The command line makes them
/// before `bench --lookup`'s first table, so a bad argument is refused at once rather than
/// after it.
pub fn check_soft_args(sizes: &[f32], repeat: u32, only: &[String]) -> Result<()> {
    if sizes.is_empty() || repeat == 0 {
        return Err(Error::Invalid(
            "soft benchmark needs light sizes and repeat ≥ 1".into(),
        ));
    }
    // A scene's `light.size` range, whose bound keeps products of two lengths finite in f32.
    let most = crate::scene::LENGTH_RANGE.1;
    if let Some(s) = sizes
        .iter()
        .find(|&&s| !(s.is_finite() && s > 0.0 && f64::from(s) <= most))
    {
        return Err(Error::Invalid(format!(
            "soft benchmark light size {s}: sizes are positive world widths up to {most} (a \
             scene's `light.size` range)"
        )));
    }
    super::check_only("bench --lookup --only", only)?;
    let named = |name: &str| only.iter().any(|o| name.contains(o.as_str()));
    if !only.is_empty() && !SOFT_TECHNIQUES.iter().any(|(name, _)| named(name)) {
        let names: Vec<&str> = SOFT_TECHNIQUES.iter().map(|(n, _)| *n).collect();
        return Err(Error::Invalid(format!(
            "bench --lookup --only {}: matches no soft configuration; they are: {}",
            only.join(","),
            names.join("; ")
        )));
    }
    Ok(())
}

/// The shading pass's cost of every configuration of [`SOFT_TECHNIQUES`] at each light size in
/// `sizes`: the median over `repeat` rounds (after [`WARMUP`] untimed ones, on a GPU at least [`super::GPU_WARMUP_MS`] of them) of the `shade`
/// pass. Rounds interleave the configurations (each renders `STEADY_FRAMES` consecutive
/// frames in turn, the last timed), so that a change of load on a shared machine reaches every
/// configuration alike while each timed frame follows frames of its own configuration.
///
/// `image` shades at that size instead of the scene's 200×150, and `map` renders the light's
/// shadow map at that size instead of the scene's 512². A non-empty `only` keeps the
/// configurations whose name contains one of its strings, `hard` (the floor of the table's
/// "above hard" ratios) and the yardstick.
pub fn soft_cost(
    gpu: &Gpu,
    sizes: &[f32],
    repeat: u32,
    image: Option<(u32, u32)>,
    map: Option<u32>,
    only: &[String],
) -> Result<Vec<SoftRow>> {
    check_soft_args(sizes, repeat, only)?;
    if !gpu.can_time() {
        return Err(Error::Invalid(
            "this device cannot time kernels: it lacks TIMESTAMP_QUERY or \
             TIMESTAMP_QUERY_INSIDE_ENCODERS"
                .to_string(),
        ));
    }
    super::check_map(&gpu.device, map, image)?;
    let named = |name: &str| only.iter().any(|o| name.contains(o.as_str()));
    let picked: Vec<&(&str, &str)> = SOFT_TECHNIQUES
        .iter()
        .enumerate()
        .filter(|(k, (name, _))| {
            *k == YARDSTICK || *name == "hard" || only.is_empty() || named(name)
        })
        .map(|(_, t)| t)
        .collect();
    let mut scenes = Vec::new();
    for (name, shadow) in &picked {
        let mut base = super::with_flags(scene_with(shadow)?, map, image);
        let by = format!("bench --lookup's `{name}` configuration");
        base.locations.set_by("light[0].shadow", by);
        for &size in sizes {
            let mut scene = base.clone();
            scene.lights[0].size = size;
            scenes.push(scene);
        }
    }
    let mut renderer = Renderer::new(&gpu.device);
    let mut times = vec![Vec::new(); scenes.len()];
    let mut prefilter = vec![Vec::new(); scenes.len()];
    let mut by_pass: Vec<Vec<(String, Vec<f64>)>> = vec![Vec::new(); scenes.len()];
    let mut frame_wall = vec![(Vec::new(), Vec::new()); scenes.len()];
    let opts = RenderOptions {
        repeat: STEADY_FRAMES,
        ..Default::default()
    };
    // Untimed rounds: WARMUP, and on a GPU until its clocks have risen (`timer::warm_up`).
    crate::timer::warm_up(&gpu.device, WARMUP, || {
        for scene in &scenes {
            renderer.render(&gpu.device, &gpu.queue, scene, opts)?;
        }
        Ok(())
    })?;
    for _ in 0..repeat {
        for (k, scene) in scenes.iter().enumerate() {
            let f = renderer.render(&gpu.device, &gpu.queue, scene, opts)?;
            let (passes, wall) = f
                .timings
                .last()
                .zip(f.wall_ms.last())
                .ok_or_else(|| Error::Invalid("the frame has no timed passes".into()))?;
            let shade = passes
                .iter()
                .find(|(name, _)| name == "shade")
                .map(|(_, ms)| *ms)
                .ok_or_else(|| Error::Invalid("the frame has no timed `shade` pass".into()))?;
            times[k].push(shade);
            let sum = |keep: &dyn Fn(&str) -> bool| -> f64 {
                passes
                    .iter()
                    .filter(|(name, _)| keep(name))
                    .map(|(_, ms)| ms)
                    .sum()
            };
            prefilter[k].push(sum(&is_prefilter));
            for (name, ms) in passes.iter().filter(|(name, _)| is_prefilter(name)) {
                match by_pass[k].iter_mut().find(|(n, _)| n == name) {
                    Some((_, v)) => v.push(*ms),
                    None => by_pass[k].push((name.clone(), vec![*ms])),
                }
            }
            frame_wall[k].0.push(sum(&|_| true));
            frame_wall[k].1.push(*wall);
        }
    }
    let mut rows = Vec::new();
    for (k, (name, _)) in picked.iter().enumerate() {
        let at = k * sizes.len();
        rows.push(SoftRow {
            technique: name.to_string(),
            fetches: shading_fetches(&scenes[at])?,
            shade_ms: times[at..at + sizes.len()]
                .iter_mut()
                .map(|t| median(t))
                .collect(),
            prefilter_ms: median(&mut prefilter[at]),
            prefilter_passes: by_pass[at]
                .iter_mut()
                .map(|(n, v)| (n.clone(), median(v)))
                .collect(),
            frame_ms: median(&mut frame_wall[at].0),
            wall_ms: median(&mut frame_wall[at].1),
            image: (scenes[at].width, scenes[at].height),
            map: scenes[at].lights[0].shadow_map,
        });
    }
    Ok(rows)
}

/// [`soft_cost`]'s report: one line per technique, its fetches per pixel, then per light size
/// the shading pass's time and its ratio to PCSS 16+32's at that size (on a CPU adapter only
/// the ratios mean anything), and last the prefilter's time and, as the timestamps'
/// cross-check, the frame's passes against its wall time.
pub fn format_soft_table(
    device: &str,
    cpu: bool,
    repeat: u32,
    sizes: &[f32],
    rows: &[SoftRow],
) -> String {
    let mut s = String::new();
    let ((w, h), map) = rows.first().map_or(((0, 0), 0), |r| (r.image, r.map));
    let _ = writeln!(s, "soft-shadow shading cost on {device}");
    let _ = writeln!(
        s,
        "scenes/techniques/cssm.toml ({w}×{h}, {map}² spot map), the light's size swept (wider \
         penumbrae); GPU timestamps of the shade pass, median of {repeat} round(s) after \
         {WARMUP} warm-up round(s) (on a GPU, at least {GPU_WARMUP_MS} ms), configurations interleaved, each round's frame the last of \
         {STEADY_FRAMES} consecutive ones; (×) = over PCSS 16+32 at the same size; prefilter = every \
         pass of the light after its raster; frame = all passes, wall = submission to completion \
         (first size)."
    );
    if cpu {
        let _ = writeln!(
            s,
            "NOTE: this adapter is a CPU device (software Vulkan): only the ratios mean anything."
        );
    }
    // The name column fits the longest configuration's name.
    let name = rows
        .iter()
        .map(|r| r.technique.chars().count())
        .max()
        .unwrap_or(0)
        .max("technique".len());
    let _ = write!(s, "{:<name$} {:>10}", "technique", "fetches/px");
    for size in sizes {
        let _ = write!(s, "  {:>17}", format!("size {size}"));
    }
    let _ = writeln!(
        s,
        "  {:>13}  {:>9}  {:>9}",
        "prefilter ms", "frame ms", "wall ms"
    );
    let yardstick = rows
        .iter()
        .find(|r| r.technique == SOFT_TECHNIQUES[YARDSTICK].0);
    for r in rows {
        let _ = write!(s, "{:<name$} {:>10}", r.technique, r.fetches);
        for (i, ms) in r.shade_ms.iter().enumerate() {
            let base = yardstick.and_then(|y| y.shade_ms.get(i)).copied();
            let ratio = base.map_or(f64::NAN, |b| ms / b);
            let _ = write!(s, "  {:>9.3} ({:>5.2})", ms, ratio);
        }
        let _ = writeln!(
            s,
            "  {:>13.3}  {:>9.3}  {:>9.3}",
            r.prefilter_ms, r.frame_ms, r.wall_ms
        );
    }
    s.push_str(&above_hard(name, rows));
    s.push_str(&prefilter_by_pass(rows));
    s
}

/// The prefilter of each configuration that has one, pass by pass (first light size): one line
/// each, `technique: pass ms, …`, the light's `light0.` prefix dropped.
fn prefilter_by_pass(rows: &[SoftRow]) -> String {
    let mut s = String::new();
    for r in rows.iter().filter(|r| !r.prefilter_passes.is_empty()) {
        if s.is_empty() {
            s.push_str("prefilter by pass (ms, first size):\n");
        }
        let passes: Vec<String> = r
            .prefilter_passes
            .iter()
            .map(|(n, ms)| format!("{} {ms:.3}", n.strip_prefix("light0.").unwrap_or(n)))
            .collect();
        let _ = writeln!(s, "  {}: {}", r.technique, passes.join(", "));
    }
    s
}

/// The lookups' own cost: at each light size, (technique − `hard`) / (PCSS 16+32 − `hard`),
/// the shading pass less what one fetch a pixel costs, against PCSS's taps measured the same
/// way (the measure of CSSM's cost in docs/TECHNIQUES.md). Empty without `hard` and the yardstick.
/// On an H200 `hard` itself was 0.29–0.32× PCSS, half of it a floor that a kernel storing a
/// constant colour a pixel still read (benches/RESULTS.md, 2026-11-27).
fn above_hard(name: usize, rows: &[SoftRow]) -> String {
    let find = |n: &str| rows.iter().find(|r| r.technique == n);
    let (Some(hard), Some(pcss)) = (find("hard"), find(SOFT_TECHNIQUES[YARDSTICK].0)) else {
        return String::new();
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "above hard: (technique − hard) / (pcss 16+32 − hard) at each size: the lookups' own \
         cost against PCSS's taps (n/a where PCSS did not take longer than hard)"
    );
    for r in rows.iter().filter(|r| r.technique != hard.technique) {
        let _ = write!(s, "{:<name$} {:>10}", r.technique, "");
        for (i, ms) in r.shade_ms.iter().enumerate() {
            let ratio = match (hard.shade_ms.get(i), pcss.shade_ms.get(i)) {
                (Some(h), Some(p)) if p > h => format!("({:.2})", (ms - h) / (p - h)),
                _ => "(n/a)".to_string(),
            };
            let _ = write!(s, "  {ratio:>17}");
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(technique: &str, shade_ms: &[f64]) -> SoftRow {
        SoftRow {
            technique: technique.into(),
            fetches: 1.0,
            shade_ms: shade_ms.to_vec(),
            prefilter_ms: 0.0,
            prefilter_passes: Vec::new(),
            frame_ms: 1.0,
            wall_ms: 1.0,
            image: (8, 8),
            map: 64,
        }
    }

    /// (technique − hard) / (pcss − hard) at each size, by hand: vssm 1/4 and 2/5, PCSS 1, n/a
    /// where PCSS took no longer than hard (a shading kernel replaced for a floor measurement),
    /// and no block without `hard`.
    #[test]
    fn above_hard_is_the_lookups_own_cost_against_pcss() {
        let rows = [
            row("hard", &[1.0, 2.0, 3.0]),
            row("pcss 16+32", &[5.0, 7.0, 3.0]),
            row("vssm", &[2.0, 4.0, 3.5]),
        ];
        let table = format_soft_table("test", false, 1, &[0.5, 1.0, 2.0], &rows);
        let line = |name: &str| {
            let block = table
                .split("above hard")
                .nth(1)
                .expect("an above-hard block");
            block
                .lines()
                .find(|l| l.starts_with(name))
                .map(str::to_string)
        };
        let vssm = line("vssm").expect("vssm's line");
        assert!(
            vssm.contains("(0.25)") && vssm.contains("(0.40)") && vssm.contains("(n/a)"),
            "{table}"
        );
        assert!(!table.contains("NaN"), "{table}");
        assert!(line("pcss 16+32").unwrap().contains("(1.00)"), "{table}");
        assert!(line("hard").is_none(), "{table}");
        let without = format_soft_table("test", false, 1, &[0.5, 1.0, 2.0], &rows[1..]);
        assert!(!without.contains("above hard"), "{without}");
    }

    /// The by-pass block lists each configuration with a prefilter, its passes in order with
    /// the light's prefix dropped, and is absent where none has one.
    #[test]
    fn prefilter_by_pass_lists_each_configurations_passes() {
        let mut vssm = row("vssm", &[1.0]);
        vssm.prefilter_passes = vec![
            ("light0.vsm.sat.tile_sums".into(), 0.1104),
            ("light0.vsm.sat.carries".into(), 0.034),
            ("light0.vsm.sat.0".into(), 0.17),
        ];
        let rows = [row("hard", &[1.0]), row("pcss 16+32", &[2.0]), vssm];
        let table = format_soft_table("test", false, 1, &[1.0], &rows);
        let block = table
            .split("prefilter by pass")
            .nth(1)
            .expect("a by-pass block");
        let lines: Vec<&str> = block.lines().skip(1).collect();
        assert_eq!(
            lines,
            ["  vssm: vsm.sat.tile_sums 0.110, vsm.sat.carries 0.034, vsm.sat.0 0.170"],
            "{table}"
        );
        let none = format_soft_table("test", false, 1, &[1.0], &rows[..2]);
        assert!(!none.contains("prefilter by pass"), "{none}");
    }

    /// The prefilter is every timed pass of a vssm frame but the raster, the G-buffer and the
    /// shading: the encoding and the table's three passes, read off a real frame's names.
    #[test]
    fn prefilter_is_the_light_passes_after_its_raster() {
        let gpu = Gpu::new().expect("GPU tests need an adapter (lavapipe on CI)");
        let mut scene = scene_with("technique = \"vssm\"").unwrap();
        (scene.width, scene.height, scene.lights[0].shadow_map) = (32, 24, 64);
        let frame = Renderer::new(&gpu.device)
            .render(&gpu.device, &gpu.queue, &scene, RenderOptions::default())
            .unwrap();
        let names: Vec<&str> = frame.timings[0].iter().map(|(n, _)| n.as_str()).collect();
        for pass in ["light0.shadow_raster", "gbuffer", "shade"] {
            assert!(names.contains(&pass), "{names:?}");
        }
        let prefilter: Vec<&str> = names.iter().copied().filter(|n| is_prefilter(n)).collect();
        let others: Vec<&str> = names.iter().copied().filter(|n| !is_prefilter(n)).collect();
        assert_eq!(others, ["light0.shadow_raster", "gbuffer", "shade"]);
        assert!(
            prefilter.len() >= 2 && prefilter.iter().any(|n| n.contains(".sat")),
            "{prefilter:?}"
        );
    }
}
