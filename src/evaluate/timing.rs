//! The timing phase of `evaluate`: every measured configuration timed under the
//! [`protocol`](super::protocol) on the GPU, its rows' times filled from the kept frames, and
//! the run's facts (commit, date) for the report's header.

use super::Measurement;
use super::protocol::{self, Protocol, Run, Sample, Spread, Timed};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::{
    model::Light,
    scene::{Scene, UpdateRate},
};

/// The pass that is the same work in every configuration: the clock check.
pub const CHECK_PASS: &str = "gbuffer";

/// Untimed frames rendered before each timed one in a visit: the first frame after a change
/// of configuration pays for what the change makes (a new map size's targets, bind groups,
/// memory touched for the first time).
pub const SETTLE_FRAMES: u32 = 1;

/// Frames a visit times for `scene`: the longest period of its lights' update rates (`update =
/// k`: k frames, one of which redraws the map), else one (a light redrawn every frame, or a
/// static light, whose timed frame reuses the map the settling frame drew).
pub fn frames_per_visit(scene: &Scene) -> u32 {
    (0..scene.lights.len())
        .map(|i| match scene.update_rate(i) {
            UpdateRate::Every(k) => k.max(1),
            UpdateRate::EveryFrame | UpdateRate::Static => 1,
        })
        .max()
        .unwrap_or(1)
}

/// The mean of `frames`' passes per frame: a pass recorded in only some frames (a cached
/// light's raster and prefilter) counts 0 in the others. Passes in the order they first
/// appear.
pub fn per_frame(frames: &[Vec<(String, f64)>]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for f in frames {
        for (label, ms) in f {
            match out.iter_mut().find(|(l, _)| l == label) {
                Some(p) => p.1 += ms,
                None => out.push((label.clone(), *ms)),
            }
        }
    }
    let n = frames.len().max(1) as f64;
    out.iter_mut().for_each(|p| p.1 /= n);
    out
}

/// What sets one configuration's scene apart from the evaluated scene: its lights (technique,
/// map size, cascades) and their update rates. The timing swaps them into one scene instead of
/// keeping a copy of the scene (its meshes) per configuration.
#[derive(Clone, Debug)]
pub struct Variant {
    /// The lights, as the configuration was measured with them.
    pub lights: Vec<Light>,
    /// Their update rates.
    pub updates: Vec<UpdateRate>,
}

impl Variant {
    /// The variant of `scene`.
    pub fn of(scene: &Scene) -> Self {
        Self {
            lights: scene.lights.clone(),
            updates: scene.updates.clone(),
        }
    }
}

/// Times the configurations `variants` of `base` under `protocol`: on a GPU, untimed frames first
/// until its clocks have risen, then the interleaved rounds, each visit [`SETTLE_FRAMES`]
/// untimed frames and [`frames_per_visit`] timed ones, whose mean per frame is the sample
/// (so a light redrawn every k frames is charged a k-th of its redraw).
pub fn time_variants(
    renderer: &mut Renderer,
    gpu: &Gpu,
    base: &Scene,
    variants: &[Variant],
    protocol: &Protocol,
    bar: &indicatif::ProgressBar,
) -> Result<Run> {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut scene = base.clone();
    let set = |scene: &mut Scene, v: &Variant| {
        scene.lights.clone_from(&v.lights);
        scene.updates.clone_from(&v.updates);
    };
    if let Some(first) = variants.first() {
        set(&mut scene, first);
        renderer.warm_up(device, queue, &scene)?;
    }
    protocol::run(protocol, variants.len(), CHECK_PASS, |c| {
        bar.inc(1);
        set(&mut scene, &variants[c]);
        let timed = frames_per_visit(&scene);
        let opts = RenderOptions {
            aux: false,
            repeat: SETTLE_FRAMES + timed,
            dump: false,
        };
        let frame = renderer.render(device, queue, &scene, opts)?;
        let first = SETTLE_FRAMES as usize;
        let walls = frame.wall_ms.get(first..).unwrap_or_default();
        Ok(Sample {
            passes: per_frame(frame.timings.get(first..).unwrap_or_default()),
            wall_ms: walls.iter().sum::<f64>() / walls.len().max(1) as f64,
        })
    })
}

/// Whether a pass is a depth raster pass: each light's map and, for the second-depth
/// techniques, its peel pass.
fn is_raster(label: &str) -> bool {
    label.ends_with(".shadow_raster") || label.ends_with(".shadow_peel")
}

