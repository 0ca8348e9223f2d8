//! Kernel microbenchmarks: every graph kernel timed by GPU timestamps at a set of square sizes,
//! next to `kernels/copy.wgsl` moving the same number of bytes (the device's practical
//! bandwidth, the yardstick a memory-bound kernel is judged against).
//!
//! Each kernel is one [`BenchCase`] in [`CASES`]: how many bytes it moves at size N and the
//! graph that runs it. The harness plans the graph, fills every imported texture with random
//! non-zero values, records it with [`Executor::record`] under a [`GpuTimer`], and keeps the
//! median over the timed runs (after [`WARMUP`] untimed ones) of the summed pass times.

use std::collections::HashMap;
use std::fmt::Write;
use std::sync::Arc;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::exec::{ComputeKernel, Executor, GpuTimer, KernelCache};
use crate::gpu::{Gpu, scoped, submit_and_wait, write_texture};
use crate::graph::{self, Graph, Plan};
use crate::sat::{self, SatCoding, SatVariant};
use crate::scene::{BlurKernel, Filter, Light, LightKind, Prefilter, Shadow, Storage, Technique};
use crate::technique;

/// Untimed runs before the timed ones (pipeline warm-up, lazy clears, caches).
pub const WARMUP: u32 = 2;

/// Bytes one invocation of the copy kernel copies (one `vec4<u32>`).
const COPY_BYTES_PER_INVOCATION: u64 = 16;

/// Name of the copy kernel's rows.
pub const COPY: &str = "copy";

/// One kernel measured at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// Kernel name ([`BenchCase::name`], or [`COPY`] for the yardstick).
    pub kernel: String,
    /// Side of the square map, texels.
    pub size: u32,
    /// Bytes read plus bytes written per run.
    pub bytes_moved: u64,
    /// Median GPU time per run over the timed runs, milliseconds (all passes of the run).
    pub median_ms: f64,
    /// Effective bandwidth: `bytes_moved / median time`, GB/s (10⁹ bytes per second).
    pub gbps: f64,
    /// `gbps` over the copy kernel's GB/s at the same size and byte count (1 for the copy).
    pub ratio_to_copy: f64,
}

/// The graph a case runs and the outputs that keep its nodes alive.
pub struct BenchGraph {
    /// The graph; its imports are R32Float textures the harness fills with random depths.
    pub graph: Graph,
    /// Resources requested from [`graph::plan`].
    pub outputs: Vec<String>,
}

/// One kernel to benchmark: adding a kernel to the benchmark is one entry of [`CASES`].
pub struct BenchCase {
    /// Name in the report.
    pub name: &'static str,
    /// Bytes read plus bytes written at size `n` (the copy kernel moves the same amount).
    pub bytes_moved: fn(u32) -> u64,
    /// The graph at size `n`.
    pub build: fn(u32) -> BenchGraph,
}

