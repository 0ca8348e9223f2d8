//! Operating points past the first: the configurations `run` measured, timed again with every
//! light at another update rate (`--update every,static`), each a report of its own whose
//! errors are the first's (a still frame's) and whose times, fronts and verdict are its own.

use super::protocol::Protocol;
use super::{EvaluateOptions, Kept, Report, apply_times, timing};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::scene::UpdateRate;

/// The folder of an operating point's report under `run`'s: `update-every`, `update-static`,
/// `update-<k>`.
pub fn dir(rate: UpdateRate) -> String {
    match rate {
        UpdateRate::EveryFrame => "update-every".into(),
        UpdateRate::Every(k) => format!("update-{k}"),
        UpdateRate::Static => "update-static".into(),
    }
}

/// Each of `opts.more_updates` not already `report`'s own rate: `report` with its rows timed
/// again at that rate under the time protocol, and its folder.
pub fn more(
    gpu: &Gpu,
    kept: &mut Kept,
    report: &Report,
    opts: &EvaluateOptions,
) -> Result<Vec<(String, Report)>> {
    let mut out: Vec<(String, Report)> = Vec::new();
    for &rate in &opts.more_updates {
        let names = vec![rate.name(); report.lights];
        if names == report.updates || out.iter().any(|(d, _)| *d == dir(rate)) {
            continue;
        }
        let variants: Vec<_> = kept
            .variants
            .iter()
            .map(|v| {
                let mut v = v.clone();
                v.updates = vec![rate; v.lights.len()];
                v
            })
            .collect();
        let bar = indicatif::ProgressBar::new((variants.len() as u64) * u64::from(opts.repeat));
        bar.set_message(format!("timing at update = {}", rate.name()));
        let protocol = Protocol::new(opts.repeat);
        let run = timing::time_variants(
            &mut kept.renderer,
            gpu,
            &kept.scene,
            &variants,
            &protocol,
            &bar,
        )?;
        bar.finish_and_clear();
        let mut r = report.clone();
        r.updates = names;
        apply_times(&mut r, &run);
        out.push((dir(rate), r));
    }
    Ok(out)
}
