//! The prefiltered techniques on filtered maps against their f64 references.

use super::*;

/// A prefiltered technique on a map the CPU encoded (and blurred) from a random blocky linear
/// map, at 3000 receivers. With the `mips` filter the CPU also builds the chain (in f64, then
/// rounded to f32 as uploaded). Maps of more than four channels (CSM) are split into
/// four-channel textures as the technique binds them. These techniques are continuous in the
/// receiver (filtered values, no comparisons), so every point counts, each with its propagated
/// f32 tolerance.
fn check_prefiltered(
    technique: Technique,
    encode: impl Fn(&cpu::Texels) -> cpu::Texels,
    visibility: impl Fn(&[cpu::Texels], &LightGpu, &cpu::light::LightSample) -> f64,
    tolerance: impl Fn(&[cpu::Texels], &LightGpu, &cpu::light::LightSample, f64) -> f64,
    seed: u64,
) {
    let g = common::gpu();
    let mut rng = common::rng(seed);
    for kind in [DIR, SPOT] {
        let l = light(kind, technique);
        let linear = common::blocky_map(&mut rng, MAP);
        let encoded = encode(&cpu::Texels::from_f32(MAP, MAP, 1, &linear));
        let round = |t: &cpu::Texels| {
            let data: Vec<f32> = t.data.iter().map(|&v| v as f32).collect();
            cpu::Texels::from_f32(t.width, t.height, t.channels, &data)
        };
        let encoded = round(&encoded);
        let levels: Vec<cpu::Texels> = match technique.filter() {
            Some(shadowgraph::Filter::Mips { .. }) => {
                let log = matches!(technique, Technique::Esm { .. });
                cpu::mips::mip_chain(&encoded, log)
                    .iter()
                    .map(round)
                    .collect()
            }
            _ => vec![encoded.clone()],
        };
        // Split the channels into the textures the technique binds.
        let channels = encoded.channels;
        let mut uploads: Vec<(wgpu::TextureFormat, Vec<f32>)> = Vec::new();
        for first in (0..channels).step_by(4) {
            let n = (channels - first).min(4);
            let format = match n {
                1 => wgpu::TextureFormat::R32Float,
                2 => wgpu::TextureFormat::Rg32Float,
                _ => wgpu::TextureFormat::Rgba32Float,
            };
            let width = if n == 3 { 4 } else { n };
            let mut data = Vec::new();
            for level in &levels {
                for texel in level.data.chunks(channels) {
                    for c in 0..width {
                        data.push(texel.get(first + c).map_or(0.0, |&v| v as f32));
                    }
                }
            }
            uploads.push((format, data));
        }
        let maps: Vec<MapData> = uploads
            .iter()
            .map(|(format, data)| MapData {
                size: MAP as u32,
                format: *format,
                mips: levels.len() as u32,
                data,
            })
            .collect();
        let points: Vec<(Vec3, Vec3)> = (0..6000).map(|_| point(&l, &mut rng)).collect();
        let mut renderer = Renderer::new(&g.device);
        let vis = visibility_at(
            &mut renderer,
            &g.device,
            &g.queue,
            std::slice::from_ref(&l),
            &maps,
            &points,
        )
        .expect("visibility_at");
        let lg = LightGpu::new(&l);
        let (mut reference, mut tol) = (Vec::new(), Vec::new());
        for (p, n) in &points {
            let s = cpu::light::sample(&lg, p.as_dvec3(), n.as_dvec3());
            let v = if s.inside {
                visibility(&levels, &lg, &s)
            } else {
                1.0
            };
            reference.push(v);
            tol.push(if s.inside {
                // Plus the receiver UV's f32 error (±4·2⁻²⁴), which moves the bilinear weights
                // between texels whose exponential moments differ by orders of magnitude.
                let d = 4.0 * 2f64.powi(-24);
                let spread = [[d, 0.0], [-d, 0.0], [0.0, d], [0.0, -d]]
                    .iter()
                    .map(|[du, dv]| {
                        let mut t = s;
                        t.uv = [s.uv[0] + du, s.uv[1] + dv];
                        (visibility(&levels, &lg, &t) - v).abs()
                    })
                    .fold(0.0, f64::max);
                tolerance(&levels, &lg, &s, v) + 2.0 * spread
            } else {
                0.0
            });
        }
        let partial = reference.iter().filter(|&&v| v > 0.01 && v < 0.99).count();
        assert!(
            partial > 100,
            "{technique:?} {kind:?}: only {partial} penumbra points"
        );
        common::assert_within(&format!("{technique:?} {kind:?}"), &vis, &reference, &tol);
    }
}

fn blurred(t: &cpu::Texels, log_space: bool) -> cpu::Texels {
    cpu::blur::blur_mode(t, 2.0, 1.0, shadowgraph::BlurKernel::Gaussian, log_space)
}

fn prefilter() -> shadowgraph::StorageFilter {
    use shadowgraph::{BlurKernel, Filter, Storage, StorageFilter};
    StorageFilter {
        storage: Storage::F32,
        filter: Filter::Blur {
            radius: 2.0,
            sigma: 1.0,
            kernel: BlurKernel::Gaussian,
        },
    }
}

