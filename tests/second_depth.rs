//! Second-depth shadow maps (`midpoint`, `second_depth`): the peeled second depth the GPU
//! rasterizes against the f64 ray cast of every surface along each texel's ray
//! (`truth::peel`), the map the shading reads against the f64 reference of its kernel
//! (`cpu::second_depth`) on the GPU's own depths (the far plane where no second surface
//! exists), and on a ground plane with nothing behind it (`scenes/casters_on_plane.toml`) the
//! visibility against the f64 ray cast, within what `hard` with its best constant bias reaches.
//! (The visibility of the bundled scenes against `cpu::vis_hard` and `cpu::vis_pcf` on that map
//! is in tests/scenes/.)

mod common;

use std::path::Path;

use glam::{DMat4, DVec3, DVec4};
use shadowgraph::low_level::render::{Frame, RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::bvh::Bvh;
use shadowgraph::low_level::truth::peel::{PeeledTexel, peeled_depths};
use shadowgraph::low_level::truth::raycast::{CpuTruth, ray_cast_truth};
use shadowgraph::low_level::truth::{axis_distance, emitter};
use shadowgraph::low_level::wgsl_mirrors::SecondDepthParams;
use shadowgraph::low_level::{cpu, technique};
use shadowgraph::{Light, LightKind, PcfKernel, Technique};

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Renders `scene` keeping every resource of its plan (imports too: both depth maps).
fn dump(renderer: &mut Renderer, g: &shadowgraph::low_level::gpu::Gpu, scene: &Scene) -> Frame {
    let opts = RenderOptions {
        aux: false,
        repeat: 1,
        dump: true,
    };
    renderer
        .render(&g.device, &g.queue, scene, opts)
        .expect("renders")
}

/// The texels of resource `name` of a dumped frame (one channel).
fn resource<'a>(frame: &'a Frame, name: &str) -> &'a [f32] {
    let r = frame
        .resources
        .iter()
        .find(|r| r.levels[0].resource == name)
        .unwrap_or_else(|| panic!("{name} not in the plan"));
    assert_eq!(r.levels[0].channels, 1, "{name}: channels");
    &r.levels[0].data
}

/// Both rasterized depths equal the ray cast's where a texel is no edge case (its jittered rays
/// meet the same triangles): within 10⁻⁶ (f32 transforms and interpolation of depths in
/// [0, 1], a few ULPs of 2⁻²⁴ each) plus the depth's slope per texel times 1/128 (the
/// rasterizer snaps vertices to 1/256 of a texel, twice that for margin). At least 95% of the
/// texels are robust. Then the map the shading reads is the kernel's f64 reference on those
/// depths, within 10⁻⁶ (f32 linearization), and exactly 1.0, the far plane, at every texel
/// with no second surface (in both modes: nothing lies behind the first surface there). The
/// example scenes (a solid slab: a second surface behind most texels) and every light of
/// `casters_on_plane` (a ground plane with nothing behind it: behind few).
#[test]
fn peeled_depth_and_map_match_the_references() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    for (name, lights, min_second) in [
        ("scenes/techniques/midpoint.toml", 1, 4),
        ("scenes/techniques/second_depth.toml", 1, 4),
        ("scenes/casters_on_plane.toml", 2, 40),
    ] {
        let scene = scene(name);
        let frame = dump(&mut renderer, &g, &scene);
        for li in 0..lights {
            let name = format!("{name} light {li}");
            let light = &scene.lights[li];
            assert_eq!(
                light.shadow.slope_bias, 0.0,
                "{name}: the reference has no slope bias"
            );
            let z1 = resource(&frame, &technique::depth_name(li));
            let z2 = resource(&frame, &technique::second_depth_name(li));
            let reference = peeled_depths(&scene, light);
            assert_eq!(reference.len(), z1.len(), "{name}: texels");
            let robust: Vec<usize> = (0..reference.len())
                .filter(|&i| reference[i].robust)
                .collect();
            assert!(
                robust.len() * 100 >= reference.len() * 95,
                "{name}: only {} of {} texels robust",
                robust.len(),
                reference.len()
            );
            let second = robust.iter().filter(|&&i| reference[i].z2 < 1.0).count();
            assert!(
                second * min_second > robust.len() && second < robust.len(),
                "{name}: a second surface behind {second} of {} texels",
                robust.len()
            );
            let tol: Vec<f64> = robust
                .iter()
                .map(|&i| 1e-6 + reference[i].slope / 128.0)
                .collect();
            for (what, gpu, of) in [
                ("first depth", z1, (|t| t.z1) as fn(&PeeledTexel) -> f64),
                ("second depth", z2, |t| t.z2),
            ] {
                let got: Vec<f32> = robust.iter().map(|&i| gpu[i]).collect();
                let want: Vec<f64> = robust.iter().map(|&i| of(&reference[i])).collect();
                common::assert_within(&format!("{name}: {what}"), &got, &want, &tol);
            }
            check_map(&name, light, li, &frame);
        }
    }
}

