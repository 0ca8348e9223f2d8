//! Kernel microbenchmarks: every graph kernel timed by GPU timestamps at a set of square sizes,
//! against a roofline per format: a texture copy kernel of each format a kernel reads or writes
//! (`kernels/copy_texture.wgsl`, the map kernels' 16×16 workgroups), beside the storage-buffer
//! copy (`kernels/copy.wgsl`, the device's practical bandwidth).
//!
//! Each kernel is one [`BenchCase`] in [`CASES`]: the graph that runs it. The bytes a case
//! moves are the cost model's ([`crate::graph::cost`]): every dispatch's reads and writes,
//! halos, second reads and mip levels included, not one read and one write per texel. Its
//! ratio is its GB/s over the texture copy of its output's format, at the same size. The
//! harness plans the graph, fills every imported texture with random values, records it with
//! [`Executor::record`] under a [`crate::exec::GpuTimer`], and keeps the median over the timed
//! runs (after [`WARMUP`] untimed ones) of the summed node times.

mod copy;
mod csm_chain;
mod harness;
mod lookup;
mod soft;

use std::collections::HashMap;
use std::fmt::Write;

use glam::Vec3;

pub use self::copy::{COPY, COPY_FORMATS, copy_texture_graph, format_name};
pub use self::harness::{Inputs, Timed, fill_imports, random_imports};
use self::harness::{gb_per_s, time_graph};
pub use self::lookup::{LOOKUP_WIDTHS, LookupRow, format_lookup_table, lookup_cost};
pub use self::soft::{
    SOFT_LIGHT_SIZES, SOFT_TECHNIQUES, SoftRow, check_soft_args, format_soft_table, soft_cost,
};
use crate::error::{Error, Result};
use crate::exec::{Executor, KernelLayout};
use crate::filter::{BlurMode, add_filter};
use crate::gpu::Gpu;
use crate::graph::{Graph, Plan, cost};
use crate::model::ParamValue;
use crate::sat::{self, SatCoding, SatVariant};
use crate::scene::{Light, LightKind, Shadow, Storage, Technique};
use crate::technique;
use crate::technique::params::storage_name;
pub use crate::timer::GPU_WARMUP_MS;

/// Untimed runs before the timed ones (pipeline warm-up, lazy clears, caches).
pub const WARMUP: u32 = 2;

/// One kernel measured at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// Kernel name ([`BenchCase::name`], `copy buffer` or `copy texture`).
    pub kernel: String,
    /// Format of the kernel's output (of a texture copy's source; `-` for the buffer copy).
    pub format: String,
    /// Side of the square map, texels.
    pub size: u32,
    /// Bytes read plus bytes written per run (the cost model's, all dispatches).
    pub bytes_moved: f64,
    /// Median GPU time per run over the timed runs, milliseconds (all nodes of the run).
    pub median_ms: f64,
    /// Median wall time per run, submission to completion, milliseconds: the cross-check of
    /// `median_ms` (on a CPU device the two agree within a fraction of a millisecond; on a GPU
    /// the submission's tens of microseconds can dominate a short run).
    pub wall_ms: f64,
    /// The shortest timed run's spans over the median wall time ([`Timed::least_share`]): the
    /// timer's check run by run.
    pub least_share: f64,
    /// Effective bandwidth: `bytes_moved / median time`, GB/s (10⁹ bytes per second).
    pub gbps: f64,
    /// `gbps` over the yardstick's GB/s at the same size.
    pub ratio: f64,
    /// Each dispatch's median time, ms, by node name in order ([`Timed::passes`]; empty for
    /// the buffer copy).
    pub passes: Vec<(String, f64)>,
    /// The yardstick: `copy texture <format>` for a kernel, `copy buffer` for a texture copy
    /// (empty for the buffer copy itself).
    pub yardstick: String,
}

/// The graph a case runs and the outputs that keep its nodes alive.
pub struct BenchGraph {
    /// The graph; its imports are R32Float textures the harness fills with random depths.
    pub graph: Graph,
    /// Resources requested from [`crate::graph::plan`].
    pub outputs: Vec<String>,
}

/// One kernel to benchmark: adding a kernel to the benchmark is one entry of [`CASES`].
pub struct BenchCase {
    /// Name in the report.
    pub name: &'static str,
    /// The graph at size `n`.
    pub build: fn(u32) -> BenchGraph,
}

