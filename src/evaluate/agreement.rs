//! Whether two runs of one evaluation agree: each Pareto front's configurations the same, or
//! differing only by ties within the spread (a configuration on one run's front that the other
//! run's front dominates only with times whose range overlaps its own), and each front
//! configuration's range of times overlapping the other run's. A lavapipe front is only
//! worth reading where a second run on the same machine agrees with it (the machine's load
//! moves CPU-driver times), and a GPU run is checked against the next the same way:
//! `shadowgraph compare A/report.json B/report.json`.

use std::fmt::Write as _;

use super::{Metric, Report, front};
use crate::error::{Error, Result};

/// One configuration on either run's front of one metric.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontConfig {
    /// The configuration's label.
    pub label: String,
    /// On the first run's front.
    pub on_a: bool,
    /// On the second run's front.
    pub on_b: bool,
    /// Each run's total time: median, fastest and slowest frame, ms.
    pub times: [[f64; 3]; 2],
    /// On one run's front only, and in the other run dominated only by configurations whose
    /// range of times overlaps its own: a tie within the spread.
    pub tied: bool,
}

impl FrontConfig {
    /// Whether the two runs' ranges (fastest to slowest frame) overlap.
    pub fn ranges_overlap(&self) -> bool {
        let [[_, min_a, max_a], [_, min_b, max_b]] = self.times;
        min_a.max(min_b) <= max_a.min(max_b)
    }

    /// Whether each run's median lies inside the other's range.
    pub fn medians_inside(&self) -> bool {
        let inside = |m: f64, [_, lo, hi]: [f64; 3]| (lo..=hi).contains(&m);
        inside(self.times[0][0], self.times[1]) && inside(self.times[1][0], self.times[0])
    }
}

/// The two runs' fronts of one metric.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontAgreement {
    /// The metric.
    pub metric: Metric,
    /// The techniques on each run's front, sorted.
    pub techniques: [Vec<String>; 2],
    /// Every configuration on either front, the first run's fastest first.
    pub configs: Vec<FrontConfig>,
}

impl FrontAgreement {
    /// Every configuration on both fronts or tied within the spread, and its ranges in the two
    /// runs overlapping.
    pub fn agrees(&self) -> bool {
        self.configs
            .iter()
            .all(|c| c.ranges_overlap() && ((c.on_a && c.on_b) || c.tied))
    }
}

/// Two runs compared ([`compare`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Agreement {
    /// Configurations timed in both runs.
    pub common: usize,
    /// Of those, how many have each run's median inside the other's range.
    pub medians_inside: usize,
    /// The second run's median total over the first's: the median ratio and the range.
    pub ratio: [f64; 3],
    /// Per metric, the fronts.
    pub fronts: Vec<FrontAgreement>,
}

impl Agreement {
    /// Whether every front agrees ([`FrontAgreement::agrees`]).
    pub fn agrees(&self) -> bool {
        self.fronts.iter().all(FrontAgreement::agrees)
    }

    /// The comparison as Markdown: a summary line, then per front its techniques and each
    /// configuration's times.
    pub fn text(&self) -> String {
        let [r, lo, hi] = self.ratio;
        let mut out = format!(
            "{} configurations in both runs; the second's totals {r:.3}× the first's at the \
             median ({lo:.2}–{hi:.2}× per configuration); {} of them with each median inside \
             the other run's range.\n",
            self.common, self.medians_inside
        );
        for f in &self.fronts {
            let verdict = if f.agrees() { "agree" } else { "differ" };
            let _ = write!(
                out,
                "\n{} front: {verdict}. Techniques: {} | {}\n\n| configuration | front | \
                 first: median (range) ms | second | ranges overlap |\n| --- | --- | ---: | ---: \
                 | --- |\n",
                f.metric.name(),
                f.techniques[0].join(", "),
                f.techniques[1].join(", "),
            );
            for c in &f.configs {
                let on = match (c.on_a, c.on_b, c.tied) {
                    (true, true, _) => "both",
                    (true, false, true) => "first (a tie in the second)",
                    (true, false, false) => "first",
                    (false, _, true) => "second (a tie in the first)",
                    _ => "second",
                };
                let t = |[m, lo, hi]: [f64; 3]| format!("{m:.3} ({lo:.3}–{hi:.3})");
                let _ = writeln!(
                    out,
                    "| {} | {on} | {} | {} | {} |",
                    c.label,
                    t(c.times[0]),
                    t(c.times[1]),
                    if c.ranges_overlap() { "yes" } else { "no" }
                );
            }
        }
        out
    }
}

