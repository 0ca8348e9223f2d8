//! Tolerances of the soft techniques (`cssm`, `vssm`, `msm_soft`) and the inputs of their f64
//! references, shared by tests/soft.rs, tests/scenes/ and tests/plugin/.
//!
//! A soft visibility is a chain: table means over the search square → blocker estimate →
//! filter width → table means over it → visibility. The GPU's errors enter at the means (f32
//! weighting of exact fixed-point windows, or f32 differences of f32 sums), at the receiver's
//! depth (the view transform in f32) and, for CSSM, at the receiver's Fourier factors (sin/cos).
//! Each tolerance propagates them through the f64 reference by perturbation: every sign
//! combination of the errors on the search step's inputs gives a range of blocker depths
//! z_avg ± δz (the visibility is then re-evaluated, exactly, at the widths of z_avg ± δz), and
//! every combination on the final step's inputs a range of visibilities (at five scales of the
//! errors, see `combinations`); the tolerance is twice the largest change of each, plus 1e-5
//! (first-order propagation is not a bound on its own: the factor 2 covers curvature). A point where a perturbation flips whether the
//! search square holds blockers (a threshold, `BLOCKER_MIN_SHARE`) has no tolerance: `None`.
//! Nor has one whose filter square has an edge within [`EDGE_MARGIN`] of the point where its
//! rounding to the nearest texel edge changes (a half texel): the box there jumps by a texel
//! row or column for a tiny change of the penumbra width, and the GPU's f32 blocker estimate
//! (a division by the blockers' share, Hamburger's root solve) can land on the other side
//! (seen: an edge at 29.4992 read as past 29.5). Wider moves of the width, from the
//! propagated errors, are in the tolerance: `finish` at z_avg ± δz takes the jump.

use shadowgraph::low_level::cpu::blocker::Blocker;
use shadowgraph::low_level::cpu::light::LightSample;
use shadowgraph::low_level::cpu::sat::Integral;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::sat::SatCoding;
use shadowgraph::low_level::wgsl_mirrors::MSM_QUANTIZED;
use shadowgraph::{CssmSearch, LightGpu, SatVariant};

mod inputs;
mod tolerances;

pub use self::inputs::{SoftInputs, split_cssm};
pub use self::tolerances::{cssm_tolerance, msm_soft_tolerance, vssm_tolerance};

const ULP: f64 = 1.0 / 16_777_216.0; // 2⁻²⁴

/// How far the GPU's table means can be from the exact integral of the table's values.
#[derive(Clone, Copy, Debug)]
pub struct TableError {
    /// Per table channel, the largest |value − offset| in the map (what the lookups weight).
    pub amp: [f64; 4],
    /// An f32 table (else fixed point).
    pub float: bool,
    /// Map side in texels.
    pub size: usize,
}

impl TableError {
    /// For the texels `t` (the values a table sums, decoded) coded by `coding`.
    pub fn new(t: &Texels, coding: &SatCoding) -> Self {
        // Channel c of the representation lands in channel c mod 4 of its table.
        let mut amp = [0.0f64; 4];
        for texel in t.data.chunks(t.channels) {
            for (c, v) in texel.iter().enumerate() {
                let k = c % 4;
                amp[k] = amp[k].max((v - f64::from(coding.offset[k])).abs());
            }
        }
        Self {
            amp,
            float: coding.variant == SatVariant::Float,
            size: t.width.max(t.height),
        }
    }

    /// Absolute error bound of the mean of channel c over the `width`-texel square at `s`
    /// (the square itself exact; the UV's error is applied separately, see [`UV_ERROR`]):
    /// 16 weights and products, a 16-term sum and a division in f32 (40 roundings of the
    /// largest |value − offset|); with f32 sums, each window is two f32 differences of strip
    /// sums up to `(size + 2)·(⌈w⌉ + 2)` values, rounded relative to those strips, over the
    /// clamped area.
    pub fn mean(&self, l: &LightGpu, s: &LightSample, width: f64) -> [f64; 4] {
        let n = self.size as f64;
        let (cx, cy) = (
            s.uv[0] as f32 * l.map_size[0],
            s.uv[1] as f32 * l.map_size[1],
        );
        let h = 0.5 * width as f32;
        let r = cpu::sat::clamp_rect([cx - h, cy - h, cx + h, cy + h], self.size, self.size)
            .map(f64::from);
        let area = (r[2] - r[0]) * (r[3] - r[1]);
        self.amp.map(|a| {
            let strips = if self.float {
                3.0 * ULP * (n + 2.0) * (width.ceil() + 2.0) * a / area
            } else {
                0.0
            };
            40.0 * ULP * a + strips
        })
    }

