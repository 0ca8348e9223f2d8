//! Every bundled scene renders with no NaN, and every covered pixel's visibility matches the
//! f64 references evaluated on the maps the GPU rasterized (read back with `aux`).

mod common;

use std::path::{Path, PathBuf};

use shadowgraph::low_level::cpu::{self, Map, Texels};
use shadowgraph::low_level::render::{DrawnLights, RenderOptions, Renderer, drawn_lights};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{Error, PcfKernel, Technique};

fn scenes() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<PathBuf> = [root.clone(), root.join("techniques")]
        .iter()
        .flat_map(|d| {
            std::fs::read_dir(d)
                .expect("scenes/")
                .map(|e| e.expect("entry").path())
        })
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 6, "bundled scenes missing: {v:?}");
    // `SHADOWGRAPH_SCENES=point` checks only the scenes whose path contains "point" (for
    // working on one technique; the suite checks them all).
    if let Ok(only) = std::env::var("SHADOWGRAPH_SCENES") {
        v.retain(|p| p.to_string_lossy().contains(&only));
        assert!(!v.is_empty(), "no bundled scene matches {only:?}");
    }
    v
}

/// Reference visibility of drawn light `k` (a scene light, or one of a cascaded light's
/// cascades) at pixel `px` and its tolerance, if robust (soft techniques: also where the
/// propagated errors could flip the blocker threshold).
fn pixel_reference(
    scene: &Scene,
    frame: &shadowgraph::low_level::render::Frame,
    moments: &[Texels],
    soft: Option<&common::soft::SoftInputs>,
    (drawn, k): (&DrawnLights, usize),
    px: usize,
) -> Option<(f64, f64)> {
    let light = &drawn.lights[k];
    let lg = drawn.gpu[k];
    let p = &frame.position[4 * px..4 * px + 3];
    let n = &frame.normal[4 * px..4 * px + 3];
    let p = glam::DVec3::new(p[0].into(), p[1].into(), p[2].into());
    let n = glam::DVec3::new(n[0].into(), n[1].into(), n[2].into()).normalize();
    // Facing away, the shading reads no map: 0 (`light_faces`). Within 10⁻⁵ of N·L = 0 the f32
    // dot product may take either sign.
    let ndl = cpu::light::facing(&lg, p, n);
    if ndl.abs() < 1e-5 {
        return None;
    }
    if ndl < 0.0 {
        return Some((0.0, 0.0));
    }
    if lg.kind == 2 && point_face_tie(&lg, p, n) {
        return None;
    }
    let mut s = cpu::light::sample(&lg, p, n);
    if lg.max_anisotropy > 0 {
        // The pixel's footprint, as the shading kernel derives it from the camera's rays.
        let rays = shadowgraph::low_level::render::CameraRays::new(&scene.camera, frame.width, frame.height);
        let (x, y) = (px as u32 % frame.width, px as u32 / frame.width);
        let eye = scene.camera.position.as_dvec3();
        let (dx, dy) = cpu::shade::pixel_differentials(eye, &rays, x, y, p, n);
        s.footprint = cpu::light::footprint(&lg, &s, p, n, dx, dy);
        // Where the tap count sits at a ceiling's step, f32 and f64 may take different counts.
        let ratio = cpu::mips::mip_taps(&lg, &s).ratio;
        if (ratio - ratio.round()).abs() < 1e-3 * ratio.max(1.0) {
            return None;
        }
    }
    // The map's width: a point light's atlas is three faces wide.
    let size = lg.map_size[0] as usize;
    let map = Map {
        size,
        texels: &frame.shade_maps[k].data,
    };
    let vis = |t: &cpu::light::LightSample| {
        if let Some(soft) = soft {
            return soft.reference(&lg, t);
        }
        if !t.inside {
            return 1.0;
        }
        match light.shadow.technique {
            Technique::Hard => cpu::vis_hard::vis_hard(&map, &lg, t),
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            } => cpu::vis_pcf::vis_pcf_hardware(&map, &lg, t),
            Technique::Pcf { .. } => cpu::vis_pcf::vis_pcf(&map, &lg, t),
            Technique::Pcss { .. } => cpu::vis_pcss::vis_pcss(&map, &lg, t),
            Technique::Smrt { .. } => cpu::vis_smrt::vis_smrt(&map, &lg, t),
            // The map holds the comparison depth (no bias; the far plane where no second
            // surface exists): tests/second_depth.rs checks it against the ray cast and the
            // kernel's reference.
            Technique::Midpoint { radius: 0, .. } | Technique::SecondDepth { radius: 0, .. } => {
                cpu::vis_hard::vis_hard(&map, &lg, t)
            }
            Technique::Midpoint { .. } | Technique::SecondDepth { .. } => {
                cpu::vis_pcf::vis_pcf(&map, &lg, t)
            }
            Technique::Vsm { .. } => cpu::vis_vsm::vis_vsm(moments, &lg, t),
            Technique::Evsm { .. } => cpu::vis_evsm::vis_evsm(moments, &lg, t),
            Technique::Esm { .. } => cpu::vis_esm::vis_esm(moments, &lg, t),
            Technique::Msm { .. } => cpu::vis_msm::vis_msm(moments, &lg, t),
            Technique::Csm { .. } => cpu::vis_csm::vis_csm(moments, &lg, t),
            Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
                unreachable!("soft techniques use SoftInputs")
            }
        }
    };
    common::robust(&s, size, vis)
        .and_then(|v| match soft {
            Some(soft) => soft.tolerance(&lg, &s, v).map(|t| (v, t)),
            None => Some((v, 0.0)),
        })
        .map(|(v, soft_tolerance)| {
            let tolerance = match light.shadow.technique {
                // Vulkan allows 8-bit bilinear weights: each of four may be off by 2⁻⁸.
                Technique::Pcf {
                    kernel: PcfKernel::Hardware,
                    ..
                } => 1.0 / 64.0,
                Technique::Vsm { .. } => common::vsm_tolerance(moments, &lg, &s),
                Technique::Evsm { .. } => common::evsm_tolerance(moments, &lg, &s),
                Technique::Esm { .. } if lg.filter_width > 0.0 => {
                    common::esm_sat_tolerance(moments, &lg, &s, v)
                }
                Technique::Esm { .. } => common::esm_tolerance(moments, &lg, &s, v),
                Technique::Msm { .. } => common::msm_tolerance(moments, &lg, &s),
                Technique::Csm { .. } => common::csm_tolerance(&lg),
                // Propagated through the chain (tests/common/soft.rs).
                Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
                    soft_tolerance
                }
                // Means of 0/1 taps in f32.
                _ => 1e-5,
            };
            // The receiver's UV comes out of f32 projections (a few 2⁻²⁴ each way), which moves the
            // filtered moments' bilinear weights; where neighbouring texels' moments differ by
            // orders of magnitude (EVSM's exp(40 z')), that is visible: add twice the reference's
            // change under ±4·2⁻²⁴ of UV.
            let tolerance = if light.shadow.technique.filter().is_some() {
                let d = 4.0 * 2f64.powi(-24);
                let spread = [[d, 0.0], [-d, 0.0], [0.0, d], [0.0, -d]]
                    .iter()
                    .map(|[du, dv]| {
                        let mut t = s;
                        t.uv = [s.uv[0] + du, s.uv[1] + dv];
                        (vis(&t) - v).abs()
                    })
                    .fold(0.0, f64::max);
                tolerance + 2.0 * spread
            } else {
                tolerance
            };
            // The GPU's footprint is a difference of f32 UVs times the map size: 2⁻²⁴ · 1024 ≈
            // 6·10⁻⁵ texels on an axis of a texel or more, so up to about 10⁻⁴ relative. It moves
            // the taps' level and spacing: add twice the reference's change under a ±2·10⁻⁴ scaling
            // of the footprint, and 8 f32 roundings per tap for the taps' running mean.
            let tolerance = if lg.max_anisotropy > 0 {
                let spread = [1.0 - 2e-4, 1.0 + 2e-4]
                    .iter()
                    .map(|k| {
                        let mut t = s;
                        t.footprint = s.footprint.map(|f| f * k);
                        (vis(&t) - v).abs()
                    })
                    .fold(0.0, f64::max);
                let taps = f64::from(cpu::mips::mip_taps(&lg, &s).count);
                // ESM's running log-sum-exp re-rounds the logarithm (|L| ≤ c) at every tap: 8 ULP
                // of c, relative in the visibility.
                let esm_logs = match light.shadow.technique {
                    Technique::Esm { exponent, .. } => {
                        8.0 * 2f64.powi(-23) * f64::from(exponent) * v
                    }
                    _ => 0.0,
                };
                tolerance + 2.0 * spread + taps * 8.0 * 2f64.powi(-23) * v + esm_logs
            } else {
                tolerance
            };
            (v, tolerance)
        })
}

