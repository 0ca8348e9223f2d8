//! Depth biases against the bias-free ray cast: renders a scene once per bias setting of its
//! first light (constant only, slope-scaled only, normal offset only, the scene's own, and
//! receiver-plane), then with the second-depth techniques (`midpoint`, `second_depth`: no bias;
//! the far plane where a texel has no second surface), and counts, over the pixels the f64 ray
//! cast finds relevant, *acne* (the ray cast sees the light's centre, the render's visibility
//! < ½) and *leak* (the ray cast does not, the render ≥ ½).
//! `cargo run --release --example bias_modes -- scenes/grazing.toml [MAP]` (`MAP`: the first
//! light's map side instead of the scene's).

use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::emitter;
use shadowgraph::low_level::truth::raycast::ray_cast_truth;

/// (label, bias, slope_bias, normal_bias, receiver_plane cap).
type Mode = (&'static str, f32, f32, f32, f32);

/// The second-depth techniques (they read no bias: 0).
const SECOND_DEPTH: &[(&str, &str, f32)] = &[
    ("midpoint", "midpoint", 0.0),
    ("second_depth", "second_depth", 0.0),
];

const MODES: &[Mode] = &[
    ("constant 0.0005", 0.0005, 0.0, 0.0, 0.0),
    ("constant 0.002", 0.002, 0.0, 0.0, 0.0),
    ("constant 0.005", 0.005, 0.0, 0.0, 0.0),
    ("constant 0.01", 0.01, 0.0, 0.0, 0.0),
    ("slope 0.5", 0.0, 0.5, 0.0, 0.0),
    ("slope 1", 0.0, 1.0, 0.0, 0.0),
    ("slope 4", 0.0, 4.0, 0.0, 0.0),
    ("normal 0.5", 0.0, 0.0, 0.5, 0.0),
    ("normal 1", 0.0, 0.0, 1.0, 0.0),
    ("normal 2", 0.0, 0.0, 2.0, 0.0),
    ("receiver plane, cap 0.01", 0.0, 0.0, 0.0, 0.01),
    (
        "receiver plane + constant 0.0002, cap 0.01",
        0.0002,
        0.0,
        0.0,
        0.01,
    ),
];

/// Errors as one line, causes joined (`{:#}`), status 1.
fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> anyhow::Result<()> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("scenes/grazing.toml".into());
    let mut base = Scene::load(&path)?;
    if let Some(side) = std::env::args().nth(2) {
        base.lights[0].shadow_map = side.parse()?;
    }
    let truth = ray_cast_truth(&base, &emitter::centre_offset());
    let gpu = Gpu::new()?;
    let mut renderer = Renderer::new(&gpu.device);
    let lights = base.lights.len();
    let mut own = base.lights[0].shadow;
    own.receiver_plane = 0.0;
    let scene_own = (
        "the scene's own",
        own.bias,
        own.slope_bias,
        own.normal_bias,
        0.0,
    );
    println!(
        "{path}, light 0 ({}), map {}²: pixels over the relevant ones of the ray cast",
        base.lights[0].shadow.technique.name(),
        base.lights[0].shadow_map
    );
    println!("| bias | acne | leak |\n| --- | --- | --- |");
    let hard = base.lights[0].shadow.technique;
    let rows = MODES
        .iter()
        .chain([&scene_own])
        .map(|&(label, bias, slope, normal, cap)| (label, hard, (bias, slope, normal, cap)));
    let second = SECOND_DEPTH.iter().filter_map(|&(label, name, bias)| {
        let t = shadowgraph::low_level::technique::named(name, &[])?;
        Some((label, t, (bias, 0.0, 0.0, 0.0)))
    });
    for (label, technique, (bias, slope, normal, cap)) in rows.chain(second) {
        let mut scene = base.clone();
        let s = &mut scene.lights[0].shadow;
        (s.bias, s.slope_bias, s.normal_bias, s.receiver_plane) = (bias, slope, normal, cap);
        s.technique = technique;
        let frame = renderer.render(&gpu.device, &gpu.queue, &scene, RenderOptions::default())?;
        let (mut acne, mut leak, mut lit, mut dark) = (0u32, 0u32, 0u32, 0u32);
        for px in 0..(truth.width * truth.height) as usize {
            let i = px * lights;
            if !truth.mask[i] {
                continue;
            }
            let v = frame.visibility[i];
            if truth.visibility[i] > 0.5 {
                lit += 1;
                acne += u32::from(v < 0.5);
            } else {
                dark += 1;
                leak += u32::from(v >= 0.5);
            }
        }
        let pct = |a: u32, b: u32| 100.0 * f64::from(a) / f64::from(b.max(1));
        println!(
            "| {label} | {:.2}% of {lit} lit | {:.2}% of {dark} shadowed |",
            pct(acne, lit),
            pct(leak, dark)
        );
    }
    Ok(())
}
