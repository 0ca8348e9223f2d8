//! Summed-area tables on the GPU against their references (`cpu::sat`): the fixed-point table
//! bit for bit against the wrapping-u32 reference, its window sums decoded against f64 sums of
//! the raw values; the f32 table against the f64 table within the rounding bound of its scan
//! tree; the rectangle-mean lookups of `shared/sat` against direct f64 integration; property
//! tests on random small maps.

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

/// A `const NAME: u32` of a kernel, from naga's IR.
fn wgsl_const(module: &naga::Module, name: &str) -> Option<u32> {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))?;
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => Some(v),
        _ => None,
    }
}

#[test]
fn sat_tile_and_params_match_the_wgsl() {
    // A row workgroup of `sat_carries` covers whole tile rows (`ROWS` of them), one invocation
    // per row; the tile kernels' per-line steps take one invocation a tile row or column.
    assert_eq!(SAT_LINES_PER_GROUP, 2 * SAT_TILE);
    let wgsl = kernels::resolve("sat_carries", None).unwrap();
    let (module, _) = kernels::reflect("sat_carries", &wgsl).unwrap();
    assert_eq!(
        wgsl_const(&module, "ROWS"),
        Some(SAT_LINES_PER_GROUP / SAT_TILE)
    );
    for kernel in [
        "sat_tile_sums",
        "sat_tile_sums_f32",
        "sat_carries",
        "sat_tiles",
        "sat_tiles_f32",
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (module, r) = kernels::reflect(kernel, &wgsl).unwrap();
        assert_eq!(
            wgsl_const(&module, "TILE"),
            Some(SAT_TILE),
            "{kernel}: TILE"
        );
        let wg = r.workgroup_size.unwrap_or_default();
        assert_eq!(wg, [SAT_LINES_PER_GROUP, 1, 1], "{kernel}: workgroup");
        assert_eq!(
            kernels::struct_size(&module, "SatParams"),
            Some(size_of::<SatParams>() as u32),
            "{kernel}: SatParams vs struct SatParams"
        );
    }
    for kernel in [
        "sat_rows",
        "sat_carry",
        "sat_cols_reduce",
        "sat_cols",
        "sat_cols_f32",
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (module, r) = kernels::reflect(kernel, &wgsl).unwrap();
        let block = wgsl_const(&module, "BLOCK");
        let items = wgsl_const(&module, "ITEMS").unwrap_or(0);
        assert_eq!(block, Some(SAT_BLOCK), "{kernel}: BLOCK");
        let wg = r.workgroup_size.unwrap_or_default();
        if kernel == "sat_carry" {
            assert_eq!(wg, [SAT_CARRY_LINES, 1, 1], "{kernel}");
        } else {
            assert_eq!([wg[0] * items, wg[1], wg[2]], [SAT_BLOCK, 1, 1], "{kernel}");
        }
        assert_eq!(
            kernels::struct_size(&module, "SatParams"),
            Some(size_of::<SatParams>() as u32),
            "{kernel}: SatParams vs struct SatParams"
        );
    }
}

/// The sizes asked for, plus lines of several blocks each way (the carry passes).
const SIZES: [(usize, usize); 8] = [
    (1, 1),
    (1, 57),
    (61, 1),
    (1000, 37),
    (256, 256),
    (1024, 1024),
    (3000, 5),
    (3, 2100),
];

#[test]
fn fixed_sat_is_bit_identical_to_the_integer_reference() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(70);
    for (i, (w, h)) in SIZES.into_iter().enumerate() {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, 0.05, 1.0);
        // Every window of the map, the full map included, decodes exactly.
        let coding = SatCoding::fixed((w * h) as u64, [0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_fixed(
            &format!("fixed {w}x{h}"),
            &mut rng,
            &map,
            &coding,
            &table,
            None,
        );
    }
}

