//! The crossover: what each technique's frame costs against PCSS of comparable penumbra error
//! as the image grows, for a light redrawn every frame and for a static one.
//!
//! Built from measurements, not a model of the device: each configuration's shading pass is
//! timed at two or more image sizes and fitted as `a + b·Mpx` ([`fit`], least squares), its
//! raster and prefilter (which depend on the map, not the image) taken as their median over
//! the same frames. A moving light costs raster + prefilter + shading per frame, a static one
//! the shading alone. Where a technique's line crosses its PCSS's in 0.25–8.3 Mpx is
//! [`crossing`]. One more image size, not used in the fit, checks the prediction against a
//! direct measurement ([`CheckError`]).
//!
//! The pure parts (the fit, the crossing, which PCSS a technique is compared with) are here;
//! the measurement is [`run`](super::crossover_run), the plot
//! [`crossover_svg`](super::crossover_svg).

use super::Measurement;

/// The image sizes the crossover is drawn over, megapixels: 0.25 Mpx to 3840×2160.
pub const RANGE_MPX: (f64, f64) = (0.25, 3840.0 * 2160.0 / 1e6);

/// How much worse than a technique's penumbra error a PCSS configuration may be and still be
/// "as accurate" ([`comparable_pcss`]): 10%, as the verdict's.
pub const COMPARABLE: f64 = super::verdict::NEAR_BEST;

/// The median relative error of the prediction the target holds on a CPU driver.
pub const TARGET_MEDIAN: f64 = 0.10;

/// The worst relative error of the prediction the target holds.
pub const TARGET_WORST: f64 = 0.25;

/// A cost in ms as a line in the image's megapixels: `a + b·Mpx`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Line {
    /// ms at 0 pixels.
    pub a: f64,
    /// ms per megapixel.
    pub b: f64,
}

impl Line {
    /// The cost at `mpx` megapixels, ms.
    pub fn at(self, mpx: f64) -> f64 {
        self.a + self.b * mpx
    }

    /// The same line raised by `ms` (a moving light's raster and prefilter).
    pub fn plus(self, ms: f64) -> Self {
        Self {
            a: self.a + ms,
            b: self.b,
        }
    }
}

/// The least-squares line through `points` (megapixels, ms); `None` with fewer than two
/// distinct x or a non-finite value.
pub fn fit(points: &[(f64, f64)]) -> Option<Line> {
    if points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    // Relative to the x's own scale, so that sizes a few pixels apart still count.
    let scale = points
        .iter()
        .map(|p| p.0 * p.0)
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    if points.len() < 2 || sxx <= 1e-12 * scale {
        return None;
    }
    let b = sxy / sxx;
    Some(Line { a: my - b * mx, b })
}

/// Where a technique is cheaper than its PCSS over an image range.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", content = "mpx", rename_all = "snake_case")]
pub enum Crossing {
    /// At every size of the range (as cheap or cheaper at both ends).
    Always,
    /// At no size of the range.
    Never,
    /// From this many megapixels up (dearer below).
    Above(f64),
    /// Up to this many megapixels (dearer above).
    Below(f64),
}

/// Where `t` costs no more than `p` over `[lo, hi]` megapixels: both lines, so the difference
/// is a line and changes sign at most once.
pub fn crossing(t: Line, p: Line, (lo, hi): (f64, f64)) -> Crossing {
    let d = |x: f64| t.at(x) - p.at(x);
    let (d0, d1) = (d(lo), d(hi));
    let at = || {
        let x = -(t.a - p.a) / (t.b - p.b);
        if x.is_finite() { x.clamp(lo, hi) } else { lo }
    };
    match (d0 <= 0.0, d1 <= 0.0) {
        (true, true) => Crossing::Always,
        (false, false) => Crossing::Never,
        (false, true) => Crossing::Above(at()),
        (true, false) => Crossing::Below(at()),
    }
}

impl Crossing {
    /// The crossing's megapixels, if the lines cross in the range.
    pub fn mpx(self) -> Option<f64> {
        match self {
            Crossing::Above(x) | Crossing::Below(x) => Some(x),
            Crossing::Always | Crossing::Never => None,
        }
    }

