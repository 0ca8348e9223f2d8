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
//! [`crate::exec::Executor::record`] under a [`crate::timer::GpuTimer`], and keeps the median over the timed
//! runs (after [`WARMUP`] untimed ones) of the summed node times.
//!
//! The entry is [`run`]; [`measure()`] ([`measure_variants`]) takes the rows, [`format_table`]
//! prints them. The case list is `cases.rs`, the graphs the cases run `graphs.rs`, the
//! yardsticks `copy.rs`, the timing `harness.rs`, the checks of the arguments and of memory
//! `args.rs` and `memory.rs`, the kernel variants compared side by side `variant.rs`; the
//! shading pass's costs are `lookup.rs` (`--lookup`) and `soft.rs` (the soft techniques).

mod args;
mod cases;
mod copy;
mod csm_chain;
mod graphs;
mod harness;
mod lookup;
mod measure;
mod memory;
mod report;
mod soft;
mod variant;

pub use self::args::{check_args, select_cases};
use self::args::{check_map, check_only, with_flags};
pub use self::cases::{BenchCase, CASES};
pub use self::copy::{COPY, COPY_FORMATS, TextureCopy, copy_texture_graph, format_name};
pub use self::graphs::BenchGraph;
pub use self::harness::{Inputs, Timed, fill_imports, random_imports};
pub use self::lookup::{LOOKUP_WIDTHS, LookupRow, format_lookup_table, lookup_cost};
pub use self::measure::{measure, measure_layouts, measure_variants, plan_bytes};
pub use self::memory::{case_bytes, check_memory};
pub use self::report::{CPU_CHECKED_MS, CPU_LEAST_SHARE, format_table, minimal_bytes};
pub use self::soft::{
    SOFT_LIGHT_SIZES, SOFT_TECHNIQUES, SoftRow, check_soft_args, format_soft_table, soft_cost,
};
pub use self::variant::{KernelVariant, SHIPPED, UNCHECKED, ZEROED};
use crate::error::{Error, Result};
use crate::exec::KernelLayout;
use crate::gpu::Gpu;
use crate::timer::GPU_WARMUP_MS;

/// Untimed runs before the timed ones (pipeline warm-up, lazy clears, caches).
pub const WARMUP: u32 = 2;

/// One kernel measured at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// Kernel name ([`BenchCase::name`], `copy buffer` or a [`TextureCopy::name`]).
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
    /// The least a run could move ([`minimal_bytes`]: one read of each texture it imports, one
    /// write of each output, every mip level), bytes; the buffer copy's own bytes.
    pub minimal_bytes: f64,
    /// The time `minimal_bytes` takes at the buffer copy's GB/s (same size) over the median
    /// time: 1.0 at the buffer copy's speed. A fused chain counts its first input and its last
    /// outputs only, so that fusing shows.
    pub roofline: f64,
    /// Each dispatch's median time, ms, by node name in order ([`Timed::passes`]; empty for
    /// the buffer copy).
    pub passes: Vec<(String, f64)>,
    /// The yardstick: `copy texture x1 <format>` for a kernel, `copy buffer` for a texture copy
    /// (empty for the buffer copy itself).
    pub yardstick: String,
}

/// Texels of an `n`² map.
fn texels(n: u32) -> u64 {
    u64::from(n) * u64::from(n)
}

/// Runs [`measure()`] on `gpu` and formats the report: each kernel in each of `layouts` in turn
/// (`--layouts`), or in each folder of `kernel_dirs` (`--kernel-dirs`, [`KernelVariant::folder`];
/// [`SHIPPED`] the embedded kernels), or the device's kernels alone. Layouts and folders are
/// not combined.
#[expect(
    clippy::too_many_arguments,
    reason = "the command line's options, each its own flag"
)]
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
