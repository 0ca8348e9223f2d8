//! Intermediates kept in storage buffers (`exec::KernelLayout::Redesign`, which keeps every
//! never-filtered intermediate of a plan in a row-major buffer; `RedesignTextures` runs the same
//! kernels with textures): the separable blur's row output in every format a buffer holds bit
//! for bit, against the f64 blur and bit for bit against the same kernels with textures; the
//! log-space blur likewise; the summed-area tables' edges and carries; the renderer's shading
//! over fixed-point tables in buffers; and which resources the executor puts in buffers (never
//! a 16-bit format, a map past the device's binding size, or a requested output unless the
//! caller allows it).

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::exec::{Executor, KernelLayout, Outputs};
use shadowgraph::low_level::filter::{BlurMode, add_filter};
use shadowgraph::low_level::gpu::{Gpu, read_resource_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, Plan, plan, texel_bytes};
use shadowgraph::{BlurKernel, Filter};

/// f32's unit roundoff.
const U: f64 = 1.0 / (1u64 << 24) as f64;

/// Runs `plan` in `layout` over `imports`, its output and every buffer poisoned with 0xFF
/// bytes first (NaN in every float format, so unwritten texels show); returns the outputs and
/// the output's texels.
fn run(
    g: &Gpu,
    plan: &Plan,
    imports: &HashMap<String, wgpu::Texture>,
    layout: KernelLayout,
) -> (Outputs, Texels) {
    let mut exec = Executor::new();
    exec.kernels.set_layout(layout);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = exec
        .record(&g.device, &mut enc, plan, imports, None)
        .expect("record");
    let name = &plan.outputs[0];
    let t = &out.textures[name];
    let bytes = texel_bytes(t.format()) as usize * (t.width() * t.height()) as usize;
    write_texture(&g.queue, t, &vec![0xFF; bytes]);
    for b in out.buffers.values() {
        g.queue
            .write_buffer(&b.buffer, 0, &vec![0xFF; b.buffer.size() as usize]);
    }
    submit_and_wait(&g.device, &g.queue, enc, "intermediate buffers").expect("submit");
    let format = plan.resource(name).expect("planned").resource.format;
    let (c, v) = read_resource_texture(&g.device, &g.queue, t, 0, format).expect("read");
    let texels = Texels::from_f32(t.width() as usize, t.height() as usize, c, &v);
    (out, texels)
}

/// Random texels of `channels` channels in [−1, 2), one in ten times 4 (edges in every window).
fn random_texels(rng: &mut impl Rng, (w, h): (u32, u32), channels: usize) -> Vec<f32> {
    (0..(w * h) as usize * channels)
        .map(|_| {
            let v: f32 = rng.random_range(-1.0..2.0);
            if rng.random_bool(0.1) { v * 4.0 } else { v }
        })
        .collect()
}

/// The plan blurring the import `in` (`format`, `w × h`) for its blurred output only.
fn blur_plan(
    format: wgpu::TextureFormat,
    (w, h): (u32, u32),
    filter: &Filter,
    mode: BlurMode,
) -> Plan {
    let mut graph = Graph::default();
    graph.import("in", format, w, h, Some(0));
    let out = add_filter(&mut graph, 0, "in", filter, mode);
    plan(&graph, &[&out]).expect("plan")
}

