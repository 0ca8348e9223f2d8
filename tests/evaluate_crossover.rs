//! `evaluate`'s crossover against PCSS: `--quick` writes `crossover.svg` and its tables with
//! finite numbers, and every figure in them is recomputed here from the report's own
//! measurements by a direct f64 computation (the least-squares line, the crossing, the PCSS
//! each technique is compared with, the prediction's errors); bad `--crossover-sizes` are one
//! line naming the flag.

use std::path::{Path, PathBuf};
use std::process::Command;

use shadowgraph::low_level::evaluate::crossover::{Crossing, Match, RANGE_MPX};
use shadowgraph::low_level::evaluate::{Metric, Report, front};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-xo-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn shadowgraph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run shadowgraph")
}

/// Least squares by the normal equations, written out.
fn least_squares(p: &[(f64, f64)]) -> (f64, f64) {
    let n = p.len() as f64;
    let (sx, sy) = p.iter().fold((0.0, 0.0), |(a, b), q| (a + q.0, b + q.1));
    let sxx: f64 = p.iter().map(|q| q.0 * q.0).sum();
    let sxy: f64 = p.iter().map(|q| q.0 * q.1).sum();
    let b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    ((sy - b * sx) / n, b)
}

/// Relative closeness for figures computed two ways (summation order only differs).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

