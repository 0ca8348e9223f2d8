//! The shading kernel's visibility functions against the f64 references, on random blocky
//! depth maps and random receivers (with random normals, so the normal offset is exercised).
//!
//! f32 and f64 may disagree where a receiver sits on a texel boundary or a comparison is a tie:
//! a point is *robust* when the f64 reference does not jump when the receiver's UV and depth
//! are nudged by ±1e-4 texel / ±2e-6 (`common::robust`). At robust points the GPU must match to 1e-5 (the
//! mean of at most a few hundred 0/1 terms in f32); robust points must be ≥ 90% of all.

mod common;

use glam::{DVec3, Vec3};
use rand::Rng;
use shadowgraph::low_level::cpu::{self, Map};
use shadowgraph::low_level::render::{MapData, Renderer, visibility_at};
use shadowgraph::{Light, LightGpu, LightKind, PcfKernel, Shadow, Technique};

const MAP: usize = 61; // not a power of two

fn light(kind: LightKind, technique: Technique) -> Light {
    let (position, near, far) = match kind {
        LightKind::Directional { .. } => (Vec3::new(-3.0, 10.0, 2.0), 2.0, 20.0),
        LightKind::Spot { .. } | LightKind::Point => (Vec3::new(1.0, 8.0, -1.0), 0.5, 20.0),
    };
    Light {
        kind,
        position,
        target: Vec3::ZERO,
        near,
        far,
        size: 0.6,
        radiance: Vec3::ONE,
        shadow_map: MAP as u32,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 0.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    }
}

/// A world point whose light-space UV and linear depth are given, with a normal facing the light.
fn point(l: &Light, rng: &mut impl Rng) -> (Vec3, Vec3) {
    let uv = [rng.random_range(0.08..0.92), rng.random_range(0.08..0.92)];
    let d: f64 = rng.random_range(0.05..0.98);
    point_at(l, uv, d, rng)
}

/// A point near the surface `map` holds: at its texel's depth ± 0.01, where the comparisons
/// are close and a receiver-plane correction decides them.
fn point_on(l: &Light, map: &[f32], rng: &mut impl Rng) -> (Vec3, Vec3) {
    let uv = [rng.random_range(0.08..0.92), rng.random_range(0.08..0.92)];
    let t = |c: f64| ((c * MAP as f64).floor() as usize).min(MAP - 1);
    let z = f64::from(map[t(uv[1]) * MAP + t(uv[0])]);
    let d = (z + rng.random_range(-0.01..0.01)).clamp(0.01, 0.99);
    point_at(l, uv, d, rng)
}

fn point_at(l: &Light, uv: [f64; 2], d: f64, rng: &mut impl Rng) -> (Vec3, Vec3) {
    let g = LightGpu::new(l);
    let ndc_z = cpu::light::linear_to_ndc(&g, d);
    let inv = (l.projection() * l.view()).as_dmat4().inverse();
    let p = inv.project_point3(DVec3::new(2.0 * uv[0] - 1.0, 1.0 - 2.0 * uv[1], ndc_z));
    let to_light = cpu::light::to_light(&g, p);
    let mut n = DVec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    n = (n.normalize_or_zero() + 1.5 * to_light).normalize();
    (p.as_vec3(), n.as_vec3())
}

fn reference(l: &LightGpu, map: &Map, s: &cpu::light::LightSample) -> f64 {
    if !s.inside {
        return 1.0;
    }
    match l.technique {
        0 => cpu::vis_hard::vis_hard(map, l, s),
        1 => cpu::vis_pcf::vis_pcf(map, l, s),
        _ => cpu::vis_pcss::vis_pcss(map, l, s),
    }
}

fn robust_reference(l: &LightGpu, map: &Map, p: Vec3, n: Vec3) -> Option<f64> {
    let s = cpu::light::sample(l, p.as_dvec3(), n.as_dvec3());
    common::robust(&s, MAP, |t| reference(l, map, t))
}

fn check(kind: LightKind, technique: Technique, seed: u64) {
    check_light(light(kind, technique), seed, false);
}

