//! Hard, PCF, receiver-plane bias and PCSS against their f64 references.

use super::*;

/// A point near the surface `map` holds: at its texel's depth ± 0.01, where the comparisons
/// are close and a receiver-plane correction decides them.
fn point_on(l: &Light, map: &[f32], rng: &mut impl Rng) -> (Vec3, Vec3) {
    let uv = [rng.random_range(0.08..0.92), rng.random_range(0.08..0.92)];
    let t = |c: f64| ((c * MAP as f64).floor() as usize).min(MAP - 1);
    let z = f64::from(map[t(uv[1]) * MAP + t(uv[0])]);
    let d = (z + rng.random_range(-0.01..0.01)).clamp(0.01, 0.99);
    point_at(l, uv, d, rng)
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
