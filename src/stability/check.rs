//! The one comparison helper of the suite: GPU values against f64 references, each value with
//! its own bound, keeping the value closest to (or farthest past) its bound, the count of
//! non-finite GPU values and the count of values outside their bounds. Also the suite's
//! deterministic random numbers.

use super::{StabilityRow, Verdict};

/// f32's unit roundoff (round to nearest).
pub(crate) use crate::tolerance::U;

/// Accumulates comparisons for one [`StabilityRow`].
#[derive(Debug, Default)]
pub(crate) struct Check {
    /// Values compared.
    values: usize,
    /// Non-finite GPU values (each also a failure).
    nonfinite: u64,
    /// Values outside their bounds (non-finite ones included).
    failures: usize,
    /// `(error, bound, ratio, where)` of the value with the largest `error / bound`.
    worst: Option<(f64, f64, f64, String)>,
    /// The largest finite error and where (shown when it is not the worst value's).
    largest: Option<(f64, String)>,
    /// Extra failures that are not value comparisons (a wrong count, a violated order).
    problems: Vec<String>,
}

impl Check {
    /// An empty check.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// `|gpu − reference| ≤ bound`; `at` names the value (only formatted when it is the worst).
    pub(crate) fn compare(
        &mut self,
        gpu: f64,
        reference: f64,
        bound: f64,
        at: impl Fn() -> String,
    ) {
        self.values += 1;
        if !gpu.is_finite() {
            self.nonfinite += 1;
            self.failures += 1;
            let ratio = f64::INFINITY;
            if self.worst.as_ref().is_none_or(|w| w.2 < ratio) {
                self.worst = Some((f64::INFINITY, bound, ratio, at()));
            }
            return;
        }
        if !reference.is_finite() {
            self.failures += 1;
            if self.worst.as_ref().is_none_or(|w| w.2 < f64::INFINITY) {
                self.worst = Some((
                    f64::INFINITY,
                    bound,
                    f64::INFINITY,
                    format!("{} (reference {reference})", at()),
                ));
            }
            return;
        }
        let error = (gpu - reference).abs();
        let ratio = if error == 0.0 {
            0.0
        } else if bound > 0.0 {
            error / bound
        } else {
            f64::INFINITY
        };
        let within = matches!(
            error.partial_cmp(&bound),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        );
        if !within {
            self.failures += 1;
        }
        if error > self.largest.as_ref().map_or(0.0, |l| l.0) {
            self.largest = Some((error, at()));
        }
        if self.worst.as_ref().is_none_or(|w| w.2 < ratio) {
            self.worst = Some((error, bound, ratio, at()));
        }
    }

    /// Records a failure that is not a value comparison.
    pub(crate) fn problem(&mut self, what: impl Into<String>) {
        self.problems.push(what.into());
    }

    /// Folds `other`'s comparisons into this check.
    pub(crate) fn merge(&mut self, other: Check) {
        self.values += other.values;
        self.nonfinite += other.nonfinite;
        self.failures += other.failures;
        self.problems.extend(other.problems);
        if let Some(w) = other.worst {
            if self.worst.as_ref().is_none_or(|mine| mine.2 < w.2) {
                self.worst = Some(w);
            }
        }
        if let Some(l) = other.largest {
            if self.largest.as_ref().is_none_or(|mine| mine.0 < l.0) {
                self.largest = Some(l);
            }
        }
    }

    /// The row: `pass` when every value is finite and within its bound and nothing else went
    /// wrong; a check that compared nothing fails (it could not have failed otherwise).
    pub(crate) fn row(self, case: u8, what: &str, technique: &str, storage: &str) -> StabilityRow {
        let (error, bound, _, at) = self.worst.unwrap_or((0.0, 0.0, 0.0, String::new()));
        let mut note = if at.is_empty() {
            format!("{} values", self.values)
        } else if error == 0.0 {
            format!("{} values, all exact", self.values)
        } else {
            format!("{} values; worst at {at}", self.values)
        };
        if let Some((e, at)) = self.largest.filter(|l| l.0 > error) {
            note = format!("{note}; largest error {e:.3e} at {at}");
        }
        let mut verdict = Verdict::Pass;
        if self.values == 0 {
            verdict = Verdict::Fail;
            note = "nothing was compared".into();
        }
        if self.failures > 0 {
            verdict = Verdict::Fail;
            note = format!("{} of {}", self.failures, note);
        }
        if !self.problems.is_empty() {
            verdict = Verdict::Fail;
            note = format!("{}; {note}", self.problems.join("; "));
        }
        StabilityRow {
            case,
            what: what.into(),
            technique: technique.into(),
            storage: storage.into(),
            error,
            bound,
            nonfinite: self.nonfinite,
            values: self.values,
            verdict,
            note,
        }
    }

