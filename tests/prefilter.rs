//! Encodings and filters on the GPU against their f64 references, on random maps of sizes
//! that are and are not multiples of the workgroup; the plan of a prefiltered light.

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{Gpu, read_resource_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, SizeRule, plan};
use shadowgraph::{BlurKernel, Filter};

fn upload(g: &Gpu, w: u32, h: u32, format: wgpu::TextureFormat, data: &[f32]) -> wgpu::Texture {
    let data = bytemuck::cast_slice(data);
    common::upload(&g.device, &g.queue, "test.input", (w, h), format, data)
}

/// The layouts the encodings are checked in: the device's, and the redesign (each invocation
/// encoding several texels), which must give the same maps bit for bit.
const ENCODE_LAYOUTS: [Option<KernelLayout>; 2] = [None, Some(KernelLayout::Redesign)];

/// Plans `graph` for `output`, runs it with `input` imported as "in" (the output poisoned with
/// NaN first, so unwritten texels show) and reads the output back.
fn run(g: &Gpu, graph: &Graph, output: &str, input: wgpu::Texture) -> Texels {
    run_levels(g, graph, output, input).swap_remove(0)
}

/// [`run`] with the kernels compiled in `layout` (the device's with `None`).
fn run_in(
    g: &Gpu,
    graph: &Graph,
    output: &str,
    input: wgpu::Texture,
    layout: Option<KernelLayout>,
) -> Texels {
    run_levels_in(g, graph, output, input, layout).swap_remove(0)
}

/// [`run_in`] in each of [`ENCODE_LAYOUTS`] on a fresh upload of the r32float `depth` (`w × h`);
/// with `same`, the maps of every layout the same bit for bit (an encoding alone: the redesign
/// keeps each texel's arithmetic), else each is checked against the reference by the caller.
fn run_layouts(
    g: &Gpu,
    graph: &Graph,
    output: &str,
    (w, h, depth): (u32, u32, &[f32]),
    same: bool,
) -> Vec<Texels> {
    let runs: Vec<Texels> = ENCODE_LAYOUTS
        .iter()
        .map(|&layout| {
            let input = upload(g, w, h, wgpu::TextureFormat::R32Float, depth);
            run_in(g, graph, output, input, layout)
        })
        .collect();
    if same {
        for (run, layout) in runs.iter().zip(ENCODE_LAYOUTS).skip(1) {
            common::assert_same_bits(&format!("{output} {w}x{h} {layout:?}"), &runs[0], run);
        }
    }
    runs
}

/// [`run`], reading back every mip level of the output.
fn run_levels(g: &Gpu, graph: &Graph, output: &str, input: wgpu::Texture) -> Vec<Texels> {
    run_levels_in(g, graph, output, input, None)
}

/// [`run_levels`] with the kernels compiled in `layout` (the device's with `None`).
fn run_levels_in(
    g: &Gpu,
    graph: &Graph,
    output: &str,
    input: wgpu::Texture,
    layout: Option<KernelLayout>,
) -> Vec<Texels> {
    let plan = plan(graph, &[output]).expect("plan");
    let mut exec = Executor::new();
    if let Some(layout) = layout {
        exec.kernels.set_layout(layout);
    }
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let first = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "warm").unwrap();
    let out_tex = &first.textures[output];
    let (w, h) = (out_tex.width(), out_tex.height());
    let format = plan.resource(output).expect("planned").resource.format;
    if shadowgraph::low_level::graph::is_packed(format) && out_tex.mip_level_count() == 1 {
        // Two NaN halves a word.
        write_texture(&g.queue, out_tex, &vec![0xFF; (w * h) as usize * 4]);
    }
    let poison_channels = if out_tex.format() == wgpu::TextureFormat::Rg32Float {
        2
    } else {
        4
    };
    let f32_texels =
        shadowgraph::low_level::graph::texel_bytes(out_tex.format()) == 4 * poison_channels as u64;
    if f32_texels && out_tex.mip_level_count() == 1 {
        write_texture(
            &g.queue,
            out_tex,
            bytemuck::cast_slice(&vec![f32::NAN; (w * h) as usize * poison_channels]),
        );
    }
    let mut enc = g.device.create_command_encoder(&Default::default());
    let outputs = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "run").unwrap();
    let t = &outputs.textures[output];
    (0..t.mip_level_count())
        .map(|level| {
            let (c, v) = read_resource_texture(&g.device, &g.queue, t, level, format).unwrap();
            let (lw, lh) = ((w >> level).max(1), (h >> level).max(1));
            Texels::from_f32(lw as usize, lh as usize, c, &v)
        })
        .collect()
}

