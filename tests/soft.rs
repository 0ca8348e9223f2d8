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

/// Runs the `csm_z` kernel for every chunk of `terms` terms at `storage` over `input`
/// (`w`×`h`), outputs poisoned with NaN first; returns each chunk's texels (its format's
/// channels).
fn csm_z_on_gpu(
    g: &Gpu,
    input: &[f32],
    (w, h): (u32, u32),
    terms: u32,
    storage: Storage,
) -> Vec<(usize, Vec<f32>)> {
    use shadowgraph::graph::{Dispatch, Graph, Node, SizeRule, plan};
    use shadowgraph::technique::{CsmParams, csm_z_channels, csm_z_maps, moments_format};
    let mut graph = Graph::default();
    graph.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
    let mut outputs = Vec::new();
    for chunk in 0..csm_z_maps(terms) {
        let n = (csm_z_channels(terms) - 4 * chunk).min(4);
        let out = format!("csm_z{chunk}");
        graph.resource(
            &out,
            moments_format(storage, n),
            SizeRule::Reduced {
                of: "in".into(),
                shift: 0,
            },
            Some(0),
        );
        graph.node(Node {
            name: out.clone(),
            kernel: "csm_z".into(),
            inputs: vec![("src".into(), "in".into())],
            outputs: vec![("dst".into(), out.clone())],
            params: bytemuck::bytes_of(&CsmParams {
                first_term: chunk,
                terms,
                _pad: [0; 2],
            })
            .to_vec(),
            dispatch: Dispatch::Texels(out.clone()),
            light: Some(0),
        });
        outputs.push(out);
    }
    let names: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let p = plan(&graph, &names).expect("plan");
    let texture = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test.csm_z.in"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    shadowgraph::gpu::write_texture(&g.queue, &texture, bytemuck::cast_slice(input));
    let imports = std::collections::HashMap::from([("in".to_string(), texture)]);
    let mut exec = shadowgraph::exec::Executor::new();
    let record = |exec: &mut shadowgraph::exec::Executor| {
        let mut enc = g.device.create_command_encoder(&Default::default());
        let out = exec
            .record(&g.device, &mut enc, &p, &imports, None)
            .expect("record");
        shadowgraph::gpu::submit_and_wait(&g.device, &g.queue, enc, "csm_z").expect("submit");
        out
    };
    let first = record(&mut exec);
    // Poison every output (NaN in its own texel format) and run again: unwritten texels show.
    for name in &outputs {
        let t = &first.textures[name];
        let texels = (w * h) as usize;
        let bytes: Vec<u8> = match t.format() {
            wgpu::TextureFormat::Rgba16Float => 0x7e00u16.to_le_bytes().repeat(4 * texels),
            f => {
                let n = shadowgraph::graph::texel_bytes(f) as usize / 4;
                f32::NAN.to_le_bytes().repeat(n * texels)
            }
        };
        shadowgraph::gpu::write_texture(&g.queue, t, &bytes);
    }
    let out = record(&mut exec);
    outputs
        .iter()
        .map(|name| {
            shadowgraph::gpu::read_float_texture(&g.device, &g.queue, &out.textures[name], 0)
                .expect("readback")
        })
        .collect()
}

#[test]
fn csm_z_encoding_matches_reference() {
    // Each channel z·sin(c_k z) or z·cos(c_k z) against f64: the device's sin/cos error (its
    // measured bound, checked against Vulkan's 2⁻¹¹ first) times z, plus the product's f32
    // rounding (2⁻²⁴); f16 storage adds an f16 step (2⁻¹⁰ relative: Vulkan may round toward
    // zero) and 2⁻¹⁴ absolute (f16's smallest normal: denormals may be flushed). Channels past 2M
    // are exactly 0 (the last map's padding), so no term leaks into the tables.
    let g = common::gpu();
    let e_trig = trig_error(&g);
    let mut rng = common::rng(230);
    let (w, h) = (257u32, 31u32);
    let mut input: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
    (input[0], input[1]) = (0.0, 1.0);
    let lin = Texels::from_f32(w as usize, h as usize, 1, &input);
    for (terms, storage) in [
        (7, Storage::F32),
        (4, Storage::F32),
        (1, Storage::F32),
        (5, Storage::F16),
    ] {
        let expected = cpu::csm_z::csm_z(&lin, terms);
        let (atol, rtol) = if storage == Storage::F16 {
            (2f64.powi(-14), 2f64.powi(-10))
        } else {
            (0.0, 0.0)
        };
        for (chunk, (stored, data)) in csm_z_on_gpu(&g, &input, (w, h), terms, storage)
            .into_iter()
            .enumerate()
        {
            let what = format!("csm_z M = {terms} {storage:?} map {chunk}");
            let (mut got, mut want, mut tol) = (Vec::new(), Vec::new(), Vec::new());
            for (t, texel) in data.chunks(stored).enumerate() {
                let z = f64::from(input[t]);
                for (c, &v) in texel.iter().enumerate() {
                    let i = 4 * chunk + c;
                    let r = expected.data.get(t * expected.channels + i).copied();
                    let r = if i < expected.channels { r } else { None };
                    got.push(v);
                    want.push(r.unwrap_or(0.0));
                    tol.push(match r {
                        Some(r) => e_trig * z + 2f64.powi(-24) + atol + rtol * r.abs(),
                        None => 0.0,
                    });
                }
            }
            common::assert_within(&what, &got, &want, &tol);
        }
    }
}

