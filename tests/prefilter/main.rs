//! Encodings and filters on the GPU against their f64 references, on random maps of sizes
//! that are and are not multiples of the workgroup; the plan of a prefiltered light.

#[path = "../common/mod.rs"]
mod common;
use rand::Rng;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{Gpu, read_resource_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, SizeRule, plan};
use shadowgraph::{BlurKernel, Filter};
use std::collections::HashMap;

mod blur;
mod encodings;
mod mips;
mod plans;

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
