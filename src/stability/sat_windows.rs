//! Case 1: summed-area tables of a large map, window sums from 1×1 up to the whole map.
//!
//! The maps hold multiples of 2⁻²⁴ (the random map `k·2⁻²⁴`, `k < 2²⁴`; the constant
//! `0.999f32`, which is one), so the f64 reference sums them *exactly* as integers (a 8192²
//! sum is below 2⁵⁰). The GPU table is read back only at the corners of the windows checked
//! (`read_texels`), never copied whole: an 8192² one-channel table is 256 MiB.
//!
//! Bounds: the fixed-point table is exact, so its texels must equal the wrapping-u32 prefix of
//! the codes and every decoded window mean is within `½/scale` (rounding each code) plus
//! `u·max|v − offset|` (the f32 subtraction before the exact power-of-two scaling). The f32
//! table has no exact answer: every texel is within `d·u·Σ|x|` over its rectangle (`d` the
//! depth of the scan's summation tree, `x = v − offset`), and a window from four texels adds
//! three roundings: `(d + 3)·u·Σ_corners X·Y·max|x|`, plus `u·max|x|` per texel for the f32
//! subtraction, all over the window's area for the mean.

use std::collections::HashMap;

use super::StabilityRow;
use super::check::{Check, Rng, U};
use super::harness::{Poison, read_texels, run_graph, upload};
use crate::cpu::sat::encode_fixed;
use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::gpu::Gpu;
use crate::graph::Graph;
use crate::sat::lookups::{Lookup, lookup_means};
use crate::{
    model::SatVariant,
    sat::{SatCoding, add_sat, float_sum_depth, lookup_area},
};

/// Units of the maps' values: every texel is an integer multiple of 2⁻²⁴.
const UNIT: f64 = 1.0 / (1u64 << 24) as f64;

/// A map and its exact prefix sums, in units of 2⁻²⁴.
struct Map {
    name: String,
    n: usize,
    values: Vec<f32>,
    /// `S(X, Y)` = sum over `[0, X) × [0, Y)`, at `(Y − 1)·n + X − 1`.
    prefix: Vec<i64>,
}

impl Map {
    fn new(name: String, n: usize, values: Vec<f32>) -> Result<Self> {
        let mut prefix = Vec::with_capacity(n * n);
        for &v in &values {
            let units = f64::from(v) / UNIT;
            if units.fract() != 0.0 || !(0.0..=(1u64 << 24) as f64).contains(&units) {
                return Err(Error::Invalid(format!(
                    "{name}: {v} is not a multiple of 2⁻²⁴ in [0, 1]"
                )));
            }
            prefix.push(units as i64);
        }
        integrate(&mut prefix, n, |a, b| a + b);
        Ok(Self {
            name,
            n,
            values,
            prefix,
        })
    }

    /// The largest `|v − offset|` over the map: the magnitude the table's centred sums grow
    /// from, which every table model scales its rounding by.
    fn spread(&self, offset: f64) -> f64 {
        self.values
            .iter()
            .fold(0.0f64, |m, &v| m.max((f64::from(v) - offset).abs()))
    }

    /// Exact sum over `[0, x) × [0, y)` in units.
    fn corner(&self, x: usize, y: usize) -> i64 {
        if x == 0 || y == 0 {
            0
        } else {
            self.prefix[(y - 1) * self.n + x - 1]
        }
    }

    /// Exact sum over `[0, x) × [0, y)` at a point of the 2⁻⁸-texel grid (`x`, `y` in
    /// 256ths of a texel), times 256²: the bilinear mix of the four nodes around it, in i128.
    fn corner_256(&self, x: i64, y: i64) -> i128 {
        let (i, j) = ((x / 256) as usize, (y / 256) as usize);
        let (a, b) = (i128::from(x % 256), i128::from(y % 256));
        let c = |x: usize, y: usize| {
            if x > self.n || y > self.n {
                0
            } else {
                i128::from(self.corner(x, y))
            }
        };
        (256 - a) * (256 - b) * c(i, j)
            + a * (256 - b) * c(i + 1, j)
            + (256 - a) * b * c(i, j + 1)
            + a * b * c(i + 1, j + 1)
    }

