//! `report.html`: one self-contained page (every image a `data:` URI, the plots inline SVG so
//! that their points' `<title>` tooltips show, the style and the table-sorting script inline,
//! a Content-Security-Policy that lets nothing else load): the run's facts and the verdict at
//! its operating point, the three Pareto plots, a sortable table of every configuration, and
//! crops of the truth and of each front configuration (and each family's best off the fronts)
//! where their penumbrae differ most from it, with error maps and times.

use std::fmt::Write;

use base64::Engine;

use super::crops::{self, Crop};
use super::flip::{flip_map, magma};
use super::output::{protocol_text, region_text, run_line, wall_check};
use super::svg::{Metric, colour, front};
use super::{ErrorStats, Images, Measurement, Report};
use crate::error::Result;

/// Crops are shown about this many CSS pixels wide (an integer zoom: square pixels).
const CROP_PX: usize = 150;

const STYLE: &str = "body{font:14px/1.45 sans-serif;margin:24px;color:#222;max-width:1500px}\
h1{font-size:22px}h2{font-size:18px;margin-top:32px}\
table.sortable{border-collapse:collapse;font-size:12.5px}\
table.sortable th{cursor:pointer;background:#eee;position:sticky;top:0;padding:4px 6px;\
border-bottom:1px solid #999;white-space:nowrap}\
table.sortable th[data-dir=asc]::after{content:' \\25B2'}\
table.sortable th[data-dir=desc]::after{content:' \\25BC'}\
table.sortable td{padding:2px 6px;border-bottom:1px solid #e4e4e4;text-align:right;\
white-space:nowrap}table.sortable td:first-child{text-align:left}\
tr.front td{background:#fff4e0}.swatch{display:inline-block;width:10px;height:10px;\
border-radius:5px;margin-right:5px}\
.plot img{max-width:100%;border:1px solid #ddd;margin:6px 0}\
.crops{display:flex;flex-wrap:wrap;gap:10px}\
.croprow{display:flex;gap:8px;overflow-x:auto;padding-bottom:6px}.croprow figure{flex:none}\
.croprow figure:first-child{position:sticky;left:0;background:#fff;z-index:1;\
padding-right:6px;border-right:1px solid #ccc}\
figure{margin:0;font-size:11.5px;text-align:center}\
figure img{display:block;image-rendering:pixelated;margin-bottom:2px}\
figcaption{max-width:180px;overflow-wrap:anywhere}.note{color:#555}\
.verdict{background:#f3f7ff;border:1px solid #c8d6f0;padding:8px 16px;margin:12px 0}\
.verdict li{margin:3px 0}.plot svg{max-width:100%;height:auto;border:1px solid #ddd;\
margin:6px 0}.plot .pt:hover{stroke-width:2}";

/// Sorts a `table.sortable` by the clicked column: numbers by `data-v`, text otherwise.
const SCRIPT: &str = "document.querySelectorAll('table.sortable th').forEach((th,col)=>{\
th.addEventListener('click',()=>{const body=th.closest('table').tBodies[0];\
const asc=th.dataset.dir!=='asc';th.parentNode.querySelectorAll('th').forEach(h=>\
delete h.dataset.dir);th.dataset.dir=asc?'asc':'desc';\
const key=tr=>{const td=tr.cells[col];return td.dataset.v!==undefined?\
parseFloat(td.dataset.v):td.textContent;};\
[...body.rows].sort((a,b)=>{const x=key(a),y=key(b);\
const c=typeof x==='number'?x-y:String(x).localeCompare(String(y));\
return asc?c:-c;}).forEach(r=>body.appendChild(r));});});";

/// `s` with HTML's special characters escaped (for text and attribute values).
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Markdown's `*word*` as `<i>word</i>` (the text is shared with report.md).
fn emphasis(s: &str) -> String {
    s.split('*')
        .enumerate()
        .map(|(k, part)| match (k % 2, k) {
            (1, _) => format!("<i>{part}"),
            (0, 0) => part.to_string(),
            _ => format!("</i>{part}"),
        })
        .collect()
}

/// Markdown's `**bold**` as `<b>bold</b>` on escaped text (the verdict is shared with
/// report.md).
fn bold(s: &str) -> String {
    s.split("**")
        .enumerate()
        .map(|(k, part)| match (k % 2, k) {
            (1, _) => format!("<b>{part}"),
            (0, 0) => part.to_string(),
            _ => format!("</b>{part}"),
        })
        .collect()
}

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// An `<img>` of an RGB8 image, shown `scale` times its size with square pixels.
fn img(rgb: &[u8], w: usize, h: usize, scale: usize, alt: &str) -> Result<String> {
    Ok(format!(
        "<img src=\"{}\" width=\"{}\" height=\"{}\" alt=\"{}\">",
        data_uri("image/png", &crops::png(rgb, w, h)?),
        w * scale,
        h * scale,
        escape(alt)
    ))
}