fn random_linear(rng: &mut impl Rng, w: usize, h: usize) -> Vec<f32> {
    // Smooth ramps plus steps: both the derivative term and silhouettes are exercised.
    let (a, b): (f32, f32) = (rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3));
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let step = if rng.random_bool(0.05) {
                rng.random_range(-0.3..0.0)
            } else {
                0.0
            };
            (0.5 + a * x + b * y + step + rng.random_range(0.0..0.01)).clamp(0.0, 1.0)
        })
        .collect()
}

fn vsm_graph(
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    filter: Option<Filter>,
) -> (Graph, String) {
    let params = shadowgraph::low_level::wgsl_mirrors::VsmParams {
        depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::ORTHOGRAPHIC,
    };
    encode_graph(
        "vsm",
        bytemuck::bytes_of(&params).to_vec(),
        w,
        h,
        format,
        filter,
        shadowgraph::low_level::filter::BlurMode::Linear,
    )
}

/// `in` → encoding `kernel` (params) → optional blur in `mode`. With orthographic depth
/// params (`LinearizeParams::ORTHOGRAPHIC`) the encodings read `in`'s values in [0, 1] as
/// linear depth unchanged.
fn encode_graph(
    kernel: &str,
    params: Vec<u8>,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    filter: Option<Filter>,
    mode: shadowgraph::low_level::filter::BlurMode,
) -> (Graph, String) {
    let mut g = Graph::default();
    g.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
    // Reuse the technique's own node builders through a light-independent graph.
    g.resource(
        "light0.vsm",
        format,
        SizeRule::Reduced {
            of: "in".into(),
            shift: 0,
        },
        Some(0),
    );
    g.node(shadowgraph::low_level::graph::Node {
        name: "light0.vsm".into(),
        kernel: shadowgraph::low_level::kernels::KernelId::from_name(kernel).expect("a kernel"),
        inputs: vec![("src".into(), "in".into())],
        // `csm` names its outputs dst0 … dst3.
        outputs: vec![(
            if kernel == "csm" { "dst0" } else { "dst" }.into(),
            "light0.vsm".into(),
        )],
        params,
        dispatch: shadowgraph::low_level::graph::Dispatch::Texels("light0.vsm".into()),
        light: Some(0),
    });
    let out = match filter {
        Some(f) => shadowgraph::low_level::filter::add_filter(&mut g, 0, "light0.vsm", &f, mode),
        None => "light0.vsm".to_string(),
    };
    (g, out)
}

/// Keeps the first `n` channels of every texel.
fn channels(t: &Texels, n: usize) -> Vec<f32> {
    t.data
        .chunks(t.channels)
        .flat_map(|c| c[..n].iter().map(|&v| v as f32))
        .collect()
}

#[test]
fn vsm_encoding_matches_reference() {
    let g = common::gpu();
    let mut rng = common::rng(40);
    for (w, h) in [(1000u32, 37u32), (64, 64), (1, 1), (5, 300)] {
        let lin = random_linear(&mut rng, w as usize, h as usize);
        let (graph, out) = vsm_graph(w, h, wgpu::TextureFormat::Rg32Float, None);
        let reference = cpu::vsm::vsm(&Texels::from_f32(w as usize, h as usize, 1, &lin));
        let mut first = None;
        for layout in ENCODE_LAYOUTS {
            let depth = upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin);
            let gpu = run_in(&g, &graph, &out, depth, layout);
            // f32: z exact; z² + ¼(dx² + dy²) is a handful of roundings of values ≤ 1.25.
            common::assert_close(
                &format!("vsm {w}x{h} {layout:?}"),
                &channels(&gpu, 2),
                &reference.data,
                1e-6,
                1e-6,
            );
            match &first {
                None => first = Some(gpu),
                Some(a) => common::assert_same_bits(&format!("vsm {w}x{h} layouts"), a, &gpu),
            }
        }
    }
}

