//! shadowgraph: shadow-map prefiltering on the GPU as a graph of WGSL compute kernels.
//!
//! A renderer of its own keeps its device, its depth pass and its shading; the plug-in stage,
//! [`Prefilter`], records a technique's kernels over the host's depth texture into the host's
//! encoder and hands back the filtered maps and the WGSL that samples them. It never submits,
//! reads back or polls, and keeps nothing of the host's.
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, depth: &wgpu::Texture, view: glam::Mat4)
//! #     -> shadowgraph::Result<()> {
//! use shadowgraph::{LightParams, Prefilter, PrefilterConfig};
//! let mut stage = Prefilter::new(device, &PrefilterConfig::vsm(1024))?;   // pipelines, once
//! let host_wgsl = stage.wgsl(1, 0)?;         // prepend to the host's shader: group 1, binding 0…
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // … the host's depth pass into `depth` …
//! let light = LightParams::orthographic(view, 5.0, 2.0, 20.0);
//! let out = stage.record(device, &mut encoder, depth, &light)?;
//! // bind out.maps[k].view at binding k of group 1, upload bytemuck::bytes_of(&out.light)
//! // as the `sg_Light` the host passes to `shadowgraph_visibility(l, p, n)`, then submit.
//! # Ok(()) }
//! ```
//!
//! The host API is at the root:
//!
//! - the stage and what it takes and gives: [`Prefilter`], [`PrefilterConfig`] (a technique
//!   and its settings, built like a scene file's light: [`PrefilterConfig::vsm`],
//!   [`PrefilterConfig::with_storage`], …), [`LightParams`] (what changes per frame),
//!   [`DepthLayer`], [`PrefilterOutput`] and its [`OutputMap`]s, [`LightGpu`] (the exported
//!   WGSL's `sg_Light`), [`PointView`] (a point light's faces);
//! - the settings its builders take: [`Technique`] and its parts ([`Storage`], [`Filter`],
//!   [`BlurKernel`], [`PcfKernel`], [`StorageFilter`], [`Soft`], [`SatVariant`],
//!   [`CssmSearch`], [`CssmResolve`], [`Cascades`]), and a scene light ([`Light`]) to build
//!   one from;
//! - [`cascades`]: a directional light's cascades fitted to a camera; [`wgsl`]: the exported
//!   WGSL for several stages or for hosts outside Rust;
//! - the device features the stage can use ([`TIMER_FEATURES`]) and what its maps are
//!   ([`PACKED_F16X2`], [`SAT_SAMPLER_DESCRIPTOR`], [`DEPTH_FORMATS`]);
//! - errors: [`Error`] and [`Result`], with [`StageError`], [`GraphError`] and [`ExecError`].
//!
//! A host depends on the crate without the default `cli` feature
//! (`default-features = false`): the stage and the kernel graph it runs on, with wgpu, naga,
//! glam, bytemuck, pollster, thiserror and log. The `cli` feature adds the front ends (the
//! binary, scene files, the renderer, the truth, evaluation, bench, dump, stability, the CPU
//! references and image I/O). Everything below the host API is in [`low_level`].

#[cfg(feature = "cli")]
pub(crate) mod bench;
#[cfg(feature = "cli")]
pub(crate) mod cli;
#[cfg(feature = "cli")]
pub(crate) mod cpu;
#[cfg(feature = "cli")]
pub(crate) mod dump;
pub(crate) mod error;
#[cfg(feature = "cli")]
pub(crate) mod evaluate;
pub(crate) mod exec;
pub(crate) mod filter;
pub(crate) mod gpu;
pub(crate) mod gpu_objects;
pub(crate) mod graph;
#[cfg(feature = "cli")]
pub(crate) mod io;
pub(crate) mod kernels;
pub(crate) mod limits;
pub(crate) mod model;
pub(crate) mod msm_quantize;
pub(crate) mod prefilter;
#[cfg(feature = "cli")]
pub(crate) mod render;
pub(crate) mod sat;
#[cfg(feature = "cli")]
pub(crate) mod scene;
#[cfg(feature = "cli")]
pub(crate) mod stability;
pub(crate) mod technique;
pub(crate) mod timer;
#[cfg(feature = "cli")]
pub(crate) mod tolerance;
#[cfg(feature = "cli")]
pub(crate) mod truth;
pub(crate) mod wgsl_mirrors;

pub use error::{Error, ExecError, GraphError, Result, StageError};
pub use graph::PACKED_F16X2;
pub use model::{
    BlurKernel, Cascades, CssmResolve, CssmSearch, Filter, Light, LightKind, PcfKernel, SatVariant,
    Shadow, Soft, Storage, StorageFilter, Technique,
};
pub use prefilter::{
    DEPTH_FORMATS, DepthLayer, LightGpu, LightParams, MAX_LIGHTS, OutputMap, PointView, Prefilter,
    PrefilterConfig, PrefilterOutput, SAT_SAMPLER_DESCRIPTOR,
};
pub use timer::TIMER_FEATURES;

/// A directional light's cascades: the practical split of the camera's depth range, each
/// slice's orthographic [`LightParams`] fitted and snapped to its texel grid
/// ([`cascades::fit_cascades`], [`Prefilter::fit_cascades`]), and cascade 0's `sg_Light`
/// fields for the exported `sg_cascade_pick` ([`cascades::pick_fields`]).
pub mod cascades {
    pub use crate::prefilter::cascades::*;
}

/// The exported WGSL: the functions of several stages' techniques in one shader module
/// ([`wgsl::functions_for`]), and every technique's functions for hosts outside Rust
/// ([`wgsl::library`], `kernels/export/shadowgraph.wgsl`).
pub mod wgsl {
    pub use crate::prefilter::wgsl::*;
}

pub mod low_level;
