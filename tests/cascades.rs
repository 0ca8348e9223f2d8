//! Cascade fitting for a host's directional light (`prefilter::cascades`), against f64
//! computations written here: the practical split, every slice of the camera's frustum inside
//! its cascade's box, and the two stability properties (a world point keeps its place within a
//! texel while the camera translates; the half-width does not change as the camera turns).

mod common;

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};
use rand::Rng;
use shadowgraph::StageError;
use shadowgraph::cascades::{
    CascadeCamera, CascadeLayout, fit_cascades, split_distances, view_distance,
};

fn camera(eye: Vec3, target: Vec3) -> CascadeCamera {
    CascadeCamera {
        view: Mat4::look_at_rh(eye, target, Vec3::Y),
        fov_y: 0.9,
        aspect: 16.0 / 9.0,
        near: 0.5,
        far: 120.0,
    }
}

const LAYOUT: CascadeLayout = CascadeLayout {
    count: 4,
    lambda: 0.75,
    map_size: 1024,
    caster_margin: 20.0,
};

fn sun() -> Vec3 {
    Vec3::new(-0.4, -1.0, 0.3)
}

/// f32 vs f64 rounding of `n · (f/n)^t` and the blend: relative 1e-6.
#[test]
fn splits_follow_the_practical_formula() {
    for (n, f, count, lambda) in [
        (0.5f64, 120.0f64, 4u32, 0.75f64),
        (0.1, 1000.0, 8, 0.9),
        (1.0, 50.0, 1, 0.3),
        (2.0, 10.0, 3, 0.0),
        (0.05, 400.0, 6, 1.0),
    ] {
        let got = split_distances(n as f32, f as f32, count, lambda as f32).expect("valid");
        assert_eq!(got.len(), count as usize);
        for (i, &d) in got.iter().enumerate() {
            let t = (i + 1) as f64 / count as f64;
            let expected = lambda * n * (f / n).powf(t) + (1.0 - lambda) * (n + (f - n) * t);
            assert!(
                (f64::from(d) - expected).abs() <= 1e-6 * expected,
                "n {n} f {f} N {count} λ {lambda}: split {i} is {d}, expected {expected}"
            );
        }
        assert!((f64::from(*got.last().expect("one")) - f).abs() <= 1e-6 * f);
    }
}

#[test]
fn bad_layouts_are_named() {
    for (count, lambda, near, far, field) in [
        (0, 0.5, 1.0, 10.0, "cascades"),
        (9, 0.5, 1.0, 10.0, "cascades"),
        (4, 1.5, 1.0, 10.0, "cascade_lambda"),
        (4, f32::NAN, 1.0, 10.0, "cascade_lambda"),
        (4, 0.5, 10.0, 1.0, "near/far"),
        (4, 0.5, 0.0, 1.0, "near/far"),
        (4, 0.5, 1.0, 1e30, "near/far"),
        (4, 0.5, 1e-9, 1.0, "near/far"),
    ] {
        let e = split_distances(near, far, count, lambda).unwrap_err();
        assert!(
            matches!(&e, StageError::Config { field: f, .. } if f.contains(field)),
            "{count} {lambda} {near} {far}: {e}"
        );
    }
    let cam = camera(Vec3::new(0.0, 5.0, 10.0), Vec3::ZERO);
    let e = fit_cascades(&cam, Vec3::ZERO, &LAYOUT).unwrap_err();
    assert!(e.to_string().contains("direction"), "{e}");
    // A camera past f32's comfort is named, not a light with a non-finite matrix.
    let far = CascadeCamera { far: 1e30, ..cam };
    let e = fit_cascades(&far, sun(), &LAYOUT).unwrap_err();
    assert!(e.to_string().contains("near/far"), "{e}");
    let nan = CascadeCamera {
        view: Mat4::from_cols_array(&[f32::NAN; 16]),
        ..cam
    };
    let e = fit_cascades(&nan, sun(), &LAYOUT).unwrap_err();
    assert!(e.to_string().contains("camera"), "{e}");
}

