//! Helpers shared by the GPU tests.
#![allow(dead_code, unused_imports, reason = "each test binary uses a subset")]

pub mod evaluate;
pub mod host;
pub mod poison;
pub mod soft;
pub mod soft_maps;

use rand::{Rng, SeedableRng, rngs::SmallRng};
use shadowgraph::low_level::gpu::Gpu;

/// The device every GPU test runs on. No adapter is a failure, never a skip.
pub fn gpu() -> Gpu {
    match Gpu::new() {
        Ok(g) => g,
        Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
    }
}

/// A 2-D `w × h` texture of `format` that kernels sample (`TEXTURE_BINDING | COPY_DST`), holding
/// `data` (its texels' bytes, rows packed): a graph's imported input.
pub fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    data: &[u8],
) -> wgpu::Texture {
    let t = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
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
    shadowgraph::low_level::gpu::write_texture(queue, &t, data);
    t
}

/// A seeded RNG so failures reproduce.
pub fn rng(seed: u64) -> SmallRng {
    SmallRng::seed_from_u64(seed)
}

/// Asserts that two GPU read-backs of the same map (e.g. one run in each kernel layout,
/// `exec::KernelLayout`) hold the same f32 bits everywhere, NaNs included; names the first
/// value that differs.
pub fn assert_same_bits(
    what: &str,
    a: &shadowgraph::low_level::cpu::Texels,
    b: &shadowgraph::low_level::cpu::Texels,
) {
    assert_eq!(a.data.len(), b.data.len(), "{what}: length");
    let bits = |v: f64| (v as f32).to_bits();
    if let Some(i) = (0..a.data.len()).find(|&i| bits(a.data[i]) != bits(b.data[i])) {
        panic!(
            "{what}: differ at value {i} (texel {}): {} against {}",
            i / a.channels.max(1),
            a.data[i],
            b.data[i]
        );
    }
}

/// Asserts `|gpu − ref| ≤ atol + rtol·|ref|` everywhere, reporting the worst index, its error
/// and the number of mismatches.
pub fn assert_close(what: &str, gpu: &[f32], reference: &[f64], atol: f64, rtol: f64) {
    let tolerance: Vec<f64> = reference.iter().map(|r| atol + rtol * r.abs()).collect();
    assert_within(what, gpu, reference, &tolerance);
}

/// Asserts `|gpu[i] − ref[i]| ≤ tolerance[i]` (a per-value bound), reporting the worst excess.
pub fn assert_within(what: &str, gpu: &[f32], reference: &[f64], tolerance: &[f64]) {
    assert_eq!(gpu.len(), reference.len(), "{what}: length");
    assert_eq!(gpu.len(), tolerance.len(), "{what}: tolerances");
    let mut worst = (0usize, f64::NEG_INFINITY);
    let mut mismatches = 0;
    for (i, ((&g, &r), &tol)) in gpu.iter().zip(reference).zip(tolerance).enumerate() {
        let excess = if g.is_finite() {
            (f64::from(g) - r).abs() - tol
        } else {
            f64::INFINITY
        };
        if excess > 0.0 {
            mismatches += 1;
        }
        if excess > worst.1 {
            worst = (i, excess);
        }
    }
    let i = worst.0;
    assert!(
        mismatches == 0,
        "{what}: {mismatches} of {} values off; worst at {i}: gpu {} ref {} (error {:e}, allowed {:e})",
        gpu.len(),
        gpu[i],
        reference[i],
        (f64::from(gpu[i]) - reference[i]).abs(),
        tolerance[i]
    );
}

/// The f32-vs-f64 error models, from the library's one tolerance module
/// (`shadowgraph::low_level::tolerance`), which the numerical-stability suite uses too.
pub use shadowgraph::low_level::tolerance::{
    csm as csm_tolerance, esm as esm_tolerance, esm_sat as esm_sat_tolerance,
    evsm as evsm_tolerance, msm as msm_tolerance, vsm as vsm_tolerance,
};

/// A linear depth map with structure: a background and overlapping random rectangles, so
/// windows see mixes of occluders (never all zeros).
pub fn blocky_map(rng: &mut SmallRng, size: usize) -> Vec<f32> {
    let mut m: Vec<f32> = (0..size * size)
        .map(|_| rng.random_range(0.85..0.95))
        .collect();
    for _ in 0..12 {
        let (x0, y0) = (rng.random_range(0..size), rng.random_range(0..size));
        let (w, h) = (rng.random_range(2..size / 3), rng.random_range(2..size / 3));
        let z: f32 = rng.random_range(0.15..0.7);
        for y in y0..(y0 + h).min(size) {
            for x in x0..(x0 + w).min(size) {
                m[y * size + x] = z + rng.random_range(0.0..0.02);
            }
        }
    }
    m
}

/// The f64 reference `f` at sample `s`, or `None` where nudging the receiver by ±1e-4 texel in
/// UV or ±2e-6 in depth makes it jump by more than 1e-3 (a texel boundary or a comparison tie,
/// where f32 and f64 may legitimately disagree). Continuous changes (bilinear weights) stay
/// below that threshold; a single tap flipping moves every tested kernel by more.
pub fn robust(
    s: &shadowgraph::low_level::cpu::light::LightSample,
    map_size: usize,
    f: impl Fn(&shadowgraph::low_level::cpu::light::LightSample) -> f64,
) -> Option<f64> {
    let v = f(s);
    let du = 1e-4 / map_size as f64;
    let nudges = [
        (du, 0.0, 0.0),
        (-du, 0.0, 0.0),
        (0.0, du, 0.0),
        (0.0, -du, 0.0),
        (0.0, 0.0, 2e-6),
        (0.0, 0.0, -2e-6),
    ];
    for (dx, dy, dz) in nudges {
        let mut t = *s;
        t.uv = [s.uv[0] + dx, s.uv[1] + dy];
        t.depth += dz;
        if (f(&t) - v).abs() > 1e-3 {
            return None;
        }
    }
    Some(v)
}