#[test]
fn blur_matches_reference_for_each_kernel_and_storage() {
    let g = common::gpu();
    let mut rng = common::rng(41);
    let cases = [
        (1000u32, 37u32, 2.0f32, 1.0f32, BlurKernel::Gaussian),
        (130, 129, 7.5, 0.0, BlurKernel::Box),
        (64, 64, 32.0, 11.0, BlurKernel::Gaussian),
        (3, 200, 4.25, 0.0, BlurKernel::Box),
        (1, 1, 3.0, 1.5, BlurKernel::Gaussian),
    ];
    for (w, h, radius, sigma, kernel) in cases {
        let lin = random_linear(&mut rng, w as usize, h as usize);
        let moments = cpu::vsm::vsm(&Texels::from_f32(w as usize, h as usize, 1, &lin));
        let filter = Filter::Blur {
            radius,
            sigma: sigma.max(0.5),
            kernel,
        };
        let expected = cpu::blur::blur(
            &moments,
            f64::from(radius),
            f64::from(sigma.max(0.5)),
            kernel,
        );
        for (format, atol, rtol) in [
            // f32: ≤ 65 weighted terms per pass, two passes: well under 1e-6 absolute.
            (wgpu::TextureFormat::Rg32Float, 1e-6, 1e-6),
            // f16: three stores (encode, blur_h, blur_v), each may lose a whole ulp — Vulkan lets
            // the f16 conversion round toward zero — so 3 · 2⁻¹⁰ relative.
            (
                wgpu::TextureFormat::Rgba16Float,
                1e-4,
                3.0 * (2.0f64).powi(-10),
            ),
            // The same f16 values packed two to an r32uint word (what `format = "f16"` VSM
            // stores): the same three roundings.
            (
                shadowgraph::PACKED_F16X2,
                1e-4,
                3.0 * (2.0f64).powi(-10),
            ),
        ] {
            let (graph, out) = vsm_graph(w, h, format, Some(filter));
            let what = format!("blur {w}x{h} r{radius} {kernel:?} {format:?}");
            let input = upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin);
            let gpu = run(&g, &graph, &out, input);
            common::assert_close(&what, &channels(&gpu, 2), &expected.data, atol, rtol);
        }
    }
}

#[test]
fn blur_of_a_constant_map_is_the_constant_up_to_the_edges() {
    let g = common::gpu();
    let (w, h) = (200u32, 90u32);
    let constant = vec![0.7f32; (w * h) as usize];
    let filter = Filter::Blur {
        radius: 20.0,
        sigma: 8.0,
        kernel: BlurKernel::Gaussian,
    };
    let (graph, out) = vsm_graph(w, h, wgpu::TextureFormat::Rg32Float, Some(filter));
    let gpu = run(
        &g,
        &graph,
        &out,
        upload(&g, w, h, wgpu::TextureFormat::R32Float, &constant),
    );
    let expected: Vec<f64> = (0..w * h)
        .flat_map(|_| [0.7f32 as f64, f64::from(0.7f32) * f64::from(0.7f32)])
        .collect();
    // Clamp-to-edge keeps the edge texels at the constant (no loss of shadow at the map edge).
    common::assert_close("constant", &channels(&gpu, 2), &expected, 2e-7, 1e-6);
}

#[test]
fn vsm_light_plans_one_fused_encode_and_blur_only() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml"),
    )
    .unwrap();
    let scene = shadowgraph::low_level::scene::Scene::parse(std::path::Path::new("vsm.toml"), &text).unwrap();
    let sp = shadowgraph::low_level::render::plan_lights(&scene.lights).unwrap();
    let kernels: Vec<&str> = sp
        .plan
        .steps
        .iter()
        .map(|s| s.node.kernel.as_str())
        .collect();
    // The encoding linearizes the depth itself and is fused into the blur: one dispatch.
    assert_eq!(kernels, ["vsm_blur"]);
    assert_eq!(sp.shade_inputs[0].maps, ["light0.vsm.blur"]);
    // The unfused encoding stays in the graph for whoever asks, but nothing here does.
    assert!(sp.plan.resource("light0.vsm").is_none());
}

