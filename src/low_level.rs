//! Everything below the host API: the kernel graph, its executor and kernels, the technique
//! registry, the GPU helpers and, with the `cli` feature, the front ends (scene files, the
//! renderer, the area-light truth, evaluation, bench, dump, the stability suite and the f64 CPU
//! references). It is here for the crate's own front ends (the `shadowgraph` binary), its
//! examples, benchmarks and tests; it carries no stability promise, and a host renderer needs
//! none of it (the crate root has the plug-in stage and everything it takes).
//!
//! Each module here is the crate's module of that name, less what the crate root holds (a
//! name has one public path): the root's names are imported privately in the modules they
//! live in, which shadows them in the glob re-export.

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
    #[expect(
        hidden_glob_reexports,
        unused_imports,
        reason = "the root holds `PACKED_F16X2`"
    )]
    use crate::graph::PACKED_F16X2;
    pub use crate::graph::*;
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
    pub use crate::model::*;
    #[expect(hidden_glob_reexports, unused_imports, reason = "the root holds these")]
    use crate::model::{
        BlurKernel, Cascades, CssmResolve, CssmSearch, Filter, Light, LightKind, PcfKernel,
        SatVariant, Shadow, Soft, Storage, StorageFilter, Technique,
    };

    pub mod cascades {
        //! The cascade slices' fitting beneath [`crate::cascades`].
        pub use crate::model::cascades::*;
        #[expect(
            hidden_glob_reexports,
            unused_imports,
            reason = "`crate::cascades` holds these"
        )]
        use crate::model::cascades::{CascadeCamera, Cascades, MAX_CASCADES, split_distances};
    }
}

#[cfg(feature = "cli")]
pub mod render {
    //! The bundled renderer: depth passes, the technique graphs, shading and readback.
    pub use crate::render::*;
}

pub mod sat {
    //! Summed-area tables: their codings, graphs and lookups.
    #[expect(
        hidden_glob_reexports,
        unused_imports,
        reason = "the root holds `SAT_SAMPLER_DESCRIPTOR`"
    )]
    use crate::sat::SAT_SAMPLER_DESCRIPTOR;
    pub use crate::sat::*;
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
    #[expect(
        hidden_glob_reexports,
        unused_imports,
        reason = "the root holds `TIMER_FEATURES`"
    )]
    use crate::timer::TIMER_FEATURES;
    pub use crate::timer::*;
}

#[cfg(feature = "cli")]
pub mod truth {
    //! Ground truth for the shadow techniques: the area light's visibility by ray casting.
    pub use crate::truth::*;
}

pub mod wgsl_mirrors {
    //! The `#[repr(C)]` mirrors of the WGSL structs the Rust side fills, and the technique ids
    //! and flags the shading kernel reads.
    #[expect(
        hidden_glob_reexports,
        unused_imports,
        reason = "the root holds `LightGpu`"
    )]
    use crate::wgsl_mirrors::LightGpu;
    pub use crate::wgsl_mirrors::*;
}
