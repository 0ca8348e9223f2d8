//! Mistakes named when the stage is made or timed: invalid configs, techniques the
//! stage cannot run, sizes past the device's limits, missing features.

use super::*;

#[test]
fn invalid_configs_are_named_by_new() {
    let g = common::gpu();
    let mut config = PrefilterConfig::vsm(64).with_blur(40.0);
    match Prefilter::new(&g.device, &config) {
        Err(Error::Stage(StageError::Config { field, message })) => {
            assert_eq!(field, "filter_radius", "{message}");
            assert!(message.contains("[0, 32]"), "{message}");
        }
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("radius 40 accepted"),
    }
    config = PrefilterConfig::evsm2(64);
    if let shadowgraph::Technique::Evsm { exp_pos, .. } = &mut config.technique {
        *exp_pos = 80.0;
    }
    let stage = Prefilter::new(&g.device, &config).expect("clamped, not rejected");
    assert!(
        stage.warnings().len() == 1 && stage.warnings()[0].contains("exponent_pos"),
        "{:?}",
        stage.warnings()
    );
}

/// The second-depth techniques read a second, peeled depth map the stage has no input for:
/// refused by name when the stage is made, not planned with a missing import.
#[test]
fn second_depth_techniques_are_refused_by_the_stage() {
    let g = common::gpu();
    for name in ["midpoint", "second_depth"] {
        let t = shadowgraph::low_level::technique::named(name, &[]).expect(name);
        let config = PrefilterConfig::new(t, 64);
        match Prefilter::new(&g.device, &config) {
            Err(Error::Stage(StageError::Config { field, message })) => {
                assert_eq!(field, "technique", "{message}");
                assert!(
                    message.contains(name) && message.contains("second, peeled depth"),
                    "{message}"
                );
            }
            Err(e) => panic!("{name}: {e}"),
            Ok(_) => panic!("{name} accepted by the plug-in stage"),
        }
    }
}

#[test]
fn sizes_and_kernels_past_the_device_limits_are_named() {
    let g = common::gpu();
    let (small, _) = device_with(
        &g,
        wgpu::Limits {
            max_texture_dimension_2d: 1024,
            ..g.adapter.limits()
        },
    );
    let e = limit_error(&small, &PrefilterConfig::vsm(2048));
    assert!(
        e.contains("map size") && e.contains("2048") && e.contains("1024"),
        "{e}"
    );

    let (little_memory, _) = device_with(
        &g,
        wgpu::Limits {
            max_compute_workgroup_storage_size: 2048,
            ..g.adapter.limits()
        },
    );
    let table = PrefilterConfig::vsm(64).with_filter(shadowgraph::Filter::Sat {
        width: 3.0,
        variant: shadowgraph::SatVariant::Fixed,
    });
    let e = limit_error(&little_memory, &table);
    assert!(
        e.contains("`vsm_sat_tile_sums`") && e.contains("max_compute_workgroup_storage_size"),
        "{e}"
    );
    // The encoding fused into the blur keeps its tile in WebGPU's default 16 KiB of workgroup
    // memory: named against a device with less.
    let e = limit_error(&little_memory, &PrefilterConfig::vsm(64));
    assert!(
        e.contains("`vsm_blur`") && e.contains("max_compute_workgroup_storage_size"),
        "{e}"
    );
    // docs/PLUGIN.md quotes this message as its example: word for word.
    let guide = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/PLUGIN.md"))
        .expect("docs/PLUGIN.md")
        .replace("\n  ", " ");
    assert!(guide.contains(&e), "docs/PLUGIN.md's example is not `{e}`");

    // A device made for WebGL 2 runs no compute shaders: one message says what to request
    // (not the first kernel's workgroup width against a limit of 0).
    let (no_compute, _) = device_with(&g, wgpu::Limits::downlevel_webgl2_defaults());
    match Prefilter::new(&no_compute, &PrefilterConfig::vsm(64)) {
        Err(e @ Error::Stage(StageError::NoCompute { .. })) => {
            let e = e.to_string();
            assert!(
                e.contains("no compute shaders")
                    && e.contains("max_compute_workgroup_size_x")
                    && e.contains("wgpu::Limits::default()")
                    && !e.contains('\n'),
                "{e}"
            );
        }
        Err(e) => panic!("expected NoCompute, got {e}"),
        Ok(_) => panic!("a stage on a device without compute shaders"),
    }
}

