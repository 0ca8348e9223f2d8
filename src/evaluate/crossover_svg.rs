//! `crossover.svg`: cost per frame against the image's megapixels, one line per compared
//! configuration (moving light solid, static dashed), its measured points, the crossings
//! ringed. The axes come from `plotters`; the lines, points and rings are written over them
//! as SVG with `<title>` tooltips and classes (`xo-line`, `xo-measured`, `xo-cross`).

use std::fmt::Write;

use plotters::prelude::*;

use super::crossover::{Cost, Crossover, RANGE_MPX};
use super::html::escape;
use super::marks::colour;
use super::svg::plot_error;
use crate::error::Result;

const W: u32 = 960;
const H: u32 = 560;
/// The legend's width on the right.
const LEGEND: u32 = 280;

/// Image sizes marked on the x axis.
const MARKED: [(&str, f64); 3] = [
    ("720p", 1280.0 * 720.0 / 1e6),
    ("1080p", 1920.0 * 1080.0 / 1e6),
    ("4K", 3840.0 * 2160.0 / 1e6),
];

/// A tick's value: as many decimals as its size needs.
fn number(v: f64) -> String {
    match v.abs() {
        a if a >= 100.0 || a == 0.0 => format!("{v:.0}"),
        a if a >= 1.0 => format!("{v:.1}"),
        _ => format!("{v:.3}"),
    }
}

/// Each cost line's colour: its technique's, lighter for a technique's second and further
/// configuration (several PCSS configurations).
fn colours(c: &Crossover) -> Vec<RGBColor> {
    c.costs
        .iter()
        .enumerate()
        .map(|(k, cost)| {
            let before = c.costs[..k]
                .iter()
                .filter(|o| o.technique == cost.technique)
                .count() as f64;
            let RGBColor(r, g, b) = colour(&cost.technique);
            let t = (0.35 * before).min(0.7);
            let mix = |v: u8| (f64::from(v) + (255.0 - f64::from(v)) * t).round() as u8;
            RGBColor(mix(r), mix(g), mix(b))
        })
        .collect()
}

/// The figure as SVG text (`title` heads it).
pub fn crossover_svg(c: &Crossover, title: &str) -> Result<String> {
    let (lo, hi) = RANGE_MPX;
    let mut top: f64 = 0.0;
    for k in &c.costs {
        for moving in [true, false] {
            top = top.max(k.line(moving).at(lo)).max(k.line(moving).at(hi));
        }
        top = top.max(k.check.moving_measured);
    }
    let top = if top.is_finite() && top > 0.0 {
        top * 1.08
    } else {
        1.0
    };
    let mut svg = String::new();
    let mut over = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let root = root.titled(title, ("sans-serif", 18)).map_err(plot_error)?;
        let (area, legend) = root.split_horizontally(W - LEGEND);
        let mut chart = ChartBuilder::on(&area)
            .margin(12)
            .x_label_area_size(46)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..hi * 1.04, 0.0..top)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("image, megapixels")
            .y_desc("cost per frame, ms")
            .light_line_style(RGBColor(0xf2, 0xf2, 0xf2))
            .bold_line_style(RGBColor(0xd8, 0xd8, 0xd8))
            .x_label_formatter(&|v| format!("{v:.1}"))
            .y_label_formatter(&|v| number(*v))
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(plot_error)?;
        let grey = RGBColor(0x99, 0x99, 0x99);
        for (name, x) in MARKED {
            chart
                .draw_series([PathElement::new(vec![(x, 0.0), (x, top)], grey.mix(0.5))])
                .map_err(plot_error)?;
            let style = ("sans-serif", 12).into_font().color(&grey);
            chart
                .draw_series([Text::new(name.to_string(), (x, top), style)])
                .map_err(plot_error)?;
        }
        let px = |x: f64, y: f64| chart.backend_coord(&(x, y));
        let fill = colours(c);
        for (k, cost) in c.costs.iter().enumerate() {
            over.push_str(&lines_of(cost, fill[k], &px));
        }
        over.push_str(&rings_of(c, &px));
        legend_of(&legend, c, &fill)?;
        root.present().map_err(plot_error)?;
    }
    if let Some(end) = svg.rfind("</svg>") {
        svg.insert_str(end, &over);
    }
    Ok(svg)
}

/// Pixel coordinates of a point of the chart (megapixels, ms).
type Px<'a> = dyn Fn(f64, f64) -> (i32, i32) + 'a;

