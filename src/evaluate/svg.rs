//! `pareto.svg`, written by hand: total GPU time (log scale) against the mean error over the
//! area-light truth, one labelled point per configuration, the Pareto front as a staircase.

use std::fmt::Write;

use super::{Report, Row};

const W: f64 = 960.0;
const H: f64 = 640.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 30.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

/// Colour per technique (by name), so families read at a glance.
fn colour(technique: &str) -> &'static str {
    match technique {
        "hard" => "#444444",
        "pcf" => "#1f77b4",
        "pcss" => "#17becf",
        "vsm" => "#2ca02c",
        "evsm2" => "#bcbd22",
        "evsm4" => "#8c564b",
        "esm" => "#9467bd",
        "msm" => "#d62728",
        "csm" => "#ff7f0e",
        _ => "#7f7f7f",
    }
}

/// Indices of the rows on the Pareto front of (total time, soft mean error), fastest first:
/// a row is on it when no row is at most as slow and at most as wrong, and better in one.
pub fn front(rows: &[Row]) -> Vec<usize> {
    let mut timed: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].total_ms.is_some())
        .collect();
    timed.sort_by(|&a, &b| {
        let key = |i: usize| (rows[i].total_ms.unwrap_or(0.0), rows[i].soft.mean_abs);
        key(a)
            .partial_cmp(&key(b))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut out = Vec::new();
    let mut best = f64::INFINITY;
    for i in timed {
        if rows[i].soft.mean_abs < best {
            best = rows[i].soft.mean_abs;
            out.push(i);
        }
    }
    out
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The figure.
pub fn pareto(report: &Report) -> String {
    let rows = &report.rows;
    let pts: Vec<(usize, f64, f64)> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            r.total_ms
                .filter(|t| *t > 0.0)
                .map(|t| (i, t, r.soft.mean_abs))
        })
        .collect();
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let title = format!(
        "{}: total GPU time vs mean |error| against the area-light truth{}",
        report.scene,
        if report.cpu_driver {
            " (CPU-driver times)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" font-size="15" text-anchor="middle">{}</text>"#,
        W / 2.0,
        escape(&title)
    );
    if pts.is_empty() {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" font-size="14" text-anchor="middle">no timestamps on this device: nothing to plot</text></svg>"#,
            W / 2.0,
            H / 2.0
        );
        return s;
    }
    let (mut t0, mut t1) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.1), b.max(p.1))
    });
    t0 = 10f64.powf(t0.log10().floor());
    t1 = 10f64.powf(t1.log10().ceil());
    if t1 <= t0 {
        t1 = t0 * 10.0;
    }
    let e1 = pts.iter().map(|p| p.2).fold(0.0, f64::max).max(1e-6) * 1.08;
    let x =
        |t: f64| LEFT + (t.log10() - t0.log10()) / (t1.log10() - t0.log10()) * (W - LEFT - RIGHT);
    let y = |e: f64| H - BOTTOM - e / e1 * (H - TOP - BOTTOM);
    axes(&mut s, t0, t1, e1, &x, &y);
    let f = front(rows);
    let mut path = String::new();
    for (k, &i) in f.iter().enumerate() {
        let (px, py) = (x(rows[i].total_ms.unwrap_or(t0)), y(rows[i].soft.mean_abs));
        if k == 0 {
            let _ = write!(path, "M{px:.1},{py:.1}");
        } else {
            let _ = write!(path, " H{px:.1} V{py:.1}");
        }
    }
    let _ = writeln!(
        s,
        "<path d=\"{path}\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"1.5\" stroke-dasharray=\"5,3\"/>"
    );
    for &(i, t, e) in &pts {
        let r = &rows[i];
        let on = f.contains(&i);
        let _ = writeln!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"{}\" fill=\"{}\" stroke=\"black\" stroke-width=\"{}\"><title>{}</title></circle>",
            x(t),
            y(e),
            if on { 5.0 } else { 3.5 },
            colour(&r.technique),
            if on { 1.2 } else { 0.3 },
            escape(&r.label)
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="8" fill="{}">{}</text>"#,
            x(t) + 5.0,
            y(e) - 3.0,
            colour(&r.technique),
            escape(&r.label)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn axes(s: &mut String, t0: f64, t1: f64, e1: f64, x: &dyn Fn(f64) -> f64, y: &dyn Fn(f64) -> f64) {
    let (xl, xr, yb, yt) = (LEFT, W - RIGHT, H - BOTTOM, TOP);
    let _ = writeln!(
        s,
        r#"<path d="M{xl},{yt} V{yb} H{xr}" fill="none" stroke="black"/>"#
    );
    let mut decade = t0;
    while decade <= t1 * 1.0001 {
        for m in [1.0, 2.0, 5.0] {
            let t = decade * m;
            if t > t1 * 1.0001 {
                break;
            }
            let px = x(t);
            let _ = writeln!(
                s,
                "<line x1=\"{px:.1}\" y1=\"{yt}\" x2=\"{px:.1}\" y2=\"{yb}\" stroke=\"#dddddd\"/>"
            );
            let _ = writeln!(
                s,
                r#"<text x="{px:.1}" y="{}" font-size="11" text-anchor="middle">{}</text>"#,
                yb + 16.0,
                trim(t)
            );
        }
        decade *= 10.0;
    }
    for k in 0..=5 {
        let e = e1 * f64::from(k) / 5.0;
        let py = y(e);
        let _ = writeln!(
            s,
            "<line x1=\"{xl}\" y1=\"{py:.1}\" x2=\"{xr}\" y2=\"{py:.1}\" stroke=\"#dddddd\"/>"
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{:.1}" font-size="11" text-anchor="end">{e:.3}</text>"#,
            xl - 6.0,
            py + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13" text-anchor="middle">total GPU time, ms (log scale): shadow raster + kernels + shading</text>"#,
        (xl + xr) / 2.0,
        H - 18.0
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{}" font-size="13" text-anchor="middle" transform="rotate(-90 18 {})">mean |visibility − truth|</text>"#,
        (yt + yb) / 2.0,
        (yt + yb) / 2.0
    );
}

fn trim(t: f64) -> String {
    let s = format!("{t:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