/// Whether the receiver at `p` (normal `n`, moved by the normal offset) lies within 10⁻⁵
/// (relative) of a tie between a point light's faces, where the f32 shading and the f64
/// reference may pick different faces. Either face reads real geometry there (the guard band):
/// the two lookups differ by resampling, not by a seam; tests/point.rs checks those receivers
/// against the ray cast.
fn point_face_tie(lg: &shadowgraph::LightGpu, p: glam::DVec3, n: glam::DVec3) -> bool {
    let pos = glam::DVec3::new(
        lg.position[0].into(),
        lg.position[1].into(),
        lg.position[2].into(),
    );
    let mut a = (cpu::light::point_moved(lg, p, n) - pos).abs().to_array();
    a.sort_by(f64::total_cmp);
    a[2] - a[1] < 1e-5 * a[2]
}

#[test]
fn every_scene_renders_and_matches_the_references() {
    let g = common::gpu();
    let e_trig = common::soft_maps::trig_error(&g);
    let mut renderer = Renderer::new(&g.device);
    for path in scenes() {
        let scene = Scene::load(&path).expect("scene loads");
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &scene,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: false,
                },
            )
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let lights = scene.lights.len();
        let drawn = drawn_lights(&scene).expect("drawn lights");
        assert!(
            frame
                .visibility
                .iter()
                .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
            "{name}: visibility not in [0, 1]"
        );
        assert!(
            frame
                .position
                .iter()
                .chain(&frame.normal)
                .all(|v| v.is_finite()),
            "{name}: NaN in G-buffer"
        );
        assert!(
            frame.sanitized.is_empty(),
            "{name}: rasterized non-finite depth"
        );
        for li in 0..lights {
            if drawn.groups.iter().any(|g| g.light == li) {
                cascades::check_light(&scene, &frame, &drawn, li, e_trig);
                continue;
            }
            check_prefilter_chain(&scene, &frame, li);
            let sm = &frame.shade_maps[li];
            let level0 =
                Texels::from_f32(sm.width as usize, sm.height as usize, sm.channels, &sm.data);
            // With the mips filter the shading reads the chain: rebuild it in f64 from level 0
            // (the chain's own accuracy is tested in tests/prefilter.rs).
            let technique = scene.lights[li].shadow.technique;
            let moments = match technique.filter() {
                Some(shadowgraph::Filter::Mips { .. }) => {
                    cpu::mips::mip_chain(&level0, matches!(technique, Technique::Esm { .. }))
                }
                _ => vec![level0.clone()],
            };
            let soft = common::soft::SoftInputs::new(&scene.lights[li], &level0, e_trig);
            let (mut gpu_v, mut ref_v, mut tol, mut covered) =
                (Vec::new(), Vec::new(), Vec::new(), 0);
            for px in 0..(frame.width * frame.height) as usize {
                if frame.position[4 * px + 3] == 0.0 {
                    continue;
                }
                covered += 1;
                if let Some((r, t)) =
                    pixel_reference(&scene, &frame, &moments, soft.as_ref(), (&drawn, li), px)
                {
                    gpu_v.push(frame.visibility[px * lights + li]);
                    ref_v.push(r);
                    tol.push(t);
                }
            }
            let what = format!("{name} light {li}");
            assert!(
                gpu_v.len() * 10 >= covered * 9,
                "{what}: only {} of {covered} pixels robust",
                gpu_v.len()
            );
            let shadowed = ref_v.iter().filter(|&&v| v < 0.5).count();
            assert!(
                shadowed * 200 > ref_v.len(),
                "{what}: casts almost no shadow ({shadowed} pixels)"
            );
            common::assert_within(&what, &gpu_v, &ref_v, &tol);
        }
    }
}