/// Every benchmarked graph kernel.
pub const CASES: &[BenchCase] = &[
    BenchCase {
        name: "linearize",
        build: linearize_graph,
    },
    BenchCase {
        name: "vsm",
        build: |n| stage_graph(light_graph(n, vsm()), "light0.depth", "light0.vsm"),
    },
    BenchCase {
        name: "evsm4",
        build: |n| stage_graph(light_graph(n, evsm4()), "light0.depth", "light0.evsm"),
    },
    BenchCase {
        name: "esm",
        build: |n| stage_graph(light_graph(n, esm()), "light0.depth", "light0.esm"),
    },
    BenchCase {
        name: "blur rg32f r4",
        build: |n| {
            stage_graph(
                unfused(n, vsm(), "light0.vsm"),
                "light0.vsm",
                "light0.vsm.blur_v",
            )
        },
    },
    BenchCase {
        name: "blur rg32f r32",
        build: |n| {
            let graph = unfused(n, vsm_blur(32.0), "light0.vsm");
            stage_graph(graph, "light0.vsm", "light0.vsm.blur_v")
        },
    },
    BenchCase {
        name: "blur log r4",
        build: |n| stage_graph(light_graph(n, esm()), "light0.esm", "light0.esm.blur_v"),
    },
    // ESM past c = 80: `blur_log_wide`, with the per-output path for texels spread wider.
    BenchCase {
        name: "blur log r4 wide (c = 200)",
        build: |n| {
            stage_graph(
                light_graph(n, esm_wide()),
                "light0.esm",
                "light0.esm.blur_v",
            )
        },
    },
    // Depth → blurred moments: the encoding fused into the blur (76856d8), and the chain it
    // replaced (encode, blur_h, blur_v: the `(old)` rows) timed beside it.
    BenchCase {
        name: "vsm_blur r4",
        build: |n| chain_graph(n, vsm(), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm+blur r4 (old)",
        build: |n| old_chain(n, vsm(), "light0.vsm"),
    },
    // Two f16 moments packed in one r32uint word (4 B/texel): against the f32 rows above.
    BenchCase {
        name: "vsm_blur r4 f16 (packed)",
        build: |n| chain_graph(n, vsm_f16(), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm_blur r32 (2 passes)",
        build: |n| chain_graph(n, vsm_blur(32.0), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm+blur r32 (old)",
        build: |n| old_chain(n, vsm_blur(32.0), "light0.vsm"),
    },
    BenchCase {
        name: "evsm_blur 4 r4",
        build: |n| chain_graph(n, evsm4(), &["light0.evsm.blur"]),
    },
    BenchCase {
        name: "evsm4+blur r4 (old)",
        build: |n| old_chain(n, evsm4(), "light0.evsm"),
    },
    BenchCase {
        name: "msm_blur r4",
        build: |n| chain_graph(n, msm(Storage::F32), &["light0.msm.blur"]),
    },
    // Past the tile's radius: the row kernels (`msm_blur_row` from 512² on) and `blur` along y.
    BenchCase {
        name: "msm_blur r32 (2 passes)",
        build: |n| chain_graph(n, msm_blur(32.0), &["light0.msm.blur"]),
    },
    BenchCase {
        name: "msm+blur r4 (old)",
        build: |n| old_chain(n, msm(Storage::F32), "light0.msm"),
    },
    BenchCase {
        name: "msm",
        build: |n| {
            stage_graph(
                light_graph(n, msm(Storage::F32)),
                "light0.depth",
                "light0.msm",
            )
        },
    },
    BenchCase {
        name: "msm f16 quantized",
        build: |n| {
            stage_graph(
                light_graph(n, msm(Storage::F16)),
                "light0.depth",
                "light0.msm",
            )
        },
    },
    BenchCase {
        name: "csm (2 terms)",
        build: |n| stage_graph(light_graph(n, csm()), "light0.depth", "light0.csm0"),
    },
    // Depth → encoded maps, whatever the dispatches (linearize fused into the encodings, CSM
    // maps four a dispatch since 2026-11-23): timed against the chains of earlier builds.
    BenchCase {
        name: "chain vsm (depth → moments)",
        build: |n| chain_graph(n, vsm(), &["light0.vsm"]),
    },
    BenchCase {
        name: "chain msm f16 (depth → moments)",
        build: |n| chain_graph(n, msm(Storage::F16), &["light0.msm"]),
    },
    BenchCase {
        name: "chain csm 8 terms (depth → 4 maps)",
        build: |n| {
            let maps = ["light0.csm0", "light0.csm1", "light0.csm2", "light0.csm3"];
            chain_graph(n, csm_terms(8), &maps)
        },
    },
    // CSSM's prefilter: the layered tables (basis computed in their tile passes) against the
    // chain before them, until the comparison is recorded.
    // The soft techniques' whole prefilter at their defaults: the soft table build.
    BenchCase {
        name: "chain vssm (depth → table)",
        build: |n| chain_graph(n, named("vssm", &[]), &["light0.vsm.sat"]),
    },
    BenchCase {
        name: "chain msm_soft (depth → table)",
        build: |n| chain_graph(n, named("msm_soft", &[]), &["light0.msm.sat"]),
    },
    // The exponential encodings through a table at the scenes' exponents
    // (`scenes/techniques/evsm4_sat.toml`, `esm_sat.toml`): computed in the table's passes.
    BenchCase {
        name: "chain evsm4 sat (depth → table)",
        build: |n| chain_graph(n, exp_sat("evsm4"), &["light0.evsm.sat"]),
    },
    BenchCase {
        name: "chain esm sat (depth → table)",
        build: |n| chain_graph(n, exp_sat("esm"), &["light0.esm.sat"]),
    },
    BenchCase {
        name: "chain cssm 8 terms (depth → 5 tables)",
        build: csm_chain::layered,
    },
    BenchCase {
        name: "chain cssm 8 terms csm_z (depth → 9 tables)",
        build: csm_chain::layered_csm_z,
    },
    BenchCase {
        name: "chain cssm 8 terms (9 maps + 27 passes, old)",
        build: csm_chain::maps_then_tables,
    },
    BenchCase {
        name: "mips rgba32f",
        build: |n| stage_graph(light_graph(n, msm_mips()), "light0.msm", "light0.msm.mips"),
    },
    BenchCase {
        name: "sat fixed",
        build: |n| sat_graph(n, SatVariant::Fixed),
    },
    BenchCase {
        name: "sat float",
        build: |n| sat_graph(n, SatVariant::Float),
    },
    // The first design, timed beside the tiled passes until their comparison is recorded.
    BenchCase {
        name: "sat fixed (5-pass, old)",
        build: |n| sat_graph_with(n, SatVariant::Fixed, sat::five_pass::add_sat_five_pass),
    },
];

fn texels(n: u32) -> u64 {
    u64::from(n) * u64::from(n)
}

/// Technique `name` of the registry with `values` over its defaults (the scene file's).
fn named(name: &str, values: &[(&'static str, ParamValue)]) -> Technique {
    technique::named(name, values).expect("bench cases name registered techniques and keys")
}

/// The Gaussian blur of radius 4 (σ = 2) the chains are timed with.
const BLUR4: [(&str, ParamValue); 2] = [
    ("filter_radius", ParamValue::Float(4.0)),
    ("filter_sigma", ParamValue::Float(2.0)),
];

fn vsm() -> Technique {
    vsm_blur(4.0)
}

/// VSM with a Gaussian blur of `radius` taps each side (σ = radius / 2).
fn vsm_blur(radius: f32) -> Technique {
    named(
        "vsm",
        &[
            ("filter_radius", ParamValue::Float(radius)),
            ("filter_sigma", ParamValue::Float(radius / 2.0)),
        ],
    )
}

/// [`vsm`] with f16 moments (stored packed, two in a 32-bit word).
fn vsm_f16() -> Technique {
    named(
        "vsm",
        &[
            ("filter_radius", ParamValue::Float(4.0)),
            ("filter_sigma", ParamValue::Float(2.0)),
            ("format", ParamValue::Choice("f16")),
        ],
    )
}

fn evsm4() -> Technique {
    named("evsm4", &BLUR4)
}

/// `evsm4` (c⁺ = c⁻ = 6, what its table keeps accurate for a 4-texel box) or `esm` (c = 20)
/// through a fixed-point summed-area table, as the scenes `evsm4_sat` and `esm_sat`.
fn exp_sat(name: &str) -> Technique {
    let sat = [
        ("filter", ParamValue::Choice("sat")),
        ("filter_width", ParamValue::Float(4.0)),
    ];
    if name == "esm" {
        named(
            name,
            &[sat[0], sat[1], ("exponent", ParamValue::Float(20.0))],
        )
    } else {
        let c = ParamValue::Float(6.0);
        named(
            name,
            &[sat[0], sat[1], ("exponent_pos", c), ("exponent_neg", c)],
        )
    }
}

fn msm(storage: Storage) -> Technique {
    let format = ("format", ParamValue::Choice(storage_name(storage)));
    named("msm", &[format, BLUR4[0], BLUR4[1]])
}

/// MSM (f32) with a Gaussian blur of `radius` taps each side (σ = radius / 2).
fn msm_blur(radius: f32) -> Technique {
    named(
        "msm",
        &[
            ("filter_radius", ParamValue::Float(radius)),
            ("filter_sigma", ParamValue::Float(radius / 2.0)),
        ],
    )
}

fn msm_mips() -> Technique {
    named(
        "msm",
        &[
            ("filter", ParamValue::Choice("mips")),
            ("filter_width", ParamValue::Float(1.0)),
            ("moment_bias", ParamValue::Float(1e-5)),
        ],
    )
}

fn csm() -> Technique {
    csm_terms(2)
}

fn esm() -> Technique {
    named("esm", &BLUR4)
}

fn esm_wide() -> Technique {
    named(
        "esm",
        &[BLUR4[0], BLUR4[1], ("exponent", ParamValue::Float(200.0))],
    )
}

/// CSM with `terms` terms (offset 0.25 whatever M: the bench times the series, not its fit).
fn csm_terms(terms: u32) -> Technique {
    let values = [
        ("terms", ParamValue::Int(terms)),
        ("offset", ParamValue::Float(0.25)),
    ];
    named("csm", &[values[0], values[1], BLUR4[0], BLUR4[1]])
}

/// A light's shipped graph from its rasterized depth to `outputs` (the encoded maps). The
/// depth is imported as r32float (4 B a texel, as depth32float; the harness writes imports,
/// which a depth format forbids).
fn chain_graph(n: u32, technique: Technique, outputs: &[&str]) -> BenchGraph {
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
    }
}

/// [`chain_graph`] up to the textures the shading reads (every table of CSSM's layered
/// tables, however many a texture holds).
fn shading_chain(n: u32, technique: Technique) -> BenchGraph {
    let mut graph = Graph::default();
    let input = technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: input.maps,
    }
}

/// A light's shipped graph at size `n`.
fn light_graph(n: u32, technique: Technique) -> Graph {
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    graph
}

/// A light's graph with the unfused linear blur over its `encoded` map added
/// (`<encoded>.blur_h`, `<encoded>.blur_v`): the chain before the encoding was fused into the
/// blur, and the standalone blur passes other representations still use.
fn unfused(n: u32, technique: Technique, encoded: &str) -> Graph {
    let filter = technique.filter();
    let mut graph = light_graph(n, technique);
    // The fused blur's nodes go: the fallback's `.blur_h` would clash with the unfused pass's.
    let fused = format!("{encoded}.blur");
    graph.nodes.retain(|node| !node.name.starts_with(&fused));
    graph.resources.retain(|r| !r.name.starts_with(&fused));
    if let Some(f) = filter {
        add_filter(&mut graph, 0, encoded, &f, BlurMode::Linear);
    }
    graph
}

/// The unfused chain depth → `encoded` → `.blur_h` → `.blur_v` (see [`unfused`]), its depth
/// an r32float import as in [`chain_graph`].
fn old_chain(n: u32, technique: Technique, encoded: &str) -> BenchGraph {
    let mut graph = unfused(n, technique, encoded);
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: vec![format!("{encoded}.blur_v")],
    }
}

/// The stages of `graph` between `input` (made an import, its producers dropped by the
/// planner) and `output`: one kernel or a filter's passes, timed alone.
fn stage_graph(mut graph: Graph, input: &str, output: &str) -> BenchGraph {
    for r in graph.resources.iter_mut().filter(|r| r.name == input) {
        r.imported = true;
    }
    graph
        .nodes
        .retain(|node| node.outputs.iter().all(|(_, r)| r != input));
    BenchGraph {
        graph,
        outputs: vec![output.to_string()],
    }
}

/// The SAT passes of [`sat::add_sat`] over an imported `n`² VSM-shaped (Rg32Float) map; fixed
/// point for lookups of up to 64 × 64 texels of values in [0, 1].
fn sat_graph(n: u32, variant: SatVariant) -> BenchGraph {
    sat_graph_with(n, variant, sat::add_sat)
}

/// [`sat_graph`] with another builder of the table's passes (the five-pass baseline).
fn sat_graph_with(
    n: u32,
    variant: SatVariant,
    add: fn(&mut Graph, usize, &str, &SatCoding) -> String,
) -> BenchGraph {
    let mut graph = Graph::default();
    let input = graph.import("light0.vsm", wgpu::TextureFormat::Rg32Float, n, n, Some(0));
    let (lo, hi) = ([0.0; 4], [1.0; 4]);
    let coding = match variant {
        SatVariant::Fixed => SatCoding::fixed(sat::lookup_area(64.0, 64.0), lo, hi),
        SatVariant::Float => SatCoding::float(lo, hi),
    };
    // The arguments are valid constants; a unit scale would only change the values summed,
    // not the work timed.
    let coding = coding.unwrap_or(SatCoding {
        variant,
        offset: [0.5; 4],
        scale: [1.0; 4],
        limit: [1.0; 4],
    });
    let output = add(&mut graph, 0, &input, &coding);
    BenchGraph {
        graph,
        outputs: vec![output],
    }
}

/// The shipped node of [`technique::add_light_nodes`] for a spot light (the perspective path,
/// the more expensive one), reading a Depth32Float import as the renderer's does.
fn linearize_graph(n: u32) -> BenchGraph {
    let light = bench_light(n, named("hard", &[]));
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &light);
    BenchGraph {
        graph,
        outputs: vec![technique::linear_name(0)],
    }
}

/// A spot light with an `n`² map and `technique`.
fn bench_light(n: u32, technique: Technique) -> Light {
    Light {
        kind: LightKind::Spot { fov_degrees: 60.0 },
        position: Vec3::new(0.0, 10.0, 0.0),
        target: Vec3::ZERO,
        near: 0.1,
        far: 100.0,
        size: 0.0,
        radiance: Vec3::ONE,
        shadow_map: n,
        shadow: Shadow {
            technique,
            bias: 0.0,
            slope_bias: 0.0,
            normal_bias: 0.0,
            receiver_plane: 0.0,
            cascades: crate::model::Cascades::SINGLE,
        },
    }
}

/// Bytes `plan` moves per run: the cost model's reads and writes of every node.
pub fn plan_bytes(plan: &Plan) -> Result<f64> {
    plan.steps
        .iter()
        .map(|s| Ok(cost::node_traffic(plan, &s.node)?.bytes()))
        .sum()
}

/// A kernel or texture-copy row from a timed plan.
fn row(name: &str, format: String, n: u32, plan: &Plan, t: Timed) -> Result<BenchRow> {
    let bytes = plan_bytes(plan)?;
    Ok(BenchRow {
        kernel: name.to_string(),
        format,
        size: n,
        bytes_moved: bytes,
        median_ms: t.ms,
        wall_ms: t.wall_ms,
        least_share: t.least_share,
        gbps: gb_per_s(bytes, t.ms),
        ratio: f64::NAN,
        yardstick: String::new(),
        passes: t.passes,
    })
}

/// Texture memory case `case` holds at side `n`: its plan's slots and its imported textures
/// (the map the host would have rasterized).
pub fn case_bytes(case: &BenchCase, n: u32) -> Result<u64> {
    let built = (case.build)(n);
    let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
    let plan = crate::graph::plan(&built.graph, &outputs)?;
    let imports: u64 = plan
        .resources
        .iter()
        .filter(|r| r.slot.is_none())
        .map(|r| r.bytes)
        .sum();
    Ok(plan.slot_bytes() + imports)
}

/// Refuses, before any GPU work, a case whose textures at one of `sizes` would pass the memory
/// `budget` ([`crate::limits::memory_budget`], as a scene's frame is checked): at 16384² CSSM's
/// nine tables alone are 36 GiB, which a CPU driver would try to take from system memory.
pub fn check_memory(cases: &[&BenchCase], sizes: &[u32], budget: u64) -> Result<()> {
    for &n in sizes {
        for case in cases {
            let need = case_bytes(case, n)?;
            if need > budget {
                let fix = "leave it out with --only, lower --sizes or raise the budget";
                return Err(past_budget(
                    &format!("`{}` at {n}²", case.name),
                    need,
                    budget,
                    fix,
                ));
            }
        }
    }
    Ok(())
}

/// [`check_memory`] for the yardstick [`measure_variants`] times at every size: a buffer copy
/// of two rgba32-sized buffers (8 GiB at 16384²).
fn check_yardstick_memory(sizes: &[u32], budget: u64) -> Result<()> {
    for &n in sizes {
        let copies = 2 * texels(n) * 16;
        if copies > budget {
            let what = format!("the buffer copy at {n}² (every run's yardstick)");
            return Err(past_budget(
                &what,
                copies,
                budget,
                "lower --sizes or raise the budget",
            ));
        }
    }
    Ok(())
}

/// The error of [`check_memory`]: `what` needs `need` bytes, past `budget`; `fix` says what to do.
fn past_budget(what: &str, need: u64, budget: u64, fix: &str) -> Error {
    Error::Invalid(format!(
        "bench: {what} needs an estimated {}, more than the memory budget of {} ({}): {fix}",
        crate::graph::print::human_bytes(need),
        crate::graph::print::human_bytes(budget),
        crate::limits::MEMORY_BUDGET_ENV
    ))
}

/// Refuses an empty entry of an `--only` list (`--only sat,` or `--only ,`): every name
/// contains the empty string, so it would keep everything while the user meant a filter.
pub(crate) fn check_only(flag: &str, only: &[String]) -> Result<()> {
    match only.iter().position(|o| o.trim().is_empty()) {
        Some(i) => Err(Error::Invalid(format!(
            "{flag} {}: entry {} is empty (every name contains it); name part of a kernel or \
             configuration",
            only.join(","),
            i + 1
        ))),
        None => Ok(()),
    }
}

/// The cases of [`CASES`] whose name contains one of `only` (all of them when `only` is
/// empty); a filter that names no case is an error listing the names.
pub fn select_cases(only: &[String]) -> Result<Vec<&'static BenchCase>> {
    check_only("bench --only", only)?;
    let picked: Vec<&BenchCase> = CASES
        .iter()
        .filter(|c| only.is_empty() || only.iter().any(|o| c.name.contains(o.as_str())))
        .collect();
    if picked.is_empty() {
        let names: Vec<&str> = CASES.iter().map(|c| c.name).collect();
        return Err(Error::Invalid(format!(
            "bench --only {}: matches no kernel; the kernels are: {}",
            only.join(","),
            names.join("; ")
        )));
    }
    Ok(picked)
}

