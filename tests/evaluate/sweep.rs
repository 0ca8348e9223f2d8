//! A quick sweep writes every file consistently; verdicts and the clock-drop flag.

use super::*;

/// Every number in a JSON value is finite (serde_json writes NaN and ±Inf as null, so a null
/// where a number belongs also fails).
fn assert_finite(v: &serde_json::Value, path: &str) {
    match v {
        serde_json::Value::Number(n) => {
            assert!(n.as_f64().is_some_and(f64::is_finite), "{path}: {n}")
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assert_finite(x, &format!("{path}[{i}]"));
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                // Optional fields are null where they do not apply, never where a number is due.
                if x.is_null() {
                    assert!(
                        k == "pcf" || k == "box_width" || k == "budget_ms" || k == "temporal",
                        "{path}.{k} is null (a non-finite number?)"
                    );
                    continue;
                }
                assert_finite(x, &format!("{path}.{k}"));
            }
        }
        _ => {}
    }
}

/// The quick sweep through the binary: all six files, a PNG of the grid's size, an SVG with
/// one point per configuration and the front, JSON whose numbers are finite and whose rows
/// equal the CSV's (CSV errors are printed to 6 decimals: tolerance 5e-7; times to 3: 5e-4),
/// and each total the sum of its parts.
#[test]
fn quick_sweep_writes_every_file_consistently() {
    let out = temp_dir("quick");
    let o = shadowgraph(&[
        "evaluate",
        scene_path("sphere_on_plane.toml").to_str().unwrap(),
        "--quick",
        "--techniques",
        "hard,pcf,pcss,vsm,msm",
        "--repeat",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "evaluate failed: {stderr}");
    for f in [
        "report.md",
        "report.csv",
        "report.json",
        "report.html",
        "pareto.svg",
        "pareto_penumbra.svg",
        "pareto_flip.svg",
        "grid.png",
        "grid.txt",
    ] {
        let meta = std::fs::metadata(out.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(meta.len() > 100, "{f} is nearly empty");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
            .expect("report.json parses");
    assert_finite(&json, "report");
    let report: Report = serde_json::from_value(json).expect("report.json has the Report shape");
    // hard, pcf box5, pcss, vsm and msm with each filter, all at 512.
    let expected = 3 + 2 * FILTERS.len();
    assert_eq!(report.rows.len(), expected, "{:?}", report.skipped);
    let csv = std::fs::read_to_string(out.join("report.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), report.rows.len());
    for (r, cells) in report.rows.iter().zip(&rows) {
        assert_eq!(cells[col("label")], r.label);
        let num = |name: &str| cells[col(name)].parse::<f64>().unwrap();
        for (name, v, tol) in [
            ("penumbra_mean_abs", r.penumbra.mean_abs, 5e-7),
            ("penumbra_p99", r.penumbra.p99, 5e-7),
            ("umbra_mean_abs", r.umbra.mean_abs, 5e-7),
            ("lit_mean_abs", r.lit.mean_abs, 5e-7),
            ("flip_mean_abs", r.flip.mean_abs, 5e-7),
            ("flip_max", r.flip.max, 5e-7),
            ("soft_mean_abs", r.soft.mean_abs, 5e-7),
            ("soft_rmse", r.soft.rmse, 5e-7),
            ("soft_p99", r.soft.p99, 5e-7),
            ("soft_max", r.soft.max, 5e-7),
            ("soft_over_0.05", r.soft.over_005, 5e-7),
            ("soft_over_0.2", r.soft.over_02, 5e-7),
            // The CSV prints ms to three decimals: half a unit of the last place, plus the
            // parse's own rounding (11.5575 printed as 11.558 differs by 5e-4 and one ulp).
            ("total_ms", r.total_ms.unwrap(), 5e-4 + 1e-12),
            ("total_q1_ms", r.total_spread.unwrap().q1, 5e-4 + 1e-12),
            ("total_q3_ms", r.total_spread.unwrap().q3, 5e-4 + 1e-12),
            ("penumbra_hf", r.penumbra_hf, 5e-7),
            ("shade_ms", r.shade_ms.unwrap(), 5e-4 + 1e-12),
            ("wall_ms", r.wall_ms.unwrap(), 5e-4 + 1e-12),
        ] {
            assert!(
                (num(name) - v).abs() <= tol,
                "{}: {name} csv {} json {v}",
                r.label,
                num(name)
            );
        }
        assert_eq!(num("memory_bytes") as u64, r.memory_bytes);
        assert_eq!(r.pcf.is_some(), r.box_width.is_some(), "{}", r.label);
        let parts = r.raster_ms.unwrap() + r.kernels_ms.unwrap() + r.shade_ms.unwrap();
        assert!((parts - r.total_ms.unwrap()).abs() < 1e-9, "{}", r.label);
        let shares = [r.soft.over_005, r.soft.over_02];
        assert!(shares.iter().all(|s| (0.0..=1.0).contains(s)) && shares[1] <= shares[0]);
        assert!(r.soft.mean_abs <= r.soft.rmse + 1e-12 && r.soft.rmse <= r.soft.max + 1e-12);
        assert!(r.soft.pixels == report.relevant_pixels, "{}", r.label);
        // The regions partition the relevant pixels.
        let regions = [r.penumbra.pixels, r.umbra.pixels, r.lit.pixels];
        assert_eq!(regions, report.region_pixels, "{}", r.label);
        assert_eq!(regions.iter().sum::<usize>(), report.relevant_pixels);
        assert_eq!(r.flip.pixels, (report.image.0 * report.image.1) as usize);
    }
    assert!(
        report.region_pixels.iter().all(|&n| n > 0),
        "{:?}",
        report.region_pixels
    );
    // Each plot: one marker per configuration, with its tooltip and its technique's colour
    // (no two techniques sharing one); labels on the front's points and on no other.
    let techniques: std::collections::BTreeSet<&str> =
        report.rows.iter().map(|r| r.technique.as_str()).collect();
    let fills: std::collections::BTreeSet<String> = techniques
        .iter()
        .map(|t| format!("{:?}", shadowgraph::low_level::evaluate::colour_of(t)))
        .collect();
    assert_eq!(fills.len(), techniques.len(), "techniques share a colour");
    for m in Metric::ALL {
        let svg = std::fs::read_to_string(out.join(m.file())).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        let on = front(&report.rows, m);
        assert!(!on.is_empty());
        assert_eq!(
            svg.matches("<g class=\"pt\">").count(),
            report.rows.len(),
            "{}",
            m.file()
        );
        for r in &report.rows {
            let title = format!("<title>{} (", r.label);
            assert_eq!(svg.matches(&title).count(), 1, "{}: {}", m.file(), r.label);
        }
        for (i, r) in report.rows.iter().enumerate() {
            // plotters writes a text element's content on a line of its own.
            let labelled = svg.contains(&format!(">\n{}\n</text>", r.label));
            assert_eq!(labelled, on.contains(&i), "{}: {}", m.file(), r.label);
        }
    }
    let png = image::open(out.join("grid.png"))
        .expect("grid.png decodes")
        .to_rgb8();
    // 160-wide quick image: cells 160×(120 + 12), 3 configurations (6 cells) per row.
    let grid_rows = 1 + report.rows.len().div_ceil(3);
    assert_eq!(png.dimensions(), (6 * 160, (grid_rows * 132) as u32));
    let legend = std::fs::read_to_string(out.join("grid.txt")).unwrap();
    assert_eq!(legend.lines().count(), 2 + 2 * report.rows.len());
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("CPU-driver times") == report.cpu_driver);
    // The header names the run; every row has its n frames' spread around its median.
    assert_eq!(report.repeats, 2);
    assert!(
        !report.commit.is_empty() && report.date.len() == 10,
        "{report:?}"
    );
    assert!(md.contains(&format!("n = {} timed frames", report.repeats)));
    assert!(md.contains("Time protocol") && md.contains("Clock check"));
    for r in &report.rows {
        let t = r.total_spread.expect("a spread");
        assert_eq!(t.n, report.repeats as usize, "{}", r.label);
        assert!(t.min <= t.q1 && t.q1 <= t.median && t.median <= t.q3 && t.q3 <= t.max);
        assert!(
            (t.median - r.total_ms.unwrap()).abs() < 1e-12,
            "{}",
            r.label
        );
        assert!(r.check_ratio.is_some_and(|q| q > 0.0), "{}", r.label);
        assert!(r.penumbra_hf.is_finite() && r.penumbra_hf >= 0.0);
        assert!(
            r.cost.dispatches >= 1 && r.cost.fetches_per_pixel >= 1.0,
            "{}",
            r.label
        );
    }
    // The verdict: the cheapest configuration within 10% of the best penumbra error, by a
    // direct search over the rows.
    let best = report
        .rows
        .iter()
        .map(|r| r.penumbra.mean_abs)
        .fold(f64::INFINITY, f64::min);
    let cheapest = report
        .rows
        .iter()
        .filter(|r| r.penumbra.mean_abs <= 1.1 * best)
        .min_by(|a, b| a.total_ms.unwrap().total_cmp(&b.total_ms.unwrap()))
        .unwrap();
    let line = md
        .lines()
        .find(|l| l.starts_with("- Cheapest within 10%"))
        .expect("a verdict line");
    assert!(line.contains(&format!("**{}**", cheapest.label)), "{line}");
    assert!(md.contains("- Most accurate within") && md.contains("- Prefiltering against PCSS"));
    clock_drop_is_flagged_in_the_report(&report);
    verdict_of_known_rows(&report);
    // --quick also times every light static: its report in update-static/, the same errors,
    // no raster or kernel time, summarized under the first report's verdict.
    let text = std::fs::read_to_string(out.join("update-static/report.json")).expect("static");
    let still: Report = serde_json::from_str(&text).expect("a Report");
    assert_eq!(still.updates, ["\"static\""]);
    assert_eq!(still.rows.len(), report.rows.len());
    for (m, s) in report.rows.iter().zip(&still.rows) {
        assert_eq!(
            (&m.label, m.soft, m.penumbra_hf),
            (&s.label, s.soft, s.penumbra_hf)
        );
        assert_eq!(
            (s.raster_ms, s.kernels_ms),
            (Some(0.0), Some(0.0)),
            "{}",
            s.label
        );
    }
    assert!(
        md.contains("### `update-static/`: 160×120, 1 light, static lights"),
        "{md}"
    );
    assert!(out.join("update-static/report.html").is_file());
    // The timestamps' cross-check against the wall clock, over every configuration.
    let check = format!("in each of the {} configurations", report.rows.len());
    assert!(md.contains(&check), "report.md lacks the wall check");
    // On a CPU driver, a configuration whose passes sum more than 25% from its wall time is
    // named as untrusted (its wall set to twice its passes here; the others' to their sum, so
    // the check does not depend on this machine's load); on a GPU none is.
    let mut skewed = report.clone();
    skewed.cpu_driver = true;
    for (i, r) in skewed.rows.iter_mut().enumerate() {
        let passes = r.total_ms.unwrap() + r.gbuffer_ms.unwrap();
        r.wall_ms = Some(if i == 0 { 2.0 * passes } else { passes });
    }
    let off = untrusted_times(&skewed);
    assert_eq!(off.len(), 1, "{off:?}");
    assert_eq!(off[0].0, skewed.rows[0].label);
    assert!((off[0].1 - 0.5).abs() < 1e-12);
    let text = wall_check(&skewed);
    assert!(text.contains("Times not trusted") && text.contains(&skewed.rows[0].label));
    skewed.cpu_driver = false;
    assert!(untrusted_times(&skewed).is_empty());
    assert!(!wall_check(&skewed).contains("not trusted"));
    for r in &report.rows {
        assert!(
            md.contains(&format!("| {} |", r.label)),
            "{} not in report.md",
            r.label
        );
    }
}

/// The verdict on a copy of a real report whose times and penumbra errors are set by hand
/// (hard and PCF 0.5 at 0.5 ms, PCSS 0.05 at 10 ms, VSM's blur 0.054 at 5 ms and its mips 0.04 at
/// 20 ms, every other row 0.3 at 1 ms; a budget of 6 ms per light): the cheapest within 10%
/// of the best (0.04) is VSM's mips, the most accurate within 6 ms VSM's blur, which is within
/// 10% of PCSS's best at half its time; with every prefiltered row at 0.2, none comes within
/// 10% and the closest is named with its 4× error.
fn verdict_of_known_rows(report: &Report) {
    use shadowgraph::low_level::evaluate::verdict::verdicts;
    let mut r = report.clone();
    r.budget_ms = Some(6.0);
    let set = |r: &mut Report, label: &str, e: f64, t: f64| {
        let row = r.rows.iter_mut().find(|x| x.label == label).expect(label);
        row.penumbra.mean_abs = e;
        row.total_ms = Some(t);
    };
    for i in 0..r.rows.len() {
        let label = r.rows[i].label.clone();
        set(&mut r, &label, 0.3, 1.0);
    }
    set(&mut r, "hard 512", 0.5, 0.5);
    set(&mut r, "pcf box5 512", 0.5, 0.5);
    set(&mut r, "pcss 16+32 512", 0.05, 10.0);
    set(&mut r, "vsm f32 blur5 512", 0.054, 5.0);
    set(&mut r, "vsm f32 mips5 512", 0.04, 20.0);
    let v = verdicts(&r);
    assert!(
        v[1].contains("(0.0400, vsm f32 mips5 512): **vsm f32 mips5 512**"),
        "{v:?}"
    );
    assert!(
        v[2].starts_with("Most accurate within 6.000 ms per light (given): **vsm f32 blur5 512**"),
        "{v:?}"
    );
    assert!(
        v[3].contains("**vsm f32 blur5 512** (5.000 ms, penumbra error 0.0540) is within 10% of")
            && v[3].ends_with("at 0.50× its time."),
        "{v:?}"
    );
    for row in r
        .rows
        .iter_mut()
        .filter(|x| x.family.starts_with("prefiltered"))
    {
        row.penumbra.mean_abs = 0.2;
    }
    let v = verdicts(&r);
    assert!(
        v[3].contains("no prefiltered configuration comes within 10%")
            && v[3].contains("4.00× its error"),
        "{v:?}"
    );
}

/// Synthetic timings with a clock drop fed to the time protocol and written into a copy of a
/// real report: every pass 2× slow in configuration 1's first attempt (retried once, its times
/// then the fast clock's) and in all of configuration 0's frames (retried twice and flagged
/// †); the report says how many were measured again and what spread remains, and the CSV
/// carries the retries and the flag.
fn clock_drop_is_flagged_in_the_report(report: &Report) {
    use shadowgraph::low_level::evaluate::protocol::{Protocol, Sample, run};
    let n = report.rows.len();
    let mut seen = vec![0u32; n];
    let timed = run(&Protocol::new(3), n, "gbuffer", |c| {
        seen[c] += 1;
        let slow = c == 0 || (c == 1 && seen[c] <= 3);
        let k = if slow { 2.0 } else { 1.0 };
        let shade = 1.0 + c as f64;
        Ok(Sample {
            passes: vec![
                ("light0.shadow_raster".into(), 0.5 * k),
                ("gbuffer".into(), k),
                ("shade".into(), shade * k),
            ],
            wall_ms: k * (1.5 + shade),
        })
    })
    .expect("protocol");
    let mut r = report.clone();
    shadowgraph::low_level::evaluate::apply_times(&mut r, &timed);
    assert_eq!((r.rows[0].retries, r.rows[0].clock_off), (2, true));
    assert_eq!((r.rows[1].retries, r.rows[1].clock_off), (1, false));
    assert!((r.rows[1].total_ms.unwrap() - 2.5).abs() < 1e-12);
    assert!((r.rows[0].total_ms.unwrap() - 3.0).abs() < 1e-12);
    assert!(r.rows[2..].iter().all(|x| x.retries == 0 && !x.clock_off));
    let md = shadowgraph::low_level::evaluate::markdown(&r);
    let text = shadowgraph::low_level::evaluate::protocol_text(&r);
    assert!(md.contains(&text));
    assert!(
        text.contains(&format!("2 of {n} configurations"))
            && text.contains(&format!("still off after that: 1 (†: {})", r.rows[0].label))
            && text.contains("span 1.00–2.00×"),
        "{text}"
    );
    assert!(md.contains(&format!("| {} |", r.rows[0].label)) && md.contains(" † |"));
    let csv = shadowgraph::low_level::evaluate::csv(&r);
    let row0 = csv.lines().nth(1).expect("a row");
    assert!(row0.contains(",2,true,"), "{row0}");
}
