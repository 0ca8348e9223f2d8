//! The Pareto plots (`pareto.svg`, `pareto_penumbra.svg`, `pareto_flip.svg`), drawn with
//! `plotters`: total GPU time (log scale) against one error [`Metric`] (log scale when it spans
//! a decade or more), one point per configuration — coloured by technique (each its own
//! colour, [`PALETTE`]), shaped by family ([`Family`]), sized by map size, with the total's
//! interquartile range as a horizontal error bar and a `<title>` tooltip — with a legend, the
//! Pareto front as a staircase, and only the front's points labelled, each label placed where
//! it overlaps no other label (see [`place_labels`]).

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

pub use super::marks::{PALETTE, colour, marker, marker_radius};
use super::marks::{draw_legend, tooltip};
use super::verdict::Family;
use super::{Measurement, Report};
use crate::error::{Error, Result};

const W: u32 = 960;
const H: u32 = 600;
/// Width of the legend column at the right.
const LEGEND: u32 = 130;
/// Font size of the front's labels (plotters' size; the SVG's is this / 1.24).
const LABEL_SIZE: f64 = 13.0;

/// What an accuracy axis measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Mean |error| against the area-light truth over the relevant pixels.
    Mean,
    /// Mean |error| over the truth's penumbra.
    Penumbra,
    /// Mean FLIP of the shaded image against the truth-shaded image.
    Flip,
    /// Mean temporal error over the scene's animation (NaN for a row without one).
    Temporal,
}

impl Metric {
    /// Every metric, in report order.
    pub const ALL: [Metric; 3] = [Metric::Mean, Metric::Penumbra, Metric::Flip];

    /// The metrics of `report`: [`Metric::ALL`], and [`Metric::Temporal`] when its scene
    /// animates.
    pub fn of(report: &Report) -> Vec<Metric> {
        let mut v = Self::ALL.to_vec();
        if report.rows.iter().any(|r| r.temporal.is_some()) {
            v.push(Metric::Temporal);
        }
        v
    }

    /// The row's value of this metric.
    pub fn value(self, r: &Measurement) -> f64 {
        match self {
            Metric::Mean => r.soft.mean_abs,
            Metric::Penumbra => r.penumbra.mean_abs,
            Metric::Flip => r.flip.mean_abs,
            Metric::Temporal => r.temporal.map_or(f64::NAN, |t| t.mean_abs),
        }
    }

    /// Short name, e.g. for a table heading.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mean => "soft mean",
            Metric::Penumbra => "penumbra mean",
            Metric::Flip => "FLIP mean",
            Metric::Temporal => "temporal mean",
        }
    }

    /// What the axis shows.
    pub fn axis(self) -> &'static str {
        match self {
            Metric::Mean => "mean |visibility − truth| (relevant pixels)",
            Metric::Penumbra => "mean |visibility − truth| over the penumbra",
            Metric::Flip => "mean FLIP, shaded vs truth-shaded image",
            Metric::Temporal => "mean |Δ visibility − Δ truth| between frames (penumbra)",
        }
    }

    /// The figure's file name.
    pub fn file(self) -> &'static str {
        match self {
            Metric::Mean => "pareto.svg",
            Metric::Penumbra => "pareto_penumbra.svg",
            Metric::Flip => "pareto_flip.svg",
            Metric::Temporal => "pareto_temporal.svg",
        }
    }
}

/// Indices of the rows on the Pareto front of (total time, `metric`), fastest first: a row
/// is on it when no row is at most as slow and at most as wrong, and better in one.
pub fn front(rows: &[Measurement], metric: Metric) -> Vec<usize> {
    let points: Vec<(Option<f64>, f64)> =
        rows.iter().map(|r| (r.total_ms, metric.value(r))).collect();
    pareto_front(&points)
}

/// Indices of the points `(time, error)` on their Pareto front, fastest first (points without
/// a time are left out): what [`front`] computes for a report's rows, and docs/MEASURED.md's
/// summary for the committed reports' (`evaluate::summary`).
pub fn pareto_front(points: &[(Option<f64>, f64)]) -> Vec<usize> {
    let mut timed: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_some())
        .collect();
    let key = |i: usize| (points[i].0.unwrap_or(0.0), points[i].1);
    timed.sort_by(|&a, &b| {
        key(a)
            .partial_cmp(&key(b))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut out = Vec::new();
    let mut best = f64::INFINITY;
    for i in timed {
        if points[i].1 < best {
            best = points[i].1;
            out.push(i);
        }
    }
    out
}

pub(super) fn plot_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Invalid(format!("pareto plot: {e}"))
}