    /// Exact sum over a rectangle on the 2⁻⁸-texel grid (texel units), as a value.
    fn fractional_window(&self, r: [f32; 4]) -> f64 {
        let [x0, y0, x1, y1] = r.map(|v| (v * 256.0) as i64);
        let s = self.corner_256(x1, y1) - self.corner_256(x0, y1) - self.corner_256(x1, y0)
            + self.corner_256(x0, y0);
        s as f64 / 65536.0 * UNIT
    }

    /// Exact window sum, as a value (f64 holds it exactly: < 2⁵³ units).
    fn window(&self, [x0, y0, x1, y1]: [usize; 4]) -> f64 {
        let s =
            self.corner(x1, y1) - self.corner(x0, y1) - self.corner(x1, y0) + self.corner(x0, y0);
        s as f64 * UNIT
    }
}

/// In-place inclusive 2-D prefix of a row-major `n × n` array.
fn integrate<T: Copy>(a: &mut [T], n: usize, add: impl Fn(T, T) -> T) {
    for y in 0..n {
        for x in 1..n {
            a[y * n + x] = add(a[y * n + x], a[y * n + x - 1]);
        }
    }
    for y in 1..n {
        for x in 0..n {
            a[y * n + x] = add(a[y * n + x], a[(y - 1) * n + x]);
        }
    }
}

/// Windows `[x0, y0, x1, y1)` to check, sides at most `max_side`: the extremes (whole map or
/// the largest square at the far corner, 1×1 at all four corners, the last row and column as
/// long as allowed, 7×7 at the far corner), then `random` windows with log-uniform sides, half
/// of them touching the far edges, where the corner sums are largest.
fn windows(rng: &mut Rng, n: usize, max_side: usize, random: usize) -> Vec<[usize; 4]> {
    let m = max_side.min(n);
    let k = m.min(7);
    let mut out = vec![
        [n - m, n - m, n, n],
        [n - 1, n - 1, n, n],
        [0, 0, 1, 1],
        [n - 1, 0, n, 1],
        [0, n - 1, 1, n],
        [n - m, n - 1, n, n],
        [n - 1, n - m, n, n],
        [n - k, n - k, n, n],
    ];
    let side = |rng: &mut Rng| ((m as f64).ln() * rng.unit()).exp().floor().max(1.0) as usize;
    for i in 0..random {
        let (w, h) = (side(rng).min(m), side(rng).min(m));
        let (x0, y0) = if i % 2 == 0 {
            (
                n - w - rng.below(3).min(n - w),
                n - h - rng.below(3).min(n - h),
            )
        } else {
            (rng.below(n - w + 1), rng.below(n - h + 1))
        };
        out.push([x0, y0, x0 + w, y0 + h]);
    }
    out
}

/// The table texels a window needs: `(X − 1, Y − 1)` of each corner node with X, Y > 0.
fn corner_texels(windows: &[[usize; 4]]) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = windows
        .iter()
        .flat_map(|&[x0, y0, x1, y1]| [(x0, y0), (x1, y0), (x0, y1), (x1, y1)])
        .filter(|&(x, y)| x > 0 && y > 0)
        .map(|(x, y)| (x as u32 - 1, y as u32 - 1))
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// What [`gpu_table`] reads of a table: its texels at the windows' corners and, for an f32
/// table, the means of `sat_mean_linear` (four filtered fetches) over the fractional rectangles.
struct Read {
    texels: HashMap<(u32, u32), [u32; 4]>,
    filtered: Vec<f32>,
}

