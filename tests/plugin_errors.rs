//! Every mistake a host can make with the plug-in stage is a typed error naming what is wrong,
//! never a panic or a wgpu validation error.

mod common;

use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::{Error, LightParams, Prefilter, PrefilterConfig, StageError};

fn texture(
    g: &Gpu,
    format: wgpu::TextureFormat,
    (w, h, layers): (u32, u32, u32),
    samples: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.depth"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

const READABLE: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::TEXTURE_BINDING);

fn light() -> LightParams {
    LightParams::orthographic(
        glam::Mat4::look_at_rh(
            glam::Vec3::new(0.0, 5.0, 1.0),
            glam::Vec3::ZERO,
            glam::Vec3::Y,
        ),
        2.0,
        1.0,
        10.0,
    )
}

/// `record` over `depth`, expecting a stage error.
fn record_err<'a>(
    g: &Gpu,
    depth: impl Into<shadowgraph::DepthLayer<'a>>,
    light: &LightParams,
) -> StageError {
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(64)).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    match stage.record(&g.device, &mut enc, depth, light) {
        Err(Error::Stage(e)) => e,
        Err(e) => panic!("expected a stage error, got {e}"),
        Ok(_) => panic!("expected a stage error, got maps"),
    }
}

#[test]
fn unusable_depth_textures_are_named() {
    let g = common::gpu();
    let colour = texture(&g, wgpu::TextureFormat::R32Float, (64, 64, 1), 1, READABLE);
    let e = record_err(&g, &colour, &light());
    assert!(
        matches!(e, StageError::DepthFormat { format, .. } if format == wgpu::TextureFormat::R32Float),
        "{e}"
    );
    assert!(
        e.to_string().contains("R32Float") && e.to_string().contains("Depth32Float"),
        "{e}"
    );

    let unbound = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 64, 1),
        1,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let e = record_err(&g, &unbound, &light());
    assert!(matches!(e, StageError::DepthUsage { .. }), "{e}");
    assert!(e.to_string().contains("TEXTURE_BINDING"), "{e}");

    let wide = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 32, 1),
        1,
        READABLE,
    );
    let e = record_err(&g, &wide, &light());
    assert!(
        matches!(
            e,
            StageError::DepthNotSquare {
                width: 64,
                height: 32
            }
        ),
        "{e}"
    );

    let layered = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 64, 2),
        1,
        READABLE,
    );
    // A layer of an array is read in place (tests/plugin_lights.rs); one past its layers is
    // named.
    let past = shadowgraph::DepthLayer::new(&layered, 2);
    let e = record_err(&g, past, &light());
    assert!(
        matches!(
            e,
            StageError::DepthLayer {
                layer: 2,
                layers: 2
            }
        ),
        "{e}"
    );
    // Passed whole, an array names no layer: refused, not read from layer 0 (a second light's
    // maps would be filtered from the first's depth), in one line naming `DepthLayer`.
    let e = record_err(&g, &layered, &light());
    assert!(matches!(e, StageError::DepthArray { layers: 2 }), "{e}");
    let line = Error::from(e).to_string();
    assert!(
        line.contains("2 array layers") && line.contains("DepthLayer::new") && !line.contains('\n'),
        "{line}"
    );
    // One layer named, the same array is read.
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(64)).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    let first = shadowgraph::DepthLayer::new(&layered, 1);
    stage
        .record(&g.device, &mut enc, first, &light())
        .expect("a named layer of the array");

    let msaa = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 64, 1),
        4,
        READABLE,
    );
    let e = record_err(&g, &msaa, &light());
    assert!(
        matches!(e, StageError::DepthLayout { samples: 4, .. }),
        "{e}"
    );
}

