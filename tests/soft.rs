//! The soft techniques (`cssm`, `vssm`, `msm_soft`) against their f64 references: the whole
//! visibility (search square → blocker → penumbra width → lookup) through the real shading
//! kernel on random blocky maps, directional and spot (the blocker kernels alone:
//! tests/blocker.rs). Tolerances are propagated
//! through the f64 references by perturbation (tests/common/soft/). Last, each bundled soft
//! scene's distance to an f64 PCSS on the same rasterized map.

mod common;

use common::soft::TableError;
use common::soft_maps::{
    DIR, MAP, SPOT, Tables, cssm_resolved, light, msm_soft, rounded, tables, trig_error, vssm,
    with_sums,
};
use glam::{DVec3, Vec3};
use rand::Rng;
use shadowgraph::low_level::cpu::sat::Integral;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::render::{MapData, Renderer, visibility_at};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique::sat_coding;
use shadowgraph::{CssmSearch, Light, LightGpu, SatVariant, Storage, Technique};

/// A world point with random light-space UV and linear depth, normal facing the light.
fn point(l: &Light, rng: &mut impl Rng) -> (Vec3, Vec3) {
    let g = LightGpu::new(l);
    let uv = [rng.random_range(0.08..0.92), rng.random_range(0.08..0.92)];
    let d: f64 = rng.random_range(0.05..0.98);
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

/// The representations a technique's tables sum, from a linear map.
type Encode<'a> = &'a dyn Fn(&Texels) -> Vec<Texels>;
/// The f64 visibility from the integral images of the decoded representations.
type Reference<'a> = &'a dyn Fn(&[Integral], &LightGpu, &cpu::light::LightSample) -> f64;
/// The tolerance at a point (`None`: a perturbation flips the blocker threshold).
type Tolerance<'a> =
    &'a dyn Fn(&[Integral], &[TableError], &LightGpu, &cpu::light::LightSample, f64) -> Option<f64>;

/// A soft technique's shading-kernel visibility at 3000 random receivers on a random blocky
/// map (both light kinds) against `reference` on the tables' decoded values. Points where the
/// f64 answer jumps under a ±1e-4-texel / ±2e-6-depth nudge, or where the propagated errors
/// could flip the blocker threshold, are set aside; they must be under 10%. Both lit and
/// shadowed receivers and over 100 penumbra points (0.01 < v < 0.99) must occur. Returns what
/// was seen: points compared, points set aside, the largest error, and the 50th, 99th
/// percentile and largest tolerance.
fn check_soft(
    g: &Gpu,
    technique: Technique,
    seed: u64,
    encode: Encode,
    reference: Reference,
    tolerance: Tolerance,
) -> Seen {
    let mut rng = common::rng(seed);
    let (mut worst, mut tolerances, mut aside) = (0.0f64, Vec::new(), 0);
    for kind in [DIR, SPOT] {
        let what = format!("{} {kind:?} seed {seed}", technique.name());
        let l = light(kind, technique);
        let lg = LightGpu::new(&l);
        let coding = sat_coding(&l)
            .expect("coding")
            .expect("a soft technique has a table");
        let linear = common::blocky_map(&mut rng, MAP);
        let tabs: Vec<Tables> = encode(&Texels::from_f32(MAP, MAP, 1, &linear))
            .iter()
            .map(|r| tables(r, &coding))
            .collect();
        let errors: Vec<TableError> = tabs
            .iter()
            .map(|t| TableError::new(&t.decoded, &coding))
            .collect();
        // f32 tables are read with filtered fetches: the filter's square on the 2⁻⁸ grid.
        let float = coding.variant == SatVariant::Float;
        let decoded: Vec<Integral> = tabs
            .iter()
            .map(|t| Integral::new(&t.decoded).filtered(float))
            .collect();
        let maps: Vec<MapData> = tabs
            .iter()
            .flat_map(|t| {
                t.words
                    .iter()
                    .map(|w| MapData::new(MAP as u32, t.format, w))
            })
            .collect();
        let points: Vec<(Vec3, Vec3)> = (0..3000).map(|_| point(&l, &mut rng)).collect();
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
        let (mut gpu_v, mut ref_v, mut tol) = (Vec::new(), Vec::new(), Vec::new());
        for (i, (p, n)) in points.iter().enumerate() {
            let s = cpu::light::sample(&lg, p.as_dvec3(), n.as_dvec3());
            let f = |t: &cpu::light::LightSample| {
                if t.inside {
                    reference(&decoded, &lg, t)
                } else {
                    1.0
                }
            };
            let Some(v) = common::robust(&s, MAP, f) else {
                continue;
            };
            let t = if s.inside {
                tolerance(&decoded, &errors, &lg, &s, v)
            } else {
                Some(0.0)
            };
            if let Some(t) = t {
                gpu_v.push(vis[i]);
                ref_v.push(v);
                tol.push(t);
            }
        }
        aside += points.len() - gpu_v.len();
        assert!(
            gpu_v.len() * 10 >= points.len() * 9,
            "{what}: only {} of {} points robust",
            gpu_v.len(),
            points.len()
        );
        let partial = ref_v.iter().filter(|&&v| v > 0.01 && v < 0.99).count();
        assert!(partial > 100, "{what}: only {partial} penumbra points");
        assert!(
            ref_v.iter().any(|&v| v < 0.5) && ref_v.iter().any(|&v| v > 0.99),
            "{what}: inputs never shadow or never light"
        );
        common::assert_within(&what, &gpu_v, &ref_v, &tol);
        for (gv, rv) in gpu_v.iter().zip(&ref_v) {
            worst = worst.max((f64::from(*gv) - rv).abs());
        }
        tolerances.extend(tol);
    }
    tolerances.sort_by(f64::total_cmp);
    let at = |q: f64| tolerances[((tolerances.len() - 1) as f64 * q) as usize];
    Seen {
        compared: tolerances.len(),
        aside,
        worst,
        tolerance: [at(0.5), at(0.99), at(1.0)],
    }
}

/// What [`check_soft`] saw.
struct Seen {
    compared: usize,
    aside: usize,
    worst: f64,
    tolerance: [f64; 3],
}

impl std::fmt::Display for Seen {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [p50, p99, max] = self.tolerance;
        write!(
            f,
            "{} points compared, {} set aside; worst |gpu − f64| {:.2e}; tolerance median \
             {p50:.2e}, 99% {p99:.2e}, max {max:.2e}",
            self.compared, self.aside, self.worst
        )
    }
}

