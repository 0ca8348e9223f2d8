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

/// A table's raw words (`texels` texels, as many words each as the table's format has
/// channels) widened to four words a texel, the channels it lacks 0: the shape of
/// [`sat_fixed`] whatever the table's channel count.
pub fn widen(words: &[u32], texels: usize) -> Vec<[u32; 4]> {
    let stride = words.len() / texels.max(1);
    words
        .chunks(stride.max(1))
        .take(texels)
        .map(|t| std::array::from_fn(|c| t.get(c).copied().unwrap_or(0)))
        .collect()
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

/// The step of the grid filtered table lookups put their corners on: 2⁻⁸ texel, the weight
/// precision of bilinear filtering hardware (`SAT_GRID` in `kernels/shared/sat.wgsl`).
pub const GRID: f32 = 1.0 / 256.0;

/// `rect` after [`clamp_rect`] with its edges on the [`GRID`] (nearest, ties up) and at least one
/// step wide, in f32 as `sat_grid` in `kernels/shared/sat.wgsl` computes it.
pub fn grid_rect(rect: [f32; 4], width: usize, height: usize) -> [f32; 4] {
    let c = clamp_rect(rect, width, height);
    let snap = |v: f32| (v * 256.0 + 0.5).floor() / 256.0;
    let (x0, y0) = (snap(c[0]), snap(c[1]));
    [x0, y0, snap(c[2]).max(x0 + GRID), snap(c[3]).max(y0 + GRID)]
}

/// The square of `width` texels centred on `uv` (formed in f32 as `sat_rect` forms it) with
/// its edges rounded to the nearest texel edges, ties to even, at least one texel wide
/// (`sat_nearest` in `kernels/shared/sat_lookup.wgsl`), before clamping: (x0, y0, x1, y1).
pub fn nearest_square(map_size: [f32; 2], uv: [f64; 2], width: f64) -> [f32; 4] {
    let [x0, y0, x1, y1] = square(map_size, uv, width).map(f32::round_ties_even);
    [x0, y0, x1.max(x0 + 1.0), y1.max(y0 + 1.0)]
}

/// The square of `width` texels centred on `uv`, formed in f32 as `sat_rect` in
/// `kernels/shared/sat_lookup.wgsl` forms it: (x0, y0, x1, y1), texel units.
pub fn square(map_size: [f32; 2], uv: [f64; 2], width: f64) -> [f32; 4] {
    let (cx, cy) = (uv[0] as f32 * map_size[0], uv[1] as f32 * map_size[1]);
    let h = 0.5 * width as f32;
    [cx - h, cy - h, cx + h, cy + h]
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

/// The integral image of a piecewise-constant map in f64, for exact rectangle means in O(1):
/// `F(X, Y)` at integer nodes is the sum over `[0, X) × [0, Y)`; inside a texel F is bilinear,
/// so F at a fractional corner is the bilinear mix of its four nodes. The soft techniques'
/// references read their squares through it (a direct integration like [`rect_mean`] costs
/// the square's area per lookup); f64 keeps its error near 2⁻⁵³ of the map's total sum.
#[derive(Clone, Debug)]
pub struct Integral {
    width: usize,
    height: usize,
    channels: usize,
    /// `(width + 1)·(height + 1)` nodes of `channels` values each, row-major.
    nodes: Vec<f64>,
    /// The table is f32 and read with filtered fetches: [`Self::filter_square_mean`] is the
    /// exact square on the 2⁻⁸-texel grid ([`grid_rect`]), not the rounded one.
    filtered: bool,
}

impl Integral {
    /// The integral image of `t`.
    pub fn new(t: &Texels) -> Self {
        let (w, h, n) = (t.width, t.height, t.channels);
        let mut nodes = vec![0.0; (w + 1) * (h + 1) * n];
        for y in 0..h {
            for x in 0..w {
                for c in 0..n {
                    let at = |x: usize, y: usize| (y * (w + 1) + x) * n + c;
                    nodes[at(x + 1, y + 1)] =
                        t.data[(y * w + x) * n + c] + nodes[at(x, y + 1)] + nodes[at(x + 1, y)]
                            - nodes[at(x, y)];
                }
            }
        }
        Self {
            width: w,
            height: h,
            channels: n,
            nodes,
            filtered: false,
        }
    }

    /// The same integral for a table read with filtered fetches (`filtered`: an f32 table,
    /// `sat_sums = "float"`) or with loads.
    pub fn filtered(self, filtered: bool) -> Self {
        Self { filtered, ..self }
    }

    /// Whether [`Self::filter_square_mean`] reads the square on the 2⁻⁸ grid of filtered
    /// fetches ([`Self::filtered`]).
    pub fn is_filtered(&self) -> bool {
        self.filtered
    }

    /// How far [`Self::grid_square_mean`] moves, per channel, when each edge of its grid
    /// rectangle may land one grid step either way: the sum over the four edges of the larger
    /// change of one step in or out. A device whose square differs from the f64 one by less
    /// than half a step (its edges' f32 error) picks the same or the next grid point.
    pub fn grid_flip_error(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        let r = grid_rect(square(map_size, uv, width), self.width, self.height);
        let base = self.rect_mean(r);
        let mut out = vec![0.0; self.channels];
        for edge in 0..4 {
            let mut worst = vec![0.0f64; self.channels];
            for step in [-GRID, GRID] {
                let mut moved = r;
                moved[edge] += step;
                for (c, m) in self.rect_mean(moved).iter().enumerate() {
                    worst[c] = worst[c].max((m - base[c]).abs());
                }
            }
            for c in 0..self.channels {
                out[c] += worst[c];
            }
        }
        out
    }

    /// Channels per texel.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// `F(x, y)` of channel `c` at a point of `[0, width] × [0, height]`.
    fn f(&self, x: f64, y: f64, c: usize) -> f64 {
        let (w, n) = (self.width, self.channels);
        let i = (x.floor() as usize).min(self.width.saturating_sub(1));
        let j = (y.floor() as usize).min(self.height.saturating_sub(1));
        let (ax, ay) = (x - i as f64, y - j as f64);
        let node = |x: usize, y: usize| self.nodes[(y * (w + 1) + x) * n + c];
        (1.0 - ay) * ((1.0 - ax) * node(i, j) + ax * node(i + 1, j))
            + ay * ((1.0 - ax) * node(i, j + 1) + ax * node(i + 1, j + 1))
    }

    /// The mean over `rect` (texel units) after [`clamp_rect`], every channel.
    pub fn rect_mean(&self, rect: [f32; 4]) -> Vec<f64> {
        let [x0, y0, x1, y1] = clamp_rect(rect, self.width, self.height).map(f64::from);
        let area = (x1 - x0) * (y1 - y0);
        (0..self.channels)
            .map(|c| {
                (self.f(x1, y1, c) - self.f(x0, y1, c) - self.f(x1, y0, c) + self.f(x0, y0, c))
                    / area
            })
            .collect()
    }

    /// The mean over the square of `width` texels centred on `uv`, formed in f32 as
    /// `sat_rect` in `kernels/shared/sat_lookup.wgsl` forms it (`sat_sample_*`).
    pub fn square_mean(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        self.rect_mean(square(map_size, uv, width))
    }

    /// The mean over the square of [`Self::square_mean`] with its edges rounded to the nearest
    /// texel edges (ties to even, as WGSL's `round`) and at least one texel wide, then
    /// [`clamp_rect`] (`sat_filter_*`, the soft techniques' filter).
    pub fn nearest_square_mean(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        let r = clamp_rect(nearest_square(map_size, uv, width), self.width, self.height);
        self.rect_mean([r[0].floor(), r[1].floor(), r[2].ceil(), r[3].ceil()])
    }

    /// The mean over the square of [`Self::square_mean`] as the soft techniques' filter reads
    /// it (CSSM's): from a table read with loads, [`Self::nearest_square_mean`]; from one read with
    /// filtered fetches ([`Self::filtered`]), the square itself on the 2⁻⁸-texel grid
    /// ([`grid_rect`], `sat_filter_float`).
    pub fn filter_square_mean(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        if self.filtered {
            self.grid_square_mean(map_size, uv, width)
        } else {
            self.nearest_square_mean(map_size, uv, width)
        }
    }

    /// The mean over the square of [`Self::square_mean`] as `vssm` and `msm_soft` read it
    /// (`sat_filter_*`): exact from a table read with loads, on the 2⁻⁸-texel grid
    /// ([`Self::grid_square_mean`]) from one read with filtered fetches.
    pub fn exact_filter_square_mean(
        &self,
        map_size: [f32; 2],
        uv: [f64; 2],
        width: f64,
    ) -> Vec<f64> {
        if self.filtered {
            self.grid_square_mean(map_size, uv, width)
        } else {
            self.square_mean(map_size, uv, width)
        }
    }

    /// The mean over the square of [`Self::square_mean`] after [`grid_rect`]: the rectangle
    /// four filtered fetches of an f32 table integrate (`sat_mean_linear`).
    pub fn grid_square_mean(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        self.rect_mean(grid_rect(
            square(map_size, uv, width),
            self.width,
            self.height,
        ))
    }

    /// The mean over the square of [`Self::square_mean`] snapped outward to texel edges after
    /// [`clamp_rect`]: `[⌊x0⌋, ⌈x1⌉) × [⌊y0⌋, ⌈y1⌉)` (`sat_search_*`, the blocker search).
    pub fn snapped_square_mean(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> Vec<f64> {
        self.rect_mean(self.snapped_square(map_size, uv, width))
    }

    /// The square of [`Self::snapped_square_mean`], `[X0, Y0, X1, Y1]` in whole texels.
    fn snapped_square(&self, map_size: [f32; 2], uv: [f64; 2], width: f64) -> [f32; 4] {
        let (cx, cy) = (uv[0] as f32 * map_size[0], uv[1] as f32 * map_size[1]);
        let h = 0.5 * width as f32;
        let r = clamp_rect([cx - h, cy - h, cx + h, cy + h], self.width, self.height);
        [r[0].floor(), r[1].floor(), r[2].ceil(), r[3].ceil()]
    }

    /// The square of [`Self::snapped_square_mean`] cut at texel edges into `n × n` cells, edge
    /// `k` of the span `[lo, hi)` at `lo + ⌊k·(hi − lo)/n⌋` (`sat_search_cells_*`): each
    /// cell's mean and area in texels, row by row. An empty cell (a square narrower than `n`
    /// texels) has area 0 and no mean (an empty vector).
    pub fn search_cells(
        &self,
        map_size: [f32; 2],
        uv: [f64; 2],
        width: f64,
        n: u32,
    ) -> Vec<(Vec<f64>, f64)> {
        let [x0, y0, x1, y1] = self.snapped_square(map_size, uv, width).map(|e| e as i64);
        let edge = |lo: i64, hi: i64, k: u32| lo + i64::from(k) * (hi - lo) / i64::from(n);
        let mut cells = Vec::with_capacity((n * n) as usize);
        for j in 1..=n {
            for i in 1..=n {
                let r = [
                    edge(x0, x1, i - 1),
                    edge(y0, y1, j - 1),
                    edge(x0, x1, i),
                    edge(y0, y1, j),
                ];
                let area = ((r[2] - r[0]) * (r[3] - r[1])) as f64;
                let mean = if area > 0.0 {
                    self.rect_mean(r.map(|e| e as f32))
                } else {
                    Vec::new()
                };
                cells.push((mean, area));
            }
        }
        cells
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_means_equal_direct_integration() {
        let (w, h, n) = (37, 23, 3);
        let data: Vec<f64> = (0..w * h * n)
            .map(|i| ((i * 7919) % 1000) as f64 / 997.0 - 0.3)
            .collect();
        let t = Texels {
            width: w,
            height: h,
            channels: n,
            data,
        };
        let integral = Integral::new(&t);
        for k in 0..500u32 {
            let f = |m: u32| ((k * m) % 4099) as f32 / 4099.0;
            // Fractional, reversed, partly outside and thinner than the minimum extent.
            let rect = [
                f(31) * 45.0 - 4.0,
                f(17) * 30.0 - 3.0,
                f(13) * 45.0 - 4.0,
                f(7) * 30.0 - 3.0,
            ];
            let direct = rect_mean(&t, rect);
            let fast = integral.rect_mean(rect);
            for c in 0..n {
                assert!(
                    (direct[c] - fast[c]).abs() <= 1e-9 * (1.0 + direct[c].abs()),
                    "{rect:?} channel {c}: {} vs {}",
                    direct[c],
                    fast[c]
                );
            }
        }
    }
}
