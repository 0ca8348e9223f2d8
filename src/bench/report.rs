//! The kernel benchmark's report: a header naming the device and the method, a line per row,
//! and on a CPU device a warning naming rows whose timer the wall clock contradicts.

use std::fmt::Write;

use super::harness::Inputs;
use super::{BenchRow, GPU_WARMUP_MS, WARMUP};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
