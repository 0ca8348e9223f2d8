//! The numerical-stability suite (`shadowgraph::low_level::stability`, `shadowgraph stability`), one test
//! per case. Each case runs the real kernels on its hard inputs and compares every value with
//! an independent f64 reference (`shadowgraph::low_level::cpu`) under a bound stated, with its reason, in
//! the case's module; here every row must pass (rows marked `reported` are figures shown
//! without a bound), have compared something, and have no NaN/Inf. The table is printed
//! (`cargo test --release --test stability -- --nocapture`).
//!
//! Case 1 builds two tables at 8192² (1 GiB each, read back only at the windows' corners) and
//! six at 2048²: 30–50 s on lavapipe with 2 cores; the other cases take about a second.

mod common;

use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::stability::{self, SatTables, StabilityReport, StabilityRow, Verdict};

/// Runs one case, prints its table and asserts every verdict; returns the rows.
fn run_case(
    case: u8,
    f: impl FnOnce(&Gpu) -> shadowgraph::Result<Vec<StabilityRow>>,
) -> Vec<StabilityRow> {
    let g = common::gpu();
    let start = std::time::Instant::now();
    let rows = f(&g).unwrap_or_else(|e| panic!("case {case}: {e}"));
    let report = StabilityReport {
        rows: rows.clone(),
        seconds: vec![(case, start.elapsed().as_secs_f64())],
        device: g.describe(),
    };
    let table = report.table();
    println!("{table}");
    assert!(!rows.is_empty(), "case {case}: no rows");
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| r.verdict == Verdict::Fail)
        .map(|r| {
            format!(
                "{} / {} / {}: error {:e}, bound {:e}, {} NaN/Inf: {}",
                r.what, r.technique, r.storage, r.error, r.bound, r.nonfinite, r.note
            )
        })
        .collect();
    assert!(
        failed.is_empty(),
        "case {case}: {} row(s) failed:\n{}\n\n{table}",
        failed.len(),
        failed.join("\n")
    );
    for r in &rows {
        assert_eq!(r.case, case, "{}: row of another case", r.what);
        if r.verdict == Verdict::Pass {
            assert!(
                r.values > 0 && r.nonfinite == 0 && r.error <= r.bound,
                "case {case}: {} / {} passed with {} values, {} NaN/Inf, error {:e} > bound {:e}",
                r.what,
                r.technique,
                r.values,
                r.nonfinite,
                r.error,
                r.bound
            );
        }
    }
    rows
}

fn find<'a>(
    rows: &'a [StabilityRow],
    what: &str,
    technique: &str,
    storage: &str,
) -> &'a StabilityRow {
    rows.iter()
        .find(|r| {
            r.what.contains(what) && r.technique.contains(technique) && r.storage.contains(storage)
        })
        .unwrap_or_else(|| panic!("no row `{what}` / `{technique}` / `{storage}`"))
}

/// SAT window sums of a constant 0.999 map and a random map: the fixed-point tables equal the
/// wrapping-integer reference at every corner read and their window means are within
/// ½/scale; the f32 tables within the scan's rounding model. At 8192² one table per map (the
/// constant map's f32 table, the random map's whole-map fixed-point table: all six tables of
/// 1 GiB take 75–85 s on 2 shared cores), every table at 2048².
#[test]
fn case1_sat_window_sums() {
    let rows = run_case(1, |g| {
        let mut rows = stability::sat_case(g, 8192, SatTables::OnePerMap)?;
        rows.extend(stability::sat_case(g, 2048, SatTables::All)?);
        Ok(rows)
    });
    find(&rows, "const 0.999 8192²: window means", "f32 model", "f32");
    let exact = find(
        &rows,
        "random 8192²: table = integer reference",
        "",
        "fixed",
    );
    assert_eq!(exact.error, 0.0, "the fixed table is exact");
    find(
        &rows,
        "random 8192²: window means",
        "all windows exact",
        "fixed u32",
    );
    for map in ["const 0.999", "random"] {
        for storage in ["fixed u32", "f32"] {
            find(&rows, &format!("{map} 2048²: window means"), "sat", storage);
        }
    }
    for map in ["const 0.999", "random"] {
        let what = format!("{map} 2048²: table = integer reference");
        let r = find(&rows, &what, "64² lookups", "fixed");
        assert_eq!(r.error, 0.0, "{map}: the wrapping table is exact");
        find(
            &rows,
            &format!("{map} 2048²: window means"),
            "64² lookups",
            "fixed u32",
        );
    }
}

/// VSM, EVSM2, EVSM4 (f32 and f16) over a zero-variance occluder.
#[test]
fn case2_planar_receiver_vsm_and_evsm() {
    let rows = run_case(2, stability::planar_case);
    for technique in ["vsm", "evsm2", "evsm4"] {
        for storage in ["f32", "f16"] {
            let r = find(&rows, "exactly 1", technique, storage);
            assert_eq!((r.error, r.bound), (0.0, 0.0), "{technique} {storage}");
            find(&rows, "behind: vs f64", technique, storage);
        }
    }
}