    /// In words, with the 16:9 image of that size.
    pub fn text(self) -> String {
        let (lo, hi) = RANGE_MPX;
        match self {
            Crossing::Always => format!("always ({lo}–{hi:.1} Mpx)"),
            Crossing::Never => format!("never ({lo}–{hi:.1} Mpx)"),
            Crossing::Above(x) => format!("above {x:.2} Mpx ({})", wide(x)),
            Crossing::Below(x) => format!("below {x:.2} Mpx ({}) only", wide(x)),
        }
    }
}

/// The 16:9 image of `mpx` megapixels, `W×H`.
pub fn wide(mpx: f64) -> String {
    let w = (mpx * 1e6 * 16.0 / 9.0).sqrt();
    format!("{:.0}×{:.0}", w, w * 9.0 / 16.0)
}

/// Which PCSS configuration a technique is compared with, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Match {
    /// The cheapest PCSS configuration whose penumbra error is at most [`COMPARABLE`] times the
    /// technique's.
    AsAccurate,
    /// No PCSS configuration is that accurate: the most accurate one.
    MostAccurate,
}

/// The PCSS configuration of `pcss` (index, penumbra mean error, total ms at the run's image)
/// a technique of penumbra error `error` is compared with: the cheapest whose error is at most
/// [`COMPARABLE`]× `error` (as accurate, within 10%), else the most accurate. `None` when
/// `pcss` is empty.
pub fn comparable_pcss(error: f64, pcss: &[(usize, f64, f64)]) -> Option<(usize, Match)> {
    let cheapest = pcss
        .iter()
        .filter(|p| p.1 <= COMPARABLE * error)
        .min_by(|a, b| a.2.total_cmp(&b.2).then(a.1.total_cmp(&b.1)));
    if let Some(p) = cheapest {
        return Some((p.0, Match::AsAccurate));
    }
    pcss.iter()
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)))
        .map(|p| (p.0, Match::MostAccurate))
}

/// The rows the crossover compares: per technique other than PCSS, its most accurate
/// configuration in the penumbra among those on a front (`on_front`), each with the PCSS row
/// it is compared with. Rows without a total time take no part.
pub fn pairs(rows: &[Measurement], on_front: &[usize]) -> Vec<(usize, usize, Match)> {
    let timed = |i: &usize| rows[*i].total_ms.is_some_and(f64::is_finite);
    let pcss: Vec<(usize, f64, f64)> = (0..rows.len())
        .filter(|i| rows[*i].technique == "pcss" && timed(i))
        .map(|i| {
            (
                i,
                rows[i].penumbra.mean_abs,
                rows[i].total_ms.unwrap_or(0.0),
            )
        })
        .collect();
    let mut best: Vec<usize> = Vec::new();
    for &i in on_front.iter().filter(|i| timed(i)) {
        let r = &rows[i];
        if r.technique == "pcss" {
            continue;
        }
        let key = |k: usize| (rows[k].penumbra.mean_abs, rows[k].total_ms.unwrap_or(0.0));
        match best.iter_mut().find(|k| rows[**k].technique == r.technique) {
            Some(k) => {
                let (e, t) = key(*k);
                let (e2, t2) = key(i);
                if e2 < e || (e2 == e && t2 < t) {
                    *k = i;
                }
            }
            None => best.push(i),
        }
    }
    best.sort_unstable();
    best.into_iter()
        .filter_map(|i| {
            let (p, how) = comparable_pcss(rows[i].penumbra.mean_abs, &pcss)?;
            Some((i, p, how))
        })
        .collect()
}

/// The prediction's relative errors at the check size, over the measured configurations.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CheckError {
    /// Median of |predicted − measured| / measured.
    pub median: f64,
    /// Largest.
    pub worst: f64,
}