/// The 8 corners of the camera's frustum slice between view distances `n` and `f`, world
/// space, in f64.
fn slice_corners(c: &CascadeCamera, n: f64, f: f64) -> Vec<DVec3> {
    let to_world = c.view.as_dmat4().inverse();
    let t = (0.5 * f64::from(c.fov_y)).tan();
    let a = f64::from(c.aspect);
    let mut out = Vec::new();
    for d in [n, f] {
        for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let v = DVec4::new(sx * t * a * d, sy * t * d, -d, 1.0);
            out.push((to_world * v).truncate());
        }
    }
    out
}

/// Light-space coordinates of `p` (f64): x, y in [−1, 1] inside the map, depth in [0, 1].
fn light_ndc(view: Mat4, projection: Mat4, p: DVec3) -> DVec3 {
    let m: DMat4 = projection.as_dmat4() * view.as_dmat4();
    let c = m * p.extend(1.0);
    c.truncate() / c.w
}

/// Every corner of each slice lies inside its cascade's map (|x|, |y| ≤ 1, depth in [0, 1]),
/// with the margin toward the light behind it; cascades tile the view range in order.
#[test]
fn each_slice_lies_inside_its_cascade() {
    let mut rng = common::rng(7);
    for _ in 0..50 {
        let eye = Vec3::new(
            rng.random_range(-50.0..50.0),
            rng.random_range(1.0..30.0),
            rng.random_range(-50.0..50.0),
        );
        let target = eye
            + Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-0.6..0.2),
                rng.random_range(-1.0..1.0),
            );
        let cam = camera(eye, target);
        let cascades = fit_cascades(&cam, sun(), &LAYOUT).expect("fit");
        assert_eq!(cascades.len(), 4);
        let mut near = cam.near;
        for (k, c) in cascades.iter().enumerate() {
            assert_eq!(c.near, near, "cascade {k} starts where the last ended");
            near = c.far;
            for p in slice_corners(&cam, f64::from(c.near), f64::from(c.far)) {
                let q = light_ndc(c.light.view, c.light.projection, p);
                assert!(
                    q.x.abs() <= 1.0 + 1e-5
                        && q.y.abs() <= 1.0 + 1e-5
                        && (0.0..=1.0).contains(&q.z),
                    "cascade {k}: corner {p} at {q}"
                );
                // The caster margin: a point `caster_margin` toward the light is still mapped.
                let toward = p - sun().as_dvec3().normalize() * f64::from(LAYOUT.caster_margin);
                let qt = light_ndc(c.light.view, c.light.projection, toward);
                assert!(qt.z >= 0.0, "cascade {k}: margin lost ({qt})");
            }
        }
        assert!((near - cam.far).abs() <= 1e-4 * cam.far);
    }
}

/// A camera translated by small random steps: each cascade's texel grid stays put in the
/// world (a fixed world point's position within its texel changes by < 1e-3 texel, f32
/// noise), and turning the camera in place keeps every half-width bit for bit.
#[test]
fn cascades_do_not_shimmer() {
    let mut rng = common::rng(11);
    let probe = DVec3::new(3.3, 0.0, -7.1);
    let base = camera(Vec3::new(2.0, 6.0, 12.0), Vec3::new(0.0, 0.0, -5.0));
    let first = fit_cascades(&base, sun(), &LAYOUT).expect("fit");
    let frac = |c: &shadowgraph::cascades::Cascade| {
        let q = light_ndc(c.light.view, c.light.projection, probe);
        let texels = (q.truncate() * 0.5 + 0.5) * f64::from(LAYOUT.map_size);
        texels - texels.floor()
    };
    for step in 0..40 {
        let shift = Vec3::new(
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.05..0.05),
            rng.random_range(-0.3..0.3),
        );
        let moved = CascadeCamera {
            view: base.view * Mat4::from_translation(-shift),
            ..base
        };
        let now = fit_cascades(&moved, sun(), &LAYOUT).expect("fit");
        for (k, (a, b)) in first.iter().zip(&now).enumerate() {
            assert_eq!(a.radius, b.radius, "step {step} cascade {k}: radius");
            let (fa, fb) = (frac(a), frac(b));
            let d = (fa - fb).abs();
            // A wrap across a texel edge reads as ~1.
            let off = d.x.min(1.0 - d.x).max(d.y.min(1.0 - d.y));
            assert!(
                off < 1e-3,
                "step {step} cascade {k}: texel phase moved {off}"
            );
        }
        // Turning in place: radii unchanged.
        let yaw = rng.random_range(-3.0..3.0);
        let turned = CascadeCamera {
            view: Mat4::from_rotation_y(yaw) * base.view,
            ..base
        };
        let t = fit_cascades(&turned, sun(), &LAYOUT).expect("fit");
        for (a, b) in first.iter().zip(&t) {
            assert_eq!(a.radius, b.radius, "turning changed a radius");
        }
    }
    // A point's cascade follows its view distance.
    let p = Vec3::new(0.0, 0.0, -5.0);
    let d = view_distance(&base, p);
    let expected = (DVec3::new(2.0, 6.0, 12.0) - p.as_dvec3())
        .dot((DVec3::new(2.0, 6.0, 12.0) - DVec3::new(0.0, 0.0, -5.0)).normalize());
    assert!((f64::from(d) - expected).abs() < 1e-4, "{d} vs {expected}");
}