/// The figure of `metric` as SVG text.
pub fn pareto(report: &Report, metric: Metric) -> Result<String> {
    let pts: Vec<(usize, f64, f64)> = report
        .rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let e = metric.value(r);
            r.total_ms
                .filter(|t| *t > 0.0 && t.is_finite() && e.is_finite())
                .map(|t| (i, t, e))
        })
        .collect();
    let mut svg = String::new();
    let mut marks = Vec::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let title = format!(
            "{}: total GPU time vs {}{}",
            report.scene,
            metric.name(),
            if report.cpu_driver {
                " (CPU-driver times)"
            } else {
                ""
            }
        );
        let root = root
            .titled(&title, ("sans-serif", 20))
            .map_err(plot_error)?;
        if pts.is_empty() {
            let style = ("sans-serif", 18).into_font().color(&BLACK);
            root.draw(&Text::new(
                "no timestamps on this device: nothing to plot",
                (60, (H / 2) as i32),
                style,
            ))
            .map_err(plot_error)?;
        } else {
            let quartiles = pts.iter().flat_map(|p| {
                let s = report.rows[p.0].total_spread;
                [s.map_or(p.1, |s| s.q1), s.map_or(p.1, |s| s.q3)]
            });
            let (t0, t1) = span(
                pts.iter()
                    .map(|p| p.1)
                    .chain(quartiles)
                    .filter(|t| *t > 0.0),
            );
            let (e0, e1) = span(pts.iter().map(|p| p.2));
            let (t0, t1) = (t0 / 1.3, t1 * 1.3);
            let (bold, light) = log_ticks(t0, t1);
            let x = (t0..t1)
                .log_scale()
                .with_key_points(bold)
                .with_light_points(light);
            if e0 > 0.0 && e1 / e0 >= 10.0 {
                let (e0, e1) = (e0 / 1.5, e1 * 1.5);
                let (bold, light) = log_ticks(e0, e1);
                let y = (e0..e1)
                    .log_scale()
                    .with_key_points(bold)
                    .with_light_points(light);
                marks = draw(&root, report, metric, &pts, x, y)?;
            } else {
                // plotters' own linear ticks are 1-2-5 steps already.
                marks = draw(&root, report, metric, &pts, x, 0.0..(e1 * 1.1).max(1e-4))?;
            }
        }
        root.present().map_err(plot_error)?;
    }
    // The markers, with their tooltips, drawn over the chart (plotters writes no <title>).
    if let Some(end) = svg.rfind("</svg>") {
        svg.insert_str(end, &marks.concat());
    }
    Ok(svg)
}

/// Ticks of a log axis over [lo, hi]: labelled at 1, 2 and 5 times each power of ten (every
/// integer multiple when that gives fewer than three), grid lines at every integer multiple.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let multiples = |ms: &[f64]| -> Vec<f64> {
        let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (a..=b)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let all = multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    let bold = multiples(&[1.0, 2.0, 5.0]);
    (if bold.len() >= 3 { bold } else { all.clone() }, all)
}

fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    })
}

