//! `shadowgraph evaluate`: every output file for a tiny sweep, the JSON finite and equal to the
//! CSV, errors recomputed independently from a render and the truth, plausibility (hard vs
//! a point light's truth, wide blur vs PCF), error statistics against a direct f64
//! computation, and clear errors for bad input.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use rand::Rng;
use shadowgraph::low_level::evaluate::{
    Config, ErrorStats, EvaluateOptions, FILTERS, Metric, Report, evaluate, front, scene_for,
    untrusted_times, wall_check,
};
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::{Emitter, TruthOptions, area_light_truth};
use shadowgraph::{Filter, PcfKernel, Technique};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-eval-{tag}-{}", std::process::id()));
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

/// A scene whose light has size 0 (stacked.toml's spot): the area-light truth is the light's
/// hard shadow. (1) With the truth at the map's own resolution, `hard` at that size is that
/// very shadow map: its error must be exactly 0. (2) The report's statistics equal a direct
/// f64 recomputation from an independent render and truth (tolerance 1e-12: the same sums in
/// another order). (3) A wide blur (VSM, box 17) is worse against the hard truth than PCF 3×3,
/// and PCF's error against its own box-PCF truth stays small (the GPU window is centred on the
/// texel, the truth's box on the receiver: at most half a texel apart, so only edge pixels
/// move, by at most 1/3 per texel column: mean below 0.01).
#[test]
fn errors_are_plausible_and_recomputable() {
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((160, 120)),
        samples: Some(4),
        truth_resolution: Some(1024),
        repeat: 1,
        ..Default::default()
    };
    // A point light: the area-light truth is then the hard shadow of its own map.
    let mut scene: Scene = scene_for(&scene_path("stacked.toml"), &opts).expect("scene");
    scene.lights[0].size = 0.0;
    let wide = FILTERS[0].1(17.0);
    assert!(matches!(wide, Filter::Blur { .. }));
    let vsm = match shadowgraph::PrefilterConfig::vsm(1024)
        .with_filter(wide)
        .validated()
    {
        Ok((c, _)) => c.technique,
        Err(e) => panic!("{e}"),
    };
    let configs = vec![
        Config {
            label: "hard 1024".into(),
            technique: Technique::Hard,
            shadow_map: 1024,
            box_width: None,
        },
        Config {
            label: "pcf box3 1024".into(),
            technique: Technique::Pcf {
                radius: 1,
                kernel: PcfKernel::Box,
            },
            shadow_map: 1024,
            box_width: Some(3.0),
        },
        Config {
            label: "vsm f32 blur17 1024".into(),
            technique: vsm,
            shadow_map: 1024,
            box_width: Some(17.0),
        },
    ];
    let (report, images) = evaluate(&g, &scene, &configs, &opts).expect("evaluate");
    let [hard, pcf, blur] = [&report.rows[0], &report.rows[1], &report.rows[2]];
    eprintln!(
        "hard {:?}\npcf {:?} / {:?}\nblur {:?} / {:?}",
        hard.soft, pcf.soft, pcf.pcf, blur.soft, blur.pcf
    );
    assert!(report.relevant_pixels > 5000);
    assert_eq!(
        hard.soft.max, 0.0,
        "hard differs from its own shadow map's truth"
    );
    assert!(blur.soft.mean_abs > 2.0 * pcf.soft.mean_abs);
    assert!(blur.soft.over_02 > pcf.soft.over_02);
    assert!(pcf.pcf.expect("pcf truth").mean_abs < 0.01);
    // Hard shadows equal to the truth: every region's error and FLIP exactly 0, the two shaded
    // images identical; the blur is worse in the penumbra and perceptually.
    for e in [hard.penumbra, hard.umbra, hard.lit, hard.flip] {
        assert_eq!(e.max, 0.0, "{e:?}");
    }
    assert_eq!(images.shaded[0], images.truth_shaded);
    assert!(blur.penumbra.mean_abs > 2.0 * pcf.penumbra.mean_abs);
    assert!(blur.flip.mean_abs > pcf.flip.mean_abs);

    // (2) Independent recomputation of the PCF row's soft error.
    let mut renderer = Renderer::new(&g.device);
    let truth = area_light_truth(
        &mut renderer,
        &g.device,
        &g.queue,
        &scene,
        &TruthOptions {
            emitter: Emitter::Stratified { k: 4, seed: 1 },
            resolution: Some(1024),
        },
    )
    .expect("truth");
    let mut s = scene.clone();
    s.lights[0].shadow.technique = configs[1].technique;
    let frame = renderer
        .render(
            &g.device,
            &g.queue,
            &s,
            RenderOptions {
                aux: false,
                repeat: 1,
                dump: false,
            },
        )
        .expect("render");
    let errors: Vec<f64> = (0..truth.mask.len())
        .filter(|&i| truth.mask[i])
        .map(|i| (f64::from(frame.visibility[i]) - f64::from(truth.visibility[i])).abs())
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let over = errors.iter().filter(|&&e| e > 0.05).count() as f64 / errors.len() as f64;
    assert_eq!(errors.len(), pcf.soft.pixels);
    assert!(
        (mean - pcf.soft.mean_abs).abs() < 1e-12,
        "{mean} vs {}",
        pcf.soft.mean_abs
    );
    assert!((over - pcf.soft.over_005).abs() < 1e-12);
    assert_eq!(images.visibility.len(), 3);
    assert_eq!(images.truth.len(), 160 * 120);
    // The shaded images are the renderer's shading: the CPU port shading PCF's visibility
    // against the GPU's image of the same frame, and the truth-shaded image against the GPU's
    // image of `hard` (equal to the truth here), both within one 8-bit step (f32 vs f64
    // arithmetic before the rounding store).
    common::evaluate::assert_same_image("pcf shaded", &images.shaded[1], &frame.rgba);
    s.lights[0].shadow.technique = Technique::Hard;
    let hard_frame = renderer
        .render(
            &g.device,
            &g.queue,
            &s,
            RenderOptions {
                aux: false,
                repeat: 1,
                dump: false,
            },
        )
        .expect("render");
    common::evaluate::assert_same_image("truth-shaded", &images.truth_shaded, &hard_frame.rgba);
}