/// Every benchmarked graph kernel.
pub const CASES: &[BenchCase] = &[
    BenchCase {
        name: "linearize",
        bytes_moved: linearize_bytes,
        build: linearize_graph,
    },
    BenchCase {
        name: "vsm",
        bytes_moved: |n| texels(n) * (4 + 8),
        build: |n| stage_graph(n, vsm(), "light0.linear", "light0.vsm"),
    },
    BenchCase {
        name: "evsm4",
        bytes_moved: |n| texels(n) * (4 + 16),
        build: |n| stage_graph(n, evsm4(), "light0.linear", "light0.evsm"),
    },
    BenchCase {
        name: "esm",
        bytes_moved: |n| texels(n) * (4 + 4),
        build: |n| stage_graph(n, esm(), "light0.linear", "light0.esm"),
    },
    BenchCase {
        name: "blur rg32f r4",
        bytes_moved: |n| 2 * texels(n) * (8 + 8),
        build: |n| stage_graph(n, vsm(), "light0.vsm", "light0.vsm.blur_v"),
    },
    BenchCase {
        name: "blur rg32f r32",
        bytes_moved: |n| 2 * texels(n) * (8 + 8),
        build: |n| stage_graph(n, vsm_blur(32.0), "light0.vsm", "light0.vsm.blur_v"),
    },
    BenchCase {
        name: "blur log r4",
        bytes_moved: |n| 2 * texels(n) * (4 + 4),
        build: |n| stage_graph(n, esm(), "light0.esm", "light0.esm.blur_v"),
    },
    BenchCase {
        name: "msm",
        bytes_moved: |n| texels(n) * (4 + 16),
        build: |n| stage_graph(n, msm(Storage::F32), "light0.linear", "light0.msm"),
    },
    BenchCase {
        name: "msm f16 quantized",
        bytes_moved: |n| texels(n) * (4 + 8),
        build: |n| stage_graph(n, msm(Storage::F16), "light0.linear", "light0.msm"),
    },
    BenchCase {
        name: "csm (2 terms)",
        bytes_moved: |n| texels(n) * (4 + 16),
        build: |n| stage_graph(n, csm(), "light0.linear", "light0.csm0"),
    },
    BenchCase {
        name: "mips rgba32f",
        // The map read once; every level written once, level 0 included (up to six levels a
        // dispatch, reduced in registers and workgroup memory).
        bytes_moved: |n| 16 * (texels(n) + mip_texels(n)),
        build: |n| stage_graph(n, msm_mips(), "light0.msm", "light0.msm.mips"),
    },
    BenchCase {
        name: "sat fixed",
        bytes_moved: sat_bytes,
        build: |n| sat_graph(n, SatVariant::Fixed),
    },
    BenchCase {
        name: "sat float",
        bytes_moved: sat_bytes,
        build: |n| sat_graph(n, SatVariant::Float),
    },
    // The first design, timed beside the tiled passes until their comparison is recorded.
    BenchCase {
        name: "sat fixed (5-pass, old)",
        bytes_moved: |n| texels(n) * (8 + 16),
        build: |n| sat_graph_five_pass(n, SatVariant::Fixed),
    },
];

fn texels(n: u32) -> u64 {
    u64::from(n) * u64::from(n)
}

fn blur4() -> Filter {
    Filter::Blur {
        radius: 4.0,
        sigma: 2.0,
        kernel: BlurKernel::Gaussian,
    }
}

fn vsm() -> Technique {
    vsm_blur(4.0)
}

/// VSM with a Gaussian blur of `radius` taps each side (σ = radius / 2).
fn vsm_blur(radius: f32) -> Technique {
    Technique::Vsm {
        prefilter: Prefilter {
            storage: Storage::F32,
            filter: Filter::Blur {
                radius,
                sigma: radius / 2.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        bleed: 0.2,
        min_variance: 1e-5,
    }
}

fn evsm4() -> Technique {
    Technique::Evsm {
        prefilter: Prefilter {
            storage: Storage::F32,
            filter: blur4(),
        },
        four: true,
        exp_pos: 40.0,
        exp_neg: 5.0,
        bleed: 0.0,
        min_variance: 1e-4,
    }
}

fn msm(storage: Storage) -> Technique {
    Technique::Msm {
        prefilter: Prefilter {
            storage,
            filter: blur4(),
        },
        hausdorff: false,
        moment_bias: crate::scene::default_moment_bias(storage),
        bleed: 0.0,
    }
}

fn msm_mips() -> Technique {
    Technique::Msm {
        prefilter: Prefilter {
            storage: Storage::F32,
            filter: Filter::Mips {
                width: 1.0,
                max_anisotropy: 0,
            },
        },
        hausdorff: false,
        moment_bias: 1e-5,
        bleed: 0.0,
    }
}

fn csm() -> Technique {
    Technique::Csm {
        prefilter: Prefilter {
            storage: Storage::F32,
            filter: blur4(),
        },
        terms: 2,
        attenuation: 1.0,
        offset: 0.25,
        scale: 2.0,
    }
}

/// Texels of a full mip chain of an `n`² map.
fn mip_texels(n: u32) -> u64 {
    let levels = technique::mip_levels(n, n);
    (0..levels).map(|l| texels((n >> l).max(1))).sum()
}

fn esm() -> Technique {
    Technique::Esm {
        filter: blur4(),
        exponent: 80.0,
    }
}

/// The stages of a light's shipped graph between `input` (made an import, its producers
/// dropped by the planner) and `output`: one kernel or a filter's passes, timed alone.
fn stage_graph(n: u32, technique: Technique, input: &str, output: &str) -> BenchGraph {
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
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

/// A SAT reads one Rg32Float moment texel and writes one 8-byte table texel per texel (its
/// passes read the moments twice: the ratio to copy counts only the essential bytes).
fn sat_bytes(n: u32) -> u64 {
    texels(n) * (8 + 8)
}

/// The SAT passes of [`sat::add_sat`] over an imported `n`² VSM-shaped (Rg32Float) map; fixed
/// point for lookups of up to 64 × 64 texels of values in [0, 1].
fn sat_graph(n: u32, variant: SatVariant) -> BenchGraph {
    sat_graph_with(n, variant, sat::add_sat)
}

/// [`sat_graph`] with the five passes of [`sat::five_pass`] (4-channel table).
fn sat_graph_five_pass(n: u32, variant: SatVariant) -> BenchGraph {
    sat_graph_with(n, variant, sat::five_pass::add_sat_five_pass)
}

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

/// `linearize` reads one R32Float texel and writes one R32Float texel per texel.
fn linearize_bytes(n: u32) -> u64 {
    2 * u64::from(n) * u64::from(n) * 4
}

/// The shipped node of [`technique::add_light_nodes`] for a spot light (the perspective path,
/// the more expensive one), with its depth import switched to R32Float: a depth texture cannot
/// be written from the CPU, and the kernel reads either through `texture_2d<f32>`.
fn linearize_graph(n: u32) -> BenchGraph {
    let light = bench_light(n, Technique::Hard);
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &light);
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
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
        },
    }
}

