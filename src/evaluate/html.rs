//! `report.html`: one self-contained page (every image a `data:` URI, the style and the
//! table-sorting script inline, a Content-Security-Policy that lets nothing else load): the
//! three Pareto plots, a sortable table of every configuration, and crops of the truth and of
//! each front configuration where their penumbrae differ most from it, with error maps.

use std::fmt::Write;

use base64::Engine;

use super::crops::{self, Crop};
use super::flip::{flip_map, magma};
use super::output::{region_text, wall_check};
use super::svg::{Metric, colour, front};
use super::{ErrorStats, Images, Report, Row};
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
figcaption{max-width:180px;overflow-wrap:anywhere}.note{color:#555}";

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

fn escape(s: &str) -> String {
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
pub fn html(report: &Report, images: &Images, plots: &[(Metric, String)]) -> Result<String> {
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
    let _ = writeln!(
        s,
        "<p>Device: {}. Image {}×{}, {} relevant pixels. Ground truth: the area light sampled \
         at K = {} points, {:?}² hard shadow maps. {}</p>\n<p class=\"note\">{}</p>",
        escape(&report.device),
        report.image.0,
        report.image.1,
        report.relevant_pixels,
        report.truth_samples,
        report.truth_resolution,
        if report.cpu_driver {
            "<b>Times are CPU-driver times</b> (a software Vulkan driver): compare \
             configurations with each other only."
        } else {
            ""
        },
        emphasis(&escape(&region_text(report)))
    );
    s.push_str("<h2>Time against error: the Pareto fronts</h2>\n");
    for (m, svg) in plots {
        let _ = writeln!(
            s,
            "<div class=\"plot\"><img src=\"{}\" alt=\"total time vs {}\" width=\"960\"></div>",
            data_uri("image/svg+xml", svg.as_bytes()),
            m.name()
        );
    }
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
    Metric::ALL
        .iter()
        .filter(|&&m| front(&report.rows, m).contains(&i))
        .map(|m| match m {
            Metric::Mean => "M",
            Metric::Penumbra => "P",
            Metric::Flip => "F",
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
         (F).</p>\n<table class=\"sortable\"><thead><tr>",
    );
    for h in [
        "configuration",
        "map",
        "raster",
        "kernels",
        "shade",
        "total",
        "wall",
        "MiB",
        "soft mean",
        "soft p99",
        "penumbra mean",
        "penumbra p99",
        "umbra mean",
        "lit mean",
        "FLIP mean",
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
        for t in [r.raster_ms, r.kernels_ms, r.shade_ms, r.total_ms, r.wall_ms] {
            s.push_str(&num(t, 2));
        }
        s.push_str(&num(Some(r.memory_bytes as f64 / 1048576.0), 1));
        s.push_str(&num(Some(r.soft.mean_abs), 4));
        s.push_str(&num(Some(r.soft.p99), 3));
        s.push_str(&num(region_mean(&r.penumbra), 4));
        s.push_str(&num(region_mean(&r.penumbra).map(|_| r.penumbra.p99), 3));
        s.push_str(&num(region_mean(&r.umbra), 4));
        s.push_str(&num(region_mean(&r.lit), 4));
        s.push_str(&num(Some(r.flip.mean_abs), 4));
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
    let mut all: Vec<usize> = Metric::ALL
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

fn crop_section(s: &mut String, report: &Report, images: &Images) -> Result<()> {
    let (w, h) = (images.width as usize, images.height as usize);
    let chosen = front_rows(report);
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
         hold the largest sum of |visibility − truth| over the configurations on a front (light \
         0). Per configuration: the shaded crop, its signed visibility error (red: brighter than \
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
        let r: &Row = &report.rows[*i];
        let _ = writeln!(
            s,
            "<figure>{}{}{}<figcaption>{}<br>penumbra {:.4}, FLIP {:.4}</figcaption></figure>",
            cell(&images.shaded[*i], &r.label)?,
            cell(err, "visibility error")?,
            cell(flip, "FLIP map")?,
            escape(&r.label),
            r.penumbra.mean_abs,
            r.flip.mean_abs
        );
    }
    s.push_str("</div>\n");
    Ok(())
}