#[test]
fn evsm_and_esm_encodings_match_reference() {
    use shadowgraph::low_level::filter::BlurMode;
    use shadowgraph::low_level::wgsl_mirrors::ExpParams;
    let g = common::gpu();
    let mut rng = common::rng(42);
    let (w, h) = (333u32, 45u32);
    let lin = random_linear(&mut rng, w as usize, h as usize);
    let input = Texels::from_f32(w as usize, h as usize, 1, &lin);
    let blur = Filter::Blur {
        radius: 3.0,
        sigma: 1.5,
        kernel: BlurKernel::Gaussian,
    };
    // SPIR-V's exp is accurate to (3 + 2|x|) ULP; the square doubles it: for c = 42, |x| ≤ 42.
    let exp_rtol = 2.0 * (3.0 + 2.0 * 42.0) * 2f64.powi(-23) + 1e-6;
    let params = bytemuck::bytes_of(&ExpParams::new(42.0, 5.0)).to_vec();
    for (format, channels, filter) in [
        (wgpu::TextureFormat::Rgba32Float, 4, None),
        (wgpu::TextureFormat::Rg32Float, 2, Some(blur)),
        (wgpu::TextureFormat::Rgba32Float, 4, Some(blur)),
    ] {
        let (graph, out) = encode_graph(
            "evsm",
            params.clone(),
            w,
            h,
            format,
            filter,
            BlurMode::Linear,
        );
        let mut expected = cpu::evsm::evsm(&input, 42.0, 5.0);
        if filter.is_some() {
            expected = cpu::blur::blur(&expected, 3.0, 1.5, BlurKernel::Gaussian);
        }
        let keep: Vec<f64> = expected
            .data
            .chunks(4)
            .flat_map(|c| c[..channels].to_vec())
            .collect();
        for gpu in run_layouts(&g, &graph, &out, (w, h, &lin), filter.is_none()) {
            // Moments span e^±42: the blur's own f32 roundings add ~65 ULP relative.
            common::assert_close(
                &format!("evsm {format:?} blur {}", filter.is_some()),
                &channels_of(&gpu, channels),
                &keep,
                0.0,
                exp_rtol + 65.0 * 2f64.powi(-24),
            );
            assert!(
                gpu.data.iter().all(|v| v.is_finite()),
                "evsm at the f32 limit overflowed"
            );
        }
    }
    // ESM at c = 40 (`blur_log`: every window within its span of 80, one exp per texel) and at
    // c = 200 (`blur_log_wide`: exp(200) overflows f32, and one texel in five is a blocker at
    // 0.1 before a receiver at 0.8 or more, so most invocations' texels span more than 80 and
    // take one exp per tap around each output's maximum): log-space blur keeps everything
    // finite. (The ramps of `random_linear` alone span at most 0.32: 64 at c = 200, which left
    // the per-output path untested.)
    let edges: Vec<f32> = lin
        .iter()
        .map(|&z| {
            if rng.random_bool(0.2) {
                0.1
            } else {
                z.max(0.8)
            }
        })
        .collect();
    let input = Texels::from_f32(w as usize, h as usize, 1, &edges);
    for c in [40.0f32, 200.0] {
        let params = bytemuck::bytes_of(&ExpParams::new(c, 0.0)).to_vec();
        let (graph, out) = encode_graph(
            "esm",
            params,
            w,
            h,
            wgpu::TextureFormat::R32Float,
            Some(blur),
            BlurMode::log_sum_exp(c),
        );
        let expected = cpu::blur::blur_mode(
            &cpu::esm::esm(&input, f64::from(c)),
            3.0,
            1.5,
            BlurKernel::Gaussian,
            true,
        );
        for gpu in run_layouts(&g, &graph, &out, (w, h, &edges), false) {
            // Each log-sum-exp: exp of (v − v₀) ∈ [−c, c] (v₀ the first texel an invocation
            // reads; at c = 200, past the span, v − max ∈ [−c, 0]) at (3 + 2|x|) ULP relative,
            // then log: the absolute error in L is ≲ 2·(3 + 2c) ULP of 1 plus the rounding of
            // |L| ≤ c.
            common::assert_close(
                &format!("esm c={c} log-space blur"),
                &channels_of(&gpu, 1),
                &expected.data,
                2.0 * (3.0 + 2.0 * f64::from(c)) * 2f64.powi(-23),
                4.0 * 2f64.powi(-24),
            );
        }
    }
    // ESM's encoding alone (L = c·z, one rounding of the product), the same in every layout.
    let params = bytemuck::bytes_of(&ExpParams::new(40.0, 0.0)).to_vec();
    let format = wgpu::TextureFormat::R32Float;
    let (graph, out) = encode_graph("esm", params, w, h, format, None, BlurMode::Linear);
    let gpu = run_layouts(&g, &graph, &out, (w, h, &edges), true).swap_remove(0);
    let expected = cpu::esm::esm(&input, 40.0);
    common::assert_close(
        "esm c=40",
        &channels_of(&gpu, 1),
        &expected.data,
        0.0,
        2f64.powi(-24),
    );
}

