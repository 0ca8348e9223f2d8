//! `shadowgraph evaluate`: every output file for a tiny sweep, the JSON finite and equal to the
//! CSV, errors recomputed independently from a render and the truth, plausibility (hard vs
//! a point light's truth, wide blur vs PCF), error statistics against a direct f64
//! computation, and clear errors for bad input.

#[path = "../common/mod.rs"]
mod common;
use rand::Rng;
use shadowgraph::low_level::evaluate::{
    Config, ErrorStats, EvaluateOptions, FILTERS, Metric, Report, evaluate, front, scene_for,
    untrusted_times, wall_check,
};
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::{Emitter, TruthOptions, area_light_truth};
use shadowgraph::{Filter, PcfKernel, Technique};
use std::path::{Path, PathBuf};
use std::process::Command;

mod bad_input;
mod errors;
mod lights;
mod sweep;

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-eval-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn shadowgraph(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run shadowgraph")
}
