//! The crossover's measurement: the configurations it compares (the fronts' and their PCSS),
//! timed again at each of its image sizes under the time protocol, fitted and checked
//! ([`crossover`](super::crossover)); and its account in `report.md` and on stdout.

use std::fmt::Write;

use super::crossover::{
    self, CheckError, Checked, Cost, Crossover, Match, Pair, RANGE_MPX, crossing, fit,
    relative_error,
};
use super::protocol::{self, Protocol, Timed};
use super::svg::{Metric, front};
use super::{EvaluateOptions, Kept, Measurement, Report, timing};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::scene::UpdateRate;

/// The sizes on a CPU driver unless `--crossover-sizes` says otherwise: fitted at 480×360 and
/// 1280×720, checked at 960×540 (a software driver shades 0.9 Mpx in a fraction of a second).
/// Fitted at 320×240 and 640×480 instead, lavapipe's slopes moved by up to 35% between runs
/// (its fixed costs weigh on images that small) and the check at 960×540 missed by up to 33%.
pub const CPU_SIZES: [(u32, u32); 3] = [(480, 360), (1280, 720), (960, 540)];

/// On a GPU: fitted at 1280×720 and 3840×2160, checked at 1920×1080.
pub const GPU_SIZES: [(u32, u32); 3] = [(1280, 720), (3840, 2160), (1920, 1080)];

/// With `--quick`: fitted at 80×60 and 160×120, checked at 120×90 (seconds on a CPU driver).
pub const QUICK_SIZES: [(u32, u32); 3] = [(80, 60), (160, 120), (120, 90)];

/// The most timed frames per configuration and size (fewer when `--repeat` says so).
pub const MAX_REPEATS: u32 = 3;

/// The sizes of a run: `opts.crossover_sizes`, else [`QUICK_SIZES`], [`CPU_SIZES`] or
/// [`GPU_SIZES`]. All but the last are fitted; the last checks the fit.
pub fn sizes(opts: &EvaluateOptions, cpu_driver: bool) -> Vec<(u32, u32)> {
    match &opts.crossover_sizes {
        Some(s) => s.clone(),
        None if opts.quick => QUICK_SIZES.to_vec(),
        None if cpu_driver => CPU_SIZES.to_vec(),
        None => GPU_SIZES.to_vec(),
    }
}

fn mpx((w, h): (u32, u32)) -> f64 {
    f64::from(w) * f64::from(h) / 1e6
}

/// Measures the crossover of `report`'s fronts against PCSS with the renderer and
/// configurations `kept` (see the module docs).
pub fn measure(
    gpu: &Gpu,
    kept: &mut Kept,
    report: &Report,
    opts: &EvaluateOptions,
) -> Result<Crossover> {
    let rows = &report.rows;
    if !rows.iter().any(|r| r.technique == "pcss") {
        return Ok(Crossover::none(
            "the sweep has no PCSS configuration to compare with",
        ));
    }
    if rows.iter().all(|r| r.total_ms.is_none()) {
        return Ok(Crossover::none("the device wrote no timestamps"));
    }
    let on_front: Vec<usize> = Metric::of(report)
        .into_iter()
        .flat_map(|m| front(rows, m))
        .collect();
    let pairs = crossover::pairs(rows, &on_front);
    if pairs.is_empty() {
        return Ok(Crossover::none(
            "no technique other than PCSS is on a front, so none is compared with it",
        ));
    }
    let mut measured: Vec<usize> = pairs.iter().flat_map(|p| [p.0, p.1]).collect();
    measured.sort_unstable();
    measured.dedup();
    let sizes = sizes(opts, report.cpu_driver);
    let (fit_sizes, check) = sizes.split_at(sizes.len().saturating_sub(1));
    let check = check.first().copied().unwrap_or((1, 1));
    let repeats = opts.repeat.min(MAX_REPEATS);
    let all: Vec<(u32, u32)> = fit_sizes.iter().copied().chain([check]).collect();
    let at_size = time_sizes(gpu, kept, report, &measured, &all, repeats)?;
    let costs: Vec<Cost> = measured
        .iter()
        .enumerate()
        .map(|(k, &i)| cost(&rows[i], i, fit_sizes, check, &at_size, k))
        .collect();
    let pairs = with_crossings(&pairs, &measured, &costs);
    let errors = |f: &dyn Fn(&Checked) -> f64| {
        let e: Vec<f64> = costs.iter().map(|c| f(&c.check)).collect();
        CheckError::of(&e).unwrap_or_default()
    };
    Ok(Crossover {
        note: None,
        fit_sizes: fit_sizes.to_vec(),
        check_size: check,
        repeats,
        moving_error: errors(&|c| relative_error(c.moving_predicted, c.moving_measured)),
        static_error: errors(&|c| relative_error(c.static_predicted, c.static_measured)),
        costs,
        pairs,
    })
}