/// The kernels' two layouts (`exec::KernelLayout`: pass 3's second sweep loading its texels
/// again, as on a GPU, or reading the first sweep's kept in private memory, as on a CPU
/// driver) build the same tables bit for bit, fixed point and f32, one, two and four channels,
/// ragged tiles and single lines (the references above run the device's layout; this ties the
/// other to it).
#[test]
fn both_layouts_build_the_same_tables() {
    let g = common::gpu();
    let mut recomputed = Executor::new();
    recomputed.kernels.set_layout(KernelLayout::Gpu);
    let mut kept = Executor::new();
    kept.kernels.set_layout(KernelLayout::Cpu);
    let mut rng = common::rng(76);
    for (i, (w, h)) in [(1, 57), (61, 1), (100, 70), (33, 200)]
        .into_iter()
        .enumerate()
    {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, -0.5, 1.0);
        let codings = [
            SatCoding::fixed((w * h) as u64, [-0.5; 4], [1.0; 4]).unwrap(),
            SatCoding::float([-0.5; 4], [1.0; 4]).unwrap(),
        ];
        for coding in codings {
            let a = build(&g, &mut recomputed, &map, &coding).bytes;
            let b = build(&g, &mut kept, &map, &coding).bytes;
            let words = |x: &[u8]| bytemuck::cast_slice::<u8, u32>(x).to_vec();
            let (a, b) = (words(&a), words(&b));
            if let Some(k) = (0..a.len()).find(|&k| a[k] != b[k]) {
                panic!(
                    "{w}×{h}, {channels} channels, {:?}: word {k} is {:#x} in the GPU layout, \
                     {:#x} in the CPU layout",
                    coding.variant, a[k], b[k]
                );
            }
        }
    }
}

/// The redesign layout (`exec::KernelLayout::Redesign`: on a device with subgroups the tile
/// passes by subgroup scans, a lane a column, `kernels/shared/sat_strip.wgsl`; without them the
/// shipped passes) builds fixed-point tables bit for bit as the GPU layout does (wrapping sums
/// in any order), and f32 tables within the same scan bound of the f64 table (its summation
/// tree is no deeper than the shipped tile's: `sat::float_sum_depth`): one, two and four
/// channels, ragged tiles, single lines, several tiles each way.
#[test]
fn redesign_layout_builds_the_same_tables() {
    let g = common::gpu();
    let mut shipped = Executor::new();
    shipped.kernels.set_layout(KernelLayout::Gpu);
    let mut redesign = Executor::new();
    redesign.kernels.set_layout(KernelLayout::Redesign);
    let mut rng = common::rng(78);
    for (i, (w, h)) in [(1, 57), (61, 1), (100, 70), (33, 200), (257, 95)]
        .into_iter()
        .enumerate()
    {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, -0.5, 1.0);
        let fixed = SatCoding::fixed((w * h) as u64, [-0.5; 4], [1.0; 4]).unwrap();
        let a = build(&g, &mut shipped, &map, &fixed).bytes;
        let table = build(&g, &mut redesign, &map, &fixed);
        if let Some(k) = (0..a.len()).find(|&k| a[k] != table.bytes[k]) {
            panic!("{w}×{h}, {channels} channels: byte {k} differs from the GPU layout's");
        }
        let what = format!("redesign fixed {w}x{h}");
        check_fixed(&what, &mut rng, &map, &fixed, &table, None);
        let float = SatCoding::float([-0.5; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut redesign, &map, &float);
        let what = format!("redesign float {w}x{h}");
        check_float(&what, &mut rng, &map, &float, &table);
    }
}

/// The redesign's modules replace the shipped ones only in the redesign layout and only on a
/// device with the feature they need: elsewhere every kernel compiles as shipped.
#[test]
fn redesigned_sat_modules_need_the_redesign_layout_and_subgroups() {
    let all = wgpu::Features::SUBGROUP;
    assert!(
        KernelLayout::Redesign
            .module_sources(wgpu::Features::empty())
            .is_empty()
    );
    assert!(KernelLayout::Gpu.module_sources(all).is_empty());
    assert!(KernelLayout::Cpu.module_sources(all).is_empty());
    assert_eq!(
        KernelLayout::Redesign.module_sources(all),
        [
            ("shared/sat_tile_sums", "shared/sat_tile_sums_subgroup"),
            ("shared/sat_tile_scan", "shared/sat_tile_scan_subgroup"),
        ]
    );
}

