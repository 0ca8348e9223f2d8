//! The separable blur's row pass in each kernel layout (`exec::KernelLayout`): the shipped rows
//! (an invocation on 8 texels of a row, neighbouring invocations side by side) and the
//! redesign's (`KernelLayout::Redesign`: an invocation a row, neighbouring invocations on
//! neighbouring rows, sliding along x for as many outputs as a column invocation), against the
//! f64 reference pass by pass, and against each other bit for bit. Sizes that are not multiples
//! of either's blocks (512 × 1 texels; 32 × 64, or 8 × 64 for the log-space blur), radii from 1
//! to 32, two and four channels, f16 and packed f16 storage, and ESM's log-space blur in both
//! of its kernels.

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::filter::{BlurMode, add_filter};
use shadowgraph::low_level::gpu::{Gpu, read_resource_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Dispatch, Graph, Node, SizeRule, plan, texel_bytes};
use shadowgraph::low_level::kernels::KernelId;
use shadowgraph::{BlurKernel, Filter};

/// The two layouts a GPU runs: the shipped rows and the redesign.
const LAYOUTS: [KernelLayout; 2] = [KernelLayout::Gpu, KernelLayout::Redesign];

/// Runs `graph` in `layout` with `imports`, every output poisoned with NaN first (so unwritten
/// texels show), and reads back `outputs` (their planned formats, packed f16 unpacked).
fn run(
    g: &Gpu,
    graph: &Graph,
    outputs: &[&str],
    imports: &HashMap<String, wgpu::Texture>,
    layout: KernelLayout,
) -> Vec<Texels> {
    let plan = plan(graph, outputs).expect("plan").unaliased();
    let mut exec = Executor::new();
    exec.kernels.set_layout(layout);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = exec
        .record(&g.device, &mut enc, &plan, imports, None)
        .expect("record");
    for name in outputs {
        let t = &out.textures[*name];
        let bytes = texel_bytes(t.format()) as usize * (t.width() * t.height()) as usize;
        // 0xFF bytes: NaN in every float format, two NaN halves in a packed word.
        write_texture(&g.queue, t, &vec![0xFF; bytes]);
    }
    submit_and_wait(&g.device, &g.queue, enc, "blur rows").expect("submit");
    outputs
        .iter()
        .map(|name| {
            let t = &out.textures[*name];
            let format = plan.resource(name).expect("planned").resource.format;
            let (c, v) = read_resource_texture(&g.device, &g.queue, t, 0, format).expect("read");
            Texels::from_f32(t.width() as usize, t.height() as usize, c, &v)
        })
        .collect()
}

/// The graph blurring the import `in` (`format`, `w × h`): its row and its final output.
fn blur_graph(
    format: wgpu::TextureFormat,
    (w, h): (u32, u32),
    filter: &Filter,
    mode: BlurMode,
) -> (Graph, [String; 2]) {
    let mut graph = Graph::default();
    graph.import("in", format, w, h, Some(0));
    let out = add_filter(&mut graph, 0, "in", filter, mode);
    (graph, ["in.blur_h".to_string(), out])
}

/// Random texels of `channels` channels in [−1, 2) with steps (one in ten times 4, so
/// |v| < 8), so that windows see edges.
fn random_texels(rng: &mut impl Rng, w: u32, h: u32, channels: usize) -> Texels {
    let data: Vec<f32> = (0..(w * h) as usize * channels)
        .map(|_| {
            let v: f32 = rng.random_range(-1.0..2.0);
            if rng.random_bool(0.1) { v * 4.0 } else { v }
        })
        .collect();
    Texels::from_f32(w as usize, h as usize, channels, &data)
}

/// `t`'s first `n` channels of every texel.
fn channels(t: &Texels, n: usize) -> Vec<f32> {
    t.data
        .chunks(t.channels)
        .flat_map(|c| c[..n].iter().map(|&v| v as f32))
        .collect()
}

