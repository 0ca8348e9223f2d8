//! The layered summed-area tables of the CSM and CSM-Z basis (`technique::add_csm_tables`,
//! `sat::layers`): the tile passes compute each basis map from the depth on the fly, so the
//! table's input is no longer a stored map but the basis the kernel computes. The contract
//! tested here: every table, decoded texel by texel (each texel's 1×1 window, which determines
//! the whole table), is the f64 basis (`cpu::csm`, `cpu::csm_z`) of the f64 linear depth
//! within the basis' f32 error and the coding's quantization; in fixed point its windows are
//! exact sums of those codes (wrapping u32, as the integer reference `cpu::sat::sat_fixed`
//! sums them), in f32 every table texel is within the scan's rounding bound of the f64 table.
//! Random depth with NaN and ±Inf texels (counted once), ragged tiles, both variants, CSM
//! alone, CSSM's CSM + CSM-Z and CSSM's CSM + MSM's quantized moments (`cpu::msm`), MSM's
//! moments alone, VSM's moments alone (`cpu::vsm`, the derivatives from the neighbours' depth),
//! EVSM's (`cpu::evsm`, four and two channels) and ESM's (`cpu::esm_linear`), f32, f16 and
//! unorm16 storage.

#[path = "../common/mod.rs"]
mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::low_level::cpu::{self, Texels, sat as reference};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{Gpu, read_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, layer_of, plan, texel_bytes};
use shadowgraph::low_level::sat::layers::LAYERED_SAT_OUTPUTS;
use shadowgraph::low_level::sat::{
    SAT_TILE, SatCoding, decode_table, float_sum_depth, lookup_area,
};
use shadowgraph::low_level::technique::{
    CsmBasis, MomentTable, Moments, add_csm_tables, add_moment_table, basis_interleave,
    basis_sequence, csm_maps, csm_z_maps,
};
use shadowgraph::low_level::wgsl_mirrors::LinearizeParams;
use shadowgraph::{CssmSearch, SatVariant, Storage};

mod storage_round;
mod tables;

/// f32's unit roundoff.
const U: f64 = 1.0 / (1u64 << 24) as f64;

/// One case: map size, terms, the blocker search's maps too, coding variant, storage,
/// non-finite texels.
struct Case {
    w: usize,
    h: usize,
    terms: u32,
    search: Option<CssmSearch>,
    /// MSM's quantized or VSM's moments alone (`technique::add_moment_table`; `terms`,
    /// `search` unused).
    moments: Option<Moments>,
    /// EVSM's (c⁺, c⁻), ESM's (c, unused).
    exp: [f32; 2],
    variant: SatVariant,
    storage: Storage,
    bad: usize,
}

/// An orthographic depth buffer (linear already): smooth ramps with steps, values over
/// [0, 1], and `bad` NaN / ±Inf texels at distinct places, the first on a tile's edges (in
/// the one-texel border that VSM's moments read around a sub-block: read by two tiles and
/// counted by one, tile columns and rows SAT_TILE − 1 and SAT_TILE, and the map's last column
/// and row, where they exist), the rest at random; with the f64 linear depth (non-finite → 1.0).
fn depth(rng: &mut impl Rng, w: usize, h: usize, bad: usize) -> (Vec<f32>, Texels) {
    let (a, b): (f32, f32) = (rng.random_range(-0.4..0.4), rng.random_range(-0.4..0.4));
    let mut raw: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let step = if rng.random_bool(0.1) { -0.3 } else { 0.0 };
            (0.5 + a * x + b * y + step + rng.random_range(-0.05..0.05)).clamp(0.0, 1.0)
        })
        .collect();
    let t = SAT_TILE as usize;
    let mut edges = Vec::new();
    for (x, y) in [
        (t, 0),
        (0, t),
        (t - 1, 1),
        (1, t - 1),
        (w - 1, h / 2),
        (w / 2, h - 1),
    ] {
        if x < w && y < h {
            edges.push(y * w + x);
        }
    }
    let mut places: Vec<usize> = Vec::new();
    while places.len() < bad {
        let at = edges
            .get(places.len())
            .copied()
            .unwrap_or_else(|| rng.random_range(0..raw.len()));
        if !places.contains(&at) {
            places.push(at);
        }
    }
    for (k, &at) in places.iter().enumerate() {
        raw[at] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][k % 3];
    }
    let data = raw
        .iter()
        .map(|&d| if d.is_finite() { f64::from(d) } else { 1.0 })
        .collect();
    (
        raw,
        Texels {
            width: w,
            height: h,
            channels: 1,
            data,
        },
    )
}

