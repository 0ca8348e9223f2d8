//! Prints docs/MEASURED.md's table of Pareto fronts for the reports under a directory
//! (`benches/evaluation` by default): per scene, the techniques on the front of total time
//! against the penumbra error and against FLIP, fastest first.
//!
//!     cargo run --release --example fronts_table -- [DIR]

/// Errors as one line, causes joined (`{:#}`), status 1.
fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "benches/evaluation".into());
    print!(
        "{}",
        shadowgraph::low_level::evaluate::summary::fronts_table_of(std::path::Path::new(&dir))?
    );
    Ok(())
}