/// Builds the table of `map` with `coding` on the GPU and reads the texels at `coords` (and,
/// for an f32 table, the filtered lookups' means over `rects`).
fn gpu_table(
    gpu: &Gpu,
    map: &Map,
    coding: &SatCoding,
    coords: &[(u32, u32)],
    rects: &[[f32; 4]],
) -> Result<Read> {
    let n = map.n as u32;
    let mut graph = Graph::default();
    graph.import("in", wgpu::TextureFormat::R32Float, n, n, Some(0));
    let out = add_sat(&mut graph, 0, "in", coding);
    let input = upload(
        gpu,
        (n, n),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(&map.values),
    );
    let imports = HashMap::from([("in".to_string(), input)]);
    // A fresh executor: its large textures go when it does.
    let mut exec = Executor::new();
    let poison = Poison::Texels(&out, coords);
    let ran = run_graph(gpu, &mut exec, &graph, &[&out], imports, false, poison)?;
    let table = &ran.outputs.textures[&out];
    let texels = read_texels(gpu, table, coords)?;
    let filtered = if coding.variant == SatVariant::Float {
        lookup_means(gpu, table, Lookup::Linear, coding, rects)?
            .iter()
            .map(|m| m[0])
            .collect()
    } else {
        Vec::new()
    };
    // Free the large textures now, not whenever wgpu next cleans up.
    for t in ran.outputs.textures.values() {
        t.destroy();
    }
    Ok(Read {
        texels: coords.iter().copied().zip(texels).collect(),
        filtered,
    })
}

/// Fractional rectangles from `windows`: each edge moved by a whole number of 2⁻⁸-texel steps
/// (up to 255 either way, inside the map, at least one step wide): where filtered fetches
/// weigh their texels exactly on every device.
fn fractional(rng: &mut Rng, windows: &[[usize; 4]], n: usize) -> Vec<[f32; 4]> {
    let steps = (n * 256) as i64;
    let mut jitter = |v: usize| -> i64 {
        let k = rng.below(511) as i64 - 255;
        (v as i64 * 256 + k).clamp(0, steps)
    };
    windows
        .iter()
        .map(|&[x0, y0, x1, y1]| {
            let (a, b) = (jitter(x0), jitter(y0));
            let (c, d) = (jitter(x1).max(a + 1), jitter(y1).max(b + 1));
            let (a, b) = (a.min(steps - 1), b.min(steps - 1));
            let (c, d) = (c.min(steps).max(a + 1), d.min(steps).max(b + 1));
            [a, b, c, d].map(|v| v as f32 / 256.0)
        })
        .collect()
}

/// Depth of the GPU's summation tree for one f32 table texel of an `n`² map
/// ([`float_sum_depth`]).
fn scan_depth(n: usize) -> f64 {
    f64::from(float_sum_depth(n as u32, n as u32))
}

/// The fixed-point table at the corners against the wrapping-u32 prefix of the codes, and the
/// decoded window means against the exact means.
fn check_fixed(
    map: &Map,
    coding: &SatCoding,
    wins: &[[usize; 4]],
    got: &HashMap<(u32, u32), [u32; 4]>,
    label: &str,
) -> [StabilityRow; 2] {
    let n = map.n;
    // The exact prefix of the codes in i64 (|sum| < 2²⁶·2³¹); the table holds it mod 2³².
    let mut codes: Vec<i64> = map
        .values
        .iter()
        .map(|&v| i64::from(encode_fixed(v, coding, 0) as i32))
        .collect();
    integrate(&mut codes, n, |a, b| a + b);
    let mut table = Check::new();
    let mut largest = 0i64;
    for (&(x, y), t) in got {
        let want = codes[y as usize * n + x as usize];
        largest = largest.max(want.abs());
        let diff = f64::from(t[0].wrapping_sub(want as u32) as i32);
        table.compare(diff, 0.0, 0.0, || format!("texel ({x}, {y})"));
        table.compare(f64::from(t[1] | t[2] | t[3]), 0.0, 0.0, || {
            format!("unused channels at ({x}, {y})")
        });
    }
    let node = |x: usize, y: usize| -> u32 {
        if x == 0 || y == 0 {
            0
        } else {
            got[&(x as u32 - 1, y as u32 - 1)][0]
        }
    };
    let (scale, offset) = (f64::from(coding.scale[0]), f64::from(coding.offset[0]));
    let spread = map.spread(offset);
    let bound = 0.5 / scale + U * spread + 1e-12;
    let mut means = Check::new();
    for &w in wins {
        let [x0, y0, x1, y1] = w;
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let sum = node(x1, y1)
            .wrapping_sub(node(x0, y1))
            .wrapping_sub(node(x1, y0))
            .wrapping_add(node(x0, y0)) as i32;
        let mean = f64::from(sum) / scale / area + offset;
        means.compare(mean, map.window(w) / area, bound, || window_name(w, n));
    }
    let what = format!("{} {}²", map.name, n);
    let mut table = table.row(
        1,
        &format!("{what}: table = integer reference"),
        label,
        "fixed u32",
    );
    table.note = format!(
        "{}; corner sums up to {:.1} × 2³¹ (past 1 they wrap)",
        table.note,
        largest as f64 / 2f64.powi(31)
    );
    [
        table,
        means.row(1, &format!("{what}: window means"), label, "fixed u32"),
    ]
}

