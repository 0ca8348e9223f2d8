//! Summed-area tables on the GPU against their references (`cpu::sat`): the fixed-point table
//! bit for bit against the wrapping-u32 reference, its window sums decoded against f64 sums of
//! the raw values; the f32 table against the f64 table within the rounding bound of its scan
//! tree; the rectangle-mean lookups of `shared/sat` against direct f64 integration; property
//! tests on random small maps.

#[path = "../common/mod.rs"]
mod common;

use std::cell::RefCell;
use std::collections::HashMap;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use rand::Rng;
use shadowgraph::SatVariant;
use shadowgraph::low_level::cpu::{Texels, sat as reference};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{Gpu, read_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, plan, texel_bytes};
use shadowgraph::low_level::kernels;
use shadowgraph::low_level::sat::five_pass::{SAT_BLOCK, SAT_CARRY_LINES, add_sat_five_pass};
use shadowgraph::low_level::sat::lookups::{Lookup, lookup_means};
use shadowgraph::low_level::sat::{
    SAT_LINES_PER_GROUP, SAT_TILE, SatCoding, SatParams, add_sat, float_sum_depth, format_channels,
    lookup_area,
};

mod layouts;
mod means;
mod structure;
mod tables;

/// f32's unit roundoff (round to nearest; Vulkan's f32 add, sub and mul are correctly rounded).
const U: f64 = 1.0 / (1u64 << 24) as f64;

/// Largest depth of the GPU's summation tree for one f32 table texel of a `w × h` map
/// (`sat::float_sum_depth`, derived from the kernels' order of additions): every f32 table
/// texel is within γ_d ≈ d·U of Σ|values| over its rectangle.
fn scan_depth(w: usize, h: usize) -> f64 {
    f64::from(float_sum_depth(w as u32, h as u32))
}

/// A random representation: `channels` f32 values per texel in `[lo, hi)`, never all zero.
#[derive(Clone, Debug)]
struct Map {
    w: usize,
    h: usize,
    channels: usize,
    values: Vec<f32>,
}

impl Map {
    fn random(rng: &mut impl Rng, w: usize, h: usize, channels: usize, lo: f32, hi: f32) -> Self {
        let values = (0..w * h * channels)
            .map(|_| rng.random_range(lo..hi))
            .collect();
        Self {
            w,
            h,
            channels,
            values,
        }
    }

    fn texels(&self) -> Texels {
        Texels::from_f32(self.w, self.h, self.channels, &self.values)
    }

    fn format(&self) -> wgpu::TextureFormat {
        match self.channels {
            1 => wgpu::TextureFormat::R32Float,
            2 => wgpu::TextureFormat::Rg32Float,
            _ => wgpu::TextureFormat::Rgba32Float,
        }
    }
}

/// A table built on the GPU: its texture (valid until the executor's next run) and bytes.
struct Table {
    texture: wgpu::Texture,
    bytes: Vec<u8>,
}

impl Table {
    /// The words of every texel, widened to four (the channels the format lacks read 0).
    fn fixed(&self) -> Vec<[u32; 4]> {
        let t = &self.texture;
        reference::widen(
            bytemuck::cast_slice(&self.bytes),
            (t.width() * t.height()) as usize,
        )
    }

    /// Four f32 values a texel, as [`Table::fixed`].
    fn float(&self) -> Vec<f32> {
        self.fixed()
            .as_flattened()
            .iter()
            .map(|&b| f32::from_bits(b))
            .collect()
    }
}

/// `add_sat`, or the five-pass baseline of `shadowgraph bench`.
type AddSat = fn(&mut Graph, usize, &str, &SatCoding) -> String;

/// Plans `add_sat` over `map` imported as `in`, runs it with every planned texture poisoned
/// (all bits set: NaN for floats) so unwritten texels show, and reads the table back; its
/// format has the map's channels.
fn build(g: &Gpu, exec: &mut Executor, map: &Map, coding: &SatCoding) -> Table {
    let table = build_with(g, exec, map, coding, add_sat);
    let channels = map.channels as u32;
    assert_eq!(table.texture.format(), coding.variant.format(channels));
    table
}

/// [`build`] with `add` in place of `add_sat`.
fn build_with(g: &Gpu, exec: &mut Executor, map: &Map, coding: &SatCoding, add: AddSat) -> Table {
    let mut graph = Graph::default();
    graph.import("in", map.format(), map.w as u32, map.h as u32, Some(0));
    let out = add(&mut graph, 0, "in", coding);
    let plan = plan(&graph, &[&out]).expect("plan");
    let input = common::upload(
        &g.device,
        &g.queue,
        "test.sat.input",
        (map.w as u32, map.h as u32),
        map.format(),
        bytemuck::cast_slice(&map.values),
    );
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let outputs = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    // Queue writes land before the submitted passes run.
    for (name, t) in &outputs.textures {
        if name != "in" {
            let bytes = texel_bytes(t.format()) as usize * (t.width() * t.height()) as usize;
            write_texture(&g.queue, t, &vec![0xFF; bytes]);
        }
    }
    // Intermediates the redesign layout keeps in storage buffers too.
    for b in outputs.buffers.values() {
        g.queue
            .write_buffer(&b.buffer, 0, &vec![0xFF; b.buffer.size() as usize]);
    }
    submit_and_wait(&g.device, &g.queue, enc, "sat").expect("run");
    let texture = outputs.textures[&out].clone();
    let bytes = read_texture(&g.device, &g.queue, &texture, 0).expect("readback");
    Table { texture, bytes }
}