/// The filtered map the shading read equals the f64 encode and blur of the linear map the GPU
/// produced: f32 storage 1e-6 (as in tests/prefilter.rs), widened by SPIR-V's (3 + 2|x|)-ULP
/// `exp` for the exponential encodings; f16 storage 3 · 2⁻¹⁰ relative.
fn check_prefilter_chain(scene: &Scene, frame: &shadowgraph::low_level::render::Frame, li: usize) {
    use shadowgraph::{Filter, Storage};
    let (encoded, channels, filter, storage, log_space, rtol) =
        match scene.lights[li].shadow.technique {
            Technique::Vsm { prefilter, .. } => (
                Box::new(|t: &Texels| cpu::vsm::vsm(t)) as Box<dyn Fn(&Texels) -> Texels>,
                2,
                prefilter.filter,
                prefilter.storage,
                false,
                1e-6,
            ),
            Technique::Evsm {
                prefilter,
                four,
                exp_pos,
                exp_neg,
                ..
            } => {
                let f = move |t: &Texels| cpu::evsm::evsm(t, exp_pos.into(), exp_neg.into());
                let rtol = 4.0 * (3.0 + 4.0 * f64::from(exp_pos.max(exp_neg))) * 2f64.powi(-23);
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    if four { 4 } else { 2 },
                    prefilter.filter,
                    prefilter.storage,
                    false,
                    rtol,
                )
            }
            Technique::Esm {
                filter: filter @ Filter::Sat { .. },
                exponent,
            } => {
                // Stored linearly for the table: exp(c (z − 1)), SPIR-V's exp to (3 + 2|x|) ULP.
                let f = move |t: &Texels| cpu::esm::esm_linear(t, exponent.into());
                let rtol = 4.0 * (3.0 + 2.0 * f64::from(exponent)) * 2f64.powi(-23);
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    1,
                    filter,
                    Storage::F32,
                    false,
                    rtol,
                )
            }
            Technique::Esm { filter, exponent } => {
                let f = move |t: &Texels| cpu::esm::esm(t, exponent.into());
                // Log-space blur: exp and log of each tap, absolute error relative to |c·z|.
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    1,
                    filter,
                    Storage::F32,
                    true,
                    1e-5,
                )
            }
            Technique::Msm { prefilter, .. } => {
                let quantized =
                    shadowgraph::low_level::technique::msm_quantized(&scene.lights[li].shadow.technique);
                let f = move |t: &Texels| cpu::msm::msm(t, quantized);
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    4,
                    prefilter.filter,
                    prefilter.storage,
                    false,
                    1e-6,
                )
            }
            Technique::Csm {
                prefilter, terms, ..
            } => {
                let f = move |t: &Texels| cpu::csm::csm(t, terms);
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    2 * terms as usize,
                    prefilter.filter,
                    prefilter.storage,
                    false,
                    1e-6,
                )
            }
            // Soft techniques: the unfiltered representation, through a table.
            Technique::Vssm { soft, .. } => (
                Box::new(|t: &Texels| cpu::vsm::vsm(t)) as Box<dyn Fn(&Texels) -> Texels>,
                2,
                Filter::None,
                soft.storage,
                false,
                1e-6,
            ),
            Technique::MsmSoft { soft, .. } => {
                let quantized =
                    shadowgraph::low_level::technique::msm_quantized(&scene.lights[li].shadow.technique);
                let f = move |t: &Texels| cpu::msm::msm(t, quantized);
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    4,
                    Filter::None,
                    soft.storage,
                    false,
                    1e-6,
                )
            }
            // The CSM basis (2M channels) then the search's: the power moments (4) or the
            // CSM-Z basis (2M + 1).
            Technique::Cssm {
                soft,
                terms,
                search,
                ..
            } => {
                let f = move |t: &Texels| {
                    let a = cpu::csm::csm(t, terms);
                    let b = match search {
                        shadowgraph::CssmSearch::Moments => cpu::msm::msm(t, true),
                        shadowgraph::CssmSearch::CsmZ => cpu::csm_z::csm_z(t, terms),
                    };
                    let data = a
                        .data
                        .chunks(a.channels)
                        .zip(b.data.chunks(b.channels))
                        .flat_map(|(x, y)| x.iter().chain(y).copied())
                        .collect();
                    Texels {
                        channels: a.channels + b.channels,
                        data,
                        ..a
                    }
                };
                let search_channels = match search {
                    shadowgraph::CssmSearch::Moments => 4,
                    shadowgraph::CssmSearch::CsmZ => 2 * terms as usize + 1,
                };
                (
                    Box::new(f) as Box<dyn Fn(&Texels) -> Texels>,
                    2 * terms as usize + search_channels,
                    Filter::None,
                    soft.storage,
                    false,
                    1e-6,
                )
            }
            _ => return,
        };
    let Some(linear) = &frame.linear_maps[li] else {
        panic!("light {li}: no linear map")
    };
    let (w, h) = (linear.width as usize, linear.height as usize);
    let mut expected = encoded(&Texels::from_f32(w, h, 1, &linear.data));
    if let Filter::Blur {
        radius,
        sigma,
        kernel,
    } = filter
    {
        expected = cpu::blur::blur_mode(&expected, radius.into(), sigma.into(), kernel, log_space);
    }
    let keep: Vec<f64> = expected
        .data
        .chunks(expected.channels)
        .flat_map(|c| c[..channels].to_vec())
        .collect();
    let got = &frame.shade_maps[li];
    let got: Vec<f32> = match scene.lights[li].shadow.technique {
        // The tables' padding channels dropped.
        Technique::Cssm { .. } => {
            let map = Texels::from_f32(
                got.width as usize,
                got.height as usize,
                got.channels,
                &got.data,
            );
            let (a, b) = common::soft::split_cssm(&scene.lights[li], &map);
            a.data
                .chunks(a.channels)
                .zip(b.data.chunks(b.channels))
                .flat_map(|(x, y)| x.iter().chain(y).map(|&v| v as f32))
                .collect()
        }
        _ => got
            .data
            .chunks(got.channels)
            .flat_map(|c| c[..channels].to_vec())
            .collect(),
    };
    let (atol, rtol) = match storage {
        Storage::F32 => (1e-6, rtol),
        Storage::F16 => (1e-4, 3.0 * 2f64.powi(-10)),
        // Rounding to 16 bits (2⁻¹⁷), after the quantization matrix's f32 products (entries up
        // to 82: about 2·10⁻⁵).
        Storage::Unorm16 => (6e-5, 0.0),
    };
    // CSM: Vulkan specifies sin/cos to 2⁻¹¹ absolute on [−π, π] (CSM-Z: times z ≤ 1).
    let technique = &scene.lights[li].shadow.technique;
    let atol = match technique {
        Technique::Csm { .. } | Technique::Cssm { .. } => atol + 2f64.powi(-11),
        // Quantized moments (soft MSM quantizes whatever the storage): four f32 products with
        // the quantization matrix's entries (up to 82) and their sum, 2⁻²⁴ of 82 each, before
        // the storage rounds: 4 · 82 · 2⁻²⁴ ≈ 2·10⁻⁵.
        Technique::Msm { .. } | Technique::MsmSoft { .. }
            if shadowgraph::low_level::technique::msm_quantized(technique) && storage == Storage::F32 =>
        {
            atol + 4.0 * 82.0 * 2f64.powi(-24)
        }
        _ => atol,
    };
    let what = format!("light {li} filtered map");
    let coding = shadowgraph::low_level::technique::sat_coding(&scene.lights[li]).expect("valid coding");
    match coding {
        // The table's texels decode to the representation quantized to the coding's step:
        // ½ / scale per channel, plus f32 rounding of the scaled value (2⁻²⁴ of it, twice).
        Some(c) if c.variant == shadowgraph::SatVariant::Fixed => {
            for ch in 0..channels {
                let pick = |v: &[f32]| -> Vec<f32> {
                    v.iter().skip(ch).step_by(channels).copied().collect()
                };
                let want: Vec<f64> = keep.iter().skip(ch).step_by(channels).copied().collect();
                let k = ch % 4;
                let step = 0.5 / f64::from(c.scale[k]) * (1.0 + 2f64.powi(-20));
                common::assert_close(
                    &format!("{what} channel {ch}"),
                    &pick(&got),
                    &want,
                    atol + step,
                    rtol + 2f64.powi(-22),
                );
            }
        }
        // The f32 table's texels are differences of sums: their error is the stability
        // report's subject (tests/stability.rs); only finiteness is checked here.
        Some(_) => assert!(got.iter().all(|v| v.is_finite()), "{what}: non-finite"),
        None => common::assert_close(&what, &got, &keep, atol, rtol),
    }
}

