//! The soft techniques (`cssm`, `vssm`, `msm_soft`) against their f64 references: the CSM-Z
//! encoding; the blocker estimates read through summed-area tables over random squares; the
//! whole visibility (search square → blocker → penumbra width → lookup) through the real
//! shading kernel on random blocky maps, directional and spot. Tolerances are propagated
//! through the f64 references by perturbation (tests/common/soft.rs). Last, each bundled soft
//! scene's distance to an f64 PCSS on the same rasterized map.

mod common;

use common::soft::{TableError, trig_error};
use glam::{DVec3, Vec3};
use rand::Rng;
use shadowgraph::cpu::sat::Integral;
use shadowgraph::cpu::{self, Texels};
use shadowgraph::gpu::Gpu;
use shadowgraph::render::{ProbeMap, Renderer, probe};
use shadowgraph::sat::{SatCoding, SatVariant};
use shadowgraph::scene::{Light, LightKind, Shadow, Soft, Storage, Technique};
use shadowgraph::technique::{LightGpu, sat_coding};

const MAP: usize = 61; // not a power of two
const DIR: LightKind = LightKind::Directional { extent: 5.0 };
const SPOT: LightKind = LightKind::Spot { fov_degrees: 60.0 };

fn soft(storage: Storage, sums: SatVariant) -> Soft {
    Soft {
        storage,
        sums,
        max_search: 0.25,
    }
}

/// A light over the random map: search squares of about 10 (directional, 2 units wide) and
/// 30 texels (spot, 0.3 wide), capped at 30.5 texels (`max_search` 0.25 of 61).
fn light(kind: LightKind, technique: Technique) -> Light {
    let (position, near, far, size) = match kind {
        LightKind::Directional { .. } => (Vec3::new(-3.0, 10.0, 2.0), 2.0, 20.0, 2.0),
        LightKind::Spot { .. } => (Vec3::new(1.0, 8.0, -1.0), 0.5, 20.0, 0.3),
    };
    Light {
        kind,
        position,
        target: Vec3::ZERO,
        near,
        far,
        size,
        radiance: Vec3::ONE,
        shadow_map: MAP as u32,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 0.0,
            normal_bias: 1.0,
        },
    }
}

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

/// A representation's summed-area tables, four channels each, as the GPU would hold them.
struct Tables {
    /// Per table, its words (fixed: u32 bit patterns as f32; float: f32 sums).
    words: Vec<Vec<f32>>,
    /// The tables' format.
    format: wgpu::TextureFormat,
    /// What the tables sum, decoded (the fixed variant's exact quantized values), in the
    /// representation's channel layout: the values the lookups integrate.
    decoded: Texels,
}

