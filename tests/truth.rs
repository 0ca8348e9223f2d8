//! Ground truth: the GPU area-light truth against the independent f64 CPU ray cast, a single
//! centre sample against the renderer's `hard` technique, and the brute-force PCF truth
//! against an independent supersampled integration.

mod common;

use std::path::Path;

use rand::Rng;
use shadowgraph::Technique;
use shadowgraph::low_level::cpu::Map;
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::pcf::{Receiver, pcf_box};
use shadowgraph::low_level::truth::raycast::{CpuTruth, ray_cast_truth};
use shadowgraph::low_level::truth::{Emitter, Truth, TruthOptions, area_light_truth, emitter};

fn scene(name: &str, width: u32, height: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = Scene::load(&path).expect("scene loads");
    s.width = width;
    s.height = height;
    s
}

/// How the GPU truth and a CPU ray cast compare on the pixels both call relevant.
struct Comparison {
    /// Pixels compared.
    compared: usize,
    /// Of those, the ray cast's penumbra (0.05 < v < 0.95) and umbra (v ≤ 0.05).
    penumbra: usize,
    umbra: usize,
    /// Pixels with |gpu − cpu| > 0.1.
    off: usize,
    /// Mean |gpu − cpu|.
    mean: f64,
    /// Pixels one side calls relevant and the other not.
    masks_disagree: usize,
}

fn compare(gpu: &Truth, cpu: &CpuTruth) -> Comparison {
    assert_eq!(gpu.visibility.len(), cpu.visibility.len());
    let mut c = Comparison {
        compared: 0,
        penumbra: 0,
        umbra: 0,
        off: 0,
        mean: 0.0,
        masks_disagree: 0,
    };
    for i in 0..gpu.mask.len() {
        c.masks_disagree += usize::from(gpu.mask[i] != cpu.mask[i]);
        if !(gpu.mask[i] && cpu.mask[i]) {
            continue;
        }
        let v = cpu.visibility[i];
        let d = (f64::from(gpu.visibility[i]) - v).abs();
        c.compared += 1;
        c.penumbra += usize::from(v > 0.05 && v < 0.95);
        c.umbra += usize::from(v <= 0.05);
        c.off += usize::from(d > 0.1);
        c.mean += d;
    }
    c.mean /= c.compared.max(1) as f64;
    c
}

/// The GPU truth against the ray cast with the same K = 256 emitter samples (so sampling
/// noise is common to both and cancels), at 128×96.
///
/// Bound: at most 1% of the compared pixels off by more than 0.1, mean |Δ| below 0.005, and
/// the masks disagreeing at most at 1% of them. Why a pixel may legitimately differ: (1) each
/// sample's 2048² map places a shadow edge within a texel (spot: ~0.005 world units on the
/// floor) and the bias (constant, slope and normal offset) moves it by about as much; a pixel
/// of a *narrow* penumbra, where many samples' edges pass within a texel, can then change by
/// more than 0.1; (2) the G-buffer's f32 raster and the f64 ray may hit different triangles at
/// silhouettes; (3) at the terminator of curved meshes the interpolated normal faces the
/// light while the facet does not, where the ray cast (no bias) sees the mesh itself and the
/// map (with bias) does not. Measured when this test was written: 0.16% (spot: 9 of 5773
/// pixels, mean 0.0007) and 0.05% (directional: 2 of 4493, mean 0.0003).
///
/// A negative control shows the check can fail: the ray cast with the emitter shrunk to its
/// centre (a hard shadow) must differ from the soft GPU truth at more than half the penumbra.
fn cross_check(name: &str, min_penumbra: usize) {
    let s = scene(name, 128, 96);
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let opts = TruthOptions {
        emitter: Emitter::Stratified { k: 256, seed: 7 },
        resolution: None,
    };
    let gpu = area_light_truth(&mut renderer, &g.device, &g.queue, &s, &opts).expect("truth");
    let cpu = ray_cast_truth(&s, &opts.emitter.offsets());
    let c = compare(&gpu, &cpu);
    eprintln!(
        "{name}: {} compared ({} penumbra, {} umbra), {} off by > 0.1 ({:.3}%), mean |Δ| {:.5}, masks disagree at {}",
        c.compared,
        c.penumbra,
        c.umbra,
        c.off,
        100.0 * c.off as f64 / c.compared as f64,
        c.mean,
        c.masks_disagree
    );
    assert!(
        c.compared > 2000,
        "{name}: only {} relevant pixels",
        c.compared
    );
    assert!(
        c.penumbra >= min_penumbra,
        "{name}: penumbra of {} pixels",
        c.penumbra
    );
    assert!(
        c.off * 100 <= c.compared,
        "{name}: {} of {} pixels off",
        c.off,
        c.compared
    );
    assert!(
        c.masks_disagree * 100 <= c.compared,
        "{name}: masks disagree at {}",
        c.masks_disagree
    );
    assert!(c.mean < 0.005, "{name}: mean |Δ| {}", c.mean);

    let hard = ray_cast_truth(&s, &emitter::centre_offset());
    let control = compare(&gpu, &hard);
    assert!(
        control.off * 2 > c.penumbra,
        "{name}: a hard-shadow ray cast differs from the soft truth at only {} pixels",
        control.off
    );
}

