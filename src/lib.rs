//! shadowgraph: shadow-map prefiltering on the GPU as a graph of WGSL compute kernels.
//!
//! Without the default `cli` feature the crate is the plug-in stage ([`prefilter`]) and the
//! kernel graph it runs on; the front ends (the binary, scene files, the renderer, the truth,
//! evaluation, bench, dump, stability, the CPU references and image I/O) need `cli`.
#[cfg(feature = "cli")]
pub mod bench;
#[cfg(feature = "cli")]
pub mod cli;
#[cfg(feature = "cli")]
pub mod cpu;
pub mod created;
#[cfg(feature = "cli")]
pub mod dump;
pub mod error;
#[cfg(feature = "cli")]
pub mod evaluate;
pub mod exec;
pub mod filter;
pub mod gpu;
pub mod gpu_data;
pub mod graph;
#[cfg(feature = "cli")]
pub mod io;
pub mod kernels;
pub mod limits;
pub mod model;
pub mod msm_quantize;
pub mod prefilter;
#[cfg(feature = "cli")]
pub mod render;
pub mod sat;
pub mod scene;
#[cfg(feature = "cli")]
pub mod stability;
pub mod technique;
pub mod timer;
#[cfg(feature = "cli")]
pub mod tolerance;
#[cfg(feature = "cli")]
pub mod truth;

pub use error::{Error, Result};
