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

fn check(g: &Gpu, seed: u64, case: &Case) {
    let what = format!(
        "{}×{} M = {} search {:?} moments {:?} {:?} {:?}",
        case.w, case.h, case.terms, case.search, case.moments, case.variant, case.storage
    );
    let mut rng = common::rng(seed);
    let (raw, lin) = depth(&mut rng, case.w, case.h, case.bad);
    // VSM's second moment passes 1 at depth steps near z = 1 (the derivative term); EVSM's
    // moments span ±exp(2c).
    let (lo, hi) = match case.moments {
        Some(Moments::Vsm) => (-1.0, 2.0),
        Some(Moments::Evsm { .. }) => {
            let e = (2.0 * case.exp[0].max(case.exp[1])).exp();
            (-e, e)
        }
        _ => (-1.0, 1.0),
    };
    let coding = match case.variant {
        SatVariant::Fixed => SatCoding::fixed(lookup_area(24.0, 24.0), [lo; 4], [hi; 4]),
        SatVariant::Float => SatCoding::float([lo; 4], [hi; 4]),
    }
    .expect("coding");
    // The shipped layout: fixed-point basis tables interleaved as many a texture as fit.
    let layers = if case.moments.is_some() {
        1
    } else {
        basis_sequence(case.terms, case.search).len() as u32
    };
    let interleave = basis_interleave(case.w as u32, layers, case.variant);
    let (tables, steps, stats) = run(g, case, &raw, coding, interleave);
    // The redesign layout (on a device with subgroups the tile passes by subgroup scans,
    // shared/sat_strip): the same dispatches and counts, fixed-point tables bit for bit, f32
    // tables checked below against the same reference and tolerance.
    let redesign = run_in(g, case, &raw, coding, interleave, KernelLayout::Redesign);
    assert_eq!(redesign.1, steps, "{what}: the redesign's dispatches");
    assert_eq!(redesign.2, stats, "{what}: the redesign's non-finite count");
    if case.variant == SatVariant::Fixed {
        for (m, (a, b)) in tables.iter().zip(&redesign.0).enumerate() {
            if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
                panic!(
                    "{what} table {m}: redesign word {i} is {:#x}, shipped {:#x}",
                    b[i], a[i]
                );
            }
        }
    }
    if interleave > 1 {
        // A texture a table, and two a texture (the last holding the rest: with nine tables
        // five textures, two pass-3 dispatches), hold the same words (each its own channels;
        // an interleaved table has its texture's, the widest table's, the rest 0).
        let texels = case.w * case.h;
        for other in [1, 2] {
            let (words, steps_other, _) = run(g, case, &raw, coding, other);
            for (m, (a, t)) in words.iter().zip(&tables).enumerate() {
                let (na, nt) = (a.len() / texels, t.len() / texels);
                let n = na.min(nt);
                let same = a.chunks(na).zip(t.chunks(nt)).all(|(x, y)| {
                    x[..n] == y[..n] && x[n..].iter().chain(&y[n..]).all(|&w| w == 0)
                });
                assert!(
                    same,
                    "{what} table {m}: {other} a texture against {interleave}, it differs"
                );
            }
            let textures = tables.len().div_ceil(other as usize);
            assert_eq!(
                steps_other,
                2 + textures.div_ceil(LAYERED_SAT_OUTPUTS as usize),
                "{what}: dispatches, {other} tables a texture"
            );
        }
    }
    let [c_pos, c_neg] = case.exp.map(f64::from);
    let want = match case.moments {
        Some(Moments::Msm) => vec![cpu::msm::msm(&lin, true)],
        Some(Moments::Vsm) => vec![cpu::vsm::vsm(&lin)],
        Some(Moments::Evsm { four }) => {
            let m = cpu::evsm::evsm(&lin, c_pos, c_neg);
            let n = if four { 4 } else { 2 };
            vec![Texels {
                channels: n,
                data: m.data.chunks(4).flat_map(|t| t[..n].to_vec()).collect(),
                ..m
            }]
        }
        Some(Moments::Esm) => vec![cpu::esm::esm_linear(&lin, c_pos)],
        None => basis(&lin, case.terms, case.search),
    };
    let moments = case.search == Some(CssmSearch::Moments);
    assert_eq!(tables.len(), want.len(), "{what}: tables");
    // The edges of every layer, the carries, four textures a dispatch.
    let per = LAYERED_SAT_OUTPUTS as usize;
    let textures = want.len().div_ceil(interleave as usize);
    assert_eq!(steps, 2 + textures.div_ceil(per), "{what}: dispatches");
    // Pass 1's layer 0 counts each non-finite texel once; nothing else counts.
    assert_eq!(stats, vec![case.bad as u32], "{what}: non-finite count");
    let texels = case.w * case.h;
    for (m, (words, v)) in tables.iter().zip(&want).enumerate() {
        let n = v.channels;
        // The format has the channels, or four for three (no three-channel format); the
        // fourth is 0 (the kernel's basis is 0 past the sequence). Interleaved tables have
        // their texture's format, the widest of its tables'.
        let stride = words.len() / texels;
        assert!(
            words.len() == texels * stride
                && stride >= n
                && (stride == n || interleave > 1 || n == 3),
            "{what} table {m}: {stride} channels for {n}"
        );
        assert!(
            words.chunks(stride).all(|t| t[n..].iter().all(|&w| w == 0)),
            "{what} table {m}: unused channel"
        );
        let decoded = decode_table(words, case.w, case.h, &coding, n);
        // MSM's quantized moments: MSM's table, or CSSM's moment map (its last table).
        let quantized = case.moments == Some(Moments::Msm) || (moments && m == want.len() - 1);
        let mut tol: Vec<f64> = v
            .data
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                // EVSM's channels: pos, pos², neg, neg².
                let channel = i % v.channels;
                if case.moments == Some(Moments::Vsm) {
                    vsm_tolerance(case.storage, x)
                } else if let Some(Moments::Evsm { .. }) = case.moments {
                    let c = if channel < 2 { c_pos } else { c_neg };
                    exp_tolerance(c, channel % 2 == 1, case.storage, x)
                } else if case.moments == Some(Moments::Esm) {
                    exp_tolerance(c_pos, false, case.storage, x)
                } else if quantized {
                    msm_tolerance(case.storage, x)
                } else {
                    basis_tolerance(case.terms, case.storage, x)
                }
            })
            .collect();
        if case.variant == SatVariant::Fixed {
            // Each code is rounded (½/scale; one scale for every channel of [−1, 1]) from the
            // f32 value less the offset (0 here); decoding rounds to f32 once more.
            assert!(coding.scale.iter().all(|&s| s == coding.scale[0]));
            let quantum = 0.5 / f64::from(coding.scale[0]);
            tol.iter_mut().for_each(|t| *t += quantum + U);
            common::assert_within(&format!("{what} table {m}"), &decoded, &v.data, &tol);
        } else {
            check_float(&format!("{what} table {m}"), words, v, &coding, &tol);
            let what = format!("{what} table {m}, redesign");
            check_float(&what, &redesign.0[m], v, &coding, &tol);
        }
    }
}

