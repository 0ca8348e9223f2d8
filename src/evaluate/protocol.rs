//! The time protocol: how `evaluate` times its configurations so that a device whose clock
//! moves during the run cannot bias one configuration against another.
//!
//! - **Interleaved**: the configurations are visited round-robin, one frame each per round,
//!   for [`Protocol::repeats`] rounds (each round starting one configuration later), never
//!   swept one after the other: a slow stretch of the device's clock falls on every
//!   configuration alike instead of on a block of them.
//! - **Clock check**: a pass that is the same work in every configuration (the camera
//!   G-buffer) is timed in every frame. A configuration whose check pass (median over its
//!   frames) is more than [`Protocol::tolerance`] off the run's median (the median over the
//!   configurations of their check medians, fixed after the first rounds) was measured at
//!   another clock: it is measured again, all its rounds interleaved with the other such
//!   configurations, at most [`Protocol::max_retries`] times, keeping the attempt whose check
//!   is closest to the run's median. One still off after that is flagged ([`Timed::off`]).
//!
//! The logic is pure: it calls a closure that measures one frame of a configuration, so that
//! a test can feed it synthetic timings with a clock drop (no GPU).

use crate::error::Result;

/// How configurations are timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Protocol {
    /// Timed frames per configuration (rounds of the round-robin).
    pub repeats: u32,
    /// Largest relative difference of a configuration's check pass from the run's median
    /// before it is measured again (0.10: 10%).
    pub tolerance: f64,
    /// Most times a configuration is measured again.
    pub max_retries: u32,
}

impl Protocol {
    /// The protocol with `repeats` rounds, a 10% clock check and at most two retries.
    pub fn new(repeats: u32) -> Self {
        Self {
            repeats,
            tolerance: 0.10,
            max_retries: 2,
        }
    }
}

/// One timed frame of a configuration.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sample {
    /// Milliseconds per pass, in pass order (empty when the device cannot time).
    pub passes: Vec<(String, f64)>,
    /// Wall time from submission to completion, ms.
    pub wall_ms: f64,
}

impl Sample {
    /// The time of the pass named `label` (summed if it occurs more than once).
    pub fn pass(&self, label: &str) -> Option<f64> {
        let v: Vec<f64> = self
            .passes
            .iter()
            .filter(|(l, _)| l == label)
            .map(|p| p.1)
            .collect();
        (!v.is_empty()).then(|| v.iter().sum())
    }
}

/// One configuration's timing under the protocol.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timed {
    /// The kept attempt's frames, one per round.
    pub samples: Vec<Sample>,
    /// Median of the check pass over the kept frames (`None` without it).
    pub check_ms: Option<f64>,
    /// Times it was measured again because its check pass was off.
    pub retries: u32,
    /// Whether its check pass is still more than the tolerance off after the retries.
    pub off: bool,
}

/// The whole run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Run {
    /// Per configuration, in the caller's order.
    pub timed: Vec<Timed>,
    /// The run's median of the check pass (over the configurations' first attempts).
    pub check_median: Option<f64>,
    /// Every frame measured, in order: the configuration's index (interleaving is visible).
    pub visits: Vec<usize>,
}

impl Run {
    /// Configurations measured again at least once.
    pub fn retried(&self) -> usize {
        self.timed.iter().filter(|t| t.retries > 0).count()
    }

    /// Configurations still off after their retries.
    pub fn still_off(&self) -> usize {
        self.timed.iter().filter(|t| t.off).count()
    }

    /// The smallest and largest check median over the run's median: the clock's spread
    /// that remains (`None` without a check pass).
    pub fn check_spread(&self) -> Option<(f64, f64)> {
        let m = self.check_median.filter(|m| *m > 0.0)?;
        let q: Vec<f64> = self.timed.iter().filter_map(|t| t.check_ms).collect();
        (!q.is_empty()).then(|| {
            q.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x / m), b.max(x / m))
                })
        })
    }
}

/// The median of `v` (the mean of the two middle values for an even count); `None` when empty.
pub fn median(v: &[f64]) -> Option<f64> {
    quantile(v, 0.5)
}

/// The `q` quantile of `v` by linear interpolation between order statistics; `None` when empty.
pub fn quantile(v: &[f64], q: f64) -> Option<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n == 0 {
        return None;
    }
    let at = q.clamp(0.0, 1.0) * (n - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    Some(s[lo] + (s[hi] - s[lo]) * (at - lo as f64))
}

/// The median of the check pass `check` over `samples`.
fn check_median(samples: &[Sample], check: &str) -> Option<f64> {
    let v: Vec<f64> = samples.iter().filter_map(|s| s.pass(check)).collect();
    median(&v)
}