/// `on_map`: receivers near the map's surface ([`point_on`]) rather than anywhere.
fn check_light(l: Light, seed: u64, on_map: bool) {
    let (kind, technique) = (l.kind, l.shadow.technique);
    let g = common::gpu();
    let mut rng = common::rng(seed);
    let map = common::blocky_map(&mut rng, MAP);
    let points: Vec<(Vec3, Vec3)> = (0..6000)
        .map(|_| match on_map {
            true => point_on(&l, &map, &mut rng),
            false => point(&l, &mut rng),
        })
        .collect();
    let mut renderer = Renderer::new(&g.device);
    let vis = visibility_at(
        &mut renderer,
        &g.device,
        &g.queue,
        std::slice::from_ref(&l),
        &[MapData::linear(MAP as u32, &map)],
        &points,
    )
    .expect("visibility_at");
    let lg = LightGpu::new(&l);
    let cmap = Map {
        size: MAP,
        texels: &map,
    };
    let (mut gpu_v, mut ref_v) = (Vec::new(), Vec::new());
    let mut partial = 0;
    for (i, (p, n)) in points.iter().enumerate() {
        if let Some(r) = robust_reference(&lg, &cmap, *p, *n) {
            gpu_v.push(vis[i]);
            ref_v.push(r);
            partial += usize::from(r > 0.0 && r < 1.0);
        }
    }
    let what = format!("{kind:?} {technique:?}");
    assert!(
        gpu_v.len() * 10 >= points.len() * 9,
        "{what}: only {} of {} points robust",
        gpu_v.len(),
        points.len()
    );
    assert!(
        ref_v.iter().any(|&v| v < 0.5) && ref_v.iter().any(|&v| v > 0.5),
        "{what}: inputs never shadow or never light"
    );
    if !matches!(technique, Technique::Hard) {
        assert!(partial > 50, "{what}: only {partial} penumbra points");
    }
    common::assert_close(&what, &gpu_v, &ref_v, 1e-5, 0.0);
}

const DIR: LightKind = LightKind::Directional { extent: 5.0 };
const SPOT: LightKind = LightKind::Spot { fov_degrees: 60.0 };

#[test]
fn hard_matches_reference() {
    check(DIR, Technique::Hard, 10);
    check(SPOT, Technique::Hard, 11);
}

#[test]
fn pcf_box_and_tent_match_reference() {
    check(
        DIR,
        Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Box,
        },
        20,
    );
    check(
        SPOT,
        Technique::Pcf {
            radius: 2,
            kernel: PcfKernel::Box,
        },
        21,
    );
    check(
        DIR,
        Technique::Pcf {
            radius: 3,
            kernel: PcfKernel::Tent,
        },
        22,
    );
    check(
        SPOT,
        Technique::Pcf {
            radius: 2,
            kernel: PcfKernel::Tent,
        },
        23,
    );
}

/// The receiver-plane bias (random normals tilt the receiver's plane every way) with a cap of
/// 0.02 that binds at some taps: the same f32-vs-f64 tolerance, and the bias must change the
/// reference's answer at a good share of the points (else the test could not see it).
#[test]
fn receiver_plane_bias_matches_reference() {
    let tent = Technique::Pcf {
        radius: 2,
        kernel: PcfKernel::Tent,
    };
    let pcss = Technique::Pcss {
        blocker_samples: 16,
        filter_samples: 32,
        max_search: 0.1,
    };
    for (i, (kind, technique)) in [
        (DIR, Technique::Hard),
        (SPOT, Technique::Hard),
        (DIR, tent),
        (SPOT, tent),
        (DIR, pcss),
        (SPOT, pcss),
    ]
    .into_iter()
    .enumerate()
    {
        let mut l = light(kind, technique);
        (l.shadow.bias, l.shadow.receiver_plane) = (0.0005, 0.02);
        check_light(l.clone(), 40 + i as u64, true);
        let (on, mut off) = (LightGpu::new(&l), LightGpu::new(&l));
        off.receiver_plane = 0.0;
        let mut rng = common::rng(40 + i as u64);
        let map = common::blocky_map(&mut rng, MAP);
        let cmap = Map {
            size: MAP,
            texels: &map,
        };
        let changed = (0..2000)
            .map(|_| point_on(&l, &map, &mut rng))
            .filter(|&(p, n)| {
                let v = |g: &LightGpu| {
                    reference(g, &cmap, &cpu::light::sample(g, p.as_dvec3(), n.as_dvec3()))
                };
                (v(&on) - v(&off)).abs() > 1e-3
            })
            .count();
        assert!(
            changed > 20,
            "{kind:?} {technique:?}: the bias changed only {changed} of 2000 points"
        );
    }
}

