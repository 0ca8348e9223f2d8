//! The report files: `report.md`, `report.csv`, `report.json`, `report.html`, and the figures
//! (`pareto.svg`, `pareto_penumbra.svg`, `pareto_flip.svg`, `grid.png` with its legend
//! `grid.txt`).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::svg::{Metric, front};
use super::{EDGE_BAND, ErrorStats, Images, PENUMBRA_HIGH, PENUMBRA_LOW, Report, out_path};
use crate::error::{Error, Result};

/// Makes the output folder `dir` and writes (then removes) an empty file in it, so that a
/// folder that cannot be made or written is refused before the sweep's GPU work, not after it.
pub fn check_dir(dir: &Path) -> Result<()> {
    let probe = out_path(dir, ".shadowgraph-write-check")?;
    std::fs::write(&probe, b"").map_err(|error| Error::Io {
        path: dir.to_path_buf(),
        error,
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Writes every output file into `dir`; returns their paths. `others` are the further
/// operating points' reports with their folders under `dir`, summarized in this one's
/// report.md and report.html.
pub fn write_all(
    dir: &Path,
    report: &Report,
    images: &Images,
    others: &[(String, Report)],
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let mut put = |name: &str, bytes: &[u8]| -> Result<()> {
        let path = out_path(dir, name)?;
        std::fs::write(&path, bytes).map_err(|error| Error::Io {
            path: path.clone(),
            error,
        })?;
        written.push(path);
        Ok(())
    };
    let mut md = markdown(report);
    md.push_str(&others_text(others));
    put("report.md", md.as_bytes())?;
    put("report.csv", csv(report).as_bytes())?;
    let json = serde_json::to_string_pretty(report)
        .map_err(|e| Error::Invalid(format!("report.json: {e}")))?;
    put("report.json", json.as_bytes())?;
    let mut plots = Vec::new();
    for m in Metric::of(report) {
        let svg = super::svg::pareto(report, m)?;
        put(m.file(), svg.as_bytes())?;
        plots.push((m, svg));
    }
    if let Some(c) = report.crossover.as_ref().filter(|c| c.note.is_none()) {
        put(
            "crossover.svg",
            super::crossover_svg::crossover_svg(c, &crossover_title(report))?.as_bytes(),
        )?;
    }
    let (png, legend) = super::grid::grid(report, images)?;
    put("grid.png", &png)?;
    put("grid.txt", legend.as_bytes())?;
    put(
        "report.html",
        super::html::html(report, images, &plots, others)?.as_bytes(),
    )?;
    Ok(written)
}

/// The crossover plot's title.
pub(super) fn crossover_title(report: &Report) -> String {
    format!(
        "{}: cost per frame against image size{}",
        report.scene,
        if report.cpu_driver {
            " (CPU-driver times)"
        } else {
            ""
        }
    )
}

fn ms(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| format!("{v:.3}"))
}

/// The CSV columns of an error statistic, with a prefix.
fn stats_header(prefix: &str) -> String {
    [
        "pixels",
        "mean_abs",
        "rmse",
        "p99",
        "max",
        "over_0.05",
        "over_0.2",
    ]
    .map(|c| format!("{prefix}_{c}"))
    .join(",")
}

fn stats_cells(s: Option<&ErrorStats>) -> String {
    match s {
        Some(s) => format!(
            "{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            s.pixels, s.mean_abs, s.rmse, s.p99, s.max, s.over_005, s.over_02
        ),
        None => ",,,,,,".into(),
    }
}

/// One line per configuration; per-pass times as `name=ms` pairs separated by `;`.
pub fn csv(report: &Report) -> String {
    let mut s = format!(
        "label,technique,shadow_map,storage,filter,box_width,raster_ms,kernels_ms,shade_ms,total_ms,total_q1_ms,total_q3_ms,total_min_ms,total_max_ms,gbuffer_ms,wall_ms,check_ratio,retries,clock_off,memory_bytes,bytes_per_texel,dispatches,fetches_per_pixel,penumbra_hf,temporal_mean_abs,temporal_max,{},{},{},{},{},{},passes\n",
        stats_header("soft"),
        stats_header("penumbra"),
        stats_header("umbra"),
        stats_header("lit"),
        stats_header("flip"),
        stats_header("pcf")
    );
    for r in &report.rows {
        let passes: Vec<String> = r
            .passes
            .iter()
            .map(|(l, v)| format!("{l}={v:.4}"))
            .collect();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.2},{},{:.2},{:.6},{},{},{},{},{},{},{},{},{}",
            r.label,
            r.technique,
            r.shadow_map,
            r.storage,
            r.filter,
            r.box_width.map_or_else(String::new, |w| w.to_string()),
            ms(r.raster_ms),
            ms(r.kernels_ms),
            ms(r.shade_ms),
            ms(r.total_ms),
            ms(r.total_spread.map(|s| s.q1)),
            ms(r.total_spread.map(|s| s.q3)),
            ms(r.total_spread.map(|s| s.min)),
            ms(r.total_spread.map(|s| s.max)),
            ms(r.gbuffer_ms),
            ms(r.wall_ms),
            r.check_ratio
                .map_or_else(String::new, |q| format!("{q:.4}")),
            r.retries,
            r.clock_off,
            r.memory_bytes,
            r.cost.bytes_per_texel,
            r.cost.dispatches,
            r.cost.fetches_per_pixel,
            r.penumbra_hf,
            r.temporal
                .map_or_else(String::new, |t| format!("{:.6}", t.mean_abs)),
            r.temporal
                .map_or_else(String::new, |t| format!("{:.6}", t.max)),
            stats_cells(Some(&r.soft)),
            stats_cells(Some(&r.penumbra)),
            stats_cells(Some(&r.umbra)),
            stats_cells(Some(&r.lit)),
            stats_cells(Some(&r.flip)),
            stats_cells(r.pcf.as_ref()),
            passes.join(";")
        );
    }
    s
}

