//! The numerical-stability suite (`shadowgraph stability`): the inputs where shadow techniques
//! are known to break numerically, each run through the real kernels and compared against an
//! independent f64 reference (`crate::cpu`), with a stated bound and the reason for it.
//!
//! | case | what | bound, and why |
//! | --- | --- | --- |
//! | 1 | SAT window sums of a constant 0.999 map and a random map (8192² with `large`), 1×1 up to the whole map, at the far corner | fixed point: exact integer sums, so the u32 table equals the wrapping-integer reference and every window mean is within the quantization `½/scale` (+ one f32 rounding of `v − offset`); f32: the scan's rounding model, `(d + 3)·u·Σ|corner sums|` |
//! | 2 | VSM, EVSM2, EVSM4 over a constant occluder (zero variance), receivers at, in front of and behind it | in front and at: exactly 1; behind: first-order f32 propagation through the Chebyshev bound |
//! | 3 | MSM (f32, f16, unorm16) on flat maps (all-equal moments), at depth exactly 0 and 1 | finite, in [0, 1], non-increasing in the receiver depth (up to the f32 evaluation error), and the f64 reference's sensitivity to f32 perturbations of the stored moments (and, with Hausdorff, to which of its two formulas rounding picks) |
//! | 4 | EVSM at the fp32/fp16 exponent limits, ESM far past them: encode, blur, mips, SAT | no Inf; each stage within its f32/f16 rounding model of the f64 stage; the validator clamps (EVSM) or refuses exponents past its range |
//! | 5 | CSM with M = 16, receivers at blocker depths and at 0 and 1 | in [0, 1] and within Vulkan's sin/cos accuracy of the f64 series; ringing away from the step within a summation-by-parts bound |
//! | 6 | NaN, +Inf, −Inf in the depth buffer | replaced and counted at `linearize`; every downstream texel finite and within the stage's tolerance of the f64 pipeline on the sanitized map |
//! | 7 | near/far 1e-4 and 0.999, spot and directional | linear depth within 5 f32 roundings of the f64 linearization; the depth buffer's own step reported against the bias |
//! | 8 | MSM (f32, f16, unorm16; soft MSM f32, f16) with the receiver 10⁻⁵–10⁻¹ behind a flat occluder, at the default moment biases | within 0.01 (f32), 0.03 (unorm16), 0.05 (soft MSM's tables) or 0.25 (f16) of exact MSM on the occluder's point mass with the same bias: the requirement the defaults were chosen to meet |
//!
//! Each case returns [`StabilityRow`]s; [`run`] runs them all, [`StabilityReport::table`] formats them.

mod check;
mod csm_ringing;
mod exponents;
mod frusta;
mod harness;
mod msm_bias;
mod msm_contact;
mod msm_flat;
mod msm_maps;
mod non_finite;
mod planar;
mod sat_windows;
mod stages;

use std::fmt::Write;
use std::time::Instant;

use crate::error::Result;
use crate::gpu::Gpu;

pub use exponents::sat_coding_for;
pub use msm_bias::{BiasRow, BiasSweep, bias_table, msm_bias_sweep};
pub use sat_windows::SatTables;

/// The outcome of one row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every value within its bound, nothing non-finite.
    Pass,
    /// Something past its bound, non-finite, or nothing compared.
    Fail,
    /// A measured figure shown for information, with no bound to meet.
    Reported,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "FAIL",
            Verdict::Reported => "reported",
        })
    }
}

/// One line of the report: a quantity measured on the GPU against its f64 reference.
#[derive(Clone, Debug)]
pub struct StabilityRow {
    /// Case number (1–8, see the module documentation).
    pub case: u8,
    /// What is measured (e.g. `window means`).
    pub what: String,
    /// Technique or kernel chain (e.g. `evsm4 c=42 → blur`).
    pub technique: String,
    /// Storage or coding (e.g. `f16`, `fixed u32`).
    pub storage: String,
    /// The worst error: of the value with the largest error relative to its bound.
    pub error: f64,
    /// That value's bound (a uniform bound where the bound does not vary).
    pub bound: f64,
    /// NaN or ±Inf values seen on the GPU.
    pub nonfinite: u64,
    /// Values compared.
    pub values: usize,
    /// The verdict.
    pub verdict: Verdict,
    /// Where the worst value is, or what a reported figure means.
    pub note: String,
}

/// What [`run`] runs.
#[derive(Clone, Copy, Debug, Default)]
pub struct StabilityOptions {
    /// Case 1 at 8192² (six 256 MiB tables; 75–95 s on lavapipe with 2 cores) instead of 2048².
    pub large: bool,
}

/// Every row of a run, with the seconds each case took.
#[derive(Clone, Debug, Default)]
pub struct StabilityReport {
    /// All rows, case by case.
    pub rows: Vec<StabilityRow>,
    /// `(case, seconds)`.
    pub seconds: Vec<(u8, f64)>,
    /// The device it ran on.
    pub device: String,
}

/// The side of case 1's maps.
pub fn sat_size(opts: &StabilityOptions) -> u32 {
    if opts.large { 8192 } else { 2048 }
}