/// Each `(technique row, PCSS row, match)` of `pairs` with its indices among `measured` (the
/// rows of `costs`) and where the technique is cheaper, moving and static.
fn with_crossings(
    pairs: &[(usize, usize, Match)],
    measured: &[usize],
    costs: &[Cost],
) -> Vec<Pair> {
    let at = |row: usize| measured.iter().position(|&m| m == row).unwrap_or(0);
    pairs
        .iter()
        .map(|&(t, p, matched)| {
            let (t, p) = (at(t), at(p));
            let cross = |moving| crossing(costs[t].line(moving), costs[p].line(moving), RANGE_MPX);
            Pair {
                config: t,
                pcss: p,
                matched,
                moving: cross(true),
                still: cross(false),
            }
        })
        .collect()
}

/// Row `row`'s cost from its times at every size (`at_size[s][k]`, the check size last).
fn cost(
    row: &Measurement,
    index: usize,
    fit_sizes: &[(u32, u32)],
    check: (u32, u32),
    at_size: &[Vec<Measurement>],
    k: usize,
) -> Cost {
    let shade = |r: &Measurement| r.shade_ms.unwrap_or(f64::NAN);
    let prefilter = |r: &Measurement| r.raster_ms.unwrap_or(0.0) + r.kernels_ms.unwrap_or(0.0);
    let fitted = &at_size[..fit_sizes.len()];
    let shade_points: Vec<(f64, f64)> = fit_sizes
        .iter()
        .zip(fitted)
        .map(|(&s, rows)| (mpx(s), shade(&rows[k])))
        .collect();
    let pre: Vec<f64> = fitted.iter().map(|rows| prefilter(&rows[k])).collect();
    let prefilter_ms = protocol::median(&pre).unwrap_or(f64::NAN);
    let line = fit(&shade_points).unwrap_or(crossover::Line {
        a: f64::NAN,
        b: f64::NAN,
    });
    let measured = &at_size[fit_sizes.len()][k];
    let x = mpx(check);
    Cost {
        label: row.label.clone(),
        technique: row.technique.clone(),
        row: index,
        penumbra: row.penumbra.mean_abs,
        prefilter_ms,
        shade: line,
        shade_points,
        check: Checked {
            mpx: x,
            moving_measured: shade(measured) + prefilter(measured),
            moving_predicted: line.plus(prefilter_ms).at(x),
            static_measured: shade(measured),
            static_predicted: line.at(x),
        },
    }
}