/// The plug-in's cascade config: a scene light's `cascades` keys carried by
/// `PrefilterConfig::from_light`, fitted by `Prefilter::fit_cascades` and handed to the exported
/// `sg_cascade_pick` through `pick_fields`, give the pick fields the renderer gives the same
/// light (`city_street`: four PCF cascades), so a host's pick and blend band are the
/// renderer's; bad keys are named by validation, and a soft technique's cascades fitted without
/// the light's plane, a spot light's cascades and a guard band past a quarter of the map by
/// the fitting.
#[test]
fn the_stages_cascade_config_matches_the_renderers_pick() {
    use shadowgraph::{Prefilter, PrefilterConfig};
    let g = common::gpu();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let scene = shadowgraph::low_level::scene::Scene::load(&path).expect("city_street loads");
    let light = &scene.lights[0];
    let config = PrefilterConfig::from_light(light);
    assert_eq!(config.cascades, light.shadow.cascades);
    let stage = Prefilter::new(&g.device, &config).expect("stage");
    let camera = shadowgraph::low_level::render::cascade_camera(&scene).expect("camera");
    let cascades = stage
        .fit_cascades(&camera, light.direction(), 10.0)
        .expect("fit");
    assert_eq!(cascades.len(), 4);
    let mut first = cascades[0].light.light_gpu(&config, config.size);
    shadowgraph::cascades::pick_fields(&mut first, &camera, &cascades, config.cascades.blend)
        .expect("pick fields");
    let drawn = shadowgraph::low_level::render::drawn_lights(&scene).expect("drawn lights");
    let r = drawn.gpu[0];
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * a.abs().max(1.0);
    assert_eq!(first.cascade_count, r.cascade_count);
    assert!(close(first.cascade_near, r.cascade_near), "near");
    assert!(close(first.cascade_blend, r.cascade_blend), "blend");
    for k in 0..3 {
        assert!(close(first.cascade_eye[k], r.cascade_eye[k]), "eye");
        assert!(
            close(first.cascade_forward[k], r.cascade_forward[k]),
            "forward"
        );
    }
    for c in 0..4 {
        let (a, b) = (first.cascade_far[c / 4][c % 4], r.cascade_far[c / 4][c % 4]);
        assert!(close(a, b), "cascade {c} far: stage {a}, renderer {b}");
    }
    // Every cascade's light is a valid orthographic light the stage records.
    for c in &cascades {
        c.light.validate().expect("cascade light");
        assert!(!c.light.perspective && !c.light.point);
    }

    // Validation: the scene's ranges.
    for (count, lambda, blend, field) in [
        (9, 0.5, 0.1, "cascades"),
        (0, 0.5, 0.1, "cascades"),
        (4, 1.5, 0.1, "cascade_lambda"),
        (4, 0.5, 0.7, "cascade_blend"),
    ] {
        match PrefilterConfig::vsm(512)
            .with_cascades(count, lambda, blend)
            .validated()
        {
            Err(StageError::Config { field: f, .. }) => assert_eq!(f, field),
            other => panic!("({count}, {lambda}, {blend}): {other:?}"),
        }
    }
    // PCSS and the soft techniques take cascades that keep the light's plane
    // (`fit_light_cascades`, checked against the renderer's in tests/plugin/); the
    // per-cascade depth ranges of `fit_cascades` are refused for them by name.
    let soft = PrefilterConfig::vssm(512, 0.5).with_cascades(4, 0.5, 0.1);
    assert!(soft.validated().is_ok());
    let soft_stage = Prefilter::new(&g.device, &soft).expect("soft stage");
    match soft_stage.fit_cascades(&camera, light.direction(), 10.0) {
        Err(shadowgraph::Error::Stage(StageError::Config { field, message })) => {
            assert_eq!(field, "technique");
            assert!(message.contains("fit_light_cascades"), "{message}");
        }
        other => panic!("vssm through fit_cascades: {other:?}"),
    }
    let sun = shadowgraph::LightParams::from_light(light);
    let spot = shadowgraph::LightParams::perspective(sun.view, 1.0, sun.near, sun.far);
    match soft_stage.fit_light_cascades(&camera, &spot) {
        Err(shadowgraph::Error::Stage(StageError::LightParams { field, .. })) => {
            assert_eq!(field, "projection")
        }
        other => panic!("a spot light's cascades: {other:?}"),
    }
    // A guard band past a quarter of the map is named (vssm: 3 texels past its reach, of 8).
    let wide = Prefilter::new(&g.device, &soft.with_size(8)).expect("stage");
    match wide.fit_light_cascades(&camera, &sun) {
        Err(shadowgraph::Error::Stage(StageError::Config { field, message })) => {
            assert_eq!(field, "shadow_map", "{message}");
        }
        other => panic!("an 8² soft cascade: {other:?}"),
    }
    assert!(
        PrefilterConfig::msm(512)
            .with_cascades(4, 0.75, 0.1)
            .validated()
            .is_ok()
    );
}