/// Fills `row`'s times from its configuration's `timed` frames: per pass the median, the
/// parts (raster, kernels, shading) and total as medians of each frame's sums, the total's
/// spread, the check pass, the wall time, the retries and the flag.
pub fn fill(row: &mut Measurement, timed: &Timed, run_check: Option<f64>) {
    let frames = &timed.samples;
    let sum = |s: &Sample, f: &dyn Fn(&str) -> bool| -> f64 {
        s.passes.iter().filter(|(l, _)| f(l)).map(|p| p.1).sum()
    };
    let timed_frames: Vec<&Sample> = frames.iter().filter(|s| !s.passes.is_empty()).collect();
    let part =
        |f: &dyn Fn(&str) -> bool| -> Vec<f64> { timed_frames.iter().map(|s| sum(s, f)).collect() };
    let kernels = |l: &str| !is_raster(l) && l != CHECK_PASS && l != "shade";
    let raster = part(&is_raster);
    let kern = part(&kernels);
    let shade = part(&|l| l == "shade");
    let total: Vec<f64> = (0..timed_frames.len())
        .map(|i| raster[i] + kern[i] + shade[i])
        .collect();
    row.passes = median_passes(&timed_frames);
    row.raster_ms = protocol::median(&raster);
    row.kernels_ms = protocol::median(&kern);
    row.shade_ms = protocol::median(&shade);
    row.total_ms = protocol::median(&total);
    row.total_spread = Spread::of(&total);
    row.gbuffer_ms = protocol::median(&part(&|l| l == CHECK_PASS));
    let walls: Vec<f64> = frames.iter().map(|s| s.wall_ms).collect();
    row.wall_ms = protocol::median(&walls).filter(|w| *w > 0.0);
    row.retries = timed.retries;
    row.clock_off = timed.off;
    row.check_ratio = timed.check_ms.zip(run_check).map(|(c, m)| c / m);
}

/// Median of each pass over the frames, in the first frame's pass order.
fn median_passes(frames: &[&Sample]) -> Vec<(String, f64)> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    first
        .passes
        .iter()
        .enumerate()
        .filter_map(|(i, (label, _))| {
            let v: Vec<f64> = frames
                .iter()
                .filter_map(|f| f.passes.get(i).map(|x| x.1))
                .collect();
            Some((label.clone(), protocol::median(&v)?))
        })
        .collect()
}

/// The commit the binary's source tree is at (`git rev-parse --short=12 HEAD` in the folder
/// it was built from, `-dirty` when what the binary is built from has changes: the reports a
/// run writes into `benches/` do not count), or `unknown` where git or the tree is not there.
pub fn commit() -> String {
    let dir = env!("CARGO_MANIFEST_DIR");
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .arg("-C")
            .arg(dir)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(hash) if !hash.is_empty() => {
            let dirty = git(&[
                "status",
                "--porcelain",
                "--untracked-files=no",
                "--",
                "src",
                "kernels",
                "build.rs",
                "Cargo.toml",
                "Cargo.lock",
            ])
            .is_some_and(|s| !s.is_empty());
            if dirty { format!("{hash}-dirty") } else { hash }
        }
        _ => "unknown".into(),
    }
}

/// Today's date (UTC) as `YYYY-MM-DD`.
pub fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date of `days` since 1970-01-01 (Howard Hinnant's algorithm).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass present in one frame of four counts a quarter of its time per frame.
    #[test]
    fn passes_per_frame() {
        let f = |v: &[(&str, f64)]| v.iter().map(|(l, t)| (l.to_string(), *t)).collect();
        let frames: Vec<Vec<(String, f64)>> = vec![
            f(&[("gbuffer", 1.0), ("shade", 2.0)]),
            f(&[("gbuffer", 1.0), ("shade", 2.0)]),
            f(&[("gbuffer", 1.0), ("shade", 2.0)]),
            f(&[
                ("light0.shadow_raster", 4.0),
                ("gbuffer", 1.0),
                ("shade", 2.0),
            ]),
        ];
        let want: Vec<(String, f64)> = f(&[
            ("gbuffer", 1.0),
            ("shade", 2.0),
            ("light0.shadow_raster", 1.0),
        ]);
        assert_eq!(per_frame(&frames), want);
    }

    /// Known dates: the epoch, a leap day, the turn of 2000 and of 2100.
    #[test]
    fn dates_from_days() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(10_957), (2000, 1, 1));
        assert_eq!(civil_from_days(47_482), (2100, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }
}