/// Times, at every size in `sizes` (`repeat` timed runs each), the buffer copy of an
/// rgba32-sized map, the texture copy of every format of [`COPY_FORMATS`] (ratio to the
/// buffer copy), then every case of [`CASES`] whose name contains one of `only` (every case
/// when `only` is empty; ratio to the texture copy of its output's format).
///
/// The copies are timed twice, before and after the cases, and each keeps the faster of its
/// two medians: the yardstick is what the device's copy reaches, and a GPU's clock or a
/// shared machine's load can slow either run (on an H100 one format's copy read 0.14 ms in one
/// run and 0.27 ms in the next).
pub fn measure(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    sizes: &[u32],
    repeat: u32,
    only: &[String],
    inputs: Inputs,
) -> Result<Vec<BenchRow>> {
    measure_layouts(device, queue, sizes, repeat, only, inputs, &[])
}

/// [`measure`], each case timed in each of `layouts` in turn, adjacent in time, its rows named
/// `<case> [gpu]`, `<case> [cpu]` (the kernels' two variants, `exec::KernelLayout`,
/// compared within one process: one warm-up, one clock, one set of copies); no layouts: the
/// device's, rows named by their case alone.
pub fn measure_layouts(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    sizes: &[u32],
    repeat: u32,
    only: &[String],
    inputs: Inputs,
    layouts: &[KernelLayout],
) -> Result<Vec<BenchRow>> {
    let variants: Vec<KernelVariant> = layouts.iter().map(|&l| KernelVariant::layout(l)).collect();
    measure_variants(device, queue, sizes, repeat, only, inputs, &variants)
}