/// `evaluate --quick` on `sphere_on_plane` (160×120, hard, PCSS, VSM and MSM soft at 512²;
/// fitted at 80×60 and 160×120, checked at 120×90): the crossover's figures in
/// report.json are finite and each is what a direct computation from its own measurements
/// gives (tolerance 1e-9 relative: the same f64 sums in another order); the PCSS a technique
/// is compared with follows the rule from the rows; the plot has two lines per configuration
/// and a ring per crossing in range; report.md and report.html carry the table, stdout the
/// prediction's error. The timings themselves are not checked (they depend on the machine).
#[test]
fn quick_evaluation_writes_the_crossover() {
    let out = temp_dir("quick");
    let o = shadowgraph(&[
        "evaluate",
        scene_path("sphere_on_plane.toml").to_str().unwrap(),
        "--quick",
        "--techniques",
        "hard,pcss,vsm,msm_soft",
        "--repeat",
        "2",
        "--update",
        "every",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    let report: Report = serde_json::from_str(&text).expect("a Report");
    let c = report.crossover.clone().expect("a crossover");
    assert_eq!(c.note, None, "{c:?}");
    assert_eq!(c.fit_sizes, [(80, 60), (160, 120)]);
    assert_eq!(c.check_size, (120, 90));
    assert_eq!(c.repeats, 2);
    // Which configurations: per technique but PCSS, its most accurate on a front, and the
    // PCSS of comparable error (the cheapest within 10%, else the most accurate).
    let rows = &report.rows;
    let mut on_front: Vec<usize> = Metric::of(&report)
        .into_iter()
        .flat_map(|m| front(rows, m))
        .collect();
    on_front.sort_unstable();
    on_front.dedup();
    let mut chosen: Vec<usize> = Vec::new();
    for &i in &on_front {
        let t = &rows[i].technique;
        if t == "pcss" || chosen.iter().any(|&k| &rows[k].technique == t) {
            continue;
        }
        let best = on_front
            .iter()
            .copied()
            .filter(|&k| &rows[k].technique == t)
            .min_by(|&a, &b| {
                (rows[a].penumbra.mean_abs, rows[a].total_ms.unwrap())
                    .partial_cmp(&(rows[b].penumbra.mean_abs, rows[b].total_ms.unwrap()))
                    .unwrap()
            })
            .unwrap();
        chosen.push(best);
    }
    chosen.sort_unstable();
    assert!(!chosen.is_empty(), "no technique but PCSS on a front");
    assert_eq!(c.pairs.len(), chosen.len());
    let pcss: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].technique == "pcss")
        .collect();
    for (p, &i) in c.pairs.iter().zip(&chosen) {
        assert_eq!(c.costs[p.config].row, i);
        let e = rows[i].penumbra.mean_abs;
        let near: Vec<usize> = pcss
            .iter()
            .copied()
            .filter(|&k| rows[k].penumbra.mean_abs <= 1.1 * e)
            .collect();
        let (want, how) = match near.iter().min_by(|&&a, &&b| {
            rows[a]
                .total_ms
                .unwrap()
                .total_cmp(&rows[b].total_ms.unwrap())
        }) {
            Some(&k) => (k, Match::AsAccurate),
            None => (
                *pcss
                    .iter()
                    .min_by(|&&a, &&b| {
                        rows[a]
                            .penumbra
                            .mean_abs
                            .total_cmp(&rows[b].penumbra.mean_abs)
                    })
                    .unwrap(),
                Match::MostAccurate,
            ),
        };
        assert_eq!(
            (c.costs[p.pcss].row, p.matched),
            (want, how),
            "{}",
            rows[i].label
        );
    }
    // Every figure from its own measurements.
    let x = 120.0 * 90.0 / 1e6;
    let (mut moving, mut still) = (Vec::new(), Vec::new());
    for k in &c.costs {
        assert_eq!(k.label, rows[k.row].label);
        assert_eq!(k.shade_points.len(), 2);
        let want_x = [80.0 * 60.0 / 1e6, 160.0 * 120.0 / 1e6];
        for (p, w) in k.shade_points.iter().zip(want_x) {
            assert!(
                close(p.0, w) && p.1.is_finite() && p.1 > 0.0,
                "{}: {p:?}",
                k.label
            );
        }
        let (a, b) = least_squares(&k.shade_points);
        assert!(
            close(k.shade.a, a) && close(k.shade.b, b),
            "{}: {:?} vs {a} {b}",
            k.label,
            k.shade
        );
        assert!(
            k.prefilter_ms.is_finite() && k.prefilter_ms >= 0.0,
            "{}",
            k.label
        );
        let ch = k.check;
        assert!(close(ch.mpx, x));
        assert!(close(ch.static_predicted, a + b * x), "{}", k.label);
        assert!(
            close(ch.moving_predicted, k.prefilter_ms + a + b * x),
            "{}",
            k.label
        );
        assert!(ch.static_measured > 0.0 && ch.moving_measured >= ch.static_measured);
        moving.push((ch.moving_predicted - ch.moving_measured).abs() / ch.moving_measured);
        still.push((ch.static_predicted - ch.static_measured).abs() / ch.static_measured);
    }
    for (e, got) in [(&mut moving, c.moving_error), (&mut still, c.static_error)] {
        e.sort_by(f64::total_cmp);
        let n = e.len();
        let median = if n % 2 == 1 {
            e[n / 2]
        } else {
            0.5 * (e[n / 2 - 1] + e[n / 2])
        };
        assert!(
            close(got.median, median) && close(got.worst, e[n - 1]),
            "{got:?} vs {e:?}"
        );
    }
    // The crossings: where the difference of the two lines changes sign in the range.
    let (lo, hi) = RANGE_MPX;
    let mut rings = 0;
    for p in &c.pairs {
        let (t, q) = (&c.costs[p.config], &c.costs[p.pcss]);
        for (moving, got) in [(true, p.moving), (false, p.still)] {
            let pre = |k: &shadowgraph::low_level::evaluate::crossover::Cost| {
                if moving { k.prefilter_ms } else { 0.0 }
            };
            let da = t.shade.a + pre(t) - q.shade.a - pre(q);
            let db = t.shade.b - q.shade.b;
            let (d0, d1) = (da + db * lo, da + db * hi);
            let want = match (d0 <= 0.0, d1 <= 0.0) {
                (true, true) => Crossing::Always,
                (false, false) => Crossing::Never,
                (false, true) => Crossing::Above(-da / db),
                (true, false) => Crossing::Below(-da / db),
            };
            match (got, want) {
                (Crossing::Above(g), Crossing::Above(w))
                | (Crossing::Below(g), Crossing::Below(w)) => {
                    assert!(close(g, w), "{}: {g} vs {w}", t.label);
                    rings += 1;
                }
                _ => assert_eq!(got, want, "{} moving {moving}", t.label),
            }
        }
    }
    let svg = std::fs::read_to_string(out.join("crossover.svg")).expect("crossover.svg");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert_eq!(
        svg.matches("class=\"xo-line moving\"").count(),
        c.costs.len()
    );
    assert_eq!(
        svg.matches("class=\"xo-line static\"").count(),
        c.costs.len()
    );
    assert_eq!(svg.matches("class=\"xo-cross\"").count(), rings);
    assert_eq!(
        svg.matches("class=\"xo-measured\"").count(),
        4 * c.costs.len()
    );
    assert!(
        !svg.contains("NaN") && !svg.contains("inf"),
        "a non-finite coordinate"
    );
    let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(md.contains("## Cost as the image grows"), "{md}");
    for p in &c.pairs {
        let t = &c.costs[p.config];
        let row = format!(
            "| {} | {} | {:.4} | {}",
            t.technique, t.label, t.penumbra, c.costs[p.pcss].label
        );
        assert!(md.contains(&row), "{row} not in report.md");
        assert!(md.contains(&p.moving.text()) && md.contains(&p.still.text()));
    }
    let pct = |v: f64| format!("{:.1}%", 100.0 * v);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("Crossover prediction at 120×90"))
        .unwrap_or_else(|| panic!("no prediction line on stdout: {stdout}"));
    for v in [
        c.moving_error.median,
        c.moving_error.worst,
        c.static_error.median,
        c.static_error.worst,
    ] {
        assert!(line.contains(&pct(v)), "{line}");
    }
    let met = c.moving_error.met() && c.static_error.met();
    assert!(
        line.ends_with(if met { ": met)." } else { ": not met)." }),
        "{line}"
    );
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert!(
        html.contains("<div class=\"crossover-plot\"")
            && html.contains("<table class=\"crossover\">")
    );
    assert_eq!(
        html.matches("class=\"xo-line moving\"").count(),
        c.costs.len()
    );
}

/// Bad `--crossover-sizes` are one line naming the flag and exit status 1, before any
/// measurement.
#[test]
fn bad_crossover_sizes_are_a_clear_error() {
    let out = temp_dir("bad");
    for value in [
        "320x240,640x480",
        "320x240,320x240,640x480",
        "0x240,640x480,960x540",
        "320x240,640x480,wide",
        "320x240,70000x10,960x540",
    ] {
        let o = shadowgraph(&[
            "evaluate",
            scene_path("sphere_on_plane.toml").to_str().unwrap(),
            "--quick",
            "--crossover-sizes",
            value,
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{value}: {err}");
        assert!(
            err.trim().lines().count() == 1
                && err.contains("--crossover-sizes")
                && !err.contains("panicked"),
            "{value}: {err}"
        );
        assert!(
            !out.join("report.json").exists(),
            "{value}: a report was written"
        );
    }
}
