//! The blocker kernels of the soft techniques against f64: the `csm_z` encoding (the CSM-Z
//! basis images z, z·sin c_k z, z·cos c_k z), and the blocker estimates of
//! `kernels/shared/blocker.wgsl` (CSM-Z, VSM, MSM) read through fixed-point summed-area tables
//! over random squares of random blocky maps, evaluated on the GPU by a kernel of the test's
//! own around the module.

mod common;

use common::soft::TableError;
use common::soft_maps::{DIR, MAP, cssm, msm_soft, rounded, tables, trig_error, vssm};
use rand::Rng;
use shadowgraph::low_level::cpu::sat::Integral;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::technique::sat_coding;
use shadowgraph::{CssmSearch, LightGpu, SatVariant, Storage};

/// Runs the `csm` kernel's CSM-Z maps (one map a dispatch) for every chunk of `terms` terms at `storage` over `input`
/// (`w`×`h`), outputs poisoned with NaN first; returns each chunk's texels (its format's
/// channels).
fn csm_z_on_gpu(
    g: &Gpu,
    input: &[f32],
    (w, h): (u32, u32),
    terms: u32,
    storage: Storage,
) -> Vec<(usize, Vec<f32>)> {
    use shadowgraph::low_level::graph::{Dispatch, Graph, Node, SizeRule, plan};
    use shadowgraph::low_level::technique::{csm_maps, csm_z_channels, csm_z_maps, moments_format};
    use shadowgraph::low_level::wgsl_mirrors::{CsmParams, LinearizeParams};
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
            kernel: shadowgraph::low_level::kernels::KernelId::Csm,
            inputs: vec![("src".into(), "in".into())],
            outputs: vec![("dst0".into(), out.clone())],
            // Orthographic depth in [0, 1] is read as linear depth unchanged.
            params: bytemuck::bytes_of(&CsmParams {
                depth: LinearizeParams::ORTHOGRAPHIC,
                first_map: csm_maps(terms) + chunk,
                maps: 1,
                terms,
                moments: 0,
            })
            .to_vec(),
            dispatch: Dispatch::Texels(out.clone()),
            light: Some(0),
        });
        outputs.push(out);
    }
    let names: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let p = plan(&graph, &names).expect("plan");
    let texture = common::upload(
        &g.device,
        &g.queue,
        "test.csm_z.in",
        (w, h),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(input),
    );
    let imports = std::collections::HashMap::from([("in".to_string(), texture)]);
    let mut exec = shadowgraph::low_level::exec::Executor::new();
    let record = |exec: &mut shadowgraph::low_level::exec::Executor| {
        let mut enc = g.device.create_command_encoder(&Default::default());
        let out = exec
            .record(&g.device, &mut enc, &p, &imports, None)
            .expect("record");
        shadowgraph::low_level::gpu::submit_and_wait(&g.device, &g.queue, enc, "csm_z")
            .expect("submit");
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
                let n = shadowgraph::low_level::graph::texel_bytes(f) as usize / 4;
                f32::NAN.to_le_bytes().repeat(n * texels)
            }
        };
        shadowgraph::low_level::gpu::write_texture(&g.queue, t, &bytes);
    }
    let out = record(&mut exec);
    outputs
        .iter()
        .map(|name| {
            shadowgraph::low_level::gpu::read_float_texture(
                &g.device,
                &g.queue,
                &out.textures[name],
                0,
            )
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
    let wgsl =
        shadowgraph::low_level::kernels::resolve_source("test.blocker", &text).expect("resolve");
    let d = &g.device;
    let kernel = shadowgraph::low_level::exec::ComputeKernel::new(d, "blocker_harness", &wgsl)
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
            let t = common::upload(
                d,
                &g.queue,
                "test.blocker.table",
                (size, size),
                wgpu::TextureFormat::Rgba32Uint,
                bytemuck::cast_slice(words),
            );
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
    shadowgraph::low_level::gpu::submit_and_wait(d, &g.queue, enc, "blocker harness")
        .expect("submit");
    let raw = shadowgraph::low_level::gpu::read_buffer(d, &readback).expect("readback");
    bytemuck::cast_slice(&raw).to_vec()
}

/// Compares the harness's `(z_avg, share)` with f64 estimates: every sign combination of the
/// inputs' errors (`estimate(σ)` for σ of each input ∈ {−1, 1}, five scales as in
/// tests/common/soft/) bounds each; the tolerance is twice the largest change plus 1e-6.
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
        footprint: [0.0; 4],
        depth_slope: [0.0; 2],
    };

    // VSM: (μ, E[z²]) ± their errors.
    let l = common::soft_maps::light(DIR, vssm(SatVariant::Fixed));
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

    // MSM: the moments ± the table error (carried through the dequantization) and the solve's
    // backward error, then projected and biased as the kernel does.
    let l = common::soft_maps::light(DIR, msm_soft(Storage::F32, false));
    let lg = LightGpu::new(&l);
    let coding = sat_coding(&l).expect("coding").expect("table");
    let quantized = shadowgraph::low_level::technique::msm_quantized(&l.shadow.technique);
    let t = tables(&rounded(cpu::msm::msm(&lin, quantized)), &coding);
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
            let b = cpu::vis_msm::dequantized(&m, &lg);
            let p: [f64; 4] =
                std::array::from_fn(|c| b[c] + sg[c] * (e[c] + 32.0 * 2f64.powi(-24) * b[c].abs()));
            cpu::blocker::msm(&cpu::vis_msm::bias_for(p, &lg), s.depth)
        },
        4,
    );

    // CSM-Z (M = 3: two basis tables, two CSM-Z tables): the series E[f] − ½ and E[f̄·z]
    // themselves, then the estimate from them.
    let terms = 3;
    let l = common::soft_maps::light(DIR, cssm(terms, 0.0, 0.0, CssmSearch::CsmZ));
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
