//! The kernel benchmark's report: a header naming the device and the method, a line per row,
//! and on a CPU device a warning naming rows whose timer the wall clock contradicts; and each
//! row's roofline, its minimal traffic ([`minimal_bytes`]) at the buffer copy's bandwidth.

use std::fmt::Write;

use super::harness::Inputs;
use super::{BenchRow, GPU_WARMUP_MS, WARMUP};
use crate::error::{Error, Result};
use crate::graph::{Plan, texel_bytes, texture_format};

/// The least a run of `plan` could move to give `outputs`, bytes: one read of every texture it
/// imports (level 0: what the steps read), one write of every output (each of its mip levels
/// and layers), from the formats and the sizes. Intermediate maps count nothing, so a fused
/// chain's minimal traffic is its first input and last output whatever its passes: the
/// roofline column ([`BenchRow::roofline`]) credits fusion, where the cost model's bytes
/// (`MiB moved`) count every pass's. An output the plan does not hold is an error naming it.
pub fn minimal_bytes(plan: &Plan, outputs: &[String]) -> Result<f64> {
    let read: u64 = plan
        .resources
        .iter()
        .filter(|r| r.producer.is_none())
        .map(|r| {
            let texel = texel_bytes(texture_format(r.resource.format));
            u64::from(r.width) * u64::from(r.height) * texel
        })
        .sum();
    let mut written = 0;
    for o in outputs {
        let r = plan
            .resource(o)
            .ok_or_else(|| Error::Invalid(format!("benchmark output `{o}` is not planned")))?;
        written += r.bytes;
    }
    Ok((read + written) as f64)
}

/// `minimal` bytes moved at `buffer_gbps` (GB/s) over `ms`: 1.0 where a run takes what its
/// minimal traffic takes at the buffer copy's bandwidth; NaN without a time.
pub fn roofline(minimal: f64, buffer_gbps: f64, ms: f64) -> f64 {
    let at_copy_ms = minimal / (buffer_gbps * 1e6);
    if ms > 0.0 { at_copy_ms / ms } else { f64::NAN }
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
         format (copy texture x1: 16x16 workgroups, one load and one store per texel; timed\n\
         before and after the kernels, the faster run kept), for a texture copy the buffer\n\
         copy. roof: the run's minimal traffic (one read of each input texture, one write of\n\
         each output, from formats and size: min MiB) at the buffer copy's GB/s over the\n\
         median time, 1.00 = the buffer copy's speed; a fused chain counts its first input\n\
         and last output only. wall ms: the median run's submission to completion, the\n\
         timestamps' cross-check.",
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
        "{:>6}  {:<18} {:<12} {:>10} {:>10} {:>10} {:>10} {:>9} {:>7} {:>6}  yardstick",
        "size",
        "kernel",
        "format",
        "MiB moved",
        "min MiB",
        "median ms",
        "wall ms",
        "GB/s",
        "x",
        "roof"
    );
    let mib = 1024.0 * 1024.0;
    for r in rows {
        let _ = writeln!(
            s,
            "{:>6}  {:<18} {:<12} {:>10.2} {:>10.2} {:>10.3} {:>10.3} {:>9.2} {:>7.2} {:>6.2}  {}",
            r.size,
            r.kernel,
            r.format,
            r.bytes_moved / mib,
            r.minimal_bytes / mib,
            r.median_ms,
            r.wall_ms,
            r.gbps,
            r.ratio,
            r.roofline,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{CASES, COPY_FORMATS, TextureCopy, copy_texture_graph};

    /// A case's minimal bytes at side `n`, from its plan.
    fn case_minimal(name: &str, n: u32) -> f64 {
        let case = CASES.iter().find(|c| c.name == name).expect("a case");
        let built = (case.build)(n);
        let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
        let plan = crate::graph::plan(&built.graph, &outputs).unwrap();
        minimal_bytes(&plan, &built.outputs).unwrap()
    }

    /// The minimal traffic against a hand count from the formats and the size (n = 48: the
    /// mip chain's levels 48² … 1², six of them): one read of the input, one write of the
    /// output; the fused chain and the unfused one it replaced the same (intermediate maps
    /// count nothing); a texture copy its two textures.
    #[test]
    fn minimal_bytes_are_one_read_of_the_inputs_and_one_write_of_the_outputs() {
        let n = 48u32;
        let t = f64::from(n * n);
        // Depth (depth32float, 4 B) → linear depth (r32float, 4 B).
        assert_eq!(case_minimal("linearize", n), t * (4.0 + 4.0));
        // Depth → VSM moments (rg32float, 8 B).
        assert_eq!(case_minimal("vsm", n), t * (4.0 + 8.0));
        // Depth (an r32float import) → blurred moments, fused or in three passes.
        assert_eq!(case_minimal("vsm_blur r4", n), t * (4.0 + 8.0));
        assert_eq!(case_minimal("vsm+blur r4 (old)", n), t * (4.0 + 8.0));
        // Depth → four f32 moments (16 B).
        assert_eq!(case_minimal("evsm4", n), t * (4.0 + 16.0));
        // MSM moments (rgba32float) → their mip chain, level 0 included.
        let levels: u32 = (0..6).map(|l| (n >> l) * (n >> l)).sum();
        assert_eq!(levels, 2304 + 576 + 144 + 36 + 9 + 1);
        assert_eq!(
            case_minimal("mips rgba32f", n),
            t * 16.0 + f64::from(levels) * 16.0
        );
        for copy in TextureCopy::ALL {
            for &format in COPY_FORMATS {
                let built = copy_texture_graph(n, format, copy);
                let plan = crate::graph::plan(&built.graph, &["copy.dst"]).unwrap();
                let texel = match format {
                    wgpu::TextureFormat::Depth32Float => 4.0,
                    f => texel_bytes(f) as f64,
                };
                let got = minimal_bytes(&plan, &built.outputs).unwrap();
                assert_eq!(got, 2.0 * t * texel, "{format:?}");
            }
        }
        let built = copy_texture_graph(n, wgpu::TextureFormat::R32Float, TextureCopy::X1);
        let plan = crate::graph::plan(&built.graph, &["copy.dst"]).unwrap();
        let e = minimal_bytes(&plan, &["nothing".into()]).unwrap_err();
        assert!(e.to_string().contains("`nothing`"), "{e}");
    }

    /// 1 GB at 1000 GB/s takes 1 ms: a run of 2 ms is at half the buffer copy's speed.
    #[test]
    fn the_roofline_is_the_minimal_traffics_time_at_the_copys_bandwidth_over_the_time() {
        assert_eq!(roofline(1e9, 1000.0, 2.0), 0.5);
        assert_eq!(roofline(1e9, 1000.0, 1.0), 1.0);
        assert!(roofline(1e9, 1000.0, 0.0).is_nan());
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
            minimal_bytes: 8.0 * 1024.0 * 1024.0,
            roofline: 0.5,
            yardstick: "copy buffer".into(),
            passes: Vec::new(),
        };
        let rows = [row("copy texture x1", 0.03), row("esm", 0.93)];
        let text = format_table("test device", true, 5, Inputs::Random, false, &rows);
        let warning = text
            .lines()
            .find(|l| l.starts_with("WARNING"))
            .expect("a warning");
        assert!(
            warning.contains("copy texture x1 r32float at 1024² (0.03)"),
            "{warning}"
        );
        assert!(!warning.contains("esm"), "{warning}");
        let fine = format_table("test device", true, 5, Inputs::Random, false, &rows[1..]);
        assert!(!fine.contains("WARNING"), "{fine}");
        let mut short = row("copy texture x1", 0.3);
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
}