#[test]
fn gpu_truth_matches_ray_cast_spot() {
    cross_check("sphere_on_plane.toml", 150);
}

/// A point light's spherical emitter: the GPU's atlas of six faces per sample against the f64
/// ray cast to the same sample points.
#[test]
fn gpu_truth_matches_ray_cast_point() {
    cross_check("point.toml", 60);
}

#[test]
fn gpu_truth_matches_ray_cast_directional() {
    cross_check("pole.toml", 60);
}

/// One sample at the emitter's centre with the light's own map size is the light's hard shadow
/// map: the truth must equal the renderer's `hard` technique at every relevant pixel, exactly
/// (same raster pipeline and matrices, the `linearize` formula and `vis_hard`'s comparison
/// operation for operation). The spot, the directional and the point light, at 160×120.
#[test]
fn centre_sample_equals_hard_technique() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    for name in [
        "sphere_on_plane.toml",
        "pole.toml",
        "stacked.toml",
        "point.toml",
    ] {
        let mut s = scene(name, 160, 120);
        for l in &mut s.lights {
            l.shadow.technique = Technique::Hard;
        }
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
        let opts = TruthOptions {
            emitter: Emitter::Offsets(emitter::centre_offset()),
            resolution: Some(s.lights[0].shadow_map),
        };
        let truth = area_light_truth(&mut renderer, &g.device, &g.queue, &s, &opts).expect("truth");
        let (mut n, mut shadowed, mut differ) = (0, 0, 0);
        for (i, &m) in truth.mask.iter().enumerate() {
            if m {
                n += 1;
                shadowed += usize::from(truth.visibility[i] == 0.0);
                differ += usize::from(truth.visibility[i] != frame.visibility[i]);
            }
        }
        eprintln!("{name}: {n} relevant, {shadowed} shadowed, {differ} differ");
        assert!(
            n > 5000 && shadowed > 25,
            "{name}: {n} relevant, {shadowed} shadowed"
        );
        assert_eq!(
            differ, 0,
            "{name}: {differ} of {n} pixels differ from `hard`"
        );
    }
}

