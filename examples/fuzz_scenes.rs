//! The scene fuzzer at scale: mutated scene files (values, types, keys, sections, meshes and
//! malformed OBJ and glTF files, damaged text) loaded and planned in-process on every core, a sample of
//! the accepted ones rendered at 16×12. Exits 1 if any case failed; failing inputs are written
//! to `<dir>/failures/case-<n>.{toml,obj,gltf,glb,txt}` and reproduce with `--first <n> --cases 1`.
//!
//!     cargo run --release --example fuzz_scenes -- --cases 1000000

#[path = "../tests/fuzz_support/mod.rs"]
mod fuzz_support;

use std::path::PathBuf;

use clap::Parser;

#[derive(Parser)]
struct Args {
    /// Cases to run.
    #[arg(long, default_value_t = 1_000_000)]
    cases: u64,
    /// First case number (case n is the same input for a given seed whatever else runs).
    #[arg(long, default_value_t = 0)]
    first: u64,
    /// Seed.
    #[arg(long, default_value_t = 0x5eed)]
    seed: u64,
    /// Worker threads (default: the cores available).
    #[arg(long)]
    threads: Option<usize>,
    /// Render every Nth accepted scene at 16×12 on the GPU (0: never).
    #[arg(long, default_value_t = 1000)]
    render_every: u64,
    /// Working folder (meshes, failures).
    #[arg(long, default_value = "target/fuzz_scenes")]
    dir: PathBuf,
}

fn main() {
    let args = Args::parse();
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let opts = fuzz_support::Options {
        cases: args.cases,
        seed: args.seed,
        first: args.first,
        threads,
        render_every: args.render_every,
        dir: args.dir.clone(),
        progress: (args.cases / 20).max(1),
    };
    // Quiet the panic hook's output for caught panics: they are counted and saved instead.
    std::panic::set_hook(Box::new(|_| {}));
    let gpu = (args.render_every > 0).then(|| match shadowgraph::low_level::gpu::Gpu::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: {e} (pass --render-every 0 to fuzz without rendering)");
            std::process::exit(1);
        }
    });
    let s = fuzz_support::run(&opts, gpu);
    println!(
        "{} cases in {:.1} s on {threads} thread(s) (seed {:#x}, cases {}..{}): {} accepted, {} refused, \
         {} rendered ({} refused by device limits), {} failed; mutated glTF files: {} accepted, {} refused",
        s.cases,
        s.elapsed.as_secs_f64(),
        args.seed,
        args.first,
        args.first + args.cases,
        s.accepted,
        s.refused,
        s.rendered,
        s.render_refused,
        s.failures.len(),
        s.gltf_accepted,
        s.gltf_refused
    );
    for (i, what) in s.failures.iter().take(50) {
        println!("  case {i}: {what}");
    }
    if !s.failures.is_empty() {
        println!("inputs in {}", args.dir.join("failures").display());
        std::process::exit(1);
    }
}