/// `report`'s rows `measured` timed at every image size of `sizes` with every light redrawn
/// every frame (raster, prefilter and shading in each timed frame): `repeats` rounds, each
/// visiting every size in turn and at each size every configuration once under the time
/// protocol (its clock check within the size), so that a change of the machine's load falls
/// on every size alike. Per size, a copy of each row with its times.
fn time_sizes(
    gpu: &Gpu,
    kept: &mut Kept,
    report: &Report,
    measured: &[usize],
    sizes: &[(u32, u32)],
    repeats: u32,
) -> Result<Vec<Vec<Measurement>>> {
    let mut timed = vec![vec![Timed::default(); measured.len()]; sizes.len()];
    let mut checks: Vec<Vec<f64>> = vec![Vec::new(); sizes.len()];
    let bar =
        indicatif::ProgressBar::new((sizes.len() * measured.len()) as u64 * u64::from(repeats));
    bar.set_message("crossover: timing at each image size");
    for _ in 0..repeats {
        for (s, &size) in sizes.iter().enumerate() {
            let run = time_round(gpu, kept, measured, size, &bar)?;
            checks[s].extend(run.check_median);
            for (all, t) in timed[s].iter_mut().zip(run.timed) {
                all.samples.extend(t.samples);
                all.retries += t.retries;
                all.off |= t.off;
            }
        }
    }
    bar.finish_and_clear();
    Ok(timed
        .iter_mut()
        .zip(&checks)
        .map(|(per_config, runs)| {
            let run_check = protocol::median(runs);
            measured
                .iter()
                .zip(per_config.iter_mut())
                .map(|(&i, t)| {
                    let c: Vec<f64> = t
                        .samples
                        .iter()
                        .filter_map(|x| x.pass(timing::CHECK_PASS))
                        .collect();
                    t.check_ms = protocol::median(&c);
                    let mut r = report.rows[i].clone();
                    timing::fill(&mut r, t, run_check);
                    r
                })
                .collect()
        })
        .collect())
}

/// One round of `report`'s rows `measured` at image `(w, h)`, every light redrawn every frame.
fn time_round(
    gpu: &Gpu,
    kept: &mut Kept,
    measured: &[usize],
    (w, h): (u32, u32),
    bar: &indicatif::ProgressBar,
) -> Result<protocol::Run> {
    let mut scene = kept.scene.clone();
    scene.width = w;
    scene.height = h;
    let by = format!("evaluate --crossover-sizes ({w}x{h})");
    scene.locations.set_by("output.width", by.clone());
    scene.locations.set_by("output.height", by);
    let variants: Vec<timing::Variant> = measured
        .iter()
        .map(|&i| {
            let mut v = kept.variants[i].clone();
            v.updates = vec![UpdateRate::EveryFrame; v.lights.len()];
            v
        })
        .collect();
    let protocol = Protocol::new(1);
    timing::time_variants(&mut kept.renderer, gpu, &scene, &variants, &protocol, bar)
}

fn size_list(sizes: &[(u32, u32)]) -> String {
    let s: Vec<String> = sizes.iter().map(|(w, h)| format!("{w}×{h}")).collect();
    s.join(", ")
}

/// The prediction's error in one line (stdout and the reports).
pub fn check_line(c: &Crossover) -> String {
    let (w, h) = c.check_size;
    let pct = |e: CheckError| {
        format!(
            "median {:.1}%, worst {:.1}%",
            100.0 * e.median,
            100.0 * e.worst
        )
    };
    let met = c.moving_error.met() && c.static_error.met();
    format!(
        "Crossover prediction at {w}×{h} (not fitted) against its measurement, over {} \
         configurations: moving light {}; static light {} (target: median ≤ {:.0}%, worst ≤ \
         {:.0}%: {}).",
        c.costs.len(),
        pct(c.moving_error),
        pct(c.static_error),
        100.0 * crossover::TARGET_MEDIAN,
        100.0 * crossover::TARGET_WORST,
        if met { "met" } else { "not met" }
    )
}

/// How the crossover was built, for the reports.
pub fn method_text(c: &Crossover) -> String {
    format!(
        "Each technique's configuration on a front (its most accurate in the penumbra) against \
         PCSS of comparable penumbra error: the cheapest PCSS configuration at most 10% less \
         accurate, else the most accurate PCSS (marked *). Built from measurements: these \
         configurations timed again with every light redrawn every frame, in {} rounds, each \
         visiting every image size in turn and at each every configuration once under the \
         time protocol; the shading pass fitted as a + b·Mpx (least squares) at {}, raster + \
         prefilter taken as its median over those frames (it depends on the map, not the \
         image), and both checked at {} (not fitted). A moving light costs raster + prefilter \
         + shading per frame, a static one the shading. Drawn over {}–{:.1} Mpx (3840×2160).",
        c.repeats,
        size_list(&c.fit_sizes),
        size_list(&[c.check_size]),
        RANGE_MPX.0,
        RANGE_MPX.1
    )
}