/// Blurs `data` (`channels` f32 channels, `format`) in the redesign layout with its row output
/// in a buffer: the blur within the f64 reference's two-pass bound, the same bits as with
/// textures, and the row output in a buffer (in a texture with `RedesignTextures`).
fn check(what: &str, data: &[f32], format: wgpu::TextureFormat, size: (u32, u32), filter: &Filter) {
    let g = common::gpu();
    let Filter::Blur {
        radius,
        sigma,
        kernel,
    } = *filter
    else {
        unreachable!("a blur")
    };
    let channels = data.len() / (size.0 * size.1) as usize;
    let plan = blur_plan(format, size, filter, BlurMode::Linear);
    let tex = common::upload(
        &g.device,
        &g.queue,
        "in",
        size,
        format,
        bytemuck::cast_slice(data),
    );
    let imports = HashMap::from([("in".to_string(), tex)]);
    let (buffered, got) = run(&g, &plan, &imports, KernelLayout::Redesign);
    let (textured, want_bits) = run(&g, &plan, &imports, KernelLayout::RedesignTextures);
    assert_eq!(
        buffered.buffers.keys().collect::<Vec<_>>(),
        vec!["in.blur_h"],
        "{what}: the row output, and only it, in a buffer"
    );
    assert!(textured.buffers.is_empty(), "{what}: textures only");
    let input = Texels::from_f32(size.0 as usize, size.1 as usize, channels, data);
    let weights = cpu::blur::weights(f64::from(radius), f64::from(sigma), kernel);
    let both = cpu::blur::blur_pass(&cpu::blur::blur_pass(&input, &weights, 0), &weights, 1);
    // As tests/blur_rows.rs: a pass's ordered sum of r + 1 terms with weights rounded once from
    // f64 is within (r + 4)·u·max |v| of the f64 pass, two passes twice that.
    let max = input.data.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let pass_error = f64::from(weights.len() as u32 + 3) * U * max;
    let got_f32: Vec<f32> = got
        .data
        .chunks(got.channels)
        .flat_map(|c| c[..channels].iter().map(|&v| v as f32))
        .collect();
    common::assert_close(what, &got_f32, &both.data, 2.0 * pass_error, 0.0);
    common::assert_same_bits(&format!("{what}: buffer against texture"), &got, &want_bits);
}

#[test]
fn row_outputs_in_buffers_blur_as_the_reference_and_as_textures() {
    use wgpu::TextureFormat as T;
    let mut rng = common::rng(0xB0FF);
    // Sizes off every block (a redesign row block is 32 × 64): a buffer row's end is where a
    // stray store or load would wrap into the next row.
    for (size, format, channels, radius) in [
        ((130u32, 67u32), T::R32Float, 1usize, 2.0f32),
        ((97, 130), T::Rg32Float, 2, 32.0),
        ((45, 33), T::Rgba32Float, 4, 4.0),
        ((33, 1), T::Rg32Float, 2, 7.5),
        ((1, 40), T::R32Float, 1, 3.0),
    ] {
        let data = random_texels(&mut rng, size, channels);
        let filter = Filter::Blur {
            radius,
            sigma: radius / 2.0,
            kernel: BlurKernel::Gaussian,
        };
        let what = format!("blur {}x{} r{radius} {format:?}", size.0, size.1);
        check(&what, &data, format, size, &filter);
    }
}

#[test]
fn log_space_row_outputs_in_buffers_are_the_textures_bits() {
    let g = common::gpu();
    let mut rng = common::rng(0x10C);
    let size = (131u32, 70u32);
    // c·z with a blocker at 0.1 before receivers past 0.8: at c = 200 the wide kernel's
    // per-output path, at c = 40 `blur_log`'s.
    for c in [40.0f32, 200.0] {
        let cz: Vec<f32> = (0..size.0 * size.1)
            .map(|_| {
                c * if rng.random_bool(0.2) {
                    0.1
                } else {
                    rng.random_range(0.8..1.0)
                }
            })
            .collect();
        let filter = Filter::Blur {
            radius: 5.0,
            sigma: 2.5,
            kernel: BlurKernel::Gaussian,
        };
        let format = wgpu::TextureFormat::R32Float;
        let plan = blur_plan(format, size, &filter, BlurMode::log_sum_exp(c));
        let tex = common::upload(
            &g.device,
            &g.queue,
            "in",
            size,
            format,
            bytemuck::cast_slice(&cz),
        );
        let imports = HashMap::from([("in".to_string(), tex)]);
        let (buffered, got) = run(&g, &plan, &imports, KernelLayout::Redesign);
        let (_, want) = run(&g, &plan, &imports, KernelLayout::RedesignTextures);
        assert!(
            buffered.buffers.contains_key("in.blur_h"),
            "c = {c}: row output in a buffer"
        );
        // The f64 log-space blur, within tests/blur_rows.rs' bound on each pass: exp of values
        // within c of the first texel at (3 + 2c) ULP, then log.
        let input = Texels::from_f32(size.0 as usize, size.1 as usize, 1, &cz);
        let weights = cpu::blur::weights(5.0, 2.5, BlurKernel::Gaussian);
        let rows = cpu::blur::blur_pass_mode(&input, &weights, 0, true);
        let both = cpu::blur::blur_pass_mode(&rows, &weights, 1, true);
        let atol = 2.0 * (3.0 + 2.0 * f64::from(c)) * 2f64.powi(-23);
        let got_f32: Vec<f32> = got
            .data
            .iter()
            .step_by(got.channels)
            .map(|&v| v as f32)
            .collect();
        common::assert_close(
            &format!("log blur c = {c}"),
            &got_f32,
            &both.data,
            atol,
            4.0 * U,
        );
        common::assert_same_bits(
            &format!("log blur c = {c}: buffer against texture"),
            &got,
            &want,
        );
    }
}