/// Draws the chart on `root` with the x and y coordinates given (log or linear); returns the
/// points' and the legend's markers as SVG, to be drawn over it.
fn draw<X, Y>(
    root: &DrawingArea<SVGBackend, Shift>,
    report: &Report,
    metric: Metric,
    pts: &[(usize, f64, f64)],
    x: X,
    y: Y,
) -> Result<Vec<String>>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let (area, legend) = root.split_horizontally(W - LEGEND);
    let mut chart = ChartBuilder::on(&area)
        .margin(10)
        .x_label_area_size(46)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(plot_error)?;
    axes(&mut chart, metric)?;
    let rows = &report.rows;
    let f = front(rows, metric);
    // The front as a staircase (each step holds the best error until the next improvement),
    // every configuration's point, a ring around each front point.
    let stair: Vec<(f64, f64)> = f
        .iter()
        .enumerate()
        .flat_map(|(k, &i)| {
            let t = rows[i].total_ms.unwrap_or(0.0);
            let before = (k > 0).then(|| (t, metric.value(&rows[f[k - 1]])));
            before.into_iter().chain([(t, metric.value(&rows[i]))])
        })
        .collect();
    chart
        .draw_series(LineSeries::new(stair, RGBColor(0x99, 0, 0).stroke_width(2)))
        .map_err(plot_error)?;
    // Each point's interquartile range of its total time, a horizontal bar.
    let bars = pts.iter().filter_map(|&(i, _, e)| {
        let s = rows[i].total_spread?;
        let style = colour(&rows[i].technique).mix(0.7).stroke_width(2);
        Some(PathElement::new(vec![(s.q1, e), (s.q3, e)], style))
    });
    chart.draw_series(bars).map_err(plot_error)?;
    let mut marks: Vec<String> = pts
        .iter()
        .map(|&(i, t, e)| {
            let r = &rows[i];
            marker(
                "pt",
                Family::named(&r.family),
                chart.backend_coord(&(t, e)),
                marker_radius(r.shadow_map),
                colour(&r.technique),
                &tooltip(r, metric),
            )
        })
        .collect();
    let rings = f.iter().filter_map(|&i| {
        let at = (rows[i].total_ms?, metric.value(&rows[i]));
        Some(Circle::new(at, 7, BLACK.stroke_width(2)))
    });
    chart.draw_series(rings).map_err(plot_error)?;
    // Pixel positions relative to `area` (the chart's are the backend's).
    let base = area.get_base_pixel();
    let at = |t: f64, e: f64| {
        let (x, y) = chart.backend_coord(&(t, e));
        (x - base.0, y - base.1)
    };
    let points: Vec<(i32, i32)> = pts.iter().map(|&(_, t, e)| at(t, e)).collect();
    let labelled: Vec<((i32, i32), String)> = pts
        .iter()
        .filter(|p| f.contains(&p.0))
        .map(|&(i, t, e)| (at(t, e), rows[i].label.clone()))
        .collect();
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let bounds = (
        xs.start - base.0,
        ys.start - base.1,
        xs.end - base.0,
        ys.end - base.1,
    );
    draw_labels(&area, &labelled, &points, bounds)?;
    marks.extend(draw_legend(&legend, report)?);
    Ok(marks)
}

/// The grid, the ticks and the axes' names.
fn axes<X, Y>(chart: &mut ChartContext<SVGBackend, Cartesian2d<X, Y>>, metric: Metric) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc("total GPU time, ms (log scale): shadow raster + kernels + shading")
        .y_desc(metric.axis())
        .x_labels(12)
        .y_labels(10)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(plot_error)
}

/// The front's labels, placed by [`place_labels`], with their leader lines.
fn draw_labels(
    area: &DrawingArea<SVGBackend, Shift>,
    labelled: &[((i32, i32), String)],
    points: &[(i32, i32)],
    bounds: Rect,
) -> Result<()> {
    for l in place_labels(labelled, points, bounds) {
        if let Some(anchor) = l.leader {
            area.draw(&PathElement::new(
                vec![anchor, l.line_end],
                RGBColor(0x88, 0x88, 0x88).stroke_width(1),
            ))
            .map_err(plot_error)?;
        }
        let style = ("sans-serif", LABEL_SIZE).into_font().color(&BLACK);
        area.draw(&Text::new(l.text, (l.x, l.y), style))
            .map_err(plot_error)?;
    }
    Ok(())
}

/// A placed label: text at (x, y) (its top-left), and a leader line from the point to it when
/// it sits away from the point.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// The text.
    pub text: String,
    /// Left edge, pixels.
    pub x: i32,
    /// Top edge, pixels.
    pub y: i32,
    /// The labelled point, when a leader line joins it to the label.
    pub leader: Option<(i32, i32)>,
    /// Where the leader line meets the label.
    pub line_end: (i32, i32),
}

/// Estimated box of a label of `text` at `LABEL_SIZE` (sans-serif: about 0.6 em a character).
fn label_size(text: &str) -> (i32, i32) {
    let em = LABEL_SIZE / 1.24;
    (
        (0.6 * em * text.chars().count() as f64).ceil() as i32,
        em.ceil() as i32 + 2,
    )
}