/// One way to compile the kernels that [`measure_variants`] times beside others: a layout
/// (`--layouts`) or a folder of replacement kernels (`--kernel-dirs`), named in its rows.
pub struct KernelVariant {
    /// The rows' suffix, `<case> [name]`: `gpu`, `cpu`, `shipped` or the folder's name.
    pub name: String,
    layout: Option<KernelLayout>,
    replaced: Option<std::sync::Arc<crate::kernels::Replacements>>,
    /// Workgroup memory zeroed first ([`ZEROED`]).
    zeroed: bool,
}

/// The `--kernel-dirs` entry that stands for the embedded kernels.
pub const SHIPPED: &str = "shipped";

/// The `--kernel-dirs` entry that stands for the embedded kernels with their workgroup memory
/// zeroed first, as wgpu does by default (`exec::WorkgroupInit`): what opting out saves.
pub const ZEROED: &str = "zeroed";

impl KernelVariant {
    /// The kernels in `layout` (`exec::KernelLayout`).
    pub fn layout(layout: KernelLayout) -> Self {
        Self {
            name: layout.name().to_string(),
            layout: Some(layout),
            replaced: None,
            zeroed: false,
        }
    }

    /// The embedded kernels, named [`SHIPPED`].
    pub fn shipped() -> Self {
        Self {
            name: SHIPPED.to_string(),
            layout: None,
            replaced: None,
            zeroed: false,
        }
    }

    /// The embedded kernels with their workgroup memory zeroed first, named [`ZEROED`].
    pub fn zeroed() -> Self {
        Self {
            name: ZEROED.to_string(),
            zeroed: true,
            ..Self::shipped()
        }
    }

    /// The kernels with the `.wgsl` files of `dir` in place of those they name (as
    /// [`crate::kernels::KERNEL_DIR_ENV`] reads a folder), named by the folder's last
    /// component; [`SHIPPED`] is [`KernelVariant::shipped`], [`ZEROED`]
    /// [`KernelVariant::zeroed`]. A folder that cannot be read or
    /// replaces nothing, a file naming no kernel, or a replaced kernel that does not validate
    /// is an error naming it. The plan (its dispatches' geometry, the bytes of the rows) is the shipped kernels':
    /// a variant may change a kernel's workgroup size only where its node's dispatch does not
    /// follow it (the tables' tile passes: one workgroup a tile), as a variant's bit-for-bit
    /// test shows; one dispatched a line an invocation is refused by the executor.
    pub fn folder(dir: &std::path::Path) -> Result<Self> {
        if dir.as_os_str() == SHIPPED {
            return Ok(Self::shipped());
        }
        if dir.as_os_str() == ZEROED {
            return Ok(Self::zeroed());
        }
        // Its messages name the environment variable that usually gives the folder.
        let env = format!("{}: ", crate::kernels::KERNEL_DIR_ENV);
        let replaced = crate::kernels::read_replacements(dir)
            .map_err(|e| Error::Invalid(e.replacen(&env, "--kernel-dirs: ", 1)))?;
        if replaced.is_empty() {
            return Err(Error::Invalid(format!(
                "--kernel-dirs {}: replaces no kernel (no `.wgsl` file naming one; `{SHIPPED}` \
                 stands for the embedded kernels)",
                dir.display()
            )));
        }
        // Each replaced kernel validated here, so that an error is one line naming the folder.
        let origin = format!("--kernel-dirs {}", dir.display());
        for name in crate::kernels::KernelId::ALL.iter().map(|k| k.name()) {
            let Ok(variant) = crate::kernels::resolve_in(name, None, Some(&replaced)) else {
                continue; // a kernel with a `// #generated` block (the shading pass)
            };
            if crate::kernels::resolve(name, None).is_ok_and(|shipped| shipped == variant) {
                continue;
            }
            crate::kernels::reflect_replaced(name, &variant, &origin)?;
        }
        let name = dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| dir.display().to_string());
        Ok(Self {
            name,
            layout: None,
            replaced: Some(std::sync::Arc::new(replaced)),
            zeroed: false,
        })
    }

    /// An executor compiling its kernels this way.
    fn executor(&self) -> Executor {
        let mut e = Executor::new();
        if let Some(layout) = self.layout {
            e.kernels.set_layout(layout);
        }
        if let Some(replaced) = &self.replaced {
            e.kernels.set_replacements(replaced.clone());
        }
        if self.zeroed {
            e.kernels.set_zeroed_workgroup_memory();
        }
        e
    }
}