#[test]
fn repeated_renders_reuse_pipelines_and_textures() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let scene =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_lights.toml")).unwrap();
    let mut counts = Vec::new();
    for _ in 0..4 {
        renderer
            .render(&g.device, &g.queue, &scene, RenderOptions::default())
            .unwrap();
        counts.push((
            renderer.executor.texture_count(),
            renderer.executor.kernels.len(),
        ));
    }
    assert!(
        counts.windows(2).all(|w| w[0] == w[1]),
        "pool or cache grew: {counts:?}"
    );
}

#[test]
fn shadow_map_past_the_device_limit_is_a_clear_error() {
    let g = common::gpu();
    let max = g.device.limits().max_texture_dimension_2d;
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_on_plane.toml"),
    )
    .unwrap();
    let mut scene = Scene::parse(Path::new("limit.toml"), &text).unwrap();
    scene.lights[0].shadow_map = max + 1;
    let mut renderer = Renderer::new(&g.device);
    match renderer.render(&g.device, &g.queue, &scene, RenderOptions::default()) {
        Err(e @ Error::SceneLimit { .. }) => {
            let m = e.to_string();
            assert!(
                m.starts_with("limit.toml:")
                    && m.contains("light[0].shadow_map")
                    && m.contains(&max.to_string()),
                "{m}"
            );
        }
        Err(e) => panic!("expected a limit error, got {e}"),
        Ok(_) => panic!(
            "a {}² shadow map rendered on a device limited to {max}",
            max + 1
        ),
    }
}

