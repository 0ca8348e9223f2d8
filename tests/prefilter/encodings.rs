//! The EVSM, ESM, MSM and CSM encodings against their f64 references.

use super::*;

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