/// The f32 table's window means against the exact means, each within the scan's model; and
/// the filtered lookups' means over the fractional rectangles `rects`, within the same model
/// plus the bilinear mixes: each corner is two lerps in x and one in y of table texels, three
/// roundings each relative to the sums there, so `(d + 12)·u` of the corner's sum bound
/// (`(⌈x⌉·⌈y⌉)·max|x|`) counts the table texels' error, the mixes and the window's three
/// subtractions.
fn check_float(
    map: &Map,
    coding: &SatCoding,
    wins: &[[usize; 4]],
    got: &Read,
    rects: &[[f32; 4]],
) -> [StabilityRow; 2] {
    let filtered = check_filtered(map, coding, rects, &got.filtered);
    let got = &got.texels;
    let n = map.n;
    let offset = f64::from(coding.offset[0]);
    let max_x = map.spread(offset);
    let d = scan_depth(n);
    let node = |x: usize, y: usize| -> f64 {
        if x == 0 || y == 0 {
            0.0
        } else {
            f64::from(f32::from_bits(got[&(x as u32 - 1, y as u32 - 1)][0]))
        }
    };
    let mut means = Check::new();
    for &w in wins {
        let [x0, y0, x1, y1] = w;
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let sum = node(x1, y1) - node(x0, y1) - node(x1, y0) + node(x0, y0);
        let corners: f64 = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            .iter()
            .map(|&(x, y)| (x * y) as f64 * max_x)
            .sum();
        let exact = map.window(w);
        let bound = ((d + 3.0) * U * corners + U * (exact - area * offset).abs()) / area
            + U * max_x
            + 1e-12;
        means.compare(sum / area + offset, exact / area, bound, || {
            window_name(w, n)
        });
    }
    [
        means.row(
            1,
            &format!("{} {}²: window means", map.name, n),
            "sat (f32 model)",
            "f32",
        ),
        filtered,
    ]
}

/// The filtered lookups' means (`sat_mean_linear`, four filtered fetches) against the exact
/// means of `rects` (see [`check_float`] for the bound).
fn check_filtered(map: &Map, coding: &SatCoding, rects: &[[f32; 4]], got: &[f32]) -> StabilityRow {
    let n = map.n;
    let offset = f64::from(coding.offset[0]);
    let max_x = map.spread(offset);
    let d = scan_depth(n);
    let mut means = Check::new();
    if got.len() != rects.len() {
        means.compare(f64::NAN, 0.0, 0.0, || {
            format!("{} means for {} rectangles", got.len(), rects.len())
        });
    }
    for (r, &mean) in rects.iter().zip(got) {
        let [x0, y0, x1, y1] = r.map(f64::from);
        let area = (x1 - x0) * (y1 - y0);
        let corners: f64 = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            .iter()
            .map(|&(x, y)| x.ceil() * y.ceil() * max_x)
            .sum();
        let exact = map.fractional_window(*r);
        let bound = ((d + 12.0) * U * corners + U * (exact - area * offset).abs()) / area
            + U * max_x
            + 1e-12;
        means.compare(f64::from(mean), exact / area, bound, || {
            format!("[{x0}, {x1}) × [{y0}, {y1})")
        });
    }
    means.row(
        1,
        &format!("{} {}²: filtered lookups (4 fetches)", map.name, n),
        "sat (f32 model)",
        "f32",
    )
}

fn window_name([x0, y0, x1, y1]: [usize; 4], n: usize) -> String {
    let far = if x1 == n && y1 == n {
        " at the far corner"
    } else {
        ""
    };
    format!("{}x{} window ({x0}, {y0}){far}", x1 - x0, y1 - y0)
}