/// The renderer's cascades of PCSS and the soft techniques (`render::cascade`): every cascade
/// caps search and filter at one world reach R (its `max_search` in its own map's UV times
/// the map's width is R, to f32 rounding) and filters with PCSS's filter capped too; and
/// around every corner of each slice of the camera's view (f64, the renderer's split), a
/// square of half-width R plus the guard's texels, less the one kept for the snapped centre,
/// lies inside the cascade's map: no lookup of a receiver in the slice reads past the map's
/// edge. Random street-level cameras over `city_street`; R = min(max_search · 2·extent,
/// size·(far − near)/(2·near)) = 2.8 units there.
#[test]
fn soft_cascades_keep_one_reach_inside_their_maps() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let base = shadowgraph::low_level::scene::Scene::load(&path).expect("city_street loads");
    let mut rng = common::rng(11);
    for name in ["pcss", "vssm", "msm_soft", "cssm"] {
        for _ in 0..8 {
            let mut scene = base.clone();
            let light = &mut scene.lights[0];
            light.shadow.technique =
                shadowgraph::low_level::technique::named(name, &[]).expect("registered");
            let eye = Vec3::new(
                rng.random_range(-20.0..20.0),
                rng.random_range(1.0..6.0),
                rng.random_range(-20.0..26.0),
            );
            scene.camera.position = eye;
            scene.camera.target = eye
                + Vec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-0.4..0.1),
                    rng.random_range(-1.0..1.0),
                );
            let guard = shadowgraph::low_level::technique::cascade_guard(&scene.lights[0]);
            let reach = f64::from(guard.world);
            assert!(
                (reach - 2.8).abs() < 1e-5,
                "{name}: reach {reach} (size·(far − near)/(2·near) = 2.8)"
            );
            let drawn = shadowgraph::low_level::render::drawn_lights(&scene).expect("drawn lights");
            let group = drawn.groups[0];
            let camera = shadowgraph::low_level::render::cascade_camera(&scene).expect("camera");
            let c = scene.lights[0].shadow.cascades;
            let fars = split_distances(camera.near, camera.far, c.count, c.lambda).expect("split");
            let mut near = f64::from(camera.near);
            for (i, &far) in fars.iter().enumerate() {
                let k = group.index(i);
                let l = &drawn.lights[k];
                let width = f64::from(l.width_at_unit());
                let cap = f64::from(l.shadow.technique.max_search().expect("capped")) * width;
                assert!(
                    (cap - reach).abs() <= 1e-6 * reach,
                    "{name} cascade {i}: cap {cap} world units, reach {reach}"
                );
                assert_eq!(drawn.gpu[k].capped_filter, 1, "{name} cascade {i}");
                let texel = width / f64::from(l.shadow_map);
                let needed = reach + (f64::from(guard.texels) - 1.0) * texel;
                for p in slice_corners(&camera, near, f64::from(far)) {
                    let q = light_ndc(l.view(), l.projection(), p);
                    let room = (1.0 - q.x.abs().max(q.y.abs())) * 0.5 * width;
                    assert!(
                        room >= needed,
                        "{name} cascade {i}: corner {p} has {room} units to the map's edge, the reach needs {needed}"
                    );
                }
                near = f64::from(far);
            }
        }
    }
}