/// The CSM-Z, VSM and MSM blocker estimates read through fixed-point tables over random
/// squares (1–30 texels) at random receiver depths, on the GPU by a kernel of the test's own
/// around `shared/blocker`, against f64: `r = (z_avg, share, extra…)` per query.
fn blocker_harness(
    g: &Gpu,
    light: &LightGpu,
    tables: &[&[f32]],
    size: u32,
    queries: &[[f32; 4]],
    body: &str,
) -> Vec<[f32; 4]> {
    use wgpu::util::DeviceExt;
    let mut text = String::from(
        "// #import shared/light\n// #import shared/sat_lookup\n// #import shared/blocker\n\
         @group(0) @binding(0) var<storage, read> lights: array<Light>;\n\
         @group(0) @binding(1) var<storage, read> queries: array<vec4<f32>>;\n\
         @group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;\n",
    );
    for k in 0..tables.len() {
        text.push_str(&format!(
            "@group(0) @binding({}) var t{k}: texture_2d<u32>;\n",
            3 + k
        ));
    }
    text.push_str(&format!(
        "@compute @workgroup_size(64)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         let i = min(id.x, arrayLength(&queries) - 1u);\n    let l = lights[0];\n    \
         let q = queries[i];\n    var s: LightSample;\n    s.uv = q.xy;\n    s.depth = q.w;\n    \
         s.view_z = 1.0;\n    s.inside = true;\n    var r = vec4<f32>(0.0);\n    {body}\n    \
         if id.x < arrayLength(&queries) {{\n        results[i] = r;\n    }}\n}}\n"
    ));
    let wgsl = shadowgraph::kernels::resolve_source("test.blocker", &text).expect("resolve");
    let d = &g.device;
    let kernel = shadowgraph::exec::ComputeKernel::new(d, "blocker_harness", &wgsl)
        .expect("harness compiles");
    let buffer = |bytes: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.blocker"),
            contents: bytes,
            usage,
        })
    };
    let lights = buffer(bytemuck::bytes_of(light), wgpu::BufferUsages::STORAGE);
    let q = buffer(bytemuck::cast_slice(queries), wgpu::BufferUsages::STORAGE);
    let results = buffer(
        &vec![0u8; queries.len() * 16],
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let views: Vec<wgpu::TextureView> = tables
        .iter()
        .map(|words| {
            let t = d.create_texture(&wgpu::TextureDescriptor {
                label: Some("test.blocker.table"),
                size: wgpu::Extent3d {
                    width: size,
                    height: size,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            shadowgraph::gpu::write_texture(&g.queue, &t, bytemuck::cast_slice(words));
            t.create_view(&Default::default())
        })
        .collect();
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: lights.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: q.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: results.as_entire_binding(),
        },
    ];
    for (k, v) in views.iter().enumerate() {
        entries.push(wgpu::BindGroupEntry {
            binding: 3 + k as u32,
            resource: wgpu::BindingResource::TextureView(v),
        });
    }
    let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("test.blocker"),
        layout: &kernel.layouts[0],
        entries: &entries,
    });
    let readback = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test.blocker.readback"),
        size: results.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups((queries.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&results, 0, &readback, 0, results.size());
    shadowgraph::gpu::submit_and_wait(d, &g.queue, enc, "blocker harness").expect("submit");
    let raw = shadowgraph::gpu::read_buffer(d, &readback).expect("readback");
    bytemuck::cast_slice(&raw).to_vec()
}

