//! `linearize` on the GPU against `cpu::linearize` on random depth buffers, including sizes
//! that are not multiples of the workgroup and non-finite texels, in the device's kernel layout
//! and in the redesign (each invocation linearizing several texels: the same bits).

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::low_level::cpu::linearize::linearize;
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{read_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Dispatch, Graph, Node, SizeRule, plan};
use shadowgraph::low_level::wgsl_mirrors::LinearizeParams;

struct Run {
    out: Vec<f32>,
    replaced: u32,
}

/// The device's layout, then the redesign.
const LAYOUTS: [Option<KernelLayout>; 2] = [None, Some(KernelLayout::Redesign)];

/// [`run_linearize_in`] in each of [`LAYOUTS`], the outputs and counts the same in each (the
/// redesign keeps each texel's arithmetic); the first run.
fn run_linearize(
    g: &shadowgraph::low_level::gpu::Gpu,
    raw: &[f32],
    w: u32,
    h: u32,
    p: LinearizeParams,
) -> Run {
    let runs = LAYOUTS.map(|layout| run_linearize_in(g, raw, (w, h), p, layout));
    for (run, layout) in runs.iter().zip(LAYOUTS).skip(1) {
        let bits = |r: &Run| r.out.iter().map(|v| v.to_bits()).collect::<Vec<u32>>();
        let (a, b) = (bits(&runs[0]), bits(run));
        if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
            panic!(
                "{layout:?}, {w}x{h}: texel {i} differs ({} against {})",
                runs[0].out[i], run.out[i]
            );
        }
        assert_eq!(
            run.replaced, runs[0].replaced,
            "{layout:?}: replaced texels"
        );
    }
    let [first, _] = runs;
    first
}

/// `linearize` of `raw` (`w × h`) with the kernels in `layout` (the device's with `None`).
fn run_linearize_in(
    g: &shadowgraph::low_level::gpu::Gpu,
    raw: &[f32],
    (w, h): (u32, u32),
    p: LinearizeParams,
    layout: Option<KernelLayout>,
) -> Run {
    let (device, queue) = (&g.device, &g.queue);
    let mut graph = Graph::default();
    let input = graph.import("in", wgpu::TextureFormat::R32Float, w, h, None);
    let out = graph.resource(
        "out",
        wgpu::TextureFormat::R32Float,
        SizeRule::Reduced {
            of: input.clone(),
            shift: 0,
        },
        None,
    );
    graph.node(Node {
        name: "linearize".into(),
        kernel: shadowgraph::low_level::kernels::KernelId::Linearize,
        inputs: vec![("src".into(), input)],
        outputs: vec![("dst".into(), out.clone())],
        params: bytemuck::bytes_of(&p).to_vec(),
        dispatch: Dispatch::Texels(out.clone()),
        light: None,
    });
    let plan = plan(&graph, &["out"]).expect("plan");
    let tex = common::upload(
        device,
        queue,
        "test.raw",
        (w, h),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(raw),
    );
    let mut exec = Executor::new();
    if let Some(layout) = layout {
        exec.kernels.set_layout(layout);
    }
    let mut enc = device.create_command_encoder(&Default::default());
    let imports = HashMap::from([("in".to_string(), tex)]);
    // Poison the output first so unwritten texels show.
    let outputs = exec
        .record(device, &mut enc, &plan, &imports, None)
        .expect("record");
    let poison = vec![f32::NAN; (w * h) as usize];
    write_texture(
        queue,
        &outputs.textures["out"],
        bytemuck::cast_slice(&poison),
    );
    let mut enc2 = device.create_command_encoder(&Default::default());
    let outputs = exec
        .record(device, &mut enc2, &plan, &imports, None)
        .expect("record");
    outputs.copy_stats(&mut enc2);
    drop(enc);
    submit_and_wait(device, queue, enc2, "linearize test").expect("submit");
    let out: Vec<f32> =
        bytemuck::cast_slice(&read_texture(device, queue, &outputs.textures["out"], 0).unwrap())
            .to_vec();
    let replaced = outputs
        .read_stats(device)
        .unwrap()
        .iter()
        .map(|(_, n)| n)
        .sum();
    Run { out, replaced }
}

fn params(perspective: bool, near: f32, far: f32) -> LinearizeParams {
    LinearizeParams {
        perspective: u32::from(perspective),
        near,
        far,
        _pad: 0,
    }
}

#[test]
fn orthographic_depth_passes_through_exactly() {
    let g = common::gpu();
    let mut rng = common::rng(1);
    for (w, h) in [(1000, 37), (64, 64), (1, 1), (17, 300)] {
        let raw: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
        let run = run_linearize(&g, &raw, w, h, params(false, 0.1, 50.0));
        let (reference, _) = linearize(&raw, false, 0.1, 50.0);
        // Exact: orthographic depth is already linear; the kernel only clamps.
        common::assert_close(&format!("ortho {w}x{h}"), &run.out, &reference, 0.0, 0.0);
        assert_eq!(run.replaced, 0);
    }
}

#[test]
fn perspective_depth_matches_f64_reference() {
    let g = common::gpu();
    let mut rng = common::rng(2);
    // Ordinary, very deep (near/far = 1e-4) and very shallow (0.999) frusta.
    for (near, far) in [(0.1f32, 50.0f32), (0.01, 100.0), (9.99, 10.0)] {
        let (w, h) = (333, 77);
        let raw: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
        let run = run_linearize(&g, &raw, w, h, params(true, near, far));
        let (reference, _) = linearize(&raw, true, near.into(), far.into());
        // The kernel evaluates near·d / (far(1 − d) + near·d) in fp32 with 1 − d exact: a few
        // roundings of relative error 2⁻²⁴ each, so 1e-6 relative (plus a denormal floor).
        common::assert_close(
            &format!("perspective {near}/{far}"),
            &run.out,
            &reference,
            1e-9,
            1e-6,
        );
    }
}

#[test]
fn non_finite_depth_is_replaced_and_counted() {
    let g = common::gpu();
    let mut rng = common::rng(3);
    let (w, h) = (100, 30);
    let mut raw: Vec<f32> = (0..w * h).map(|_| rng.random_range(0.0..1.0)).collect();
    let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut injected = 0;
    for i in (0..raw.len()).step_by(37) {
        raw[i] = specials[injected % 3];
        injected += 1;
    }
    // Out-of-range finite values are clamped, not counted.
    raw[1] = 2.5;
    raw[2] = -0.5;
    let run = run_linearize(&g, &raw, w, h, params(true, 0.1, 50.0));
    let (reference, replaced) = linearize(&raw, true, 0.1, 50.0);
    assert_eq!(replaced as usize, injected);
    assert_eq!(run.replaced, replaced, "kernel's count of replaced texels");
    common::assert_close("sanitized", &run.out, &reference, 1e-9, 1e-6);
    assert!(run.out.iter().all(|v| v.is_finite()));
}