/// The f64 receiver-plane slope against the plane itself: a point moved within the receiver's
/// plane (by up to 3 texels) lands at depth `d + slope · Δtexels` — exactly for the directional
/// light (1e-6 relative: the light's matrices are f32, orthonormal to ~1e-7), to first order for the spot light, whose depth over a plane is
/// not affine in the map's coordinates (1e-3 of the move's depth change plus 1e-9).
#[test]
fn receiver_plane_slope_is_the_planes_depth() {
    let mut rng = common::rng(50);
    for kind in [DIR, SPOT] {
        let mut l = light(kind, Technique::Hard);
        (l.shadow.normal_bias, l.shadow.receiver_plane) = (0.0, 0.02);
        let g = LightGpu::new(&l);
        let texel = f64::from(g.width_at_unit) / MAP as f64;
        for _ in 0..500 {
            let (p, n) = point(&l, &mut rng);
            let (p, n) = (p.as_dvec3(), n.as_dvec3());
            let s = cpu::light::sample(&g, p, n);
            let along = n.any_orthonormal_pair();
            let (a, b) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let scale = match kind {
                LightKind::Spot { .. } => 1e-3 * s.view_z,
                _ => 1.0,
            };
            let q = p + (along.0 * a + along.1 * b) * (3.0 * texel * scale);
            let t = cpu::light::sample(&g, q, n);
            let moved = [
                (t.uv[0] - s.uv[0]) * MAP as f64,
                (t.uv[1] - s.uv[1]) * MAP as f64,
            ];
            let predicted = s.depth_slope[0] * moved[0] + s.depth_slope[1] * moved[1];
            let actual = t.depth - s.depth;
            let allowed = match kind {
                LightKind::Spot { .. } => 1e-3 * actual.abs() + 1e-9,
                _ => 1e-6 * actual.abs() + 1e-9,
            };
            assert!(
                (predicted - actual).abs() <= allowed,
                "{kind:?}: predicted {predicted}, actual {actual}"
            );
        }
    }
}

/// [`receiver_plane_slope_is_the_planes_depth`] for a point light: the slope in the view of
/// the face that sees the receiver (first order, as the spot light's), for 2000 receivers
/// around the light with random normals facing it; moves that cross into another face are
/// not compared.
#[test]
fn receiver_plane_slope_is_the_planes_depth_on_every_face() {
    let mut rng = common::rng(51);
    let mut l = light(LightKind::Point, Technique::Hard);
    (l.shadow.normal_bias, l.shadow.receiver_plane) = (0.0, 0.02);
    let g = LightGpu::new(&l);
    let (size, centre) = (g.map_size, l.position.as_dvec3());
    let mut faces = [0usize; 6];
    for _ in 0..2000 {
        let dir = glam::DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if dir.length() < 0.1 {
            continue;
        }
        let p = centre + dir.normalize() * rng.random_range(2.0..8.0);
        let to_light = (centre - p).normalize();
        let n = (to_light
            + 0.7
                * glam::DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ))
        .normalize();
        if n.dot(to_light) < 0.2 {
            continue;
        }
        let s = cpu::light::sample(&g, p, n);
        let tile = |uv: [f64; 2]| ((uv[0] * 3.0).floor(), (uv[1] * 2.0).floor());
        let texel = f64::from(g.width_at_unit) * s.view_z / MAP as f64;
        let along = n.any_orthonormal_pair();
        let (a, b) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let q = p + (along.0 * a + along.1 * b) * (3.0 * texel * 1e-3);
        let t = cpu::light::sample(&g, q, n);
        if tile(s.uv) != tile(t.uv) {
            continue;
        }
        let (fx, fy) = tile(s.uv);
        faces[(fy * 3.0 + fx) as usize] += 1;
        let moved = [
            (t.uv[0] - s.uv[0]) * f64::from(size[0]),
            (t.uv[1] - s.uv[1]) * f64::from(size[1]),
        ];
        let predicted = s.depth_slope[0] * moved[0] + s.depth_slope[1] * moved[1];
        let actual = t.depth - s.depth;
        assert!(
            (predicted - actual).abs() <= 1e-3 * actual.abs() + 1e-9,
            "point, face tile {:?}: predicted {predicted}, actual {actual}",
            tile(s.uv)
        );
    }
    assert!(faces.iter().all(|&n| n > 100), "faces compared: {faces:?}");
}

#[test]
fn pcss_matches_reference() {
    let t = Technique::Pcss {
        blocker_samples: 16,
        filter_samples: 32,
        max_search: 0.1,
    };
    check(DIR, t, 30);
    check(SPOT, t, 31);
}

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
    cpu::blur::blur_mode(
        t,
        2.0,
        1.0,
        shadowgraph::BlurKernel::Gaussian,
        log_space,
    )
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

use shadowgraph::{Filter, Storage};

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