/// On `sphere_on_plane` (one spot light of size 0.5, K = 16, 160×120), the penumbra, umbra and
/// lit errors of hard, PCF 5×5 and VSM blur 5 equal a direct f64 recomputation from the
/// returned images by the written-out definition (`regions_direct`; tolerance 1e-12: the same
/// sums in another order), and FLIP equals a direct call of the FLIP library on the returned
/// shaded images, averaged in f64 (same map: 1e-12).
#[test]
fn region_and_flip_errors_match_direct_computation() {
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((160, 120)),
        samples: Some(16),
        truth_resolution: Some(1024),
        repeat: 1,
        ..Default::default()
    };
    let scene: Scene = scene_for(&scene_path("sphere_on_plane.toml"), &opts).expect("scene");
    assert_eq!(scene.lights.len(), 1, "the images hold light 0 only");
    let vsm = match shadowgraph::PrefilterConfig::vsm(512)
        .with_filter(FILTERS[0].1(5.0))
        .validated()
    {
        Ok((c, _)) => c.technique,
        Err(e) => panic!("{e}"),
    };
    let config = |label: &str, technique| Config {
        label: label.into(),
        technique,
        shadow_map: 512,
        box_width: None,
    };
    let pcf = Technique::Pcf {
        radius: 2,
        kernel: PcfKernel::Box,
    };
    let configs = [
        config("hard", Technique::Hard),
        config("pcf", pcf),
        config("vsm", vsm),
    ];
    let (report, images) = evaluate(&g, &scene, &configs, &opts).expect("evaluate");
    let regions = common::evaluate::regions_direct(&images.truth, &images.mask, 160, 120);
    let count = |k: u8| regions.iter().filter(|&&r| r == k).count();
    assert_eq!(report.region_pixels, [count(1), count(2), count(3)]);
    assert!(
        count(1) > 300 && count(2) > 300 && count(3) > 3000,
        "{:?}",
        report.region_pixels
    );
    for (k, r) in report.rows.iter().enumerate() {
        let v = &images.visibility[k];
        for (region, stats) in [(1, r.penumbra), (2, r.umbra), (3, r.lit)] {
            let e: Vec<f64> = (0..v.len())
                .filter(|&i| regions[i] == region)
                .map(|i| (f64::from(v[i]) - f64::from(images.truth[i])).abs())
                .collect();
            let mean = e.iter().sum::<f64>() / e.len() as f64;
            let max = e.iter().copied().fold(0.0, f64::max);
            assert_eq!(stats.pixels, e.len(), "{} region {region}", r.label);
            assert!(
                (stats.mean_abs - mean).abs() < 1e-12,
                "{} region {region}: {} vs {mean}",
                r.label,
                stats.mean_abs
            );
            assert_eq!(stats.max, max, "{} region {region}", r.label);
        }
        let reference = nv_flip::FlipImageRgb8::with_data(160, 120, &images.truth_shaded);
        let test = nv_flip::FlipImageRgb8::with_data(160, 120, &images.shaded[k]);
        let map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
        let mean = map.iter().map(|&x| f64::from(x)).sum::<f64>() / map.len() as f64;
        assert!(
            (r.flip.mean_abs - mean).abs() < 1e-12,
            "{}: FLIP {} vs {mean}",
            r.label,
            r.flip.mean_abs
        );
        eprintln!(
            "{}: penumbra {:.4} umbra {:.4} lit {:.4} FLIP {:.4}",
            r.label, r.penumbra.mean_abs, r.umbra.mean_abs, r.lit.mean_abs, r.flip.mean_abs
        );
    }
    // Soft shadows from PCF beat hard shadows in the penumbra and by FLIP.
    let [hard, pcf] = [&report.rows[0], &report.rows[1]];
    assert!(pcf.penumbra.mean_abs < hard.penumbra.mean_abs);
    assert!(pcf.flip.mean_abs < hard.flip.mean_abs);
}