/// The tables of `rep` (rounded to f32 as a texture stores it) coded by `coding`. A float
/// table is the f64 SAT of the centred values rounded to f32 (the GPU builds its own; what
/// matters here is that the reference integrates what this table holds).
fn tables(rep: &Texels, coding: &SatCoding) -> Tables {
    let (w, h) = (rep.width, rep.height);
    let mut words = Vec::new();
    let mut chunks = Vec::new();
    for first in (0..rep.channels).step_by(4) {
        let n = (rep.channels - first).min(4);
        let chunk = Texels {
            width: w,
            height: h,
            channels: n,
            data: rep
                .data
                .chunks(rep.channels)
                .flat_map(|t| t[first..first + n].iter().map(|&v| f64::from(v as f32)))
                .collect(),
        };
        let raw: Vec<u32> = match coding.variant {
            SatVariant::Fixed => cpu::sat::sat_fixed(&chunk, coding)
                .into_iter()
                .flatten()
                .collect(),
            SatVariant::Float => cpu::sat::sat(&cpu::sat::scaled_texels(&chunk, coding))
                .data
                .iter()
                .map(|&v| (v as f32).to_bits())
                .collect(),
        };
        chunks.push((n, shadowgraph::sat::decode_table(&raw, w, h, coding, n)));
        words.push(raw.into_iter().map(f32::from_bits).collect());
    }
    let data = (0..w * h)
        .flat_map(|t| {
            chunks
                .iter()
                .flat_map(move |(n, d)| d[t * n..(t + 1) * n].iter().map(|&v| f64::from(v)))
        })
        .collect();
    Tables {
        words,
        format: coding.variant.format(),
        decoded: Texels {
            width: w,
            height: h,
            channels: rep.channels,
            data,
        },
    }
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
        let decoded: Vec<Integral> = tabs.iter().map(|t| Integral::new(&t.decoded)).collect();
        let maps: Vec<ProbeMap> = tabs
            .iter()
            .flat_map(|t| {
                t.words
                    .iter()
                    .map(|w| ProbeMap::new(MAP as u32, t.format, w))
            })
            .collect();
        let points: Vec<(Vec3, Vec3)> = (0..3000).map(|_| point(&l, &mut rng)).collect();
        let mut renderer = Renderer::new(&g.device);
        let vis = probe(
            &mut renderer,
            &g.device,
            &g.queue,
            std::slice::from_ref(&l),
            &maps,
            &points,
        )
        .expect("probe");
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

/// f32 rounding of a representation, as a texture stores it.
fn rounded(t: Texels) -> Texels {
    Texels {
        data: t.data.iter().map(|&v| f64::from(v as f32)).collect(),
        ..t
    }
}

fn vssm(sums: SatVariant) -> Technique {
    Technique::Vssm {
        soft: soft(Storage::F32, sums),
        bleed: 0.1,
        min_variance: 1e-5,
    }
}

#[test]
fn vssm_matches_reference() {
    // Tolerance (tests/common/soft.rs): the table means' f32 weighting (and, for the float
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

fn msm_soft(storage: Storage, hausdorff: bool) -> Technique {
    Technique::MsmSoft {
        soft: soft(storage, SatVariant::Fixed),
        hausdorff,
        moment_bias: shadowgraph::scene::default_moment_bias(storage),
        bleed: 0.0,
    }
}

#[test]
fn msm_soft_matches_reference() {
    // Tolerance: as VSSM's, with the moments perturbed in the moment domain (the table error
    // carried through the dequantization, plus Cholesky's backward error, 32·2⁻²⁴ relative).
    // The quantized case reads the f32 quantized moments (only the flag and bias differ).
    let g = common::gpu();
    for (storage, hausdorff, seed) in [
        (Storage::F32, false, 210),
        (Storage::F32, true, 211),
        (Storage::Unorm16, false, 212),
    ] {
        let quantized = storage != Storage::F32;
        let seen = check_soft(
            &g,
            msm_soft(storage, hausdorff),
            seed,
            &|lin| vec![rounded(cpu::msm::msm(lin, quantized))],
            &|t, l, s| cpu::vis_msm_soft::vis_msm_soft(&t[0], l, s),
            &|t, e, l, s, v| common::soft::msm_soft_tolerance(&t[0], &e[0], l, s, v),
        );
        eprintln!("msm_soft {storage:?} hausdorff {hausdorff}: {seen}");
    }
}

fn cssm(terms: u32, sharpen: f32, sharpen_falloff: f32) -> Technique {
    Technique::Cssm {
        soft: soft(Storage::F32, SatVariant::Fixed),
        terms,
        attenuation: 1.0,
        offset: 0.5 / terms as f32,
        scale: 2.0,
        sharpen,
        sharpen_falloff,
    }
}

#[test]
fn cssm_matches_reference() {
    // Tolerance: the series carry the device's measured sin/cos error (checked against
    // Vulkan's 2⁻¹¹ first) and the means' errors per term; then as VSSM's, plus the f32
    // exp2/log2 of the sharpening v^p. Sharpening A = 3, B = 10 per depth unit, so that most
    // penumbra points are sharpened noticeably.
    let g = common::gpu();
    let e_trig = trig_error(&g);
    eprintln!("device sin/cos error (×2 + 2⁻²⁴): {e_trig:.2e}");
    for (terms, seed) in [(4, 220), (7, 221)] {
        let seen = check_soft(
            &g,
            cssm(terms, 3.0, 10.0),
            seed,
            &|lin| {
                vec![
                    rounded(cpu::csm::csm(lin, terms)),
                    rounded(cpu::csm_z::csm_z(lin, terms)),
                ]
            },
            &|t, l, s| {
                let maps = cpu::vis_cssm::Maps {
                    basis: &t[0],
                    z: &t[1],
                };
                cpu::vis_cssm::vis_cssm(maps, l, s)
            },
            &|t, e, l, s, v| {
                let maps = cpu::vis_cssm::Maps {
                    basis: &t[0],
                    z: &t[1],
                };
                common::soft::cssm_tolerance(maps, (&e[0], &e[1]), e_trig, l, s, v)
            },
        );
        eprintln!("cssm M = {terms}: {seen}");
    }
}