#[test]
fn fixed_sat_wraps_yet_keeps_small_windows_exact() {
    // Scale for 33×33 windows of values in [-2, 3]: codes up to ±2²¹, corner sums near 2⁴⁰
    // wrap many times over, and every window of up to 33×33 is still exact.
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(71);
    let map = Map::random(&mut rng, 1024, 1024, 2, -2.0, 3.0);
    let coding = SatCoding::fixed(33 * 33, [-2.0; 4], [3.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &coding);
    check_fixed(
        "fixed 1024² (33² windows)",
        &mut rng,
        &map,
        &coding,
        &table,
        Some(33),
    );
    let (w, h) = (map.w, map.h);
    let small: Vec<[usize; 4]> = (0..300)
        .map(|_| {
            let (x, y) = (rng.random_range(0..w - 33), rng.random_range(0..h - 33));
            let (a, b) = (rng.random_range(1..=33), rng.random_range(1..=33));
            [x, y, x + a, y + b]
        })
        .chain([[w - 33, h - 33, w, h]])
        .collect();
    let raw = reference::sat(&map.texels());
    let words = table.fixed();
    for [x0, y0, x1, y1] in small {
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let codes = reference::window_fixed(&words, w, x0, y0, x1, y1);
        let sums = reference::window(&raw, x0, y0, x1, y1);
        for c in 0..2 {
            let d = reference::decode_window(f64::from(codes[c]), area, &coding, c);
            let tol = area * (0.5 / f64::from(coding.scale[c]) + 2.5 * U) + 1e-9;
            assert!(
                (d - sums[c]).abs() <= tol,
                "window {x0},{y0}..{x1},{y1} c{c}: {d} vs {}",
                sums[c]
            );
        }
    }
}

#[test]
fn fixed_sat_of_a_4096_map_is_bit_identical() {
    // The stability case: 4096² (4 column blocks and 4 row blocks a line), corner sums near
    // 2⁴⁴ in units of the scale for 64×64-texel lookups, wrapped; still bit for bit.
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(75);
    let map = Map::random(&mut rng, 4096, 4096, 1, 0.0, 1.0);
    let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &coding);
    check_fixed("fixed 4096²", &mut rng, &map, &coding, &table, Some(65));
}

#[test]
fn float_sat_is_within_the_scan_rounding_bound() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(72);
    for (i, (w, h)) in SIZES.into_iter().enumerate() {
        let channels = [4, 1, 2][i % 3];
        let map = Map::random(&mut rng, w, h, channels, 0.05, 1.0);
        let coding = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_float(&format!("float {w}x{h}"), &mut rng, &map, &coding, &table);
    }
}

#[test]
fn constant_depth_0_999_map() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(73);
    let (w, h) = (512, 384);
    let map = Map {
        w,
        h,
        channels: 1,
        values: vec![0.999; w * h],
    };
    let fixed = SatCoding::fixed((w * h) as u64, [0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &fixed);
    check_fixed("fixed constant", &mut rng, &map, &fixed, &table, None);
    // Every window holds exactly area × the code of 0.999.
    let code = reference::encode_fixed(0.999, &fixed, 0) as i32;
    let words = table.fixed();
    for [x0, y0, x1, y1] in windows(&mut rng, w, h, 100) {
        let area = ((x1 - x0) * (y1 - y0)) as i64;
        let got = reference::window_fixed(&words, w, x0, y0, x1, y1)[0];
        assert_eq!(
            i64::from(got),
            area * i64::from(code),
            "{x0},{y0}..{x1},{y1}"
        );
    }
    let float = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &float);
    check_float("float constant", &mut rng, &map, &float, &table);
}

/// Means over `rects` looked up on the GPU from `table` (`shared/sat`'s exact lookup of the
/// table's variant, by the library's probe kernel: one rectangle per invocation).
fn probe(g: &Gpu, table: &wgpu::Texture, coding: &SatCoding, rects: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let lookup = match coding.variant {
        SatVariant::Fixed => Lookup::Fixed,
        SatVariant::Float => Lookup::Float,
    };
    lookup_means(g, table, lookup, coding, rects).expect("probe")
}

/// Random rectangles up to `max` texels a side, some reversed, partly or wholly outside the
/// map, thinner than the minimum extent, the whole map and the far corner.
fn rects(rng: &mut impl Rng, w: f32, h: f32, max: f32) -> Vec<[f32; 4]> {
    let mut out = vec![
        // The whole map, or the largest rectangle at the far corner.
        [(w - max).max(0.0), (h - max).max(0.0), w, h],
        [w - 0.3, h - 0.7, w, h],
        [w - 2.5, h - 1.25, w + 3.0, h + 3.0],
        [-5.0, -5.0, -1.0, -1.0],
        [w + 1.0, 3.0, w + 2.0, 4.0],
        [2.5, 1.5, 2.5, 1.5],
        [w - 1.0, h - 1.0, w - 1.0 + 1e-4, h],
    ];
    for i in 0..300 {
        let (x, y) = (
            rng.random_range(-2.0..w + 1.0),
            rng.random_range(-2.0..h + 1.0),
        );
        let sw: f32 = rng.random_range(0.0..max.min(w + 3.0));
        let sh: f32 = rng.random_range(0.0..max.min(h + 3.0));
        out.push(if i % 5 == 0 {
            [x + sw, y + sh, x, y]
        } else {
            [x, y, x + sw, y + sh]
        });
    }
    out
}