/// The f32 table against the f64 table of the f64 basis: within the scan tree's rounding,
/// `float_sum_depth`·U·Σ|x| over each texel's rectangle, plus the basis error summed over it.
fn check_float(what: &str, words: &[u32], v: &Texels, coding: &SatCoding, basis_tol: &[f64]) {
    let exact = reference::sat(&reference::scaled_texels(v, coding));
    let abs = reference::sat(&Texels {
        data: v.data.iter().map(|x| x.abs()).collect(),
        ..v.clone()
    });
    let errors = reference::sat(&Texels {
        data: basis_tol.to_vec(),
        ..v.clone()
    });
    let depth = f64::from(float_sum_depth(v.width as u32, v.height as u32));
    let n = v.channels;
    let stride = words.len() / (v.width * v.height);
    let got: Vec<f32> = words
        .chunks(stride)
        .flat_map(|t| t[..n].iter().map(|&b| f32::from_bits(b)))
        .collect();
    let mut want = Vec::with_capacity(got.len());
    let mut tol = Vec::with_capacity(got.len());
    for i in 0..v.width * v.height {
        for c in 0..n {
            want.push(exact.data[i * 4 + c]);
            tol.push(depth * U * abs.data[i * n + c] + errors.data[i * n + c]);
        }
    }
    common::assert_within(what, &got, &want, &tol);
}