fn channels_of(t: &Texels, n: usize) -> Vec<f32> {
    channels(t, n)
}

#[test]
fn msm_encoding_matches_reference_for_each_storage() {
    use shadowgraph::low_level::filter::BlurMode;
    use shadowgraph::low_level::wgsl_mirrors::{LinearizeParams, MsmParams};
    let g = common::gpu();
    let mut rng = common::rng(43);
    let (w, h) = (1000u32, 37u32);
    let lin = random_linear(&mut rng, w as usize, h as usize);
    let input = Texels::from_f32(w as usize, h as usize, 1, &lin);
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    for (format, quantized, filter, atol, rtol) in [
        // Raw powers of z ≤ 1: a few roundings each.
        (
            wgpu::TextureFormat::Rgba32Float,
            false,
            None,
            1e-7,
            4.0 * 2f64.powi(-24),
        ),
        (
            wgpu::TextureFormat::Rgba32Float,
            false,
            Some(blur),
            1e-7,
            1e-6,
        ),
        // Quantization matrix entries up to 82 in f32 (~2·10⁻⁵ absolute), then f16 storage
        // after the encoding and each blur pass (Vulkan allows round-toward-zero: 2⁻¹⁰
        // relative each, three times) or 16-bit rounding (2⁻¹⁷ absolute).
        (
            wgpu::TextureFormat::Rgba16Float,
            true,
            Some(blur),
            3e-5,
            3.0 * 2f64.powi(-10),
        ),
        (
            wgpu::TextureFormat::Rgba16Unorm,
            true,
            None,
            3e-5 + 2f64.powi(-17),
            0.0,
        ),
    ] {
        let params = bytemuck::bytes_of(&MsmParams {
            depth: LinearizeParams::ORTHOGRAPHIC,
            quantized: u32::from(quantized),
            _pad: [0; 3],
        })
        .to_vec();
        let (graph, out) = encode_graph("msm", params, w, h, format, filter, BlurMode::Linear);
        let mut expected = cpu::msm::msm(&input, quantized);
        if filter.is_some() {
            expected = cpu::blur::blur(&expected, 2.0, 1.0, BlurKernel::Gaussian);
        }
        for gpu in run_layouts(&g, &graph, &out, (w, h, &lin), filter.is_none()) {
            common::assert_close(
                &format!("msm {format:?} blur {}", filter.is_some()),
                &channels(&gpu, 4),
                &expected.data,
                atol,
                rtol,
            );
            if quantized {
                // The optimized quantization keeps every z ∈ [0, 1] inside [0, 1].
                assert!(
                    gpu.data.iter().all(|v| (-1e-6..=1.0 + 1e-6).contains(v)),
                    "quantized moments leave [0, 1]"
                );
            }
        }
    }
    // Dequantization inverts quantization (the two published matrices).
    for z in [0.0, 0.1, 0.5, 0.93, 1.0] {
        let b = [z, z * z, z * z * z, z * z * z * z];
        let back = cpu::msm::dequantize(cpu::msm::quantize(b));
        for i in 0..4 {
            assert!((back[i] - b[i]).abs() < 1e-8, "z = {z}: {back:?} vs {b:?}");
        }
    }
}

