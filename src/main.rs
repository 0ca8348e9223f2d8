//! `shadowgraph`: the command-line tool. Each subcommand calls one library function.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

use shadowgraph::{cli, gpu::Gpu};

#[derive(Parser)]
#[command(
    name = "shadowgraph",
    version,
    about = "Shadow-map prefiltering on the GPU"
)]
struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to PNG.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long, default_value = "out.png")]
        output: PathBuf,
        /// Also write position, normal and per-light visibility as 32-bit float OpenEXR here.
        #[arg(long)]
        aux: Option<PathBuf>,
        /// Print GPU time per node and for the shading pass.
        #[arg(long)]
        timings: bool,
        /// Frames to render (timings are medians over them).
        #[arg(long, default_value_t = 1)]
        repeat: u32,
    },
    /// Print the kernels a scene will run (per light), its resources and peak memory.
    Plan {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Print Graphviz instead of text.
        #[arg(long)]
        dot: bool,
    },
    /// Write every resource of the executed plan: OpenEXR per texture and mip level, a PNG
    /// preview per channel, and manifest.json with provenance and per-channel statistics.
    Dump {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Dump only this resource (e.g. `light0.linear`).
        #[arg(long)]
        only: Option<String>,
    },
    /// Print the adapter, its backend, and the features and limits that matter.
    Info,
    /// Time kernels by GPU timestamps against a copy kernel over the same bytes.
    Bench {
        /// Square map sizes.
        #[arg(long, value_delimiter = ',', default_value = "512,1024,2048,4096")]
        sizes: Vec<u32>,
        /// Timed repetitions per kernel and size (the median is reported).
        #[arg(long, default_value_t = 10)]
        repeat: u32,
    },
    /// Run the numerical-stability suite: each hard input through the real kernels against its
    /// f64 reference and stated bound; exits non-zero when a check fails.
    Stability {
        /// Summed-area tables at 8192² (1 GiB each) instead of 2048².
        #[arg(long)]
        large: bool,
    },
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    if let Err(e) = run(Args::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: Args) -> Result<()> {
    match args.command {
        Command::Render {
            scene,
            output,
            aux,
            timings,
            repeat,
        } => {
            let gpu = Gpu::new()?;
            let report = cli::render(&gpu, &scene, &output, aux.as_deref(), timings, repeat)?;
            print!("{report}");
        }
        Command::Plan { scene, dot } => print!("{}", cli::plan(&scene, dot)?),
        Command::Dump { scene, out, only } => {
            let gpu = Gpu::new()?;
            print!(
                "{}",
                shadowgraph::dump::dump(&gpu, &scene, &out, only.as_deref())?
            );
        }
        Command::Info => print!("{}", Gpu::new()?.info_report()),
        Command::Bench { sizes, repeat } => {
            let gpu = Gpu::new()?;
            print!("{}", shadowgraph::bench::run(&gpu, &sizes, repeat)?);
        }
        Command::Stability { large } => {
            let gpu = Gpu::new()?;
            let opts = shadowgraph::stability::StabilityOptions { large };
            let report = shadowgraph::stability::run(&gpu, &opts, &mut |case, name| {
                eprintln!("stability: case {case}/7, {name}");
            })?;
            print!("{}", report.table());
            let failed = report.failures().len();
            if failed > 0 {
                anyhow::bail!("{failed} stability check(s) failed");
            }
        }
    }
    Ok(())
}