/// Which tables case 1 builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SatTables {
    /// Per map three tables: fixed point coded for the whole map (every window exact), fixed
    /// point at the fine scale of 64×64-texel lookups (windows up to 65²; the constant map's
    /// corner sums pass 2³¹ thousands of times and wrap), and f32.
    All,
    /// One table per map, a third of the time at 8192²: the f32 table of the constant map
    /// (where fp32 sums are at their worst) and the whole-map fixed-point table of the random
    /// map (where every code differs).
    OnePerMap,
}

/// Case 1 at `size`²: a constant 0.999 map and a random map, the tables `tables` names.
pub(crate) fn sat_case(gpu: &Gpu, size: u32, tables: SatTables) -> Result<Vec<StabilityRow>> {
    let n = size as usize;
    if n < 8 || size > gpu.device.limits().max_texture_dimension_2d {
        return Err(Error::Invalid(format!(
            "SAT stability size {size} must be at least 8 and within the device's texture limit"
        )));
    }
    let mut rng = Rng::new(0x5A7);
    let mut rows = Vec::new();
    let constant = Map::new("const 0.999".into(), n, vec![0.999f32; n * n])?;
    let random: Vec<f32> = (0..n * n)
        .map(|_| (rng.next_u64() >> 40) as f32 * UNIT as f32)
        .collect();
    let random = Map::new("random".into(), n, random)?;
    let whole = SatCoding::fixed((n * n) as u64, [0.0; 4], [1.0; 4])?;
    let fine = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4])?;
    let float = SatCoding::float([0.0; 4], [1.0; 4])?;
    for map in [&constant, &random] {
        let wins = windows(&mut rng, n, n, 400);
        // Drawn whatever runs, so every table sees the same windows in either mode.
        let small = windows(&mut rng, n, 65, 400);
        // The f32 table's filtered lookups: the whole-map windows with fractional edges.
        let rects = fractional(&mut rng, &wins, n);
        let mut codings = vec![
            (whole, wins.clone(), "sat (all windows exact)"),
            (fine, small, "sat (64² lookups)"),
            (float, wins, ""),
        ];
        if tables == SatTables::OnePerMap {
            let keep = if map.name == "random" {
                SatVariant::Fixed
            } else {
                SatVariant::Float
            };
            codings.retain(|(c, _, label)| c.variant == keep && !label.contains("64²"));
        }
        for (coding, wins, label) in codings {
            let coords = corner_texels(&wins);
            let got = gpu_table(gpu, map, &coding, &coords, &rects)?;
            match coding.variant {
                SatVariant::Fixed => {
                    rows.extend(check_fixed(map, &coding, &wins, &got.texels, label))
                }
                SatVariant::Float => rows.extend(check_float(map, &coding, &wins, &got, &rects)),
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_stay_inside_and_include_the_extremes() {
        let mut rng = Rng::new(1);
        for (n, max) in [(8, 8), (100, 65), (8192, 8192)] {
            let w = windows(&mut rng, n, max, 200);
            assert!(w.contains(&[n - 1, n - 1, n, n]));
            assert!(
                w.iter()
                    .all(|&[a, b, c, d]| a < c && b < d && c <= n && d <= n)
            );
            assert!(w.iter().all(|&[a, b, c, d]| c - a <= max && d - b <= max));
            assert!(w.iter().any(|&[a, b, c, d]| (c - a, d - b) == (1, 1)));
        }
        assert!(windows(&mut rng, 64, 64, 0).contains(&[0, 0, 64, 64]));
    }

    #[test]
    fn exact_prefix_matches_direct_sums() {
        let mut rng = Rng::new(2);
        let n = 9;
        let v: Vec<f32> = (0..n * n)
            .map(|_| (rng.next_u64() >> 40) as f32 * UNIT as f32)
            .collect();
        let m = Map::new("t".into(), n, v.clone()).unwrap();
        let w = [2, 3, 7, 9];
        let direct: f64 = (3..9)
            .flat_map(|y| (2..7).map(move |x| (x, y)))
            .map(|(x, y)| f64::from(v[y * n + x]))
            .sum();
        assert_eq!(m.window(w), direct);
        assert!(Map::new("bad".into(), 1, vec![0.1]).is_err());
    }
}