#[test]
fn timing_without_timestamps_is_a_missing_feature() {
    let g = common::gpu();
    let (plain, queue) = device_with(&g, g.adapter.limits());
    let mut stage = Prefilter::new(&plain, &PrefilterConfig::esm(64)).expect("stage");
    match stage.enable_timing(&plain, &queue) {
        Err(Error::Stage(StageError::MissingFeature {
            feature,
            needed_for,
        })) => {
            assert_eq!(feature, shadowgraph::TIMER_FEATURES);
            assert!(needed_for.contains("timing"));
        }
        Err(e) => panic!("{e}"),
        Ok(()) => panic!("timing enabled without TIMESTAMP_QUERY"),
    }
    // Pass timestamps alone are not enough: the timer writes between passes.
    let (passes_only, queue) =
        pollster::block_on(g.adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pass timestamps only"),
            required_features: wgpu::Features::TIMESTAMP_QUERY,
            required_limits: g.adapter.limits(),
            ..Default::default()
        }))
        .expect("a device with TIMESTAMP_QUERY (lavapipe has it)");
    let mut stage = Prefilter::new(&passes_only, &PrefilterConfig::esm(64)).expect("stage");
    match stage.enable_timing(&passes_only, &queue) {
        Err(Error::Stage(StageError::MissingFeature { feature, .. })) => {
            assert_eq!(feature, wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);
        }
        Err(e) => panic!("{e}"),
        Ok(()) => panic!("timing enabled without TIMESTAMP_QUERY_INSIDE_ENCODERS"),
    }
}

#[test]
fn unorm16_msm_without_the_16_bit_norm_feature_is_a_missing_feature() {
    let g = common::gpu();
    let (plain, _) = device_with(&g, g.adapter.limits());
    let config = PrefilterConfig::msm(64).with_storage(shadowgraph::Storage::Unorm16);
    match Prefilter::new(&plain, &config) {
        Err(e @ Error::MissingFeature { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("unorm16") && m.contains("TEXTURE_FORMAT_16BIT_NORM"),
                "{m}"
            );
        }
        Err(e) => panic!("expected a missing feature, got {e}"),
        Ok(_) => panic!("unorm16 MSM accepted without TEXTURE_FORMAT_16BIT_NORM"),
    }
    // f16 quantized moments need no feature.
    let f16 = PrefilterConfig::msm(64).with_storage(shadowgraph::Storage::F16);
    Prefilter::new(&plain, &f16).expect("f16 MSM on a plain device");
}

/// f32 tables are read with filtered fetches, so they need FLOAT32_FILTERABLE; fixed-point ones
/// need nothing.
#[test]
fn float_tables_without_float32_filterable_are_a_missing_feature() {
    let g = common::gpu();
    let (plain, _) = device_with(&g, g.adapter.limits());
    let config = PrefilterConfig::vssm(64, 0.5).with_soft(shadowgraph::SatVariant::Float, 0.2);
    match Prefilter::new(&plain, &config) {
        Err(e @ Error::MissingFeature { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("sat_sums") && m.contains("FLOAT32_FILTERABLE"),
                "{m}"
            );
        }
        Err(e) => panic!("expected a missing feature, got {e}"),
        Ok(_) => panic!("f32 tables accepted without FLOAT32_FILTERABLE"),
    }
    let fixed = PrefilterConfig::vssm(64, 0.5).with_soft(shadowgraph::SatVariant::Fixed, 0.2);
    Prefilter::new(&plain, &fixed).expect("fixed-point tables on a plain device");
}