/// The cases in order: number, name, function.
type CaseFn = fn(&Gpu, &StabilityOptions) -> Result<Vec<StabilityRow>>;
const CASES: [(u8, &str, CaseFn); 8] = [
    (1, "summed-area tables", |g, o| {
        sat_windows::sat_case(g, sat_size(o), SatTables::All)
    }),
    (2, "VSM/EVSM on a planar receiver", |g, _| {
        planar::planar_case(g)
    }),
    (3, "MSM on flat maps and at 0 and 1", |g, _| {
        msm_flat::msm_case(g)
    }),
    (4, "exponents at and past the limits", |g, _| {
        exponents::exponent_case(g)
    }),
    (5, "CSM (M = 16) ringing", |g, _| csm_ringing::csm_case(g)),
    (6, "non-finite depth", |g, _| non_finite::non_finite_case(g)),
    (7, "deep and shallow frusta", |g, _| frusta::frusta_case(g)),
    (8, "MSM behind a flat occluder", |g, _| {
        msm_contact::msm_contact_case(g)
    }),
];

/// Case 1: SAT window sums at `size`² (see the module documentation) for `tables`.
pub fn sat_case(gpu: &Gpu, size: u32, tables: SatTables) -> Result<Vec<StabilityRow>> {
    sat_windows::sat_case(gpu, size, tables)
}

/// Case 2: VSM/EVSM over a zero-variance planar occluder.
pub fn planar_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    planar::planar_case(gpu)
}

/// Case 3: MSM with all-equal moments and depths exactly 0 and 1.
pub fn msm_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    msm_flat::msm_case(gpu)
}

/// Case 4: EVSM and ESM exponents at and past the storage limits, through every filter.
pub fn exponent_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    exponents::exponent_case(gpu)
}

/// Case 5: CSM (M = 16) at blocker depths and at 0 and 1, and its ringing.
pub fn csm_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    csm_ringing::csm_case(gpu)
}

/// Case 6: NaN and ±Inf in the depth buffer.
pub fn non_finite_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    non_finite::non_finite_case(gpu)
}

/// Case 7: linear depth of very deep and very shallow frusta.
pub fn frusta_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    frusta::frusta_case(gpu)
}

/// Case 8: MSM with the receiver just behind a flat occluder, at the default moment biases.
pub fn msm_contact_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    msm_contact::msm_contact_case(gpu)
}

/// Runs every case; `progress(case, name)` is called before each.
pub fn run(
    gpu: &Gpu,
    opts: &StabilityOptions,
    progress: &mut dyn FnMut(u8, &str),
) -> Result<StabilityReport> {
    let mut report = StabilityReport {
        device: gpu.describe(),
        ..Default::default()
    };
    for (case, name, f) in CASES {
        progress(case, name);
        let start = Instant::now();
        report.rows.extend(f(gpu, opts)?);
        report.seconds.push((case, start.elapsed().as_secs_f64()));
    }
    Ok(report)
}

impl StabilityReport {
    /// Rows that failed.
    pub fn failures(&self) -> Vec<&StabilityRow> {
        self.rows
            .iter()
            .filter(|r| r.verdict == Verdict::Fail)
            .collect()
    }

    /// The report as a table: case, what, technique, storage, worst error, bound, NaN/Inf
    /// count, verdict, and where the worst value is; then the time per case.
    pub fn table(&self) -> String {
        let mut s = format!("numerical stability on {}\n", self.device);
        let head = [
            "case",
            "what",
            "technique",
            "storage",
            "worst error",
            "bound",
            "NaN/Inf",
            "verdict",
            "note",
        ];
        let cells: Vec<[String; 9]> = self
            .rows
            .iter()
            .map(|r| {
                [
                    r.case.to_string(),
                    r.what.clone(),
                    r.technique.clone(),
                    r.storage.clone(),
                    number(r.error),
                    number(r.bound),
                    r.nonfinite.to_string(),
                    r.verdict.to_string(),
                    r.note.clone(),
                ]
            })
            .collect();
        let mut width = head.map(|h| h.chars().count());
        for row in &cells {
            for (w, c) in width.iter_mut().zip(row) {
                *w = (*w).max(c.chars().count());
            }
        }
        let line = |s: &mut String, cols: &[&str]| {
            let last = cols.len() - 1;
            for (i, c) in cols.iter().enumerate() {
                if i == last {
                    let _ = writeln!(s, "{c}");
                } else {
                    let pad = width[i] - c.chars().count();
                    let _ = write!(s, "{c}{}  ", " ".repeat(pad));
                }
            }
        };
        line(&mut s, &head);
        for row in &cells {
            let cols: Vec<&str> = row.iter().map(String::as_str).collect();
            line(&mut s, &cols);
        }
        let fails = self.failures().len();
        let _ = writeln!(
            s,
            "{} rows: {} pass, {fails} FAIL, {} reported",
            self.rows.len(),
            self.rows
                .iter()
                .filter(|r| r.verdict == Verdict::Pass)
                .count(),
            self.rows
                .iter()
                .filter(|r| r.verdict == Verdict::Reported)
                .count()
        );
        let times: Vec<String> = self
            .seconds
            .iter()
            .map(|(c, t)| format!("case {c} {t:.1} s"))
            .collect();
        let _ = writeln!(s, "time: {}", times.join(", "));
        s
    }
}

/// A number for the table: `0`, `-` for NaN (no bound), `inf`, four decimals between 10⁻³
/// and 10⁴, else scientific with three decimals.
fn number(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.is_nan() {
        "-".into()
    } else if v.is_infinite() {
        "inf".into()
    } else if (1e-3..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}