impl CheckError {
    /// Of the relative errors `e` (`None` when empty).
    pub fn of(e: &[f64]) -> Option<Self> {
        Some(Self {
            median: super::protocol::median(e)?,
            worst: e.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }

    /// Whether it meets the target (median ≤ 10%, worst ≤ 25%).
    pub fn met(self) -> bool {
        self.median <= TARGET_MEDIAN && self.worst <= TARGET_WORST
    }
}

/// |predicted − measured| / measured (infinite for a measured 0).
pub fn relative_error(predicted: f64, measured: f64) -> f64 {
    if measured > 0.0 {
        (predicted - measured).abs() / measured
    } else {
        f64::INFINITY
    }
}

/// One measured configuration's cost per frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cost {
    /// Its row's label.
    pub label: String,
    /// Its technique.
    pub technique: String,
    /// Its row in the report.
    pub row: usize,
    /// Its penumbra mean error.
    pub penumbra: f64,
    /// Raster + prefilter (every light's), ms: the median over the fit sizes' frames.
    pub prefilter_ms: f64,
    /// The shading pass against the image's megapixels, fitted.
    pub shade: Line,
    /// The shading pass measured at each fit size: (Mpx, median ms).
    pub shade_points: Vec<(f64, f64)>,
    /// At the check size, measured and predicted, ms: a moving light's frame (raster +
    /// prefilter + shading) and a static light's (shading).
    pub check: Checked,
}

impl Cost {
    /// The line of a moving light (raster + prefilter + shading) or a static one (shading).
    pub fn line(&self, moving: bool) -> Line {
        if moving {
            self.shade.plus(self.prefilter_ms)
        } else {
            self.shade
        }
    }
}

/// A configuration's cost at the check size, measured and predicted, ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Checked {
    /// Megapixels of the check size.
    pub mpx: f64,
    /// A moving light's frame, measured (the median of raster + prefilter + shading).
    pub moving_measured: f64,
    /// The same, predicted from the fit.
    pub moving_predicted: f64,
    /// A static light's frame, measured (the median shading pass).
    pub static_measured: f64,
    /// The same, predicted.
    pub static_predicted: f64,
}

/// A technique against the PCSS configuration it is compared with.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pair {
    /// The technique's configuration ([`Crossover::costs`] index).
    pub config: usize,
    /// The PCSS configuration's ([`Crossover::costs`] index).
    pub pcss: usize,
    /// Why that PCSS configuration.
    pub matched: Match,
    /// Where the technique is cheaper for a light redrawn every frame.
    pub moving: Crossing,
    /// Where it is cheaper for a static light.
    pub still: Crossing,
}

/// The crossover of a run ([`Report::crossover`](super::Report::crossover)).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Crossover {
    /// Why there is none, when there is none (no PCSS, no timestamps, no other technique on a
    /// front).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The image sizes the shading was fitted at.
    pub fit_sizes: Vec<(u32, u32)>,
    /// The image size the prediction was checked at.
    pub check_size: (u32, u32),
    /// Timed frames per configuration and size (interleaved as the time protocol's).
    pub repeats: u32,
    /// Every measured configuration's cost.
    pub costs: Vec<Cost>,
    /// Per technique, against its PCSS.
    pub pairs: Vec<Pair>,
    /// The prediction's error at the check size for a moving light.
    pub moving_error: CheckError,
    /// The same for a static light.
    pub static_error: CheckError,
}