/// The page. `plots` are the SVG texts of the Pareto plots.
pub fn html(
    report: &Report,
    images: &Images,
    plots: &[(Metric, String)],
    others: &[(String, Report)],
) -> Result<String> {
    let mut s = String::new();
    let title = format!("Accuracy vs time: {}", report.scene);
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; \
         img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'\">\
         <title>{t}</title><style>{STYLE}</style></head><body>\n<h1>{t}</h1>\n",
        t = escape(&title)
    );
    let _ = writeln!(s, "<p>{}</p>", escape(&run_line(report)));
    let verdicts = super::verdict::verdicts(report);
    if !verdicts.is_empty() {
        s.push_str("<div class=\"verdict\"><h2>At this operating point</h2><ul>\n");
        for v in &verdicts {
            let _ = writeln!(s, "<li class=\"verdict-line\">{}</li>", bold(&escape(v)));
        }
        s.push_str("</ul>\n");
        for (dir, r) in others {
            let _ = writeln!(
                s,
                "<h3>Timed again at <a href=\"{d}/report.html\">{d}/</a>: {}</h3><ul>",
                escape(&super::verdict::operating_point(r)),
                d = escape(dir)
            );
            for v in super::verdict::verdicts(r).iter().skip(1) {
                let _ = writeln!(s, "<li class=\"verdict-other\">{}</li>", bold(&escape(v)));
            }
            s.push_str("</ul>\n");
        }
        s.push_str("</div>\n");
    }
    let _ = writeln!(
        s,
        "<p>Image {}×{}, {} relevant pixels. Ground truth: the area light sampled \
         at K = {} points, {:?}² hard shadow maps. {}</p>\n<p class=\"note\">{}</p>\n\
         <p class=\"note\">{}</p>",
        report.image.0,
        report.image.1,
        report.relevant_pixels,
        report.truth_samples,
        report.truth_resolution,
        if report.cpu_driver {
            "<b>Times are CPU-driver times</b> (a software Vulkan driver, whose ratios between \
             passes differ from a GPU's by up to 7×): these fronts test the machinery, not the \
             answer for a GPU; compare configurations with each other only."
        } else {
            ""
        },
        emphasis(&escape(&region_text(report))),
        escape(&protocol_text(report))
    );
    s.push_str("<h2>Time against error: the Pareto fronts</h2>\n");
    s.push_str(
        "<p class=\"note\">Colour: technique; shape: family (circle: a lookup or fixed kernel, \
         square: a per-pixel search, triangle: prefiltered, diamond: prefiltered soft); size: \
         map side; bar: the total time's interquartile range over the timed frames. Hover a \
         point for its figures.</p>\n",
    );
    for (m, svg) in plots {
        let body = svg.find("<svg").map_or(svg.as_str(), |k| &svg[k..]);
        let _ = writeln!(
            s,
            "<div class=\"plot\" role=\"img\" aria-label=\"total time vs {}\">{body}</div>",
            m.name()
        );
    }
    s.push_str(&super::crossover_run::html(report)?);
    table(&mut s, report);
    crop_section(&mut s, report, images)?;
    for (label, why) in &report.skipped {
        let _ = writeln!(s, "<p>Skipped {}: {}</p>", escape(label), escape(why));
    }
    let _ = write!(s, "<script>{SCRIPT}</script>\n</body></html>\n");
    Ok(s)
}

/// A numeric cell: sortable by its value, shown with `decimals`.
fn num(v: Option<f64>, decimals: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("<td data-v=\"{v}\">{v:.decimals$}</td>"),
        _ => "<td data-v=\"Infinity\"></td>".into(),
    }
}

fn region_mean(e: &ErrorStats) -> Option<f64> {
    (e.pixels > 0).then_some(e.mean_abs)
}