/// [`measure`], each case timed in each of `variants` in turn, adjacent in time (one warm-up,
/// one clock, one set of copies), its rows named `<case> [<variant>]`; no variants: the
/// device's kernels, rows named by their case alone. Two variants of one name are refused.
pub fn measure_variants(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    sizes: &[u32],
    repeat: u32,
    only: &[String],
    inputs: Inputs,
    variants: &[KernelVariant],
) -> Result<Vec<BenchRow>> {
    check_args(device, sizes, repeat)?;
    if let Some((k, v)) = variants
        .iter()
        .enumerate()
        .find(|(k, v)| variants[..*k].iter().any(|u| u.name == v.name))
    {
        let flag = if v.layout.is_some() {
            "--layouts"
        } else {
            "--kernel-dirs"
        };
        return Err(Error::Invalid(format!(
            "{flag} names `{}` twice (entry {})",
            v.name,
            k + 1
        )));
    }
    let cases = select_cases(only)?;
    let budget = crate::limits::memory_budget()?;
    check_yardstick_memory(sizes, budget)?;
    check_memory(&cases, sizes, budget)?;
    harness::timer(device, queue, 1)?;
    let mut executor = Executor::new();
    // One executor a variant (its own pipelines), or the device's kernels unnamed.
    let mut variants: Vec<(String, Executor)> = variants
        .iter()
        .map(|v| (format!(" [{}]", v.name), v.executor()))
        .collect();
    let mut rows = Vec::new();
    for &n in sizes {
        let buffer = texels(n) * 16;
        let t = copy::time_buffer_copy(device, queue, &mut executor.kernels, buffer, repeat)?;
        let buffer_gbps = gb_per_s(2.0 * buffer as f64, t.ms);
        rows.push(BenchRow {
            kernel: "copy buffer".into(),
            format: "-".into(),
            size: n,
            bytes_moved: 2.0 * buffer as f64,
            median_ms: t.ms,
            wall_ms: t.wall_ms,
            least_share: t.least_share,
            gbps: buffer_gbps,
            ratio: 1.0,
            yardstick: String::new(),
            passes: Vec::new(),
        });
        let time = |executor: &mut Executor, built: &BenchGraph| {
            time_graph(
                device,
                queue,
                executor,
                &built.graph,
                &built.outputs,
                repeat,
                inputs,
            )
        };
        let time_copies = |executor: &mut Executor| -> Result<Vec<BenchRow>> {
            let mut copies = Vec::new();
            for &format in COPY_FORMATS {
                let (plan, t) = time(executor, &copy::copy_texture_graph(n, format))?;
                let mut r = row("copy texture", format_name(format), n, &plan, t)?;
                r.ratio = r.gbps / buffer_gbps;
                r.yardstick = "copy buffer".into();
                copies.push(r);
                executor.release_textures();
            }
            Ok(copies)
        };
        let before = time_copies(&mut executor)?;
        let copies_at = rows.len();
        rows.extend(before);
        let mut copies: HashMap<wgpu::TextureFormat, f64> = HashMap::new();
        let mut cases_rows = Vec::new();
        for case in &cases {
            let built = (case.build)(n);
            let mut time_in = |suffix: &str, executor: &mut Executor| -> Result<()> {
                let (plan, t) = time(executor, &built)?;
                let output = built.outputs.first().and_then(|o| plan.resource(o));
                // The texture's own format (a packed f16 pair is an r32uint texture).
                let format = output
                    .map(|r| crate::graph::texture_format(r.resource.format))
                    .ok_or_else(|| {
                        Error::Invalid(format!("benchmark `{}` plans no output", case.name))
                    })?;
                let name = format!("{}{suffix}", case.name);
                cases_rows.push((format, row(&name, format_name(format), n, &plan, t)?));
                executor.release_textures();
                Ok(())
            };
            if variants.is_empty() {
                time_in("", &mut executor)?;
            }
            for (suffix, executor) in &mut variants {
                time_in(suffix, executor)?;
            }
        }
        // The copies again: each format's row keeps the faster of its two runs.
        for (k, again) in time_copies(&mut executor)?.into_iter().enumerate() {
            let first = &mut rows[copies_at + k];
            if again.median_ms < first.median_ms {
                *first = again;
            }
        }
        for (&format, r) in COPY_FORMATS.iter().zip(&rows[copies_at..]) {
            copies.insert(format, r.gbps);
        }
        for (format, mut r) in cases_rows {
            let copy_gbps = copies.get(&format).copied().ok_or_else(|| {
                Error::Invalid(format!(
                    "benchmark `{}` writes {}, which has no texture copy row (COPY_FORMATS)",
                    r.kernel,
                    format_name(format)
                ))
            })?;
            r.ratio = r.gbps / copy_gbps;
            r.yardstick = format!("copy texture {}", r.format);
            rows.push(r);
        }
    }
    Ok(rows)
}

/// Runs [`measure`] on `gpu` and formats the report: each kernel in each of `layouts` in turn
/// (`--layouts`), or in each folder of `kernel_dirs` (`--kernel-dirs`, [`KernelVariant::folder`];
/// [`SHIPPED`] the embedded kernels), or the device's kernels alone. Layouts and folders are
/// not combined.
#[allow(clippy::too_many_arguments)]
pub fn run(
    gpu: &Gpu,
    sizes: &[u32],
    repeat: u32,
    only: &[String],
    inputs: Inputs,
    passes: bool,
    layouts: &[KernelLayout],
    kernel_dirs: &[std::path::PathBuf],
) -> Result<String> {
    if !layouts.is_empty() && !kernel_dirs.is_empty() {
        return Err(Error::Invalid(
            "--layouts and --kernel-dirs: give one of them".into(),
        ));
    }
    if !kernel_dirs.is_empty() && std::env::var_os(crate::kernels::KERNEL_DIR_ENV).is_some() {
        return Err(Error::Invalid(format!(
            "--kernel-dirs with {} set: its replacements would lie under every folder, \
             `{SHIPPED}` included; unset it",
            crate::kernels::KERNEL_DIR_ENV
        )));
    }
    let variants: Vec<KernelVariant> = if kernel_dirs.is_empty() {
        layouts.iter().map(|&l| KernelVariant::layout(l)).collect()
    } else {
        kernel_dirs
            .iter()
            .map(|d| KernelVariant::folder(d))
            .collect::<Result<_>>()?
    };
    let rows = measure_variants(
        &gpu.device,
        &gpu.queue,
        sizes,
        repeat,
        only,
        inputs,
        &variants,
    )?;
    let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    // Which layout the kernels ran in: the rows say it under `--layouts`.
    let device_layout = KernelLayout::for_device(&gpu.device)?.name();
    let names: Vec<&str> = variants.iter().map(|v| v.name.as_str()).collect();
    let layout = if variants.is_empty() {
        format!("kernel layout {device_layout}")
    } else if kernel_dirs.is_empty() {
        format!("kernel layouts {}, each kernel in each", names.join(", "))
    } else {
        format!(
            "kernel layout {device_layout}; kernel folders {}, each kernel in each",
            names.join(", ")
        )
    };
    Ok(format_table(
        &format!("{} ({layout})", gpu.describe()),
        cpu,
        repeat,
        inputs,
        passes,
        &rows,
    ))
}