/// Compares the harness's `(z_avg, share)` with f64 estimates: every sign combination of the
/// inputs' errors (`estimate(σ)` for σ of each input ∈ {−1, 1}, five scales as in
/// tests/common/soft.rs) bounds each; the tolerance is twice the largest change plus 1e-6.
/// z_avg counts only where every perturbation finds blockers. At least 10% of the queries
/// must have shares strictly between 0.05 and 0.95.
fn check_estimates(
    what: &str,
    gpu: &[[f32; 4]],
    estimate: &dyn Fn(usize, &[f64]) -> cpu::blocker::Blocker,
    inputs: usize,
) {
    let (mut got, mut want, mut tol) = (Vec::new(), Vec::new(), Vec::new());
    let mut partial = 0;
    for (i, r) in gpu.iter().enumerate() {
        let b0 = estimate(i, &vec![0.0; inputs]);
        let (mut dz, mut ds, mut all_found) = (0.0f64, 0.0f64, true);
        for scale in [1.0, 0.5, 0.25, 0.125, 0.0625] {
            for k in 0..(1u32 << inputs) {
                let sg: Vec<f64> = (0..inputs)
                    .map(|j| if k >> j & 1 == 1 { scale } else { -scale })
                    .collect();
                let b = estimate(i, &sg);
                ds = ds.max((b.share - b0.share).abs());
                dz = dz.max((b.depth - b0.depth).abs());
                all_found &= b.found();
            }
        }
        partial += usize::from(b0.share > 0.05 && b0.share < 0.95);
        got.push(r[1]);
        want.push(b0.share);
        tol.push(1e-6 + 2.0 * ds);
        if all_found && b0.found() {
            got.push(r[0]);
            want.push(b0.depth);
            tol.push(1e-6 + 2.0 * dz);
        }
    }
    assert!(
        partial * 10 >= gpu.len(),
        "{what}: only {partial} of {} shares strictly between 0.05 and 0.95",
        gpu.len()
    );
    common::assert_within(what, &got, &want, &tol);
}

/// Random queries `(u, v, width, d)`.
fn queries(rng: &mut impl Rng, n: usize) -> Vec<[f32; 4]> {
    (0..n)
        .map(|_| {
            [
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
                rng.random_range(1.0..30.0),
                rng.random_range(0.05..0.98),
            ]
        })
        .collect()
}

