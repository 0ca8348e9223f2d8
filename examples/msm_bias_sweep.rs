//! The moment-bias sweep behind MSM's default biases (docs/STABILITY.md, "MSM moment bias"): every MSM
//! technique and storage through the real kernels at each bias, against MSM in exact
//! arithmetic on exact moments (`shadowgraph::low_level::stability::msm_bias_sweep`). Prints a Markdown
//! table. About 6 s on a software GPU (lavapipe, 2 cores).
//!
//!     cargo run --release --example msm_bias_sweep [-- ALPHA,ALPHA,…]

use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::stability::{BiasSweep, bias_table, msm_bias_sweep};

/// Errors as one line, causes joined (`{:#}`), status 1.
fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> anyhow::Result<()> {
    let mut sweep = BiasSweep::default();
    if let Some(list) = std::env::args().nth(1) {
        sweep.alphas = list
            .split(',')
            .map(|a| a.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow::anyhow!("biases: expected numbers separated by commas: {e}"))?;
    }
    let gpu = Gpu::new()?;
    println!("MSM moment-bias sweep on {}", gpu.describe());
    let rows = msm_bias_sweep(&gpu, &sweep, &mut |t, s| eprintln!("{t} {s:?}"))?;
    print!("{}", bias_table(&rows));
    Ok(())
}