#[test]
fn csm_basis_matches_reference() {
    use shadowgraph::low_level::filter::BlurMode;
    use shadowgraph::low_level::wgsl_mirrors::CsmParams;
    let g = common::gpu();
    let mut rng = common::rng(44);
    let (w, h) = (257u32, 31u32);
    let lin = random_linear(&mut rng, w as usize, h as usize);
    let input = Texels::from_f32(w as usize, h as usize, 1, &lin);
    let terms = 7;
    let expected = cpu::csm::csm(&input, terms);
    for (first_term, format) in [
        (1u32, wgpu::TextureFormat::Rgba32Float),
        (5, wgpu::TextureFormat::Rgba16Float),
        (7, wgpu::TextureFormat::Rg32Float),
    ] {
        // One map a dispatch here (`tests/fused.rs` writes several): map m holds terms
        // 2m + 1 and 2m + 2.
        let params = bytemuck::bytes_of(&CsmParams {
            depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::ORTHOGRAPHIC,
            first_map: (first_term - 1) / 2,
            maps: 1,
            terms,
            moments: 0,
        })
        .to_vec();
        let (graph, out) = encode_graph("csm", params, w, h, format, None, BlurMode::Linear);
        // The same bits in every layout, so the first stands for all.
        let gpu = run_layouts(&g, &graph, &out, (w, h, &lin), true).swap_remove(0);
        let n = (2 * (terms - first_term + 1)).min(4) as usize;
        let first = 2 * (first_term as usize - 1);
        let keep: Vec<f64> = expected
            .data
            .chunks(expected.channels)
            .flat_map(|c| c[first..first + n].to_vec())
            .collect();
        // Vulkan's sin/cos: 2⁻¹¹ absolute on [−π, π] (the kernel reduces its argument there);
        // f16 storage adds 2⁻¹¹ relative.
        let rtol = if format == wgpu::TextureFormat::Rgba16Float {
            2f64.powi(-11)
        } else {
            0.0
        };
        common::assert_close(
            &format!("csm terms {first_term}.. {format:?}"),
            &channels(&gpu, n),
            &keep,
            2f64.powi(-11),
            rtol,
        );
    }
    // With `moments` (CSSM's moment search) the map after the basis is MSM's quantized moments:
    // the quantization matrix's f32 products (entries up to 82: 6·82·2⁻²⁴).
    let params = bytemuck::bytes_of(&CsmParams {
        depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::ORTHOGRAPHIC,
        first_map: shadowgraph::low_level::technique::csm_maps(terms),
        maps: 1,
        terms,
        moments: 1,
    })
    .to_vec();
    let format = wgpu::TextureFormat::Rgba32Float;
    let (graph, out) = encode_graph("csm", params, w, h, format, None, BlurMode::Linear);
    let gpu = run_layouts(&g, &graph, &out, (w, h, &lin), true).swap_remove(0);
    let want = cpu::msm::msm(&input, true);
    common::assert_close(
        "csm moments map",
        &channels(&gpu, 4),
        &want.data,
        6.0 * 82.0 * 2f64.powi(-24),
        0.0,
    );
}

/// The layouts the mip chains are checked in: the device's, and the redesign (the chain after
/// AMD FidelityFX SPD, `kernels/shared/mips_spd.wgsl`), against the same f64 chain with the
/// same tolerances: it computes every texel by the same sums in the same order
/// (`tests/mips_redesign.rs`: bit for bit).
const MIP_LAYOUTS: [Option<KernelLayout>; 2] = [None, Some(KernelLayout::Redesign)];

