//! `shadowgraph evaluate` at other operating points and over time: a static light timed without
//! its map (`--update static`), and an animated scene's temporal error against the temporal
//! module's, recomputed independently.

mod common;

use std::path::{Path, PathBuf};

use shadowgraph::low_level::evaluate::{Config, EvaluateOptions, Metric, evaluate, scene_for};
use shadowgraph::low_level::render::Renderer;
use shadowgraph::low_level::truth::{Emitter, TruthOptions};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

/// `--update` through the library: with every light static, each timed frame reuses the map
/// the visit's settling frame drew, so no configuration is charged a raster or a kernel (0 ms,
/// exactly: the passes are not recorded) while every frame redraws them (both > 0); the errors
/// are the same still frame's in both runs (equal exactly), and the report names the rate.
#[test]
fn a_static_light_is_timed_without_its_map() {
    use shadowgraph::low_level::scene::UpdateRate;
    let g = common::gpu();
    let run = |update| {
        let opts = EvaluateOptions {
            image: Some((96, 72)),
            samples: Some(4),
            truth_resolution: Some(512),
            techniques: Some(vec!["hard".into(), "vsm".into()]),
            sizes: Some(vec![256]),
            quick: true,
            repeat: 2,
            update: Some(update),
            ..Default::default()
        };
        let scene = scene_for(&scene_path("sphere_on_plane.toml"), &opts).expect("scene");
        let configs = shadowgraph::low_level::evaluate::sweep(&scene, &opts).expect("sweep");
        evaluate(&g, &scene, &configs, &opts).expect("evaluate").0
    };
    let moving = run(UpdateRate::EveryFrame);
    let still = run(UpdateRate::Static);
    assert_eq!(still.updates, ["\"static\""]);
    assert_eq!(moving.updates, ["1"]);
    assert!(moving.rows.len() >= 2);
    for (m, s) in moving.rows.iter().zip(&still.rows) {
        assert_eq!(m.label, s.label);
        assert_eq!(m.soft, s.soft, "{}", m.label);
        assert!(
            m.raster_ms.unwrap() > 0.0 && m.kernels_ms.unwrap() > 0.0,
            "{}",
            m.label
        );
        assert_eq!(
            (s.raster_ms, s.kernels_ms),
            (Some(0.0), Some(0.0)),
            "{}",
            s.label
        );
        assert_eq!(s.total_ms, s.shade_ms, "{}", s.label);
    }
    let md = shadowgraph::low_level::evaluate::markdown(&still);
    assert!(
        md.contains("static lights: maps drawn once and kept"),
        "{md}"
    );
}

/// An animated scene (`colonnade_sun`, 8 frames of a sweeping sun): each row's temporal error
/// equals the temporal module's, recomputed from an independent renderer's frames and truths
/// (1e-12: the same sums); `hard` flickers more than a 5-texel VSM blur (its edge steps from
/// texel to texel as the sun moves by a fraction of one); the report has the temporal front and
/// its plot.
#[test]
fn an_animated_scene_has_a_temporal_error() {
    use shadowgraph::low_level::evaluate::temporal;
    let g = common::gpu();
    let opts = EvaluateOptions {
        image: Some((80, 60)),
        samples: Some(4),
        truth_resolution: Some(512),
        techniques: Some(vec!["hard".into(), "vsm".into()]),
        quick: true,
        repeat: 1,
        ..Default::default()
    };
    let scene = scene_for(&scene_path("colonnade_sun.toml"), &opts).expect("scene");
    assert!(scene.frames() > 2);
    let configs: Vec<Config> = shadowgraph::low_level::evaluate::sweep(&scene, &opts)
        .expect("sweep")
        .into_iter()
        .filter(|c| c.label == "hard 512" || c.label == "vsm f32 blur5 512")
        .collect();
    assert_eq!(configs.len(), 2);
    let (report, _) = evaluate(&g, &scene, &configs, &opts).expect("evaluate");
    let truth_opts = TruthOptions {
        emitter: Emitter::Stratified { k: 4, seed: 1 },
        resolution: Some(512),
    };
    let mut renderer = Renderer::new(&g.device);
    let truths =
        temporal::animation_truths(&mut renderer, &g.device, &g.queue, &scene, &truth_opts)
            .expect("truths");
    for (c, r) in configs.iter().zip(&report.rows) {
        let mut s = scene.clone();
        for l in &mut s.lights {
            l.shadow.technique = c.technique;
            l.shadow_map = c.shadow_map;
        }
        let v =
            temporal::animation_visibility(&mut Renderer::new(&g.device), &g.device, &g.queue, &s)
                .expect("frames");
        let want = temporal::animation_temporal_error(&truths, &v).expect("temporal");
        let got = r.temporal.expect("a temporal error");
        assert_eq!(
            (got.pairs, got.pixels),
            (want.pairs, want.pixels),
            "{}",
            r.label
        );
        assert!((got.mean_abs - want.mean_abs).abs() < 1e-12, "{}", r.label);
        assert!(got.pixels > 0 && got.mean_abs > 0.0, "{}", r.label);
    }
    let t = |i: usize| report.rows[i].temporal.unwrap().mean_abs;
    assert!(t(0) > t(1), "hard {} vs vsm {}", t(0), t(1));
    let md = shadowgraph::low_level::evaluate::markdown(&report);
    assert!(md.contains("front of total time vs temporal mean"), "{md}");
    assert_eq!(Metric::of(&report).last(), Some(&Metric::Temporal));
    let svg = shadowgraph::low_level::evaluate::pareto(&report, Metric::Temporal).expect("plot");
    assert_eq!(svg.matches("<g class=\"pt\">").count(), 2);
}