#[test]
fn only_unfiltered_intermediates_that_a_buffer_holds_go_to_buffers() {
    use shadowgraph::low_level::exec::slot_in_buffer;
    let filter = Filter::Blur {
        radius: 3.0,
        sigma: 1.5,
        kernel: BlurKernel::Gaussian,
    };
    let limits = wgpu::Limits::default();
    let in_buffers = |plan: &Plan, layout, limits: &wgpu::Limits| -> Vec<String> {
        plan.resources
            .iter()
            .filter(|r| {
                r.slot
                    .is_some_and(|s| slot_in_buffer(plan, s, layout, limits, false))
            })
            .map(|r| r.resource.name.clone())
            .collect()
    };
    let rg = blur_plan(
        wgpu::TextureFormat::Rg32Float,
        (64, 64),
        &filter,
        BlurMode::Linear,
    );
    assert_eq!(
        in_buffers(&rg, KernelLayout::Redesign, &limits),
        ["in.blur_h"]
    );
    for layout in [
        KernelLayout::Gpu,
        KernelLayout::Cpu,
        KernelLayout::RedesignTextures,
    ] {
        assert!(in_buffers(&rg, layout, &limits).is_empty(), "{layout:?}");
    }
    // f16 channels round on a texture store: a buffer would not hold the same bits.
    let f16 = blur_plan(
        wgpu::TextureFormat::Rgba16Float,
        (64, 64),
        &filter,
        BlurMode::Linear,
    );
    assert!(in_buffers(&f16, KernelLayout::Redesign, &limits).is_empty());
    // A map past one storage binding stays a texture (64² rg32float: 32 KiB).
    let small = wgpu::Limits {
        max_storage_buffer_binding_size: 32 * 1024 - 8,
        ..limits.clone()
    };
    assert!(in_buffers(&rg, KernelLayout::Redesign, &small).is_empty());
    // A requested output is bound by a host as a texture: a buffer only where the caller
    // allows it (the renderer, whose shading reads them rewritten), and never one that is
    // filtered (the blur's output).
    let mut graph = Graph::default();
    graph.import("in", wgpu::TextureFormat::Rg32Float, 64, 64, Some(0));
    let out = add_filter(&mut graph, 0, "in", &filter, BlurMode::Linear);
    let both = plan(&graph, &["in.blur_h", &out]).expect("plan");
    assert!(in_buffers(&both, KernelLayout::Redesign, &limits).is_empty());
    let allowed: Vec<&str> = both
        .resources
        .iter()
        .filter(|r| {
            r.slot
                .is_some_and(|s| slot_in_buffer(&both, s, KernelLayout::Redesign, &limits, true))
        })
        .map(|r| r.resource.name.as_str())
        .collect();
    assert_eq!(allowed, ["in.blur_h"]);
}