/// A configuration's two lines (moving solid, static dashed) and its measured points, as SVG.
fn lines_of(cost: &Cost, colour: RGBColor, px: &Px) -> String {
    let (lo, hi) = RANGE_MPX;
    let mut over = String::new();
    let RGBColor(r, g, b) = colour;
    for moving in [true, false] {
        let line = cost.line(moving);
        let (a, z) = (px(lo, line.at(lo)), px(hi, line.at(hi)));
        let _ = writeln!(
            over,
            "<path class=\"xo-line {}\" d=\"M{} {} L{} {}\" stroke=\"rgb({r},{g},{b})\" \
             stroke-width=\"2\" fill=\"none\"{}><title>{}</title></path>",
            if moving { "moving" } else { "static" },
            a.0,
            a.1,
            z.0,
            z.1,
            if moving {
                ""
            } else {
                " stroke-dasharray=\"7 5\""
            },
            escape(&format!(
                "{}, {} light: {:.3} + {:.3}·Mpx ms",
                cost.label,
                if moving { "moving" } else { "static" },
                line.a,
                line.b
            ))
        );
    }
    let mut dot = |x: f64, y: f64, hollow: bool, what: &str| {
        let (u, v) = px(x, y);
        let paint = if hollow {
            format!("fill=\"white\" stroke=\"rgb({r},{g},{b})\" stroke-width=\"1.5\"")
        } else {
            format!("fill=\"rgb({r},{g},{b})\"")
        };
        let _ = writeln!(
            over,
            "<g class=\"xo-measured\"><title>{}</title><circle cx=\"{u}\" cy=\"{v}\" r=\"3.5\" {paint}/></g>",
            escape(&format!("{}: {what} {y:.3} ms at {x:.3} Mpx", cost.label))
        );
    };
    for &(x, y) in &cost.shade_points {
        dot(x, y, false, "shading measured (fitted)");
    }
    let ch = cost.check;
    dot(ch.mpx, ch.static_measured, true, "shading measured (check)");
    dot(
        ch.mpx,
        ch.moving_measured,
        true,
        "moving frame measured (check)",
    );
    over
}

/// A ring at each crossing of a technique with its PCSS, as SVG.
fn rings_of(c: &Crossover, px: &Px) -> String {
    let mut over = String::new();
    for p in &c.pairs {
        let (t, q) = (&c.costs[p.config], &c.costs[p.pcss]);
        for (moving, cross) in [(true, p.moving), (false, p.still)] {
            let Some(x) = cross.mpx() else { continue };
            let (u, v) = px(x, t.line(moving).at(x));
            let _ = writeln!(
                over,
                "<g class=\"xo-cross\"><title>{}</title><circle cx=\"{u}\" cy=\"{v}\" r=\"7\" \
                 fill=\"none\" stroke=\"black\" stroke-width=\"2\"/></g>",
                escape(&format!(
                    "{} against {}, {} light: cheaper {}",
                    t.label,
                    q.label,
                    if moving { "moving" } else { "static" },
                    cross.text()
                ))
            );
        }
    }
    over
}

/// The legend: each line's label in its colour, then the styles.
fn legend_of(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    c: &Crossover,
    fill: &[RGBColor],
) -> Result<()> {
    let style = ("sans-serif", 13).into_font().color(&BLACK);
    let mut y = 30;
    for (k, cost) in c.costs.iter().enumerate() {
        area.draw(&PathElement::new(
            vec![(6, y), (30, y)],
            fill[k].stroke_width(3),
        ))
        .map_err(plot_error)?;
        area.draw(&Text::new(cost.label.clone(), (36, y - 7), style.clone()))
            .map_err(plot_error)?;
        y += 20;
    }
    y += 10;
    let black = BLACK.stroke_width(2);
    area.draw(&PathElement::new(vec![(6, y), (30, y)], black))
        .map_err(plot_error)?;
    area.draw(&Text::new(
        "moving light (every frame)",
        (36, y - 7),
        style.clone(),
    ))
    .map_err(plot_error)?;
    y += 20;
    for x in [6, 18] {
        area.draw(&PathElement::new(vec![(x, y), (x + 8, y)], black))
            .map_err(plot_error)?;
    }
    area.draw(&Text::new(
        "static light (shading only)",
        (36, y - 7),
        style.clone(),
    ))
    .map_err(plot_error)?;
    y += 22;
    area.draw(&Circle::new((18, y), 7, black))
        .map_err(plot_error)?;
    area.draw(&Text::new(
        "crossing with its PCSS",
        (36, y - 7),
        style.clone(),
    ))
    .map_err(plot_error)?;
    y += 22;
    area.draw(&Circle::new((18, y), 3, BLACK.filled()))
        .map_err(plot_error)?;
    area.draw(&Text::new(
        "measured, fitted (hollow: check)",
        (36, y - 7),
        style,
    ))
    .map_err(plot_error)?;
    Ok(())
}
