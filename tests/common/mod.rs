//! Helpers shared by the GPU tests.
#![allow(dead_code, reason = "each test binary uses a subset")]

use rand::{Rng, SeedableRng, rngs::SmallRng};
use shadowgraph::gpu::Gpu;

/// The device every GPU test runs on. No adapter is a failure, never a skip.
pub fn gpu() -> Gpu {
    match Gpu::new() {
        Ok(g) => g,
        Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
    }
}

/// A seeded RNG so failures reproduce.
pub fn rng(seed: u64) -> SmallRng {
    SmallRng::seed_from_u64(seed)
}

/// Asserts `|gpu − ref| ≤ atol + rtol·|ref|` everywhere, reporting the worst index, its error
/// and the number of mismatches.
pub fn assert_close(what: &str, gpu: &[f32], reference: &[f64], atol: f64, rtol: f64) {
    assert_eq!(gpu.len(), reference.len(), "{what}: length");
    let mut worst = (0usize, 0.0f64);
    let mut mismatches = 0;
    for (i, (&g, &r)) in gpu.iter().zip(reference).enumerate() {
        let err = (f64::from(g) - r).abs();
        let bad = !g.is_finite() || err > atol + rtol * r.abs();
        if bad {
            mismatches += 1;
        }
        if bad || err > worst.1 {
            worst = (i, if g.is_finite() { err } else { f64::INFINITY });
        }
    }
    assert!(
        mismatches == 0,
        "{what}: {mismatches} of {} values off (atol {atol}, rtol {rtol}); worst at {}: gpu {} ref {} (error {:e})",
        gpu.len(),
        worst.0,
        gpu[worst.0],
        reference[worst.0],
        worst.1
    );
}

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
    s: &shadowgraph::cpu::light::LightSample,
    map_size: usize,
    f: impl Fn(&shadowgraph::cpu::light::LightSample) -> f64,
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