/// `ErrorStats` against a direct computation on random data: mean, RMSE and shares by
/// definition, the 99th percentile as the value at rank ⌈0.99 n⌉ of the sorted errors (the
/// nearest-rank definition), max; masked-out values ignored. Tolerance 1e-12 (sums of ≤ 5000
/// values in [0, 1] in another order).
#[test]
fn error_stats_match_direct_computation() {
    let mut rng = common::rng(3);
    for n in [1usize, 7, 100, 5000] {
        let v: Vec<f32> = (0..n).map(|_| rng.random_range(0.0..1.0)).collect();
        let t: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..1.0)).collect();
        let mut m: Vec<bool> = (0..n).map(|_| rng.random_bool(0.7)).collect();
        m[0] = true;
        let s = ErrorStats::new(&v, &t, &m);
        let mut e: Vec<f64> = (0..n)
            .filter(|&i| m[i])
            .map(|i| (f64::from(v[i]) - t[i]).abs())
            .collect();
        let k = e.len();
        let mean = e.iter().sum::<f64>() / k as f64;
        let rmse = (e.iter().map(|x| x * x).sum::<f64>() / k as f64).sqrt();
        e.sort_by(|a, b| b.partial_cmp(a).unwrap());
        let rank = (0.99 * k as f64).ceil() as usize; // 1-based rank in ascending order
        let p99 = e[k - rank];
        assert_eq!(s.pixels, k);
        for (what, got, want) in [
            ("mean", s.mean_abs, mean),
            ("rmse", s.rmse, rmse),
            ("p99", s.p99, p99),
            ("max", s.max, e[0]),
            (
                "over 0.05",
                s.over_005,
                e.iter().filter(|&&x| x > 0.05).count() as f64 / k as f64,
            ),
            (
                "over 0.2",
                s.over_02,
                e.iter().filter(|&&x| x > 0.2).count() as f64 / k as f64,
            ),
        ] {
            assert!((got - want).abs() < 1e-12, "n {n} {what}: {got} vs {want}");
        }
    }
}