    /// [`Self::mean`] of one cell of the blocker search, an integer window of `area` texels
    /// (no weights; its side at most √area + 1: the cells of a snapped square differ by a
    /// texel at most).
    pub fn cell(&self, area: f64) -> [f64; 4] {
        let n = self.size as f64;
        let side = area.sqrt() + 1.0;
        self.amp.map(|a| {
            let strips = if self.float {
                3.0 * ULP * (n + 2.0) * (side.ceil() + 2.0) * a / area.max(1.0)
            } else {
                0.0
            };
            40.0 * ULP * a + strips
        })
    }
}

/// The blocker search's cells as one vector for [`Chain`]: each cell's first `ch` values (as
/// `f` makes them from its mean; zeros for an empty cell), then its area.
pub fn flat_cells(
    cells: &[(Vec<f64>, f64)],
    ch: usize,
    f: impl Fn(&[f64]) -> Vec<f64>,
) -> Vec<f64> {
    let mut v = Vec::with_capacity(cells.len() * (ch + 1));
    for (m, area) in cells {
        if *area > 0.0 {
            v.extend_from_slice(&f(m)[..ch]);
        } else {
            v.extend(std::iter::repeat_n(0.0, ch));
        }
        v.push(*area);
    }
    v
}

/// [`flat_cells`] back into cells of `ch` values and an area.
pub fn unflat_cells(v: &[f64], ch: usize) -> Vec<(Vec<f64>, f64)> {
    v.chunks(ch + 1)
        .map(|c| (c[..ch].to_vec(), c[ch]))
        .collect()
}

/// The errors of [`flat_cells`]' entries: `e(m, area)` for each non-empty cell's values, 0
/// for the areas (exact) and empty cells.
fn cell_errors(v: &[f64], ch: usize, e: impl Fn(&[f64], f64) -> [f64; 4]) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    for c in v.chunks(ch + 1) {
        let area = c[ch];
        if area > 0.0 {
            out.extend_from_slice(&e(&c[..ch], area)[..ch]);
        } else {
            out.extend(std::iter::repeat_n(0.0, ch));
        }
        out.push(0.0);
    }
    out
}

/// The f32 error of the receiver's UV (the projection of the normal-offset point: a few
/// roundings of clip coordinates of magnitude about 1, over w): it moves the squares, so the
/// means are recomputed at the UV moved by ± this on both axes (the moments move together,
/// which independent per-channel errors would not model).
pub const UV_ERROR: f64 = 16.0 * ULP;

/// The f32 error of the receiver's linear depth: the view transform (4 roundings of Z and
/// near), over far − near.
pub fn depth_error(l: &LightGpu, s: &LightSample) -> f64 {
    8.0 * ULP * (s.view_z + f64::from(l.near)) / f64::from(l.far - l.near)
}

/// Every sign combination of `n` errors at each of five scales (1, ½, ¼, ⅛, 1⁄16 of the
/// bound): `f(factors)` for `factors[i] = ±scale`. The blocker estimates are not monotone in
/// their inputs near singular moments (MSM), so the corners of the error box alone can miss
/// a flip that a smaller error causes.
fn combinations(n: usize, mut f: impl FnMut(&[f64])) {
    for scale in [1.0, 0.5, 0.25, 0.125, 0.0625] {
        for k in 0..(1u32 << n) {
            let signs: Vec<f64> = (0..n)
                .map(|i| if k >> i & 1 == 1 { scale } else { -scale })
                .collect();
            f(&signs);
        }
    }
}

