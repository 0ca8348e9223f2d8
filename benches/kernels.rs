//! `cargo bench --bench kernels`: the kernel microbenchmark of `shadowgraph bench`.
//!
//! Sizes come from `SHADOWGRAPH_BENCH_SIZES` (comma list, default `512,1024,2048`), timed runs
//! per kernel from `SHADOWGRAPH_BENCH_REPEAT` (default 10). With `SHADOWGRAPH_BENCH_LOOKUP`
//! set, the shading pass's lookup cost (PCF against summed-area tables, 3² to 65²) follows.

use std::process::ExitCode;

use shadowgraph::low_level::bench;
use shadowgraph::low_level::gpu::Gpu;

const DEFAULT_SIZES: &[u32] = &[512, 1024, 2048];
const DEFAULT_REPEAT: u32 = 10;

fn sizes() -> Result<Vec<u32>, String> {
    match std::env::var("SHADOWGRAPH_BENCH_SIZES") {
        Ok(list) if !list.trim().is_empty() => list
            .split(',')
            .map(|s| {
                s.trim()
                    .parse::<u32>()
                    .map_err(|e| format!("SHADOWGRAPH_BENCH_SIZES: `{s}`: {e}"))
            })
            .collect(),
        _ => Ok(DEFAULT_SIZES.to_vec()),
    }
}

fn repeat() -> Result<u32, String> {
    match std::env::var("SHADOWGRAPH_BENCH_REPEAT") {
        Ok(r) if !r.trim().is_empty() => r
            .trim()
            .parse()
            .map_err(|e| format!("SHADOWGRAPH_BENCH_REPEAT: `{r}`: {e}")),
        _ => Ok(DEFAULT_REPEAT),
    }
}

fn run() -> Result<String, String> {
    let (sizes, repeat) = (sizes()?, repeat()?);
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    let mut report = bench::run(
        &gpu,
        &sizes,
        repeat,
        &[],
        bench::Inputs::Random,
        false,
        &[],
        &[],
    )
    .map_err(|e| e.to_string())?;
    if std::env::var_os("SHADOWGRAPH_BENCH_LOOKUP").is_some() {
        let rows = bench::lookup_cost(&gpu, bench::LOOKUP_WIDTHS, repeat, None, None)
            .map_err(|e| e.to_string())?;
        let cpu = gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
        report += &bench::format_lookup_table(&gpu.describe(), cpu, repeat, &rows);
    }
    Ok(report)
}

fn main() -> ExitCode {
    // `cargo bench` passes `--bench` (and any filter); this harness takes no arguments.
    match run() {
        Ok(report) => {
            print!("{report}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