/// The cascaded shading block evaluates each cascade's visibility at one call site, guarded by
/// the pick (the pixel's cascade, or the next inside the blend band), so a driver that runs
/// every branch under lane masks (llvmpipe) evaluates each cascade once a pixel, not once for
/// the pick and again for the blend (2026-11-28: shading 1.3–2.0× faster there); every
/// cascade's light case appears once.
#[test]
fn the_cascaded_shading_calls_each_cascade_once() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let scene = shadowgraph::low_level::scene::Scene::load(&path).expect("city_street loads");
    let drawn = shadowgraph::low_level::render::drawn_lights(&scene).expect("drawn lights");
    let block =
        shadowgraph::low_level::technique::shading_block_cascaded(&drawn.lights, &drawn.groups);
    let group = drawn.groups[0];
    assert_eq!(group.count, 4);
    for c in 0..group.count {
        let call = format!("light0_cascade{c}(p, n, dpdx, dpdy)");
        assert_eq!(block.matches(&call).count(), 1, "{call}:\n{block}");
        assert_eq!(
            block.matches(&format!("fn light0_cascade{c}(")).count(),
            1,
            "cascade {c}'s function"
        );
        let k = group.index(c);
        assert_eq!(
            block.matches(&format!("light{k}_visibility(l, s)")).count(),
            1,
            "cascade {c} (drawn light {k}) has one light case"
        );
    }
    assert_eq!(
        block.matches("light0_cascaded(p, n, dpdx, dpdy)").count(),
        1
    );
}

/// A scene file with a directional light in three cascades, the camera at `eye` looking at
/// `target`, and a plane `scale` times 18 units wide and a unit box at `at`.
fn far_scene(eye: [f64; 3], target: [f64; 3], scale: f64, at: [f64; 3]) -> String {
    format!(
        "[output]\nwidth = 64\nheight = 48\n\n[camera]\nposition = {eye:?}\ntarget = {target:?}\n\
         fov_y_degrees = 45.0\n\n[[light]]\nkind = \"directional\"\nposition = [-3.0, 6.0, 2.0]\n\
         target = [0.0, 0.0, 0.0]\nextent = 4.0\n\n[light.shadow]\ntechnique = \"hard\"\n\
         cascades = 3\n\n[[object]]\nshape = \"plane\"\nsize = 18.0\nscale = {scale:?}\n\
         translate = {at:?}\n\n\
         [[object]]\nshape = \"box\"\nsize = 1.0\ntranslate = {at:?}\n"
    )
}

