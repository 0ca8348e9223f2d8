//! Everything below the host API: the kernel graph, its executor and kernels, the technique
//! registry, the GPU helpers and, with the `cli` feature, the front ends (scene files, the
//! renderer, the area-light truth, evaluation, bench, dump, the stability suite and the f64 CPU
//! references). It is here for the crate's own front ends (the `shadowgraph` binary), its
//! examples, benchmarks and tests; it carries no stability promise, and a host renderer needs
//! none of it (the crate root has the plug-in stage and everything it takes).
//!
//! Each module here is the crate's module of that name, less what the crate root holds (a
//! name has one public path): a whole module where the root holds none of its names, a list
//! of its names where it does (`graph`, `model`, `sat`, `timer`, `wgsl_mirrors`).

#[cfg(feature = "cli")]
pub mod bench {
    //! Kernel benchmarks: the bench cases, their graphs and timing (`shadowgraph bench`).
    pub use crate::bench::*;
}

#[cfg(feature = "cli")]
pub mod cli {
    //! The library functions behind the CLI's subcommands; each returns the text it prints.
    pub use crate::cli::*;
}

#[cfg(feature = "cli")]
pub mod cpu {
    //! The f64 CPU references, one per kernel or WGSL module, named after it.
    pub use crate::cpu::*;
}

#[cfg(feature = "cli")]
pub mod dump {
    //! `shadowgraph dump`: every resource of the executed plan written to disk for inspection.
    pub use crate::dump::*;
}

#[cfg(feature = "cli")]
pub mod evaluate {
    //! `shadowgraph evaluate`: a sweep over techniques and their accuracy knobs, measured against
    //! the ground truth ([`truth`](super::truth)), with its reports and plots.
    pub use crate::evaluate::*;
}

pub mod exec {
    //! The executor: records a plan's compute passes into the caller's encoder.
    pub use crate::exec::*;
}

pub mod filter {
    //! Filters that work on any prefiltered representation: the separable blur and the mip chain.
    pub use crate::filter::*;
}

pub mod gpu {
    //! GPU context: adapter selection, device creation with the adapter's own limits, submission,
    //! upload and readback.
    pub use crate::gpu::*;
}

pub mod gpu_objects {
    //! Creates and counts (per thread) every GPU object of the renderer, the executor, the timer
    //! and the stage.
    pub use crate::gpu_objects::*;
}

pub mod graph {
    //! The kernel graph: nodes, resources, planning, cost and printing.
    pub use crate::graph::{
        Dispatch, Graph, LevelView, Node, Plan, PlannedResource, Resource, SizeRule, Slot, Step,
        SubDispatch, block_count, cost, format_label, is_packed, layer_of, plan, print,
        texel_bytes, texture_format,
    };
}

pub mod kernels {
    //! The embedded WGSL, the `// #import` resolver and naga reflection.
    pub use crate::kernels::*;
}

pub mod limits {
    //! What kernels, plans and frames need of a device, checked before anything is created.
    pub use crate::limits::*;
}

pub mod model {
    //! The model's plain data beside the root's settings: cameras, parameter tables, defaults,
    //! point-light faces and cascade slices.
    pub use crate::model::{
        Camera, CameraRays, DEFAULT_MAX_SEARCH, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, Needs,
        ParamDefault, ParamKind, ParamSource, ParamSpec, ParamValue, ParamValues, check_params,
        default_moment_bias, default_soft_moment_bias, exponent_limit, keys, mip_levels, point,
    };

    pub mod cascades {
        //! The cascade slices' fitting beneath [`crate::cascades`].
        pub use crate::model::cascades::{
            CascadeSlice, MAX_VIEW_DISTANCE, SliceGuard, cascade_light, fit_slices, light_rotation,
        };
    }
}

#[cfg(feature = "cli")]
pub mod render {
    //! The bundled renderer: depth passes, the technique graphs, shading and readback.
    pub use crate::render::*;
}

pub mod sat {
    //! Summed-area tables: their codings, graphs and lookups.
    pub use crate::sat::{
        MAX_FIXED_AREA, SAT_LINES_PER_GROUP, SAT_TILE, SatCoding, SatParams, add_sat, decode_table,
        five_pass, fixed_scale, float_sum_depth, format_channels, layers, lookup_area, lookups,
        sat_name,
    };
}

#[cfg(feature = "cli")]
pub mod scene {
    //! Scene files: the validated `Scene`, loaded from TOML, OBJ and glTF.
    pub use crate::scene::*;
}

#[cfg(feature = "cli")]
pub mod stability {
    //! The numerical-stability suite (`shadowgraph stability`).
    pub use crate::stability::*;
}

pub mod technique {
    //! The technique registry: each technique's parameters, maps, nodes and shading.
    pub use crate::technique::*;
}

#[cfg(feature = "cli")]
pub mod tolerance {
    //! Error models of the shading kernel's f32 visibility functions against their f64
    //! references: how far apart the two may be.
    pub use crate::tolerance::*;
}

pub mod timer {
    //! GPU timing by timestamps at the boundaries between passes, and warm-up.
    pub use crate::timer::{
        GPU_WARMUP_MS, GpuTimer, MAX_WARMUP_RUNS, is_gpu, keep_warming, warm_up,
    };
}

#[cfg(feature = "cli")]
pub mod truth {
    //! Ground truth for the shadow techniques: the area light's visibility by ray casting.
    pub use crate::truth::*;
}

pub mod wgsl_mirrors {
    //! The `#[repr(C)]` mirrors of the WGSL structs the Rust side fills, and the technique ids
    //! and flags the shading kernel reads.
    pub use crate::wgsl_mirrors::{
        CSM_OUTPUTS, CsmParams, ExpParams, FrameGpu, LinearizeParams, MSM_HAUSDORFF, MSM_QUANTIZED,
        MsmParams, PEEL_EPSILON, SecondDepthParams, TECHNIQUE_CSM, TECHNIQUE_CSSM, TECHNIQUE_ESM,
        TECHNIQUE_EVSM, TECHNIQUE_HARD, TECHNIQUE_IDS, TECHNIQUE_MIDPOINT, TECHNIQUE_MSM,
        TECHNIQUE_MSM_SOFT, TECHNIQUE_PCF, TECHNIQUE_PCSS, TECHNIQUE_SECOND_DEPTH, TECHNIQUE_SMRT,
        TECHNIQUE_VSM, TECHNIQUE_VSSM, Vertex, VsmParams,
    };
}