/// The map light `li` of `frame` shades with is the kernel's f64 reference on the GPU's own
/// depths, within 10⁻⁶ (f32 linearization), and exactly 1.0, the far plane, at every texel
/// with no second surface (more than 100 of them).
fn check_map(name: &str, light: &Light, li: usize, frame: &Frame) {
    let z1 = resource(frame, &technique::depth_name(li));
    let z2 = resource(frame, &technique::second_depth_name(li));
    let midpoint = matches!(light.shadow.technique, Technique::Midpoint { .. });
    let params = SecondDepthParams {
        depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::new(light),
        mode: u32::from(!midpoint),
        _pad: [0; 3],
    };
    let map = resource(frame, &format!("light{li}.second_depth"));
    let want = cpu::second_depth::second_depth(z1, z2, &params);
    common::assert_close(&format!("{name}: map"), map, &want, 1e-6, 0.0);
    let far: Vec<usize> = (0..z2.len()).filter(|&i| z2[i] >= 1.0).collect();
    assert!(
        far.len() > 100,
        "{name}: {} texels at the far plane",
        far.len()
    );
    for i in far {
        assert_eq!(map[i], 1.0, "{name}: texel {i} without a second surface");
    }
}

/// Whether the centre of `light` sees `q`: the ray cast's shadow ray (`truth::raycast`), from
/// `q` to the light's near plane, no bias (`q` lies on the ground, which the ray leaves).
fn sees(bvh: &Bvh, light: &Light, q: DVec3) -> bool {
    let near = f64::from(light.near);
    let z = axis_distance(light, q);
    let (_, _, axis) = emitter::frame(light);
    let centre = emitter::point(light, [0.0, 0.0]);
    let (dir, t_max) = match light.kind {
        LightKind::Directional { .. } => {
            let d = (light.target.as_dvec3() - centre).normalize();
            (-d, ((z - near) / d.dot(axis)).max(0.0))
        }
        _ => {
            let to = centre - q;
            let len = to.length();
            (to / len, len * (1.0 - near / z).max(0.0))
        }
    };
    !bvh.occluded(q, dir, 1e-9 * (1.0 + q.length()), t_max, None)
}

/// Whether the ground point `p` lies `reach` texels or more from any shadow edge of `light`:
/// the points of the ground whose light rays pass through the map within `reach` texels of
/// `p`'s (a 9 × 9 grid over that square) all see the light as `p` does (`lit`).
fn unambiguous(
    bvh: &Bvh,
    light: &Light,
    view_proj: &DMat4,
    p: DVec3,
    lit: bool,
    reach: f64,
) -> bool {
    let inverse = view_proj.inverse();
    let clip = *view_proj * p.extend(1.0);
    let (x, y) = (clip.x / clip.w, clip.y / clip.w);
    let texel = 2.0 / f64::from(light.shadow_map);
    let at = |x: f64, y: f64, z: f64| {
        let v: DVec4 = inverse * DVec4::new(x, y, z, 1.0);
        v.truncate() / v.w
    };
    (-4..=4).all(|i| {
        (-4..=4).all(|j| {
            let (dx, dy) = (
                f64::from(i) * reach * texel / 4.0,
                f64::from(j) * reach * texel / 4.0,
            );
            let (o, e) = (at(x + dx, y + dy, 0.0), at(x + dx, y + dy, 1.0));
            let mut q = o + (e - o) * (o.y / (o.y - e.y));
            q.y = 0.0;
            sees(bvh, light, q) == lit
        })
    })
}