/// Bad input is one clear line and exit status 1, never a panic.
#[test]
fn bad_input_is_a_clear_error() {
    let out = temp_dir("bad");
    let o = shadowgraph(&[
        "evaluate",
        scene_path("sphere_on_plane.toml").to_str().unwrap(),
        "--quick",
        "--techniques",
        "hard,phong",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("unknown technique `phong`") && err.contains("vsm"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    for (flag, value) in [
        ("--update", "0"),
        ("--update", "sometimes"),
        ("--update", "-3"),
        ("--budget", "0"),
        ("--budget", "-1"),
        ("--budget", "NaN"),
    ] {
        let o = shadowgraph(&[
            "evaluate",
            scene_path("sphere_on_plane.toml").to_str().unwrap(),
            "--quick",
            flag,
            value,
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{flag} {value}: {err}");
        assert!(
            err.trim().lines().count() == 1 && err.contains(flag) && !err.contains("panicked"),
            "{flag} {value}: {err}"
        );
    }
    let o = shadowgraph(&[
        "evaluate",
        "no/such/scene.toml",
        "--quick",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("no/such/scene.toml") && !err.contains("panicked"),
        "{err}"
    );
    let o = shadowgraph(&[
        "evaluate",
        scene_path("pole.toml").to_str().unwrap(),
        "--sizes",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--sizes") && !err.contains("panicked"),
        "{err}"
    );
    assert!(
        !out.join("report.json").exists(),
        "a failed run wrote a report"
    );
}

/// On `sphere_on_plane` (spot light of size 0.5) against the area-light truth (K = 64 emitter
/// samples, 2048² maps, 160×120 pixels), every soft technique at its scene defaults on a 1024²
/// map: its mean error over the lit receivers is at most 0.75 × that of hard shadows from the
/// same map (a soft technique has to recover a good part of the penumbra a hard shadow gets
/// wrong; hard shadows are off by ~0.5 across the penumbra) and at most 2 × PCSS's (the
/// per-pixel search it replaces with constant-time lookups), and its share of pixels off by
/// more than 0.2 is below hard's. Measured (lavapipe): mean error hard 0.0097, PCSS 0.0055,
/// cssm 0.0066 (0.68 × hard: the closest to its bound), vssm 0.0045, msm_soft 0.0030; off by
/// more than 0.2: hard 2.27%, PCSS 0.36%, cssm 1.48%, vssm 0.00%, msm_soft 0.03%
/// (`cargo test --release --test evaluate soft -- --nocapture`).
#[test]
fn soft_techniques_approach_the_area_light_truth() {
    use shadowgraph::PrefilterConfig;
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((160, 120)),
        samples: Some(64),
        truth_resolution: Some(2048),
        repeat: 1,
        ..Default::default()
    };
    let scene: Scene = scene_for(&scene_path("sphere_on_plane.toml"), &opts).expect("scene");
    let size = scene.lights[0].size;
    assert!(size > 0.0, "sphere_on_plane has an area light");
    let soft = |c: PrefilterConfig| match c.validated() {
        Ok((v, _)) => v.technique,
        Err(e) => panic!("{e}"),
    };
    let config = |label: &str, technique| Config {
        label: label.into(),
        technique,
        shadow_map: 1024,
        box_width: None,
    };
    let configs = vec![
        config("hard", Technique::Hard),
        config(
            "pcss",
            Technique::Pcss {
                blocker_samples: 16,
                filter_samples: 32,
                max_search: 0.1,
            },
        ),
        config("cssm", soft(PrefilterConfig::cssm(1024, 8, size))),
        config("vssm", soft(PrefilterConfig::vssm(1024, size))),
        config("msm_soft", soft(PrefilterConfig::msm_soft(1024, size))),
    ];
    let (report, _) = evaluate(&g, &scene, &configs, &opts).expect("evaluate");
    for r in &report.rows {
        eprintln!(
            "{}: mean {:.4} rmse {:.4} >0.05 {:.2}% >0.2 {:.2}%",
            r.label,
            r.soft.mean_abs,
            r.soft.rmse,
            100.0 * r.soft.over_005,
            100.0 * r.soft.over_02
        );
    }
    assert!(report.relevant_pixels > 5000);
    let (hard, pcss) = (&report.rows[0].soft, &report.rows[1].soft);
    assert!(pcss.mean_abs < hard.mean_abs, "PCSS must beat hard shadows");
    for r in &report.rows[2..] {
        let e = &r.soft;
        assert!(
            e.mean_abs <= 0.75 * hard.mean_abs,
            "{}: mean error {} vs hard {}",
            r.label,
            e.mean_abs,
            hard.mean_abs
        );
        assert!(
            e.mean_abs <= 2.0 * pcss.mean_abs,
            "{}: mean error {} vs PCSS {}",
            r.label,
            e.mean_abs,
            pcss.mean_abs
        );
        assert!(
            e.over_02 < hard.over_02,
            "{}: {e:?} vs hard {hard:?}",
            r.label
        );
    }
}

/// A cascaded light's memory is every cascade's: `city_street`'s four 256² PCF cascades hold
/// four depth maps and four linear maps, against one of each with `cascades = 1`, the other
/// resources alike; a point light's is its 3N × 2N atlas.
#[test]
fn memory_counts_every_cascade_and_a_point_lights_atlas() {
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((64, 48)),
        samples: Some(1),
        truth_resolution: Some(256),
        repeat: 1,
        ..Default::default()
    };
    let hard = |size| {
        vec![Config {
            label: format!("hard {size}"),
            technique: Technique::Hard,
            shadow_map: size,
            box_width: None,
        }]
    };
    let memory = |scene: &Scene, size| {
        evaluate(&g, scene, &hard(size), &opts)
            .expect("evaluate")
            .0
            .rows[0]
            .memory_bytes
    };
    let mut street: Scene = scene_for(&scene_path("city_street.toml"), &opts).expect("scene");
    assert_eq!(street.lights[0].shadow.cascades.count, 4);
    let four = memory(&street, 256);
    street.lights[0].shadow.cascades = shadowgraph::Cascades::SINGLE;
    let one = memory(&street, 256);
    // Each cascade: a Depth32Float map and its R32Float linear map, 4 bytes a texel each.
    let per_cascade = 2 * 256 * 256 * 4;
    assert_eq!(
        four - one,
        3 * per_cascade,
        "four cascades {four}, one {one}"
    );
    let point: Scene = scene_for(&scene_path("point.toml"), &opts).expect("scene");
    let atlas = 3 * 128 * 2 * 128 * 4;
    assert_eq!(memory(&point, 128), 2 * atlas);
}

/// The PCF column of a cascaded light compares each pixel with brute-force box PCF of the map
/// of its own cascade, picked and blended as the shading does: `city_street`'s four PCF 3×3
/// cascades stay within the PCF row's bound of `errors_are_plausible_and_recomputable` (mean
/// below 0.01: the GPU window is centred on the texel, the truth's box on the receiver). Taken
/// over the light's one-map projection of cascade 0's map, it read a mean of 0.28.
#[test]
fn a_cascaded_lights_pcf_truth_is_each_cascades() {
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((160, 120)),
        samples: Some(1),
        truth_resolution: Some(512),
        repeat: 1,
        ..Default::default()
    };
    let street: Scene = scene_for(&scene_path("city_street.toml"), &opts).expect("scene");
    assert_eq!(street.lights[0].shadow.cascades.count, 4);
    let configs = vec![Config {
        label: "pcf box3 256".into(),
        technique: Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Box,
        },
        shadow_map: 256,
        box_width: Some(3.0),
    }];
    let (report, _) = evaluate(&g, &street, &configs, &opts).expect("evaluate");
    let pcf = report.rows[0].pcf.expect("pcf truth");
    eprintln!("cascaded pcf against its box truth: {pcf:?}");
    assert!(pcf.pixels > 5000, "{pcf:?}");
    assert!(pcf.mean_abs < 0.01, "{pcf:?}");
}