/// The perturbation tolerance of one soft visibility `v0` (see the module documentation).
/// `search(δuv)`, `e_search`: the search step's inputs with the receiver's UV moved, and their
/// errors; `blocker` their estimate (with the receiver depth moved); `finish(z)`: the exact
/// visibility for blockers at depth z; `last(δuv)`, `e_last`, `visibility`: the final step's
/// inputs (at the unperturbed blocker's width), errors and function of them (with the
/// receiver depth moved).
pub struct Chain<'a> {
    /// Search-step inputs at the UV moved by the argument.
    pub search: &'a dyn Fn([f64; 2]) -> Vec<f64>,
    /// Their absolute errors, or with `cells` a function of the moved inputs giving them.
    pub e_search: Vec<f64>,
    /// The search's inputs are this many cells of equal length ([`flat_cells`]) whose errors
    /// are independent: each cell is perturbed on its own and the changes of the estimate are
    /// summed (first order), instead of every sign combination of every input at once
    /// (2^(4·4) for MSM's four cells). 1: the inputs are perturbed together.
    pub cells: usize,
    /// With `cells` > 1, the errors of the search's inputs at the moved UV (their areas change
    /// with it).
    pub cell_errors: Option<&'a CellErrors<'a>>,
    /// Blocker estimate of (inputs, depth offset).
    pub blocker: &'a dyn Fn(&[f64], f64) -> Blocker,
    /// Visibility for blockers at this depth (exact lookups at its filter width).
    pub finish: &'a dyn Fn(f64) -> f64,
    /// Final-step inputs at the UV moved by the argument.
    pub last: &'a dyn Fn([f64; 2]) -> Vec<f64>,
    /// Their absolute errors.
    pub e_last: Vec<f64>,
    /// Visibility of (inputs, depth offset).
    pub visibility: &'a dyn Fn(&[f64], f64) -> f64,
    /// The receiver depth's error.
    pub e_depth: f64,
    /// The filter square's edges before rounding for blockers at this depth
    /// (`cpu::sat::square`).
    pub filter_box: &'a dyn Fn(f64) -> [f32; 4],
    /// The filter's square is exact (`vssm`, `msm_soft`) or read with filtered fetches of an
    /// f32 table, whose edges snap to the 2⁻⁸ grid, where an edge landing one step off moves
    /// the means by no more than [`grid_flips`] adds to `e_last`: no point is set aside for
    /// its edges. Else (CSSM's fixed-point tables) its edges are rounded to texel edges.
    pub grid: bool,
}

/// The errors of a search's cells' values at a moved UV ([`Chain::cell_errors`]).
pub type CellErrors<'a> = dyn Fn(&[f64]) -> Vec<f64> + 'a;

/// `e` (a mean's error per channel, of the filter's square at `width`) plus, for a table read
/// with filtered fetches, the change of the means when the GPU's square lands its edges one
/// grid step away from the f64 one ([`Integral::grid_flip_error`]).
pub fn grid_flips(
    t: &Integral,
    l: &LightGpu,
    s: &LightSample,
    width: f64,
    e: [f64; 4],
) -> [f64; 4] {
    if !t.is_filtered() {
        return e;
    }
    let flips = t.grid_flip_error(l.map_size, s.uv, width);
    std::array::from_fn(|c| e[c] + flips.get(c).copied().unwrap_or(0.0))
}

/// How close to a half texel a filter square's edge may lie before its point is set aside:
/// 2·10⁻³ texel, 2.5 times the largest GPU–f64 difference of an edge seen (8·10⁻⁴), which sets
/// aside about 1.6% of points.
pub const EDGE_MARGIN: f32 = 2e-3;

/// The receiver's UV and the four moved by ±[`UV_ERROR`] on both axes.
const UV_MOVES: [[f64; 2]; 5] = [
    [0.0, 0.0],
    [UV_ERROR, UV_ERROR],
    [UV_ERROR, -UV_ERROR],
    [-UV_ERROR, UV_ERROR],
    [-UV_ERROR, -UV_ERROR],
];