/// Times every case of [`CASES`] and the copy kernel at every size in `sizes`, `repeat` timed
/// runs each. Rows come per size: the copy first, then the cases in [`CASES`] order.
pub fn measure(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    sizes: &[u32],
    repeat: u32,
) -> Result<Vec<BenchRow>> {
    check_args(device, sizes, repeat)?;
    timer(device, queue, 1)?;
    let mut executor = Executor::new();
    let mut rows = Vec::new();
    for &n in sizes {
        // Copy GB/s per byte count, so each case is compared with a copy of its own size.
        let mut copies: HashMap<u64, f64> = HashMap::new();
        for case in CASES {
            let bytes = (case.bytes_moved)(n);
            let copy_buffer =
                (bytes / 2).div_ceil(COPY_BYTES_PER_INVOCATION).max(1) * COPY_BYTES_PER_INVOCATION;
            let copy_gbps = match copies.get(&copy_buffer) {
                Some(&g) => g,
                None => {
                    let row =
                        time_copy(device, queue, &mut executor.kernels, n, copy_buffer, repeat)?;
                    copies.insert(copy_buffer, row.gbps);
                    let g = row.gbps;
                    rows.push(row);
                    g
                }
            };
            let ms = time_case(device, queue, &mut executor, case, n, repeat)?;
            let gbps = gb_per_s(bytes, ms);
            rows.push(BenchRow {
                kernel: case.name.to_string(),
                size: n,
                bytes_moved: bytes,
                median_ms: ms,
                gbps,
                ratio_to_copy: gbps / copy_gbps,
            });
        }
    }
    Ok(rows)
}

/// Runs [`measure`] on `gpu` and formats the report.
pub fn run(gpu: &Gpu, sizes: &[u32], repeat: u32) -> Result<String> {
    let rows = measure(&gpu.device, &gpu.queue, sizes, repeat)?;
    let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    Ok(format_table(&gpu.describe(), cpu, repeat, &rows))
}