/// The lookups against direct f64 integration of the raw map. Fixed: quantization ½/scale
/// plus U·max|v − o| (the subtraction), and the f32 weighting of the 16 windows: ≲ 32 roundings
/// of Σ|w·window| ≤ (lookup area)·max|v − o|, relative to the rectangle's area. Float: the
/// same weighting, plus every window's error, ≤ (depth + 3)·U times the absolute sums at
/// its four corners, each at most the sum over [0, X₁) × [0, Y₁), X₁, Y₁ the far node.
/// Both: 4·U·(|mean| + |offset|) for the area, the division and the final add.
fn check_means(what: &str, map: &Map, coding: &SatCoding, rects: &[[f32; 4]], got: &[[f32; 4]]) {
    let input = map.texels();
    let x = reference::scaled_texels(&input, coding);
    let abs = reference::sat(&Texels {
        data: x.data.iter().map(|v| v.abs()).collect(),
        ..x.clone()
    });
    // max |v − offset| per channel.
    let mut spread = [0.0f64; 4];
    for (i, &v) in input.data.iter().enumerate() {
        let c = i % map.channels;
        spread[c] = spread[c].max((v - f64::from(coding.offset[c])).abs());
    }
    let depth = scan_depth(map.w, map.h);
    let mut gpu = Vec::new();
    let mut want = Vec::new();
    let mut tol = Vec::new();
    for (rect, g) in rects.iter().zip(got) {
        let r = reference::clamp_rect(*rect, map.w, map.h);
        let (rw, rh) = (r[2] - r[0], r[3] - r[1]);
        let area = f64::from(rw) * f64::from(rh);
        let lookup = lookup_area(rw, rh) as f64;
        let far_x = ((r[2].floor() as usize) + 1).min(map.w);
        let far_y = ((r[3].floor() as usize) + 1).min(map.h);
        let corner = reference::window(&abs, 0, 0, far_x, far_y);
        let mean = reference::rect_mean(&input, *rect);
        for c in 0..map.channels {
            let s = f64::from(coding.scale[c]);
            let o = f64::from(coding.offset[c]);
            let weighting = 32.0 * U * lookup * spread[c] / area;
            let base = weighting + 4.0 * U * (mean[c].abs() + o.abs());
            let t = match coding.variant {
                SatVariant::Fixed => base + 0.5 / s + U * spread[c],
                SatVariant::Float => base + (depth + 3.0) * U * 4.0 * corner[c] / area,
            };
            gpu.push(g[c]);
            want.push(mean[c]);
            tol.push(t);
        }
    }
    common::assert_within(what, &gpu, &want, &tol);
}

#[test]
fn rect_mean_lookups_match_direct_integration() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(74);
    let (w, h) = (300, 270);
    let map = Map::random(&mut rng, w, h, 2, 0.0, 1.0);
    let (wf, hf) = (w as f32, h as f32);
    // Any rectangle, up to the whole map: the scale for the map's lookup area.
    let whole = rects(&mut rng, wf, hf, wf.max(hf));
    // Rectangles up to 8 texels: a 2⁵-times finer scale, and the table wraps.
    let small = rects(&mut rng, wf, hf, 8.0);
    let codings = [
        (
            SatCoding::fixed(lookup_area(wf, hf), [0.0; 4], [1.0; 4]).unwrap(),
            &whole,
        ),
        (
            SatCoding::fixed(lookup_area(8.0, 8.0), [0.0; 4], [1.0; 4]).unwrap(),
            &small,
        ),
        (SatCoding::float([0.0; 4], [1.0; 4]).unwrap(), &whole),
        (SatCoding::float([0.0; 4], [1.0; 4]).unwrap(), &small),
    ];
    for (coding, rects) in codings {
        let table = build(&g, &mut exec, &map, &coding);
        let means = probe(&g, &table.texture, &coding, rects);
        check_means(
            &format!("{:?} means, scale {}", coding.variant, coding.scale[0]),
            &map,
            &coding,
            rects,
            &means,
        );
    }
}

