//! The measurement: at each size the buffer copy, a texture copy per format, then each case
//! (in each kernel variant), every row's ratio taken to its yardstick.

use std::collections::HashMap;

use super::args::{check_args, select_cases};
use super::copy::{self, COPY_FORMATS, TextureCopy, format_name};
use super::graphs::BenchGraph;
use super::harness::{self, Inputs, Timed, gb_per_s, time_graph};
use super::memory::{check_memory, check_yardstick_memory};
use super::report::{minimal_bytes, roofline};
use super::variant::{KernelVariant, check_distinct};
use super::{BenchRow, texels};
use crate::error::{Error, Result};
use crate::exec::{Executor, KernelLayout};
use crate::graph::{Plan, cost};

/// Bytes `plan` moves per run: the cost model's reads and writes of every node.
pub fn plan_bytes(plan: &Plan) -> Result<f64> {
    plan.steps
        .iter()
        .map(|s| Ok(cost::node_traffic(plan, &s.node)?.bytes()))
        .sum()
}

/// A kernel or texture-copy row from a timed plan of `built`, its roofline from the buffer
/// copy's `buffer_gbps`.
fn row(
    name: &str,
    format: String,
    n: u32,
    (built, plan): (&BenchGraph, &Plan),
    t: Timed,
    buffer_gbps: f64,
) -> Result<BenchRow> {
    let bytes = plan_bytes(plan)?;
    let minimal = minimal_bytes(plan, &built.outputs)?;
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
        minimal_bytes: minimal,
        roofline: roofline(minimal, buffer_gbps, t.ms),
        yardstick: String::new(),
        passes: t.passes,
    })
}

/// Times, at every size in `sizes` (`repeat` timed runs each), the buffer copy of an
/// rgba32-sized map, the texture copies ([`TextureCopy`]: one texel an invocation, then four)
/// of every format of [`COPY_FORMATS`] (ratio to the buffer copy), then every case of
/// [`CASES`](super::CASES) whose name contains one of `only` (every case when `only` is empty;
/// ratio to the one-texel texture copy of its output's format). Every row's roofline is its
/// minimal traffic at the buffer copy's bandwidth of the same size ([`BenchRow::roofline`]).
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
    check_distinct(variants)?;
    let cases = select_cases(only)?;
    let budget = crate::limits::memory_budget()?;
    check_yardstick_memory(sizes, budget)?;
    check_memory(&cases, sizes, budget)?;
    harness::timer(device, queue, 1)?;
    let bench = Bench {
        device,
        queue,
        repeat,
        inputs,
    };
    let mut executor = Executor::new();
    // One executor a variant (its own pipelines), or the device's kernels unnamed.
    let mut variants: Vec<(String, Executor)> = variants
        .iter()
        .map(|v| (format!(" [{}]", v.name), v.executor()))
        .collect();
    let mut rows = Vec::new();
    for &n in sizes {
        let buffer = bench.buffer_copy(&mut executor, n)?;
        let buffer_gbps = buffer.gbps;
        rows.push(buffer);
        let mut copies = bench.texture_copies(&mut executor, n, buffer_gbps)?;
        let mut timed = Vec::new();
        for case in &cases {
            let built = (case.build)(n);
            let time = |suffix: &str, executor: &mut Executor| {
                bench.case_row(case.name, &built, (n, suffix), executor, buffer_gbps)
            };
            if variants.is_empty() {
                timed.push(time("", &mut executor)?);
            }
            for (suffix, executor) in &mut variants {
                timed.push(time(suffix, executor)?);
            }
        }
        // The copies again: each format's row keeps the faster of its two runs.
        let again = bench.texture_copies(&mut executor, n, buffer_gbps)?;
        for (first, again) in copies.iter_mut().zip(again) {
            if again.median_ms < first.median_ms {
                *first = again;
            }
        }
        // The kernels' yardstick: the one-texel copies, the first of each format.
        let by_format: HashMap<wgpu::TextureFormat, f64> = COPY_FORMATS
            .iter()
            .copied()
            .zip(copies.iter().map(|r| r.gbps))
            .collect();
        rows.extend(copies);
        for (format, r) in timed {
            rows.push(against_copy(r, format, &by_format)?);
        }
    }
    Ok(rows)
}

/// What every timing of one [`measure_variants`] shares: the device, the number of timed runs
/// and the values the imports are filled with.
struct Bench<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    repeat: u32,
    inputs: Inputs,
}