#[test]
fn vsm_matches_reference_on_filtered_moments() {
    let t = Technique::Vsm {
        prefilter: prefilter(),
        bleed: 0.2,
        min_variance: 1e-5,
    };
    check_prefiltered(
        t,
        |lin| blurred(&cpu::vsm::vsm(lin), false),
        cpu::vis_vsm::vis_vsm,
        |m, l, s, _| common::vsm_tolerance(m, l, s),
        50,
    );
}

#[test]
fn evsm2_and_evsm4_match_reference() {
    for (four, seed) in [(false, 60), (true, 61)] {
        let t = Technique::Evsm {
            prefilter: prefilter(),
            four,
            exp_pos: 40.0,
            exp_neg: 5.0,
            bleed: 0.1,
            min_variance: 1e-4,
        };
        let channels = if four { 4 } else { 2 };
        check_prefiltered(
            t,
            move |lin| {
                let e = blurred(&cpu::evsm::evsm(lin, 40.0, 5.0), false);
                let data = e
                    .data
                    .chunks(4)
                    .flat_map(|c| c[..channels].to_vec())
                    .collect();
                cpu::Texels {
                    channels,
                    data,
                    ..e
                }
            },
            cpu::vis_evsm::vis_evsm,
            |m, l, s, _| common::evsm_tolerance(m, l, s),
            seed,
        );
    }
}

#[test]
fn esm_matches_reference_in_log_space() {
    use shadowgraph::{BlurKernel, Filter};
    let t = Technique::Esm {
        filter: Filter::Blur {
            radius: 2.0,
            sigma: 1.0,
            kernel: BlurKernel::Gaussian,
        },
        exponent: 80.0,
    };
    check_prefiltered(
        t,
        |lin| blurred(&cpu::esm::esm(lin, 80.0), true),
        cpu::vis_esm::vis_esm,
        common::esm_tolerance,
        70,
    );
}

fn msm(storage: shadowgraph::Storage, hausdorff: bool, filter: Filter) -> Technique {
    Technique::Msm {
        prefilter: shadowgraph::StorageFilter { storage, filter },
        hausdorff,
        moment_bias: shadowgraph::low_level::model::default_moment_bias(storage),
        bleed: 0.05,
    }
}

#[test]
fn msm_hamburger_and_hausdorff_match_reference() {
    let blur = prefilter().filter;
    for (hausdorff, seed) in [(false, 80), (true, 81)] {
        check_prefiltered(
            msm(Storage::F32, hausdorff, blur),
            |lin| blurred(&cpu::msm::msm(lin, false), false),
            cpu::vis_msm::vis_msm,
            |m, l, s, _| common::msm_tolerance(m, l, s),
            seed,
        );
    }
}

#[test]
fn msm_quantized_moments_match_reference() {
    // The shading dequantizes whatever the texture holds; the values here are the f32
    // quantized moments, so only the storage's bias and flag differ from the f32 case.
    check_prefiltered(
        msm(Storage::Unorm16, false, prefilter().filter),
        |lin| blurred(&cpu::msm::msm(lin, true), false),
        cpu::vis_msm::vis_msm,
        |m, l, s, _| common::msm_tolerance(m, l, s),
        82,
    );
}

fn csm(terms: u32, filter: Filter) -> Technique {
    Technique::Csm {
        prefilter: shadowgraph::StorageFilter {
            storage: Storage::F32,
            filter,
        },
        terms,
        attenuation: 1.0,
        offset: 0.5 / terms as f32,
        scale: 2.0,
    }
}

#[test]
fn csm_matches_reference_for_odd_and_even_terms() {
    for (terms, seed) in [(7, 90), (16, 91)] {
        check_prefiltered(
            csm(terms, prefilter().filter),
            move |lin| blurred(&cpu::csm::csm(lin, terms), false),
            cpu::vis_csm::vis_csm,
            |_, l, _, _| common::csm_tolerance(l),
            seed,
        );
    }
}

#[test]
fn mip_filtered_lookups_match_reference_trilinearly() {
    // A width of 2.6 texels samples between levels 1 and 2 of the chain.
    let mips = Filter::Mips {
        width: 2.6,
        max_anisotropy: 0,
    };
    let vsm = Technique::Vsm {
        prefilter: shadowgraph::StorageFilter {
            storage: Storage::F32,
            filter: mips,
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    check_prefiltered(
        vsm,
        cpu::vsm::vsm,
        cpu::vis_vsm::vis_vsm,
        |m, l, s, _| common::vsm_tolerance(m, l, s),
        100,
    );
    let esm = Technique::Esm {
        filter: mips,
        exponent: 80.0,
    };
    check_prefiltered(
        esm,
        |lin| cpu::esm::esm(lin, 80.0),
        cpu::vis_esm::vis_esm,
        common::esm_tolerance,
        101,
    );
    check_prefiltered(
        csm(5, mips),
        |lin| cpu::csm::csm(lin, 5),
        cpu::vis_csm::vis_csm,
        |_, l, _, _| common::csm_tolerance(l),
        102,
    );
}