/// Compares two reports of the same scene (matched by configuration label; a report from
/// before the time protocol has a median without a range, which then stands for both ends).
/// Errors when the
/// scenes differ or the runs have no timed configuration in common.
pub fn compare(a: &Report, b: &Report) -> Result<Agreement> {
    if a.scene != b.scene {
        return Err(Error::Invalid(format!(
            "compare: the reports are of different scenes ({} and {})",
            a.scene, b.scene
        )));
    }
    let times = |r: &Report, label: &str| {
        let m = r.rows.iter().find(|m| m.label == label)?;
        match m.total_spread {
            Some(s) => Some([s.median, s.min, s.max]),
            // A report from before the time protocol: its median alone.
            None => m.total_ms.map(|t| [t; 3]),
        }
    };
    let mut ratios = Vec::new();
    let mut medians_inside = 0;
    for m in &a.rows {
        if let (Some(ta), Some(tb)) = (times(a, &m.label), times(b, &m.label)) {
            ratios.push(tb[0] / ta[0]);
            let c = FrontConfig {
                label: m.label.clone(),
                on_a: false,
                on_b: false,
                times: [ta, tb],
                tied: false,
            };
            medians_inside += usize::from(c.medians_inside());
        }
    }
    if ratios.is_empty() {
        return Err(Error::Invalid(format!(
            "compare: no configuration of {} is timed in both reports",
            a.scene
        )));
    }
    ratios.sort_by(f64::total_cmp);
    let ratio = [
        ratios[ratios.len() / 2],
        ratios[0],
        ratios[ratios.len() - 1],
    ];
    let metrics = Metric::of(a)
        .into_iter()
        .filter(|m| Metric::of(b).contains(m));
    let fronts = metrics.map(|metric| front_agreement(a, b, metric, &times));
    Ok(Agreement {
        common: ratios.len(),
        medians_inside,
        ratio,
        fronts: fronts.collect(),
    })
}

fn front_agreement(
    a: &Report,
    b: &Report,
    metric: Metric,
    times: &dyn Fn(&Report, &str) -> Option<[f64; 3]>,
) -> FrontAgreement {
    let labels = |r: &Report| -> Vec<String> {
        front(&r.rows, metric)
            .into_iter()
            .map(|i| r.rows[i].label.clone())
            .collect()
    };
    let techniques = |r: &Report, front: &[String]| {
        let mut t: Vec<String> = r
            .rows
            .iter()
            .filter(|m| front.contains(&m.label))
            .map(|m| m.technique.clone())
            .collect();
        t.sort();
        t.dedup();
        t
    };
    let (fa, fb) = (labels(a), labels(b));
    let mut all = fa.clone();
    all.extend(fb.iter().filter(|l| !fa.contains(l)).cloned());
    let configs = all
        .into_iter()
        .filter_map(|label| {
            let t = [times(a, &label)?, times(b, &label)?];
            let (on_a, on_b) = (fa.contains(&label), fb.contains(&label));
            let tied = match (on_a, on_b) {
                (true, false) => tied(b, metric, &label, times),
                (false, true) => tied(a, metric, &label, times),
                _ => false,
            };
            Some(FrontConfig {
                on_a,
                on_b,
                label,
                times: t,
                tied,
            })
        })
        .collect();
    FrontAgreement {
        metric,
        techniques: [techniques(a, &fa), techniques(b, &fb)],
        configs,
    }
}

/// Whether every configuration of `r` that dominates `label` in (median time, `metric`) has a
/// range of times overlapping `label`'s: `label` is off `r`'s front by a tie within the spread.
fn tied(
    r: &Report,
    metric: Metric,
    label: &str,
    times: &dyn Fn(&Report, &str) -> Option<[f64; 3]>,
) -> bool {
    let Some(row) = r.rows.iter().find(|m| m.label == label) else {
        return false;
    };
    let Some([median, min, max]) = times(r, label) else {
        return false;
    };
    let error = metric.value(row);
    r.rows
        .iter()
        .filter(|d| d.label != label && metric.value(d) <= error)
        .filter_map(|d| times(r, &d.label))
        .filter(|t| t[0] <= median)
        .all(|[_, lo, hi]| lo.max(min) <= hi.min(max))
}

