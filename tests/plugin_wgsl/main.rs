//! The plug-in stage without a GPU: the exported WGSL is current and compiles inside a host's
//! shader (naga), the host block of every technique validates, and configurations follow the
//! scene file's rules and defaults.

use shadowgraph::low_level::kernels;
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{
    BlurKernel, CssmResolve, CssmSearch, Filter, LightGpu, PcfKernel, PrefilterConfig, StageError,
    Storage, StorageFilter, Technique, wgsl,
};
use std::path::Path;

mod configs;
mod shaders;

fn vsm(bleed: f32, min_variance: f32) -> PrefilterConfig {
    let mut c = PrefilterConfig::vsm(64);
    c.technique = Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: Filter::Blur {
                radius: 2.0,
                sigma: 1.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        bleed,
        min_variance,
    };
    c
}

fn esm(c: f32) -> PrefilterConfig {
    let mut config = PrefilterConfig::esm(64);
    if let Technique::Esm { exponent, .. } = &mut config.technique {
        *exponent = c;
    }
    config
}