fn mib(b: u64) -> String {
    format!("{:.1}", b as f64 / (1024.0 * 1024.0))
}

/// How the regions and FLIP are defined, for the reports.
pub fn region_text(report: &Report) -> String {
    let [pen, umb, lit] = report.region_pixels;
    format!(
        "Regions of the truth (per light; {pen} penumbra, {umb} umbra, {lit} lit pixels): the \
         *penumbra* is every relevant pixel whose truth is strictly between {PENUMBRA_LOW} and \
         {PENUMBRA_HIGH}, or within {EDGE_BAND} pixels (a {w}×{w} square) of an edge pixel (a \
         pixel whose truth and a relevant 4-neighbour's lie on opposite sides of 0.5), so a hard \
         shadow's edge band counts too; the *umbra* is the rest with truth ≤ {PENUMBRA_LOW} \
         (error there: light leaking, lost contact shadows); *lit* the rest with truth ≥ \
         {PENUMBRA_HIGH} (error there: false shadow — acne, over-darkening, ringing). *FLIP*: \
         NVIDIA's perceptual error (HPG 2020, 67 pixels per degree) of the shaded image against \
         the truth-shaded image (the renderer's shading with the truth's visibility per light), \
         mean over the whole image.",
        w = 2 * EDGE_BAND + 1
    )
}

/// The further operating points (Markdown): per folder, its operating point and verdict.
pub fn others_text(others: &[(String, Report)]) -> String {
    let mut s = String::new();
    if others.is_empty() {
        return s;
    }
    s.push_str(
        "\n## Other operating points\n\nThe same configurations and errors, timed again under \
         the same protocol with every light at another update rate; each is a report of its own \
         in its folder.\n",
    );
    for (dir, r) in others {
        let _ = writeln!(
            s,
            "\n### `{dir}/`: {}\n",
            super::verdict::operating_point(r)
        );
        for v in super::verdict::verdicts(r).iter().skip(1) {
            let _ = writeln!(s, "- {v}");
        }
    }
    s
}

/// The run's facts: device and driver, commit, date, timed frames per configuration.
pub fn run_line(report: &Report) -> String {
    format!(
        "Device: {}. Commit {}, {} (UTC); n = {} timed frames per configuration.",
        report.device,
        if report.commit.is_empty() {
            "unknown"
        } else {
            &report.commit
        },
        if report.date.is_empty() {
            "date unknown"
        } else {
            &report.date
        },
        report.repeats
    )
}

/// How the times were taken (the time protocol), and what its clock check found.
pub fn protocol_text(report: &Report) -> String {
    let n = report.rows.len();
    let mut s = format!(
        "Time protocol: after every configuration's error was measured, the {n} \
         configurations were timed interleaved, round-robin over {} rounds (each round starting \
         one configuration later, one untimed frame before each timed one, and on a GPU {} ms of \
         untimed frames first so that its clocks have risen).",
        report.repeats,
        crate::timer::GPU_WARMUP_MS
    );
    let Some(m) = report.check_median_ms else {
        s.push_str(" No clock check: the device wrote no timestamps.");
        return s;
    };
    let retried = report.rows.iter().filter(|r| r.retries > 0).count();
    let off: Vec<&str> = report
        .rows
        .iter()
        .filter(|r| r.clock_off)
        .map(|r| r.label.as_str())
        .collect();
    let ratios: Vec<f64> = report.rows.iter().filter_map(|r| r.check_ratio).collect();
    let (lo, hi) = ratios
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &q| {
            (a.min(q), b.max(q))
        });
    let _ = write!(
        s,
        " Clock check: the camera G-buffer, the same work in every configuration, ran {m:.3} ms \
         (the run's median); {retried} of {n} configurations had their G-buffer more than 10% off \
         it and were measured again (at most twice, keeping the attempt closest to it); still \
         off after that: {}",
        off.len()
    );
    if !off.is_empty() {
        let _ = write!(s, " (†: {})", off.join(", "));
    }
    if lo.is_finite() {
        let _ = write!(
            s,
            "; the configurations' G-buffer medians span {lo:.2}–{hi:.2}× the run's."
        );
    } else {
        s.push('.');
    }
    s
}

