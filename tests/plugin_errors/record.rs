//! Mistakes `Prefilter::record` names: unusable depth textures, inconsistent light
//! parameters, a point light's atlas; every accepted depth format runs; wrapped errors
//! print their cause once.

use super::*;

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
        let (_, moments) = shadowgraph::low_level::gpu::read_float_texture(
            &g.device,
            &g.queue,
            &out.maps[0].texture,
            0,
        )
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
        shadowgraph::low_level::graph::plan(
            &shadowgraph::low_level::graph::Graph::default(),
            &["light0.vsm"],
        )
        .expect_err("an undeclared output"),
    );
    let exec = Error::from(shadowgraph::ExecError::MissingImport("light0.depth".into()));
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
