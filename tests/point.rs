//! Point lights: the faces' geometry (f64, no GPU) and shadows that cross a face edge against
//! the f64 ray cast.

mod common;

use std::path::Path;

use glam::{DMat4, DVec3, Vec3};
use rand::{Rng, SeedableRng};
use shadowgraph::low_level::model::point::{self, PointLayout};
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique::reach;
use shadowgraph::low_level::truth::emitter;
use shadowgraph::low_level::truth::raycast::ray_cast_truth;
use shadowgraph::{Filter, PcfKernel, Technique};

/// Every direction lands in exactly the face `face_of` names, inside that face's 90° core
/// (|x/z|, |y/z| ≤ 1 in its view, the matrices the raster pass draws with), and the core
/// projects into the tile's inner `face − 2·guard` texels: what the guard band rests on.
#[test]
fn each_direction_lands_in_its_faces_core() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(16);
    let layout = PointLayout::new(512, 6.5).expect("layout");
    assert_eq!(layout.guard, 8);
    let proj = layout.projection(0.1, 10.0).as_dmat4();
    let inner = f64::from(layout.guard) / f64::from(layout.face);
    for _ in 0..20_000 {
        let d = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if d.length() < 1e-3 {
            continue;
        }
        let f = point::face_of(d);
        let (forward, up) = point::face_axes(f);
        let view = DMat4::look_at_rh(DVec3::ZERO, forward.as_dvec3(), up.as_dvec3());
        let v = (view * d.extend(1.0)).truncate();
        let z = -v.z;
        assert!(
            (z - d.abs().max_element()).abs() < 1e-12,
            "{d}: face {f} depth {z}"
        );
        assert!(
            v.x.abs() <= z * (1.0 + 1e-12) && v.y.abs() <= z * (1.0 + 1e-12),
            "{d}: outside face {f}'s core ({v})"
        );
        // Into the tile: NDC → texel fraction of the face, then the guard band.
        let c = proj * (v * 5.0).extend(1.0);
        let u = 0.5 + 0.5 * c.x / c.w;
        let t = 0.5 - 0.5 * c.y / c.w;
        for w in [u, t] {
            assert!(
                (inner - 1e-6..=1.0 - inner + 1e-6).contains(&w),
                "{d}: face {f} puts the core at {w}, outside [{inner}, {}]",
                1.0 - inner
            );
        }
    }
    // The six faces tile the atlas without overlap.
    let tiles: Vec<(u32, u32)> = (0..point::FACES).map(|f| layout.origin(f)).collect();
    for (a, ta) in tiles.iter().enumerate() {
        for tb in &tiles[a + 1..] {
            assert_ne!(ta, tb);
        }
        assert!(ta.0 + layout.face <= layout.atlas().0 && ta.1 + layout.face <= layout.atlas().1);
    }
}

/// Each technique's reach is what its lookup reads: the guard band is one texel wider.
#[test]
fn guard_bands_follow_each_techniques_reach() {
    let pcf = |radius, kernel| Technique::Pcf { radius, kernel };
    assert_eq!(reach(&Technique::Hard, 512), Ok(1.0));
    assert_eq!(reach(&pcf(3, PcfKernel::Tent), 512), Ok(4.0));
    assert_eq!(reach(&pcf(3, PcfKernel::Hardware), 512), Ok(1.0));
    let pcss = Technique::Pcss {
        blocker_samples: 16,
        filter_samples: 32,
        max_search: 0.02,
    };
    // 0.02 of a 512-texel face: 10.24 texels of search (and, on a point light, of filter).
    assert!((reach(&pcss, 512).unwrap() - 11.24).abs() < 1e-4);
    assert_eq!(PointLayout::new(512, 11.24).unwrap().guard, 13);
    // A mip chain read at width 8 (level 3) needs faces that are a multiple of 8.
    let esm = |width| Technique::Esm {
        filter: Filter::Mips {
            width,
            max_anisotropy: 0,
        },
        exponent: 40.0,
    };
    assert_eq!(reach(&esm(8.0), 512), Ok(16.0));
    assert!(reach(&esm(8.0), 300).is_err());
    // A guard band past a quarter of the face is refused.
    assert!(PointLayout::new(64, 16.0).is_err());
    assert!(PointLayout::new(64, 15.0).is_ok());
}