/// The report: a header naming the device and the method, then one line per row.
pub fn format_table(device: &str, cpu: bool, repeat: u32, rows: &[BenchRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "kernel benchmark on {device}");
    let _ = writeln!(
        s,
        "GPU timestamps, median of {repeat} run(s) after {WARMUP} warm-up run(s); GB/s = bytes \
         moved (one read + one write per texel) / time; x copy = GB/s over the copy kernel's \
         GB/s for the same bytes."
    );
    if cpu {
        let _ = writeln!(
            s,
            "NOTE: this adapter is a CPU device (software Vulkan): times and GB/s are CPU numbers, \
             only the ratios to copy are meaningful."
        );
    }
    let _ = writeln!(
        s,
        "{:>6}  {:<12} {:>10} {:>10} {:>9} {:>7}",
        "size", "kernel", "MiB moved", "median ms", "GB/s", "x copy"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:>6}  {:<12} {:>10.2} {:>10.3} {:>9.2} {:>7.2}",
            r.size,
            r.kernel,
            r.bytes_moved as f64 / (1024.0 * 1024.0),
            r.median_ms,
            r.gbps,
            r.ratio_to_copy
        );
    }
    s
}

fn check_args(device: &wgpu::Device, sizes: &[u32], repeat: u32) -> Result<()> {
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

/// The scene the lookup-cost benchmark shades: `scenes/techniques/vsm.toml` (built-in shapes
/// only), embedded so the benchmark runs from anywhere.
const LOOKUP_SCENE: &str = include_str!("../scenes/techniques/vsm.toml");

/// Default filter widths of [`lookup_cost`]: 3×3 to 65×65 texels.
pub const LOOKUP_WIDTHS: &[u32] = &[3, 5, 9, 17, 33, 65];

/// One filter width of the lookup-cost benchmark: the shading pass's median GPU time with a
/// `width × width` PCF box and with VSM through summed-area tables of the same box.
#[derive(Clone, Debug, PartialEq)]
pub struct LookupRow {
    /// Filter width in texels (odd: PCF's window is `2r + 1`).
    pub width: u32,
    /// Shading pass, PCF box of `width²` taps, ms.
    pub pcf_ms: f64,
    /// Shading pass, VSM through the u32 fixed-point table (16 loads per channel), ms.
    pub sat_fixed_ms: f64,
    /// Shading pass, VSM through the f32 table, ms.
    pub sat_float_ms: f64,
    /// Building the fixed-point table (its passes), ms.
    pub sat_build_ms: f64,
}

/// The shading pass's cost as the filter widens: for each width in `widths`, the median over
/// `repeat` frames (after [`WARMUP`]) of the `shade` pass of the VSM technique scene rendered
/// with a PCF box of that width and with VSM read through summed-area tables of that box.
/// PCF's taps grow with the square of the width; the table's lookups stay at four per channel
/// (sixteen with sub-texel edges) whatever the width.
pub fn lookup_cost(gpu: &Gpu, widths: &[u32], repeat: u32) -> Result<Vec<LookupRow>> {
    if widths.is_empty() || repeat == 0 {
        return Err(Error::Invalid(
            "lookup benchmark needs widths and repeat ≥ 1".into(),
        ));
    }
    if let Some(w) = widths.iter().find(|&&w| w == 0 || w % 2 == 0 || w > 65) {
        return Err(Error::Invalid(format!(
            "lookup benchmark width {w}: widths are odd, 1 to 65 (PCF windows are 2r + 1 wide, r ≤ 32)"
        )));
    }
    if !gpu.can_time() {
        return Err(Error::Invalid(
            "this device cannot time kernels: it has no TIMESTAMP_QUERY feature".to_string(),
        ));
    }
    let base = crate::scene::Scene::parse(std::path::Path::new("vsm.toml"), LOOKUP_SCENE)?;
    let mut renderer = crate::render::Renderer::new(&gpu.device);
    let mut shade = |technique: Technique| -> Result<(f64, f64)> {
        let mut scene = base.clone();
        scene.lights[0].shadow.technique = technique;
        let frame = renderer.render(
            &gpu.device,
            &gpu.queue,
            &scene,
            crate::render::RenderOptions {
                aux: false,
                repeat: WARMUP + repeat,
                dump: false,
            },
        )?;
        let pass = |frame_timings: &[(String, f64)], f: &dyn Fn(&str) -> bool| -> f64 {
            frame_timings
                .iter()
                .filter(|(name, _)| f(name))
                .map(|(_, ms)| ms)
                .sum()
        };
        let timed = &frame.timings[WARMUP as usize..];
        let mut shade: Vec<f64> = timed.iter().map(|t| pass(t, &|n| n == "shade")).collect();
        let mut table: Vec<f64> = timed
            .iter()
            .map(|t| pass(t, &|n| n.contains(".sat")))
            .collect();
        Ok((median(&mut shade), median(&mut table)))
    };
    let vsm = |variant, width: u32| Technique::Vsm {
        prefilter: Prefilter {
            storage: Storage::F32,
            filter: Filter::Sat {
                width: width as f32,
                variant,
            },
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    let mut rows = Vec::new();
    for &width in widths {
        let (pcf_ms, _) = shade(Technique::Pcf {
            radius: (width - 1) / 2,
            kernel: crate::scene::PcfKernel::Box,
        })?;
        let (sat_fixed_ms, sat_build_ms) = shade(vsm(SatVariant::Fixed, width))?;
        let (sat_float_ms, _) = shade(vsm(SatVariant::Float, width))?;
        rows.push(LookupRow {
            width,
            pcf_ms,
            sat_fixed_ms,
            sat_float_ms,
            sat_build_ms,
        });
    }
    Ok(rows)
}

/// [`lookup_cost`]'s report: one line per width, times and each over the narrowest width's
/// (on a CPU adapter only those ratios mean anything).
pub fn format_lookup_table(device: &str, cpu: bool, repeat: u32, rows: &[LookupRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "shading-pass lookup cost on {device}");
    let _ = writeln!(
        s,
        "scenes/techniques/vsm.toml (400×300, 512² map); GPU timestamps of the shade pass, median \
         of {repeat} frame(s) after {WARMUP} warm-up frame(s); (×) = over the first width's time."
    );
    if cpu {
        let _ = writeln!(
            s,
            "NOTE: this adapter is a CPU device (software Vulkan): only the ratios mean anything."
        );
    }
    let _ = writeln!(
        s,
        "{:>7}  {:>10} {:>7}  {:>12} {:>7}  {:>12} {:>7}  {:>13}",
        "width", "pcf ms", "(×)", "sat u32 ms", "(×)", "sat f32 ms", "(×)", "table build ms"
    );
    let first = rows.first();
    for r in rows {
        let ratio = |v: f64, f: fn(&LookupRow) -> f64| first.map_or(f64::NAN, |r0| v / f(r0));
        let _ = writeln!(
            s,
            "{:>4}²   {:>10.3} {:>7.2}  {:>12.3} {:>7.2}  {:>12.3} {:>7.2}  {:>13.3}",
            r.width,
            r.pcf_ms,
            ratio(r.pcf_ms, |r| r.pcf_ms),
            r.sat_fixed_ms,
            ratio(r.sat_fixed_ms, |r| r.sat_fixed_ms),
            r.sat_float_ms,
            ratio(r.sat_float_ms, |r| r.sat_float_ms),
            r.sat_build_ms,
        );
    }
    s
}

/// A timer for `passes` passes, or the error saying this device cannot time.
fn timer(device: &wgpu::Device, queue: &wgpu::Queue, passes: u32) -> Result<GpuTimer> {
    GpuTimer::new(device, queue, passes.max(1)).ok_or_else(|| {
        Error::Invalid(
            "this device cannot time kernels: it has no TIMESTAMP_QUERY feature".to_string(),
        )
    })
}

fn gb_per_s(bytes: u64, ms: f64) -> f64 {
    bytes as f64 / (ms * 1e6)
}

/// Median of the summed pass times of `repeat` runs of `record` (after [`WARMUP`] runs), ms.
fn median_time(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    timer: &mut GpuTimer,
    repeat: u32,
    mut record: impl FnMut(&mut wgpu::CommandEncoder, &mut GpuTimer) -> Result<()>,
) -> Result<f64> {
    let mut times = Vec::with_capacity(repeat as usize);
    for run in 0..WARMUP + repeat {
        timer.reset();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("shadowgraph.bench"),
        });
        record(&mut enc, timer)?;
        timer.resolve(&mut enc);
        submit_and_wait(device, queue, enc, "bench")?;
        let passes = timer.read(device)?;
        if passes.is_empty() {
            return Err(Error::Gpu {
                stage: "bench".into(),
                message: "no pass was timed".into(),
            });
        }
        if run >= WARMUP {
            times.push(passes.iter().map(|(_, ms)| ms).sum());
        }
    }
    Ok(median(&mut times))
}

/// Median (mean of the middle two for an even count); NaN for no values.
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// Median time of one case at size `n`, ms.
fn time_case(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    executor: &mut Executor,
    case: &BenchCase,
    n: u32,
    repeat: u32,
) -> Result<f64> {
    let built = (case.build)(n);
    let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
    let plan = graph::plan(&built.graph, &outputs)?;
    executor.prepare(device, &plan)?;
    let imports = random_imports(device, queue, &plan)?;
    let mut timer = timer(device, queue, plan.steps.len() as u32)?;
    median_time(device, queue, &mut timer, repeat, |enc, t| {
        executor.record(device, enc, &plan, &imports, Some(t))?;
        Ok(())
    })
}

/// A texture for every import of `plan`, filled with random depths in (0, 1].
fn random_imports(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
) -> Result<HashMap<String, wgpu::Texture>> {
    let mut imports = HashMap::new();
    for (i, r) in plan
        .resources
        .iter()
        .filter(|r| r.slot.is_none())
        .enumerate()
    {
        let name = &r.resource.name;
        let channels = match r.resource.format {
            wgpu::TextureFormat::R32Float => 1,
            wgpu::TextureFormat::Rg32Float => 2,
            wgpu::TextureFormat::Rgba32Float => 4,
            other => {
                return Err(Error::Invalid(format!(
                    "benchmark import `{name}` is {other:?}; the harness fills 32-bit float imports only"
                )));
            }
        };
        let texture = scoped(
            device,
            || {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("shadowgraph.bench.import"),
                    size: wgpu::Extent3d {
                        width: r.width,
                        height: r.height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: r.resource.format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                })
            },
            |m| Error::Gpu {
                stage: format!("creating benchmark import `{name}`"),
                message: m,
            },
        )?;
        let texels = r.width as usize * r.height as usize;
        let depths = random_depths(texels * channels, 0x5EED + i as u64);
        write_texture(queue, &texture, bytemuck::cast_slice(&depths));
        imports.insert(name.clone(), texture);
    }
    Ok(imports)
}