#[test]
fn mip_chain_matches_reference_and_ends_at_the_mean() {
    use shadowgraph::low_level::filter::BlurMode;
    let g = common::gpu();
    let mut rng = common::rng(45);
    for (w, h, mode) in [
        (1000u32, 37u32, BlurMode::Linear),
        (61, 61, BlurMode::Linear),
        (64, 64, BlurMode::LogSumExp),
        (1, 57, BlurMode::Linear),
        (1, 1, BlurMode::Linear),
        (130, 7, BlurMode::LogSumExp),
        // Several workgroups through six levels in one dispatch, then the tail.
        (512, 512, BlurMode::Linear),
        (256, 256, BlurMode::LogSumExp),
        (384, 160, BlurMode::Linear),
    ] {
        let lin = random_linear(&mut rng, w as usize, h as usize);
        let log = mode.is_log();
        // Log mode holds logarithms (ESM's c·z with c = 80); linear mode the VSM moments.
        let data: Vec<f32> = if log {
            lin.iter().map(|z| 80.0 * z).collect()
        } else {
            lin.clone()
        };
        let mut graph = Graph::default();
        graph.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
        let out = shadowgraph::low_level::filter::add_filter(
            &mut graph,
            0,
            "in",
            &Filter::Mips {
                width: 1.0,
                max_anisotropy: 0,
            },
            mode,
        );
        for layout in MIP_LAYOUTS {
            let gpu = run_levels_in(
                &g,
                &graph,
                &out,
                upload(&g, w, h, wgpu::TextureFormat::R32Float, &data),
                layout,
            );
            let input = Texels::from_f32(w as usize, h as usize, 1, &data);
            let expected = cpu::mips::mip_chain(&input, log);
            assert_eq!(gpu.len(), expected.len(), "{w}x{h}: level count");
            for (level, (got, want)) in gpu.iter().zip(&expected).enumerate() {
                assert_eq!((got.width, got.height), (want.width, want.height));
                // Each level: at most 16 weighted taps of the level above in f32, so a few ULP per
                // level, compounding over the chain (≤ 11 levels here); log mode adds exp/log at
                // (3 + 2|x|) ULP with |x| ≤ 80.
                let (atol, rtol) = if log {
                    (4.0 * (3.0 + 2.0 * 80.0) * 2f64.powi(-23), 2f64.powi(-20))
                } else {
                    (0.0, 8.0 * (level as f64 + 1.0) * 2f64.powi(-24))
                };
                common::assert_close(
                    &format!("{w}x{h} {mode:?} {layout:?} level {level}"),
                    &channels(got, 1),
                    &want.data,
                    atol,
                    rtol,
                );
            }
            // The last level is the mean of the whole map (of exp(v), as a log, in log mode),
            // computed directly, not through the chain.
            let last = gpu.last().unwrap().data[0];
            let n = data.len() as f64;
            let mean = if log {
                let m = data.iter().fold(f32::MIN, |a, &b| a.max(b)) as f64;
                m + (data.iter().map(|&v| (f64::from(v) - m).exp()).sum::<f64>() / n).ln()
            } else {
                data.iter().map(|&v| f64::from(v)).sum::<f64>() / n
            };
            let tol = if log { 1e-3 } else { 1e-5 * mean.abs() };
            assert!(
                (last - mean).abs() <= tol,
                "{w}x{h} {layout:?}: last level {last} vs mean {mean}"
            );
        }
    }
}

#[test]
fn mip_chain_of_16_bit_maps_matches_reference() {
    use shadowgraph::low_level::filter::BlurMode;
    use shadowgraph::low_level::wgsl_mirrors::{LinearizeParams, MsmParams};
    let g = common::gpu();
    let mut rng = common::rng(46);
    let (w, h) = (200u32, 75u32);
    let lin = random_linear(&mut rng, w as usize, h as usize);
    for format in [
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureFormat::Rgba16Unorm,
        wgpu::TextureFormat::Rgba32Float,
    ] {
        let params = bytemuck::bytes_of(&MsmParams {
            depth: LinearizeParams::ORTHOGRAPHIC,
            quantized: 1,
            _pad: [0; 3],
        })
        .to_vec();
        let (graph, out) = encode_graph(
            "msm",
            params,
            w,
            h,
            format,
            Some(Filter::Mips {
                width: 1.0,
                max_anisotropy: 0,
            }),
            BlurMode::Linear,
        );
        for layout in MIP_LAYOUTS {
            let gpu = run_levels_in(
                &g,
                &graph,
                &out,
                upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
                layout,
            );
            for level in 1..gpu.len() {
                let above = &gpu[level - 1];
                let want = cpu::mips::reduce(above, gpu[level].width, gpu[level].height, false);
                common::assert_close(
                    &format!("{format:?} {layout:?} level {level}"),
                    &channels(&gpu[level], 4),
                    &want.data,
                    2f64.powi(-15),
                    2f64.powi(-9),
                );
            }
        }
    }
}