#[test]
fn vssm_matches_reference() {
    // Tolerance (tests/common/soft/): the table means' f32 weighting (and, for the float
    // variant, the f32 differences of strip sums), the UV's rounding of the square's edges
    // and the receiver depth's, propagated through the Chebyshev blocker estimate, the
    // penumbra width and the final bound.
    let g = common::gpu();
    for (sums, seed) in [(SatVariant::Fixed, 200), (SatVariant::Float, 201)] {
        let seen = check_soft(
            &g,
            vssm(sums),
            seed,
            &|lin| vec![rounded(cpu::vsm::vsm(lin))],
            &|t, l, s| cpu::vis_vssm::vis_vssm(&t[0], l, s),
            &|t, e, l, s, v| common::soft::vssm_tolerance(&t[0], &e[0], l, s, v),
        );
        eprintln!("vssm {sums:?}: {seen}");
    }
}

#[test]
fn msm_soft_matches_reference() {
    // Tolerance: as VSSM's, with the moments perturbed in the moment domain (the table error
    // carried through the dequantization, plus Cholesky's backward error, 32·2⁻²⁴ relative).
    // The table always sums the quantized moments (`technique::msm_quantized`); the unorm16
    // case reads them rounded to f32 as well (only the bias differs).
    let g = common::gpu();
    for (storage, hausdorff, sums, seed) in [
        (Storage::F32, false, SatVariant::Fixed, 210),
        (Storage::F32, true, SatVariant::Fixed, 211),
        (Storage::Unorm16, false, SatVariant::Fixed, 212),
        (Storage::F32, false, SatVariant::Float, 213),
    ] {
        let technique = with_sums(msm_soft(storage, hausdorff), sums);
        let quantized = shadowgraph::low_level::technique::msm_quantized(&technique);
        assert!(quantized, "a soft MSM table sums quantized moments");
        let seen = check_soft(
            &g,
            technique,
            seed,
            &|lin| vec![rounded(cpu::msm::msm(lin, quantized))],
            &|t, l, s| cpu::vis_msm_soft::vis_msm_soft(&t[0], l, s),
            &|t, e, l, s, v| common::soft::msm_soft_tolerance(&t[0], &e[0], l, s, v),
        );
        eprintln!("msm_soft {storage:?} hausdorff {hausdorff} {sums:?}: {seen}");
    }
}