/// Which fronts a row is on, as `mean, penumbra, FLIP` initials.
fn fronts_of(report: &Report, i: usize) -> String {
    Metric::of(report)
        .iter()
        .filter(|&&m| front(&report.rows, m).contains(&i))
        .map(|m| match m {
            Metric::Mean => "M",
            Metric::Penumbra => "P",
            Metric::Flip => "F",
            Metric::Temporal => "T",
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn table(s: &mut String, report: &Report) {
    s.push_str(
        "<h2>Every configuration</h2>\n<p class=\"note\">Click a heading to sort. Times in ms \
         (wall: a whole frame, G-buffer included, from submission to completion), \
         errors are mean |visibility − truth| over the relevant pixels (soft), the penumbra, \
         umbra and lit regions, and against the box-PCF truth of the configuration's own map \
         (pcf); FLIP is the mean perceptual error of the shaded image. <i>front</i>: on the \
         Pareto front of total time vs the soft mean (M), the penumbra mean (P), FLIP \
         (F). IQR: the total's first–third quartile over the timed frames; retries: times \
         measured again for its clock check († still off); B/texel, dispatches, fetches/px: \
         <code>shadowgraph plan</code>'s cost of light 0; penumbra HF: RMS of the Laplacian \
         of the penumbra's error.</p>\n<table class=\"sortable\"><thead><tr>",
    );
    for h in [
        "configuration",
        "map",
        "raster",
        "kernels",
        "shade",
        "total",
        "IQR",
        "retries",
        "wall",
        "MiB",
        "B/texel",
        "dispatches",
        "fetches/px",
        "soft mean",
        "soft p99",
        "penumbra mean",
        "penumbra p99",
        "penumbra HF",
        "umbra mean",
        "lit mean",
        "FLIP mean",
        "temporal mean",
        "pcf mean",
        "front",
    ] {
        let _ = write!(s, "<th>{h}</th>");
    }
    s.push_str("</tr></thead><tbody>\n");
    for (i, r) in report.rows.iter().enumerate() {
        let fronts = fronts_of(report, i);
        let c = colour(&r.technique);
        let _ = write!(
            s,
            "<tr{}><td><span class=\"swatch\" style=\"background:rgb({},{},{})\"></span>{}</td>",
            if fronts.is_empty() {
                ""
            } else {
                " class=\"front\""
            },
            c.0,
            c.1,
            c.2,
            escape(&r.label)
        );
        s.push_str(&num(Some(f64::from(r.shadow_map)), 0));
        for t in [r.raster_ms, r.kernels_ms, r.shade_ms, r.total_ms] {
            s.push_str(&num(t, 2));
        }
        match r.total_spread {
            Some(t) => {
                let _ = write!(
                    s,
                    "<td data-v=\"{}\">{:.2}–{:.2}</td>",
                    t.q3 - t.q1,
                    t.q1,
                    t.q3
                );
            }
            None => s.push_str(&num(None, 0)),
        }
        let _ = write!(
            s,
            "<td data-v=\"{}\">{}{}</td>",
            r.retries,
            r.retries,
            if r.clock_off { " †" } else { "" }
        );
        s.push_str(&num(r.wall_ms, 2));
        s.push_str(&num(Some(r.memory_bytes as f64 / 1048576.0), 1));
        s.push_str(&num(Some(r.cost.bytes_per_texel), 1));
        s.push_str(&num(Some(f64::from(r.cost.dispatches)), 0));
        s.push_str(&num(Some(r.cost.fetches_per_pixel), 1));
        s.push_str(&num(Some(r.soft.mean_abs), 4));
        s.push_str(&num(Some(r.soft.p99), 3));
        s.push_str(&num(region_mean(&r.penumbra), 4));
        s.push_str(&num(region_mean(&r.penumbra).map(|_| r.penumbra.p99), 3));
        s.push_str(&num(region_mean(&r.penumbra).map(|_| r.penumbra_hf), 4));
        s.push_str(&num(region_mean(&r.umbra), 4));
        s.push_str(&num(region_mean(&r.lit), 4));
        s.push_str(&num(Some(r.flip.mean_abs), 4));
        s.push_str(&num(r.temporal.map(|t| t.mean_abs), 4));
        s.push_str(&num(r.pcf.map(|p| p.mean_abs), 4));
        let _ = writeln!(s, "<td>{fronts}</td></tr>");
    }
    s.push_str("</tbody></table>\n");
    let check = wall_check(report);
    if !check.is_empty() {
        let _ = writeln!(s, "<p class=\"note\">{}</p>", escape(check.trim()));
    }
}

/// The union of the fronts, fastest first.
fn front_rows(report: &Report) -> Vec<usize> {
    let mut all: Vec<usize> = Metric::of(report)
        .iter()
        .flat_map(|&m| front(&report.rows, m))
        .collect();
    all.sort_by(|&a, &b| {
        let t = |i: usize| report.rows[i].total_ms.unwrap_or(f64::INFINITY);
        t(a).total_cmp(&t(b)).then(a.cmp(&b))
    });
    all.dedup();
    all
}

/// The rows the crops show: the fronts' union, then each family's most accurate in the
/// penumbra where it is on no front, fastest first.
pub(super) fn crop_rows(report: &Report) -> Vec<usize> {
    let mut all = front_rows(report);
    for f in super::verdict::Family::ALL {
        let best = (0..report.rows.len())
            .filter(|&i| super::verdict::Family::named(&report.rows[i].family) == f)
            .min_by(|&a, &b| {
                let e = |i: usize| report.rows[i].penumbra.mean_abs;
                e(a).total_cmp(&e(b))
            });
        if let Some(i) = best.filter(|i| !all.contains(i)) {
            all.push(i);
        }
    }
    let t = |i: usize| report.rows[i].total_ms.unwrap_or(f64::INFINITY);
    all.sort_by(|&a, &b| t(a).total_cmp(&t(b)).then(a.cmp(&b)));
    all
}

fn crop_section(s: &mut String, report: &Report, images: &Images) -> Result<()> {
    let (w, h) = (images.width as usize, images.height as usize);
    let chosen = crop_rows(report);
    let windows = crops::choose(images, &chosen);
    s.push_str("<h2>Where the front's penumbrae differ most</h2>\n");
    if windows.is_empty() || images.truth_shaded.is_empty() {
        s.push_str(
            "<p>No penumbra pixel where a front configuration differs from the truth.</p>\n",
        );
        return Ok(());
    }
    let _ = writeln!(
        s,
        "<p class=\"note\">The {} windows of {side}×{side} pixels (outlined) whose penumbra pixels \
         hold the largest sum of |visibility − truth| over the configurations on a front and \
         each family's most accurate off the fronts (light 0). Per configuration, with its total \
         time (median and interquartile range): the shaded crop, its signed visibility error (red: brighter than \
         the truth, blue: darker, full colour at 0.5; grey: not a relevant pixel) and its FLIP \
         map (magma: black 0, yellow 1). The truth's column shows the regions (orange penumbra, \
         navy umbra, pale lit).</p>",
        windows.len(),
        side = windows[0].side
    );
    let overview_scale = (480 / w).max(1);
    let outlined = crops::outlined(&images.truth_shaded, w, &windows, [255, 40, 200]);
    let regions = crops::region_map(images);
    let _ = writeln!(
        s,
        "<div class=\"crops\"><figure>{}<figcaption>truth-shaded</figcaption></figure><figure>{}\
         <figcaption>regions of light 0</figcaption></figure></div>",
        img(&outlined, w, h, overview_scale, "truth-shaded image")?,
        img(
            &crops::outlined(&regions, w, &windows, [255, 40, 200]),
            w,
            h,
            overview_scale,
            "regions"
        )?
    );
    // Per front row: its error map and FLIP map, made once for every crop.
    let maps: Vec<(usize, Vec<u8>, Vec<u8>)> = chosen
        .iter()
        .filter_map(|&i| images.shaded.get(i).map(|sh| (i, sh)))
        .map(|(i, sh)| {
            let fm = flip_map(&images.truth_shaded, sh, images.width, images.height);
            (
                i,
                crops::error_map(images, i),
                magma(&fm, images.width, images.height),
            )
        })
        .collect();
    for (k, c) in windows.iter().enumerate() {
        crop_row(s, report, images, k, *c, &maps, &regions)?;
    }
    Ok(())
}

fn crop_row(
    s: &mut String,
    report: &Report,
    images: &Images,
    k: usize,
    c: Crop,
    maps: &[(usize, Vec<u8>, Vec<u8>)],
    regions: &[u8],
) -> Result<()> {
    let w = images.width as usize;
    let scale = (CROP_PX as f64 / c.side as f64).round().max(1.0) as usize;
    let _ = writeln!(
        s,
        "<h3>Crop {} at ({}, {})</h3>\n<div class=\"croprow\">",
        k + 1,
        c.x,
        c.y
    );
    let cell = |rgb: &[u8], alt: &str| img(&crops::cut(rgb, w, c), c.side, c.side, scale, alt);
    let _ = writeln!(
        s,
        "<figure>{}{}<figcaption>truth (K = {})</figcaption></figure>",
        cell(&images.truth_shaded, "truth")?,
        cell(regions, "regions")?,
        report.truth_samples
    );
    for (i, err, flip) in maps {
        let r: &Measurement = &report.rows[*i];
        let time = r.total_spread.map_or_else(
            || {
                r.total_ms
                    .map_or_else(|| "untimed".into(), |t| format!("{t:.3} ms"))
            },
            |t| format!("{} ms", t.text(3)),
        );
        let on_front = Metric::of(report)
            .iter()
            .any(|&m| front(&report.rows, m).contains(i));
        let _ = writeln!(
            s,
            "<figure>{}{}{}<figcaption class=\"crop-caption\">{}{}<br>{}<br>penumbra {:.4}, FLIP {:.4}\
             </figcaption></figure>",
            cell(&images.shaded[*i], &r.label)?,
            cell(err, "visibility error")?,
            cell(flip, "FLIP map")?,
            escape(&r.label),
            if on_front {
                ""
            } else {
                " (its family's best, off the fronts)"
            },
            escape(&time),
            r.penumbra.mean_abs,
            r.flip.mean_abs
        );
    }
    s.push_str("</div>\n");
    Ok(())
}