#[test]
fn plan_contains_only_what_techniques_need() {
    let two =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_lights.toml")).unwrap();
    let sp = shadowgraph::low_level::render::plan_lights(&two.lights).unwrap();
    for (i, l) in two.lights.iter().enumerate() {
        let steps: Vec<&str> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect();
        let hardware = matches!(
            l.shadow.technique,
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            }
        );
        // The hardware comparison sampler reads the rasterized depth: no kernel at all.
        assert_eq!(
            steps,
            if hardware { vec![] } else { vec!["linearize"] },
            "light {i}"
        );
    }
}

/// The blocker kernels are planned only for lights that ask for soft shadows: every bundled
/// and technique scene's lights, and one plan mixing CSM, CSSM, VSM, VSSM and MSM lights.
/// A CSSM light plans the tables of its ⌈M/2⌉ basis maps and ⌈(2M + 1)/4⌉ CSM-Z maps as one
/// layered table (2 + ⌈maps / 4⌉ passes, the maps never stored), and nothing else; VSSM and soft MSM plan exactly the
/// encoding of their hard counterparts and one table.
#[test]
fn blocker_kernels_are_planned_only_for_soft_lights() {
    let mut lights: Vec<shadowgraph::Light> = Vec::new();
    for path in scenes() {
        lights.extend(Scene::load(&path).expect("scene").lights);
    }
    let soft_scene = |name: &str| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/techniques/{name}"));
        Scene::load(path).expect("scene").lights.remove(0)
    };
    let mut csm = soft_scene("csm_sat.toml");
    csm.shadow_map = 64;
    lights.extend([
        csm,
        soft_scene("cssm.toml"),
        soft_scene("vsm_sat.toml"),
        soft_scene("vssm.toml"),
        soft_scene("msm_sat.toml"),
        soft_scene("msm_soft.toml"),
    ]);
    let sp = shadowgraph::low_level::render::plan_lights(&lights).expect("plan");
    for (i, l) in lights.iter().enumerate() {
        let mut kernels: Vec<&str> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect();
        let what = format!("light {i} ({})", l.shadow.technique.name());
        // CSM-Z maps or their tables written (`light{i}.csm_z<k>` or `light{i}.csm_z<k>.sat`,
        // tables interleaved in one texture by the names of the tables it holds).
        let written: Vec<String> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .flat_map(|s| &s.node.outputs)
            .flat_map(|(_, r)| match sp.plan.resource(r) {
                Some(p) if !p.resource.layers.is_empty() => p.resource.layers.clone(),
                _ => vec![r.clone()],
            })
            .collect();
        let blocker = written
            .iter()
            .filter(|r| {
                let r = r.strip_suffix(".sat").unwrap_or(r);
                r.rsplit('.')
                    .next()
                    .is_some_and(|n| n.starts_with("csm_z") || n == "csm_moments")
            })
            .count();
        let expected: Option<Vec<&str>> = match l.shadow.technique {
            Technique::Cssm {
                soft,
                terms,
                search,
                ..
            } => {
                let basis = shadowgraph::low_level::technique::csm_maps(terms) as usize;
                let z = match search {
                    shadowgraph::CssmSearch::CsmZ => {
                        shadowgraph::low_level::technique::csm_z_maps(terms) as usize
                    }
                    shadowgraph::CssmSearch::Moments => 1,
                };
                assert_eq!(blocker, z, "{what}: the blocker search's tables");
                // One layered table (`sat::layers`): the edges of every layer from the depth,
                // the carries, and four textures a dispatch, fixed-point tables as many a
                // texture as fit; no basis map stored.
                let per = shadowgraph::low_level::sat::layers::LAYERED_SAT_OUTPUTS as usize;
                let tables = (basis + z) as u32;
                let interleave =
                    shadowgraph::low_level::technique::basis_interleave(l.map_dims().0, tables, soft.sums);
                let textures = (basis + z).div_ceil(interleave as usize);
                let (sums, tiles) = match soft.sums {
                    shadowgraph::SatVariant::Fixed => ("csm_sat_tile_sums", "csm_sat_tiles"),
                    shadowgraph::SatVariant::Float => {
                        ("csm_sat_tile_sums_f32", "csm_sat_tiles_f32")
                    }
                };
                let mut v = vec![sums, "sat_carries"];
                v.extend(vec![tiles; textures.div_ceil(per)]);
                Some(v)
            }
            // The moments computed in the table's own tile passes (one layer, no map).
            Technique::Vssm { soft, .. } => Some(match soft.sums {
                shadowgraph::SatVariant::Fixed => {
                    vec!["vsm_sat_tile_sums", "sat_carries", "vsm_sat_tiles"]
                }
                shadowgraph::SatVariant::Float => {
                    vec!["vsm_sat_tile_sums_f32", "sat_carries", "vsm_sat_tiles_f32"]
                }
            }),
            Technique::MsmSoft { soft, .. } => Some(match soft.sums {
                shadowgraph::SatVariant::Fixed => {
                    vec!["msm_sat_tile_sums", "sat_carries", "msm_sat_tiles"]
                }
                shadowgraph::SatVariant::Float => {
                    vec!["msm_sat_tile_sums_f32", "sat_carries", "msm_sat_tiles_f32"]
                }
            }),
            _ => None,
        };
        match expected {
            Some(mut e) => {
                kernels.sort_unstable();
                e.sort_unstable();
                assert_eq!(kernels, e, "{what}");
            }
            None => assert_eq!(blocker, 0, "{what} plans blocker kernels"),
        }
    }
    assert!(
        lights
            .iter()
            .any(|l| matches!(l.shadow.technique, Technique::Csm { .. }))
            && lights
                .iter()
                .any(|l| matches!(l.shadow.technique, Technique::Cssm { .. })),
        "the mixed plan lacks CSM or CSSM"
    );
}