/// Blurs `input` (f32 texels, `format` of as many channels) in each layout: each pass against
/// the f64 reference within `atol + rtol·|ref|`, the redesign's rows and result equal to the
/// shipped rows' bit for bit.
fn check_f32(what: &str, input: &Texels, format: wgpu::TextureFormat, filter: &Filter) {
    let g = common::gpu();
    let Filter::Blur {
        radius,
        sigma,
        kernel,
    } = *filter
    else {
        unreachable!("a blur")
    };
    let (w, h) = (input.width as u32, input.height as u32);
    let (graph, [rows, out]) = blur_graph(format, (w, h), filter, BlurMode::Linear);
    let f32s: Vec<f32> = input.data.iter().map(|&v| v as f32).collect();
    let tex = common::upload(
        &g.device,
        &g.queue,
        "in",
        (w, h),
        format,
        bytemuck::cast_slice(&f32s),
    );
    let imports = HashMap::from([("in".to_string(), tex)]);
    let weights = cpu::blur::weights(f64::from(radius), f64::from(sigma), kernel);
    let row_ref = cpu::blur::blur_pass(input, &weights, 0);
    let both_ref = cpu::blur::blur_pass(&row_ref, &weights, 1);
    let n = input.channels;
    // f32, a pass: w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ) summed in order, the pair i through its add, its
    // product and r − i + 1 accumulations, each weight rounded once from f64 (Σ w = 1): at most
    // (r + 4)·2⁻²⁴·max |v| from the f64 pass; the columns add their own to the rows' error,
    // which their weights carry unchanged (the worst case of tests/prefilter/'s 1e-6 on
    // moments in [0, 1]).
    let max = input.data.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let pass_error = f64::from(weights.len() as u32 + 3) * 2f64.powi(-24) * max;
    let mut runs = Vec::new();
    for layout in LAYOUTS {
        let maps = run(&g, &graph, &[&rows, &out], &imports, layout);
        let what = format!("{what}, {} layout", layout.name());
        common::assert_close(
            &format!("{what}, rows"),
            &channels(&maps[0], n),
            &row_ref.data,
            pass_error,
            0.0,
        );
        common::assert_close(
            &format!("{what}, both"),
            &channels(&maps[1], n),
            &both_ref.data,
            2.0 * pass_error,
            0.0,
        );
        runs.push(maps);
    }
    // Each output's sum in the same order (the centre, then the symmetric pairs outward): the
    // same bits whichever invocation makes it.
    for (k, pass) in ["rows", "both"].iter().enumerate() {
        common::assert_same_bits(
            &format!("{what}, {pass}: redesign against gpu"),
            &runs[0][k],
            &runs[1][k],
        );
    }
}

#[test]
fn row_redesign_blurs_as_the_reference_and_the_shipped_rows() {
    let mut rng = common::rng(0xB10B);
    let cases = [
        // (w, h, radius, sigma, kernel, channels): rows longer than a shipped block (512) and
        // not a multiple of a redesign block (32 × 64) either way.
        (1000u32, 37u32, 2.0f32, 1.0f32, BlurKernel::Gaussian, 2usize),
        (130, 129, 7.5, 0.5, BlurKernel::Box, 2),
        (300, 70, 32.0, 11.0, BlurKernel::Gaussian, 2),
        (97, 65, 32.0, 0.5, BlurKernel::Box, 4),
        (45, 131, 4.0, 2.0, BlurKernel::Gaussian, 4),
        (3, 200, 4.25, 0.5, BlurKernel::Box, 2),
        (33, 1, 1.0, 0.5, BlurKernel::Box, 4),
        (1, 1, 3.0, 1.5, BlurKernel::Gaussian, 2),
    ];
    for (w, h, radius, sigma, kernel, n) in cases {
        let input = random_texels(&mut rng, w, h, n);
        let format = if n == 2 {
            wgpu::TextureFormat::Rg32Float
        } else {
            wgpu::TextureFormat::Rgba32Float
        };
        let filter = Filter::Blur {
            radius,
            sigma,
            kernel,
        };
        check_f32(
            &format!("blur {w}x{h} r{radius} {kernel:?} {format:?}"),
            &input,
            format,
            &filter,
        );
    }
}

/// `in` (r32float linear depth in [0, 1]) → VSM moments in `format` → blur: the f16 storages
/// (and packed f16 pairs) take the moments from the encoding, as a VSM light does.
fn vsm_blur_graph(
    format: wgpu::TextureFormat,
    (w, h): (u32, u32),
    filter: &Filter,
) -> (Graph, [String; 2]) {
    let mut graph = Graph::default();
    graph.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
    graph.resource(
        "vsm",
        format,
        SizeRule::Reduced {
            of: "in".into(),
            shift: 0,
        },
        Some(0),
    );
    let params = shadowgraph::low_level::wgsl_mirrors::VsmParams {
        depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::ORTHOGRAPHIC,
    };
    graph.node(Node {
        name: "vsm".into(),
        kernel: KernelId::from_name("vsm").expect("the vsm kernel"),
        inputs: vec![("src".into(), "in".into())],
        outputs: vec![("dst".into(), "vsm".into())],
        params: bytemuck::bytes_of(&params).to_vec(),
        dispatch: Dispatch::Texels("vsm".into()),
        light: Some(0),
    });
    let out = add_filter(&mut graph, 0, "vsm", filter, BlurMode::Linear);
    (graph, ["vsm.blur_h".to_string(), out])
}

