//! Every bundled scene against the f64 references, pixel by pixel, and each light's prefilter chain
//! rebuilt in f64.

use super::*;

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
            // (the chain's own accuracy is tested in tests/prefilter/).
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
/// produced: f32 storage 1e-6 (as in tests/prefilter/), widened by SPIR-V's (3 + 2|x|)-ULP
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
                let quantized = shadowgraph::low_level::technique::msm_quantized(
                    &scene.lights[li].shadow.technique,
                );
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
                let quantized = shadowgraph::low_level::technique::msm_quantized(
                    &scene.lights[li].shadow.technique,
                );
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
            if shadowgraph::low_level::technique::msm_quantized(technique)
                && storage == Storage::F32 =>
        {
            atol + 4.0 * 82.0 * 2f64.powi(-24)
        }
        _ => atol,
    };
    let what = format!("light {li} filtered map");
    let coding =
        shadowgraph::low_level::technique::sat_coding(&scene.lights[li]).expect("valid coding");
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
