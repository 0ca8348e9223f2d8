//! Encodings and filters on the GPU against their f64 references, on random maps of sizes
//! that are and are not multiples of the workgroup; the plan of a prefiltered light.

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::cpu::{self, Texels};
use shadowgraph::exec::Executor;
use shadowgraph::gpu::{Gpu, read_float_texture, submit_and_wait, write_texture};
use shadowgraph::graph::{Graph, SizeRule, plan};
use shadowgraph::scene::{BlurKernel, Filter};

fn upload(g: &Gpu, w: u32, h: u32, format: wgpu::TextureFormat, data: &[f32]) -> wgpu::Texture {
    let t = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test.input"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    write_texture(&g.queue, &t, bytemuck::cast_slice(data));
    t
}

/// Plans `graph` for `output`, runs it with `input` imported as "in" (the output poisoned with
/// NaN first, so unwritten texels show) and reads the output back.
fn run(g: &Gpu, graph: &Graph, output: &str, input: wgpu::Texture) -> Texels {
    let plan = plan(graph, &[output]).expect("plan");
    let mut exec = Executor::new();
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let first = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "warm").unwrap();
    let out_tex = &first.textures[output];
    let (w, h) = (out_tex.width(), out_tex.height());
    let poison_channels = if out_tex.format() == wgpu::TextureFormat::Rg32Float {
        2
    } else {
        4
    };
    if out_tex.format() != wgpu::TextureFormat::Rgba16Float {
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
    let (c, v) = read_float_texture(&g.device, &g.queue, &outputs.textures[output], 0).unwrap();
    Texels::from_f32(w as usize, h as usize, c, &v)
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
    encode_graph(
        "vsm",
        vec![],
        w,
        h,
        format,
        filter,
        shadowgraph::filter::BlurMode::Linear,
    )
}

/// `in` → encoding `kernel` (params) → optional blur in `mode`.
fn encode_graph(
    kernel: &str,
    params: Vec<u8>,
    w: u32,
    h: u32,
    format: wgpu::TextureFormat,
    filter: Option<Filter>,
    mode: shadowgraph::filter::BlurMode,
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
    g.node(shadowgraph::graph::Node {
        name: "light0.vsm".into(),
        kernel: kernel.into(),
        inputs: vec![("src".into(), "in".into())],
        outputs: vec![("dst".into(), "light0.vsm".into())],
        params,
        dispatch: shadowgraph::graph::Dispatch::Texels("light0.vsm".into()),
        light: Some(0),
    });
    let out = match filter {
        Some(f) => shadowgraph::filter::add_filter(&mut g, 0, "light0.vsm", &f, mode),
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
        let gpu = run(
            &g,
            &graph,
            &out,
            upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
        );
        let reference = cpu::vsm::vsm(&Texels::from_f32(w as usize, h as usize, 1, &lin));
        // f32: z exact; z² + ¼(dx² + dy²) is a handful of roundings of values ≤ 1.25.
        common::assert_close(
            &format!("vsm {w}x{h}"),
            &channels(&gpu, 2),
            &reference.data,
            1e-6,
            1e-6,
        );
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
        ] {
            let (graph, out) = vsm_graph(w, h, format, Some(filter));
            let gpu = run(
                &g,
                &graph,
                &out,
                upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
            );
            common::assert_close(
                &format!("blur {w}x{h} r{radius} {kernel:?} {format:?}"),
                &channels(&gpu, 2),
                &expected.data,
                atol,
                rtol,
            );
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
fn vsm_light_plans_encode_and_two_blur_passes_only() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml"),
    )
    .unwrap();
    let scene = shadowgraph::scene::Scene::parse(std::path::Path::new("vsm.toml"), &text).unwrap();
    let sp = shadowgraph::render::plan_lights(&scene.lights).unwrap();
    let kernels: Vec<&str> = sp
        .plan
        .steps
        .iter()
        .map(|s| s.node.kernel.as_str())
        .collect();
    assert_eq!(kernels, ["linearize", "vsm", "blur", "blur"]);
    assert_eq!(sp.shade_inputs[0].maps, ["light0.vsm.blur_v"]);
    // The encode's output is dead once blur_h has read it: blur_v (same shape) reuses it.
    let slot = |r: &str| sp.plan.resource(r).unwrap().slot;
    assert_eq!(slot("light0.vsm"), slot("light0.vsm.blur_v"));
}

#[test]
fn evsm_and_esm_encodings_match_reference() {
    use shadowgraph::filter::BlurMode;
    use shadowgraph::technique::ExpParams;
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
        let gpu = run(
            &g,
            &graph,
            &out,
            upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
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
    // ESM at c = 200 (exp(200) overflows f32): log-space blur keeps everything finite.
    let params = bytemuck::bytes_of(&ExpParams::new(200.0, 0.0)).to_vec();
    let (graph, out) = encode_graph(
        "esm",
        params,
        w,
        h,
        wgpu::TextureFormat::R32Float,
        Some(blur),
        BlurMode::LogSumExp,
    );
    let gpu = run(
        &g,
        &graph,
        &out,
        upload(&g, w, h, wgpu::TextureFormat::R32Float, &lin),
    );
    let expected = cpu::blur::blur_mode(
        &cpu::esm::esm(&input, 200.0),
        3.0,
        1.5,
        BlurKernel::Gaussian,
        true,
    );
    // Each log-sum-exp: exp of (v − max) ∈ [−200, 0] at (3 + 2|x|) ULP relative, then log: the
    // absolute error in L is ≲ 2 · 403 ULP of 1 plus the rounding of |L| ≤ 200.
    common::assert_close(
        "esm c=200 log-space blur",
        &channels_of(&gpu, 1),
        &expected.data,
        2.0 * 403.0 * 2f64.powi(-23),
        4.0 * 2f64.powi(-24),
    );
}

fn channels_of(t: &Texels, n: usize) -> Vec<f32> {
    channels(t, n)
}