    /// A row whose number is measured and shown, with no bound to meet (`bound` may still be
    /// the model value it is shown against, or NaN for none).
    pub(crate) fn reported(
        case: u8,
        [what, technique, storage]: [&str; 3],
        value: f64,
        bound: f64,
        nonfinite: u64,
        note: String,
    ) -> StabilityRow {
        StabilityRow {
            case,
            what: what.into(),
            technique: technique.into(),
            storage: storage.into(),
            error: value,
            bound,
            nonfinite,
            values: 1,
            verdict: Verdict::Reported,
            note,
        }
    }
}

/// SplitMix64: a small deterministic generator, so every run checks the same inputs and a
/// failure reproduces.
#[derive(Clone, Debug)]
pub(crate) struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform integer in `[0, n)` (`n > 0`).
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_past_its_bound_fails_and_is_the_worst() {
        let mut c = Check::new();
        c.compare(1.0, 1.0, 0.0, || "exact".into());
        c.compare(1.5, 1.0, 1.0, || "inside".into());
        c.compare(2.0, 1.0, 0.5, || "outside".into());
        let row = c.row(1, "w", "t", "s");
        assert_eq!(row.verdict, Verdict::Fail);
        assert_eq!((row.error, row.bound), (1.0, 0.5));
        assert!(row.note.contains("outside") && row.note.starts_with("1 of 3"));
    }

    #[test]
    fn non_finite_values_and_empty_checks_fail() {
        let mut c = Check::new();
        c.compare(f64::NAN, 1.0, 10.0, || "nan".into());
        let row = c.row(1, "w", "t", "s");
        assert_eq!((row.verdict, row.nonfinite), (Verdict::Fail, 1));
        assert_eq!(Check::new().row(1, "w", "t", "s").verdict, Verdict::Fail);
        let mut c = Check::new();
        c.compare(0.0, f64::NAN, 1.0, String::new);
        assert_eq!(c.row(1, "w", "t", "s").verdict, Verdict::Fail);
    }

    #[test]
    fn a_problem_fails_an_otherwise_clean_check() {
        let mut c = Check::new();
        c.compare(1.0, 1.0, 0.0, String::new);
        c.problem("count 3, expected 4");
        let row = c.row(1, "w", "t", "s");
        assert_eq!(row.verdict, Verdict::Fail);
        assert!(row.note.starts_with("count 3"));
        let mut c = Check::new();
        c.compare(1.0, 1.0 + 1e-9, 1e-8, String::new);
        assert_eq!(c.row(1, "w", "t", "s").verdict, Verdict::Pass);
    }

    #[test]
    fn merged_checks_keep_the_worst_and_the_counts() {
        let mut a = Check::new();
        a.compare(1.1, 1.0, 1.0, || "a".into());
        let mut b = Check::new();
        b.compare(1.5, 1.0, 1.0, || "b".into());
        b.compare(f64::INFINITY, 1.0, 1.0, || "b inf".into());
        a.merge(b);
        let row = a.row(1, "w", "t", "s");
        assert_eq!(
            (row.values, row.nonfinite, row.verdict),
            (3, 1, Verdict::Fail)
        );
        assert!(row.note.contains("b inf"));
    }

    #[test]
    fn rng_is_uniform_enough_and_deterministic() {
        let mut a = Rng::new(7);
        let mut b = Rng::new(7);
        let xs: Vec<f64> = (0..10_000).map(|_| a.unit()).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        assert_eq!(xs[0], b.unit());
        assert!((0..1000).all(|_| a.below(7) < 7));
    }
}