/// `count` pseudo-random values in (0, 1] (SplitMix64; deterministic per `seed`).
fn random_depths(count: usize, seed: u64) -> Vec<f32> {
    let mut state = seed;
    (0..count)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 40) as f32 + 1.0) / (1u32 << 24) as f32
        })
        .collect()
}

/// The copy kernel's row at size `n`: a copy of a `buffer_bytes` buffer (moving twice that).
fn time_copy(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    kernels: &mut KernelCache,
    n: u32,
    buffer_bytes: u64,
    repeat: u32,
) -> Result<BenchRow> {
    let max_x = device
        .limits()
        .max_compute_workgroups_per_dimension
        .min(65535);
    let copy = CopyBench::new(device, queue, kernels, buffer_bytes, max_x)?;
    let mut timer = timer(device, queue, 1)?;
    let ms = median_time(device, queue, &mut timer, repeat, |enc, t| {
        copy.record(enc, Some(t));
        Ok(())
    })?;
    let bytes = 2 * buffer_bytes;
    Ok(BenchRow {
        kernel: COPY.to_string(),
        size: n,
        bytes_moved: bytes,
        median_ms: ms,
        gbps: gb_per_s(bytes, ms),
        ratio_to_copy: 1.0,
    })
}

/// Workgroups for copying `bytes` with `wg`-wide groups: a 2-D grid with `x ≤ max_x` and
/// `y ≤ max_y`, as `kernels/copy.wgsl` indexes it (`i = id.x + id.y · groups.x · WG_SIZE`).
fn copy_groups(bytes: u64, wg: u32, max_x: u32, max_y: u32) -> Result<[u32; 3]> {
    let invocations = bytes.div_ceil(COPY_BYTES_PER_INVOCATION);
    let groups = invocations.div_ceil(u64::from(wg.max(1))).max(1);
    let x = groups.min(u64::from(max_x.max(1)));
    let y = groups.div_ceil(x);
    if y > u64::from(max_y) {
        return Err(Error::Limit {
            what: "copy benchmark workgroups".into(),
            requested: groups,
            limit: u64::from(max_x) * u64::from(max_y),
        });
    }
    Ok([x as u32, y as u32, 1])
}

