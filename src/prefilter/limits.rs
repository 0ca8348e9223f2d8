//! The device limits the stage needs, checked before any pipeline is made so that a device
//! which cannot run it gets a named [`Error::Limit`] rather than a pipeline error.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::graph::{Dispatch, Plan};
use crate::kernels;

/// Checks the map size and every planned kernel against the device's limits, so a device
/// that cannot run the stage is a named [`Error::Limit`] rather than a pipeline error.
pub(super) fn check(device: &wgpu::Device, plan: &Plan, size: u32) -> Result<()> {
    let l = device.limits();
    let over = |what: String, requested: u64, limit: u32| {
        if requested > u64::from(limit) {
            Err(Error::Limit {
                what,
                requested,
                limit: u64::from(limit),
            })
        } else {
            Ok(())
        }
    };
    over(
        "map size (max_texture_dimension_2d)".into(),
        size.into(),
        l.max_texture_dimension_2d,
    )?;
    let mut workgroups: HashMap<&str, [u32; 3]> = HashMap::new();
    for step in &plan.steps {
        let name = step.node.kernel.as_str();
        if !workgroups.contains_key(name) {
            let wgsl = kernels::resolve(name, None)?;
            let (module, refl) = kernels::reflect(name, &wgsl)?;
            for (what, requested, limit) in kernel_needs(&module, &refl, &l)? {
                over(format!("kernel `{name}`: {what}"), requested, limit)?;
            }
            workgroups.insert(name, refl.workgroup_size.unwrap_or([1, 1, 1]));
        }
        let wg = workgroups.get(name).copied().unwrap_or([1, 1, 1]);
        let groups = dispatch_groups(plan, &step.node, wg);
        for g in groups {
            over(
                format!(
                    "node `{}` at map size {size}: workgroups per dimension \
                     (max_compute_workgroups_per_dimension)",
                    step.node.name
                ),
                g.into(),
                l.max_compute_workgroups_per_dimension,
            )?;
        }
    }
    Ok(())
}

/// `(what, needed, device limit)` for what a compute kernel needs of the device.
fn kernel_needs(
    module: &naga::Module,
    refl: &kernels::Reflection,
    l: &wgpu::Limits,
) -> Result<Vec<(&'static str, u64, u32)>> {
    use wgpu::BindingType as B;
    let count = |f: fn(&B) -> bool| refl.bindings.iter().filter(|b| f(&b.ty)).count() as u64;
    let wg = refl.workgroup_size.unwrap_or([1, 1, 1]).map(u64::from);
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| Error::Invalid(format!("workgroup memory layout: {e}")))?;
    let shared: u64 = module
        .global_variables
        .iter()
        .filter(|(_, g)| g.space == naga::AddressSpace::WorkGroup)
        .map(|(_, g)| u64::from(layouter[g.ty].size))
        .sum();
    Ok(vec![
        (
            "workgroup width (max_compute_workgroup_size_x)",
            wg[0],
            l.max_compute_workgroup_size_x,
        ),
        (
            "workgroup height (max_compute_workgroup_size_y)",
            wg[1],
            l.max_compute_workgroup_size_y,
        ),
        (
            "workgroup depth (max_compute_workgroup_size_z)",
            wg[2],
            l.max_compute_workgroup_size_z,
        ),
        (
            "invocations per workgroup (max_compute_invocations_per_workgroup)",
            wg.iter().product(),
            l.max_compute_invocations_per_workgroup,
        ),
        (
            "workgroup memory in bytes (max_compute_workgroup_storage_size)",
            shared,
            l.max_compute_workgroup_storage_size,
        ),
        (
            "storage textures (max_storage_textures_per_shader_stage)",
            count(|t| matches!(t, B::StorageTexture { .. })),
            l.max_storage_textures_per_shader_stage,
        ),
        (
            "storage buffers (max_storage_buffers_per_shader_stage)",
            count(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: wgpu::BufferBindingType::Storage { .. },
                        ..
                    }
                )
            }),
            l.max_storage_buffers_per_shader_stage,
        ),
        (
            "sampled textures (max_sampled_textures_per_shader_stage)",
            count(|t| matches!(t, B::Texture { .. })),
            l.max_sampled_textures_per_shader_stage,
        ),
        (
            "uniform buffers (max_uniform_buffers_per_shader_stage)",
            count(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        ..
                    }
                )
            }),
            l.max_uniform_buffers_per_shader_stage,
        ),
        (
            "bind groups (max_bind_groups)",
            refl.group_count().into(),
            l.max_bind_groups,
        ),
    ])
}

/// Workgroup counts of a node's dispatch (as the executor computes them).
fn dispatch_groups(plan: &Plan, node: &crate::graph::Node, wg: [u32; 3]) -> [u32; 3] {
    let size = |r: &str| plan.resource(r).map_or((1, 1), |p| (p.width, p.height));
    match &node.dispatch {
        // The largest of a mip chain's dispatches covers level 1 in tiles of 32² texels.
        Dispatch::MipChain => {
            let (w, h) = node.outputs.first().map_or((1, 1), |(_, r)| size(r));
            let tile = crate::filter::MIP_TILE / 2;
            [
                (w / 2).max(1).div_ceil(tile),
                (h / 2).max(1).div_ceil(tile),
                1,
            ]
        }
        other => other
            .groups(|r| plan.resource(r).map(|p| (p.width, p.height)), wg)
            .unwrap_or([1, 1, 1]),
    }
}
