//! `grid.png`: light 0's truth, then per configuration its visibility and its error map, each
//! cell labelled in an 8×8 bitmap font; `grid.txt` lists the cells.

use std::fmt::Write;

use image::ImageEncoder;

use super::{Images, Report};
use crate::error::{Error, Result};

/// Configurations per grid row (each takes two cells: visibility, error).
const PER_ROW: usize = 3;
/// Label band above each cell, pixels.
const BAND: usize = 12;
/// Cells are at most this wide (the image is box-downsampled by an integer factor).
const MAX_CELL: u32 = 240;
/// |error| that gets full colour.
const FULL: f64 = 0.5;

struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn put(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.w && y < self.h {
            let i = 3 * (y * self.w + x);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// ASCII text in the 8×8 font (other characters as `?`), clipped to `max_w` pixels.
    fn text(&mut self, x: usize, y: usize, s: &str, max_w: usize) {
        for (k, ch) in s.chars().enumerate() {
            if 8 * (k + 1) > max_w {
                break;
            }
            let code = if ch.is_ascii() {
                ch as usize
            } else {
                '?' as usize
            };
            let glyph = font8x8::legacy::BASIC_LEGACY[code];
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits & (1 << col) != 0 {
                        self.put(x + 8 * k + col, y + row, [255, 255, 255]);
                    }
                }
            }
        }
    }
}

/// Box-downsamples `values` (w × h) by `f` and paints them with `colour` at (x0, y0).
fn cell(
    canvas: &mut Canvas,
    x0: usize,
    y0: usize,
    (w, h): (usize, usize),
    f: usize,
    label: &str,
    colour: &dyn Fn(usize) -> [f64; 3],
) {
    let (cw, ch) = (w / f, h / f);
    for y in 0..BAND {
        for x in 0..cw {
            canvas.put(x0 + x, y0 + y, [24, 24, 24]);
        }
    }
    canvas.text(x0 + 2, y0 + 2, label, cw.saturating_sub(2));
    for cy in 0..ch {
        for cx in 0..cw {
            let mut acc = [0.0; 3];
            for dy in 0..f {
                for dx in 0..f {
                    let c = colour((cy * f + dy) * w + cx * f + dx);
                    for k in 0..3 {
                        acc[k] += c[k];
                    }
                }
            }
            let n = (f * f) as f64;
            let px = acc.map(|v| (v / n * 255.0).round().clamp(0.0, 255.0) as u8);
            canvas.put(x0 + cx, y0 + BAND + cy, px);
        }
    }
}

fn grey(v: f32) -> [f64; 3] {
    let g = f64::from(v).clamp(0.0, 1.0);
    [g, g, g]
}

/// Red where the rendering is brighter than the truth, blue where darker; grey outside the mask.
pub(super) fn error_colour(v: f32, t: f32, relevant: bool) -> [f64; 3] {
    if !relevant {
        return [0.25, 0.25, 0.25];
    }
    let e = f64::from(v) - f64::from(t);
    let a = (e.abs() / FULL).min(1.0);
    if e > 0.0 {
        [a, 0.15 * a, 0.1 * a]
    } else {
        [0.1 * a, 0.35 * a, a]
    }
}

/// The PNG bytes and the legend text.
pub fn grid(report: &Report, images: &Images) -> Result<(Vec<u8>, String)> {
    let (w, h) = (images.width as usize, images.height as usize);
    let f = images.width.div_ceil(MAX_CELL).max(1) as usize;
    let (cw, ch) = ((w / f).max(1), (h / f).max(1) + BAND);
    let rows = 1 + images.visibility.len().div_ceil(PER_ROW);
    let mut canvas = Canvas {
        w: 2 * PER_ROW * cw,
        h: rows * ch,
        rgb: vec![0; 3 * 2 * PER_ROW * cw * rows * ch],
    };
    let mut legend = String::from(
        "grid.png cells, (row, column) from 0; light 0 of the scene. Error maps: red = brighter \
         than the truth, blue = darker, full colour at |error| >= 0.5, grey = not a relevant pixel.\n",
    );
    let truth_label = format!("truth K={}", report.truth_samples);
    let truth = |i: usize| grey(images.truth[i]);
    cell(&mut canvas, 0, 0, (w, h), f, &truth_label, &truth);
    let _ = writeln!(legend, "(0, 0): {truth_label}: area-light truth visibility");
    for (k, (row, vis)) in report.rows.iter().zip(&images.visibility).enumerate() {
        let (r, c) = (1 + k / PER_ROW, 2 * (k % PER_ROW));
        let paint = |i: usize| grey(vis[i]);
        cell(&mut canvas, c * cw, r * ch, (w, h), f, &row.label, &paint);
        let err = |i: usize| error_colour(vis[i], images.truth[i], images.mask[i]);
        let err_label = format!("err {:.4}", row.soft.mean_abs);
        cell(
            &mut canvas,
            (c + 1) * cw,
            r * ch,
            (w, h),
            f,
            &err_label,
            &err,
        );
        let _ = writeln!(legend, "({r}, {c}): {}: visibility", row.label);
        let _ = writeln!(
            legend,
            "({r}, {}): {}: error against the truth, mean |error| {:.4}",
            c + 1,
            row.label,
            row.soft.mean_abs
        );
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            &canvas.rgb,
            canvas.w as u32,
            canvas.h as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Image {
            path: "grid.png".into(),
            message: e.to_string(),
        })?;
    Ok((png, legend))
}