/// The PCF truth against an independent evaluation: midpoint supersampling of the comparison
/// over the box. With box centres on a 1/8-texel grid, widths on a 1/4-texel grid (so the edges
/// fall on the 1/8 grid) and 8 sub-samples per texel, every sub-cell lies inside one texel, so supersampling is exact and the two must agree to
/// 1e-12 (sums of multiples of 1/64). With arbitrary real centres and widths, M = 512
/// sub-samples per side misclassify at most a strip of 1/M of the box per texel boundary line
/// crossing it: the bound is (lines in x + lines in y) / M. Random blocky maps (61², not a
/// power of two), receivers reaching past the edge (clamp-to-edge), widths from 1/4 to 12.
#[test]
fn pcf_truth_matches_supersampling() {
    let mut rng = common::rng(42);
    let size = 61;
    let texels = common::blocky_map(&mut rng, size);
    let map = Map {
        size,
        texels: &texels,
    };
    let n = size as f64;
    let supersample = |r: &Receiver, width: f64, bias: f64, m: usize| {
        let (cx, cy) = (r.uv[0] * n, r.uv[1] * n);
        let mut lit = 0usize;
        for j in 0..m {
            let y = cy - 0.5 * width + (j as f64 + 0.5) * width / m as f64;
            for i in 0..m {
                let x = cx - 0.5 * width + (i as f64 + 0.5) * width / m as f64;
                lit += usize::from(r.depth <= map.load(x.floor() as i64, y.floor() as i64) + bias);
            }
        }
        lit as f64 / (m * m) as f64
    };
    let (mut partial, mut worst) = (0, 0.0f64);
    for case in 0..400 {
        let exact = case % 2 == 0;
        let (uv, width) = if exact {
            let grid = 61 * 8 + 16;
            let x = f64::from(rng.random_range(-16i32..grid)) / 8.0 / n;
            let y = f64::from(rng.random_range(-16i32..grid)) / 8.0 / n;
            ([x, y], f64::from(rng.random_range(1u32..=48)) / 4.0)
        } else {
            let x = rng.random_range(-0.05..1.05);
            let y = rng.random_range(-0.05..1.05);
            ([x, y], rng.random_range(0.3..12.0))
        };
        let r = Receiver {
            uv,
            depth: rng.random_range(0.1..0.95),
        };
        let bias = rng.random_range(0.0..0.01);
        let got = pcf_box(&map, &r, width, bias);
        partial += usize::from(got > 0.0 && got < 1.0);
        let (want, tol) = if exact {
            (
                supersample(&r, width, bias, (8.0 * width).round() as usize),
                1e-12,
            )
        } else {
            let m = 512;
            let lines = 2.0 * (width.ceil() + 1.0);
            (supersample(&r, width, bias, m), lines / m as f64)
        };
        worst = worst.max((got - want).abs() / tol);
        assert!(
            (got - want).abs() <= tol,
            "case {case}: pcf_box {got}, supersampled {want}, tolerance {tol}"
        );
    }
    eprintln!("{partial} of 400 boxes partly lit; worst error / tolerance {worst:.3}");
    assert!(partial > 100, "only {partial} boxes straddle an edge");
}

/// More emitter samples than `MAX_EMITTER_SAMPLES`, stratified or as explicit offsets, is an
/// `Error::Limit` naming K, before any offset is made (10⁸ asked for 50 GB at once and aborted
/// the process).
#[test]
fn too_many_emitter_samples_are_a_limit() {
    let s = scene("sphere_on_plane.toml", 32, 24);
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let most = shadowgraph::low_level::truth::MAX_EMITTER_SAMPLES;
    for emitter in [
        Emitter::Stratified {
            k: most as u32 + 1,
            seed: 7,
        },
        Emitter::Stratified {
            k: 100_000_000,
            seed: 7,
        },
        Emitter::Offsets(vec![[0.0, 0.0]; most + 1]),
    ] {
        let k = emitter.count();
        let opts = TruthOptions {
            emitter,
            resolution: Some(16),
        };
        match area_light_truth(&mut renderer, &g.device, &g.queue, &s, &opts) {
            Err(e @ shadowgraph::Error::Limit { .. }) => {
                let e = e.to_string();
                assert!(
                    e.contains("emitter samples") && e.contains(&k.to_string()),
                    "{e}"
                );
            }
            other => panic!("K = {k}: {:?}", other.map(|t| t.samples)),
        }
    }
}