type Rect = (i32, i32, i32, i32);

fn overlaps(a: Rect, b: Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Places each label near its point: the first of a ring of candidate positions (beside the
/// point, then further out with a leader line) that stays inside `bounds` and overlaps no
/// label placed before it, preferring the one that covers the fewest `points`. A label that
/// fits nowhere is placed at its least crowded candidate.
pub fn place_labels(
    labels: &[((i32, i32), String)],
    points: &[(i32, i32)],
    bounds: Rect,
) -> Vec<Label> {
    let mut placed: Vec<Rect> = Vec::new();
    let mut out = Vec::new();
    for ((px, py), text) in labels {
        let (w, h) = label_size(text);
        let mut best: Option<(i64, Rect, bool)> = None;
        for (ring, r) in [9, 26, 48, 74].into_iter().enumerate() {
            for k in 0..12 {
                let a = std::f64::consts::TAU * f64::from(k) / 12.0 - 0.5;
                let (cx, cy) = (
                    px + (f64::from(r) * a.cos()).round() as i32,
                    py + (f64::from(r) * a.sin()).round() as i32,
                );
                // Anchor the box on the side facing away from the point.
                let x = if cx >= *px { cx } else { cx - w };
                let y = if cy >= *py { cy } else { cy - h };
                let rect = (x, y, x + w, y + h);
                if rect.0 < bounds.0 || rect.1 < bounds.1 || rect.2 > bounds.2 || rect.3 > bounds.3
                {
                    continue;
                }
                let hits_label = placed.iter().filter(|&&p| overlaps(p, rect)).count() as i64;
                let hits_point = points
                    .iter()
                    .filter(|&&(qx, qy)| overlaps((qx - 4, qy - 4, qx + 4, qy + 4), rect))
                    .count() as i64;
                let cost = 1000 * hits_label + 4 * hits_point + 15 * ring as i64;
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, rect, ring > 0));
                }
            }
        }
        let Some((_, rect, leader)) = best else {
            continue;
        };
        placed.push(rect);
        let line_end = ((*px).clamp(rect.0, rect.2), (*py).clamp(rect.1, rect.3));
        out.push(Label {
            text: text.clone(),
            x: rect.0,
            y: rect.1,
            leader: leader.then_some((*px, *py)),
            line_end,
        });
    }
    out
}

/// A tick label with three significant digits, trailing zeros dropped (`0.018`, `250`).
fn tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".into();
    }
    let decimals = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every registered technique has a colour of its own (the palette does not wrap).
    #[test]
    fn every_technique_has_its_own_colour() {
        let names: Vec<&str> = crate::technique::REGISTRY.iter().map(|d| d.name).collect();
        assert!(names.len() <= PALETTE.len(), "extend PALETTE");
        for (i, a) in names.iter().enumerate() {
            for b in &names[i + 1..] {
                assert_ne!(colour(a), colour(b), "{a} and {b}");
            }
        }
    }

    /// Eight labels on points crowded into a few pixels, in a plot 600×400: every label inside
    /// the bounds and no two labels' boxes overlapping.
    #[test]
    fn crowded_labels_do_not_collide() {
        let labels: Vec<((i32, i32), String)> = (0..8)
            .map(|k| ((300 + 3 * k, 200 - 2 * k), format!("vsm f32 blur{k} 1024")))
            .collect();
        let points: Vec<(i32, i32)> = labels.iter().map(|l| l.0).collect();
        let bounds = (0, 0, 600, 400);
        let placed = place_labels(&labels, &points, bounds);
        assert_eq!(placed.len(), labels.len());
        let rects: Vec<Rect> = placed
            .iter()
            .map(|l| {
                let (w, h) = label_size(&l.text);
                (l.x, l.y, l.x + w, l.y + h)
            })
            .collect();
        for (i, a) in rects.iter().enumerate() {
            assert!(a.0 >= 0 && a.1 >= 0 && a.2 <= 600 && a.3 <= 400, "{a:?}");
            for b in &rects[i + 1..] {
                assert!(!overlaps(*a, *b), "{a:?} overlaps {b:?}");
            }
        }
    }
}
