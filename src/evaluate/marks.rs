//! The Pareto plots' marks: each technique's colour, each point's marker (shape by family,
//! size by map side, a `<title>` tooltip) written as SVG over the chart, and the legend.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::svg::{Metric, plot_error};
use super::verdict::Family;
use super::{Measurement, Report};
use crate::error::Result;

/// The plots' colours, one per registered technique in registry order: as many as there are
/// techniques, so none shares a colour ([`colour`]; a test checks they differ).
pub const PALETTE: [[u8; 3]; 20] = [
    [0x44, 0x44, 0x44],
    [0x1f, 0x77, 0xb4],
    [0x17, 0xbe, 0xcf],
    [0x2c, 0xa0, 0x2c],
    [0xbc, 0xbd, 0x22],
    [0x8c, 0x56, 0x4b],
    [0x94, 0x67, 0xbd],
    [0xd6, 0x27, 0x28],
    [0xff, 0x7f, 0x0e],
    [0xe3, 0x77, 0xc2],
    [0x00, 0x5f, 0x3f],
    [0x8b, 0x00, 0x00],
    [0xf0, 0x02, 0x7f],
    [0x00, 0x00, 0x80],
    [0xc4, 0x9c, 0x94],
    [0x98, 0xdf, 0x8a],
    [0xae, 0xc7, 0xe8],
    [0xff, 0xbb, 0x78],
    [0x7f, 0x7f, 0x00],
    [0x9e, 0xda, 0xe5],
];

/// Colour per technique: its registry position's [`PALETTE`] entry (grey for a name not
/// registered; past the palette, a hue of its own by the golden angle).
pub fn colour(technique: &str) -> RGBColor {
    let Some(i) = crate::technique::REGISTRY
        .iter()
        .position(|d| d.name == technique)
    else {
        return RGBColor(0x7f, 0x7f, 0x7f);
    };
    match PALETTE.get(i) {
        Some(&[r, g, b]) => RGBColor(r, g, b),
        None => {
            let hue = (i as f64 * 137.508).rem_euclid(360.0);
            let c = HSLColor(hue / 360.0, 0.65, 0.45).to_rgba();
            RGBColor(c.0, c.1, c.2)
        }
    }
}

/// A marker's radius in pixels for a map of side `map`: 3 at 256², one more per doubling,
/// within [2.5, 9].
pub fn marker_radius(map: u32) -> f64 {
    (3.0 + (f64::from(map.max(1)) / 256.0).log2()).clamp(2.5, 9.0)
}

/// One point's marker as SVG: the family's shape at (x, y), `r` in radius, filled with
/// `fill`, inside a group whose `<title>` (the browser's tooltip) is `title`.
pub fn marker(
    class: &str,
    family: Family,
    (x, y): (i32, i32),
    r: f64,
    fill: RGBColor,
    title: &str,
) -> String {
    let (x, y) = (f64::from(x), f64::from(y));
    let style = format!(
        "fill=\"rgb({},{},{})\" fill-opacity=\"0.85\" stroke=\"#222\" stroke-width=\"0.6\"",
        fill.0, fill.1, fill.2
    );
    let poly = |pts: &[(f64, f64)]| {
        let p: Vec<String> = pts
            .iter()
            .map(|(a, b)| format!("{:.1},{:.1}", x + a * r, y + b * r))
            .collect();
        format!("<polygon points=\"{}\" {style}/>", p.join(" "))
    };
    let shape = match family {
        Family::Lookup => format!("<circle cx=\"{x}\" cy=\"{y}\" r=\"{r:.1}\" {style}/>"),
        Family::Search => poly(&[(-0.9, -0.9), (0.9, -0.9), (0.9, 0.9), (-0.9, 0.9)]),
        Family::Prefiltered => poly(&[(0.0, -1.2), (1.1, 0.8), (-1.1, 0.8)]),
        Family::PrefilteredSoft => poly(&[(0.0, -1.25), (1.25, 0.0), (0.0, 1.25), (-1.25, 0.0)]),
    };
    format!(
        "<g class=\"{class}\"><title>{}</title>{shape}</g>\n",
        super::html::escape(title)
    )
}