/// The cascades of a scene file cover the view distances of its geometry, computed here in f64
/// from the loaded vertices, whatever the camera's distance: a camera ~13,000 units from a
/// small scene (its depth range a two-thousandth of its distance), one at z = 10⁶ before
/// geometry reaching past the 10⁷ cascades cover (the range cut there), and one looking away
/// from everything (the cascades shade nothing, as one map would not). Geometry whose nearest
/// point lies past 10⁷ is refused naming the light's `cascades` key and its line.
#[test]
fn cascades_cover_the_scene_files_view_range() {
    use shadowgraph::low_level::scene::Scene;
    let path = std::path::Path::new("far.toml");
    let cases = [
        ([0.0, 3.0, 13000.0], [0.0; 3], 0.5, [0.0; 3], true),
        ([0.0, 0.0, 1e6], [0.0; 3], 1e6, [0.0, 0.0, -1e6], true),
        ([0.0, 3.0, 20.0], [0.0, 3.0, 40.0], 1.0, [0.0; 3], false),
    ];
    for (eye, target, scale, at, in_front) in cases {
        let text = far_scene(eye, target, scale, at);
        let scene = Scene::parse(path, &text).expect("the scene loads");
        let drawn = shadowgraph::low_level::render::drawn_lights(&scene)
            .unwrap_or_else(|e| panic!("camera at {eye:?}: {e}"));
        assert_eq!(drawn.groups.len(), 1);
        let g = drawn.gpu[0];
        let eye = DVec3::from_array(eye);
        let forward = (DVec3::from_array(target) - eye).normalize();
        let d: Vec<f64> = scene
            .objects
            .iter()
            .flat_map(|o| &o.mesh.positions)
            .map(|p| (p.as_dvec3() - eye).dot(forward))
            .collect();
        let lo = d.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let near = f64::from(g.cascade_near);
        let far = f64::from(g.cascade_far[0][2]);
        let last = f64::from(g.cascade_far[0][1]);
        assert!(near < last && last < far, "splits {near} {last} {far}");
        if in_front {
            // f32 rounding of distances near 10⁶: relative 1e-6.
            let tol = 1e-6 * hi.abs().max(1.0);
            assert!(
                (near - lo.max(0.05)).abs() <= tol,
                "near {near}, geometry from {lo}"
            );
            assert!(
                (far - hi.min(1e7)).abs() <= tol || far >= hi,
                "far {far}, geometry to {hi}"
            );
        } else {
            assert!(hi < 0.05, "the camera was to look away ({hi})");
            assert_eq!(near, 0.05f32 as f64);
        }
    }
    // Only a mesh's vertices reach past 10⁷ from a camera within 10⁶ (a built-in shape holds its
    // centre, within 10⁶): a triangle 1.05·10⁷ ahead.
    let dir = std::env::temp_dir().join(format!("shadowgraph-far-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("far.obj"),
        "v 0 0 -9.5e6\nv 1 0 -9.5e6\nv 0 1 -9.5e6\nf 1 2 3\n",
    )
    .expect("mesh");
    let text = far_scene([0.0, 0.0, 1e6], [0.0; 3], 1.0, [0.0; 3]);
    let at = text.find("[[object]]").expect("objects");
    let text = format!(
        "{}[[object]]\nshape = \"mesh\"\npath = \"far.obj\"\n",
        &text[..at]
    );
    let path = dir.join("far.toml");
    let scene = Scene::parse(&path, &text).expect("the scene loads");
    std::fs::remove_dir_all(&dir).ok();
    let line = text[..text.find("cascades = 3").expect("key")]
        .matches('\n')
        .count()
        + 1;
    match shadowgraph::low_level::render::drawn_lights(&scene) {
        Err(shadowgraph::Error::Scene {
            location, message, ..
        }) => {
            assert!(
                location.starts_with(&format!(":{line}:")),
                "{location}: {message}"
            );
            assert!(
                message.contains("light[0].shadow.cascades") && message.contains("camera.position"),
                "{message}"
            );
            assert!(!message.contains('\n'));
        }
        other => panic!("expected a scene error at line {line}, got {other:?}"),
    }
}