#[test]
fn row_redesign_blurs_f16_storage_as_the_reference_and_the_shipped_rows() {
    let g = common::gpu();
    let mut rng = common::rng(0xF16);
    let (w, h) = (300u32, 70u32);
    let depth: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
    let moments = cpu::vsm::vsm(&Texels::from_f32(w as usize, h as usize, 1, &depth));
    for radius in [3.0f32, 32.0] {
        let filter = Filter::Blur {
            radius,
            sigma: radius / 3.0,
            kernel: BlurKernel::Gaussian,
        };
        let expected = cpu::blur::blur(
            &moments,
            f64::from(radius),
            f64::from(radius / 3.0),
            BlurKernel::Gaussian,
        );
        for format in [wgpu::TextureFormat::Rgba16Float, shadowgraph::PACKED_F16X2] {
            let (graph, [rows, out]) = vsm_blur_graph(format, (w, h), &filter);
            let tex = common::upload(
                &g.device,
                &g.queue,
                "in",
                (w, h),
                wgpu::TextureFormat::R32Float,
                bytemuck::cast_slice(&depth),
            );
            let imports = HashMap::from([("in".to_string(), tex)]);
            let what = format!("vsm blur {w}x{h} r{radius} {format:?}");
            let runs: Vec<Vec<Texels>> = LAYOUTS
                .iter()
                .map(|&layout| {
                    let maps = run(&g, &graph, &[&rows, &out], &imports, layout);
                    // f16: three stores (encode, rows, columns), each may lose a whole ulp —
                    // Vulkan lets the f16 conversion round toward zero — so 3 · 2⁻¹⁰ relative.
                    common::assert_close(
                        &format!("{what}, {} layout", layout.name()),
                        &channels(&maps[1], 2),
                        &expected.data,
                        1e-4,
                        3.0 * 2f64.powi(-10),
                    );
                    maps
                })
                .collect();
            for (k, pass) in ["rows", "both"].iter().enumerate() {
                common::assert_same_bits(
                    &format!("{what}, {pass}: redesign against gpu"),
                    &runs[0][k],
                    &runs[1][k],
                );
            }
        }
    }
}

#[test]
fn row_redesign_of_the_log_space_blur_matches_the_reference_and_the_shipped_rows() {
    let g = common::gpu();
    let mut rng = common::rng(0xE5);
    let (w, h) = (131u32, 70u32);
    // One texel in five a blocker at 0.1 before a receiver at 0.8 or more: at c = 200 most
    // invocations' texels span more than 80 (`blur_log_wide`'s per-output path); at c = 40
    // none does (`blur_log`).
    let z: Vec<f64> = (0..w * h)
        .map(|_| {
            if rng.random_bool(0.2) {
                0.1
            } else {
                rng.random_range(0.8..1.0)
            }
        })
        .collect();
    for (c, radius) in [(40.0f64, 3.0f32), (40.0, 32.0), (200.0, 3.0), (200.0, 32.0)] {
        let cz: Vec<f32> = z.iter().map(|&z| (c * z) as f32).collect();
        let input = Texels::from_f32(w as usize, h as usize, 1, &cz);
        let filter = Filter::Blur {
            radius,
            sigma: radius / 2.0,
            kernel: BlurKernel::Gaussian,
        };
        let mode = BlurMode::log_sum_exp(c as f32);
        let (graph, [rows, out]) = blur_graph(wgpu::TextureFormat::R32Float, (w, h), &filter, mode);
        let tex = common::upload(
            &g.device,
            &g.queue,
            "in",
            (w, h),
            wgpu::TextureFormat::R32Float,
            bytemuck::cast_slice(&cz),
        );
        let imports = HashMap::from([("in".to_string(), tex)]);
        let weights = cpu::blur::weights(
            f64::from(radius),
            f64::from(radius / 2.0),
            BlurKernel::Gaussian,
        );
        let row_ref = cpu::blur::blur_pass_mode(&input, &weights, 0, true);
        let both_ref = cpu::blur::blur_pass_mode(&row_ref, &weights, 1, true);
        let what = format!("esm c={c} r{radius} log-space blur");
        // Each log-sum-exp: exp of (v − v₀) ∈ [−c, c] (v₀ the first texel an invocation reads;
        // past the span, v − max ∈ [−c, 0]) at (3 + 2|x|) ULP relative, then log: the absolute
        // error in L is ≲ 2·(3 + 2c) ULP of 1 plus the rounding of |L| ≤ c (tests/prefilter/'s
        // tolerance of both passes, here on each).
        let atol = 2.0 * (3.0 + 2.0 * c) * 2f64.powi(-23);
        let rtol = 4.0 * 2f64.powi(-24);
        let mut runs = Vec::new();
        for layout in LAYOUTS {
            let maps = run(&g, &graph, &[&rows, &out], &imports, layout);
            let what = format!("{what}, {} layout", layout.name());
            common::assert_close(
                &format!("{what}, rows"),
                &channels(&maps[0], 1),
                &row_ref.data,
                atol,
                rtol,
            );
            common::assert_close(
                &format!("{what}, both"),
                &channels(&maps[1], 1),
                &both_ref.data,
                atol,
                rtol,
            );
            runs.push(maps);
        }
        // Runs of 8 from multiples of 8 either way: each output's sums from the same first
        // texel, in the same order.
        for (k, pass) in ["rows", "both"].iter().enumerate() {
            common::assert_same_bits(
                &format!("{what}, {pass}: redesign against gpu"),
                &runs[0][k],
                &runs[1][k],
            );
        }
    }
}
