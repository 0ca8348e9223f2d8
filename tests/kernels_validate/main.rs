//! Every WGSL file parses and validates with naga (no GPU needed); Rust mirrors of WGSL
//! structs match naga's layout.

use shadowgraph::low_level::exec::REDESIGNED_MODULES;
use shadowgraph::low_level::kernels::{self, KernelId, SOURCES, struct_size};
use shadowgraph::low_level::technique::shading_block;
use shadowgraph::low_level::wgsl_mirrors::LinearizeParams;
use shadowgraph::{
    BlurKernel, Filter, Light, LightGpu, LightKind, PcfKernel, SatVariant, Shadow, Soft, Storage,
    StorageFilter, Technique,
};
use std::collections::BTreeSet;

mod dispatch;
mod mirrors;
mod registry;
mod validation;

fn light(technique: Technique) -> Light {
    Light {
        kind: LightKind::Spot { fov_degrees: 60.0 },
        position: glam::Vec3::new(0.0, 5.0, 0.0),
        target: glam::Vec3::ZERO,
        near: 0.5,
        far: 20.0,
        size: 0.5,
        radiance: glam::Vec3::ONE,
        shadow_map: 64,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 1.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    }
}
