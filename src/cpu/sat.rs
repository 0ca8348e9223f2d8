//! References of the summed-area-table kernels (`kernels/sat_*.wgsl`) and of the lookups of
//! `kernels/shared/sat.wgsl`: the coding of one value (in f32, as the kernels do it), the f64
//! SAT, the wrapping-u32 SAT (the integer reference a fixed-point table must equal bit for
//! bit), window sums, and the mean over a rectangle by direct integration over the texels it
//! overlaps (independent of any table).

use super::Texels;
use crate::sat::SatCoding;

/// `SAT_MIN_EXTENT` of `kernels/shared/sat.wgsl`: thinner rectangles are widened to it.
pub const MIN_EXTENT: f32 = 1.0 / 256.0;

/// `(v − offset)·scale` clamped to `±limit` for channel `c`, in f32 like `sat_encode`.
pub fn scaled(v: f32, coding: &SatCoding, c: usize) -> f32 {
    ((v - coding.offset[c]) * coding.scale[c]).clamp(-coding.limit[c], coding.limit[c])
}

/// The fixed-point code of `v`: `scaled` rounded to nearest, ties to even (WGSL's `round`),
/// as a two's-complement u32.
pub fn encode_fixed(v: f32, coding: &SatCoding, c: usize) -> u32 {
    scaled(v, coding, c).round_ties_even() as i32 as u32
}

/// The values the kernels sum, 4 channels: `scaled` per used channel of `input` (as f64,
/// exactly), 0 for the channels `input` does not have.
pub fn scaled_texels(input: &Texels, coding: &SatCoding) -> Texels {
    let mut data = vec![0.0; input.width * input.height * 4];
    for (i, texel) in input.data.chunks(input.channels).enumerate() {
        for (c, &v) in texel.iter().enumerate().take(4) {
            data[i * 4 + c] = f64::from(scaled(v as f32, coding, c));
        }
    }
    Texels {
        width: input.width,
        height: input.height,
        channels: 4,
        data,
    }
}

/// Inclusive summed-area table in f64: texel (x, y) is the sum over `[0, x] × [0, y]`.
pub fn sat(t: &Texels) -> Texels {
    let (w, h, n) = (t.width, t.height, t.channels);
    let mut data = t.data.clone();
    for y in 0..h {
        for x in 1..w {
            for c in 0..n {
                data[(y * w + x) * n + c] += data[(y * w + x - 1) * n + c];
            }
        }
    }
    for y in 1..h {
        for x in 0..w {
            for c in 0..n {
                data[(y * w + x) * n + c] += data[((y - 1) * w + x) * n + c];
            }
        }
    }
    Texels { data, ..t.clone() }
}

/// The fixed-point table: codes of `input` (4 channels, unused ones 0) summed with u32
/// wraparound, row-major.
pub fn sat_fixed(input: &Texels, coding: &SatCoding) -> Vec<[u32; 4]> {
    let (w, h) = (input.width, input.height);
    let mut out = vec![[0u32; 4]; w * h];
    for (i, texel) in input.data.chunks(input.channels).enumerate() {
        for (c, &v) in texel.iter().enumerate().take(4) {
            out[i][c] = encode_fixed(v as f32, coding, c);
        }
    }
    let add = |a: [u32; 4], b: [u32; 4]| std::array::from_fn(|c| a[c].wrapping_add(b[c]));
    for y in 0..h {
        for x in 1..w {
            out[y * w + x] = add(out[y * w + x], out[y * w + x - 1]);
        }
    }
    for y in 1..h {
        for x in 0..w {
            out[y * w + x] = add(out[y * w + x], out[(y - 1) * w + x]);
        }
    }
    out
}

/// `F(X, Y)`, the sum over `[0, X) × [0, Y)`, from an inclusive table (0 on the top/left edge).
fn node<T: Copy>(table: &[T], width: usize, x: usize, y: usize, zero: T) -> T {
    if x == 0 || y == 0 {
        zero
    } else {
        table[(y - 1) * width + x - 1]
    }
}

/// Sum over the integer window `[x0, x1) × [y0, y1)` from an f64 table, four lookups.
pub fn window(sat: &Texels, x0: usize, y0: usize, x1: usize, y1: usize) -> Vec<f64> {
    let n = sat.channels;
    let at = |x, y| -> Vec<f64> {
        if x == 0 || y == 0 {
            vec![0.0; n]
        } else {
            sat.at(x as i64 - 1, y as i64 - 1).to_vec()
        }
    };
    let (a, b, c, d) = (at(x1, y1), at(x0, y1), at(x1, y0), at(x0, y0));
    (0..n).map(|k| a[k] - b[k] - c[k] + d[k]).collect()
}

/// Sum over `[x0, x1) × [y0, y1)` from a fixed-point table with wrapping subtraction, read
/// as i32: the exact sum of the codes whenever that sum fits an i32.
pub fn window_fixed(
    table: &[[u32; 4]],
    width: usize,
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
) -> [i32; 4] {
    let f = |x, y| node(table, width, x, y, [0u32; 4]);
    let (a, b, c, d) = (f(x1, y1), f(x0, y1), f(x1, y0), f(x0, y0));
    std::array::from_fn(|k| {
        a[k].wrapping_sub(b[k])
            .wrapping_sub(c[k])
            .wrapping_add(d[k]) as i32
    })
}

/// Decodes a window sum of codes over `area` texels of channel `c` to a sum of values.
pub fn decode_window(sum: f64, area: f64, coding: &SatCoding, c: usize) -> f64 {
    sum / f64::from(coding.scale[c]) + area * f64::from(coding.offset[c])
}

/// The rectangle `sat_nodes` looks up: ordered, clamped to a `width × height` map and
/// widened to [`MIN_EXTENT`], computed in f32 as the shader does. `(x0, y0, x1, y1)`.
pub fn clamp_rect(rect: [f32; 4], width: usize, height: usize) -> [f32; 4] {
    let size = [width as f32, height as f32];
    let mut out = [0.0; 4];
    for a in 0..2 {
        let lo = rect[a].min(rect[a + 2]).clamp(0.0, size[a]);
        let hi = rect[a].max(rect[a + 2]).clamp(0.0, size[a]);
        let lo = lo.min(size[a] - MIN_EXTENT);
        out[a] = lo;
        out[a + 2] = hi.max(lo + MIN_EXTENT);
    }
    out
}

/// Mean of `t` (piecewise constant: texel (i, j) covers `[i, i + 1) × [j, j + 1)`) over the
/// rectangle `rect` in texel units after [`clamp_rect`], by direct f64 integration of the
/// overlap of every texel; 4 values (channels `t` lacks are 0).
pub fn rect_mean(t: &Texels, rect: [f32; 4]) -> [f64; 4] {
    let [x0, y0, x1, y1] = clamp_rect(rect, t.width, t.height).map(f64::from);
    let overlap = |lo: f64, hi: f64, i: usize| (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0);
    let mut sum = [0.0; 4];
    for j in (y0.floor() as usize)..(y1.ceil() as usize).min(t.height) {
        let wy = overlap(y0, y1, j);
        for i in (x0.floor() as usize)..(x1.ceil() as usize).min(t.width) {
            let w = wy * overlap(x0, x1, i);
            for (c, v) in t.at(i as i64, j as i64).iter().enumerate().take(4) {
                sum[c] += w * v;
            }
        }
    }
    let area = (x1 - x0) * (y1 - y0);
    sum.map(|s| s / area)
}