impl Bench<'_> {
    /// `built`'s plan and its time in `executor`.
    fn time(&self, executor: &mut Executor, built: &BenchGraph) -> Result<(Plan, Timed)> {
        time_graph(
            self.device,
            self.queue,
            executor,
            &built.graph,
            &built.outputs,
            self.repeat,
            self.inputs,
        )
    }

    /// The row of the buffer copy of an rgba32-sized `n`² map (the texture copies' yardstick).
    fn buffer_copy(&self, executor: &mut Executor, n: u32) -> Result<BenchRow> {
        let buffer = texels(n) * 16;
        let t = copy::time_buffer_copy(
            self.device,
            self.queue,
            &mut executor.kernels,
            buffer,
            self.repeat,
        )?;
        Ok(BenchRow {
            kernel: "copy buffer".into(),
            format: "-".into(),
            size: n,
            bytes_moved: 2.0 * buffer as f64,
            median_ms: t.ms,
            wall_ms: t.wall_ms,
            least_share: t.least_share,
            gbps: gb_per_s(2.0 * buffer as f64, t.ms),
            ratio: 1.0,
            minimal_bytes: 2.0 * buffer as f64,
            roofline: 1.0,
            yardstick: String::new(),
            passes: Vec::new(),
        })
    }

    /// The rows of the texture copies at side `n`: each [`TextureCopy`] in its order, of every
    /// format of [`COPY_FORMATS`] in theirs, each's ratio to the buffer copy's `buffer_gbps`.
    fn texture_copies(
        &self,
        executor: &mut Executor,
        n: u32,
        buffer_gbps: f64,
    ) -> Result<Vec<BenchRow>> {
        let mut copies = Vec::new();
        for (shape, &format) in TextureCopy::ALL
            .iter()
            .flat_map(|&c| COPY_FORMATS.iter().map(move |f| (c, f)))
        {
            let built = copy::copy_texture_graph(n, format, shape);
            let (plan, t) = self.time(executor, &built)?;
            let name = format_name(format);
            let mut r = row(shape.name(), name, n, (&built, &plan), t, buffer_gbps)?;
            r.ratio = r.gbps / buffer_gbps;
            r.yardstick = "copy buffer".into();
            copies.push(r);
            executor.release_textures();
        }
        Ok(copies)
    }

    /// The row of case `name` (graph `built`, side `n`) timed in `executor`, named
    /// `<name><suffix>`, and the format of its output texture, whose copy is its yardstick; its
    /// roofline from the buffer copy's `buffer_gbps`.
    fn case_row(
        &self,
        name: &str,
        built: &BenchGraph,
        (n, suffix): (u32, &str),
        executor: &mut Executor,
        buffer_gbps: f64,
    ) -> Result<(wgpu::TextureFormat, BenchRow)> {
        let (plan, t) = self.time(executor, built)?;
        let output = built.outputs.first().and_then(|o| plan.resource(o));
        // The texture's own format (a packed f16 pair is an r32uint texture).
        let format = output
            .map(|r| crate::graph::texture_format(r.resource.format))
            .ok_or_else(|| Error::Invalid(format!("benchmark `{name}` plans no output")))?;
        let r = row(
            &format!("{name}{suffix}"),
            format_name(format),
            n,
            (built, &plan),
            t,
            buffer_gbps,
        )?;
        executor.release_textures();
        Ok((format, r))
    }
}

/// Case row `r`, whose output is a `format` texture, with its ratio to that format's texture
/// copy (`copies`: GB/s by format); a format without a copy row is an error naming the case.
fn against_copy(
    mut r: BenchRow,
    format: wgpu::TextureFormat,
    copies: &HashMap<wgpu::TextureFormat, f64>,
) -> Result<BenchRow> {
    let copy_gbps = copies.get(&format).copied().ok_or_else(|| {
        Error::Invalid(format!(
            "benchmark `{}` writes {}, which has no texture copy row (COPY_FORMATS)",
            r.kernel,
            format_name(format)
        ))
    })?;
    r.ratio = r.gbps / copy_gbps;
    r.yardstick = format!("{} {}", TextureCopy::X1.name(), r.format);
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{CASES, format_table};
    use crate::gpu::Gpu;

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
        let before = crate::gpu_objects::created();
        let again = time(&mut executor, &msm);
        let after = crate::gpu_objects::created();
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
        let copies = rows
            .iter()
            .filter(|r| r.kernel.starts_with("copy texture"))
            .count();
        assert_eq!(copies, 2 * COPY_FORMATS.len());
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
            for copy in TextureCopy::ALL {
                want.extend(COPY_FORMATS.iter().map(|_| (copy.name(), n)));
            }
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
                .find(|c| c.size == r.size && c.kernel == "copy texture x1" && c.format == r.format)
                .unwrap();
            assert_eq!(r.yardstick, format!("copy texture x1 {}", r.format));
            assert!((r.ratio - r.gbps / copy.gbps).abs() < 1e-12, "{r:?}");
        }
        let text = format_table("test device", true, 2, Inputs::Random, false, &rows);
        assert!(text.contains("only the ratios") && text.contains("copy texture x1 rg32float"));
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