/// A point's tooltip: label, family, map, total time with its quartiles, the metric.
pub(super) fn tooltip(r: &Measurement, metric: Metric) -> String {
    let t = r.total_spread.map_or_else(
        || format!("{:.3}", r.total_ms.unwrap_or(f64::NAN)),
        |s| s.text(3),
    );
    format!(
        "{} ({}, {}² map): {t} ms total; {} {:.4}; penumbra HF {:.4}{}",
        r.label,
        r.family,
        r.shadow_map,
        metric.name(),
        metric.value(r),
        r.penumbra_hf,
        if r.clock_off {
            "; clock check off: timed at another clock"
        } else {
            ""
        }
    )
}

/// One technique per line (its colour), in the order they first appear, then the families
/// (their shapes), the map sizes (marker sizes) and the front's ring; returns the shapes'
/// markers as SVG.
pub(super) fn draw_legend(
    area: &DrawingArea<SVGBackend, Shift>,
    report: &Report,
) -> Result<Vec<String>> {
    let mut seen: Vec<&str> = Vec::new();
    for r in &report.rows {
        if !seen.contains(&r.technique.as_str()) {
            seen.push(&r.technique);
        }
    }
    let style = ("sans-serif", 15).into_font().color(&BLACK);
    area.draw(&Text::new("technique", (10, 20), style.clone()))
        .map_err(plot_error)?;
    for (k, t) in seen.iter().enumerate() {
        let y = 46 + 22 * k as i32;
        area.draw(&Circle::new((16, y), 5, colour(t).filled()))
            .map_err(plot_error)?;
        area.draw(&Text::new(t.to_string(), (28, y - 7), style.clone()))
            .map_err(plot_error)?;
    }
    let mut y = 46 + 22 * seen.len() as i32 + 8;
    area.draw(&Circle::new((16, y), 7, BLACK.stroke_width(2)))
        .map_err(plot_error)?;
    area.draw(&Text::new("Pareto front", (28, y - 7), style.clone()))
        .map_err(plot_error)?;
    let base = area.get_base_pixel();
    let small = ("sans-serif", 13).into_font().color(&BLACK);
    let mut marks = Vec::new();
    let mut families: Vec<Family> = Vec::new();
    for r in &report.rows {
        let f = Family::named(&r.family);
        if !families.contains(&f) {
            families.push(f);
        }
    }
    y += 30;
    area.draw(&Text::new("family", (10, y - 7), style.clone()))
        .map_err(plot_error)?;
    for f in families {
        y += 20;
        let grey = RGBColor(0xaa, 0xaa, 0xaa);
        marks.push(marker(
            "legend",
            f,
            (base.0 + 16, base.1 + y),
            5.0,
            grey,
            f.name(),
        ));
        area.draw(&Text::new(f.name(), (28, y - 7), small.clone()))
            .map_err(plot_error)?;
    }
    let mut sizes: Vec<u32> = report.rows.iter().map(|r| r.shadow_map).collect();
    sizes.sort_unstable();
    sizes.dedup();
    y += 30;
    area.draw(&Text::new("map side", (10, y - 7), style))
        .map_err(plot_error)?;
    for m in sizes {
        y += 20;
        let grey = RGBColor(0xaa, 0xaa, 0xaa);
        let r = marker_radius(m);
        let at = (base.0 + 16, base.1 + y);
        marks.push(marker(
            "legend",
            Family::Lookup,
            at,
            r,
            grey,
            &format!("{m}²"),
        ));
        area.draw(&Text::new(format!("{m}²"), (28, y - 7), small.clone()))
            .map_err(plot_error)?;
    }
    y += 26;
    area.draw(&PathElement::new(
        vec![(8, y), (24, y)],
        RGBColor(0x88, 0x88, 0x88).stroke_width(2),
    ))
    .map_err(plot_error)?;
    area.draw(&Text::new("time IQR", (28, y - 7), small))
        .map_err(plot_error)?;
    Ok(marks)
}