/// The other accepted depth formats run and give the Depth32Float result to within their
/// precision: nothing is rasterized here, so every texel is the cleared 1.0, which each
/// format holds exactly.
#[test]
fn every_accepted_depth_format_runs() {
    let g = common::gpu();
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(32)).expect("stage");
    for format in shadowgraph::DEPTH_FORMATS {
        if !format
            .required_features()
            .iter()
            .all(|f| g.device.features().contains(f))
        {
            continue;
        }
        let depth = texture(&g, format, (32, 32, 1), 1, READABLE);
        let mut enc = g.device.create_command_encoder(&Default::default());
        let view = depth.create_view(&Default::default());
        drop(enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("clear"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: format.has_stencil_aspect().then_some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0),
                    store: wgpu::StoreOp::Store,
                }),
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        }));
        let out = stage
            .record(&g.device, &mut enc, &depth, &light())
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        shadowgraph::low_level::gpu::submit_and_wait(&g.device, &g.queue, enc, "stage")
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        let (_, moments) =
            shadowgraph::low_level::gpu::read_float_texture(&g.device, &g.queue, &out.maps[0].texture, 0)
                .expect("readback");
        assert!(
            moments.chunks(2).all(|m| m == [1.0, 1.0]),
            "{format:?}: moments of a cleared map are not (1, 1)"
        );
    }
}

#[test]
fn inconsistent_light_params_are_named() {
    let g = common::gpu();
    let depth = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 64, 1),
        1,
        READABLE,
    );
    let view = light().view;
    let cases: Vec<(LightParams, &str)> = vec![
        (
            LightParams {
                near: 10.0,
                far: 1.0,
                ..light()
            },
            "far",
        ),
        (
            LightParams {
                near: 0.0,
                ..light()
            },
            "near",
        ),
        (
            LightParams {
                target_distance: f32::NAN,
                ..light()
            },
            "target_distance",
        ),
        (
            LightParams {
                view: glam::Mat4::from_cols_array(&[f32::NAN; 16]),
                ..light()
            },
            "view",
        ),
        // A search cap on a technique without a search (the stage here runs VSM), and one
        // that is not a UV fraction.
        (
            LightParams {
                max_search: Some(0.1),
                ..light()
            },
            "max_search",
        ),
        (
            LightParams {
                max_search: Some(f32::NAN),
                ..light()
            },
            "max_search",
        ),
        // Reversed Z: depth 1 at near, 0 at far.
        (
            LightParams {
                projection: glam::Mat4::orthographic_rh(-2.0, 2.0, -2.0, 2.0, 10.0, 1.0),
                ..light()
            },
            "projection",
        ),
        // A perspective matrix declared orthographic.
        (
            LightParams {
                projection: glam::Mat4::perspective_rh(1.0, 1.0, 1.0, 10.0),
                ..light()
            },
            "projection",
        ),
        // Planes that are not the projection's.
        (
            LightParams {
                far: 20.0,
                ..LightParams::perspective(view, 1.0, 1.0, 10.0)
            },
            "projection",
        ),
    ];
    // A point light's own cap would read past the faces' bands, which follow the config's
    // (refused by the light itself, whatever the stage's technique).
    let point = LightParams {
        max_search: Some(0.1),
        ..LightParams::point(glam::Vec3::ZERO, 0.5, 10.0)
    };
    match point.validate() {
        Err(StageError::LightParams { field, message }) => {
            assert_eq!(field, "max_search");
            assert!(message.contains("point light"), "{message}");
        }
        other => panic!("a point light's own max_search: {other:?}"),
    }
    for (params, field) in cases {
        let e = record_err(&g, &depth, &params);
        assert!(
            matches!(e, StageError::LightParams { field: f, .. } if f == field),
            "expected `{field}`: {e}"
        );
    }
}

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