#[test]
fn cssm_matches_reference() {
    // Tolerance: the series carry the device's measured sin/cos error (checked against
    // Vulkan's 2⁻¹¹ first) and the means' errors per term; the moment search's means their
    // tables' error as msm_soft's do; then as VSSM's, plus the f32 exp2/log2 of the sharpening
    // v^p. Sharpening A = 3, B = 10 per depth unit, so that most penumbra points are sharpened
    // noticeably. Both blocker searches: the moments (the default) and the paper's CSM-Z; the
    // three resolves: the two-depth inversion (the default; its two series carry the sin/cos
    // error) with the blockers' depth over the filter square (its moments' means carry their
    // table's error) or the search's, and the paper's sharpening alone.
    let g = common::gpu();
    let e_trig = trig_error(&g);
    eprintln!("device sin/cos error (×2 + 2⁻²⁴): {e_trig:.2e}");
    use shadowgraph::CssmResolve::{Sharpen, TwoDepth, TwoDepthSearch};
    for (terms, seed, kind, sums, resolve) in [
        (4, 220, CssmSearch::Moments, SatVariant::Fixed, TwoDepth),
        (7, 221, CssmSearch::Moments, SatVariant::Fixed, TwoDepth),
        (4, 222, CssmSearch::CsmZ, SatVariant::Fixed, TwoDepth),
        (7, 223, CssmSearch::CsmZ, SatVariant::Fixed, Sharpen),
        (4, 224, CssmSearch::Moments, SatVariant::Float, TwoDepth),
        (7, 225, CssmSearch::Moments, SatVariant::Fixed, Sharpen),
        (
            5,
            226,
            CssmSearch::Moments,
            SatVariant::Fixed,
            TwoDepthSearch,
        ),
    ] {
        let technique = cssm_resolved(terms, 3.0, 10.0, kind, resolve);
        let seen = check_soft(
            &g,
            with_sums(technique, sums),
            seed,
            &|lin| {
                let search = match kind {
                    CssmSearch::Moments => cpu::msm::msm(lin, true),
                    CssmSearch::CsmZ => cpu::csm_z::csm_z(lin, terms),
                };
                vec![rounded(cpu::csm::csm(lin, terms)), rounded(search)]
            },
            &|t, l, s| {
                let maps = cpu::vis_cssm::Maps {
                    basis: &t[0],
                    search: &t[1],
                    kind,
                };
                cpu::vis_cssm::vis_cssm(maps, l, s)
            },
            &|t, e, l, s, v| {
                let maps = cpu::vis_cssm::Maps {
                    basis: &t[0],
                    search: &t[1],
                    kind,
                };
                common::soft::cssm_tolerance(maps, (&e[0], &e[1]), e_trig, l, s, v)
            },
        );
        eprintln!(
            "cssm M = {terms} {} {sums:?} {}: {seen}",
            kind.name(),
            resolve.name()
        );
    }
}

/// Distances of a rendered soft scene's visibility to an f64 PCSS of the same rasterized map
/// (64 blocker and 256 filter taps on the Vogel disc, the technique's search cap): the mean
/// |v − v_pcss| over covered pixels inside the map, the same over pixels where either is in
/// (0.02, 0.98) and, for scale, the mean |v_hard − v_pcss| of the f64 hard shadow test; and
/// how many pixels each of the technique and PCSS leaves in (0.02, 0.98).
struct Distance {
    mean: f64,
    penumbra: f64,
    hard: f64,
    hard_penumbra: f64,
    pixels: usize,
    partial: usize,
    pcss_partial: usize,
}

