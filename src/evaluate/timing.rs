//! The timing phase of `evaluate`: every measured configuration timed under the
//! [`protocol`](super::protocol) on the GPU, its rows' times filled from the kept frames, and
//! the run's facts (commit, date) for the report's header.

use super::Row;
use super::protocol::{self, Protocol, Run, Sample, Spread, Timed};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;

/// The pass that is the same work in every configuration: the clock check.
pub const CHECK_PASS: &str = "gbuffer";

/// Untimed frames rendered before each timed one in a visit: the first frame after a change
/// of configuration pays for what the change makes (a new map size's targets, bind groups,
/// memory touched for the first time).
pub const SETTLE_FRAMES: u32 = 1;

/// Times `scenes` (one per configuration) under `protocol`: on a GPU, untimed frames first
/// until its clocks have risen (and again before each retry round), then the interleaved
/// rounds, each visit [`SETTLE_FRAMES`] untimed frames and one timed.
pub fn time_scenes(
    renderer: &mut Renderer,
    gpu: &Gpu,
    scenes: &[Scene],
    protocol: &Protocol,
    bar: &indicatif::ProgressBar,
) -> Result<Run> {
    let (device, queue) = (&gpu.device, &gpu.queue);
    if let Some(first) = scenes.first() {
        renderer.warm_up(device, queue, first)?;
    }
    let opts = RenderOptions {
        aux: false,
        repeat: SETTLE_FRAMES + 1,
        dump: false,
    };
    protocol::run(protocol, scenes.len(), CHECK_PASS, |c| {
        bar.inc(1);
        let frame = renderer.render(device, queue, &scenes[c], opts)?;
        let last = SETTLE_FRAMES as usize;
        Ok(Sample {
            passes: frame.timings.get(last).cloned().unwrap_or_default(),
            wall_ms: frame.wall_ms.get(last).copied().unwrap_or(0.0),
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
pub fn fill(row: &mut Row, timed: &Timed, run_check: Option<f64>) {
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
/// it was built from, `-dirty` when it has changes), or `unknown` where git or the tree is
/// not there.
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
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
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