#[test]
fn mip_chain_of_packed_f16_moments_matches_reference() {
    let g = common::gpu();
    let mut rng = common::rng(47);
    // 200 × 75: an odd level side (its own dispatch); 512²: six levels in one dispatch.
    for (w, h) in [(200u32, 75u32), (512, 512)] {
        let lin = random_linear(&mut rng, w as usize, h as usize);
        let filter = Filter::Mips {
            width: 1.0,
            max_anisotropy: 0,
        };
        let (graph, out) = vsm_graph(w, h, shadowgraph::PACKED_F16X2, Some(filter));
        for layout in MIP_LAYOUTS {
            let gpu = run_levels_in(
                &g,
                &graph,
                &out,
                upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
                layout,
            );
            // Level 0: the moments, stored once in f16 (2⁻¹⁰ relative: Vulkan may round toward
            // zero; the f32 encoding's 1e-6 below that).
            let moments = cpu::vsm::vsm(&Texels::from_f32(w as usize, h as usize, 1, &lin));
            common::assert_close(
                &format!("{w}x{h} {layout:?} level 0"),
                &channels(&gpu[0], 2),
                &moments.data,
                1e-6,
                2f64.powi(-10),
            );
            // Each level from the level above as stored (f16, unpacked): an f32 mean of f16
            // values, then one f16 store.
            for level in 1..gpu.len() {
                let above = &gpu[level - 1];
                let want = cpu::mips::reduce(above, gpu[level].width, gpu[level].height, false);
                common::assert_close(
                    &format!("{w}x{h} {layout:?} level {level}"),
                    &channels(&gpu[level], 2),
                    &want.data,
                    2f64.powi(-15),
                    2f64.powi(-9),
                );
            }
            assert!(gpu.len() > 6, "{w}x{h}: {} levels", gpu.len());
        }
    }
}

#[test]
fn plans_hold_exactly_what_each_light_needs() {
    use shadowgraph::{Light, LightKind, PcfKernel, Shadow, Storage, StorageFilter, Technique};
    let light = |technique| Light {
        kind: LightKind::Directional { extent: 5.0 },
        position: glam::Vec3::new(0.0, 10.0, 0.1),
        target: glam::Vec3::ZERO,
        near: 1.0,
        far: 20.0,
        size: 0.0,
        radiance: glam::Vec3::ONE,
        shadow_map: 64,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 1.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    };
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let pcf = Technique::Pcf {
        radius: 1,
        kernel: PcfKernel::Tent,
    };
    let vsm = Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: blur,
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    let msm = Technique::Msm {
        prefilter: StorageFilter {
            storage: Storage::F16,
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 0,
            },
        },
        hausdorff: false,
        moment_bias: 5e-4,
        bleed: 0.0,
    };
    let csm = Technique::Csm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: blur,
        },
        terms: 3,
        attenuation: 1.0,
        offset: 0.1,
        scale: 2.0,
    };
    let lights = [light(pcf), light(vsm), light(msm), light(csm), light(pcf)];
    let sp = shadowgraph::low_level::render::plan_lights(&lights).expect("plan");
    let kernels = |i: usize| -> Vec<&str> {
        sp.plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect()
    };
    // PCF reads the linear map: no encoding, no filter; a second PCF light adds only its own.
    // The encodings read the depth themselves: no `linearize` for them.
    assert_eq!(kernels(0), ["linearize"]);
    assert_eq!(kernels(4), ["linearize"]);
    assert_eq!(kernels(1), ["vsm_blur"]);
    assert_eq!(kernels(2), ["msm", "mips"]);
    // CSM with 3 terms: two basis maps, written by one dispatch and each blurred.
    let mut csm_kernels = kernels(3);
    csm_kernels.sort();
    assert_eq!(csm_kernels, ["blur", "blur", "blur", "blur", "csm"]);
    assert_eq!(sp.shade_inputs[3].maps.len(), 2);
    assert_eq!(sp.plan.steps.len(), 1 + 1 + 2 + 5 + 1);
}
