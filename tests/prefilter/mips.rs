//! Mip chains against their f64 references.

use super::*;

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
