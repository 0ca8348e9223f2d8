//! Where `report.html` looks closely: square crops of light 0's image at the penumbrae where
//! the Pareto fronts' configurations are furthest from the truth, and the small images shown
//! there (shaded crops, signed error maps, FLIP maps, the region map).

use super::Images;
use super::grid::error_colour;
use super::stats::Region;
use crate::error::{Error, Result};

/// Crops per report.
pub const CROPS: usize = 3;

/// A square window of the image: top-left corner and side, pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// Left column.
    pub x: usize,
    /// Top row.
    pub y: usize,
    /// Side.
    pub side: usize,
}

/// The crop side for a `w × h` image: a quarter of its shorter side, within [16, 96].
pub fn crop_side(w: usize, h: usize) -> usize {
    (w.min(h) / 4).clamp(16, 96).min(w.min(h))
}

/// Up to [`CROPS`] windows at least half a side apart, best first, maximizing the sum over the window's
/// penumbra pixels (light 0) of Σ_c |v_c − truth| over the configurations `chosen`; windows
/// whose sum is 0 are not returned.
pub fn choose(images: &Images, chosen: &[usize]) -> Vec<Crop> {
    let (w, h) = (images.width as usize, images.height as usize);
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let side = crop_side(w, h);
    // Integral image of the score, (w + 1) × (h + 1).
    let mut sat = vec![0.0f64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0.0;
        for x in 0..w {
            let px = y * w + x;
            if images.regions.get(px) == Some(&Region::Penumbra) {
                let t = f64::from(images.truth[px]);
                row += chosen
                    .iter()
                    .filter_map(|&c| images.visibility.get(c))
                    .map(|v| (f64::from(v[px]) - t).abs())
                    .sum::<f64>();
            }
            sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + row;
        }
    }
    let sum = |x: usize, y: usize| {
        let at = |x: usize, y: usize| sat[y * (w + 1) + x];
        at(x + side, y + side) - at(x, y + side) - at(x + side, y) + at(x, y)
    };
    let step = (side / 8).max(1);
    let mut out: Vec<Crop> = Vec::new();
    while out.len() < CROPS {
        let mut best: Option<(f64, Crop)> = None;
        for y in (0..=h - side).step_by(step) {
            for x in (0..=w - side).step_by(step) {
                let c = Crop { x, y, side };
                let gap = side + side / 2;
                let free = out
                    .iter()
                    .all(|o| x + gap <= o.x || o.x + gap <= x || y + gap <= o.y || o.y + gap <= y);
                let s = sum(x, y);
                if free && s > 0.0 && best.is_none_or(|b| s > b.0) {
                    best = Some((s, c));
                }
            }
        }
        match best {
            Some((_, c)) => out.push(c),
            None => break,
        }
    }
    out
}

/// The pixels of `crop` of an RGB8 image `w` wide.
pub fn cut(rgb: &[u8], w: usize, crop: Crop) -> Vec<u8> {
    let mut out = Vec::with_capacity(3 * crop.side * crop.side);
    for y in crop.y..crop.y + crop.side {
        let row = 3 * (y * w + crop.x);
        out.extend_from_slice(&rgb[row..row + 3 * crop.side]);
    }
    out
}

fn to_rgb8(c: [f64; 3]) -> [u8; 3] {
    c.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8)
}

/// Light 0's signed error map of row `row` (red = brighter than the truth, blue = darker, full
/// colour at |error| ≥ 0.5, grey outside the relevant pixels), RGB8.
pub fn error_map(images: &Images, row: usize) -> Vec<u8> {
    let v = &images.visibility[row];
    (0..v.len())
        .flat_map(|i| to_rgb8(error_colour(v[i], images.truth[i], images.mask[i])))
        .collect()
}

/// Light 0's regions: penumbra orange, umbra dark blue, lit pale yellow, others grey. RGB8.
pub fn region_map(images: &Images) -> Vec<u8> {
    images
        .regions
        .iter()
        .flat_map(|r| match r {
            Region::Penumbra => [240, 140, 30],
            Region::Umbra => [30, 40, 110],
            Region::Lit => [250, 240, 190],
            Region::Outside => [90, 90, 90],
        })
        .collect()
}

/// `rgb` (`w` wide) with each crop's outline drawn in `colour`.
pub fn outlined(rgb: &[u8], w: usize, crops: &[Crop], colour: [u8; 3]) -> Vec<u8> {
    let mut out = rgb.to_vec();
    let mut put = |x: usize, y: usize| {
        let i = 3 * (y * w + x);
        if i + 3 <= out.len() {
            out[i..i + 3].copy_from_slice(&colour);
        }
    };
    for c in crops {
        let (x1, y1) = (c.x + c.side - 1, c.y + c.side - 1);
        for k in 0..c.side {
            put(c.x + k, c.y);
            put(c.x + k, y1);
            put(c.x, c.y + k);
            put(x1, c.y + k);
        }
    }
    out
}

/// PNG bytes of an RGB8 image.
pub fn png(rgb: &[u8], w: usize, h: usize) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, w as u32, h as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::Image {
            path: "report.html".into(),
            message: e.to_string(),
        })?;
    Ok(out)
}