/// The tables of `case` on the GPU (every planned texture poisoned first, all bits set), as
/// raw words, with the plan's step count and each step's non-finite count; in each of the
/// kernels' two layouts (`exec::KernelLayout`: pass 3's second sweep loading and encoding its
/// texels again, as on a GPU, or reading the first sweep's kept in private memory, as on a
/// CPU driver), which must agree bit for bit, counts included.
fn run(
    g: &Gpu,
    case: &Case,
    raw: &[f32],
    coding: SatCoding,
    interleave: u32,
) -> (Vec<Vec<u32>>, usize, Vec<u32>) {
    let recomputed = run_in(g, case, raw, coding, interleave, KernelLayout::Gpu);
    let kept = run_in(g, case, raw, coding, interleave, KernelLayout::Cpu);
    for (m, (a, b)) in recomputed.0.iter().zip(&kept.0).enumerate() {
        if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
            panic!(
                "{}×{} {:?} interleave {interleave}: table {m}, GPU layout against CPU layout: \
                 word {i} is {:#x} against {:#x}",
                case.w, case.h, case.moments, a[i], b[i]
            );
        }
    }
    assert_eq!(recomputed.1, kept.1, "steps in the two layouts");
    assert_eq!(
        recomputed.2, kept.2,
        "non-finite counts, GPU layout against CPU layout"
    );
    recomputed
}

/// [`run`] in one layout.
fn run_in(
    g: &Gpu,
    case: &Case,
    raw: &[f32],
    coding: SatCoding,
    interleave: u32,
    layout: KernelLayout,
) -> (Vec<Vec<u32>>, usize, Vec<u32>) {
    let mut graph = Graph::default();
    let (w, h) = (case.w as u32, case.h as u32);
    graph.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
    let tables = if let Some(moments) = case.moments {
        let m = MomentTable {
            moments,
            exp: case.exp,
            storage: case.storage,
            depth: LinearizeParams::ORTHOGRAPHIC,
        };
        vec![add_moment_table(&mut graph, 0, "in", &m, coding)]
    } else {
        let basis = CsmBasis {
            terms: case.terms,
            search: case.search,
            storage: case.storage,
            depth: LinearizeParams::ORTHOGRAPHIC,
            interleave,
        };
        add_csm_tables(&mut graph, 0, "in", &basis, coding)
    };
    let names: Vec<&str> = tables.iter().map(String::as_str).collect();
    let plan = plan(&graph, &names).expect("plan");
    let input = common::upload(
        &g.device,
        &g.queue,
        "test.csm_sat.depth",
        (w, h),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(raw),
    );
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut exec = Executor::new();
    exec.kernels.set_layout(layout);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    for (name, t) in &out.textures {
        if name != "in" {
            let bytes = texel_bytes(t.format()) as usize * (t.width() * t.height()) as usize;
            write_texture(&g.queue, t, &vec![0xFF; bytes]);
        }
    }
    out.copy_stats(&mut enc);
    submit_and_wait(&g.device, &g.queue, enc, "csm_sat").expect("run");
    // Each table, split out of the texture that holds it (interleaved along x with others).
    let words = tables
        .iter()
        .flat_map(|t| {
            let bytes = read_texture(&g.device, &g.queue, &out.textures[t], 0).expect("read");
            let words: Vec<u32> = bytemuck::cast_slice(&bytes).to_vec();
            let n = plan
                .resource(t)
                .map_or(0, |r| r.resource.layers.len())
                .max(1);
            let per_texel = words.len() / (n * case.w * case.h);
            (0..n)
                .map(|k| layer_of(&words, per_texel, n, k))
                .collect::<Vec<_>>()
        })
        .collect();
    let stats = out.read_stats(&g.device).expect("stats");
    (words, plan.steps.len(), stats.iter().map(|s| s.1).collect())
}

