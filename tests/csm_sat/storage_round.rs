//! `shared/storage_round`'s f16 and unorm16 rounding bit for bit against f64.

use super::*;

/// `round_f16(x)` in f64: to nearest, ties to even, with 11 significant bits in f16's normal
/// range and f16's subnormal step 2⁻²⁴ below it.
fn f16_reference(x: f64) -> f64 {
    let step = if x.abs() < 2f64.powi(-14) {
        2f64.powi(-24)
    } else {
        2f64.powi(x.abs().log2().floor() as i32 - 10)
    };
    (x / step).round_ties_even() * step
}

/// `shared/storage_round`, which the depth-sourced tables use to hold what an f16 or unorm16
/// map would, on the GPU by a kernel of the test's own: `round_f16` bit for bit against f64
/// round-to-nearest-even at 11 significant bits (subnormal step below 2⁻¹⁴), `round_unorm16`'s
/// code `round(65535·v)` the nearest to `65535·clamp(x)` up to the f32 product's rounding
/// (2⁻⁹; its value is that code over 65535 within the division's 2.5 ULP). Inputs: random magnitudes over [2⁻³⁰, 2] of both signs,
/// f16 values, the exact midpoints between neighbours (ties), the edges of the subnormal range,
/// 0 and 1.
#[test]
fn storage_rounding_matches_f64() {
    use wgpu::util::DeviceExt;
    let g = common::gpu();
    let mut rng = common::rng(0x516);
    let mut xs: Vec<f32> = vec![
        0.0,
        1.0,
        -1.0,
        2f32.powi(-14),
        -2f32.powi(-14),
        2f32.powi(-24),
    ];
    for _ in 0..20000 {
        let e: f64 = rng.random_range(-30.0..1.0);
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        xs.push((sign * 2f64.powf(e)) as f32);
        // An f16 value, and the midpoint above it (exact in f32): a tie.
        let h = f16_reference(sign * 2f64.powf(e));
        let step = if h.abs() < 2f64.powi(-14) {
            2f64.powi(-24)
        } else {
            2f64.powi(h.abs().log2().floor() as i32 - 10)
        };
        xs.push(h as f32);
        xs.push((h + 0.5 * step) as f32);
        xs.push(rng.random_range(-0.2..1.2));
    }
    xs.resize(xs.len().div_ceil(4) * 4, 0.5);
    let text = "// #import shared/storage_round\n\
                @group(0) @binding(0) var<storage, read> xs: array<vec4<f32>>;\n\
                @group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;\n\
                @compute @workgroup_size(64)\n\
                fn main(@builtin(global_invocation_id) id: vec3<u32>) {\n\
                    let i = id.x;\n\
                    if i < arrayLength(&xs) {\n\
                        out[2u * i] = round_f16(xs[i]);\n\
                        out[2u * i + 1u] = round_unorm16(xs[i]);\n\
                    }\n\
                }\n";
    let wgsl = shadowgraph::low_level::kernels::resolve_source("test.storage_round", text)
        .expect("resolve");
    let d = &g.device;
    let kernel = shadowgraph::low_level::exec::ComputeKernel::new(d, "storage_round", &wgsl)
        .expect("harness compiles");
    let input = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("test.storage_round.in"),
        contents: bytemuck::cast_slice(&xs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (xs.len() * 2 * 4) as u64;
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test.storage_round.out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("test.storage_round"),
        layout: &kernel.layouts[0],
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(((xs.len() / 4) as u32).div_ceil(64), 1, 1);
    }
    let raw = shadowgraph::low_level::gpu::submit_and_read(d, &g.queue, enc, &out, "storage_round")
        .expect("readback");
    let got: &[f32] = bytemuck::cast_slice(&raw);
    let (mut f16_bad, mut unorm_bad) = (Vec::new(), Vec::new());
    for (i, &x) in xs.iter().enumerate() {
        let (v, c) = (i / 4, i % 4);
        let h = got[8 * v + c];
        let u = got[8 * v + 4 + c];
        let want = f16_reference(f64::from(x));
        if f64::from(h) != want {
            f16_bad.push((x, h, want));
        }
        // The code is the nearest to 65535·x, up to the f32 product's rounding (≤ 2⁻⁹ below
        // 65536): within that of a tie it may go either way.
        let exact = 65535.0 * f64::from(x).clamp(0.0, 1.0);
        let code = (f64::from(u) * 65535.0).round();
        if (code - exact).abs() > 0.5 + 2f64.powi(-9) {
            unorm_bad.push((x, u, exact));
        }
    }
    assert!(
        f16_bad.is_empty(),
        "round_f16: {} of {} differ, e.g. {:?}",
        f16_bad.len(),
        xs.len(),
        &f16_bad[..f16_bad.len().min(5)]
    );
    assert!(
        unorm_bad.is_empty(),
        "round_unorm16: {} of {} differ, e.g. {:?}",
        unorm_bad.len(),
        xs.len(),
        &unorm_bad[..unorm_bad.len().min(5)]
    );
}