fn distance_to_pcss(g: &Gpu, renderer: &mut Renderer, scene: &Scene) -> Distance {
    let frame = renderer
        .render(
            &g.device,
            &g.queue,
            scene,
            shadowgraph::low_level::render::RenderOptions {
                aux: true,
                repeat: 1,
                dump: false,
            },
        )
        .expect("render");
    let light = &scene.lights[0];
    let mut lg = LightGpu::new(light);
    (lg.blocker_samples, lg.filter_samples) = (64, 256);
    let linear = frame.linear_maps[0].as_ref().expect("linear map");
    let map = cpu::Map {
        size: linear.width as usize,
        texels: &linear.data,
    };
    let (mut sum, mut hard, mut n, mut psum, mut pn, mut phard) = (0.0, 0.0, 0, 0.0, 0, 0.0);
    let (mut partial, mut pcss_partial) = (0, 0);
    for px in 0..(frame.width * frame.height) as usize {
        if frame.position[4 * px + 3] == 0.0 {
            continue;
        }
        let p = &frame.position[4 * px..4 * px + 3];
        let normal = &frame.normal[4 * px..4 * px + 3];
        let (p, normal) = (
            DVec3::new(p[0].into(), p[1].into(), p[2].into()),
            DVec3::new(normal[0].into(), normal[1].into(), normal[2].into()).normalize(),
        );
        let s = cpu::light::sample(&lg, p, normal);
        // Receivers facing away read 0 by definition (`light_faces`): no estimate to compare.
        if !s.inside || cpu::light::facing(&lg, p, normal) <= 0.0 {
            continue;
        }
        let pcss = cpu::vis_pcss::vis_pcss(&map, &lg, &s);
        let v = f64::from(frame.visibility[px * scene.lights.len()]);
        let h = (cpu::vis_hard::vis_hard(&map, &lg, &s) - pcss).abs();
        sum += (v - pcss).abs();
        hard += h;
        n += 1;
        let (soft, reference) = ((0.02..0.98).contains(&v), (0.02..0.98).contains(&pcss));
        partial += usize::from(soft);
        pcss_partial += usize::from(reference);
        if soft || reference {
            psum += (v - pcss).abs();
            phard += h;
            pn += 1;
        }
    }
    Distance {
        mean: sum / n as f64,
        penumbra: psum / pn.max(1) as f64,
        hard: hard / n as f64,
        hard_penumbra: phard / pn.max(1) as f64,
        pixels: n,
        partial,
        pcss_partial,
    }
}

#[test]
fn soft_scenes_approach_pcss() {
    // Not an accuracy claim (PCSS is itself an estimate; ground truth is area-light
    // sampling): a guard that each soft technique's whole chain still makes soft shadows where
    // PCSS does. On each bundled soft scene: mean |v − v_pcss| ≤ 0.05, and at least a third
    // as many penumbra pixels (visibility in (0.02, 0.98)) as PCSS leaves (hard shadows leave
    // almost none). A third, not more: PCSS widens the sphere's penumbra on vssm.toml well
    // past the area-light truth's (`shadowgraph evaluate`, 512² map, K = 64: penumbra error
    // PCSS 16 + 32 0.087, vssm 0.057), and vssm's blocker search in cells follows the truth.
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques");
    let mut failures = Vec::new();
    for name in ["cssm", "vssm", "msm_soft"] {
        let scene = Scene::load(root.join(format!("{name}.toml"))).expect("scene");
        let d = distance_to_pcss(&g, &mut renderer, &scene);
        let line = format!(
            "{name}.toml: mean |v − pcss| {:.4} over {} pixels, {:.4} in penumbrae (hard \
             shadows: {:.4}, {:.4}); penumbra pixels {} (PCSS {})",
            d.mean, d.pixels, d.penumbra, d.hard, d.hard_penumbra, d.partial, d.pcss_partial
        );
        eprintln!("{line}");
        if d.mean > 0.05 || 3 * d.partial < d.pcss_partial {
            failures.push(line);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