/// A mean, or a dash where its region is empty.
fn mean_cell(s: &ErrorStats) -> String {
    if s.pixels == 0 {
        "—".into()
    } else {
        format!("{:.4}", s.mean_abs)
    }
}

/// How far a CPU driver's passes may sum from a frame's wall time before the report calls the
/// configuration's times untrusted: `tests/timing.rs`'s tolerance for the same instrument.
pub const WALL_TOLERANCE: f64 = 0.25;

/// Per configuration with timings: its label and its passes' sum, G-buffer included, over its
/// frame's wall time.
pub fn wall_ratios(report: &Report) -> Vec<(&str, f64)> {
    report
        .rows
        .iter()
        .filter_map(|r| {
            let wall = r.wall_ms.filter(|w| *w > 0.0)?;
            Some((r.label.as_str(), (r.total_ms? + r.gbuffer_ms?) / wall))
        })
        .collect()
}

/// The configurations of a CPU-driver report whose passes sum further than
/// [`WALL_TOLERANCE`] from their wall time (none on a GPU, where the difference is the
/// submission's latency, a fixed 0.1–0.3 ms).
pub fn untrusted_times(report: &Report) -> Vec<(&str, f64)> {
    if !report.cpu_driver {
        return Vec::new();
    }
    wall_ratios(report)
        .into_iter()
        .filter(|(_, q)| (q - 1.0).abs() > WALL_TOLERANCE)
        .collect()
}

/// The timestamps against the wall clock: the range of [`wall_ratios`] over the report, and
/// the configurations whose times it does not trust (empty without timings).
pub fn wall_check(report: &Report) -> String {
    let ratios = wall_ratios(report);
    if ratios.is_empty() {
        return String::new();
    }
    let lo = ratios.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
    let hi = ratios.iter().map(|r| r.1).fold(f64::NEG_INFINITY, f64::max);
    let mut s = format!(
        "\nTimestamps against the wall clock: in each of the {} configurations, the passes \
         (G-buffer included) sum to {lo:.2}–{hi:.2}× the frame's wall time (a frame's submission \
         to its completion; on a GPU the difference is submission and scheduling, on a CPU \
         driver a stamp's wait for its own work).\n",
        ratios.len()
    );
    let off = untrusted_times(report);
    if !off.is_empty() {
        let list: Vec<String> = off.iter().map(|(l, q)| format!("{l} ({q:.2}×)")).collect();
        s.push_str(&format!(
            "\n**Times not trusted** (passes more than {:.0}% from the wall time on a CPU driver; \
             rerun on an idle machine): {}.\n",
            100.0 * WALL_TOLERANCE,
            list.join(", ")
        ));
    }
    s
}

/// The Pareto fronts, one list per metric.
fn fronts_text(report: &Report) -> String {
    let mut s = String::new();
    for m in Metric::of(report) {
        let f = front(&report.rows, m);
        if f.is_empty() {
            continue;
        }
        let _ = writeln!(
            s,
            "\nPareto front of total time vs {} (no configuration is both faster and more \
             accurate):\n",
            m.name()
        );
        for i in f {
            let r = &report.rows[i];
            let _ = writeln!(
                s,
                "- {}: {} ms, {} {:.4}",
                r.label,
                ms(r.total_ms),
                m.name(),
                m.value(r)
            );
        }
    }
    s
}