fn point_scene() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/point.toml");
    let mut s = Scene::load(&path).expect("point.toml loads");
    // A hard truth: the point itself.
    s.lights[0].size = 0.0;
    s
}

/// A shadow that crosses the edge between two faces (point.toml's box at x = 1.6 straddles the
/// −Y / +X edge at x = 2 on the floor), with a filter that reads across the edge's texels, is
/// the ray cast's shadow: away from the shadow's own boundary (2 pixels), no pixel within 5%
/// of a face tie disagrees with the f64 ray cast to the light's centre — no seam, no leak, no
/// missing shadow where a filter's taps cross into the guard band. The same holds elsewhere.
#[test]
fn shadows_across_face_edges_match_the_ray_cast() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let base = point_scene();
    let truth = ray_cast_truth(&base, &emitter::centre_offset());
    let (w, h) = (base.width as usize, base.height as usize);
    let centre = base.lights[0].position.as_dvec3();
    // Ray-cast pixels within 2 pixels of a boundary of its shadow.
    let boundary: Vec<bool> = (0..w * h)
        .map(|px| {
            let (x, y) = ((px % w) as i64, (px / w) as i64);
            let v = truth.visibility[px] < 0.5;
            (-2..=2).any(|dy| {
                (-2..=2).any(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    (0..w as i64).contains(&nx)
                        && (0..h as i64).contains(&ny)
                        && truth.mask[ny as usize * w + nx as usize]
                        && (truth.visibility[ny as usize * w + nx as usize] < 0.5) != v
                })
            })
        })
        .collect();
    let techniques = [
        ("hard", Technique::Hard),
        (
            "pcf tent r2",
            Technique::Pcf {
                radius: 2,
                kernel: PcfKernel::Tent,
            },
        ),
        ("vsm blur r3", vsm_blur(3.0)),
    ];
    for (name, technique) in techniques {
        let mut s = base.clone();
        s.lights[0].shadow.technique = technique;
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &s,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: false,
                },
            )
            .expect("render");
        let (mut edge, mut edge_shadowed, mut edge_off, mut other, mut other_off) = (0, 0, 0, 0, 0);
        for px in 0..w * h {
            if !truth.mask[px] || boundary[px] || frame.position[4 * px + 3] == 0.0 {
                continue;
            }
            let at = |d: &[f32]| Vec3::new(d[4 * px], d[4 * px + 1], d[4 * px + 2]).as_dvec3();
            let mut a = (at(&frame.position) - centre).abs().to_array();
            a.sort_by(f64::total_cmp);
            let off = (f64::from(frame.visibility[px]) - truth.visibility[px]).abs() > 0.5;
            if a[2] - a[1] < 0.05 * a[2] {
                edge += 1;
                edge_shadowed += usize::from(truth.visibility[px] < 0.5);
                edge_off += usize::from(off);
            } else {
                other += 1;
                other_off += usize::from(off);
            }
        }
        eprintln!(
            "{name}: {edge} pixels by a face edge ({edge_shadowed} shadowed), {edge_off} off; \
             {other} elsewhere, {other_off} off"
        );
        assert!(
            edge > 2000 && edge_shadowed > 100,
            "{name}: the scene no longer casts a shadow across a face edge ({edge}, {edge_shadowed})"
        );
        assert_eq!(
            edge_off, 0,
            "{name}: {edge_off} pixels by a face edge disagree"
        );
        assert!(
            other_off * 1000 <= other,
            "{name}: {other_off} of {other} pixels disagree"
        );
    }
}

fn vsm_blur(radius: f32) -> Technique {
    use shadowgraph::low_level::model::ParamValue;
    shadowgraph::low_level::technique::named(
        "vsm",
        &[
            ("filter_radius", ParamValue::Float(radius)),
            ("filter_sigma", ParamValue::Float(0.5 * radius)),
        ],
    )
    .expect("vsm with a blur")
}