/// Times the configurations `0..n` under protocol `p`: `measure(c)` renders one timed frame
/// of configuration `c`. Rounds visit `0..n` in order, round `r` starting at `r mod n`.
/// `check` names the pass that is the same work in every configuration. The first error of
/// `measure` ends the run.
pub fn run(
    p: &Protocol,
    n: usize,
    check: &str,
    mut measure: impl FnMut(usize) -> Result<Sample>,
) -> Result<Run> {
    let mut visits = Vec::new();
    let all: Vec<usize> = (0..n).collect();
    let mut attempt = |which: &[usize], visits: &mut Vec<usize>| -> Result<Vec<Vec<Sample>>> {
        let mut got = vec![Vec::new(); which.len()];
        for r in 0..p.repeats as usize {
            for k in 0..which.len() {
                let j = (k + r) % which.len();
                visits.push(which[j]);
                got[j].push(measure(which[j])?);
            }
        }
        Ok(got)
    };
    let first = attempt(&all, &mut visits)?;
    let mut timed: Vec<Timed> = first
        .into_iter()
        .map(|samples| Timed {
            check_ms: check_median(&samples, check),
            samples,
            retries: 0,
            off: false,
        })
        .collect();
    let checks: Vec<f64> = timed.iter().filter_map(|t| t.check_ms).collect();
    let run_median = median(&checks).filter(|m| *m > 0.0);
    let Some(m) = run_median else {
        return Ok(Run {
            timed,
            check_median: None,
            visits,
        });
    };
    let dist = |t: &Timed| t.check_ms.map_or(0.0, |c| (c / m - 1.0).abs());
    for _ in 0..p.max_retries {
        let off: Vec<usize> = (0..n).filter(|&c| dist(&timed[c]) > p.tolerance).collect();
        if off.is_empty() {
            break;
        }
        let again = attempt(&off, &mut visits)?;
        for (&c, samples) in off.iter().zip(again) {
            let candidate = Timed {
                check_ms: check_median(&samples, check),
                samples,
                retries: timed[c].retries + 1,
                off: false,
            };
            if dist(&candidate) < dist(&timed[c]) {
                timed[c] = candidate;
            } else {
                timed[c].retries += 1;
            }
        }
    }
    for t in &mut timed {
        t.off = dist(t) > p.tolerance;
    }
    Ok(Run {
        timed,
        check_median: run_median,
        visits,
    })
}

/// Median, quartiles and range of a time over a configuration's frames, ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spread {
    /// Frames.
    pub n: usize,
    /// Median.
    pub median: f64,
    /// First quartile.
    pub q1: f64,
    /// Third quartile.
    pub q3: f64,
    /// Fastest frame.
    pub min: f64,
    /// Slowest frame.
    pub max: f64,
}

impl Spread {
    /// The spread of `v` (`None` when empty).
    pub fn of(v: &[f64]) -> Option<Self> {
        let q = |x| quantile(v, x);
        Some(Self {
            n: v.len(),
            median: q(0.5)?,
            q1: q(0.25)?,
            q3: q(0.75)?,
            min: q(0.0)?,
            max: q(1.0)?,
        })
    }

    /// `median (q1–q3)`, each with `decimals`.
    pub fn text(&self, decimals: usize) -> String {
        format!(
            "{:.decimals$} ({:.decimals$}–{:.decimals$})",
            self.median, self.q1, self.q3
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six configurations whose passes take `base[c]` ms and whose check pass is 1 ms at the
    /// full clock. The clock drops (every pass 2× slow) in configuration 2's first attempt
    /// and for all of configuration 4's frames: 2 is measured again once and kept from the
    /// retry (its times the fast clock's), 4 is measured again `max_retries` times and
    /// flagged; no other is retried. The visits interleave: each round visits all six, no
    /// configuration twice in a row.
    #[test]
    fn a_clock_drop_is_retried_and_flagged() {
        let base = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let mut seen = [0usize; 6];
        let p = Protocol::new(5);
        let run = run(&p, 6, "gbuffer", |c| {
            seen[c] += 1;
            let slow = (c == 2 && seen[c] <= 5) || c == 4;
            let k = if slow { 2.0 } else { 1.0 };
            Ok(Sample {
                passes: vec![("gbuffer".into(), k), ("shade".into(), k * base[c])],
                wall_ms: k * (1.0 + base[c]),
            })
        })
        .expect("run");
        assert_eq!(run.check_median, Some(1.0));
        let retries: Vec<u32> = run.timed.iter().map(|t| t.retries).collect();
        assert_eq!(retries, [0, 0, 1, 0, 2, 0]);
        let off: Vec<bool> = run.timed.iter().map(|t| t.off).collect();
        assert_eq!(off, [false, false, false, false, true, false]);
        assert_eq!((run.retried(), run.still_off()), (2, 1));
        assert_eq!(run.check_spread(), Some((1.0, 2.0)));
        for (c, t) in run.timed.iter().enumerate() {
            assert_eq!(t.samples.len(), 5);
            let shade: Vec<f64> = t.samples.iter().filter_map(|s| s.pass("shade")).collect();
            let want = if c == 4 { 2.0 * base[c] } else { base[c] };
            assert_eq!(median(&shade), Some(want), "configuration {c}");
        }
        // 30 first visits, 10 retries (2 and 4), 5 more (4).
        assert_eq!(run.visits.len(), 30 + 10 + 5);
        for round in run.visits[..30].chunks(6) {
            let mut r = round.to_vec();
            r.sort();
            assert_eq!(r, [0, 1, 2, 3, 4, 5]);
        }
        assert!(run.visits[..30].windows(2).all(|w| w[0] != w[1]));
        assert_ne!(&run.visits[..6], &run.visits[6..12], "rounds start apart");
    }

    /// Without a check pass (a device that cannot time) nothing is retried or flagged.
    #[test]
    fn no_check_pass_no_retry() {
        let run = run(&Protocol::new(3), 4, "gbuffer", |_| Ok(Sample::default())).expect("run");
        assert_eq!(run.visits.len(), 12);
        assert_eq!((run.retried(), run.still_off()), (0, 0));
        assert_eq!(run.check_spread(), None);
    }

    /// Quantiles against a direct count on a small set.
    #[test]
    fn spread_of_known_values() {
        let s = Spread::of(&[4.0, 1.0, 3.0, 2.0, 5.0]).expect("spread");
        assert_eq!(
            (s.n, s.median, s.q1, s.q3, s.min, s.max),
            (5, 3.0, 2.0, 4.0, 1.0, 5.0)
        );
        assert_eq!(median(&[1.0, 2.0, 4.0, 10.0]), Some(3.0));
        assert_eq!(Spread::of(&[]), None);
    }
}