impl Crossover {
    /// No crossover, and why.
    pub fn none(note: impl Into<String>) -> Self {
        Self {
            note: Some(note.into()),
            ..Self::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact points of a known line give it back; noisy points give the normal equations'
    /// solution computed directly (x̄, ȳ, Σ(x − x̄)(y − ȳ) / Σ(x − x̄)²) to 1e-12.
    #[test]
    fn fit_recovers_a_known_line() {
        let line = Line { a: 3.5, b: 12.25 };
        let pts: Vec<(f64, f64)> = [0.0768, 0.3072, 0.5184]
            .iter()
            .map(|&x| (x, line.at(x)))
            .collect();
        let f = fit(&pts).expect("a fit");
        assert!(
            (f.a - 3.5).abs() < 1e-12 && (f.b - 12.25).abs() < 1e-12,
            "{f:?}"
        );
        let noisy = [(0.1, 4.0), (0.4, 9.5), (0.9, 17.0), (2.0, 30.5)];
        let n = noisy.len() as f64;
        let mx = noisy.iter().map(|p| p.0).sum::<f64>() / n;
        let my = noisy.iter().map(|p| p.1).sum::<f64>() / n;
        let num: f64 = noisy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let den: f64 = noisy.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let f = fit(&noisy).expect("a fit");
        assert!((f.b - num / den).abs() < 1e-12, "{f:?}");
        assert!((f.a - (my - num / den * mx)).abs() < 1e-12, "{f:?}");
        // One size twice is no fit, nor is a non-finite time.
        assert_eq!(fit(&[(0.3, 1.0), (0.3, 2.0)]), None);
        assert_eq!(fit(&[(0.3, 1.0)]), None);
        assert_eq!(fit(&[(0.1, 1.0), (0.3, f64::NAN)]), None);
    }

    /// A technique with a fixed cost of 6 ms and 1 ms/Mpx against PCSS at 1 + 3.5 ms/Mpx:
    /// equal at 2 Mpx (6 + 2 = 1 + 7), cheaper above. Swapped, cheaper below only. Lines apart
    /// over the whole range: always or never. The crossing stays exact at 1e-12.
    #[test]
    fn crossing_of_known_lines() {
        let t = Line { a: 6.0, b: 1.0 };
        let p = Line { a: 1.0, b: 3.5 };
        match crossing(t, p, RANGE_MPX) {
            Crossing::Above(x) => assert!((x - 2.0).abs() < 1e-12, "{x}"),
            c => panic!("{c:?}"),
        }
        match crossing(p, t, RANGE_MPX) {
            Crossing::Below(x) => assert!((x - 2.0).abs() < 1e-12, "{x}"),
            c => panic!("{c:?}"),
        }
        // Cheaper at both ends, dearer at both ends; parallel lines.
        let cheap = Line { a: 0.5, b: 0.9 };
        assert_eq!(crossing(cheap, p, RANGE_MPX), Crossing::Always);
        assert_eq!(crossing(p, cheap, RANGE_MPX), Crossing::Never);
        let above = Line { a: 1.5, b: 3.5 };
        assert_eq!(crossing(above, p, RANGE_MPX), Crossing::Never);
        assert_eq!(crossing(p, p, RANGE_MPX), Crossing::Always);
        // A crossing past the range is no crossing in it: 6 + x = 1 + 1.5x at x = 10 Mpx.
        let late = Line { a: 1.0, b: 1.5 };
        assert_eq!(crossing(t, late, RANGE_MPX), Crossing::Never);
        assert_eq!(Crossing::Above(2.0736).text(), "above 2.07 Mpx (1920×1080)");
    }

    /// The cheapest PCSS within 10% of the technique's error, else the most accurate.
    #[test]
    fn the_pcss_a_technique_is_compared_with() {
        // (row, penumbra error, ms)
        let pcss = [(3, 0.050, 10.0), (4, 0.040, 20.0), (5, 0.030, 40.0)];
        assert_eq!(comparable_pcss(0.046, &pcss), Some((3, Match::AsAccurate)));
        // 0.040 ≤ 1.1 × 0.037 = 0.0407, 0.050 is not.
        assert_eq!(comparable_pcss(0.037, &pcss), Some((4, Match::AsAccurate)));
        assert_eq!(
            comparable_pcss(0.020, &pcss),
            Some((5, Match::MostAccurate))
        );
        assert_eq!(comparable_pcss(0.020, &[]), None);
    }

    /// Relative errors: median and worst, and the target.
    #[test]
    fn check_error_of_known_values() {
        let e = [
            relative_error(11.0, 10.0),
            relative_error(9.5, 10.0),
            relative_error(4.0, 5.0),
        ];
        let c = CheckError::of(&e).expect("errors");
        assert!(
            (c.median - 0.1).abs() < 1e-12 && (c.worst - 0.2).abs() < 1e-12,
            "{c:?}"
        );
        assert!(c.met());
        assert!(
            !CheckError {
                median: 0.05,
                worst: 0.3
            }
            .met()
        );
        assert_eq!(relative_error(1.0, 0.0), f64::INFINITY);
    }
}