#[test]
fn table_edges_and_carries_in_buffers_are_the_textures_words() {
    use shadowgraph::low_level::gpu::read_texture;
    use shadowgraph::low_level::sat::{SatCoding, add_sat};
    let g = common::gpu();
    let mut rng = common::rng(0x5A7);
    // Ragged tiles, and rows of more than one segment of the carries' scan (64 tiles).
    for (w, h) in [(100u32, 70u32), (2090, 40)] {
        let values = random_texels(&mut rng, (w, h), 2);
        let mut graph = Graph::default();
        graph.import("in", wgpu::TextureFormat::Rg32Float, w, h, Some(0));
        let tex = common::upload(
            &g.device,
            &g.queue,
            "in",
            (w, h),
            wgpu::TextureFormat::Rg32Float,
            bytemuck::cast_slice(&values),
        );
        let imports = HashMap::from([("in".to_string(), tex)]);
        for coding in [
            SatCoding::fixed(u64::from(w * h), [-4.0; 4], [8.0; 4]).expect("fixed"),
            SatCoding::float([-4.0; 4], [8.0; 4]).expect("float"),
        ] {
            let mut graph = graph.clone();
            let out = add_sat(&mut graph, 0, "in", &coding);
            let plan = plan(&graph, &[&out]).expect("plan");
            let words = |layout| {
                let mut exec = Executor::new();
                exec.kernels.set_layout(layout);
                let mut enc = g.device.create_command_encoder(&Default::default());
                let outputs = exec
                    .record(&g.device, &mut enc, &plan, &imports, None)
                    .expect("record");
                for b in outputs.buffers.values() {
                    g.queue
                        .write_buffer(&b.buffer, 0, &vec![0xFF; b.buffer.size() as usize]);
                }
                submit_and_wait(&g.device, &g.queue, enc, "table").expect("submit");
                let bytes = read_texture(&g.device, &g.queue, &outputs.textures[&out], 0);
                let mut held: Vec<String> = outputs.buffers.keys().cloned().collect();
                held.sort();
                (bytes.expect("read"), held)
            };
            let (got, held) = words(KernelLayout::Redesign);
            let (want, _) = words(KernelLayout::RedesignTextures);
            let what = format!("{w}x{h} {:?}", coding.variant);
            assert!(
                got == want,
                "{what}: the table differs from the textures' one"
            );
            // Every tile pass reads them by `textureLoad`, directly (`shared/sat_strip`) or in
            // functions specialized to them (the shipped modules, `exec::monomorph`).
            let parts = ["col_carry", "col_part", "row_carry", "row_part"];
            let want: Vec<String> = parts.iter().map(|p| format!("in.sat.{p}")).collect();
            assert_eq!(held, want, "{what}: the edges and carries in buffers");
        }
    }
}

/// Renders bundled technique scene `name` (shrunk to 160 × 120 with 128² maps) in `layout`:
/// the image and visibility, and the plan outputs its executor held in storage buffers.
fn render_in(name: &str, layout: KernelLayout) -> (Vec<u8>, Vec<f32>, Vec<String>) {
    use shadowgraph::low_level::render::{RenderOptions, Renderer};
    use shadowgraph::low_level::scene::Scene;
    let g = common::gpu();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/techniques")
        .join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path)
        .expect("scene")
        .replace("width = 400", "width = 160")
        .replace("height = 300", "height = 120")
        .replace("shadow_map = 512", "shadow_map = 128");
    let scene = Scene::parse(&path, &text).expect("parse");
    let mut r = Renderer::new(&g.device);
    r.executor.kernels.set_layout(layout);
    let opts = RenderOptions {
        aux: true,
        ..RenderOptions::default()
    };
    let frame = r.render(&g.device, &g.queue, &scene, opts).expect("render");
    let plan = shadowgraph::low_level::render::plan_lights_for(&scene.lights, &opts)
        .expect("plan")
        .plan;
    let held = r
        .executor
        .buffer_slots(&g.device, &plan)
        .expect("placement");
    let mut names: Vec<String> = plan
        .resources
        .iter()
        .filter(|p| p.slot.is_some_and(|s| held[s]))
        .map(|p| p.resource.name.clone())
        .collect();
    names.sort();
    (frame.rgba, frame.visibility, names)
}

/// The renderer's shading pass reads fixed-point tables that the redesign layout keeps in
/// storage buffers (its lookups specialized to each table, `exec::monomorph`, then its loads
/// rewritten): `msm_soft`'s and `vsm_sat`'s frames the same bit for bit as with the tables in
/// textures, their visibility too, and the tables in buffers.
#[test]
fn the_shading_reads_tables_in_buffers_as_in_textures() {
    for (name, table) in [
        ("msm_soft", "light0.msm.sat"),
        ("vsm_sat", "light0.vsm.sat"),
    ] {
        let (rgba, vis, held) = render_in(name, KernelLayout::Redesign);
        let (want_rgba, want_vis, none) = render_in(name, KernelLayout::RedesignTextures);
        assert!(held.contains(&table.to_string()), "{name}: {held:?}");
        assert!(none.is_empty(), "{name}: textures only, {none:?}");
        assert!(
            vis.iter().any(|&v| v < 0.5) && vis.iter().any(|&v| v > 0.5),
            "{name}: shadow and light"
        );
        assert!(
            rgba == want_rgba,
            "{name}: the image differs from the textures' one"
        );
        let same = vis
            .iter()
            .zip(&want_vis)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same,
            "{name}: the visibility differs from the textures' one"
        );
    }
}