/// The report: what was measured and how, then one table row per configuration.
pub fn markdown(report: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Accuracy vs time: `{}`\n", report.scene);
    let _ = writeln!(s, "{}\n", run_line(report));
    for v in super::verdict::verdicts(report) {
        let _ = writeln!(s, "- {v}");
    }
    let _ = writeln!(
        s,
        "\nImage {}×{}, {} relevant pixels (lit receivers: facing the light, inside its \
         frustum and cone). Ground truth: the area light's emitter (a square of side `size` at \
         the light's position, perpendicular to its direction) sampled at K = {} stratified \
         points, one {:?}² hard shadow map each (`shadowgraph::truth`).\n",
        report.image.0,
        report.image.1,
        report.relevant_pixels,
        report.truth_samples,
        report.truth_resolution
    );
    if report.cpu_driver {
        s.push_str(
            "**Times are CPU-driver times** (a software Vulkan driver runs the kernels on the \
             CPU, and its ratios between passes differ from a GPU's by up to 7×): these fronts \
             test the machinery, not the answer for a GPU; compare configurations with each \
             other only.\n\n",
        );
    }
    s.push_str(&protocol_text(report));
    s.push_str("\n\n");
    s.push_str(
        "Columns: GPU time per part (median over the timed frames, from timestamps): raster = shadow \
         map (and the peel pass of a second-depth technique), kernels = the graph (linearize, encode, filter), shade = the shading pass, total = \
         their sum (the camera G-buffer is common to all and left out), shown as median (first–third \
         quartile); † marks a configuration whose clock check stayed off; wall = a whole frame, \
         G-buffer included, from submission to completion (median), which the timestamps are \
         checked against below the table; memory = the plan's peak \
         live textures plus the depth maps; B/texel, dispatches and fetches/px: what \
         `shadowgraph plan` counts for light 0 (the graph's bytes read and written per map \
         texel, its dispatches, the shading's texture fetches per pixel). *soft*: error against the area-light truth (the \
         scene as it should look); *pcf*: error against brute-force box PCF of the \
         configuration's own map with the same box width (what a prefiltered technique \
         approximates), where the configuration filters with a box. Errors are |visibility − \
         truth| over the relevant pixels: mean, RMSE, 99th percentile, max, and the shares of \
         pixels off by more than 0.05 and 0.2; *penumbra*, *umbra*, *lit*: the soft mean over \
         each region of the truth; *temporal* (animated scenes): the mean |Δ visibility − Δ \
         truth| between consecutive frames over the truth's penumbra, the flicker the truth \
         does not have; *penumbra HF*: the penumbra's high-frequency error, the \
         RMS of the discrete Laplacian of (visibility − truth) over penumbra pixels (0 for an \
         error that varies smoothly, large for a staircase, banding or noise).\n\n",
    );
    s.push_str(&region_text(report));
    s.push_str("\n\n");
    s.push_str(
        "| configuration | raster ms | kernels ms | shade ms | total ms (IQR) | wall ms | MiB | B/texel | dispatches | fetches/px | soft mean | soft rmse | soft p99 | soft max | soft >0.05 | soft >0.2 | penumbra mean | penumbra HF | umbra mean | lit mean | FLIP mean | temporal mean | pcf mean | pcf p99 | pcf >0.05 |\n",
    );
    s.push_str("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for r in &report.rows {
        let (pm, pp, po) =
            r.pcf
                .as_ref()
                .map_or((String::new(), String::new(), String::new()), |p| {
                    (
                        format!("{:.4}", p.mean_abs),
                        format!("{:.3}", p.p99),
                        format!("{:.2}%", 100.0 * p.over_005),
                    )
                });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {}{} | {} | {} | {:.1} | {} | {:.1} | {:.4} | {:.4} | {:.3} | {:.3} | {:.2}% | {:.2}% | {} | {:.4} | {} | {} | {:.4} | {} | {pm} | {pp} | {po} |",
            r.label,
            ms(r.raster_ms),
            ms(r.kernels_ms),
            ms(r.shade_ms),
            r.total_spread.map_or_else(|| ms(r.total_ms), |t| t.text(3)),
            if r.clock_off { " †" } else { "" },
            ms(r.wall_ms),
            mib(r.memory_bytes),
            r.cost.bytes_per_texel,
            r.cost.dispatches,
            r.cost.fetches_per_pixel,
            r.soft.mean_abs,
            r.soft.rmse,
            r.soft.p99,
            r.soft.max,
            100.0 * r.soft.over_005,
            100.0 * r.soft.over_02,
            mean_cell(&r.penumbra),
            r.penumbra_hf,
            mean_cell(&r.umbra),
            mean_cell(&r.lit),
            r.flip.mean_abs,
            r.temporal
                .map_or_else(|| "—".into(), |t| format!("{:.4}", t.mean_abs)),
        );
    }
    s.push_str(&wall_check(report));
    s.push_str(&fronts_text(report));
    if let Some(c) = &report.crossover {
        s.push_str(&super::crossover_run::markdown(c, report.cpu_driver));
    }
    for (label, why) in &report.skipped {
        let _ = writeln!(s, "\nSkipped {label}: {why}");
    }
    s.push_str(
        "\nFigures: `report.html` (the plots, a sortable table, and crops of the truth and of \
         the front's configurations where their penumbrae differ most, with error maps), \
         `pareto.svg`, `pareto_penumbra.svg` and `pareto_flip.svg` (total time, log scale, vs \
         the soft mean, the penumbra mean and FLIP; the fronts drawn and labelled), `grid.png` \
         (light 0: the truth, then per configuration its visibility and its error map — red \
         where brighter than the truth, blue where darker, full colour at |error| ≥ 0.5, grey \
         outside the relevant pixels), cells listed in `grid.txt`.\n",
    );
    s
}