/// Random small maps: lines of one to three blocks in either direction, 1, 2 or 4 channels,
/// random value ranges, both variants.
#[test]
fn property_sat_matches_the_references_on_random_small_maps() {
    let g = common::gpu();
    let exec = RefCell::new(Executor::new());
    let mut runner = TestRunner::new(Config {
        cases: 24,
        max_shrink_iters: 16,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        1usize..=2600,
        1usize..=12,
        any::<bool>(),
        prop::sample::select(vec![1usize, 2, 4]),
        -4.0f32..4.0,
        0.01f32..8.0,
        any::<bool>(),
        any::<u64>(),
    );
    runner
        .run(
            &strategy,
            |(long, short, transpose, channels, lo, span, fixed, seed)| {
                let (w, h) = if transpose {
                    (short, long)
                } else {
                    (long, short)
                };
                let mut rng = common::rng(seed);
                let map = Map::random(&mut rng, w, h, channels, lo, lo + span);
                let what = format!("{w}x{h}x{channels} [{lo}, {}] fixed {fixed}", lo + span);
                let mut exec = exec.borrow_mut();
                if fixed {
                    let coding = SatCoding::fixed((w * h) as u64, [lo; 4], [lo + span; 4]).unwrap();
                    let table = build(&g, &mut exec, &map, &coding);
                    check_fixed(&what, &mut rng, &map, &coding, &table, None);
                } else {
                    let coding = SatCoding::float([lo; 4], [lo + span; 4]).unwrap();
                    let table = build(&g, &mut exec, &map, &coding);
                    check_float(&what, &mut rng, &map, &coding, &table);
                }
                Ok(())
            },
        )
        .unwrap();
}

/// The device's largest 2-D texture along each axis (16384 on lavapipe), as a strip of 16
/// lines (16 row blocks of 1024 texels a line; 16 column blocks a column): fixed tables bit
/// for bit, f32 tables within the scan bound. A full 16384² rgba32 table is 4 GiB, past what
/// a 24 GiB test machine holds with its intermediates and readback, so the strips stand in.
#[test]
fn largest_texture_dimension_each_way() {
    let g = common::gpu();
    let max = g.device.limits().max_texture_dimension_2d as usize;
    let mut exec = Executor::new();
    let mut rng = common::rng(76);
    for (w, h) in [(max, 16), (16, max)] {
        let map = Map::random(&mut rng, w, h, 2, 0.0, 1.0);
        let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_fixed(
            &format!("fixed {w}x{h}"),
            &mut rng,
            &map,
            &coding,
            &table,
            Some(17),
        );
        let coding = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_float(&format!("float {w}x{h}"), &mut rng, &map, &coding, &table);
    }
}

/// The structural cost of a table: three dispatches; over them the map is read twice and the
/// table written once, everything else (tile edges and carries, each written once and read
/// once) 8/SAT_TILE of a table texel per texel; the table and its intermediates have the map's
/// channels. Exact, from the plan's resources as the passes bind them.
#[test]
fn sat_reads_the_map_twice_and_writes_the_table_once() {
    for (format, table_bytes) in [
        (wgpu::TextureFormat::R32Float, 4u64),
        (wgpu::TextureFormat::Rg32Float, 8),
        (wgpu::TextureFormat::Rgba32Float, 16),
    ] {
        let n = 4096u32;
        let mut graph = Graph::default();
        graph.import("in", format, n, n, Some(0));
        let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
        let out = add_sat(&mut graph, 0, "in", &coding);
        let p = plan(&graph, &[&out]).unwrap();
        assert_eq!(p.steps.len(), 3, "{format:?}: dispatches");
        let bytes = |r: &str| p.resource(r).map_or(0, |r| r.bytes);
        let texels = u64::from(n) * u64::from(n);
        let (mut input, mut table, mut other) = (0, 0, 0);
        for step in &p.steps {
            for (_, r) in step.node.inputs.iter().chain(&step.node.outputs) {
                match r.as_str() {
                    "in" => input += bytes(r),
                    r if r == out => table += bytes(r),
                    r => other += bytes(r),
                }
            }
        }
        let input_texel = texel_bytes(format);
        assert_eq!(
            input,
            2 * input_texel * texels,
            "{format:?}: map read twice"
        );
        assert_eq!(
            table,
            table_bytes * texels,
            "{format:?}: table written once"
        );
        assert_eq!(
            other,
            8 * table_bytes * texels / u64::from(SAT_TILE),
            "{format:?}: edges and carries"
        );
        assert_eq!(
            p.resource(&out).unwrap().resource.format,
            SatVariant::Fixed.format(format_channels(format))
        );
    }
}

/// The five-pass baseline `shadowgraph bench` times against still builds the same table.
#[test]
fn five_pass_baseline_is_bit_identical_too() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(77);
    let map = Map::random(&mut rng, 1500, 70, 2, 0.05, 1.0);
    let coding = SatCoding::fixed(lookup_area(16.0, 16.0), [0.0; 4], [1.0; 4]).unwrap();
    let table = build_with(&g, &mut exec, &map, &coding, add_sat_five_pass);
    check_fixed(
        "five-pass 1500x70",
        &mut rng,
        &map,
        &coding,
        &table,
        Some(17),
    );
}