/// Per table, the f64 basis of `lin`: its channels of the CSM sequence (2M) then, with
/// `search`, of the CSM-Z sequence (2M + 1), four a table, or MSM's four quantized moments.
fn basis(lin: &Texels, terms: u32, search: Option<CssmSearch>) -> Vec<Texels> {
    let chunks = |t: Texels, maps: u32| -> Vec<Texels> {
        (0..maps as usize)
            .map(|m| {
                let n = (t.channels - 4 * m).min(4);
                let data = t
                    .data
                    .chunks(t.channels)
                    .flat_map(|c| c[4 * m..4 * m + n].to_vec())
                    .collect();
                Texels {
                    channels: n,
                    data,
                    ..t.clone()
                }
            })
            .collect()
    };
    let mut out = chunks(cpu::csm::csm(lin, terms), csm_maps(terms));
    match search {
        Some(CssmSearch::CsmZ) => {
            out.extend(chunks(cpu::csm_z::csm_z(lin, terms), csm_z_maps(terms)));
        }
        Some(CssmSearch::Moments) => out.push(cpu::msm::msm(lin, true)),
        None => {}
    }
    out
}

/// The GPU's basis values against f64: Vulkan's sin/cos is within 2⁻¹¹ absolute on
/// [−π, π] (the kernel reduces its argument there); forming and reducing the argument (2k − 1)·z ≤
/// 2M − 1 rounds it by ≤ 2·U·(2M − 1), moved by π (slope ≤ 1); the CSM-Z product (|z| ≤ 1)
/// adds a rounding; f16 storage rounds each value by 2⁻¹¹ relative.
fn basis_tolerance(terms: u32, storage: Storage, v: f64) -> f64 {
    2f64.powi(-11) + 2.0 * U * f64::from(2 * terms - 1) * std::f64::consts::PI + U + f16(storage, v)
}

/// f16 storage's rounding of `v` (2⁻¹¹ relative), 0 for f32.
fn f16(storage: Storage, v: f64) -> f64 {
    if storage == Storage::F16 {
        2f64.powi(-11) * v.abs()
    } else {
        0.0
    }
}

/// MSM's quantized moments against f64: the power moments (≤ 1) through the quantization
/// matrix in f32, four products with entries up to 82 and their sum (6·82·U), then the
/// storage's rounding (f16 2⁻¹¹ relative, unorm16 half of 1/65535, 2⁻¹⁷).
fn msm_tolerance(storage: Storage, v: f64) -> f64 {
    let unorm16 = if storage == Storage::Unorm16 {
        2f64.powi(-17)
    } else {
        0.0
    };
    6.0 * 82.0 * U + f16(storage, v) + unorm16
}

/// VSM's moments against f64 (`cpu::vsm`): z exact; z² + ¼(∂x² + ∂y²), a sum of non-negative
/// terms, rounded by at most six f32 operations (each difference, square, the products and the
/// sums: 6·U relative), and where the two one-sided differences are equal within their
/// rounding f32 may take the other, whose square differs by 4·U of it: 8·U·|v|; then the
/// storage's rounding (f16 2⁻¹¹ relative).
fn vsm_tolerance(storage: Storage, v: f64) -> f64 {
    8.0 * U * v.abs() + f16(storage, v)
}

/// SPIR-V's exp: (3 + 2|x|) ULP (2⁻²³ relative each) at |x| ≤ c; the argument c·(2z − 1)
/// (EVSM) or c·(z − 1) (ESM) rounded twice, 2·c·U absolute, which moves exp by that relative;
/// EVSM's squares double both and add a rounding; then f16 storage's 2⁻¹¹ relative.
fn exp_tolerance(c: f64, squared: bool, storage: Storage, v: f64) -> f64 {
    let once = (3.0 + 2.0 * c) * 2f64.powi(-23) + 2.0 * c * U;
    let rel = if squared { 2.0 * once + U } else { once };
    rel * v.abs() + f16(storage, v)
}