/// Whether a storage buffer of `bytes` can be created and bound whole.
fn check_copy_bytes(limits: &wgpu::Limits, bytes: u64) -> Result<()> {
    let limit = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    if bytes > limit {
        return Err(Error::Limit {
            what: "copy benchmark buffer (bytes)".into(),
            requested: bytes,
            limit,
        });
    }
    Ok(())
}

/// The copy kernel bound to a source and a destination buffer of the same size.
struct CopyBench {
    kernel: Arc<ComputeKernel>,
    /// The destination (the bind group keeps both buffers alive; the tests read this one).
    #[cfg_attr(not(test), allow(dead_code, reason = "read back by the tests only"))]
    dst: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    groups: [u32; 3],
}

impl CopyBench {
    /// Buffers of `bytes` (a multiple of 16), the source random, bound by reflected names.
    fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernels: &mut KernelCache,
        bytes: u64,
        max_x: u32,
    ) -> Result<Self> {
        let limits = device.limits();
        check_copy_bytes(&limits, bytes)?;
        let kernel = kernels.get(device, COPY)?;
        let wg = kernel.reflection.workgroup_size.unwrap_or([1, 1, 1]);
        let max_y = limits.max_compute_workgroups_per_dimension;
        let groups = copy_groups(bytes, wg[0] * wg[1] * wg[2], max_x, max_y)?;
        let gpu_err = |m: String| Error::Gpu {
            stage: "creating the copy benchmark".into(),
            message: m,
        };
        let buffer = |label: &str, usage: wgpu::BufferUsages| {
            scoped(
                device,
                || {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size: bytes,
                        usage,
                        mapped_at_creation: false,
                    })
                },
                gpu_err,
            )
        };
        let src = buffer(
            "shadowgraph.bench.copy.src",
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        )?;
        let dst = buffer(
            "shadowgraph.bench.copy.dst",
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        )?;
        let data = random_depths((bytes / 4) as usize, 0xC0FF);
        queue.write_buffer(&src, 0, bytemuck::cast_slice(&data));
        let bind_group = copy_bind_group(device, &kernel, &src, &dst)?;
        Ok(Self {
            kernel,
            dst,
            bind_group,
            groups,
        })
    }

    /// Records one copy pass, timed when `timer` is given.
    fn record(&self, enc: &mut wgpu::CommandEncoder, timer: Option<&mut GpuTimer>) {
        let timestamp_writes = timer.and_then(|t| t.compute_pass(COPY));
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shadowgraph.bench.copy"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.kernel.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.groups[0], self.groups[1], self.groups[2]);
    }
}

