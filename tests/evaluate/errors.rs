//! Error figures recomputed independently from a render and the truth.

use super::*;

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