/// Every technique (with each filter; the soft ones on a light 0.3 units wide where the scene's
/// light has no size) on every bundled scene, at a reduced size: no NaN or Inf,
/// visibility in [0, 1] and some shadow cast (some pixel below 0.95: a thin pole on a 512² map
/// seen in 120×90 pixels casts little).
#[test]
fn every_technique_renders_every_bundled_scene() {
    use shadowgraph::{BlurKernel, Filter, Storage, StorageFilter};
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let pre = |storage, filter| StorageFilter { storage, filter };
    let sat = Filter::Sat {
        width: 4.5,
        variant: shadowgraph::SatVariant::Fixed,
    };
    let sat_float = Filter::Sat {
        width: 2.0,
        variant: shadowgraph::SatVariant::Float,
    };
    let sat_limit = shadowgraph::low_level::technique::sat_exponent_limit(&sat, false).expect("sat limit");
    let soft = |storage, sums| shadowgraph::Soft {
        storage,
        sums,
        max_search: shadowgraph::low_level::model::DEFAULT_MAX_SEARCH,
    };
    let techniques = [
        Technique::Hard,
        Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Hardware,
        },
        Technique::Pcss {
            blocker_samples: 8,
            filter_samples: 16,
            max_search: 0.05,
        },
        Technique::Vsm {
            prefilter: pre(
                Storage::F16,
                Filter::Mips {
                    width: 2.0,
                    max_anisotropy: 0,
                },
            ),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Evsm {
            prefilter: pre(Storage::F32, blur),
            four: true,
            exp_pos: 40.0,
            exp_neg: 5.0,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        // Two f16 moments packed in r32uint words, blurred (the fused kernel) and read by the
        // shading through `sample_map_packed`.
        Technique::Evsm {
            prefilter: pre(Storage::F16, blur),
            four: false,
            exp_pos: 5.0,
            exp_neg: 5.0,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        Technique::Esm {
            filter: Filter::Mips {
                width: 3.0,
                max_anisotropy: 0,
            },
            exponent: 80.0,
        },
        Technique::Msm {
            prefilter: pre(Storage::F32, blur),
            hausdorff: false,
            moment_bias: 1e-5,
            bleed: 0.0,
        },
        Technique::Msm {
            prefilter: pre(
                Storage::F16,
                Filter::Mips {
                    width: 1.5,
                    max_anisotropy: 0,
                },
            ),
            hausdorff: true,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
        Technique::Csm {
            prefilter: pre(Storage::F32, blur),
            terms: 9,
            attenuation: 1.0,
            offset: 0.05,
            scale: 2.0,
        },
        Technique::Vsm {
            prefilter: pre(Storage::F32, sat_float),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Evsm {
            prefilter: pre(Storage::F16, sat),
            four: false,
            exp_pos: sat_limit,
            exp_neg: sat_limit,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        Technique::Esm {
            filter: sat,
            exponent: 4.0 * sat_limit,
        },
        Technique::Msm {
            prefilter: pre(Storage::F16, sat),
            hausdorff: false,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
        Technique::Csm {
            prefilter: pre(Storage::F32, sat),
            terms: 5,
            attenuation: 1.0,
            offset: 0.1,
            scale: 2.0,
        },
        Technique::Cssm {
            soft: soft(Storage::F32, shadowgraph::SatVariant::Fixed),
            terms: 3,
            attenuation: 1.0,
            offset: 0.5 / 3.0,
            scale: 2.0,
            sharpen: shadowgraph::low_level::model::DEFAULT_SHARPEN,
            sharpen_falloff: shadowgraph::low_level::model::DEFAULT_SHARPEN_FALLOFF,
            search: shadowgraph::CssmSearch::CsmZ,
            resolve: shadowgraph::CssmResolve::TwoDepth,
        },
        Technique::Vssm {
            soft: soft(Storage::F16, shadowgraph::SatVariant::Float),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::MsmSoft {
            soft: soft(Storage::F16, shadowgraph::SatVariant::Fixed),
            hausdorff: false,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
    ];
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for entry in std::fs::read_dir(&root).expect("scenes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let base = Scene::load(&path).expect("scene");
        for t in techniques {
            let mut scene = base.clone();
            (scene.width, scene.height) = (120, 90);
            for l in &mut scene.lights {
                l.shadow.technique = t;
                // A technique that refuses cascades (`params::cascade_support`): one map.
                if shadowgraph::low_level::technique::params::cascade_support(&t).is_err() {
                    l.shadow.cascades = shadowgraph::Cascades::SINGLE;
                }
                l.shadow_map = l.shadow_map.min(512);
                // PCSS and the soft techniques model an area light (scenes require a size).
                if t.soft().is_some() && l.size <= 0.0 {
                    l.size = 0.3;
                }
            }
            let what = format!("{} with {}", path.display(), t.name());
            let frame = renderer
                .render(
                    &g.device,
                    &g.queue,
                    &scene,
                    RenderOptions {
                        aux: false,
                        repeat: 1,
                        dump: false,
                    },
                )
                .unwrap_or_else(|e| panic!("{what}: {e}"));
            assert!(
                frame
                    .visibility
                    .iter()
                    .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
                "{what}: visibility not finite in [0, 1]"
            );
            assert!(
                frame.visibility.iter().any(|&v| v < 0.95),
                "{what}: no shadow at all"
            );
        }
    }
}

/// A cascaded directional light: every pixel's visibility against the f64 pick of its cascade
/// (`cpu::cascade`) and the per-cascade references on the maps the GPU made, blended in f64.
mod cascades {
    use super::*;

    /// The maps a cascade's visibility reads (with the mips filter, the chain rebuilt in f64).
    fn moments(frame: &shadowgraph::low_level::render::Frame, technique: Technique, k: usize) -> Vec<Texels> {
        let sm = &frame.shade_maps[k];
        let level0 = Texels::from_f32(sm.width as usize, sm.height as usize, sm.channels, &sm.data);
        match technique.filter() {
            Some(shadowgraph::Filter::Mips { .. }) => {
                cpu::mips::mip_chain(&level0, matches!(technique, Technique::Esm { .. }))
            }
            _ => vec![level0],
        }
    }

    /// Checks light `li`'s visibility at every robust covered pixel. Tolerance: each cascade's
    /// own (as for a single map), blended with the pick's weights, plus the f32 error of the
    /// blend weight — the view distance's rounding, 8 · 2⁻²⁴ of the distances involved, over
    /// the band — times the two cascades' difference. Pixels within that rounding of a split
    /// (where f32 may pick the other cascade) are skipped; at least 1% of the checked pixels
    /// lie inside a blend band.
    pub fn check_light(
        scene: &Scene,
        frame: &shadowgraph::low_level::render::Frame,
        drawn: &DrawnLights,
        li: usize,
        e_trig: f64,
    ) {
        let group = drawn
            .groups
            .iter()
            .find(|g| g.light == li)
            .expect("cascaded");
        let technique = scene.lights[li].shadow.technique;
        let maps: Vec<Vec<Texels>> = (0..group.count)
            .map(|c| moments(frame, technique, group.index(c)))
            .collect();
        // A soft technique's inputs per cascade: its own table and `max_search`.
        let softs: Vec<Option<common::soft::SoftInputs>> = (0..group.count)
            .map(|c| {
                common::soft::SoftInputs::new(&drawn.lights[group.index(c)], &maps[c][0], e_trig)
            })
            .collect();
        let lg = drawn.gpu[li];
        let lights = scene.lights.len();
        let (mut gpu_v, mut ref_v, mut tol, mut covered, mut banded) =
            (Vec::new(), Vec::new(), Vec::new(), 0, 0);
        let mut used = vec![0usize; group.count];
        for px in 0..(frame.width * frame.height) as usize {
            if frame.position[4 * px + 3] == 0.0 {
                continue;
            }
            covered += 1;
            let q = &frame.position[4 * px..4 * px + 3];
            let p = glam::DVec3::new(q[0].into(), q[1].into(), q[2].into());
            let pick = cpu::cascade::pick(&lg, p);
            let eye = glam::DVec3::from_array(lg.cascade_eye.map(f64::from));
            let rounding =
                8.0 * 2f64.powi(-24) * (pick.distance.abs() + pick.far + p.length() + eye.length());
            // Within f32's rounding of a split the GPU may pick the neighbour: skipped.
            let split_near = (0..group.count - 1)
                .any(|c| (pick.distance - cpu::cascade::cascade_far_of(&lg, c)).abs() < rounding);
            if split_near {
                continue;
            }
            let reference = |c: usize| {
                let soft = softs[c].as_ref();
                pixel_reference(scene, frame, &maps[c], soft, (drawn, group.index(c)), px)
            };
            let Some((v0, t0)) = reference(pick.index) else {
                continue;
            };
            let in_band = pick.band > 0.0 && pick.distance > pick.far - pick.band - rounding;
            let (v, t) = if in_band {
                let Some((v1, t1)) = reference(pick.index + 1) else {
                    continue;
                };
                banded += 1;
                let dt = rounding / pick.band;
                let w = pick.blend;
                (
                    v0 + (v1 - v0) * w,
                    (1.0 - w) * t0 + w * t1 + (v1 - v0).abs() * dt + 1e-6,
                )
            } else {
                (v0, t0)
            };
            used[pick.index] += 1;
            gpu_v.push(frame.visibility[px * lights + li]);
            ref_v.push(v);
            tol.push(t);
        }
        let what = format!(
            "light {li} ({}) in {} cascades",
            technique.name(),
            group.count
        );
        assert!(
            gpu_v.len() * 10 >= covered * 9,
            "{what}: only {} of {covered} pixels robust",
            gpu_v.len()
        );
        assert!(
            used.iter().all(|&n| n > 0),
            "{what}: a cascade shades no pixel ({used:?})"
        );
        assert!(
            banded * 100 >= gpu_v.len(),
            "{what}: only {banded} of {} pixels in a blend band",
            gpu_v.len()
        );
        let shadowed = ref_v.iter().filter(|&&v| v < 0.5).count();
        assert!(
            shadowed * 200 > ref_v.len(),
            "{what}: casts almost no shadow ({shadowed} pixels)"
        );
        common::assert_within(&what, &gpu_v, &ref_v, &tol);
    }
}

/// Technique `name` with its registry defaults.
fn registered(name: &str) -> Technique {
    shadowgraph::low_level::technique::named(name, &[]).unwrap_or_else(|| panic!("{name} is registered"))
}

/// The cascaded street view with the other techniques that take cascades: each cascade's map
/// prefiltered by the same graph (hard; VSM blurred; MSM through a float table; ESM mipmapped,
/// isotropic and anisotropic;
/// PCSS and the soft techniques, each cascade with its guard band and `max_search`; the
/// second-depth techniques, each cascade peeled), every pixel against the f64 pick and
/// references (`cascades::check_light`).
#[test]
fn cascaded_techniques_match_the_references() {
    use shadowgraph::{BlurKernel, Filter, Storage, StorageFilter};
    let g = common::gpu();
    let e_trig = common::soft_maps::trig_error(&g);
    let mut renderer = Renderer::new(&g.device);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let mut scene = Scene::load(&path).expect("scene loads");
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let table = Filter::Sat {
        width: 3.0,
        variant: shadowgraph::SatVariant::Float,
    };
    let pre = |storage, filter| StorageFilter { storage, filter };
    for t in [
        Technique::Hard,
        Technique::Vsm {
            prefilter: pre(Storage::F32, blur),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Msm {
            prefilter: pre(Storage::F32, table),
            hausdorff: false,
            moment_bias: 3e-5,
            bleed: 0.0,
        },
        Technique::Esm {
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 0,
            },
            exponent: 40.0,
        },
        // Anisotropic: each cascade's lookups follow the pixel's footprint in its own map.
        Technique::Esm {
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 8,
            },
            exponent: 40.0,
        },
        registered("pcss"),
        registered("vssm"),
        registered("msm_soft"),
        registered("cssm"),
        registered("midpoint"),
        registered("second_depth"),
    ] {
        scene.lights[0].shadow.technique = t;
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &scene,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: false,
                },
            )
            .unwrap_or_else(|e| panic!("{}: {e}", t.name()));
        let drawn = drawn_lights(&scene).expect("drawn lights");
        assert_eq!(drawn.lights.len(), 4, "{}: four cascades drawn", t.name());
        cascades::check_light(&scene, &frame, &drawn, 0, e_trig);
    }
}
