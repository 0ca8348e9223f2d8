//! Reference of `kernels/mips.wgsl` and of `sample_map` / `sample_map_log` in
//! `kernels/shared/sampling.wgsl`.

use super::Texels;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// Weight of texel `i` of an `n_from`-texel axis in texel `j` of its `n_to`-texel reduction:
/// the overlap of `[i/n_from, (i+1)/n_from)` and `[j/n_to, (j+1)/n_to)` over the latter's length.
fn weight(i: usize, j: usize, n_from: usize, n_to: usize) -> f64 {
    let lo = (i * n_to).max(j * n_from);
    let hi = ((i + 1) * n_to).min((j + 1) * n_from);
    if hi <= lo {
        0.0
    } else {
        (hi - lo) as f64 / n_from as f64
    }
}

/// `t` reduced to `w`×`h` by area-weighted means (of `exp(v)`, as a log, when `log`).
pub fn reduce(t: &Texels, w: usize, h: usize, log: bool) -> Texels {
    let mut data = Vec::with_capacity(w * h * t.channels);
    // Texel j of an n_to axis covers texels [j·n_from/n_to, ⌈(j+1)·n_from/n_to⌉) above.
    let covered =
        |j: usize, n_from: usize, n_to: usize| j * n_from / n_to..((j + 1) * n_from).div_ceil(n_to);
    for y in 0..h {
        for x in 0..w {
            let mut taps = Vec::new();
            for sy in covered(y, t.height, h) {
                let wy = weight(sy, y, t.height, h);
                for sx in covered(x, t.width, w) {
                    let wx = weight(sx, x, t.width, w);
                    if wx * wy > 0.0 {
                        taps.push((wx * wy, t.at(sx as i64, sy as i64)));
                    }
                }
            }
            data.extend(
                (0..t.channels).map(|c| combine(taps.iter().map(|(w, v)| (*w, v[c])), log)),
            );
        }
    }
    Texels {
        width: w,
        height: h,
        channels: t.channels,
        data,
    }
}

/// `Σ wᵢ vᵢ`, or `log Σ wᵢ exp(vᵢ)` when `log`.
fn combine(taps: impl Iterator<Item = (f64, f64)> + Clone, log: bool) -> f64 {
    if !log {
        return taps.map(|(w, v)| w * v).sum();
    }
    let m = taps.clone().map(|(_, v)| v).fold(f64::MIN, f64::max);
    m + taps.map(|(w, v)| w * (v - m).exp()).sum::<f64>().ln()
}

/// The full chain of `t`: level 0 is `t`, level m is `max(1, size >> m)`, each reduced from the
/// one above, down to 1×1.
pub fn mip_chain(t: &Texels, log: bool) -> Vec<Texels> {
    let mut levels = vec![t.clone()];
    while let Some(last) = levels.last() {
        if last.width == 1 && last.height == 1 {
            break;
        }
        let (w, h) = ((last.width / 2).max(1), (last.height / 2).max(1));
        let next = reduce(last, w, h, log);
        levels.push(next);
    }
    levels
}

/// How `sample_map` reads a footprint (`mip_taps` in `kernels/shared/sampling.wgsl`):
/// `count` trilinear taps at `lod`, `step` (UV) apart along the major axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MipTaps {
    /// Level.
    pub lod: f64,
    /// Taps.
    pub count: u32,
    /// UV between taps.
    pub step: [f64; 2],
    /// `major / w` before the ceiling (a test skips receivers where it is near an integer,
    /// where f32 and f64 may take different counts).
    pub ratio: f64,
}

/// `mip_taps`: one tap at `log2(filter width)` with `max_anisotropy` 0 or no footprint; else
/// `n = clamp(⌈major / w⌉, 1, max_anisotropy)` taps at `log2(max(w, major / n))`,
/// `w = max(filter width, minor)`.
pub fn mip_taps(l: &LightGpu, s: &LightSample) -> MipTaps {
    let f = s.footprint;
    let (la, lb) = (f[0].hypot(f[1]), f[2].hypot(f[3]));
    let major = la.max(lb);
    let mut t = MipTaps {
        lod: f64::from(l.filter_lod),
        count: 1,
        step: [0.0; 2],
        ratio: 1.0,
    };
    if l.max_anisotropy == 0 || major <= 0.0 {
        return t;
    }
    let axis = if la >= lb { [f[0], f[1]] } else { [f[2], f[3]] };
    let w = f64::from(l.filter_lod).exp2().max(la.min(lb));
    t.ratio = major / w;
    t.count = t.ratio.ceil().clamp(1.0, f64::from(l.max_anisotropy)) as u32;
    let n = f64::from(t.count);
    t.lod = w.max(major / n).log2();
    t.step = [
        axis[0] / (n * f64::from(l.map_size[0])),
        axis[1] / (n * f64::from(l.map_size[1])),
    ];
    t
}