impl Chain<'_> {
    /// The tolerance, or `None` where a perturbation flips the blocker threshold.
    pub fn tolerance(&self, v0: f64) -> Option<f64> {
        let search0 = (self.search)([0.0; 2]);
        let b0 = (self.blocker)(&search0, 0.0);
        let (flips, dz) = if self.cells > 1 {
            self.cell_search_range(b0)
        } else {
            self.search_range(b0)
        };
        self.finish_tolerance(v0, b0, flips, dz)
    }

    /// Whether a perturbation of the search's inputs flips the blocker threshold, and the
    /// largest change of the blocker depth, every input perturbed together.
    fn search_range(&self, b0: Blocker) -> (bool, f64) {
        let mut flips = false;
        let mut dz: f64 = 0.0;
        for moved in UV_MOVES {
            let search = (self.search)(moved);
            let n = search.len();
            combinations(n + 1, |sg| {
                let m: Vec<f64> = (0..n)
                    .map(|i| search[i] + sg[i] * self.e_search[i])
                    .collect();
                let b = (self.blocker)(&m, sg[n] * self.e_depth);
                flips |= b.found() != b0.found();
                dz = dz.max((b.depth - b0.depth).abs());
            });
        }
        (flips, dz)
    }

    /// [`Self::search_range`] for inputs in cells: at each moved UV, each cell perturbed on
    /// its own (every sign combination of its values and the depth), the changes of the
    /// depth summed over the cells (first order), and every cell perturbed at once with the
    /// same signs per channel (errors that move together); a perturbation flips the threshold
    /// where it changes whether the estimate finds blockers.
    fn cell_search_range(&self, b0: Blocker) -> (bool, f64) {
        let mut flips = false;
        let mut dz: f64 = 0.0;
        for moved in UV_MOVES {
            let search = (self.search)(moved);
            let e = self
                .cell_errors
                .map_or_else(|| self.e_search.clone(), |f| f(&search));
            let bm = (self.blocker)(&search, 0.0);
            flips |= bm.found() != b0.found();
            let stride = search.len() / self.cells;
            let mut d_depth = 0.0f64;
            for k in 0..self.cells {
                let idx: Vec<usize> = (k * stride..(k + 1) * stride)
                    .filter(|&i| e[i] > 0.0)
                    .collect();
                let mut cz = 0.0f64;
                combinations(idx.len() + 1, |sg| {
                    let mut m = search.clone();
                    for (j, &i) in idx.iter().enumerate() {
                        m[i] += sg[j] * e[i];
                    }
                    let b = (self.blocker)(&m, sg[idx.len()] * self.e_depth);
                    flips |= b.found() != b0.found();
                    cz = cz.max((b.depth - bm.depth).abs());
                });
                d_depth += cz;
            }
            combinations(stride, |sg| {
                let m: Vec<f64> = (0..search.len())
                    .map(|i| search[i] + sg[i % stride] * e[i])
                    .collect();
                let b = (self.blocker)(&m, sg[stride - 1] * self.e_depth);
                flips |= b.found() != b0.found();
                d_depth = d_depth.max((b.depth - bm.depth).abs());
            });
            dz = dz.max((bm.depth - b0.depth).abs() + d_depth);
        }
        (flips, dz)
    }

    /// The tolerance from the search's range: `None` where it flips the threshold.
    fn finish_tolerance(&self, v0: f64, b0: Blocker, flips: bool, dz: f64) -> Option<f64> {
        if flips {
            return None;
        }
        if !b0.found() {
            return Some(1e-5);
        }
        let near_half = |x: &f32| (x - x.floor() - 0.5).abs() < EDGE_MARGIN;
        if !self.grid && (self.filter_box)(b0.depth).iter().any(near_half) {
            return None;
        }
        let search = [b0.depth - dz, b0.depth + dz]
            .iter()
            .map(|&z| ((self.finish)(z) - v0).abs())
            .fold(0.0, f64::max);
        let mut last: f64 = 0.0;
        for moved in UV_MOVES {
            let inputs = (self.last)(moved);
            let n = inputs.len();
            combinations(n + 1, |sg| {
                let m: Vec<f64> = (0..n).map(|i| inputs[i] + sg[i] * self.e_last[i]).collect();
                let v = (self.visibility)(&m, sg[n] * self.e_depth);
                last = last.max((v - v0).abs());
            });
        }
        Some(1e-5 + 2.0 * (search + last))
    }
}

/// The filter square's edges (before rounding) at `s` for blockers at depth `z`.
fn filter_box(l: &LightGpu, s: &LightSample, z: f64) -> [f32; 4] {
    cpu::sat::square(l.map_size, s.uv, cpu::blocker::filter_width(l, s, z))
}

/// `s` with its UV moved by `du`.
pub fn shifted(s: &LightSample, du: [f64; 2]) -> LightSample {
    let mut t = *s;
    t.uv = [s.uv[0] + du[0], s.uv[1] + du[1]];
    t
}

/// `s` with its depth moved by `dd`.
pub fn moved(s: &LightSample, dd: f64) -> LightSample {
    let mut t = *s;
    t.depth += dd;
    t
}
