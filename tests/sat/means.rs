//! The rectangle means of `shared/sat` against direct f64 integration of the raw map.

use super::*;

/// Means over `rects` looked up on the GPU from `table` (`shared/sat`'s exact lookup of the
/// table's variant, by the library's probe kernel: one rectangle per invocation).
fn probe(g: &Gpu, table: &wgpu::Texture, coding: &SatCoding, rects: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let lookup = match coding.variant {
        SatVariant::Fixed => Lookup::Fixed,
        SatVariant::Float => Lookup::Float,
    };
    lookup_means(g, table, lookup, coding, rects).expect("probe")
}

/// Random rectangles up to `max` texels a side, some reversed, partly or wholly outside the
/// map, thinner than the minimum extent, the whole map and the far corner.
fn rects(rng: &mut impl Rng, w: f32, h: f32, max: f32) -> Vec<[f32; 4]> {
    let mut out = vec![
        // The whole map, or the largest rectangle at the far corner.
        [(w - max).max(0.0), (h - max).max(0.0), w, h],
        [w - 0.3, h - 0.7, w, h],
        [w - 2.5, h - 1.25, w + 3.0, h + 3.0],
        [-5.0, -5.0, -1.0, -1.0],
        [w + 1.0, 3.0, w + 2.0, 4.0],
        [2.5, 1.5, 2.5, 1.5],
        [w - 1.0, h - 1.0, w - 1.0 + 1e-4, h],
    ];
    for i in 0..300 {
        let (x, y) = (
            rng.random_range(-2.0..w + 1.0),
            rng.random_range(-2.0..h + 1.0),
        );
        let sw: f32 = rng.random_range(0.0..max.min(w + 3.0));
        let sh: f32 = rng.random_range(0.0..max.min(h + 3.0));
        out.push(if i % 5 == 0 {
            [x + sw, y + sh, x, y]
        } else {
            [x, y, x + sw, y + sh]
        });
    }
    out
}

/// The lookups against direct f64 integration of the raw map. Fixed: quantization ½/scale
/// plus U·max|v − o| (the subtraction), and the f32 weighting of the 16 windows: ≲ 32 roundings
/// of Σ|w·window| ≤ (lookup area)·max|v − o|, relative to the rectangle's area. Float: the
/// same weighting, plus every window's error, ≤ (depth + 3)·U times the absolute sums at
/// its four corners, each at most the sum over [0, X₁) × [0, Y₁), X₁, Y₁ the far node.
/// Both: 4·U·(|mean| + |offset|) for the area, the division and the final add.
fn check_means(what: &str, map: &Map, coding: &SatCoding, rects: &[[f32; 4]], got: &[[f32; 4]]) {
    let input = map.texels();
    let x = reference::scaled_texels(&input, coding);
    let abs = reference::sat(&Texels {
        data: x.data.iter().map(|v| v.abs()).collect(),
        ..x.clone()
    });
    // max |v − offset| per channel.
    let mut spread = [0.0f64; 4];
    for (i, &v) in input.data.iter().enumerate() {
        let c = i % map.channels;
        spread[c] = spread[c].max((v - f64::from(coding.offset[c])).abs());
    }
    let depth = scan_depth(map.w, map.h);
    let mut gpu = Vec::new();
    let mut want = Vec::new();
    let mut tol = Vec::new();
    for (rect, g) in rects.iter().zip(got) {
        let r = reference::clamp_rect(*rect, map.w, map.h);
        let (rw, rh) = (r[2] - r[0], r[3] - r[1]);
        let area = f64::from(rw) * f64::from(rh);
        let lookup = lookup_area(rw, rh) as f64;
        let far_x = ((r[2].floor() as usize) + 1).min(map.w);
        let far_y = ((r[3].floor() as usize) + 1).min(map.h);
        let corner = reference::window(&abs, 0, 0, far_x, far_y);
        let mean = reference::rect_mean(&input, *rect);
        for c in 0..map.channels {
            let s = f64::from(coding.scale[c]);
            let o = f64::from(coding.offset[c]);
            let weighting = 32.0 * U * lookup * spread[c] / area;
            let base = weighting + 4.0 * U * (mean[c].abs() + o.abs());
            let t = match coding.variant {
                SatVariant::Fixed => base + 0.5 / s + U * spread[c],
                SatVariant::Float => base + (depth + 3.0) * U * 4.0 * corner[c] / area,
            };
            gpu.push(g[c]);
            want.push(mean[c]);
            tol.push(t);
        }
    }
    common::assert_within(what, &gpu, &want, &tol);
}

#[test]
fn rect_mean_lookups_match_direct_integration() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(74);
    let (w, h) = (300, 270);
    let map = Map::random(&mut rng, w, h, 2, 0.0, 1.0);
    let (wf, hf) = (w as f32, h as f32);
    // Any rectangle, up to the whole map: the scale for the map's lookup area.
    let whole = rects(&mut rng, wf, hf, wf.max(hf));
    // Rectangles up to 8 texels: a 2⁵-times finer scale, and the table wraps.
    let small = rects(&mut rng, wf, hf, 8.0);
    let codings = [
        (
            SatCoding::fixed(lookup_area(wf, hf), [0.0; 4], [1.0; 4]).unwrap(),
            &whole,
        ),
        (
            SatCoding::fixed(lookup_area(8.0, 8.0), [0.0; 4], [1.0; 4]).unwrap(),
            &small,
        ),
        (SatCoding::float([0.0; 4], [1.0; 4]).unwrap(), &whole),
        (SatCoding::float([0.0; 4], [1.0; 4]).unwrap(), &small),
    ];
    for (coding, rects) in codings {
        let table = build(&g, &mut exec, &map, &coding);
        let means = probe(&g, &table.texture, &coding, rects);
        check_means(
            &format!("{:?} means, scale {}", coding.variant, coding.scale[0]),
            &map,
            &coding,
            rects,
            &means,
        );
    }
}