/// The report: a header naming the device and the method, then one line per row (with
/// `passes`, a kernel of several dispatches followed by one line for each).
pub fn format_table(
    device: &str,
    cpu: bool,
    repeat: u32,
    inputs: Inputs,
    passes: bool,
    rows: &[BenchRow],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "kernel benchmark on {device}");
    let _ = writeln!(
        s,
        "GPU timestamps between passes, median of {repeat} run(s) after {WARMUP} warm-up run(s)\n\
         (on a GPU, at least {GPU_WARMUP_MS} ms of them: its clocks rise). Imported textures:\n\
         {} values. MiB moved: the cost model's bytes (every dispatch's reads and writes,\n\
         halos and second reads included, as `shadowgraph plan` prints them); GB/s = bytes /\n\
         time; x = GB/s over the yardstick's: for a kernel the texture copy of its output's\n\
         format (16x16 workgroups, one load and one store per texel; timed before and after\n\
         the kernels, the faster run kept), for a texture copy the buffer copy. wall ms: the\n\
         median run's submission to completion, the timestamps' cross-check.",
        inputs.name()
    );
    if cpu {
        let _ = writeln!(
            s,
            "NOTE: this adapter is a CPU device (software Vulkan): times and GB/s are CPU \
             numbers,\nonly the ratios are meaningful."
        );
    }
    let _ = writeln!(
        s,
        "{:>6}  {:<18} {:<12} {:>10} {:>10} {:>10} {:>9} {:>7}  yardstick",
        "size", "kernel", "format", "MiB moved", "median ms", "wall ms", "GB/s", "x"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:>6}  {:<18} {:<12} {:>10.2} {:>10.3} {:>10.3} {:>9.2} {:>7.2}  {}",
            r.size,
            r.kernel,
            r.format,
            r.bytes_moved / (1024.0 * 1024.0),
            r.median_ms,
            r.wall_ms,
            r.gbps,
            r.ratio,
            r.yardstick
        );
        if passes && r.passes.len() > 1 {
            for (label, ms) in &r.passes {
                let _ = writeln!(s, "{:>6}    - {:<40} {:>10.3}", "", label, ms);
            }
        }
    }
    if cpu {
        let suspect: Vec<String> = rows
            .iter()
            .filter(|r| r.least_share < CPU_LEAST_SHARE && r.wall_ms >= CPU_CHECKED_MS)
            .map(|r| {
                format!(
                    "{} {} at {}² ({:.2})",
                    r.kernel, r.format, r.size, r.least_share
                )
            })
            .collect();
        if !suspect.is_empty() {
            let _ = writeln!(
                s,
                "WARNING: measure again, a run read under {CPU_LEAST_SHARE} of the median wall time (a \
                 CPU device's true timer never does: another load on the cores, or a timer \
                 fault): {}",
                suspect.join("; ")
            );
        }
    }
    s
}

/// On a CPU device a run's spans read at least this share of the median wall time (the
/// submission adds 0.1–0.5 ms; runs of 3–15 ms read 0.85 and more on idle cores): a row with a
/// run below it is flagged by [`format_table`] if its runs take [`CPU_CHECKED_MS`] or more.
pub const CPU_LEAST_SHARE: f64 = 0.5;

/// Runs shorter than this by the wall clock are mostly submission on a CPU device (a 256² copy:
/// 0.3 ms of 0.43), so the wall clock cannot check them.
pub const CPU_CHECKED_MS: f64 = 2.0;

/// `bench --lookup`'s `--map` and `--image` against the device's largest texture side: past
/// it an error naming the flag (the bench's own scene file would name a key and a line the
/// user did not write).
fn check_map(device: &wgpu::Device, map: Option<u32>, image: Option<(u32, u32)>) -> Result<()> {
    crate::limits::flag_sides(
        device.limits().max_texture_dimension_2d,
        [
            ("bench --map (shadow-map side)", map),
            ("bench --image (width)", image.map(|(w, _)| w)),
            ("bench --image (height)", image.map(|(_, h)| h)),
        ],
    )
}

/// `bench --lookup`'s scene with `--image` and `--map` applied, each recorded as set by its flag
/// (`Locations::set_by`), so that a limit or memory error names the flag rather than a line of
/// the bundled scene, which the user did not write.
fn with_flags(
    mut scene: crate::scene::Scene,
    map: Option<u32>,
    image: Option<(u32, u32)>,
) -> crate::scene::Scene {
    if let Some((w, h)) = image {
        (scene.width, scene.height) = (w, h);
        let by = format!("bench --lookup --image {w}x{h}");
        scene.locations.set_by("output.width", by.clone());
        scene.locations.set_by("output.height", by);
    }
    if let Some(n) = map {
        for (i, l) in scene.lights.iter_mut().enumerate() {
            l.shadow_map = n;
            let by = format!("bench --lookup --map {n}");
            scene.locations.set_by(format!("light[{i}].shadow_map"), by);
        }
    }
    scene
}