/// Reads a `report.json` that `evaluate` wrote.
pub fn read_report(path: &std::path::Path) -> Result<Report> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))?;
    serde_json::from_str(&text).map_err(|e| {
        Error::Invalid(format!(
            "{}: line {}: not an evaluation report: {e}",
            path.display(),
            e.line()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A committed report (a real run: 100+ configurations, fronts of several techniques).
    fn committed() -> Report {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("benches/evaluation/long_shadows/report.json");
        read_report(&path).expect("committed report")
    }

    /// Scales every frame time of the row `label` by `k`.
    fn scale(r: &mut Report, label: &str, k: f64) {
        let m = r.rows.iter_mut().find(|m| m.label == label).expect("row");
        m.total_ms = m.total_ms.map(|t| t * k);
        let s = m.total_spread.as_mut().expect("timed");
        for v in [&mut s.median, &mut s.q1, &mut s.q3, &mut s.min, &mut s.max] {
            *v *= k;
        }
    }

    #[test]
    fn a_run_agrees_with_itself() {
        let a = committed();
        let c = compare(&a, &a).unwrap();
        assert!(c.agrees(), "{}", c.text());
        assert_eq!(c.ratio, [1.0; 3]);
        assert_eq!(c.medians_inside, c.common);
        assert!(c.common > 50 && c.fronts.len() >= 3);
        assert!(
            c.fronts
                .iter()
                .all(|f| f.configs.iter().all(|x| x.on_a && x.on_b))
        );
    }

    /// Slowing the fastest configuration of a front 3× takes it off that front (it is then
    /// dominated or its range leaves the other's): the fronts differ, and the summary counts
    /// exactly one configuration whose median left the other's range.
    #[test]
    fn a_slowed_front_configuration_is_reported() {
        let a = committed();
        let first = front(&a.rows, Metric::Penumbra)[0];
        let label = a.rows[first].label.clone();
        let mut b = a.clone();
        scale(&mut b, &label, 3.0);
        let c = compare(&a, &b).unwrap();
        assert_eq!(c.common - c.medians_inside, 1, "{}", c.text());
        assert_eq!(c.ratio[2], 3.0);
        let penumbra = c
            .fronts
            .iter()
            .find(|f| f.metric == Metric::Penumbra)
            .unwrap();
        let row = penumbra.configs.iter().find(|x| x.label == label).unwrap();
        assert!(row.on_a && !row.ranges_overlap(), "{}", c.text());
        assert!(!penumbra.agrees() && !c.agrees());
        assert!(c.text().contains("penumbra mean front: differ"));
    }

    /// Two runs of `sphere_on_plane` in a row on an idle machine (`benches/agreement/`): the
    /// soft-mean front holds `pcss 16+32 512` in the first run only, where in the second it is
    /// dominated by `evsm4 f32 mips9 512` alone (30.9 ms, range 30.6–32.2, against its own
    /// 34.8, 29.9–38.0): a tie, so every front agrees; slowing that PCSS configuration 2× in
    /// the second run makes it a real difference.
    #[test]
    fn a_tie_within_the_spread_agrees_and_a_real_gap_does_not() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/agreement");
        let a = read_report(&dir.join("sphere_on_plane_first.json")).unwrap();
        let b = read_report(&dir.join("sphere_on_plane_second.json")).unwrap();
        let c = compare(&a, &b).unwrap();
        assert!(c.agrees(), "{}", c.text());
        let soft = c.fronts.iter().find(|f| f.metric == Metric::Mean).unwrap();
        let pcss = soft
            .configs
            .iter()
            .find(|x| x.label == "pcss 16+32 512")
            .unwrap();
        assert!(pcss.on_a && !pcss.on_b && pcss.tied, "{}", c.text());
        assert_ne!(soft.techniques[0], soft.techniques[1]);
        let mut slow = b.clone();
        scale(&mut slow, "pcss 16+32 512", 2.0);
        let c = compare(&a, &slow).unwrap();
        assert!(!c.agrees(), "{}", c.text());
    }

    #[test]
    fn different_scenes_or_no_common_rows_are_errors() {
        let a = committed();
        let mut b = a.clone();
        b.scene = "scenes/pole.toml".into();
        let e = compare(&a, &b).unwrap_err().to_string();
        assert!(e.contains("different scenes"), "{e}");
        let mut b = a.clone();
        for m in &mut b.rows {
            m.label.push_str(" other");
        }
        let e = compare(&a, &b).unwrap_err().to_string();
        assert!(e.contains("no configuration"), "{e}");
    }
}