#[test]
fn blocker_estimates_match_reference() {
    // Inputs and errors: the table means (f32 weighting of exact windows, `TableError`), the
    // receiver depth exact (the query's f32); MSM's moments also carry Cholesky's backward
    // error (32·2⁻²⁴ relative), CSSM's series the device's sin/cos error per term.
    let g = common::gpu();
    let e_trig = trig_error(&g);
    let mut rng = common::rng(240);
    let linear = common::blocky_map(&mut rng, MAP);
    let lin = Texels::from_f32(MAP, MAP, 1, &linear);
    let q = queries(&mut rng, 4000);
    let sample = |q: &[f32; 4]| cpu::light::LightSample {
        uv: [f64::from(q[0]), f64::from(q[1])],
        depth: f64::from(q[3]),
        view_z: 1.0,
        inside: true,
    };

    // VSM: (μ, E[z²]) ± their errors.
    let l = light(DIR, vssm(SatVariant::Fixed));
    let lg = LightGpu::new(&l);
    let coding = sat_coding(&l).expect("coding").expect("table");
    let t = tables(&rounded(cpu::vsm::vsm(&lin)), &coding);
    let (integral, err) = (
        Integral::new(&t.decoded),
        TableError::new(&t.decoded, &coding),
    );
    let body = "let m = sat_sample_fixed(t0, l, s.uv, q.z);\n    \
                r = vec4<f32>(blocker_vsm(m, q.w, l.min_variance), m.xy);";
    let gpu = blocker_harness(&g, &lg, &[&t.words[0]], MAP as u32, &q, body);
    check_estimates(
        "blocker_vsm",
        &gpu,
        &|i, sg| {
            let s = sample(&q[i]);
            let w = f64::from(q[i][2]);
            let e = err.mean(&lg, &s, w);
            let mut m = integral.square_mean(lg.map_size, s.uv, w);
            m[0] += sg[0] * e[0];
            m[1] += sg[1] * e[1];
            cpu::blocker::vsm(&m, s.depth, f64::from(lg.min_variance))
        },
        2,
    );

    // MSM: the biased moments ± the table error (raw f32 moments) and Cholesky's.
    let l = light(DIR, msm_soft(Storage::F32, false));
    let lg = LightGpu::new(&l);
    let coding = sat_coding(&l).expect("coding").expect("table");
    let t = tables(&rounded(cpu::msm::msm(&lin, false)), &coding);
    let (integral, err) = (
        Integral::new(&t.decoded),
        TableError::new(&t.decoded, &coding),
    );
    let body = "let m = sat_sample_fixed(t0, l, s.uv, q.z);\n    \
                r = vec4<f32>(blocker_msm(msm_biased(m, l), q.w), 0.0, 0.0);";
    let gpu = blocker_harness(&g, &lg, &[&t.words[0]], MAP as u32, &q, body);
    check_estimates(
        "blocker_msm",
        &gpu,
        &|i, sg| {
            let s = sample(&q[i]);
            let w = f64::from(q[i][2]);
            let e = err.mean(&lg, &s, w);
            let m = integral.square_mean(lg.map_size, s.uv, w);
            let b = cpu::vis_msm::biased(&m, &lg);
            let p: [f64; 4] =
                std::array::from_fn(|c| b[c] + sg[c] * (e[c] + 32.0 * 2f64.powi(-24) * b[c].abs()));
            cpu::blocker::msm(p, s.depth)
        },
        4,
    );

    // CSM-Z (M = 3: two basis tables, two CSM-Z tables): the series E[f] − ½ and E[f̄·z]
    // themselves, then the estimate from them.
    let terms = 3;
    let l = light(DIR, cssm(terms, 0.0, 0.0));
    let lg = LightGpu::new(&l);
    let coding = sat_coding(&l).expect("coding").expect("table");
    let basis = tables(&rounded(cpu::csm::csm(&lin, terms)), &coding);
    let z = tables(&rounded(cpu::csm_z::csm_z(&lin, terms)), &coding);
    let (ib, iz) = (Integral::new(&basis.decoded), Integral::new(&z.decoded));
    let (eb, ez) = (
        TableError::new(&basis.decoded, &coding),
        TableError::new(&z.decoded, &coding),
    );
    let body = "var below = 0.0;\n    \
                below += csm_chunk_of(sat_sample_fixed(t0, l, s.uv, q.z), 0u, l, s);\n    \
                below += csm_chunk_of(sat_sample_fixed(t1, l, s.uv, q.z), 1u, l, s);\n    \
                var zsum = 0.0;\n    \
                zsum += csm_z_chunk_of(sat_sample_fixed(t2, l, s.uv, q.z), 0u, l, s);\n    \
                zsum += csm_z_chunk_of(sat_sample_fixed(t3, l, s.uv, q.z), 1u, l, s);\n    \
                r = vec4<f32>(blocker_csm_z(below, zsum, q.w), below, zsum);";
    let words: Vec<&[f32]> = basis
        .words
        .iter()
        .chain(&z.words)
        .map(Vec::as_slice)
        .collect();
    let gpu = blocker_harness(&g, &lg, &words, MAP as u32, &q, body);
    let series = |i: usize| {
        let s = sample(&q[i]);
        let w = f64::from(q[i][2]);
        let d = cpu::vis_csm::shifted_depth(&lg, &s);
        let below = cpu::vis_csm::series(&ib.square_mean(lg.map_size, s.uv, w), &lg, d);
        let zsum = cpu::blocker::csm_z_series(&iz.square_mean(lg.map_size, s.uv, w), &lg, d);
        // Per term: two factors off by e_trig against values ≤ 1, two means off by e.
        let weights: f64 = (1..=terms).map(|k| cpu::vis_csm::weight(k, &lg)).sum();
        let max = |e: [f64; 4]| e.iter().copied().fold(0.0, f64::max);
        let e_below = weights * 2.0 * (e_trig + max(eb.mean(&lg, &s, w))) + 16.0 * 2f64.powi(-24);
        let e_z = max(ez.mean(&lg, &s, w));
        let e_zsum = weights * 2.0 * (e_trig + e_z) + 0.5 * e_z + 16.0 * 2f64.powi(-24);
        ((below, e_below), (zsum, e_zsum), s.depth)
    };
    let (mut got, mut want, mut tol) = (Vec::new(), Vec::new(), Vec::new());
    for (i, r) in gpu.iter().enumerate() {
        let ((below, e_below), (zsum, e_zsum), _) = series(i);
        got.extend([r[2], r[3]]);
        want.extend([below, zsum]);
        tol.extend([e_below, e_zsum]);
    }
    common::assert_within("CSM-Z series", &got, &want, &tol);
    check_estimates(
        "blocker_csm_z",
        &gpu,
        &|i, sg| {
            let ((below, e_below), (zsum, e_zsum), d) = series(i);
            cpu::blocker::csm_z(below + sg[0] * e_below, zsum + sg[1] * e_zsum, d)
        },
        2,
    );
}
