//! The CLI's library functions: `render --aux` writes readable EXRs, `plan` prints the kernels.

mod common;

use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-test-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

#[test]
fn render_writes_png_and_aux_exrs() {
    let g = common::gpu();
    let dir = temp_dir("aux");
    let png = dir.join("out.png");
    let report = shadowgraph::low_level::cli::render(
        &g,
        &scene("two_lights.toml"),
        &png,
        Some(&dir),
        true,
        2,
    )
    .expect("render");
    assert!(report.contains("wrote"), "{report}");
    assert!(
        report.contains("shade") && report.contains("light0.linearize"),
        "timings missing:\n{report}"
    );
    let img = image::open(&png).expect("png readable").to_rgba8();
    assert_eq!(img.dimensions(), (480, 360));
    let vis = exr::prelude::read_all_flat_layers_from_file(dir.join("visibility.exr"))
        .expect("visibility.exr");
    let layer = &vis.layer_data[0];
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    assert_eq!(names, ["light0", "light1"]);
    for c in &layer.channel_data.list {
        let v: Vec<f32> = c.sample_data.values_as_f32().collect();
        assert_eq!(v.len(), 480 * 360);
        assert!(
            v.iter().all(|x| (0.0..=1.0).contains(x)),
            "{}: out of [0, 1]",
            c.name
        );
        assert!(
            v.iter().any(|&x| x < 0.5),
            "{}: no shadow in the EXR",
            c.name
        );
    }
    for f in ["position.exr", "normal.exr"] {
        let img = exr::prelude::read_all_flat_layers_from_file(dir.join(f)).expect(f);
        assert_eq!(img.layer_data[0].channel_data.list.len(), 4, "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plan_text_and_dot() {
    let text = shadowgraph::low_level::cli::plan(&scene("bunny.toml"), false).expect("plan");
    for needle in [
        "light 0",
        "light0.linearize",
        "R32Float",
        "1024x1024",
        "peak live",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
    let dot = shadowgraph::low_level::cli::plan(&scene("bunny.toml"), true).expect("dot");
    assert!(dot.starts_with("digraph") && dot.contains("light0.linearize"));
}

#[test]
fn bad_scene_path_is_an_error_naming_the_file() {
    let e = shadowgraph::low_level::cli::plan(Path::new("no/such/scene.toml"), false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no/such/scene.toml"), "{e}");
}

/// `bench --lookup`'s soft table: one row per configuration with positive, finite shading
/// times per light size; the prefilter's time is the light's passes after its raster (tables
/// for the soft techniques, none of them for `hard`'s one-pass linearization to outweigh), the
/// frame's passes add up to at least shade + prefilter, the prefilter's passes (their table's
/// among them for the soft techniques) add up to it in one round, and `--image` and `--map`
/// reach the scene and the table's header.
#[test]
fn soft_benchmark_reports_every_configuration() {
    let g = common::gpu();
    let rows = shadowgraph::low_level::bench::soft_cost(
        &g,
        &[0.5, 1.0],
        1,
        Some((48, 36)),
        Some(128),
        &[],
    )
    .expect("soft bench");
    let names: Vec<&str> = rows.iter().map(|r| r.technique.as_str()).collect();
    let want: Vec<&str> = shadowgraph::low_level::bench::SOFT_TECHNIQUES
        .iter()
        .map(|(n, _)| *n)
        .collect();
    assert_eq!(names, want);
    for r in &rows {
        assert_eq!(
            (r.image, r.map, r.shade_ms.len()),
            ((48, 36), 128, 2),
            "{r:?}"
        );
        for v in r.shade_ms.iter().chain([&r.frame_ms, &r.wall_ms]) {
            assert!(v.is_finite() && *v > 0.0, "{r:?}");
        }
        assert!(r.prefilter_ms.is_finite() && r.prefilter_ms >= 0.0, "{r:?}");
        // One round: the passes' medians are the round's own times, and add up to the total.
        let by_pass: f64 = r.prefilter_passes.iter().map(|(_, ms)| ms).sum();
        assert!(
            (by_pass - r.prefilter_ms).abs() <= 1e-9 * r.prefilter_ms.max(1.0),
            "prefilter by pass: {r:?}"
        );
        assert!(
            r.frame_ms >= r.shade_ms[0] + r.prefilter_ms - 1e-9,
            "the frame's passes include shade and prefilter: {r:?}"
        );
    }
    let tables = |name: &str| rows.iter().find(|r| r.technique == name).unwrap();
    for soft in ["vssm", "msm_soft", "cssm M=8", "cssm M=8 csm_z"] {
        assert!(
            tables(soft)
                .prefilter_passes
                .iter()
                .any(|(n, _)| n.contains(".sat")),
            "{soft}'s passes name its table: {:?}",
            tables(soft)
        );
        assert!(
            tables(soft).prefilter_ms > 0.0,
            "{soft} builds tables: {:?}",
            tables(soft)
        );
    }
    let table =
        shadowgraph::low_level::bench::format_soft_table("test", true, 1, &[0.5, 1.0], &rows);
    assert!(table.contains("(48×36, 128² spot map)"), "{table}");
    assert!(
        table.contains("prefilter ms") && table.contains("wall ms"),
        "{table}"
    );
    // `--only` keeps the named configurations, `hard` and the yardstick, whose ratios stay 1.
    let only = ["cssm".to_string()];
    let some =
        shadowgraph::low_level::bench::soft_cost(&g, &[0.5], 1, Some((48, 36)), Some(128), &only)
            .expect("soft bench, only cssm");
    let names: Vec<&str> = some.iter().map(|r| r.technique.as_str()).collect();
    assert_eq!(names, ["hard", "pcss 16+32", "cssm M=8", "cssm M=8 csm_z"]);
    let table = shadowgraph::low_level::bench::format_soft_table("test", true, 1, &[0.5], &some);
    let pcss = table.lines().find(|l| l.starts_with("pcss 16+32")).unwrap();
    assert!(pcss.contains("( 1.00)"), "{table}");
    assert!(table.contains("above hard"), "{table}");
}

/// `bench --lookup`: one row per width with positive, finite times for the three lookups;
/// even or out-of-range widths are errors naming the width. (The times themselves are the
/// benchmark's business, not a test's.)
#[test]
fn lookup_benchmark_reports_every_width() {
    let g = common::gpu();
    let rows = shadowgraph::low_level::bench::lookup_cost(&g, &[3, 9], 1, None, None)
        .expect("lookup bench");
    assert_eq!(rows.iter().map(|r| r.width).collect::<Vec<_>>(), vec![3, 9]);
    for r in &rows {
        for v in [r.pcf_ms, r.sat_fixed_ms, r.sat_float_ms] {
            assert!(v.is_finite() && v > 0.0, "{r:?}");
        }
    }
    let table = shadowgraph::low_level::bench::format_lookup_table("test", true, 1, &rows);
    assert!(
        table.contains("   3²") && table.contains("   9²"),
        "{table}"
    );
    assert!(rows.iter().all(|r| r.image == (400, 300)), "{rows:?}");
    // `--image` shades at the size asked for, and the table says so.
    let small = shadowgraph::low_level::bench::lookup_cost(&g, &[3], 1, Some((64, 48)), Some(256))
        .expect("at 64x48");
    assert_eq!((small[0].image, small[0].map), ((64, 48), 256));
    let table = shadowgraph::low_level::bench::format_lookup_table("test", true, 1, &small);
    assert!(table.contains("(64×48, 256² map)"), "{table}");
    for bad in [4, 0, 67] {
        let e = shadowgraph::low_level::bench::lookup_cost(&g, &[bad], 1, None, None)
            .expect_err("bad width");
        assert!(e.to_string().contains(&format!("width {bad}")), "{e}");
    }
}