/// The crossover's section of `report.md`.
pub fn markdown(c: &Crossover, cpu_driver: bool) -> String {
    let mut s = String::from("\n## Cost as the image grows: the crossover against PCSS\n\n");
    if let Some(note) = &c.note {
        let _ = writeln!(s, "No crossover: {note}.");
        return s;
    }
    let _ = writeln!(s, "{}\n\n{}\n", method_text(c), check_line(c));
    if cpu_driver {
        s.push_str(
            "These are CPU-driver times: where lines cross on a GPU differs (its passes' ratios \
             differ by up to 7×).\n\n",
        );
    }
    s.push_str("| technique | configuration | penumbra mean | PCSS compared | its penumbra mean | cheaper than it, moving light | cheaper than it, static light |\n");
    s.push_str("| --- | --- | ---: | --- | ---: | --- | --- |\n");
    for p in &c.pairs {
        let (t, q) = (&c.costs[p.config], &c.costs[p.pcss]);
        let star = if p.matched == Match::MostAccurate {
            " *"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {}{star} | {:.4} | {} | {} |",
            t.technique,
            t.label,
            t.penumbra,
            q.label,
            q.penumbra,
            p.moving.text(),
            p.still.text()
        );
    }
    let (w, h) = c.check_size;
    let _ = writeln!(
        s,
        "\n| configuration | raster + prefilter ms | shading ms = a + b·Mpx | moving at {w}×{h}: predicted / measured ms | static: predicted / measured ms |"
    );
    s.push_str("| --- | ---: | --- | ---: | ---: |\n");
    for k in &c.costs {
        let x = &k.check;
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} + {:.3}·Mpx | {:.3} / {:.3} | {:.3} / {:.3} |",
            k.label,
            k.prefilter_ms,
            k.shade.a,
            k.shade.b,
            x.moving_predicted,
            x.moving_measured,
            x.static_predicted,
            x.static_measured
        );
    }
    s.push_str("\nFigure: `crossover.svg` (cost per frame against megapixels; moving light solid, static dashed, crossings ringed).\n");
    s
}

/// The crossover's section of `report.html`: the plot inline, the table per technique.
pub fn html(report: &Report) -> Result<String> {
    use super::html::escape;
    let Some(c) = &report.crossover else {
        return Ok(String::new());
    };
    let mut s = String::from(
        "<h2 id=\"crossover\">Cost as the image grows: the crossover against PCSS</h2>\n",
    );
    if let Some(note) = &c.note {
        let _ = writeln!(s, "<p>No crossover: {}.</p>", escape(note));
        return Ok(s);
    }
    let _ = writeln!(
        s,
        "<p class=\"note\">{}</p>\n<p class=\"crossover-check\">{}</p>",
        escape(&method_text(c)),
        escape(&check_line(c))
    );
    let svg = super::crossover_svg::crossover_svg(c, &super::output::crossover_title(report))?;
    let body = svg.find("<svg").map_or(svg.as_str(), |k| &svg[k..]);
    let _ = writeln!(
        s,
        "<div class=\"crossover-plot\" role=\"img\" aria-label=\"cost per frame against image size\">{body}</div>"
    );
    s.push_str(
        "<table class=\"crossover\"><thead><tr><th>technique</th><th>configuration</th>\
         <th>penumbra mean</th><th>PCSS compared</th><th>its penumbra mean</th>\
         <th>cheaper than it, moving light</th><th>cheaper than it, static light</th></tr></thead><tbody>\n",
    );
    for p in &c.pairs {
        let (t, q) = (&c.costs[p.config], &c.costs[p.pcss]);
        let star = if p.matched == Match::MostAccurate {
            " *"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{:.4}</td><td>{}{star}</td><td>{:.4}</td><td>{}</td><td>{}</td></tr>",
            escape(&t.technique),
            escape(&t.label),
            t.penumbra,
            escape(&q.label),
            q.penumbra,
            escape(&p.moving.text()),
            escape(&p.still.text())
        );
    }
    s.push_str("</tbody></table>\n");
    Ok(s)
}
