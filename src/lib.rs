//! shadowgraph: shadow-map prefiltering on the GPU as a graph of WGSL compute kernels.
pub mod bench;
pub mod cli;
pub mod cpu;
pub mod created;
pub mod dump;
pub mod error;
pub mod evaluate;
pub mod exec;
pub mod filter;
pub mod gpu;
pub mod graph;
pub mod io;
pub mod kernels;
pub mod limits;
pub mod prefilter;
pub mod render;
pub mod sat;
pub mod scene;
pub mod stability;
pub mod technique;
pub mod timer;
pub mod tolerance;
pub mod truth;

pub use error::{Error, Result};
