//! The VSM encoding and the blurs against their f64 references.

use super::*;

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
            (shadowgraph::PACKED_F16X2, 1e-4, 3.0 * (2.0f64).powi(-10)),
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
    let scene =
        shadowgraph::low_level::scene::Scene::parse(std::path::Path::new("vsm.toml"), &text)
            .unwrap();
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