#[test]
fn layered_csm_tables_match_the_f64_basis() {
    let g = common::gpu();
    let cases = [
        // CSSM M = 8 (4 + 5 tables, three pass-3 dispatches), 4 × 3 tiles, the last ragged.
        Case {
            w: 200,
            h: 130,
            terms: 8,
            search: Some(CssmSearch::CsmZ),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 11,
        },
        // Odd M: the last CSM table two channels, the last CSM-Z one three; f32 sums.
        Case {
            w: 70,
            h: 150,
            terms: 3,
            search: Some(CssmSearch::CsmZ),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F32,
            bad: 6,
        },
        // CSM alone, M = 16 (8 tables, two dispatches), one exact tile, f16 storage.
        Case {
            w: 64,
            h: 64,
            terms: 16,
            search: None,
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F16,
            bad: 5,
        },
        // CSSM M = 8 with the moment search (4 + 1 tables, two pass-3 dispatches).
        Case {
            w: 200,
            h: 130,
            terms: 8,
            search: Some(CssmSearch::Moments),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 7,
        },
        // The moment search at odd M, f32 sums, f16 storage.
        Case {
            w: 90,
            h: 70,
            terms: 5,
            search: Some(CssmSearch::Moments),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 6,
        },
        // MSM's quantized moments alone (msm_soft, msm with `filter = "sat"`): one layer, no
        // terms; unorm16 and f16 rounding, both variants.
        Case {
            w: 150,
            h: 100,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::Unorm16,
            bad: 7,
        },
        Case {
            w: 64,
            h: 97,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 5,
        },
        Case {
            w: 33,
            h: 70,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
        // CSM at M = 1: one two-channel table, so two-channel edges and carries.
        Case {
            w: 40,
            h: 33,
            terms: 1,
            search: None,
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 5,
        },
        // VSM's moments alone (vssm, vsm with `filter = "sat"`): one two-channel layer, the
        // derivatives from the neighbours' depth at ragged tile and map edges; both variants,
        // f32 and f16.
        Case {
            w: 150,
            h: 77,
            terms: 0,
            search: None,
            moments: Some(Moments::Vsm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 7,
        },
        Case {
            w: 64,
            h: 97,
            terms: 0,
            search: None,
            moments: Some(Moments::Vsm),
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 6,
        },
        // EVSM's moments (evsm4 and evsm2 with `filter = "sat"`) and ESM's exp(c (z − 1))
        // (esm with `filter = "sat"`): one layer of four, two and one channel.
        Case {
            w: 130,
            h: 70,
            terms: 0,
            search: None,
            moments: Some(Moments::Evsm { four: true }),
            exp: [5.0, 4.0],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
        Case {
            w: 70,
            h: 45,
            terms: 0,
            search: None,
            moments: Some(Moments::Evsm { four: false }),
            exp: [5.5, 0.0],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 5,
        },
        Case {
            w: 100,
            h: 67,
            terms: 0,
            search: None,
            moments: Some(Moments::Esm),
            exp: [20.0, 0.0],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
    ];
    for (k, case) in cases.iter().enumerate() {
        check(&g, 0xC55 + k as u64, case);
    }
}

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