/// Binds `src` and `dst` to the copy kernel's bindings of those names.
fn copy_bind_group(
    device: &wgpu::Device,
    kernel: &ComputeKernel,
    src: &wgpu::Buffer,
    dst: &wgpu::Buffer,
) -> Result<wgpu::BindGroup> {
    let mut entries = Vec::new();
    for (name, buffer) in [("src", src), ("dst", dst)] {
        let b = kernel
            .reflection
            .binding(name)
            .ok_or_else(|| Error::Pipeline {
                kernel: COPY.into(),
                message: format!("the copy kernel has no binding `{name}`"),
            })?;
        entries.push(wgpu::BindGroupEntry {
            binding: b.binding,
            resource: buffer.as_entire_binding(),
        });
    }
    scoped(
        device,
        || {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadowgraph.bench.copy"),
                layout: &kernel.layouts[0],
                entries: &entries,
            })
        },
        |message| Error::Pipeline {
            kernel: COPY.into(),
            message: format!("binding the copy benchmark: {message}"),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::read_buffer;

    #[test]
    fn copy_groups_cover_every_invocation_once_in_a_2d_grid() {
        for (bytes, max_x) in [
            (16, 65535),
            (40_000, 3),
            (256 * 16 * 70_000, 65535),
            (64, 1),
        ] {
            let [x, y, z] = copy_groups(bytes, 256, max_x, 65535).unwrap();
            let invocations = bytes / 16;
            let cover = u64::from(x) * u64::from(y) * 256;
            assert!(x <= max_x && z == 1, "{bytes}: {x}x{y}x{z}");
            assert!(cover >= invocations, "{bytes}: {x}x{y} covers {cover}");
            assert!(
                cover - invocations < u64::from(x) * 256,
                "{bytes}: a whole spare row"
            );
        }
        assert!(copy_groups(16 * 256 * 10, 256, 3, 3).is_err());
    }

    #[test]
    fn median_of_odd_even_and_unsorted() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn random_depths_are_in_zero_one_and_never_zero() {
        let d = random_depths(100_000, 7);
        assert!(d.iter().all(|&v| v > 0.0 && v <= 1.0));
        assert!(d.iter().any(|&v| v < 0.01) && d.iter().any(|&v| v > 0.99));
    }

    fn gpu() -> Gpu {
        match Gpu::new() {
            Ok(g) => g,
            Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
        }
    }

    /// The yardstick must really copy, including through the 2-D grid (forced by `max_x`).
    #[test]
    fn copy_kernel_copies_through_a_2d_grid() {
        let gpu = gpu();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut kernels = KernelCache::default();
        let bytes = 40_000;
        let copy = CopyBench::new(device, queue, &mut kernels, bytes, 3).unwrap();
        assert_eq!(copy.groups, [3, 4, 1]);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        copy.record(&mut enc, None);
        enc.copy_buffer_to_buffer(&copy.dst, 0, &readback, 0, bytes);
        submit_and_wait(device, queue, enc, "test").unwrap();
        let got = read_buffer(device, &readback).unwrap();
        let want = random_depths((bytes / 4) as usize, 0xC0FF);
        assert_eq!(got, bytemuck::cast_slice::<f32, u8>(&want));
    }

    #[test]
    fn measure_reports_copy_then_each_case_per_size() {
        let gpu = gpu();
        let rows = measure(&gpu.device, &gpu.queue, &[32, 48], 2).unwrap();
        let names: Vec<(&str, u32)> = rows.iter().map(|r| (r.kernel.as_str(), r.size)).collect();
        // Per size: each case, preceded by a copy row whenever its byte count is new.
        let mut want = Vec::new();
        for n in [32, 48] {
            let mut seen = Vec::new();
            for case in CASES {
                let bytes = (case.bytes_moved)(n);
                if !seen.contains(&bytes) {
                    seen.push(bytes);
                    want.push((COPY, n));
                }
                want.push((case.name, n));
            }
        }
        assert_eq!(names, want);
        for r in &rows {
            assert!(r.median_ms > 0.0 && r.gbps.is_finite(), "{r:?}");
            if let Some(case) = CASES.iter().find(|c| c.name == r.kernel) {
                assert_eq!(r.bytes_moved, (case.bytes_moved)(r.size), "{r:?}");
            }
        }
        let text = format_table("test device", true, 2, &rows);
        assert!(text.contains("only the ratios") && text.contains("linearize"));
    }

    #[test]
    fn bad_arguments_are_errors() {
        let gpu = gpu();
        let (d, q) = (&gpu.device, &gpu.queue);
        assert!(matches!(measure(d, q, &[], 1), Err(Error::Invalid(_))));
        assert!(matches!(measure(d, q, &[64], 0), Err(Error::Invalid(_))));
        assert!(matches!(measure(d, q, &[0], 1), Err(Error::Invalid(_))));
        assert!(matches!(
            measure(d, q, &[u32::MAX], 1),
            Err(Error::Limit { .. })
        ));
    }
}