/// MSM with all-equal moments and at depths exactly 0 and 1, at every storage the device has.
#[test]
fn case3_msm_flat_maps_and_extreme_depths() {
    let rows = run_case(3, stability::msm_case);
    for storage in ["f32", "f16"] {
        find(&rows, "rise along the depth sweep", "hamburger", storage);
        find(&rows, "visibility vs f64", "hamburger", storage);
    }
    find(&rows, "rise along the depth sweep", "hausdorff", "f32");
    let g = common::gpu();
    if g.device
        .features()
        .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
    {
        let r = find(&rows, "rise along the depth sweep", "hamburger", "unorm16");
        assert_eq!(r.verdict, Verdict::Pass);
    }
}

/// EVSM and ESM at and past the exponent limits: encode, blur, mips and SAT stay finite and
/// within their models; the validator clamps and refuses; the f32 SAT of EVSM at c = 42 would
/// overflow, which is why the chosen coding is fixed point.
#[test]
fn case4_exponents_at_and_past_the_limits() {
    let rows = run_case(4, stability::exponent_case);
    for (technique, storage) in [
        ("evsm4 c=42", "f32"),
        ("evsm4 c=5.54", "f16"),
        ("esm c=200", "f32"),
        ("esm c=10000", "f32"),
    ] {
        for what in [
            "encode vs f64",
            "blur vs f64",
            "mips vs f64",
            "(chosen coding)",
        ] {
            let r = find(&rows, what, technique, storage);
            assert_eq!(r.verdict, Verdict::Pass, "{technique} {what}");
        }
    }
    let chosen = find(&rows, "(chosen coding)", "evsm4 c=42", "f32");
    assert!(chosen.storage.ends_with("fixed u32"), "{}", chosen.storage);
    let other = find(&rows, "(other coding)", "evsm4 c=42", "f32");
    assert!(
        other.nonfinite > 0,
        "the f32 table of exp(84)-sized moments overflows"
    );
    let past = find(
        &rows,
        "past the limit (what the clamp prevents)",
        "evsm4 c=45",
        "f32",
    );
    assert!(past.nonfinite > 0, "exp(90) overflows f32");
    for what in ["past the limit → clamped", "past the range → error"] {
        assert_eq!(find(&rows, what, "", "").verdict, Verdict::Pass);
    }
}

/// CSM with M = 16: in [0, 1], the f64 series, and the ringing bound.
#[test]
fn case5_csm_ringing() {
    let rows = run_case(5, stability::csm_case);
    for storage in ["f32", "f16"] {
        find(&rows, "vs f64 series", "csm M=16", storage);
        let away = find(&rows, "clamped output = step", "csm M=16", storage);
        assert!(
            away.values > 1000,
            "{} points away from the jump",
            away.values
        );
    }
    find(&rows, "unclamped series vs scaled step", "csm M=16", "-");
}

/// NaN, +Inf, −Inf in the depth buffer: replaced and counted; nothing non-finite downstream.
#[test]
fn case6_non_finite_depth() {
    let rows = run_case(6, stability::non_finite_case);
    let count = find(&rows, "replaced and counted", "linearize", "");
    assert_eq!(count.error, 0.0);
    assert!(
        rows.iter()
            .filter(|r| r.what.contains("sanitized map"))
            .count()
            >= 8
    );
    assert!(rows.iter().all(|r| r.nonfinite == 0));
}

/// Deep and shallow frusta: linear depth within 5 roundings of f64; depth steps below the bias.
#[test]
fn case7_deep_and_shallow_frusta() {
    let rows = run_case(7, stability::frusta_case);
    for light in [
        "spot near/far 1e-4",
        "spot near/far 0.999",
        "directional near/far 1e-4",
        "directional near/far 0.999",
    ] {
        find(&rows, "linear depth vs f64", light, "r32float");
        find(&rows, "depth-buffer step", light, "depth32float");
    }
}

/// MSM with the receiver 10⁻⁵–10⁻¹ behind a flat occluder, at the default moment biases:
/// within 0.01 (f32), 0.03 (unorm16), 0.05 (soft MSM's tables) or 0.25 (f16) of exact MSM on
/// the point mass.
#[test]
fn case8_msm_behind_a_flat_occluder() {
    let rows = run_case(8, stability::msm_contact_case);
    for (technique, storage) in [
        ("msm hamburger", "f32"),
        ("msm hamburger", "f16"),
        ("msm_soft", "f32"),
        ("msm_soft", "f16"),
    ] {
        let r = find(&rows, "behind a flat occluder", technique, storage);
        assert_eq!(r.verdict, Verdict::Pass, "{technique} {storage}");
        assert!(
            r.values > 150,
            "{technique} {storage}: {} receivers",
            r.values
        );
    }
    let g = common::gpu();
    if g.device
        .features()
        .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
    {
        for technique in ["msm hamburger", "msm_soft"] {
            let r = find(&rows, "behind a flat occluder", technique, "unorm16");
            assert_eq!(r.verdict, Verdict::Pass, "{technique} unorm16");
        }
    }
}
