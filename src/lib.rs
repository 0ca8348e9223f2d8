//! shadowgraph: shadow-map prefiltering on the GPU as a graph of WGSL compute kernels.
pub mod error;
pub mod gpu;
pub mod graph;
pub mod kernels;
pub mod scene;

pub use error::{Error, Result};