/// The kernel benchmark's sizes (at least one, each 1 to the device's largest texture side) and
/// `repeat` (at least 1), checked before any work; [`run`] and the `kernel_wall` example share
/// it.
pub fn check_args(device: &wgpu::Device, sizes: &[u32], repeat: u32) -> Result<()> {
    if sizes.is_empty() {
        return Err(Error::Invalid("no benchmark sizes given".into()));
    }
    if repeat == 0 {
        return Err(Error::Invalid("repeat must be at least 1".into()));
    }
    let max = device.limits().max_texture_dimension_2d;
    for &n in sizes {
        if n == 0 {
            return Err(Error::Invalid("benchmark size 0".into()));
        }
        if n > max {
            return Err(Error::Limit {
                what: "benchmark size".into(),
                requested: u64::from(n),
                limit: u64::from(max),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `shadowgraph bench` at its default sizes (up to 4096²) fits the default memory budget
    /// with every case and its yardstick, so its default run is never refused; at 16384² the
    /// buffer copy every run times (8 GiB) is refused under it, and so is CSSM with the CSM-Z
    /// search (nine tables, 36 GiB), naming the case, its estimate and the variable; a budget
    /// at the case's own estimate takes it. (Plans only, no GPU.)
    #[test]
    fn the_bench_checks_its_memory_against_the_budget() {
        let all = select_cases(&[]).expect("cases");
        let budget = crate::limits::DEFAULT_MEMORY_BUDGET;
        check_memory(&all, &[512, 1024, 2048, 4096], budget).expect("defaults fit");
        let csm_z = select_cases(&["csm_z".into()]).expect("csm_z");
        check_yardstick_memory(&[4096], budget).expect("the default sizes' copies fit");
        let e = check_yardstick_memory(&[16384], budget)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("buffer copy at 16384²") && e.contains("8.0 GiB"),
            "{e}"
        );
        let e = check_memory(&csm_z, &[16384], budget)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("csm_z") && e.contains("16384²") && e.contains("SHADOWGRAPH_MEMORY_BUDGET"),
            "{e}"
        );
        let need = case_bytes(csm_z[0], 16384).expect("estimate");
        // Nine rgba32uint tables of 16384² (the tile edges and carries on top).
        assert!(need >= 9 * 16384 * 16384 * 16, "{need}");
        check_memory(&csm_z, &[16384], need).expect("a budget at the estimate");
        assert!(check_memory(&csm_z, &[16384], need - 1).is_err());
    }

    fn gpu() -> Gpu {
        match Gpu::new() {
            Ok(g) => g,
            Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
        }
    }

    /// `Executor::release_textures` (called after each case) drops every pooled texture and
    /// keeps the compiled kernels: the case runs again making its textures anew and no pipeline.
    #[test]
    fn a_released_executor_makes_textures_again_and_keeps_kernels() {
        let gpu = gpu();
        let built = |name: &str| (CASES.iter().find(|c| c.name == name).unwrap().build)(64);
        let (sat, msm) = (built("sat fixed"), built("msm"));
        let mut executor = Executor::new();
        let time = |executor: &mut Executor, b: &BenchGraph| {
            time_graph(
                &gpu.device,
                &gpu.queue,
                executor,
                &b.graph,
                &b.outputs,
                1,
                Inputs::Random,
            )
            .unwrap();
            executor.texture_count()
        };
        let own = time(&mut executor, &msm);
        time(&mut executor, &sat);
        // The pool keeps msm's textures beside sat's.
        let held = time(&mut executor, &msm);
        assert!(held > own, "{held} {own}");
        executor.release_textures();
        assert_eq!(executor.texture_count(), 0);
        let before = crate::created::created();
        let again = time(&mut executor, &msm);
        let after = crate::created::created();
        assert_eq!(after.pipelines, before.pipelines, "kernels kept");
        assert_eq!(
            after.textures - before.textures,
            own as u64,
            "textures made again"
        );
        assert_eq!(again, own);
    }

    /// `timer::warm_up` runs `least` times on a CPU device (lavapipe: no clock to raise), at
    /// least that on a GPU, and stops at the first error.
    #[test]
    fn warm_up_runs_least_times_on_a_cpu_device_and_stops_at_an_error() {
        let gpu = gpu();
        let mut calls = 0;
        let runs = crate::timer::warm_up(&gpu.device, 3, || {
            calls += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(runs, calls);
        if crate::timer::is_gpu(&gpu.device) {
            assert!(runs >= 3, "{runs}");
        } else {
            assert_eq!(runs, 3);
        }
        let mut calls = 0;
        let e = crate::timer::warm_up(&gpu.device, 5, || {
            calls += 1;
            match calls {
                2 => Err(Error::Invalid("second run".into())),
                _ => Ok(()),
            }
        });
        assert!(e.is_err() && calls == 2, "{calls}");
    }

    /// Each row carries its dispatches' medians by node name, in the plan's order (the SAT's
    /// three), each within the run's total; `--passes` prints them under the row, and only
    /// then.
    #[test]
    fn rows_carry_their_passes_and_print_them_on_request() {
        let gpu = gpu();
        let only = vec!["sat fixed".to_string()];
        let rows = measure(&gpu.device, &gpu.queue, &[64], 2, &only, Inputs::Random).unwrap();
        let sat = rows.iter().find(|r| r.kernel == "sat fixed").unwrap();
        let built = (CASES.iter().find(|c| c.name == "sat fixed").unwrap().build)(64);
        let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
        let plan = crate::graph::plan(&built.graph, &outputs).unwrap();
        let names: Vec<&str> = sat.passes.iter().map(|(l, _)| l.as_str()).collect();
        let want: Vec<&str> = plan.steps.iter().map(|s| s.node.name.as_str()).collect();
        assert_eq!(names, want);
        assert_eq!(names.len(), 3, "{names:?}");
        let total: f64 = sat.passes.iter().map(|p| p.1).sum();
        assert!(
            sat.passes.iter().all(|p| p.1 >= 0.0 && p.1 <= total),
            "{:?}",
            sat.passes
        );
        let device = "test device";
        let with = format_table(device, true, 2, Inputs::Random, true, &rows);
        let without = format_table(device, true, 2, Inputs::Random, false, &rows);
        for name in &names {
            assert!(
                with.lines()
                    .any(|l| l.trim_start().starts_with(&format!("- {name} ")))
            );
            assert!(!without.contains(&format!("- {name}")), "{without}");
        }
    }

    /// `only` keeps the cases whose name contains one of its strings (the copies stay: they
    /// are the yardsticks); a filter that keeps none is an error naming the kernels.
    #[test]
    fn only_keeps_the_named_cases() {
        let gpu = gpu();
        let only = vec!["sat fixed".to_string(), "linearize".to_string()];
        let rows = measure(&gpu.device, &gpu.queue, &[32], 1, &only, Inputs::Random).unwrap();
        let kernels: Vec<&str> = rows
            .iter()
            .filter(|r| !r.kernel.starts_with("copy"))
            .map(|r| r.kernel.as_str())
            .collect();
        let want: Vec<&str> = CASES
            .iter()
            .map(|c| c.name)
            .filter(|n| n.contains("sat fixed") || n.contains("linearize"))
            .collect();
        assert_eq!(kernels, want);
        assert!(want.len() >= 2, "{want:?}");
        let copies = rows.iter().filter(|r| r.kernel == "copy texture").count();
        assert_eq!(copies, COPY_FORMATS.len());
        let e = measure(
            &gpu.device,
            &gpu.queue,
            &[32],
            1,
            &["no such".to_string()],
            Inputs::Random,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("--only no such: matches no kernel"),
            "{e}"
        );
    }

    /// `--layouts gpu,cpu`: each case once per layout, in that order, side by side, named by
    /// its layout, with the same bytes (one plan); the copies once; the report's header names
    /// the layouts, or the device's one without them.
    #[test]
    fn each_case_runs_in_each_layout_side_by_side() {
        let gpu = gpu();
        let only = vec!["sat fixed".to_string(), "blur rg32f r4".to_string()];
        let layouts = [KernelLayout::Gpu, KernelLayout::Cpu];
        let rows = measure_layouts(
            &gpu.device,
            &gpu.queue,
            &[32],
            1,
            &only,
            Inputs::Random,
            &layouts,
        )
        .unwrap();
        let cases: Vec<&BenchRow> = rows
            .iter()
            .filter(|r| !r.kernel.starts_with("copy"))
            .collect();
        let want: Vec<String> = CASES
            .iter()
            .map(|c| c.name)
            .filter(|n| n.contains("sat fixed") || n.contains("blur rg32f r4"))
            .flat_map(|n| [format!("{n} [gpu]"), format!("{n} [cpu]")])
            .collect();
        let names: Vec<&str> = cases.iter().map(|r| r.kernel.as_str()).collect();
        assert_eq!(names, want);
        for pair in cases.chunks(2) {
            assert_eq!(
                pair[0].bytes_moved, pair[1].bytes_moved,
                "{}",
                pair[0].kernel
            );
        }
        let copies = rows.iter().filter(|r| r.kernel == "copy texture").count();
        assert_eq!(copies, COPY_FORMATS.len());
        // The report's first line says which layout the kernels ran in.
        let only = ["linearize".to_string()];
        let both = run(&gpu, &[32], 1, &only, Inputs::Random, false, &layouts, &[]).unwrap();
        let first = both.lines().next().unwrap_or_default();
        assert!(
            first.ends_with("(kernel layouts gpu, cpu, each kernel in each)"),
            "{first}"
        );
        let device = KernelLayout::for_device(&gpu.device).unwrap().name();
        let one = run(&gpu, &[32], 1, &only, Inputs::Random, false, &[], &[]).unwrap();
        let first = one.lines().next().unwrap_or_default();
        assert!(
            first.ends_with(&format!("(kernel layout {device})")),
            "{first}"
        );
    }

    /// Per size: the buffer copy, a texture copy per format, then every case, each case's
    /// ratio taken to the copy of its output's format and its bytes the cost model's.
    #[test]
    fn measure_reports_copies_then_each_case_per_size() {
        let gpu = gpu();
        let rows = measure(&gpu.device, &gpu.queue, &[32, 48], 2, &[], Inputs::Random).unwrap();
        let names: Vec<(&str, u32)> = rows.iter().map(|r| (r.kernel.as_str(), r.size)).collect();
        let mut want = Vec::new();
        for n in [32, 48] {
            want.push(("copy buffer", n));
            want.extend(COPY_FORMATS.iter().map(|_| ("copy texture", n)));
            want.extend(CASES.iter().map(|c| (c.name, n)));
        }
        assert_eq!(names, want);
        for r in &rows {
            assert!(r.median_ms > 0.0 && r.gbps.is_finite(), "{r:?}");
            let Some(case) = CASES.iter().find(|c| c.name == r.kernel) else {
                continue;
            };
            let built = (case.build)(r.size);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            let plan = crate::graph::plan(&built.graph, &outputs).unwrap();
            assert_eq!(r.bytes_moved, plan_bytes(&plan).unwrap(), "{r:?}");
            let copy = rows
                .iter()
                .find(|c| c.size == r.size && c.kernel == "copy texture" && c.format == r.format)
                .unwrap();
            assert_eq!(r.yardstick, format!("copy texture {}", r.format));
            assert!((r.ratio - r.gbps / copy.gbps).abs() < 1e-12, "{r:?}");
        }
        let text = format_table("test device", true, 2, Inputs::Random, false, &rows);
        assert!(text.contains("only the ratios") && text.contains("copy texture rg32float"));
    }

    /// On a CPU device a row with a run under [`CPU_LEAST_SHARE`] of its median wall time is named
    /// in a warning after the table, unless its runs are too short to check; on a GPU (wall
    /// time mostly submission) it is not.
    #[test]
    fn rows_with_a_short_run_are_flagged_on_a_cpu_device() {
        let row = |kernel: &str, least_share: f64| BenchRow {
            kernel: kernel.into(),
            format: "r32float".into(),
            size: 1024,
            bytes_moved: 8.0 * 1024.0 * 1024.0,
            median_ms: 3.3,
            wall_ms: 3.5,
            least_share,
            gbps: 2.5,
            ratio: 1.0,
            yardstick: "copy buffer".into(),
            passes: Vec::new(),
        };
        let rows = [row("copy texture", 0.03), row("esm", 0.93)];
        let text = format_table("test device", true, 5, Inputs::Random, false, &rows);
        let warning = text
            .lines()
            .find(|l| l.starts_with("WARNING"))
            .expect("a warning");
        assert!(
            warning.contains("copy texture r32float at 1024² (0.03)"),
            "{warning}"
        );
        assert!(!warning.contains("esm"), "{warning}");
        let fine = format_table("test device", true, 5, Inputs::Random, false, &rows[1..]);
        assert!(!fine.contains("WARNING"), "{fine}");
        let mut short = row("copy texture", 0.3);
        short.wall_ms = 0.4;
        assert!(
            !format_table("test device", true, 5, Inputs::Random, false, &[short])
                .contains("WARNING")
        );
        assert!(
            !format_table("test device", false, 5, Inputs::Random, false, &rows)
                .contains("WARNING")
        );
    }

    /// The bytes of a SAT are its three passes' (two reads of the representation, one write
    /// of the table, the tiles' edges and carries), the five-pass baseline's as before, a
    /// blur's both passes with their halos.
    #[test]
    fn case_bytes_follow_the_cost_model() {
        let n = 512;
        let bytes = |name: &str| {
            let case = CASES.iter().find(|c| c.name == name).unwrap();
            let built = (case.build)(n);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            plan_bytes(&crate::graph::plan(&built.graph, &outputs).unwrap()).unwrap()
                / f64::from(n * n)
        };
        // rg32float moments in twice (2 × 8) and an rg32uint table out (8); a SAT_TILE² tile's last
        // row and column (2 × 8/64), read and written again as carries, and read once more.
        assert_eq!(
            bytes("sat fixed"),
            8.0 + 8.0 + 8.0 + 4.0 * 2.0 * 8.0 / f64::from(crate::sat::SAT_TILE)
        );
        // The first design: rg32float moments in (8), row scans out (16) and a block total per
        // row (1/32), their carries (2 × 2/32), the row scans again with a row carry per texel
        // (32) and column totals (1/32), the scans a third time with carries (32 + 1/32) and
        // the rgba32uint table (16).
        assert_eq!(
            bytes("sat fixed (5-pass, old)"),
            8.0 + 16.0 + 32.0 + 32.0 + 16.0 + 7.0 / 32.0
        );
        // Two passes of radius 4, 8 B out each: a row workgroup reads its 512 texels and 4 on
        // either side (520/512 × 8 B), a column workgroup 64 columns of 32 + 8 texels
        // (BLUR_COL_PER rows an invocation: 40/32 × 8 B).
        assert_eq!(
            bytes("blur rg32f r4"),
            520.0 / 512.0 * 8.0 + 8.0 + 40.0 / 32.0 * 8.0 + 8.0
        );
        // Depth (4 B) in, linear depth (4 B) out.
        assert_eq!(bytes("linearize"), 8.0);
    }

    #[test]
    fn bad_arguments_are_errors() {
        let gpu = gpu();
        let (d, q) = (&gpu.device, &gpu.queue);
        assert!(matches!(
            measure(d, q, &[], 1, &[], Inputs::Random),
            Err(Error::Invalid(_))
        ));
        assert!(matches!(
            measure(d, q, &[64], 0, &[], Inputs::Random),
            Err(Error::Invalid(_))
        ));
        assert!(matches!(
            measure(d, q, &[0], 1, &[], Inputs::Random),
            Err(Error::Invalid(_))
        ));
        assert!(matches!(
            measure(d, q, &[u32::MAX], 1, &[], Inputs::Random),
            Err(Error::Limit { .. })
        ));
    }
}