/// The ground's pixels for light `li` that the comparison counts, for a window reaching `r`
/// texels: ground in both the ray cast and the G-buffer (y = 0, facing up), relevant to the
/// light, and `r + 1` texels or more from a shadow edge (so every texel the nearest-texel test
/// or the PCF window reads has the same ray-cast visibility: a texel's coverage and the
/// receiver's position within it are not judged). Each with the ray cast's verdict (lit).
fn ground_pixels(
    scene: &Scene,
    truth: &CpuTruth,
    gbuffer: &[f32],
    li: usize,
    r: u32,
) -> Vec<(usize, bool)> {
    let bvh = Bvh::new(scene);
    let light = &scene.lights[li];
    let view_proj = light.projection().as_dmat4() * light.view().as_dmat4();
    let lights = scene.lights.len();
    let candidates: Vec<(usize, DVec3, bool)> = (0..truth.hits.len())
        .filter_map(|px| {
            let (p, n) = truth.hits[px]?;
            let on_ground = p.y.abs() < 1e-9 && n.y > 0.999;
            let gpu_ground = gbuffer[4 * px + 3] != 0.0 && gbuffer[4 * px + 1].abs() < 1e-4;
            let relevant = truth.mask[px * lights + li];
            (on_ground && gpu_ground && relevant).then_some((
                px,
                p,
                truth.visibility[px * lights + li] > 0.5,
            ))
        })
        .collect();
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    std::thread::scope(|s| {
        let handles: Vec<_> = candidates
            .chunks(candidates.len().div_ceil(threads).max(1))
            .map(|chunk| {
                let (bvh, view_proj) = (&bvh, &view_proj);
                s.spawn(move || {
                    chunk
                        .iter()
                        .filter(|&&(_, p, lit)| {
                            unambiguous(bvh, light, view_proj, p, lit, f64::from(r + 1))
                        })
                        .map(|&(px, _, lit)| (px, lit))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// Renders `base` with every light's shadow set by `set`; the visibility and the G-buffer's
/// positions.
fn render_with(
    renderer: &mut Renderer,
    g: &shadowgraph::low_level::gpu::Gpu,
    base: &Scene,
    set: impl Fn(&mut shadowgraph::Shadow),
) -> Frame {
    let mut scene = base.clone();
    for l in &mut scene.lights {
        set(&mut l.shadow);
    }
    let opts = RenderOptions {
        aux: true,
        repeat: 1,
        dump: false,
    };
    renderer
        .render(&g.device, &g.queue, &scene, opts)
        .expect("renders")
}

/// Pixels of `pixels` where `frame`'s visibility of light `li` and the ray cast disagree
/// (lit: ≥ ½).
fn wrong(frame: &Frame, lights: usize, li: usize, pixels: &[(usize, bool)]) -> usize {
    pixels
        .iter()
        .filter(|&&(px, lit)| (frame.visibility[px * lights + li] >= 0.5) != lit)
        .count()
}

/// A ground plane with nothing behind it, under closed casters standing on it and floating
/// above it (`casters_on_plane`: a spot light and a sun), every bias 0: over the ground's
/// pixels away from shadow edges (see [`ground_pixels`]), `midpoint` and `second_depth` — the
/// nearest texel, and a 3×3 tent PCF window — disagree with the f64 ray cast of the light's
/// centre at no more pixels than `hard` does with the best of five constant biases
/// (0.0005–0.008 linear depth units). Where no second surface exists they store the far plane,
/// so the ground is lit wherever nothing stands in front of it; had they stored the first
/// depth (plus a bias of 0), they would shade the ground as `hard` with no bias, acne at about
/// half its lit pixels.
#[test]
fn on_a_ground_plane_they_match_the_ray_cast_as_hard_with_a_tuned_bias_does() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let base = scene("scenes/casters_on_plane.toml");
    let lights = base.lights.len();
    let truth = ray_cast_truth(&base, &emitter::centre_offset());
    let hard: Vec<Frame> = [0.0005, 0.001, 0.002, 0.004, 0.008]
        .iter()
        .map(|&bias| {
            render_with(&mut renderer, &g, &base, |s| {
                s.technique = Technique::Hard;
                (s.bias, s.slope_bias, s.normal_bias) = (bias, 0.0, 0.0);
            })
        })
        .collect();
    for radius in [0, 1] {
        let kernel = PcfKernel::Tent;
        let techniques = [
            ("midpoint", Technique::Midpoint { radius, kernel }),
            ("second_depth", Technique::SecondDepth { radius, kernel }),
        ];
        let frames: Vec<Frame> = techniques
            .iter()
            .map(|&(_, t)| {
                render_with(&mut renderer, &g, &base, |s| {
                    s.technique = t;
                    (s.bias, s.slope_bias, s.normal_bias) = (0.0, 0.0, 0.0);
                })
            })
            .collect();
        for li in 0..lights {
            let pixels = ground_pixels(&base, &truth, &frames[0].position, li, radius);
            let shadowed = pixels.iter().filter(|p| !p.1).count();
            assert!(
                shadowed > 300 && pixels.len() - shadowed > 3000,
                "light {li}: {shadowed} shadowed of {} ground pixels",
                pixels.len()
            );
            let bound = hard
                .iter()
                .map(|f| wrong(f, lights, li, &pixels))
                .min()
                .expect("biases");
            for ((name, _), frame) in techniques.iter().zip(&frames) {
                let n = wrong(frame, lights, li, &pixels);
                eprintln!(
                    "light {li}, radius {radius}: {name} {n}, hard's best {bound} of {} ground pixels ({shadowed} shadowed)",
                    pixels.len()
                );
                assert!(
                    n <= bound,
                    "light {li}, radius {radius}: {name} disagrees with the ray cast at {n} of {} ground pixels, hard with its best bias at {bound}",
                    pixels.len()
                );
            }
        }
    }
}