/// The `(weight, texel)` taps `sample_map` reads for receiver `s`: bilinear on level 0; with a
/// SAT box, its texels; with a mip chain (`l.mip_levels > 1`) the [`mip_taps`], each bilinear
/// on the two levels around its lod, weighted `1 / count`.
pub fn taps<'a>(levels: &'a [Texels], l: &LightGpu, s: &LightSample) -> Vec<(f64, &'a [f64])> {
    let uv = s.uv;
    let bilinear = |t: &'a Texels, uv: [f64; 2], scale: f64| {
        let fx = uv[0] * t.width as f64 - 0.5;
        let fy = uv[1] * t.height as f64 - 0.5;
        let (x0, y0) = (fx.floor() as i64, fy.floor() as i64);
        let (ax, ay) = (fx - fx.floor(), fy - fy.floor());
        [
            ((1.0 - ax) * (1.0 - ay), 0, 0),
            (ax * (1.0 - ay), 1, 0),
            ((1.0 - ax) * ay, 0, 1),
            (ax * ay, 1, 1),
        ]
        .map(|(w, dx, dy)| (scale * w, t.at(x0 + dx, y0 + dy)))
    };
    if l.filter_width > 0.0 {
        return sat_taps(&levels[0], l, uv);
    }
    if l.mip_levels <= 1 || levels.len() <= 1 {
        return bilinear(&levels[0], uv, 1.0).to_vec();
    }
    let top = (l.mip_levels.min(levels.len() as u32) - 1) as f64;
    let mt = mip_taps(l, s);
    let lod = mt.lod.clamp(0.0, top);
    let l0 = lod.floor() as usize;
    let l1 = (l0 + 1).min(top as usize);
    let t = lod - lod.floor();
    let n = f64::from(mt.count);
    let mut v = Vec::new();
    for k in 0..mt.count {
        let o = f64::from(k) + 0.5 - 0.5 * n;
        let at = [uv[0] + mt.step[0] * o, uv[1] + mt.step[1] * o];
        v.extend(bilinear(&levels[l0], at, (1.0 - t) / n));
        v.extend(bilinear(&levels[l1], at, t / n));
    }
    v
}

/// The `sat` filter's taps (`sat_sample_*` in `kernels/shared/sat_lookup.wgsl`): every texel
/// the square of `l.filter_width` texels centred on `uv` overlaps, weighted by its overlap over
/// the (clamped) square's area; the rectangle itself is formed in f32 as the shader forms it,
/// and for a table read with filtered fetches (`l.sat_filtered`) put on the 2⁻⁸-texel grid.
pub fn sat_taps<'a>(t: &'a Texels, l: &LightGpu, uv: [f64; 2]) -> Vec<(f64, &'a [f64])> {
    sat_taps_width(t, l, uv, l.filter_width)
}

/// [`sat_taps`] for a square of `width` texels (`sat_sample_*(map, l, uv, width)`).
pub fn sat_taps_width<'a>(
    t: &'a Texels,
    l: &LightGpu,
    uv: [f64; 2],
    width: f32,
) -> Vec<(f64, &'a [f64])> {
    let (cx, cy) = (uv[0] as f32 * l.map_size[0], uv[1] as f32 * l.map_size[1]);
    let h = 0.5 * width;
    let rect = [cx - h, cy - h, cx + h, cy + h];
    // An f32 table is read with filtered fetches, its rectangle on the 2⁻⁸-texel grid.
    let clamped = if l.sat_filtered != 0 {
        super::sat::grid_rect(rect, t.width, t.height)
    } else {
        super::sat::clamp_rect(rect, t.width, t.height)
    };
    let [x0, y0, x1, y1] = clamped.map(f64::from);
    let area = (x1 - x0) * (y1 - y0);
    let overlap = |lo: f64, hi: f64, i: usize| (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0);
    let mut taps = Vec::new();
    for j in (y0.floor() as usize)..(y1.ceil() as usize).min(t.height) {
        let wy = overlap(y0, y1, j);
        for i in (x0.floor() as usize)..(x1.ceil() as usize).min(t.width) {
            let w = wy * overlap(x0, x1, i) / area;
            if w > 0.0 {
                taps.push((w, t.at(i as i64, j as i64)));
            }
        }
    }
    taps
}

/// `sample_map`: the filtered representation for receiver `s`.
pub fn sample(levels: &[Texels], l: &LightGpu, s: &LightSample) -> Vec<f64> {
    let taps = taps(levels, l, s);
    (0..levels[0].channels)
        .map(|c| taps.iter().map(|(w, v)| w * v[c]).sum())
        .collect()
}