/// A point light's stage: an atlas of the wrong shape, `point_views` of a light that is not a
/// point light, and a technique six faces cannot bound are each named.
#[test]
fn point_light_mistakes_are_named() {
    let g = common::gpu();
    let point = LightParams::point(glam::Vec3::new(0.0, 2.0, 0.0), 0.1, 10.0);
    // A square texture (the face alone), and 3N × 2N but for one texel.
    for (w, h) in [(64, 64), (192, 127), (193, 128)] {
        let depth = texture(
            &g,
            wgpu::TextureFormat::Depth32Float,
            (w, h, 1),
            1,
            READABLE,
        );
        match record_err(&g, &depth, &point) {
            StageError::DepthNotAtlas { width, height } => assert_eq!((width, height), (w, h)),
            e => panic!("{w}x{h}: {e}"),
        }
    }
    let stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(64)).expect("stage");
    match stage.point_views(&light(), 64) {
        Err(Error::Stage(StageError::LightParams { field, .. })) => assert_eq!(field, "point"),
        other => panic!("point_views of a directional light: {other:?}"),
    }
    // The default blur (radius 2) on 64-texel faces: a guard band of 4; six views.
    let views = stage.point_views(&point, 64).expect("views");
    assert_eq!(views.len(), 6);
    assert_eq!(views[5].viewport, [128, 64, 64, 64]);
    let smrt = shadowgraph::low_level::technique::named("smrt", &[]).expect("smrt");
    let config = PrefilterConfig::new(smrt, 64).with_light_size(0.2);
    let stage = Prefilter::new(&g.device, &config).expect("stage");
    match stage.point_views(&point, 64) {
        Err(Error::Stage(StageError::Config { field, message })) => {
            assert_eq!(field, "technique");
            assert!(message.contains("smrt"), "{message}");
        }
        other => panic!("smrt on a point light: {other:?}"),
    }
    // A face too small for the guard band: refused by name before anything is planned.
    let depth = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (24, 16, 1),
        1,
        READABLE,
    );
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(64)).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    match stage.record(&g.device, &mut enc, &depth, &point) {
        Err(Error::Stage(StageError::Config { message, .. })) => {
            assert!(message.contains("guard band"), "{message}")
        }
        Err(e) => panic!("8-texel faces: {e}"),
        Ok(_) => panic!("8-texel faces accepted"),
    }
}

/// A device (and queue) of the same adapter with `limits` and no optional features.
fn device_with(g: &Gpu, limits: wgpu::Limits) -> (wgpu::Device, wgpu::Queue) {
    pollster::block_on(g.adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("limited"),
        required_limits: limits,
        ..Default::default()
    }))
    .expect("a device with lower limits")
}

fn limit_error(device: &wgpu::Device, config: &PrefilterConfig) -> String {
    match Prefilter::new(device, config) {
        Err(e @ Error::Limit { .. }) => e.to_string(),
        Err(e) => panic!("expected a limit error, got {e}"),
        Ok(_) => panic!("expected a limit error"),
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

/// A wrapped error prints its cause once, also where causes are printed one by one (anyhow's
/// `{:#}`, what the examples and a host's `main` print): the variant's message holds the
/// cause, so it is not also its `source()`.
#[test]
fn wrapped_errors_print_their_cause_once() {
    let g = common::gpu();
    let cleared = texture(
        &g,
        wgpu::TextureFormat::Depth32Float,
        (64, 32, 1),
        1,
        READABLE,
    );
    let stage = Error::from(record_err(&g, &cleared, &light()));
    let graph = Error::from(
        shadowgraph::low_level::graph::plan(&shadowgraph::low_level::graph::Graph::default(), &["light0.vsm"])
            .expect_err("an undeclared output"),
    );
    let exec = Error::from(shadowgraph::ExecError::MissingImport(
        "light0.depth".into(),
    ));
    for (e, cause) in [
        (stage, "is 64x32"),
        (graph, "`light0.vsm`"),
        (exec, "`light0.depth`"),
    ] {
        let line = e.to_string();
        let chain = format!("{:#}", anyhow::Error::from(e));
        assert_eq!(chain, line, "the chain adds to the message");
        assert_eq!(chain.matches(cause).count(), 1, "{chain}");
    }
}