/// Integer windows `[x0, x1) × [y0, y1)` to check: random ones, the full map, and windows at
/// the far corner and along the far edges (where the corner sums are largest).
fn windows(rng: &mut impl Rng, w: usize, h: usize, random: usize) -> Vec<[usize; 4]> {
    let k = w.min(h).min(7);
    let mut out = vec![
        [0, 0, w, h],
        [w - 1, h - 1, w, h],
        [w - k, h - k, w, h],
        [0, h - 1, w, h],
        [w - 1, 0, w, h],
    ];
    for _ in 0..random {
        let (a, b) = (rng.random_range(0..=w), rng.random_range(0..=w));
        let (c, d) = (rng.random_range(0..=h), rng.random_range(0..=h));
        out.push([a.min(b), c.min(d), a.max(b), c.max(d)]);
    }
    out
}

/// The fixed-point table equals the wrapping-u32 reference bit for bit; unused channels are 0;
/// every window decodes to the f64 sum of the raw values within its quantization:
/// `area·½/scale` (rounding each code) `+ U·Σ|v − offset|` (the f32 subtraction; the scale is
/// a power of two, so the product is exact). `max_window` bounds the windows checked.
fn check_fixed(
    what: &str,
    rng: &mut impl Rng,
    map: &Map,
    coding: &SatCoding,
    table: &Table,
    max_window: Option<usize>,
) {
    let input = map.texels();
    let expected = reference::sat_fixed(&input, coding);
    let got = &table.fixed();
    if let Some(i) = (0..expected.len()).find(|&i| got[i] != expected[i]) {
        let mismatches = (0..expected.len())
            .filter(|&i| got[i] != expected[i])
            .count();
        panic!(
            "{what}: {mismatches} of {} texels differ; first ({}, {}): gpu {:08x?} ref {:08x?}",
            expected.len(),
            i % map.w,
            i / map.w,
            got[i],
            expected[i]
        );
    }
    assert!(
        got.iter()
            .all(|t| t[map.channels..].iter().all(|&v| v == 0)),
        "{what}: unused channels"
    );
    let raw = reference::sat(&input);
    let dev = reference::sat(&Texels {
        data: input
            .data
            .iter()
            .enumerate()
            .map(|(i, &v)| (v - f64::from(coding.offset[i % map.channels])).abs())
            .collect(),
        ..input.clone()
    });
    let mut gpu = Vec::new();
    let mut want = Vec::new();
    let mut tol = Vec::new();
    for [x0, y0, x1, y1] in windows(rng, map.w, map.h, 200) {
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        if max_window.is_some_and(|m| x1 - x0 > m || y1 - y0 > m) {
            continue;
        }
        let codes = reference::window_fixed(got, map.w, x0, y0, x1, y1);
        let sums = reference::window(&raw, x0, y0, x1, y1);
        let spread = reference::window(&dev, x0, y0, x1, y1);
        for c in 0..map.channels {
            let decoded = reference::decode_window(f64::from(codes[c]), area, coding, c);
            gpu.push(decoded as f32);
            want.push(sums[c]);
            // The f32 of the decoded sum adds U·|sum|; the f64 sums are exact to ~1e-12.
            tol.push(
                area * 0.5 / f64::from(coding.scale[c]) + U * spread[c] + U * sums[c].abs() + 1e-9,
            );
        }
    }
    common::assert_within(&format!("{what}: decoded windows"), &gpu, &want, &tol);
}

/// The f32 table within `scan_depth`·U of Σ|x| of each texel's rectangle, x the scaled values
/// (≤ 42·U ≈ 2.5e-6 of the absolute sum up to 1024²); windows from four lookups within
/// (depth + 3)·U of the absolute sums at their four corners — fp32's weakness: the error
/// follows the corners, not the window.
fn check_float(what: &str, rng: &mut impl Rng, map: &Map, coding: &SatCoding, table: &Table) {
    let x = reference::scaled_texels(&map.texels(), coding);
    let exact = reference::sat(&x);
    let abs = reference::sat(&Texels {
        data: x.data.iter().map(|v| v.abs()).collect(),
        ..x.clone()
    });
    let got = table.float();
    let depth = scan_depth(map.w, map.h);
    let tol: Vec<f64> = abs.data.iter().map(|a| depth * U * a).collect();
    common::assert_within(&format!("{what}: table"), &got, &exact.data, &tol);
    let gpu_table = Texels::from_f32(map.w, map.h, 4, &got);
    let mut gpu = Vec::new();
    let mut want = Vec::new();
    let mut tol = Vec::new();
    for [x0, y0, x1, y1] in windows(rng, map.w, map.h, 200) {
        let g = reference::window(&gpu_table, x0, y0, x1, y1);
        let e = reference::window(&exact, x0, y0, x1, y1);
        let corners: Vec<f64> = (0..4)
            .map(|c| {
                [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                    .iter()
                    .map(|&(a, b)| reference::window(&abs, 0, 0, a, b)[c])
                    .sum()
            })
            .collect();
        for c in 0..4 {
            gpu.push(g[c] as f32);
            want.push(e[c]);
            tol.push((depth + 3.0) * U * corners[c] + U * e[c].abs());
        }
    }
    common::assert_within(&format!("{what}: windows"), &gpu, &want, &tol);
}
